"""Use a trained model: `load_model` turns a sweep's checkpoint into a `Predictor` of push effects.

    predictor = load_model("work/train")             # a run's or a sweep's work directory, or a checkpoint
    prediction = predictor(depth, pusher_pos, action, camera, l=0.0343, mu=0.25)
    prediction.motion                                # [3]: dx, dy [m], dyaw [rad]

A checkpoint holds the stacked parameters of a sweep's K models and, beside them, their `ModelConfig` and
variants (`pushjax.train.sweep_trainer.MODEL_CONFIG_KEY`), so the model is rebuilt without its dataset or training
config. A checkpoint written before pushjax stored the configuration cannot be loaded (the error names the missing
key). Nothing is written into the folder read.
"""

from __future__ import annotations

import dataclasses
import functools
import os
from collections.abc import Mapping
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from pushjax import logs
from pushjax.geometry import THICKNESS
from pushjax.models import ERROR_OPTIONS, ModelConfig, PushModel
from pushjax.render.camera import Camera, project
from pushjax.train.checkpoint import Checkpointer
from pushjax.train.batching import ModelSpec
from pushjax.train.sweep_trainer import MODEL_CONFIG_KEY, MODEL_VARIANTS_KEY, model_metadata
from pushjax.train.train_state import TrainState


@dataclasses.dataclass(frozen=True)
class Prediction:
    """What a model predicts for a batch of B pushes (NumPy arrays; without the batch axis for a single push).

    Attributes:
      motion: [B, 3] object motion over the push: centre-of-mass translation dx, dy (m, world) and yaw change (rad).
      object_pos: [B, 2] the object's centre of mass the perception located, world, m.
      contact: [B, 2] contact point relative to `object_pos`, world axes, m (variants with physics; else None).
      normal: [B, 2] unit inward surface normal at the contact, world (hybrid and error variants; else None).
      contact_probability: [B] the predicted contact indicator s in [0, 1] (hybrid and error variants; else None).
    """

    motion: np.ndarray
    object_pos: np.ndarray
    contact: np.ndarray | None = None
    normal: np.ndarray | None = None
    contact_probability: np.ndarray | None = None


@dataclasses.dataclass(frozen=True)
class Predictor:
    """One trained model, called on images and pushes (`__call__`).

    Attributes:
      model: the Flax module.
      variables: its ``params`` and ``batch_stats``.
      name: the model's label in its sweep (e.g. ``size=200/seed=0``).
      variant: its variant (`pushjax.models.VARIANTS`).
      checkpoint: the checkpoint folder it was read from, and its step.
    """

    model: PushModel
    variables: Mapping
    name: str
    variant: str
    checkpoint: tuple[Path, int]

    @property
    def config(self) -> ModelConfig:
        return self.model.config

    def __call__(self, image: jax.typing.ArrayLike, pusher_pos: jax.typing.ArrayLike, action: jax.typing.ArrayLike,
                 camera: Camera, l: jax.typing.ArrayLike, mu: jax.typing.ArrayLike) -> Prediction:
        """Predicts the effect of pushes on the scenes of `image`.

        Args:
          image: top-down view: [H, W] or [H, W, 1] depth [m]; free view: [H, W, 3] organised point cloud in world
            coordinates [m] (`pushjax.render.renderer.DepthRenderer`); a leading batch axis B for several pushes.
          pusher_pos: [2] or [B, 2] pusher centre at the push's start, world, m.
          action: [2] or [B, 2] pusher displacement over the push (0.5 s in the datasets), world, m.
          camera: the camera that took `image` (`pushjax.render.top_down_camera` / `free_camera`).
          l: [] or [B] the object's limit-surface ratio, m (`pushjax.geometry.limit_surface_ratio`).
          mu: [] or [B] pusher-object friction coefficient.

        Returns:
          the `Prediction`, batched like `pusher_pos`.
        """
        pusher_pos = np.asarray(pusher_pos, np.float32)
        single = pusher_pos.ndim == 1
        batch = _batch(self.config, image, pusher_pos, action, camera, l, mu, single)
        outputs = jax.tree.map(np.asarray, _apply(self.model, self.variables, batch, self._error_options()))
        if single:
            outputs = {name: value[0] for name, value in outputs.items()}
        normal = outputs.get("normal")
        if normal is not None:
            normal = normal / np.maximum(np.linalg.norm(normal, axis=-1, keepdims=True), 1e-12)
        return Prediction(motion=outputs["motion"], object_pos=outputs["object_pos"], contact=outputs.get("contact"),
                          normal=normal, contact_probability=outputs.get("s"))

    def _error_options(self) -> jax.Array | None:
        if self.variant not in ERROR_OPTIONS:
            return None
        return jnp.asarray(ERROR_OPTIONS[self.variant], jnp.float32)


def _batch(config: ModelConfig, image, pusher_pos: np.ndarray, action, camera: Camera, l, mu,
           single: bool) -> dict[str, np.ndarray]:
    """The model's input batch (`pushjax.data.schema` fields) of one push or a batch of them."""
    image = np.asarray(image, np.float32)
    channels = 1 if config.view == "top_down" else 3
    if config.view == "top_down" and image.shape[-2:] == (camera.height, camera.width):
        image = image[..., None]
    expected = (camera.height, camera.width, channels)
    if image.shape[-3:] != expected or image.ndim != 3 + (not single):
        raise ValueError(f"image: expected {'' if single else '[B] + '}{list(expected)} ({config.image_field}, the "
                         f"camera's image size), got {list(image.shape)}")
    if single:
        image, pusher_pos = image[None], pusher_pos[None]
    count = len(pusher_pos)
    if pusher_pos.shape != (count, 2):
        raise ValueError(f"pusher_pos: expected [2] or [B, 2] (m), got {list(pusher_pos.shape)}")
    action = np.broadcast_to(np.asarray(action, np.float32).reshape(-1, 2), (count, 2))
    on_top_face = np.concatenate([pusher_pos, np.full((count, 1), THICKNESS, np.float32)], axis=-1)
    pusher_pixel = np.asarray(project(on_top_face, camera)[0], np.float32)
    zeros = {name: np.zeros((count, 2), np.float32) for name in ("object_pos", "contact", "normal")}
    batch = {
        **zeros,
        "motion": np.zeros((count, 3), np.float32),
        "contact_flag": np.zeros(count, np.float32),
        config.image_field: np.broadcast_to(image, (count, *expected)),
        "pusher_pos": pusher_pos,
        "pusher_pixel": pusher_pixel,
        "action": action,
        "l": np.broadcast_to(np.asarray(l, np.float32), (count,)),
        "mu": np.broadcast_to(np.asarray(mu, np.float32), (count,)),
        "camera_intrinsics": np.broadcast_to(
            np.asarray([camera.fx, camera.fy, camera.cx, camera.cy], np.float32), (count, 4)),
        "camera_extrinsics": np.broadcast_to(np.asarray(camera.world_from_camera, np.float32), (count, 4, 4)),
    }
    return batch


@functools.partial(jax.jit, static_argnames="model")
def _apply(model: PushModel, variables, batch, error_options):
    return model.apply(variables, batch, train=False, error_options=error_options)


def _holds_steps(folder: Path) -> bool:
    """Whether `folder` is a checkpoint folder (orbax steps as numbered subfolders)."""
    return folder.is_dir() and any(child.name.isdigit() for child in folder.iterdir() if child.is_dir())


def find_checkpoints(path: str | os.PathLike) -> Path:
    """The checkpoint folder (orbax steps) at or under `path`: a sweep's work directory (``<path>/checkpoints``),
    the folder itself, or the one sweep under a run's work directory; raises ValueError naming the choices when there
    are several and when there is none."""
    path = Path(path)
    if not path.is_dir():
        raise ValueError(f"path: {path} is not a folder (a run's or a sweep's work directory, or its checkpoints)")
    if _holds_steps(path):
        return path
    found = sorted(folder for folder in path.rglob("checkpoints") if folder.is_dir())
    if len(found) != 1:
        choices = f"choose one of {', '.join(str(folder.parent) for folder in found)}" if found else "found none"
        raise ValueError(f"path: expected one sweep's checkpoints under {path}; {choices}")
    return found[0]


def checkpoint_variables(state: TrainState) -> dict:
    """The variables of one model that `save_model` writes: its parameters and, where it has them, batch statistics."""
    return {"params": state.params, **({"batch_stats": state.batch_stats} if state.batch_stats else {})}


def save_model(folder: str | os.PathLike, step: int, model_config: ModelConfig, spec: ModelSpec,
               state: TrainState) -> None:
    """Writes one trained model as a checkpoint that `load_model` reads: its parameters and batch statistics (a model
    axis of one, as in a sweep's checkpoint) at `step` in `folder`, with `model_metadata` beside them."""
    variables = checkpoint_variables(state)
    checkpointer = Checkpointer(folder)
    try:
        checkpointer.save(step, jax.tree.map(lambda leaf: np.asarray(leaf)[None], variables),
                          model_metadata(model_config, [spec]))
    finally:
        checkpointer.close()


def _one_line(error: BaseException, limit: int = 300) -> str:
    """``<type>: <message>`` of `error` on one line, without tensorstore's spec dump, at most `limit` characters."""
    text = " ".join(f"{type(error).__name__}: {error}".split(" [tensorstore_spec=")[0].split())
    return text if len(text) <= limit else text[:limit - 1] + "…"


def model_config_from_json(config: Mapping) -> ModelConfig:
    """The `ModelConfig` of ``dataclasses.asdict(config)`` read back from JSON (lists become tuples)."""
    fields = {field.name for field in dataclasses.fields(ModelConfig)}
    unknown = sorted(set(config) - fields)
    if unknown:
        raise ValueError(f"model_config: unknown fields {unknown}; expected those of ModelConfig")
    return ModelConfig(**{name: tuple(value) if isinstance(value, list) else value for name, value in config.items()})


def load_model(path: str | os.PathLike, model: int | str = 0, step: int | None = None) -> Predictor:
    """One trained model of a sweep's checkpoint, ready to predict.

    Args:
      path: a sweep's work directory, its ``checkpoints`` folder, or a run's work directory holding one sweep
        (`pushjax.paper.runner`; with several, the error lists them); or a work directory whose ``checkpoints`` folder
        holds one checkpoint folder per model (`pushjax.paper.full_run`, `save_model`).
      model: which of the sweep's models: its index (negative from the end: -1 is the largest size's last seed), or
        its name (e.g. ``"size=200/seed=0"``); with one folder per model, the folder's name (e.g.
        ``"hybrid_2500_seed0"``).
      step: the checkpoint's step; None: the newest.

    Raises:
      ValueError: naming what is missing or wrong (no checkpoint, no model configuration in an old checkpoint, an
        unknown model or step, the ``neural_dyn`` variant, which predicts from the true state and not from images).
    """
    logs.quiet_known_noise()  # orbax's 'Given directory is read only' on every read
    folder = find_checkpoints(path)
    per_model = sorted(child.name for child in folder.iterdir() if _holds_steps(child))
    if per_model and not _holds_steps(folder):
        if model not in per_model:
            raise ValueError(f"model: {folder} holds one checkpoint folder per model; expected one of {per_model}, got "
                             f"{model!r}")
        folder, model = folder / model, 0
    checkpointer = Checkpointer(folder, read_only=True)
    try:
        steps = checkpointer.all_steps()
        if not steps:
            raise ValueError(f"path: no checkpoint in {folder}")
        step = max(steps) if step is None else step
        if step not in steps:
            raise ValueError(f"step: {folder} has checkpoints at steps {sorted(steps)}, not {step}")
        try:
            state, metadata = checkpointer.restore_arrays(step)
        except Exception as error:  # orbax and tensorstore report a damaged file in many ways
            raise ValueError(f"path: the checkpoint {folder / str(step)} cannot be read, a file in it is damaged or "
                             f"missing ({_one_line(error)}); train the model again or restore the folder") from error
    finally:
        checkpointer.close()
    if not isinstance(metadata, Mapping) or not isinstance(state, Mapping) or "params" not in state:
        raise ValueError(f"path: the checkpoint {folder / str(step)} holds no model: expected parameters ('params') "
                         "and a metadata dictionary")
    missing = [key for key in (MODEL_CONFIG_KEY, MODEL_VARIANTS_KEY, "identity") if key not in metadata]
    if missing:
        raise ValueError(f"path: the checkpoint {folder / str(step)} has no {', '.join(missing)} in its metadata (it "
                         "was written before pushjax stored the model configuration beside the parameters); retrain "
                         "it, or resume its sweep for a step, to load it")
    names = metadata["identity"]["names"]
    index = names.index(model) if model in names else model
    if not isinstance(index, int) or not -len(names) <= index < len(names):
        raise ValueError(f"model: expected an index in [{-len(names)}, {len(names)}) or one of {names}, got {model!r}")
    index %= len(names)
    config = model_config_from_json(metadata[MODEL_CONFIG_KEY])
    if config.variant == "neural_dyn":
        raise ValueError("model: neural_dyn predicts from the true contact state, not from images; load another variant")
    variables = jax.tree.map(lambda leaf: jnp.asarray(leaf[index]),
                             {"params": state["params"], "batch_stats": state.get("batch_stats") or {}})
    return Predictor(PushModel(config), variables, names[index], metadata[MODEL_VARIANTS_KEY][index], (folder, step))
