"""MuJoCo testbed standing in for the MIT Push Dataset: scenes, simulated pushes, effects, recording.

``scene`` builds the scenes (``mujoco.MjSpec``), ``push`` simulates and records single pushes along the MIT protocol of
:mod:`pushjax.mit.protocol`, ``dataset`` records whole data sets in parallel (``experiments/record_pushes.py``)
in the file layout of :mod:`pushjax.mit.files`, ``effects`` declares the physical and sensor effects and
``surfaces`` the friction data and ``testbed`` the testbed profiles (``ideal``, ``realistic``: the physics that the
quasi-static model leaves out, drawn per surface, object and push). ``pushjax.sim.quasi_static`` (which imports JAX) compares slow pushes with the
quasi-static model.
"""

from pushjax.sim import dataset, effects, push, scene, surfaces, testbed
from pushjax.sim.dataset import RecordingConfig, plan_pushes, record_pushes
from pushjax.sim.effects import Effects
from pushjax.sim.push import Recording, Simulator, simulate_push
from pushjax.sim.scene import build_model, scene_xml, write_scene
from pushjax.sim.surfaces import SURFACE_NAMES, get_surface
from pushjax.sim.testbed import IDEAL, REALISTIC, Testbed

__all__ = [
    "Effects",
    "IDEAL",
    "REALISTIC",
    "Recording",
    "RecordingConfig",
    "SURFACE_NAMES",
    "Simulator",
    "Testbed",
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
    "testbed",
    "write_scene",
]
