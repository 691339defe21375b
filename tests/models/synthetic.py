"""Physically consistent synthetic batches for model tests: a disc pushed by a point pusher.

The depth image of a top-down camera shows a disc (the object) and a smaller, taller disc (the
pusher) on the table; the motion is Lynch's model for the drawn contact, so every variant can learn it.
"""

from __future__ import annotations

import numpy as np

from pushjax.data import schema
from pushjax.physics import lynch
from pushjax.render import camera as camera_lib

IMAGE_SIZE = 32
OBJECT_RADIUS_M = 0.04
PUSHER_RADIUS_M = 0.008


def synthetic_examples(
    count: int, seed: int, image_size: int = IMAGE_SIZE, view: str = "top_down"
) -> dict[str, np.ndarray]:
    """`count` examples with every `schema.FIELDS` key, float32 / int32 as the schema says.

    ``view="free"`` sees the scene with the oblique `free_camera` and fills `point_cloud` (the table
    points under each pixel, raised by the object's or pusher's height inside their discs).
    """
    rng = np.random.default_rng(seed)
    if view == "top_down":
        camera = camera_lib.top_down_camera(image_size, image_size, height_m=0.4)
    else:
        camera = camera_lib.free_camera(image_size, image_size)
    object_pos = rng.uniform(-0.04, 0.04, (count, 2))
    angle = rng.uniform(0, 2 * np.pi, count)
    outward = np.stack([np.cos(angle), np.sin(angle)], -1)
    contact = OBJECT_RADIUS_M * outward
    normal = -outward
    pusher_pos = object_pos + (OBJECT_RADIUS_M + PUSHER_RADIUS_M) * outward
    push_angle = rng.uniform(-0.6, 0.6, count)
    rotation = np.stack([np.cos(push_angle), -np.sin(push_angle), np.sin(push_angle), np.cos(push_angle)], -1)
    action = 0.01 * np.einsum("bij,bj->bi", rotation.reshape(-1, 2, 2), normal)
    l = np.full(count, 0.03)
    mu = np.full(count, 0.3)
    contact_flag = rng.uniform(size=count) < 0.9
    twist = np.asarray(lynch.predict(contact, normal, action, l, mu, contact_flag.astype(float)))
    push_velocity, _ = lynch.effective_push_velocity(contact, normal, action, l, mu)

    # Table points under the pixel centres: unproject at unit depth, scale the ray to z = 0.
    unit = np.asarray(camera_lib.unproject(camera_lib.pixel_centres(image_size, image_size), 1.0, camera))
    eye = np.asarray(camera.position)
    table = eye + (unit - eye) * (eye[2] / (eye[2] - unit[..., 2]))[..., None]
    centres = table[..., :2]
    height = np.zeros((count, image_size, image_size))
    on_object = np.linalg.norm(centres[None] - object_pos[:, None, None], axis=-1) < OBJECT_RADIUS_M
    on_pusher = np.linalg.norm(centres[None] - pusher_pos[:, None, None], axis=-1) < 2 * PUSHER_RADIUS_M
    height[on_object] = 0.03
    height[on_pusher] = 0.07
    depth = 0.4 - height
    point_cloud = np.broadcast_to(table, (count,) + table.shape).copy()
    point_cloud[..., 2] = height

    def pixels(points):
        return np.asarray(camera_lib.project(np.concatenate([points, np.zeros((count, 1))], -1), camera)[0])

    intrinsics = np.array([camera.fx, camera.fy, camera.cx, camera.cy])
    values = {
        "depth": depth[..., None],
        "point_cloud": point_cloud if view == "free" else np.zeros_like(point_cloud),
        "pusher_pos": pusher_pos,
        "pusher_pixel": pixels(pusher_pos),
        "action": action,
        "object_pos": object_pos,
        "object_pixel": pixels(object_pos),
        "motion": twist,
        "motion_pixel": twist[:, :2] * float(camera_lib.pixels_per_metre_at_table(camera)) * [1, -1],
        "contact": contact * contact_flag[:, None],
        "normal": normal * contact_flag[:, None],
        "contact_flag": contact_flag,
        "action_from_contact": action * contact_flag[:, None],
        "l": l,
        "mu": mu,
        "push_velocity": np.asarray(push_velocity) * contact_flag[:, None],
        "camera_intrinsics": np.broadcast_to(intrinsics, (count, 4)),
        "camera_extrinsics": np.broadcast_to(np.asarray(camera.world_from_camera), (count, 4, 4)),
        "scene_transform": np.broadcast_to(np.eye(3), (count, 3, 3)),
    }
    examples = {}
    for name, field in schema.FIELDS.items():
        value = values.get(name, np.zeros((count,) + tuple(d for d in field.shape if isinstance(d, int))))
        examples[name] = np.ascontiguousarray(value, dtype=field.dtype)
    return examples
