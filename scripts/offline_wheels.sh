#!/usr/bin/env bash
# Wheels of pushjax's run-time packages for an x86-64 Python 3.12 machine without network that already has JAX (with
# its GPU plugin), NumPy, SciPy, h5py, matplotlib, tqdm, protobuf, etils and tensorstore -- e.g. a lent GPU machine
# running benchmarks/paper_full_gpu.sh. Downloads them into DIR (default .whl, gitignored) and strips what pushjax does
# not import (TFDS's dataset catalogue, MuJoCo's viewer, headers and docs, PyOpenGL's Windows DLLs), so that they and
# the working tree fit a 64 MiB transfer (about 21.6 MiB of wheels). On the machine:
#
#   python3 -m pip install -q --no-index --no-deps --target /tmp/site .whl/*.whl && export PYTHONPATH=/tmp/site:$PWD
#
#   bash scripts/offline_wheels.sh [DIR]
set -euo pipefail
dir=${1:-.whl}
mkdir -p "$dir"
platforms=()
for platform in manylinux_2_17_x86_64 manylinux2014_x86_64 manylinux_2_24_x86_64 manylinux_2_27_x86_64 \
  manylinux_2_28_x86_64 any; do platforms+=(--platform "$platform"); done
download() { python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
  "${platforms[@]}" -d "$dir" "$@"; }
# mujoco-studio (the viewer, 12 MiB) is left out: `import mujoco` does not need it.
download mujoco==4.0.0 mujoco-core==4.0.0 glfw==2.11.0 PyOpenGL==3.1.10 trimesh==5.2.0 shapely==2.2.0 \
  mapbox_earcut==2.1.0 tensorflow-datasets==4.9.10 array_record==0.8.6 dm-tree==0.1.10 immutabledict==4.3.1 \
  simple-parsing==0.1.9 docstring_parser==0.18.0 tensorflow-metadata==1.21.0 googleapis-common-protos==1.76.0 \
  termcolor==3.3.0 toml==0.10.2 tensorboardX==2.6.5 importlib_resources==7.1.0 flax==0.12.8 optax==0.2.8 \
  orbax-checkpoint==0.12.8
python3 -m pip wheel -q --no-deps -w "$dir" promise==2.3  # a source distribution only

python3 - "$dir" <<'EOF'
"""Rewrites wheels without the files under folder prefixes pushjax never imports (and their RECORD lines)."""
import sys
import zipfile
from pathlib import Path

CATALOGUE = ("audio", "graphs", "image", "image_classification", "object_detection", "nearest_neighbors",
             "question_answering", "d4rl", "ranking", "recommendation", "rl_unplugged", "robotics", "robomimic",
             "structured", "summarization", "text", "text_simplification", "time_series", "translate", "video",
             "vision_language", "datasets")
STRIP = {
    "tensorflow_datasets-": tuple(f"tensorflow_datasets/{name}/" for name in CATALOGUE),
    "mujoco_core-": ("mujoco/_simulate", "mujoco/_batch", "mujoco/doc/", "mujoco/include/", "mujoco/batch_test.py",
                     "mujoco/rollout_test.py", "mujoco/plugin/libsdf"),
    "pyopengl-": ("OpenGL/DLLS/",),
}
for path in sorted(Path(sys.argv[1]).glob("*.whl")):
    prefixes = next((value for key, value in STRIP.items() if path.name.startswith(key)), None)
    if prefixes is None:
        continue
    with zipfile.ZipFile(path) as source:
        items = [(info, source.read(info)) for info in source.infolist()]
    kept = [(info, data) for info, data in items if not info.filename.startswith(prefixes)]
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED, compresslevel=9) as target:
        for info, data in kept:
            if info.filename.endswith(".dist-info/RECORD"):
                data = b"\n".join(line for line in data.split(b"\n") if not line.decode().startswith(prefixes))
            target.writestr(info, data)
    print(f"{path.name}: {len(items) - len(kept)} files stripped")
EOF
du -sh "$dir"
