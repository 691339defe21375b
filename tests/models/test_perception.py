import flax.linen as nn
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from pushjax.models import perception
from pushjax.render import camera as camera_lib


def test_glimpse_is_the_patch_around_the_centre_and_edge_padded():
    image = jnp.arange(16 * 20, dtype=jnp.float32).reshape(1, 16, 20, 1)
    images = jnp.concatenate([image, image])
    centres = jnp.array([[6.0, 8.0], [0.2, 0.4]])  # (u, v) pixels
    glimpses = perception.extract_glimpses(images, centres, 4)
    assert glimpses.shape == (2, 4, 4, 1)
    np.testing.assert_array_equal(glimpses[0, ..., 0], image[0, 6:10, 4:8, 0])
    padded = np.pad(np.asarray(image[0, ..., 0]), 2, mode="edge")
    np.testing.assert_array_equal(glimpses[1, ..., 0], padded[0:4, 0:4])


def test_glimpse_size_must_be_positive():
    with pytest.raises(ValueError, match="size"):
        perception.extract_glimpses(jnp.zeros((1, 8, 8, 1)), jnp.zeros((1, 2)), 0)


def test_spatial_softmax_of_a_peak_is_its_pixel_centre():
    logits = jnp.zeros((1, 8, 16)).at[0, 3, 5].set(100.0)
    np.testing.assert_allclose(perception.spatial_softmax(logits), [[5.5, 3.5]], atol=1e-4)
    uniform = perception.spatial_softmax(jnp.zeros((1, 8, 16)))
    np.testing.assert_allclose(uniform, [[8.0, 4.0]], atol=1e-5)


def test_object_locator_maps_to_input_resolution_and_checks_size():
    locator = perception.ObjectLocator((4, 4, 4, 4), (4, 4))
    images = jax.random.normal(jax.random.key(0), (2, 16, 24, 1))
    variables = locator.init(jax.random.key(1), images)
    pixels = locator.apply(variables, images)
    assert pixels.shape == (2, 2)
    assert np.all((pixels >= 0) & (pixels <= jnp.array([24, 16])))
    with pytest.raises(ValueError, match="divisible by 8"):
        locator.init(jax.random.key(1), jnp.zeros((1, 12, 16, 1)))


def test_glimpse_encoder_shape_and_batch_stats():
    encoder = perception.GlimpseEncoder((4, 4, 2), 3)
    glimpses = jax.random.normal(jax.random.key(0), (3, 12, 12, 1))
    variables = encoder.init(jax.random.key(1), glimpses, train=False)
    assert set(variables) == {"params", "batch_stats"}
    encoding, updates = encoder.apply(variables, glimpses, train=True, mutable=["batch_stats"])
    assert encoding.shape == (3, 2 * 2 * 2)  # 12 -> 6 -> 3 -> 2 with SAME pooling
    assert not np.allclose(updates["batch_stats"]["BatchNorm_0"]["mean"], 0)


def _batched(camera, count):
    intrinsics = jnp.tile(jnp.array([camera.fx, camera.fy, camera.cx, camera.cy])[None], (count, 1))
    extrinsics = jnp.tile(camera.world_from_camera[None], (count, 1, 1))
    return perception.cameras_from_batch(intrinsics, extrinsics, camera.width, camera.height)


def test_top_down_pixels_map_back_to_table_points():
    camera = camera_lib.top_down_camera(32, 32, center_xy=(0.01, -0.02))
    points = jnp.array([[0.03, -0.05, 0.0], [-0.1, 0.07, 0.0]])
    pixels, _ = camera_lib.project(points, camera)
    np.testing.assert_allclose(
        perception.table_points_top_down(pixels, _batched(camera, 2)), points[:, :2], atol=1e-6
    )


def test_free_view_unprojection_recovers_the_point_cloud():
    camera = camera_lib.free_camera(32, 32)
    depth = jnp.full((32, 32), 0.45) + 0.01 * jnp.sin(jnp.arange(32))[None]
    cloud = camera_lib.point_cloud_from_depth(depth, camera, frame="world")[None]
    cameras = _batched(camera, 1)
    recovered_depth = perception.depth_from_point_cloud(cloud, cameras)
    np.testing.assert_allclose(recovered_depth[0], depth, atol=1e-5)
    pixels = jnp.array([[[10.5, 20.5], [3.5, 7.5]]])
    points = perception.unproject_with_depth(pixels, recovered_depth, cameras)
    np.testing.assert_allclose(points[0], cloud[0, [20, 7], [10, 3]], atol=1e-5)


@pytest.mark.parametrize("kernel_size", [2, 3, 4, 5])
@pytest.mark.parametrize("strides", [(1, 1), (2, 2), (3, 2)])
def test_conv_transpose_matches_flax_in_value_and_gradient(kernel_size, strides):
    inputs = jax.random.normal(jax.random.key(0), (2, 7, 5, 3))
    reference = nn.ConvTranspose(4, (kernel_size, kernel_size), strides=strides)
    ours = perception.ConvTranspose(4, (kernel_size, kernel_size), strides=strides)
    variables = jax.jit(reference.init)(jax.random.key(1), inputs)

    def shapes(tree):
        return jax.tree.map(lambda leaf: leaf.shape, tree)

    assert shapes(jax.eval_shape(ours.init, jax.random.key(1), inputs)) == shapes(variables)

    def outputs_and_gradients(module):
        # Jitted: a case compiles one program per module instead of each of its operations, forward and backward.
        return jax.jit(lambda v, x: (module.apply(v, x), jax.grad(
            lambda v, x: jnp.sum(jnp.sin(module.apply(v, x))), argnums=(0, 1))(v, x)))(variables, inputs)

    (ours_outputs, ours_gradients), (reference_outputs, reference_gradients) = (
        outputs_and_gradients(ours), outputs_and_gradients(reference))
    np.testing.assert_allclose(ours_outputs, reference_outputs, atol=1e-5)
    for ours_leaf, reference_leaf in zip(jax.tree.leaves(ours_gradients), jax.tree.leaves(reference_gradients)):
        np.testing.assert_allclose(ours_leaf, reference_leaf, atol=1e-4, rtol=1e-5)
