"""A persistent XLA compilation cache for pushjax's binaries and notebooks, on by default.

JAX compiles every jitted program when it is first called; the controller's, the rollout's gradient and the filters'
take 5-45 s on a CPU, and without a persistent cache every run pays them again. `enable` points JAX's persistent
compilation cache (``jax_compilation_cache_dir``) at a folder that outlives the run, so a second run of the same
command loads its programs instead of compiling them. JAX writes each entry to a temporary file and renames it into
place, so runs sharing the folder at the same time are safe.

Where (the first that is set):

* ``PUSHJAX_COMPILATION_CACHE``: a folder, or ``off`` (also ``0``, ``false``, ``none``) to compile afresh every run;
* ``JAX_COMPILATION_CACHE_DIR``, JAX's own variable (the test suite sets it to pytest's cache folder);
* ``$XDG_CACHE_HOME/pushjax/xla``, by default ``~/.cache/pushjax/xla``.

Every program is stored, however quickly it compiled (JAX's default skips those under 1 s, and a smoke run's many
small programs then cost as much as its large ones; ``JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS`` overrides it).
Library users call `enable` themselves (importing pushjax changes no JAX setting).
"""

from __future__ import annotations

import os
from pathlib import Path

import jax

ENVIRONMENT = "PUSHJAX_COMPILATION_CACHE"
OFF = ("off", "0", "false", "none")
MIN_COMPILE_SECONDS = 0.0


def default_folder() -> Path:
    """``$XDG_CACHE_HOME/pushjax/xla`` (``~/.cache/pushjax/xla`` without it)."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "pushjax" / "xla"


def folder(setting: str | None = None) -> Path | None:
    """The cache folder that `setting` (else ``$PUSHJAX_COMPILATION_CACHE``, else ``$JAX_COMPILATION_CACHE_DIR``, else
    `default_folder`) names; None when it switches the cache off."""
    setting = setting if setting is not None else os.environ.get(ENVIRONMENT)
    if setting is not None and setting.strip().lower() in OFF:
        return None
    if setting:
        return Path(setting).expanduser()
    if os.environ.get("JAX_COMPILATION_CACHE_DIR"):
        return Path(os.environ["JAX_COMPILATION_CACHE_DIR"])
    return default_folder()


def enable(setting: str | None = None) -> Path | None:
    """Points JAX's persistent compilation cache at `folder(setting)` (created if missing) and returns it; with the
    cache switched off, or a folder that cannot be created, leaves JAX's settings alone and returns None."""
    path = folder(setting)
    if path is None:
        return None
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    if not os.access(path, os.W_OK):
        return None
    jax.config.update("jax_compilation_cache_dir", str(path))
    if "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS" not in os.environ:
        jax.config.update("jax_persistent_cache_min_compile_time_secs", MIN_COMPILE_SECONDS)
    return path
