"""Cameras of the pushing scene (pure JAX, :mod:`~pushjax.render.camera`); this package exports only them.

The offscreen MuJoCo depth / point-cloud renderer is imported explicitly, so that camera maths never loads
MuJoCo: ``from pushjax.render.renderer import DepthRenderer`` (it chooses the OpenGL backend when the first
renderer is made).
"""

from pushjax.render.camera import (
    Camera,
    bilinear_lookup,
    camera_to_world,
    field_of_view_deg,
    free_camera,
    intrinsics_from_fov,
    look_at,
    pixel_centres,
    pixels_per_metre_at_table,
    point_cloud_from_depth,
    project,
    top_down_camera,
    unproject,
    unproject_to_camera,
    world_to_camera,
)

__all__ = [
    "Camera",
    "bilinear_lookup",
    "camera_to_world",
    "field_of_view_deg",
    "free_camera",
    "intrinsics_from_fov",
    "look_at",
    "pixel_centres",
    "pixels_per_metre_at_table",
    "point_cloud_from_depth",
    "project",
    "top_down_camera",
    "unproject",
    "unproject_to_camera",
    "world_to_camera",
]
