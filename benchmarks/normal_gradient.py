"""Which training examples give the predicted surface normal a gradient, at the start and the end of training.

For the hybrid and error variants (top-down view) the normal enters the loss only through Lynch's model, and
there only while the predicted push slips: sticking transmits the pusher's motion whatever the normal, and a
predicted normal that faces away from the push (``action . normal <= 0``) gives no motion at all. This script
trains (or resumes) the same sweep as ``experiments.train`` and, for every model at its initialisation and
after training, sorts the training examples with contact by the contact mode of the predicted contact and normal
(not pushing / sticking / slipping) and counts those whose normal gets exactly zero gradient from the training
loss, through Lynch's model alone and with the straight-through push gate the hybrid heads train with
(`lynch.with_push_gate_gradient`); it also gives the normal's error [deg] per mode and the modes of the
ground-truth pushes. A second table asks how far the normal that the motion loss prefers lies from the annotated
one: per training example with contact, Lynch's model on the true contact point and the action from first contact
with the normal turned by every offset in +-60 deg (0.5 deg steps), and the offset of least trans [mm] + rot [deg]
error; shown for the pushes that slip (in sticking pushes the loss does not depend on the normal).

    python benchmarks/normal_gradient.py --scale=smoke --workdir=DIR [--variant=hybrid] [--sizes=N] \
        [--seeds=0,1,2] [--num_steps=N] [--testbed=realistic]

``--workdir`` takes the same folder as ``experiments.train``: a sweep trained there with the same flags is
reused from its checkpoints, otherwise it is trained (and checkpointed) there. The gradient is taken as in
training: batch statistics of batches of the training batch size, the model's loss (`losses.loss_for`).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
from absl import app, flags

from pushjax.models import ERROR_OPTIONS, PHYSICS_VARIANTS, PushModel
from pushjax.paper import runner
from pushjax.paper import spec as spec_lib
from pushjax.physics import lynch
from pushjax.sim import testbed
from pushjax.train import losses
from pushjax.train import train_state as train_state_lib
from pushjax.train.batching import examples_from_source, model_fields

_SCALE = flags.DEFINE_enum("scale", "smoke", ["smoke", "cpu", "paper"], "Dataset and training scale.")
_WORKDIR = flags.DEFINE_string("workdir", None, "Work directory of the sweep (as experiments.train's).", required=True)
_VARIANT = flags.DEFINE_enum("variant", "hybrid", [v for v in PHYSICS_VARIANTS if v != "simple"], "Model variant.")
_SIZES = flags.DEFINE_list("sizes", [], "Training-set sizes (default: the whole training split).")
_SEEDS = flags.DEFINE_list("seeds", ["0"], "Subset and initialisation seeds.")
_NUM_STEPS = flags.DEFINE_integer("num_steps", None, "Training steps (default: the scale's).")
_TESTBED = flags.DEFINE_enum("testbed", testbed.DEFAULT_PROFILE, list(testbed.PROFILES), "Testbed profile.")

NORMAL_OFFSETS_DEG = np.arange(-60, 60.25, 0.5)
"""Turns of the annotated normal searched for the one the motion loss prefers [deg]."""

MODES = ("not pushing", "sticking", "slipping")
"""Contact modes of Lynch's stage 1, in the order of `contact_modes`' codes."""


def contact_modes(contact: np.ndarray, normal: np.ndarray, action: np.ndarray, l: np.ndarray,
                  mu: np.ndarray) -> np.ndarray:
    """[N] int index into `MODES` of N pushes ([N, 2] contact [m], normal, action [m]; [N] l [m], mu)."""
    push_velocity, sticking = lynch.effective_push_velocity(contact, normal, action, l, mu)
    pushing = np.linalg.norm(np.asarray(push_velocity), axis=-1) > 0
    return np.where(np.asarray(sticking), 1, np.where(pushing, 2, 0))


def _angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    cosine = np.sum(a * b, -1) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
    return np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))


def normal_gradients(model: PushModel, state, batch, error_options, weight_decay: float):
    """Predicted contact [B, 2] and normal [B, 2], and the training loss's gradients [2, B, 2] w.r.t. that normal.

    The model runs as in a training step (batch statistics); the normal is then fed to the physics again with
    every other output held fixed, so the gradient is the one the normal output receives in training: first
    through Lynch's model alone (its exact derivative), then with `lynch.with_push_gate_gradient` as the hybrid
    heads train it.
    """
    predictions = model.apply({"params": state.params, "batch_stats": state.batch_stats}, batch, train=True,
                              error_options=error_options, mutable=["batch_stats"])[0]
    loss_fn = losses.loss_for(model.config.variant, model.config.view)
    contact, action, l, mu, s = predictions["contact"], batch["action"], batch["l"], batch["mu"], predictions["s"]
    physics_motion = lynch.predict(contact, predictions["normal"], action, l, mu, s)
    rest = jax.lax.stop_gradient(predictions["motion"] - physics_motion)  # the error term, if any

    def loss_of_normal(normal, push_gate_gradient):
        motion = lynch.predict(contact, normal, action, l, mu, s)
        if push_gate_gradient:
            motion = lynch.with_push_gate_gradient(motion, contact, normal, action, l, mu, s)
        return loss_fn({**predictions, "motion": rest + motion}, batch, state.params, weight_decay)[0]

    gradients = [jax.grad(loss_of_normal)(predictions["normal"], gated) for gated in (False, True)]
    return contact, predictions["normal"], jnp.stack(gradients)


def measure(model: PushModel, state, examples, indices: np.ndarray, batch_size: int, error_options) -> dict:
    """Per-mode shares of the contact examples among `indices`, their zero-gradient share and normal error."""
    fields = model_fields(model.config)
    step = jax.jit(normal_gradients, static_argnums=(0, 4))
    contacts, normals, gradients = [], [], []
    for start in range(0, len(indices) - batch_size + 1, batch_size):
        batch = {name: jnp.asarray(examples[name][indices[start:start + batch_size]]) for name in fields}
        contact, normal, gradient = step(model, state, batch, error_options, 0.0)
        contacts.append(np.asarray(contact))
        normals.append(np.asarray(normal))
        gradients.append(np.asarray(gradient))
    contact, normal, gradient = (np.concatenate(parts, axis=-2) for parts in (contacts, normals, gradients))
    used = indices[: len(contact)]
    touching = (np.asarray(examples["contact_flag"])[used] > 0.5) & (np.linalg.norm(normal, axis=-1) > 0)
    contact, normal, gradient, used = contact[touching], normal[touching], gradient[:, touching], used[touching]
    true_contact, true_normal, action, l, mu = (
        np.asarray(examples[name])[used] for name in ("contact", "normal", "action", "l", "mu")
    )
    predicted_mode = contact_modes(contact, normal, action, l, mu)
    true_mode = contact_modes(true_contact, true_normal, action, l, mu)
    zero_exact, zero_gated = np.all(gradient == 0, axis=-1)
    error = _angle_deg(normal, true_normal)
    row = {"contacts": len(used), "zero_exact": zero_exact.mean(), "zero_gated": zero_gated.mean(),
           "normal_deg": error.mean()}
    for code, name in enumerate(MODES):
        selected = predicted_mode == code
        row[name] = selected.mean()
        row[f"{name} deg"] = error[selected].mean() if selected.any() else float("nan")
        row[f"true {name}"] = (true_mode == code).mean()
    return row


def loss_optimal_normal_offsets(examples) -> tuple[np.ndarray, np.ndarray]:
    """[N] angle [deg] between the annotated normal and the one of least motion error, and [N] whether it slips.

    N: the examples with contact. Lynch's model runs on the true contact point, the action from first contact
    (``action_from_contact``, as the ``physics`` baseline) and the normal turned by each of `NORMAL_OFFSETS_DEG`.
    """
    touching = np.asarray(examples["contact_flag"]) > 0.5
    contact, normal, action, l, mu, motion = (
        np.asarray(examples[name])[touching]
        for name in ("contact", "normal", "action_from_contact", "l", "mu", "motion")
    )
    angle = np.arctan2(normal[:, 1], normal[:, 0])

    @jax.jit
    def motion_error(offset):
        turned = jnp.stack([jnp.cos(angle + offset), jnp.sin(angle + offset)], axis=-1)
        predicted = lynch.predict(contact, turned, action, l, mu)
        return (jnp.linalg.norm(predicted[:, :2] - motion[:, :2], axis=-1) * 1e3
                + jnp.degrees(jnp.abs(predicted[:, 2] - motion[:, 2])))

    errors = np.stack([np.asarray(motion_error(offset)) for offset in np.radians(NORMAL_OFFSETS_DEG)])
    push_velocity, sticking = lynch.effective_push_velocity(contact, normal, action, l, mu)
    slipping = (np.linalg.norm(np.asarray(push_velocity), axis=-1) > 0) & ~np.asarray(sticking)
    return np.abs(NORMAL_OFFSETS_DEG[np.argmin(errors, axis=0)]), slipping


def main(argv):
    del argv
    setup = spec_lib.Setup("train", "data_efficiency", (_VARIANT.value,))
    spec = spec_lib.make_spec(setup, _SCALE.value, sizes=_SIZES.value, seeds=_SEEDS.value,
                              num_steps=_NUM_STEPS.value, testbed=_TESTBED.value)
    source = runner.load_splits(spec, spec.dataset, progress=False)["train"]
    examples = examples_from_source(source, tuple(dict.fromkeys((*spec.example_fields(), "action_from_contact"))))
    result = runner.train_sweep(spec, (_VARIANT.value,), examples, f"{_WORKDIR.value}/train/l1/{_VARIANT.value}")
    train = spec.train_config(_VARIANT.value)
    error_options = (jnp.asarray(ERROR_OPTIONS[_VARIANT.value], jnp.float32) if _VARIANT.value in ERROR_OPTIONS
                     else None)
    optimizer = train_state_lib.make_optimizer(train.learning_rate)
    rows = []
    for index, model_spec in enumerate(result.specs):
        first_batch = {name: examples[name][model_spec.train_indices[: train.batch_size]]
                       for name in model_fields(train.model)}
        initial = train_state_lib.create_train_state(result.model, optimizer, first_batch, model_spec.seed)
        for when, state in (("start", initial), (f"step {int(result.steps_trained[index])}",
                                                 result.model_state(index))):
            rows.append((model_spec.name, when, measure(result.model, state, examples, model_spec.train_indices,
                                                        train.batch_size, error_options)))
    print(f"{_VARIANT.value}, data_efficiency {_SCALE.value} ({_TESTBED.value}): training examples with contact and "
          "a non-zero predicted normal. Zero gradient: share whose normal gets none from the loss, through Lynch's "
          "model alone / with the push-gate surrogate. Per mode of the predicted contact and normal: share / "
          "normal error [deg]. Last columns: modes of the true contact and normal.\n")
    print("| model | when | contacts | zero gradient exact / gated | " + " | ".join(MODES)
          + " | normal error [deg] | true: " + " / ".join(MODES) + " |")
    print("|---|---|---:|---:|" + "---:|" * len(MODES) + "---:|---:|")
    for name, when, row in rows:
        modes = " | ".join(f"{row[mode]:.0%} / {row[f'{mode} deg']:.1f}" for mode in MODES)
        true_modes = " / ".join(f"{row[f'true {mode}']:.0%}" for mode in MODES)
        print(f"| {name} | {when} | {row['contacts']} | {row['zero_exact']:.0%} / {row['zero_gated']:.0%} | {modes} | "
              f"{row['normal_deg']:.1f} | {true_modes} |")
    offsets, slipping = loss_optimal_normal_offsets(examples)
    print(f"\nNormal the motion loss prefers, on the {slipping.size} training examples with contact "
          f"({slipping.mean():.0%} slip): its angle from the annotated normal [deg] over the slipping ones\n")
    print("| mean | median | 90th percentile | within 2 deg |")
    print("|---:|---:|---:|---:|")
    slip_offsets = offsets[slipping]
    print(f"| {slip_offsets.mean():.1f} | {np.median(slip_offsets):.1f} | {np.percentile(slip_offsets, 90):.1f} | "
          f"{np.mean(slip_offsets <= 2):.0%} |")


if __name__ == "__main__":
    app.run(main)
