"""Depth rendering throughput of pushjax.render.renderer.DepthRenderer on one CPU core.

Each frame sets a new random object pose and pusher position (as dataset generation does), updates the
kinematics and renders a depth image through EGL. Prints a markdown table.

    MUJOCO_GL=egl python benchmarks/render.py [--frames 2000] [--sizes 64 128] [--core 0]

The process is pinned to one core and Mesa's llvmpipe software rasteriser is limited to one thread
(LP_NUM_THREADS=1) unless the variable is already set; on a GPU EGL driver only the pinning matters.
"""

import argparse
import functools
import os
import time

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("LP_NUM_THREADS", "1")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from pushjax.render.camera import free_camera, top_down_camera  # noqa: E402
from pushjax.render.renderer import DepthRenderer  # noqa: E402

# The scene of the naming convention in pushjax.render.renderer with the MIT push dataset's rect1 object.
SCENE_XML = """
<mujoco>
  <worldbody>
    <light pos="0 0 2"/>
    <geom name="table" type="box" size="0.5 0.5 0.02" pos="0 0 -0.02"/>
    <camera name="camera" pos="0 0 1"/>
    <body name="object" pos="0 0 0.00635">
      <freejoint name="object_joint"/>
      <geom type="box" size="0.045 0.045 0.00635"/>
    </body>
    <body name="pusher" mocap="true">
      <geom type="cylinder" size="0.00476 0.05" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>"""


def frames_per_second(renderer: DepthRenderer, frames: int, seed: int, point_cloud: bool) -> float:
    rng = np.random.default_rng(seed)
    poses = np.column_stack([rng.uniform(-0.05, 0.05, (frames, 2)), rng.uniform(-np.pi, np.pi, frames)])
    pushers = rng.uniform(-0.1, 0.1, (frames, 2))
    render = functools.partial(renderer.point_cloud, frame="world") if point_cloud else renderer.depth
    for i in range(min(20, frames)):  # warm up: GL state, JIT compilation
        render(poses[i], pushers[i])
    start = time.perf_counter()
    for pose, pusher in zip(poses, pushers):
        render(pose, pusher)
    return frames / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=2000, help="frames timed per configuration")
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 128], help="square image sizes [pixels]")
    parser.add_argument("--core", type=int, default=0, help="CPU core to pin the process to (-1: no pinning)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    if args.core >= 0:
        os.sched_setaffinity(0, {args.core})

    model = mujoco.MjModel.from_xml_string(SCENE_XML)
    print(f"LP_NUM_THREADS={os.environ.get('LP_NUM_THREADS')}, cores={sorted(os.sched_getaffinity(0))}, "
          f"frames={args.frames}\n")
    print("| camera | image | depth [frames/s] | depth [ms/frame] | world point cloud [frames/s] |")
    print("|---|---|---|---|---|")
    for size in args.sizes:
        for name, make_camera in (("top-down", top_down_camera), ("free", free_camera)):
            with DepthRenderer(model, make_camera(size, size)) as renderer:
                depth_fps = frames_per_second(renderer, args.frames, args.seed, point_cloud=False)
                cloud_fps = frames_per_second(renderer, args.frames, args.seed, point_cloud=True)
            print(f"| {name} | {size}x{size} | {depth_fps:.0f} | {1e3 / depth_fps:.2f} | {cloud_fps:.0f} |")


if __name__ == "__main__":
    main()
