"""Dataset build throughput: simulation, annotation, rendering and writing of one push dataset, from scratch.

Builds ``--experiment`` at ``--scale`` into a fresh temporary data directory (so the push sequences are simulated
too, unless ``--raw_dir`` points at an existing raw cache) and prints examples/s and the disk sizes.

    python benchmarks/build_dataset.py [--experiment data_efficiency] [--scale cpu] [--workers N] [--raw_dir DIR]
"""

import argparse
import os
import resource
import tempfile
import time
from pathlib import Path

import tensorflow_datasets as tfds

from pushjax.data.builder import build


def _size(path: Path) -> int:
    return sum(file.stat().st_size for file in path.rglob("*") if file.is_file())


def _cpu_seconds() -> dict[str, float]:
    """User + system CPU seconds of this process and of its finished child processes (the workers)."""
    main, workers = (resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return {"main": main.ru_utime + main.ru_stime, "workers": workers.ru_utime + workers.ru_stime}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--experiment", default="data_efficiency")
    parser.add_argument("--scale", default="cpu")
    parser.add_argument("--workers", type=int, default=None, help="default: all cores")
    parser.add_argument("--raw_dir", default=None, help="existing raw cache (default: simulate into the temp dir)")
    args = parser.parse_args()
    tfds.disable_progress_bar()
    with tempfile.TemporaryDirectory() as directory:
        start = time.perf_counter()
        cpu_start = _cpu_seconds()
        builder = build(args.experiment, args.scale, data_dir=directory, workers=args.workers, progress=False,
                        raw_dir=args.raw_dir)
        seconds = time.perf_counter() - start
        cpu = {who: _cpu_seconds()[who] - cpu_start[who] for who in cpu_start}
        examples = sum(split.num_examples for split in builder.info.splits.values())
        dataset_bytes = _size(Path(builder.data_dir))
        raw_bytes = _size(builder.raw_dir) if args.raw_dir is None else 0
    print(f"{args.experiment} at {args.scale} scale, {args.workers or os.cpu_count()} workers on "
          f"{os.cpu_count()} cores: {examples} examples in {seconds:.1f} s = {examples / seconds:.0f} examples/s; "
          f"dataset {dataset_bytes / 2**20:.1f} MiB ({dataset_bytes / examples / 1024:.2f} KiB/example)"
          + (f", raw sequence cache {raw_bytes / 2**20:.1f} MiB" if raw_bytes else ""))
    total = sum(cpu.values())
    print(f"CPU time: main process {cpu['main']:.1f} s, workers {cpu['workers']:.1f} s = "
          f"{total / examples * 1e3:.2f} CPU-ms/example, i.e. {2 * examples / total:.0f} examples/s on 2 idle cores "
          f"(load average during the run: {os.getloadavg()[1]:.1f})")


if __name__ == "__main__":
    main()
