"""The dependencies pyproject.toml declares are exactly those the library and the binaries import."""

import ast
import importlib.metadata
import re
import sys
import tomllib
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[1]


IMPORTED_BY_DEPENDENCIES = {"importlib-resources": "tensorflow-datasets imports it (through etils.epath) undeclared"}
"""Declared for a dependency that imports it without declaring it: no pushjax module imports these."""


def _normalise(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _declared() -> set[str]:
    project = tomllib.loads((REPOSITORY / "pyproject.toml").read_text())["project"]
    return {_normalise(re.match(r"[A-Za-z0-9_.-]+", requirement).group()) for requirement in project["dependencies"]}


def _imported_modules() -> dict[str, str]:
    """Top-level third-party module -> a file that imports it, over pushjax/ and experiments/."""
    modules = {}
    for path in sorted([*(REPOSITORY / "pushjax").rglob("*.py"), *(REPOSITORY / "experiments").rglob("*.py")]):
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for name in names:
                top = name.split(".")[0]
                if top not in sys.stdlib_module_names and top not in ("pushjax", "experiments"):
                    modules.setdefault(top, str(path.relative_to(REPOSITORY)))
    return modules


def test_declared_dependencies_match_the_imports():
    declared = _declared()
    distributions = importlib.metadata.packages_distributions()
    undeclared, used = {}, set()
    for module, path in _imported_modules().items():
        candidates = {_normalise(name) for name in distributions.get(module, [module])}
        if candidates & declared:
            used |= candidates & declared
        else:
            undeclared[module] = path
    assert not undeclared, f"imported but not declared in pyproject.toml (module: a file importing it): {undeclared}"
    unused = declared - used - set(IMPORTED_BY_DEPENDENCIES)
    assert unused == set(), f"declared in pyproject.toml but imported by no module: {unused}"
