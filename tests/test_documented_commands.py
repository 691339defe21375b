"""Every ``python -m experiments.<binary> --flag=...`` command in the docs parses with the binary's own flags."""

import collections
import json
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[1]
DOCUMENTS = ("README.md", "BUILD.md", "RESULTS.md")
_COMMAND = re.compile(r"python -m experiments\.(\w+)((?:[ \t]+(?:\\\n[ \t]*)?(?:--[\w-]+(?:=[^\s`|\\]+)?|\[[^\]]*\]))*)")
_PARSE = """
import importlib, json, sys
from absl import flags
for binary, commands in json.loads(sys.argv[1]).items():
    importlib.import_module("experiments." + binary)
    for arguments in commands:
        flags.FLAGS.unparse_flags()
        try:
            flags.FLAGS(["prog", *arguments])
        except flags.Error as error:
            sys.exit(f"{binary} {arguments}: {error}")
"""
SHARED_FLAGS = ("data_efficiency", "new_pushes", "velocities", "error_velocities", "objects", "error_variants",
                "viewpoint", "visualize",
                "train", "findings", "demo")
"""Binaries whose flags can live in one process (absl refuses two modules defining the same flag name)."""


def documented_commands() -> dict[str, list[list[str]]]:
    """binary -> the flag lists of its commands in `DOCUMENTS` (optional ``[--flag=...]`` parts included)."""
    commands = collections.defaultdict(list)
    for document in DOCUMENTS:
        for binary, text in _COMMAND.findall((REPOSITORY / document).read_text()):
            text = text.replace("\\\n", " ").replace("[", " ").replace("]", " ")
            commands[binary].append(shlex.split(text))
    return dict(commands)


def test_the_docs_show_a_command_of_every_binary():
    binaries = {path.stem for path in (REPOSITORY / "experiments").glob("*.py") if path.stem != "__init__"}
    assert set(documented_commands()) == binaries


def _process_groups() -> list[list[str]]:
    binaries = sorted(documented_commands())
    return [[b for b in binaries if b in SHARED_FLAGS], *([b] for b in binaries if b not in SHARED_FLAGS)]


@pytest.mark.parametrize("binaries", _process_groups(), ids=lambda binaries: ",".join(binaries))
def test_documented_flags_parse(binaries):
    commands = {binary: documented_commands()[binary] for binary in binaries}
    result = subprocess.run([sys.executable, "-c", _PARSE, json.dumps(commands)], cwd=REPOSITORY,
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr.strip().splitlines()[-1:]
