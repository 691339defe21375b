"""The OpenGL backend is chosen where rendering starts: EGL when nothing is set, one line when nothing works."""

import os
import subprocess
import sys
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[2]
RENDER = ("import os, pushjax.sim\n"
          "from pushjax.render import top_down_camera\n"
          "from pushjax.render.renderer import DepthRenderer\n"
          "assert 'MUJOCO_GL' not in os.environ\n"
          "renderer = DepthRenderer(pushjax.sim.build_model('rect1', 'abs'), top_down_camera(16, 16))\n"
          "print(os.environ['MUJOCO_GL'], float(renderer.depth([0.0, 0.0, 0.0], [0.1, 0.1]).min()))")


def _render(**env: str) -> subprocess.CompletedProcess:
    clean = {key: value for key, value in os.environ.items() if key not in ("MUJOCO_GL", "DISPLAY")}
    return subprocess.run([sys.executable, "-c", RENDER], capture_output=True, text=True, cwd=REPOSITORY,
                          env={**clean, "PYTHONPATH": str(REPOSITORY), **env})


def test_rendering_without_mujoco_gl_chooses_egl():
    result = _render()
    assert result.returncode == 0, result.stderr[-2000:]
    backend, nearest = result.stdout.split()
    assert backend == "egl" and 0 < float(nearest) < 2


def test_no_working_backend_is_one_line_naming_each():
    result = _render(PYOPENGL_PLATFORM="none")  # every backend refuses this OpenGL platform
    assert result.returncode != 0
    last = result.stderr.strip().splitlines()[-1]
    assert last.startswith("RuntimeError: no OpenGL backend for MuJoCo's offscreen rendering works")
    assert all(f"MUJOCO_GL={backend}" in last for backend in ("egl", "osmesa", "glfw"))
