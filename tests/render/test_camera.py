"""Tests for pushjax.render.camera: conventions, round trips, gradients, vmap and input validation."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from pushjax.render import camera as cam


def random_world_points(seed, n=200):
    """Points [n, 3] on and above the table patch that both default cameras look at [m]."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-0.12, 0.12, size=(n, 2))
    z = rng.uniform(0.0, 0.15, size=(n, 1))
    return jnp.asarray(np.concatenate([xy, z], axis=1), dtype=jnp.float32)


CAMERAS = {
    "top_down": cam.top_down_camera(64, 48, center_xy=(0.02, -0.01)),
    "free": cam.free_camera(80, 64),
}


def test_intrinsics_from_fov_matches_mujoco_model():
    fx, fy, cx, cy = cam.intrinsics_from_fov(60.0, 80, 64)
    assert float(fy) == pytest.approx(32 / math.tan(math.radians(30)), rel=1e-6)
    assert float(fx) == float(fy)
    assert (float(cx), float(cy)) == (40.0, 32.0)


def test_look_at_is_a_proper_rotation_pointing_at_the_target():
    eye, target = jnp.array([0.3, -0.25, 0.4]), jnp.array([0.05, 0.02, 0.0])
    world_from_camera = cam.look_at(eye, target)
    rotation = world_from_camera[:3, :3]
    np.testing.assert_allclose(rotation.T @ rotation, np.eye(3), atol=1e-6)
    assert float(jnp.linalg.det(rotation)) == pytest.approx(1.0, abs=1e-6)
    np.testing.assert_allclose(world_from_camera[3], [0, 0, 0, 1])
    np.testing.assert_allclose(world_from_camera[:3, 3], eye)
    viewing_direction = -rotation[:, 2]
    np.testing.assert_allclose(viewing_direction, (target - eye) / jnp.linalg.norm(target - eye), atol=1e-6)
    assert abs(float(rotation[2, 0])) < 1e-6, "image x axis must be horizontal"
    assert float(rotation[2, 1]) > 0, "image up must point up in the world"


def test_top_down_camera_orientation_and_scale():
    camera = cam.top_down_camera(64, 64, height_m=0.5, center_xy=(0.1, 0.2))
    pixels, depth = cam.project(jnp.array([[0.1, 0.2, 0.0], [0.11, 0.2, 0.0], [0.1, 0.21, 0.0]]), camera)
    np.testing.assert_allclose(pixels[0], [32.0, 32.0], atol=1e-4)
    np.testing.assert_allclose(depth, 0.5, atol=1e-6)
    assert pixels[1, 0] > pixels[0, 0], "world +x must be image right"
    assert pixels[2, 1] < pixels[0, 1], "world +y must be image up"
    scale = cam.pixels_per_metre_at_table(camera)
    np.testing.assert_allclose(pixels[1, 0] - pixels[0, 0], 0.01 * scale, rtol=1e-5)
    np.testing.assert_allclose(cam.field_of_view_deg(camera), 45.0, rtol=1e-6)


def test_default_top_down_view_holds_an_object_and_a_push():
    camera = cam.top_down_camera()
    half = 0.09 + 0.05 + 0.01  # half of the largest object, a 5 cm push, the pusher
    corners = jnp.array([[sx * half, sy * half, 0.0] for sx in (-1, 1) for sy in (-1, 1)])
    pixels, _ = cam.project(corners, camera)
    assert bool(jnp.all((pixels > 0) & (pixels < 64)))
    # RESULTS.md's "5.2 mm per pixel" of the 64 x 64 images.
    assert 1000 / float(cam.pixels_per_metre_at_table(camera)) == pytest.approx(5.2, abs=0.05)


def test_free_camera_sits_at_the_papers_pose_and_sees_the_table_centre():
    camera = cam.free_camera(64, 64)
    np.testing.assert_allclose(camera.position, [0.0, -0.25, 0.4], atol=1e-7)
    pixels, depth = cam.project(jnp.zeros(3), camera)
    np.testing.assert_allclose(pixels, [32.0, 32.0], atol=1e-4)
    np.testing.assert_allclose(depth, math.hypot(0.25, 0.4), rtol=1e-6)


@pytest.mark.parametrize("name", sorted(CAMERAS))
def test_unproject_inverts_project(name):
    camera = CAMERAS[name]
    points = random_world_points(0)
    pixels, depth = cam.project(points, camera)
    assert bool(jnp.all(depth > 0))
    np.testing.assert_allclose(cam.unproject(pixels, depth, camera), points, atol=1e-6)


@pytest.mark.parametrize("name", sorted(CAMERAS))
def test_project_inverts_unproject(name):
    camera = CAMERAS[name]
    rng = np.random.default_rng(1)
    pixels = jnp.asarray(rng.uniform(0, [camera.width, camera.height], size=(300, 2)), jnp.float32)
    depth = jnp.asarray(rng.uniform(0.1, 1.0, size=300), jnp.float32)
    projected, projected_depth = cam.project(cam.unproject(pixels, depth, camera), camera)
    np.testing.assert_allclose(projected, pixels, atol=1e-3)
    np.testing.assert_allclose(projected_depth, depth, rtol=1e-5)


def test_point_cloud_of_a_flat_table_lies_on_the_table():
    camera = cam.top_down_camera(32, 24, height_m=0.4)
    depth = jnp.full((24, 32), 0.4)
    world = cam.point_cloud_from_depth(depth, camera, frame="world")
    assert world.shape == (24, 32, 3)
    np.testing.assert_allclose(world[..., 2], 0.0, atol=1e-6)
    pixels, _ = cam.project(world, camera)
    np.testing.assert_allclose(pixels, cam.pixel_centres(32, 24), atol=1e-4)
    local = cam.point_cloud_from_depth(depth, camera)
    np.testing.assert_allclose(local[..., 2], -0.4)
    assert float(local[0, 0, 0]) < 0 < float(local[0, 0, 1]), "row 0 is the top, column 0 the left"


def test_bilinear_lookup_interpolates_clamps_and_keeps_channels():
    image = jnp.arange(12.0).reshape(3, 4)
    pixels = jnp.array([[0.5, 0.5], [3.5, 2.5], [1.0, 0.5], [1.0, 1.0], [-5.0, -5.0], [9.0, 1.5]])
    np.testing.assert_allclose(
        cam.bilinear_lookup(image, pixels), [0.0, 11.0, 0.5, 2.5, 0.0, 7.0], atol=1e-6
    )
    coloured = jnp.stack([image, -image], axis=-1)
    values = cam.bilinear_lookup(coloured, pixels.reshape(2, 3, 2))
    assert values.shape == (2, 3, 2)
    np.testing.assert_allclose(values[..., 1], -values[..., 0])


def test_bilinear_lookup_of_a_linear_image_is_exact_with_exact_gradients():
    u, v = jnp.meshgrid(jnp.arange(8) + 0.5, jnp.arange(6) + 0.5, indexing="xy")
    image = 2.0 * u - 3.0 * v
    pixels = jnp.array([[1.3, 2.9], [6.2, 0.7], [4.5, 5.4]])
    np.testing.assert_allclose(cam.bilinear_lookup(image, pixels), 2.0 * pixels[:, 0] - 3.0 * pixels[:, 1], atol=1e-5)
    gradient = jax.grad(lambda p: cam.bilinear_lookup(image, p).sum())(pixels)
    np.testing.assert_allclose(gradient, jnp.tile(jnp.array([2.0, -3.0]), (3, 1)), atol=1e-4)
    image_gradient = jax.grad(lambda im: cam.bilinear_lookup(im, pixels).sum())(image)
    np.testing.assert_allclose(image_gradient.sum(), 3.0, atol=1e-5)


def test_gradients_are_finite():
    camera = CAMERAS["free"]
    points = random_world_points(2, n=20)

    def loss(points, camera):
        pixels, depth = cam.project(points, camera)
        back = cam.unproject(pixels, depth, camera)
        return jnp.sum(pixels**2) + jnp.sum(depth) + jnp.sum(back)

    point_grad, camera_grad = jax.grad(loss, argnums=(0, 1))(points, camera)
    for leaf in jax.tree_util.tree_leaves((point_grad, camera_grad)):
        assert bool(jnp.all(jnp.isfinite(leaf)))
    assert float(jnp.abs(camera_grad.fx)) > 0
    eye_grad = jax.grad(lambda eye: cam.project(points, cam.Camera.create(
        fx=camera.fx, fy=camera.fy, cx=camera.cx, cy=camera.cy, width=camera.width, height=camera.height,
        world_from_camera=cam.look_at(eye, jnp.zeros(3))))[0].sum())(jnp.array([0.0, -0.25, 0.4]))
    assert bool(jnp.all(jnp.isfinite(eye_grad))) and float(jnp.abs(eye_grad).sum()) > 0


def test_vmap_over_cameras_and_jit():
    eyes = jnp.array([[0.0, -0.25, 0.4], [0.2, -0.2, 0.3], [-0.1, 0.3, 0.5]])
    make = jax.vmap(lambda eye: cam.free_camera(32, 32, eye=eye))
    cameras = make(eyes)
    assert cameras.world_from_camera.shape == (3, 4, 4)
    points = random_world_points(3, n=10)
    pixels, depth = jax.jit(jax.vmap(cam.project, in_axes=(None, 0)))(points, cameras)
    assert pixels.shape == (3, 10, 2) and depth.shape == (3, 10)
    for i in range(3):
        single_pixels, _ = cam.project(points, cam.free_camera(32, 32, eye=eyes[i]))
        np.testing.assert_allclose(pixels[i], single_pixels, atol=1e-4)
    clouds = jax.vmap(cam.point_cloud_from_depth, in_axes=(0, 0, None))(jnp.ones((3, 32, 32)), cameras, "world")
    assert clouds.shape == (3, 32, 32, 3)


@pytest.mark.parametrize(
    "build, name",
    [
        (lambda: cam.intrinsics_from_fov(45.0, 0, 64), "width"),
        (lambda: cam.intrinsics_from_fov(45.0, 64, 6.5), "height"),
        (lambda: cam.intrinsics_from_fov(190.0, 64, 64), "fovy_deg"),
        (lambda: cam.look_at((0.0, 0.0), (0.0, 0.0, 0.0)), "eye"),
        (lambda: cam.look_at((0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1.0)), "target"),
        (lambda: cam.look_at((0.0, 0.0, 1.0), (0.0, 0.0, 0.0)), "up"),
        (lambda: cam.top_down_camera(center_xy=(0.0, 0.0, 0.0)), "center_xy"),
        (lambda: cam.top_down_camera(height_m=-0.1), "height_m"),
        (lambda: cam.Camera.create(fx=50.0, fy=50.0, cx=32.0, cy=32.0, width=64, height=64,
                                   world_from_camera=jnp.eye(3)), "world_from_camera"),
        (lambda: cam.Camera.create(fx=jnp.ones(2), fy=50.0, cx=32.0, cy=32.0, width=64, height=64,
                                   world_from_camera=jnp.eye(4)), "fx"),
        (lambda: cam.project(jnp.zeros((5, 2)), CAMERAS["free"]), "world_points"),
        (lambda: cam.unproject(jnp.zeros((5, 3)), jnp.ones(5), CAMERAS["free"]), "pixels"),
        (lambda: cam.point_cloud_from_depth(jnp.ones((64, 64)), CAMERAS["free"]), "depth"),
        (lambda: cam.point_cloud_from_depth(jnp.ones((64, 80)), CAMERAS["free"], frame="table"), "frame"),
        (lambda: cam.bilinear_lookup(jnp.ones(4), jnp.zeros(2)), "image"),
    ],
)
def test_bad_inputs_raise_value_error_naming_the_argument(build, name):
    with pytest.raises(ValueError, match=name):
        build()
