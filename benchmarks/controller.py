"""Speed of the push-to-goal controller (``pushjax.control.mpc.replan``): plans per second on CPU.

One plan is one ``replan`` call with the default ``ControllerConfig`` (horizon 12, 32 candidate contacts × 5
directions × 4 push lengths scored, the planner's own iterations: gradient 30 Adam steps through the rollout,
sampling 4 × 64 cross-entropy samples), from rect1-like states: the object at the origin, the pusher touching its
-x side, a goal 10 cm away turned by 45°. Prints a markdown table of the first (compiling) call and the median
(best) of ``--repeats`` calls.

    python benchmarks/controller.py [--objects=rect1,ellip2,butter] [--planners=gradient,sampling] [--repeats=20]
        [--effects=limit_surface,table_tilt] [--searches=full,local]

``--effects`` plans with Lynch's model and those effects at their "no effect" values (``limit_surface``: the exact
limit surface of the uniform support, a Newton solve per step instead of Lynch's closed form).

``--searches=full,local`` plans, in one sitting, with the rollout's former contact search (``full``: every outline
feature every step, the outline unpadded, a program per vertex count) and the current one (``local``: around the
tracked contact, the outline padded to 256 vertices, one program for every object); ``replan`` compiles once per
search (it takes the model as an argument), so a later object's first call shows whether it compiled again.
"""

import dataclasses
import platform

import jax
import jax.numpy as jnp
from absl import app, flags

from pushjax.control import model, mpc
from pushjax.geometry import outline_jax
from pushjax.geometry.objects import PUSHER_RADIUS, get_object
from timing import time_calls

_OBJECTS = flags.DEFINE_list("objects", ["rect1", "ellip2", "butter"], "Objects to measure.")
_PLANNERS = flags.DEFINE_list("planners", list(mpc.PLANNERS), "Planners to measure.")
_REPEATS = flags.DEFINE_integer("repeats", 20, "Timed calls per measurement.")
_EFFECTS = flags.DEFINE_list("effects", [], "Effects composed with Lynch's model (pushjax.physics.effects).")
_SEARCHES = flags.DEFINE_list("searches", ["local"], "The rollout's contact searches: full (former) and/or local.")


def main(argv):
    del argv
    print(f"{platform.processor() or platform.machine()}, {jax.devices()[0].platform}, jax {jax.__version__}; "
          f"default ControllerConfig, float32, effects {_EFFECTS.value or 'none'}, median (best) of {_REPEATS.value}\n")
    print("| object | search | planner | first call (s) | time per plan (ms) | plans/s |")
    print("|---|---|---|---:|---:|---:|")
    for name in _OBJECTS.value:
        left = float(get_object(name).outline[:, 0].min())
        pusher = jnp.array([left - PUSHER_RADIUS - 1e-3, 0.0])
        goal = jnp.array([0.1, 0.0, 0.785])
        for search in _SEARCHES.value:
            push_model = model.make_model(name, effects=_EFFECTS.value)
            if search != "local":
                push_model = dataclasses.replace(push_model, shape=outline_jax.outline(name, pad_to=None), search=search)
            for planner in _PLANNERS.value:
                config = mpc.ControllerConfig(planner=planner)
                state = mpc.init(config, jax.random.key(0))
                first, median, best = time_calls(
                    lambda config=config, push_model=push_model, state=state: mpc.replan(
                        config, push_model, state, jnp.zeros(3), pusher, goal), _REPEATS.value)
                print(f"| {name} | {search} | {planner} | {first:.1f} | {1e3 * median:.1f} ({1e3 * best:.1f}) | "
                      f"{1 / median:.1f} ({1 / best:.1f}) |", flush=True)


if __name__ == "__main__":
    app.run(main)
