"""MuJoCo testbed standing in for the MIT Push Dataset: scenes, simulated pushes, effects, recording.

``scene`` builds the MJCF scenes, ``push`` simulates and records single pushes along the MIT protocol of
:mod:`pushjax.mit.protocol`, ``dataset`` records whole data sets in parallel (``experiments/record_pushes.py``)
in the file layout of :mod:`pushjax.mit.files`, ``effects`` declares the physical and sensor effects and
``surfaces`` the friction data. ``pushjax.sim.quasi_static`` (which imports JAX) compares slow pushes with the
quasi-static model.
"""

from pushjax.sim import dataset, effects, push, scene, surfaces
from pushjax.sim.dataset import plan_pushes, record_pushes
from pushjax.sim.effects import Effects
from pushjax.sim.push import Recording, Simulator, simulate_push
from pushjax.sim.scene import build_model, scene_xml, write_scene
from pushjax.sim.surfaces import SURFACE_NAMES, get_surface

__all__ = [
    "Effects",
    "Recording",
    "SURFACE_NAMES",
    "Simulator",
    "build_model",
    "dataset",
    "effects",
    "get_surface",
    "plan_pushes",
    "push",
    "record_pushes",
    "scene",
    "scene_xml",
    "simulate_push",
    "surfaces",
    "write_scene",
]
