"""Tests for pushjax.render.renderer: MuJoCo depth images agree with the JAX camera model to 1 mm / 1 px."""

import os
import subprocess
import sys
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

import jax  # noqa: E402
import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from pushjax.render import camera as cam  # noqa: E402
from pushjax.render import renderer as rnd  # noqa: E402

HALF_X, HALF_Y, THICKNESS = 0.045, 0.056, 0.0127  # rect2 of the MIT push dataset [m]
PUSHER_RADIUS, PUSHER_HALF_LENGTH = 0.00476, 0.05
SCENE_XML = f"""
<mujoco>
  <worldbody>
    <light pos="0 0 2"/>
    <geom name="table" type="box" size="0.5 0.5 0.02" pos="0 0 -0.02" rgba="0.5 0.5 0.5 1"/>
    <camera name="camera" pos="0 0 1"/>
    <body name="object" pos="0 0 {THICKNESS / 2}">
      <freejoint name="object_joint"/>
      <geom type="box" size="{HALF_X} {HALF_Y} {THICKNESS / 2}" rgba="0.9 0.1 0.1 1"/>
    </body>
    <body name="pusher" mocap="true">
      <geom type="cylinder" size="{PUSHER_RADIUS} {PUSHER_HALF_LENGTH}" rgba="0.1 0.1 0.9 1"
            contype="0" conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>"""
OBJECT_POSE = np.array([0.04, -0.03, 0.6])
PUSHER_OUT_OF_VIEW = np.array([0.45, 0.45])


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_string(SCENE_XML)


@pytest.fixture(scope="module")
def top_down(model):
    with rnd.DepthRenderer(model, cam.top_down_camera(64, 64)) as renderer:
        yield renderer


@pytest.fixture(scope="module")
def free(model):
    with rnd.DepthRenderer(model, cam.free_camera(96, 72)) as renderer:
        yield renderer


def first_hits(camera, pose, pixels):
    """Analytic first intersection [..., 3] of the rays through `pixels` with the box object or the table,
    and whether it is the object [...]."""
    origin = np.asarray(camera.position, np.float64)
    direction = np.asarray(cam.unproject(pixels, np.ones(pixels.shape[:-1]), camera), np.float64) - origin
    x, y, yaw = pose
    rotation = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
    local_origin = rotation.T @ (origin - [x, y, 0])
    local_direction = direction @ rotation
    low, high = np.array([-HALF_X, -HALF_Y, 0.0]), np.array([HALF_X, HALF_Y, THICKNESS])
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (low - local_origin) / local_direction, (high - local_origin) / local_direction
    t_enter = np.minimum(t0, t1).max(axis=-1)
    t_exit = np.maximum(t0, t1).min(axis=-1)
    on_object = (t_enter <= t_exit) & (t_enter > 0)
    t_table = -origin[2] / direction[..., 2]
    t = np.where(on_object, t_enter, t_table)
    return origin + t[..., None] * direction, on_object


def check_point_cloud_against_ray_casting(renderer, pose):
    camera = renderer.camera
    world = renderer.point_cloud(pose, PUSHER_OUT_OF_VIEW, frame="world")
    centres = np.asarray(cam.pixel_centres(camera.width, camera.height))
    expected, on_object = first_hits(camera, pose, centres)
    # Rays within 0.05 px of an edge may hit either surface; compare only pixels whose neighbourhood agrees.
    unambiguous = np.ones(on_object.shape, bool)
    for offset in ((0.05, 0), (-0.05, 0), (0, 0.05), (0, -0.05)):
        unambiguous &= first_hits(camera, pose, centres + np.array(offset))[1] == on_object
    assert unambiguous.mean() > 0.9
    assert (on_object & unambiguous).sum() > 40, "object should cover many pixels"
    error = np.linalg.norm(world - expected, axis=-1)[unambiguous]
    assert error.max() < 1e-3, f"largest point cloud error {error.max() * 1e3:.2f} mm"
    top_face = unambiguous & on_object & (np.abs(expected[..., 2] - THICKNESS) < 1e-9)
    np.testing.assert_allclose(world[top_face][:, 2], THICKNESS, atol=1e-3)
    np.testing.assert_allclose(world[unambiguous & ~on_object][:, 2], 0.0, atol=1e-3)


def test_top_down_depth_at_table_centre_is_camera_height(top_down):
    depth = top_down.depth((0.12, 0.1, 0.0), PUSHER_OUT_OF_VIEW)
    assert depth.shape == (64, 64) and depth.dtype == np.float32
    np.testing.assert_allclose(depth[31:33, 31:33], 0.4, atol=1e-3)
    np.testing.assert_allclose(cam.bilinear_lookup(depth, np.array([32.0, 32.0])), 0.4, atol=1e-3)


def test_top_down_point_cloud_matches_ray_casting(top_down):
    check_point_cloud_against_ray_casting(top_down, OBJECT_POSE)


def test_free_camera_point_cloud_matches_ray_casting(free):
    check_point_cloud_against_ray_casting(free, OBJECT_POSE)


def test_object_centre_lands_at_projected_pixel_top_down(top_down):
    camera = top_down.camera
    depth = top_down.depth(OBJECT_POSE, PUSHER_OUT_OF_VIEW)
    top_face = np.abs(depth - (0.4 - THICKNESS)) < 1e-3
    rows, columns = np.nonzero(top_face)
    centroid = np.array([columns.mean() + 0.5, rows.mean() + 0.5])
    predicted, predicted_depth = cam.project(np.array([*OBJECT_POSE[:2], THICKNESS]), camera)
    assert np.linalg.norm(centroid - predicted) < 1.0
    np.testing.assert_allclose(cam.bilinear_lookup(depth, predicted), predicted_depth, atol=1e-3)


def test_free_camera_renders_the_object_where_project_says(free):
    camera = free.camera
    depth = free.depth(OBJECT_POSE, PUSHER_OUT_OF_VIEW)
    x, y, yaw = OBJECT_POSE
    offsets = np.array([[0, 0], [0.03, 0.0], [-0.03, 0.04], [0.0, -0.045]])
    rotation = np.array([[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]])
    top_points = np.concatenate([offsets @ rotation.T + [x, y], np.full((4, 1), THICKNESS)], axis=1)
    pixels, predicted_depth = cam.project(top_points, camera)
    np.testing.assert_allclose(cam.bilinear_lookup(depth, pixels), predicted_depth, atol=1e-3)
    empty = free.depth((0.3, 0.3, 0.0), PUSHER_OUT_OF_VIEW)
    assert np.all(cam.bilinear_lookup(empty, pixels) > np.asarray(predicted_depth) + 5e-3)


def test_pusher_stands_just_above_the_table(top_down):
    pusher_xy = np.array([-0.1, 0.08])
    depth = top_down.depth((0.3, 0.3, 0.0), pusher_xy)
    pusher_top = rnd.PUSHER_CLEARANCE_M + 2 * PUSHER_HALF_LENGTH
    (u, v), top_depth = cam.project(np.array([*pusher_xy, pusher_top]), top_down.camera)
    np.testing.assert_allclose(depth[int(v), int(u)], top_depth, atol=1e-3)
    np.testing.assert_allclose(top_depth, 0.4 - pusher_top, atol=1e-6)
    assert top_down.pusher_z == pytest.approx(rnd.PUSHER_CLEARANCE_M + PUSHER_HALF_LENGTH)
    assert top_down.object_rest_z == pytest.approx(THICKNESS / 2)


def test_object_pose_forms_agree(top_down, model):
    x, y, yaw = OBJECT_POSE
    free_joint = np.array([x, y, THICKNESS / 2, np.cos(yaw / 2), 0, 0, np.sin(yaw / 2)])
    full = model.qpos0.copy()
    full[:7] = free_joint
    planar = top_down.depth(OBJECT_POSE, PUSHER_OUT_OF_VIEW)
    np.testing.assert_array_equal(top_down.depth(free_joint, PUSHER_OUT_OF_VIEW), planar)
    np.testing.assert_array_equal(top_down.depth(full, PUSHER_OUT_OF_VIEW), planar)


def test_camera_point_cloud_and_rgb(top_down):
    local = top_down.point_cloud(OBJECT_POSE, PUSHER_OUT_OF_VIEW)
    depth = top_down.depth(OBJECT_POSE, PUSHER_OUT_OF_VIEW)
    assert local.shape == (64, 64, 3)
    np.testing.assert_allclose(-local[..., 2], depth, rtol=1e-6)
    rgb = top_down.rgb(OBJECT_POSE, PUSHER_OUT_OF_VIEW)
    assert rgb.shape == (64, 64, 3) and rgb.dtype == np.uint8
    pixel, _ = cam.project(np.array([*OBJECT_POSE[:2], THICKNESS]), top_down.camera)
    red, green, blue = rgb[int(pixel[1]), int(pixel[0])].astype(int)
    assert red > green + 50 and red > blue + 50, "the red object should be at its projected pixel"


def test_set_camera_writes_the_camera_pose(model):
    camera = cam.free_camera(64, 64, eye=(0.1, -0.3, 0.35), fovy_deg=50.0)
    scene = mujoco.MjModel.from_xml_string(SCENE_XML)
    rnd.set_camera(scene, camera)
    data = mujoco.MjData(scene)
    mujoco.mj_forward(scene, data)
    np.testing.assert_allclose(data.cam_xpos[0], camera.position, atol=1e-6)
    np.testing.assert_allclose(data.cam_xmat[0].reshape(3, 3), camera.rotation, atol=1e-6)
    assert scene.cam_fovy[0] == pytest.approx(50.0, rel=1e-5)
    assert model.cam_fovy[0] == 45.0, "DepthRenderer must not modify the caller's model"


@pytest.mark.parametrize(
    "changes, name",
    [({"fx": 40.0}, "fx == fy"), ({"cx": 30.0}, "principal point"), ({"cy": 33.0}, "principal point")],
)
def test_set_camera_rejects_unrepresentable_intrinsics(model, changes, name):
    camera = cam.top_down_camera(64, 64).replace(**{k: np.float32(v) for k, v in changes.items()})
    with pytest.raises(ValueError, match=name):
        rnd.set_camera(mujoco.MjModel.from_xml_string(SCENE_XML), camera)


def test_scene_convention_violations_raise(model):
    camera = cam.top_down_camera(32, 32)
    with pytest.raises(ValueError, match="'overhead'"):
        rnd.set_camera(mujoco.MjModel.from_xml_string(SCENE_XML), camera, camera_name="overhead")
    with pytest.raises(ValueError, match="'pusher'"):
        rnd.DepthRenderer(mujoco.MjModel.from_xml_string(SCENE_XML.replace('"pusher"', '"tool"')), camera)
    with pytest.raises(ValueError, match="mocap"):
        rnd.DepthRenderer(mujoco.MjModel.from_xml_string(SCENE_XML.replace('mocap="true"', "")), camera)


@pytest.mark.parametrize("egl_exit_hook_runs", ["first", "last"])
def test_renderers_left_open_exit_silently(egl_exit_hook_runs):
    """Renderers never closed (held to the end, in a reference cycle) free their context without a word at exit,
    whether MuJoCo's EGL display is terminated before or after they are freed."""
    script = f"""
import weakref
if {egl_exit_hook_runs == "last"!r}:
    weakref.finalize(int, int)  # registers weakref's exit hook first, so that it runs after EGL's
import mujoco
from pushjax.render import camera, renderer
model = mujoco.MjModel.from_xml_string({SCENE_XML!r})
held = renderer.DepthRenderer(model, camera.top_down_camera(32, 32))
held.depth([0.0, 0.0, 0.0], [0.1, 0.0])
in_a_cycle = renderer.DepthRenderer(model, camera.free_camera(32, 32))
in_a_cycle.itself = in_a_cycle
print(in_a_cycle.depth([0.0, 0.0, 0.0], [0.1, 0.0]).shape)
"""
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                            cwd=Path(__file__).resolve().parents[2], env={**os.environ, "MUJOCO_GL": "egl"})
    assert (result.returncode, result.stdout, result.stderr) == (0, "(32, 32)\n", "")


def test_close_twice_and_context_manager(model):
    renderer = rnd.DepthRenderer(model, cam.top_down_camera(32, 32))
    renderer.close()
    renderer.close()
    with rnd.DepthRenderer(model, cam.top_down_camera(32, 32)) as renderer:
        assert renderer.depth(OBJECT_POSE, PUSHER_OUT_OF_VIEW).shape == (32, 32)


def test_bad_state_raises(top_down):
    with pytest.raises(ValueError, match="object_pose"):
        top_down.depth(np.zeros(4), PUSHER_OUT_OF_VIEW)
    with pytest.raises(ValueError, match="pusher_xy"):
        top_down.depth(OBJECT_POSE, np.zeros(3))


def test_random_scene_transform_is_seeded_bounded_and_rigid():
    first = rnd.random_scene_transform(np.random.default_rng(7), 0.02, 0.3)
    second = rnd.random_scene_transform(np.random.default_rng(7), 0.02, 0.3)
    np.testing.assert_array_equal(first, second)
    assert isinstance(first, np.ndarray) and first.shape == (3, 3)
    assert np.all(np.abs(first[:2, 2]) <= 0.02) and abs(np.arctan2(first[1, 0], first[0, 0])) <= 0.3
    keyed = rnd.random_scene_transform(jax.random.key(7), 0.02, 0.3)
    np.testing.assert_array_equal(keyed, rnd.random_scene_transform(jax.random.key(7), 0.02, 0.3))
    np.testing.assert_allclose(keyed[:2, :2].T @ keyed[:2, :2], np.eye(2), atol=1e-6)
    with pytest.raises(ValueError, match="max_translation_m"):
        rnd.random_scene_transform(np.random.default_rng(0), -0.01, 0.3)


def test_apply_scene_transform_moves_object_and_pusher_together():
    transform = rnd.planar_transform(np.array([0.01, -0.02]), 0.4)
    pose, pusher = np.array([0.04, -0.03, 0.6]), np.array([-0.02, 0.05])
    new_pose, new_pusher = rnd.apply_scene_transform(transform, pose, pusher)
    np.testing.assert_allclose(new_pose[2], 1.0, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(new_pusher - new_pose[:2]), np.linalg.norm(pusher - pose[:2]), atol=1e-6)
    corner = np.array([HALF_X, HALF_Y])

    def corner_of(p):
        c, s = np.cos(p[2]), np.sin(p[2])
        return np.array([[c, -s], [s, c]]) @ corner + p[:2]

    np.testing.assert_allclose(corner_of(np.asarray(new_pose)), rnd.transform_planar_points(transform, corner_of(pose)),
                               atol=1e-6)
    batched_poses = rnd.transform_planar_poses(transform, np.tile(pose, (5, 2, 1)))
    assert batched_poses.shape == (5, 2, 3)
    with pytest.raises(ValueError, match="transform"):
        rnd.apply_scene_transform(np.eye(4), pose, pusher)


@pytest.mark.parametrize("shape", ["butter", "tri1"])
def test_mit_mesh_object_rests_on_the_table(shared_dir, shape):
    """MIT push meshes are y-up OBJ files in metres; a scene rotates them to a z-up body frame."""
    mesh_file = shared_dir / "data" / "mit_push_objects" / f"{shape}.obj"
    scene = SCENE_XML.replace("<worldbody>", f'<asset><mesh name="shape" file="{mesh_file}"/></asset><worldbody>')
    scene = scene.replace(f'<geom type="box" size="{HALF_X} {HALF_Y} {THICKNESS / 2}"',
                          '<geom type="mesh" mesh="shape" euler="90 0 0"')
    camera = cam.top_down_camera(64, 64)
    with rnd.DepthRenderer(mujoco.MjModel.from_xml_string(scene), camera) as renderer:
        assert renderer.object_rest_z == pytest.approx(THICKNESS / 2, abs=1e-4)
        world = renderer.point_cloud(OBJECT_POSE, PUSHER_OUT_OF_VIEW, frame="world")
    heights = world[..., 2].ravel()
    assert np.sum(np.abs(heights - THICKNESS) < 1e-3) > 40, "the top face should be visible at 12.7 mm"
    assert -1e-3 < heights.min() and heights.max() < THICKNESS + 1e-3
