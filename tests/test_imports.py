"""Import hygiene: the pure layers load without MuJoCo, and no module hides an import inside a function."""

import ast
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "pushjax"


@pytest.mark.parametrize("module", ["pushjax.models", "pushjax.mit", "pushjax.physics", "pushjax.geometry"])
def test_pure_packages_do_not_import_mujoco(module):
    script = f"import {module}, sys; assert 'mujoco' not in sys.modules, 'mujoco was imported'"
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            env={**os.environ, "MUJOCO_GL": "egl"})
    assert result.returncode == 0, result.stderr[-3000:]


ALGORITHM_PACKAGES = ("pushjax.filter", "pushjax.control")
"""The packages that keep the algorithms only: their harnesses on the testbed are studies (``pushjax.studies``)."""


@pytest.mark.parametrize("package", ALGORITHM_PACKAGES)
def test_algorithm_packages_import_neither_mujoco_nor_the_testbed(package):
    folder = PACKAGE / package.removeprefix("pushjax.")
    modules = [package] + [f"{package}.{path.stem}" for path in sorted(folder.glob("*.py")) if path.stem != "__init__"]
    assert len(modules) > 5
    script = (f"import sys; import {', '.join(modules)}; "
              "found = sorted(name for name in sys.modules if name.split('.')[0] == 'mujoco' "
              "or name.startswith(('pushjax.sim', 'pushjax.studies'))); assert not found, found")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            env={**os.environ, "MUJOCO_GL": "egl"})
    assert result.returncode == 0, result.stderr[-3000:]


def _indented_imports(tree: ast.Module) -> list[int]:
    """Line numbers of the import statements that are not at the module's top level (inside a function, class,
    ``if`` or ``try``)."""
    top_level = set(tree.body)
    return sorted(node.lineno for node in ast.walk(tree)
                  if isinstance(node, (ast.Import, ast.ImportFrom)) and node not in top_level)


def test_no_function_level_imports():
    indented = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        lines = _indented_imports(ast.parse(path.read_text(), filename=str(path)))
        if lines:
            indented[path.relative_to(PACKAGE.parent).as_posix()] = lines
    assert not indented, f"indented (function-level) imports, file: lines: {indented}"


ARCHITECTURE = PACKAGE.parent / "ARCHITECTURE.md"


def _documented_layers() -> dict[str, int]:
    """Package or module -> layer, from the rows ``| N | `pushjax.name` | ... |`` of ARCHITECTURE.md's table."""
    rows = re.finditer(r"^\| (\d+) \| `(pushjax(?:\.\w+)*)` \|", ARCHITECTURE.read_text(), re.MULTILINE)
    return {row[2]: int(row[1]) for row in rows}


LAYERS = {"pushjax": 0, "pushjax.render": 3, **_documented_layers()}
"""The layers of ARCHITECTURE.md: a module imports only from lower layers or from its own package. The package
``pushjax`` itself and ``pushjax.render`` (a package over ``render.camera``, 1, and ``render.renderer``, 3) are not rows
there."""


def test_architecture_gives_every_package_a_layer():
    named = sorted(f"pushjax.{path.stem}" for path in PACKAGE.iterdir()
                   if (path.suffix == ".py" and path.stem != "__init__") or (path / "__init__.py").is_file())
    undocumented = [name for name in named if _layer(name)[1] == "pushjax"]
    assert not undocumented, f"packages without a row in ARCHITECTURE.md's layer table: {undocumented}"


def _layer(module: str) -> tuple[int, str]:
    """(layer, owning package) of a ``pushjax`` module: the longest prefix listed in `LAYERS`."""
    parts = module.split(".")
    for end in range(len(parts), 0, -1):
        prefix = ".".join(parts[:end])
        if prefix in LAYERS:
            return LAYERS[prefix], prefix
    raise AssertionError(f"{module} is in no layer of LAYERS")


def _is_module(name: str) -> bool:
    path = PACKAGE.parent / name.replace(".", "/")
    return path.is_dir() or path.with_suffix(".py").is_file()


def _imported_modules(tree: ast.Module) -> list[str]:
    """The ``pushjax`` modules and packages a module imports (``from package import module`` names the module)."""
    names = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module:
            names += [f"{node.module}.{alias.name}" if _is_module(f"{node.module}.{alias.name}") else node.module
                      for alias in node.names]
    return [name for name in names if name.split(".")[0] == "pushjax"]


def test_modules_import_only_lower_layers_or_their_own_package():
    violations = []
    for path in sorted(PACKAGE.rglob("*.py")):
        module = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts).removesuffix(".__init__")
        layer, owner = _layer(module)
        for imported in _imported_modules(ast.parse(path.read_text(), filename=str(path))):
            imported_layer, imported_owner = _layer(imported)
            if imported_owner != owner and imported_layer >= layer and imported_owner != "pushjax":
                violations.append(f"{module} (layer {layer}) imports {imported} (layer {imported_layer})")
    assert not violations, "\n".join(violations)
