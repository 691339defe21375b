"""A trained model's perception as a position sensor of the filters (issue 31): the object's centre of mass that the
model locates in the testbed scene's depth image.

    sensor = perception.load("results/track_perception/model", data_configs.get_config("data_efficiency", "cpu"))
    positions = sensor.locate("rect1", poses, pushers)    # [N, 2] centre of mass, world, m

The scene is rendered as the model's dataset renders its examples (:func:`pushjax.data.examples.make_renderer`: the
testbed scene of the object on its surface seen by the dataset's camera at its image size, the object at its pose,
the pusher at its position), and the model's perception locates the object
(:attr:`pushjax.train.predictor.Prediction.object_pos`). That output comes from the image alone (the object
locator); the pusher's motion and the physical parameters a :class:`~pushjax.train.predictor.Predictor` also takes
do not enter it (zeros and the object's nominal values are passed). Give the dataset the model was trained on: its
camera and image size are not stored with the model, and a model sees only what its camera saw in training.

Readings along pushes (:func:`readings`) are taken at every ``every``-th step of the filter clock, from the first,
NaN between (rendering and the network cost more than a filter step); :func:`estimate_noise` gives the readings'
noise from other pushes than the evaluated ones, :func:`stream` both as the filters' second observation stream
(:class:`pushjax.filter.observations.PositionStream`, :class:`pushjax.filter.models.PositionSensor`).

The controller closed on the testbed (``pushjax.studies.episode``, issue 32) can take its state from the same sensor:
:meth:`PerceptionSensor.locate` on the scene at the controller's period, and
:func:`pushjax.filter.models.update_position` after the EKF's pose update there.

Units: SI (m, rad).
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Sequence

import numpy as np

from pushjax import planar
from pushjax.data.configs import DatasetConfig, get_config
from pushjax.data.examples import make_renderer
from pushjax.filter.observations import PositionStream, TrackedPush
from pushjax.geometry.objects import get_object, limit_surface_ratio
from pushjax.render.renderer import DepthRenderer
from pushjax.train.predictor import Predictor, load_model

__all__ = ["BATCH", "PerceptionSensor", "estimate_noise", "load", "load_data_efficiency", "readings", "stream"]

BATCH = 32
"""The most images per call of the network; a shorter batch is padded to the next power of two, so the network
compiles at most six times and a single reading runs the network on one image."""


@dataclasses.dataclass
class PerceptionSensor:
    """A trained model's perception on the testbed scenes of a dataset's camera.

    Attributes:
      predictor: the trained model (:func:`pushjax.train.predictor.load_model`).
      dataset: the dataset it was trained on: its camera and image size render the scenes.
      surface: the table surface of the rendered scenes (the tracked pushes': ``abs``).
    """

    predictor: Predictor
    dataset: DatasetConfig
    surface: str = "abs"
    _renderers: dict[str, DepthRenderer] = dataclasses.field(default_factory=dict, repr=False)

    @property
    def description(self) -> str:
        """The model's checkpoint, name, variant and step, and the camera, in words."""
        folder, step = self.predictor.checkpoint
        return (f"{self.predictor.variant} {self.predictor.name} ({folder}, step {step}), "
                f"{self.dataset.image_size} x {self.dataset.image_size} px {self.dataset.camera} depth")

    def renderer(self, obj: str) -> DepthRenderer:
        """The depth renderer of `obj`'s scene (made once per object)."""
        if obj not in self._renderers:
            self._renderers[obj] = make_renderer(self.dataset, obj, self.surface)
        return self._renderers[obj]

    def locate(self, obj: str, poses, pushers) -> np.ndarray:
        """[N, 2] the centre of mass of `obj` the perception locates (world, m) in the scenes of `poses` [N, 3]
        (tracked frame: x m, y m, yaw rad) with the pusher at `pushers` [N, 2] (m)."""
        poses, pushers = np.asarray(poses, np.float64), np.asarray(pushers, np.float64)
        if poses.ndim != 2 or poses.shape[1] != 3 or pushers.shape != (len(poses), 2):
            raise ValueError(f"poses, pushers: expected [N, 3] and [N, 2], got {list(poses.shape)}, "
                             f"{list(pushers.shape)}")
        renderer = self.renderer(obj)
        shape = get_object(obj)
        l, mu = limit_surface_ratio(shape), 0.25
        located = []
        for start in range(0, len(poses), BATCH):
            pose, pusher = poses[start:start + BATCH], pushers[start:start + BATCH]
            depth = np.stack([renderer.depth(p, q) for p, q in zip(pose, pusher)])
            pad = (1 << (len(depth) - 1).bit_length()) - len(depth)
            depth = np.concatenate([depth, np.repeat(depth[-1:], pad, axis=0)])
            pusher = np.concatenate([pusher, np.repeat(pusher[-1:], pad, axis=0)])
            prediction = self.predictor(depth, pusher, np.zeros(2), renderer.camera, l, mu)
            located.append(np.asarray(prediction.object_pos, np.float64)[:len(depth) - pad])
        return np.concatenate(located) if located else np.zeros((0, 2))


def load(path: str | os.PathLike, dataset: DatasetConfig, model: int | str = -1, surface: str = "abs"
         ) -> PerceptionSensor:
    """The :class:`PerceptionSensor` of the trained model at `path` (a run's or sweep's work directory or a checkpoint
    folder; `model` as in :func:`pushjax.train.predictor.load_model`, whose ValueError names what is wrong), trained
    on `dataset`. Reads only."""
    return PerceptionSensor(load_model(path, model=model), dataset, surface)


def load_data_efficiency(path: str | os.PathLike, scale: str) -> PerceptionSensor:
    """:func:`load` of a model trained on the ``data_efficiency`` dataset at `scale` (``pushjax.data.configs.SCALES``),
    as the binaries' ``--perception`` and ``--perception_scale`` name it; a ValueError names what is wrong."""
    return load(path, get_config("data_efficiency", scale))


def readings(sensor: PerceptionSensor, pushes: Sequence[TrackedPush], every: int) -> dict[str, np.ndarray]:
    """{push name: [T + 1, 2]} the sensor's readings of each push's true scene (its simulated pose, not the motion
    capture's) at every `every`-th step of its filter clock from the first (world, m), NaN rows between."""
    if every < 1:
        raise ValueError(f"every: expected a whole number of filter steps >= 1, got {every}")
    result = {}
    for push in pushes:
        rows = np.arange(0, len(push.truth), every)
        positions = np.full((len(push.truth), 2), np.nan)
        positions[rows] = sensor.locate(push.obj, push.truth[rows], push.pusher[rows])
        result[push.name] = positions
    return result


def estimate_noise(sensor: PerceptionSensor, pushes: Sequence[TrackedPush], every: int) -> dict:
    """The readings' noise on `pushes` (which must not be the evaluated ones), against their true centres of mass.

    Returns:
      {"std": [2] the root mean square error per axis (world x, y; m), bias included (the filter has no bias term),
      "bias": [2] the mean error (m), "rmse": [] the root mean square distance (m), "readings": how many,
      "pushes": how many}.
    """
    errors = []
    for push in pushes:
        found = readings(sensor, [push], every)[push.name]
        rows = np.isfinite(found[:, 0])
        errors.append(found[rows] - planar.centre_of_mass(get_object(push.obj).centroid, push.truth[rows]))
    errors = np.concatenate(errors)
    if len(errors) < 2:
        raise ValueError(f"pushes: expected readings of at least 2 scenes to estimate the noise, got {len(errors)}")
    return {"std": np.sqrt(np.mean(errors ** 2, axis=0)).tolist(), "bias": np.mean(errors, axis=0).tolist(),
            "rmse": float(np.sqrt(np.mean(np.sum(errors ** 2, axis=-1)))), "readings": len(errors),
            "pushes": len(pushes)}


def stream(sensor: PerceptionSensor, pushes: Sequence[TrackedPush], noise_pushes: Sequence[TrackedPush],
           every: int, rate_hz: float, noise_seed: int | None = None) -> PositionStream:
    """The sensor's readings of the evaluated `pushes` with the noise estimated on `noise_pushes` (other pushes,
    e.g. simulated with another seed, `noise_seed`), as the filters' second observation stream; the filter clock runs
    at `rate_hz`, the sensor at `rate_hz / every`."""
    if any(np.array_equal(held_out.truth, evaluated.truth) for held_out in noise_pushes for evaluated in pushes):
        raise ValueError("noise_pushes: the noise must be estimated on other pushes than the evaluated ones")
    start = time.perf_counter()
    noise = estimate_noise(sensor, noise_pushes, every)
    positions = readings(sensor, pushes, every)
    seconds = time.perf_counter() - start
    seed = "" if noise_seed is None else f" simulated with seed {noise_seed}"
    count = noise["readings"] + sum(int(np.isfinite(found[:, 0]).sum()) for found in positions.values())
    details = {"model": sensor.description, "rate_hz": rate_hz / every, "every_steps": every,
               "seconds_with_compile": seconds, "scenes": count,
               "noise_bias": noise["bias"], "noise_rmse": noise["rmse"], "noise_readings": noise["readings"],
               "noise_estimated_on": (f"the RMS error per axis of {noise['readings']} readings of {noise['pushes']} "
                                      f"other pushes{seed} (bias included: "
                                      f"{', '.join(f'{1e3 * b:+.2f}' for b in noise['bias'])} mm)")}
    return PositionStream(positions=positions,
                          std=tuple(max(value, 1e-5) for value in noise["std"]), details=details)
