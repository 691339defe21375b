"""The MIT Push Dataset (Yu et al., IROS 2016): its raw file layout and its push protocol.

:mod:`~pushjax.mit.files` names, writes, reads, cleans and iterates the raw push files;
:mod:`~pushjax.mit.protocol` holds the grid of pushes and the pusher's path and motion. Both the MuJoCo testbed
(:mod:`pushjax.sim`) and the datasets (:mod:`pushjax.data`) build on this package, which imports neither of them
nor MuJoCo or TFDS.
"""

from pushjax.mit import files, protocol
from pushjax.mit.files import (
    DATASETS,
    DEFAULT_FREQUENCY,
    EFFECTS_ATTRIBUTE,
    POSE_DATASETS,
    WRENCH_DATASET,
    Push,
    PushFileError,
    PushIterator,
    PushParams,
    RawPush,
    clean_push,
    iter_pushes,
    load_push,
    parse_push_file_name,
    push_file_name,
    push_file_path,
    read_raw_push,
    write_push,
)
from pushjax.mit.protocol import (
    APPROACH_DISTANCE,
    MIT_ACCELERATIONS,
    MIT_ANGLES,
    MIT_VELOCITIES,
    PUSH_DISTANCE,
    push_duration,
    pusher_line,
    pusher_motion,
    sample_push,
    side_points,
)

__all__ = [
    "APPROACH_DISTANCE",
    "DATASETS",
    "DEFAULT_FREQUENCY",
    "EFFECTS_ATTRIBUTE",
    "MIT_ACCELERATIONS",
    "MIT_ANGLES",
    "MIT_VELOCITIES",
    "POSE_DATASETS",
    "PUSH_DISTANCE",
    "Push",
    "PushFileError",
    "PushIterator",
    "PushParams",
    "RawPush",
    "WRENCH_DATASET",
    "clean_push",
    "files",
    "iter_pushes",
    "load_push",
    "parse_push_file_name",
    "protocol",
    "push_duration",
    "push_file_name",
    "push_file_path",
    "pusher_line",
    "pusher_motion",
    "read_raw_push",
    "sample_push",
    "side_points",
    "write_push",
]
