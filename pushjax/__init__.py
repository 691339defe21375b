"""pushjax: predicting the effect of pushes from depth images with learned perception and the
differentiable Lynch quasi-static pushing model."""

import os

# MuJoCo picks its OpenGL backend once, at its first import anywhere in the process; headless EGL
# is the only one that works on servers without a display.
os.environ.setdefault("MUJOCO_GL", "egl")

__version__ = "0.1.0"
