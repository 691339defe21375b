"""Every command that RESULTS.md and BENCHMARKS.md cite beside a number exists and takes the flags it is given, and
every record they cite under ``results/`` is committed.

``python -m experiments.<binary>`` commands of the README, BUILD.md and RESULTS.md are parsed with the binaries' own
flags by ``tests/test_documented_commands.py``; here: the flag names of those in BENCHMARKS.md (which also names
binaries in prose, without their required flags), the benchmark scripts (``python benchmarks/<script>.py --flag``, their
absl or argparse flags read from the script's source, so nothing is imported or run), the shell scripts
(``sh results/<run>/commands.sh``, ``bash benchmarks/<script>.sh``), every other ``python -m <module>``, and the
``results/...`` paths in backticks.
"""

import ast
import functools
import importlib.util
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[1]
DOCUMENTS = ("RESULTS.md", "BENCHMARKS.md")
_SCRIPT = re.compile(r"python (benchmarks/\w+\.py)([^`\n;]*)")
_SHELL = re.compile(r"\b(?:sh|bash) ((?:benchmarks|results|scripts)/[\w./-]+\.sh)\b")
_MODULE = re.compile(r"python -m ([A-Za-z_][\w.]*)")
_FLAG = re.compile(r"(?:^|\s)--([A-Za-z_][\w-]*)")
_RECORD = re.compile(r"`(results/[^`\s*<>{}|]+)`")
_BINARY = re.compile(r"python -m experiments\.(\w+)([^`\n;|]*)")
# Imports each binary in a forked child (absl refuses two modules defining the same flag name) and prints one JSON
# line: the binary and every flag name it parses.
_FLAG_NAMES = """
import importlib, json, os, sys
from absl import flags
import experiments
for binary in json.loads(sys.argv[1]):
    sys.stdout.flush()
    pid = os.fork()
    if pid == 0:
        importlib.import_module("experiments." + binary)
        print(json.dumps([binary, sorted(flags.FLAGS)]), flush=True)
        os._exit(0)
    os.waitpid(pid, 0)
"""


def _text(document: str) -> str:
    """The document with its shell line continuations joined."""
    return re.sub(r"\\\n\s*", " ", (REPOSITORY / document).read_text())


@functools.cache
def _script_flags(path: str) -> frozenset[str]:
    """The flag names a benchmark script defines: absl ``DEFINE_*`` (booleans also as ``no<name>``) and argparse
    ``add_argument("--name")``."""
    names = set()
    for node in ast.walk(ast.parse((REPOSITORY / path).read_text())):
        if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Attribute):
            continue
        strings = [arg.value for arg in node.args if isinstance(arg, ast.Constant) and isinstance(arg.value, str)]
        if node.func.attr.startswith("DEFINE_") and strings:
            names.add(strings[0])
            if node.func.attr in ("DEFINE_bool", "DEFINE_boolean"):
                names.add("no" + strings[0])
        elif node.func.attr == "add_argument":
            names.update(string[2:] for string in strings if string.startswith("--"))
    return frozenset(names | {"help", "helpfull"})


def _cited_scripts() -> list[tuple[str, str, str]]:
    """(document, script path, its arguments) of every ``python benchmarks/...py`` command in `DOCUMENTS`."""
    return [(document, script, arguments.split(" #")[0]) for document in DOCUMENTS
            for script, arguments in _SCRIPT.findall(_text(document))]


def test_the_documents_cite_benchmark_scripts():
    assert len({script for _, script, _ in _cited_scripts()}) > 20


@pytest.mark.parametrize("document", DOCUMENTS)
def test_cited_benchmark_scripts_exist_and_define_their_flags(document):
    problems = []
    for cited_in, script, arguments in _cited_scripts():
        if cited_in != document:
            continue
        if not (REPOSITORY / script).is_file():
            problems.append(f"{script}: no such script")
            continue
        unknown = set(_FLAG.findall(arguments)) - _script_flags(script)
        if unknown:
            problems.append(f"{script}: --{', --'.join(sorted(unknown))} not defined ({arguments.strip()})")
    assert not problems, problems


@pytest.mark.parametrize("document", DOCUMENTS)
def test_cited_shell_scripts_exist(document):
    missing = sorted({path for path in _SHELL.findall(_text(document)) if not (REPOSITORY / path).is_file()})
    assert not missing, missing


@pytest.mark.parametrize("document", DOCUMENTS)
def test_cited_modules_exist(document):
    modules = set(_MODULE.findall(_text(document)))
    assert modules
    missing = sorted(module for module in modules if importlib.util.find_spec(module.split(".")[0]) is None
                     or (module.startswith(("experiments.", "pushjax.", "benchmarks."))
                         and not (REPOSITORY / (module.replace(".", "/") + ".py")).is_file()
                         and not (REPOSITORY / module.replace(".", "/") / "__init__.py").is_file()))
    assert not missing, missing


@pytest.mark.parametrize("document", DOCUMENTS)
def test_cited_records_are_committed(document):
    cited = {path.rstrip(".,:;)") for path in _RECORD.findall(_text(document))}
    assert cited
    missing = sorted(path for path in cited if not (REPOSITORY / path).exists())
    assert not missing, missing


def test_benchmark_documents_experiment_flags_exist():
    cited = [(binary, set(_FLAG.findall(arguments))) for binary, arguments in _BINARY.findall(_text("BENCHMARKS.md"))]
    binaries = sorted({binary for binary, _ in cited})
    result = subprocess.run([sys.executable, "-c", _FLAG_NAMES, json.dumps(binaries)], cwd=REPOSITORY,
                            capture_output=True, text=True, timeout=120)
    known = dict(json.loads(line) for line in result.stdout.splitlines() if line.startswith("["))
    assert set(known) == set(binaries), result.stderr.strip().splitlines()[-1:]
    unknown = [(binary, sorted(names - set(known[binary]))) for binary, names in cited if names - set(known[binary])]
    assert not unknown, unknown
