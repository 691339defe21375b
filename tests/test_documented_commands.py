"""Every ``python -m experiments.<binary> --flag=...`` command in the docs parses with the binary's own flags."""

import collections
import json
import re
import shlex
import subprocess
import sys
from pathlib import Path

from tests.test_binaries_bad_flags import LIBRARIES

REPOSITORY = Path(__file__).resolve().parents[1]
DOCUMENTS = ("README.md", "BUILD.md", "RESULTS.md")
_COMMAND = re.compile(r"python -m experiments\.(\w+)((?:[ \t]+(?:\\\n[ \t]*)?(?:--[\w-]+(?:=[^\s`|\\]+)?|\[[^\]]*\]))*)")
# Imports the binaries' libraries once, then forks a child per group of binaries (absl refuses two modules
# defining the same flag name), which parses each command and prints one JSON line: the first error, or null.
_PARSE = """
import importlib, json, os, sys
from absl import flags
import """ + LIBRARIES + """


def first_error(commands):
    for binary, argument_lists in commands.items():
        importlib.import_module("experiments." + binary)
        for arguments in argument_lists:
            flags.FLAGS.unparse_flags()
            try:
                flags.FLAGS(["prog", *arguments])
            except flags.Error as error:
                return f"{binary} {arguments}: {error}"
    return None


for group in json.loads(sys.argv[1]):
    sys.stdout.flush()
    pid = os.fork()
    if pid == 0:
        print(json.dumps(first_error(group)), flush=True)
        os._exit(0)
    if os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1]) != 0:
        sys.exit(f"parsing {sorted(group)} crashed")
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


def test_documented_flags_parse():
    commands = documented_commands()
    groups = _process_groups()
    result = subprocess.run([sys.executable, "-c", _PARSE, json.dumps([{b: commands[b] for b in group}
                                                                        for group in groups])],
                            cwd=REPOSITORY, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr.strip().splitlines()[-1:]
    errors = [json.loads(line) for line in result.stdout.splitlines() if line.startswith(("null", '"'))]
    assert len(errors) == len(groups), result.stdout
    assert not [error for error in errors if error], errors
