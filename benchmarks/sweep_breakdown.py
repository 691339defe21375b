"""Where a training step's time goes, and what vmapping K models over it can gain on this machine.

For each part of the model (object locator, glimpse encoder, prediction head) at the chosen scale:
the time of one gradient step of K models run one after another (K calls of the single-model jit),
vmapped over the model axis, and unrolled in one jit; plus the number of cores a single-model step
keeps busy (process CPU time / wall time). Then, for the locator's first convolution (1 input channel
at full resolution, its most expensive layer), three ways to run K models' per-model kernels:
one convolution per model, vmap (a grouped convolution) and one dense convolution with a
block-diagonal kernel (K times the arithmetic).

    python benchmarks/sweep_breakdown.py [--scale=smoke] [--models=4] [--repeats=30]
"""

import os
import platform
import time

import jax
import jax.numpy as jnp
from absl import app, flags

from pushjax.data import configs as data_configs
from pushjax.models import MLP, perception
from pushjax.train.configs import get_config

_SCALE = flags.DEFINE_enum("scale", "smoke", data_configs.SCALES, "Model config scale.")
_MODELS = flags.DEFINE_integer("models", 4, "K, the number of models.", lower_bound=2)
_REPEATS = flags.DEFINE_integer("repeats", 30, "Timed calls per measurement.", lower_bound=1)
_IMAGE_SIZE = flags.DEFINE_integer("image_size", 64, "Image side [pixels].")


def _timed(fn, *args):
    """(ms per call, cores busy) of a jitted function, after one warm-up call."""
    jax.block_until_ready(fn(*args))
    cpu_start, wall_start = os.times(), time.perf_counter()
    for _ in range(_REPEATS.value):
        out = fn(*args)
    jax.block_until_ready(out)
    wall = time.perf_counter() - wall_start
    cpu_end = os.times()
    busy = (cpu_end.user - cpu_start.user + cpu_end.system - cpu_start.system) / wall
    return 1000 * wall / _REPEATS.value, busy


def _part_row(name, module, inputs, **kwargs):
    """Timings of a gradient step of `module` for K models; inputs [K, B, ...]."""
    count = inputs.shape[0]
    variables = jax.vmap(lambda key: module.init(key, inputs[0], **kwargs))(
        jax.random.split(jax.random.key(0), count))

    def loss(variables, x):
        out = module.apply(variables, x, mutable=["batch_stats"], **kwargs)[0] if "batch_stats" in variables \
            else module.apply(variables, x, **kwargs)
        return jnp.mean(out ** 2)

    single = jax.jit(jax.grad(loss))
    vmapped = jax.jit(jax.vmap(jax.grad(loss)))
    unrolled = jax.jit(lambda v, x: [jax.grad(loss)(jax.tree.map(lambda leaf: leaf[k], v), x[k])
                                     for k in range(count)])
    first = jax.tree.map(lambda leaf: leaf[0], variables)
    single_ms, busy = _timed(single, first, inputs[0])
    vmap_ms, _ = _timed(vmapped, variables, inputs)
    unroll_ms, _ = _timed(unrolled, variables, inputs)
    sequential_ms = count * single_ms
    print(f"| {name} | {sequential_ms:.1f} | {vmap_ms:.1f} ({sequential_ms / vmap_ms:.2f}x) | "
          f"{unroll_ms:.1f} ({sequential_ms / unroll_ms:.2f}x) | {busy:.2f} |")


def _first_conv_rows(images, features):
    """K models' first locator convolution: per model, vmapped (grouped) and block-diagonal."""
    count, batch, height, width, channels = images.shape
    kernels = jax.random.normal(jax.random.key(1), (count, 3, 3, channels, features))

    def conv(x, w):
        return jax.lax.conv_general_dilated(x, w, (1, 1), "SAME", dimension_numbers=("NHWC", "HWIO", "NHWC"))

    def block_diagonal(x, w):
        stacked = jnp.moveaxis(x, 0, -2).reshape(batch, height, width, count * channels)
        kernel = jnp.einsum("kijcf,kl->ijkclf", w, jnp.eye(count)).reshape(3, 3, count * channels, count * features)
        out = conv(stacked, kernel).reshape(batch, height, width, count, features)
        return jnp.moveaxis(out, 3, 0)

    def gradient(fn):
        return jax.jit(jax.grad(lambda w, x: jnp.mean(fn(x, w) ** 2)))

    per_model = gradient(lambda x, w: jnp.stack([conv(x[k], w[k]) for k in range(count)]))
    for name, fn in (("one convolution per model", per_model), ("vmap (grouped convolution)",
                     gradient(jax.vmap(conv))), ("block-diagonal dense kernel", gradient(block_diagonal))):
        ms, busy = _timed(fn, kernels, images)
        print(f"| {name} | {ms:.1f} | {busy:.2f} |")


def main(argv):
    del argv
    config = get_config(data_configs.get_config("data_efficiency", _SCALE.value))
    model, batch = config.model, config.batch_size
    count, size = _MODELS.value, _IMAGE_SIZE.value
    images = jax.random.normal(jax.random.key(2), (count, batch, size, size, 1))
    glimpses = jax.random.normal(jax.random.key(3), (count, batch, model.glimpse_size, model.glimpse_size, 1))
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, jax {jax.__version__}; scale "
          f"{_SCALE.value}, K = {count} models, batch {batch}, {size}x{size} images, "
          f"{model.glimpse_size}x{model.glimpse_size} glimpses")
    print("\n| part (gradient step) | K sequential ms | vmap ms | unroll ms | cores busy, one model |")
    print("|---|---:|---:|---:|---:|")
    _part_row("object locator", perception.ObjectLocator(
        model.locator_conv_features, model.locator_deconv_features, model.locator_kernel), images)
    _part_row("glimpse encoder", perception.GlimpseEncoder(model.glimpse_features, model.glimpse_kernel),
              glimpses, train=True)
    head_inputs = jax.random.normal(jax.random.key(4), (count, batch, 64))
    _part_row("prediction head", MLP((*model.head_features, 5)), head_inputs)
    print(f"\n| first locator conv, K models (1 -> {model.locator_conv_features[0]} channels) | ms | cores busy |")
    print("|---|---:|---:|")
    _first_conv_rows(images, model.locator_conv_features[0])


if __name__ == "__main__":
    app.run(main)
