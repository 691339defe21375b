"""The persistent compilation cache: where it goes, switching it off, and a second process reusing it."""

import os
import subprocess
import sys

import pytest

from pushjax import compilation_cache


def test_the_folder_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.delenv(compilation_cache.ENVIRONMENT, raising=False)
    monkeypatch.delenv("JAX_COMPILATION_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert compilation_cache.folder() == tmp_path / "xdg" / "pushjax" / "xla"
    monkeypatch.setenv("JAX_COMPILATION_CACHE_DIR", str(tmp_path / "jax"))
    assert compilation_cache.folder() == tmp_path / "jax"
    monkeypatch.setenv(compilation_cache.ENVIRONMENT, str(tmp_path / "mine"))
    assert compilation_cache.folder() == tmp_path / "mine"
    for off in ("off", "0", "FALSE", "none"):
        monkeypatch.setenv(compilation_cache.ENVIRONMENT, off)
        assert compilation_cache.folder() is None and compilation_cache.enable() is None
    assert compilation_cache.folder(str(tmp_path / "given")) == tmp_path / "given"


def test_an_unwritable_folder_leaves_jax_alone(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    assert compilation_cache.enable(str(blocker / "cache")) is None


_PROGRAM = """
import sys, jax, jax.numpy as jnp
from pushjax import compilation_cache
hits = []
jax.monitoring.register_event_listener(lambda event, **_: hits.append(event) if event.endswith("cache_hits") else None)
jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
print(compilation_cache.enable(sys.argv[1]))
f = jax.jit(lambda x: jnp.sin(x) @ jnp.cos(x).T + jnp.float32(%s))
print(float(f(jnp.ones((8, 8)))[0, 0]))
print("hits", len(hits))
"""


@pytest.mark.parametrize("constant", ["1.5"])
def test_a_second_process_loads_what_the_first_compiled(tmp_path, constant):
    cache = tmp_path / "cache"
    env = {key: value for key, value in os.environ.items() if key != "JAX_COMPILATION_CACHE_DIR"}
    env["JAX_PLATFORMS"] = "cpu"
    runs = [subprocess.run([sys.executable, "-c", _PROGRAM % constant, str(cache)], env=env, capture_output=True,
                           text=True, timeout=120) for _ in range(2)]
    assert all(run.returncode == 0 for run in runs), runs[0].stderr[-2000:]
    first, second = (run.stdout.splitlines() for run in runs)
    assert first[0] == second[0] == str(cache) and first[1] == second[1]  # the same folder, the same result
    assert any(cache.iterdir()), "the first process wrote no cache entry"
    assert first[2] == "hits 0" and second[2] != "hits 0"  # the second process loaded the program
