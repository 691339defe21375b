"""An experiment rerun with ``--min_test_sequences`` against its published run (issue 30, part 3).

The rerun trains on the same training and validation data as the published run and evaluates on the test splits
grown to at least N sequences, which hold the published test sequences (`pushjax.data.configs.plan_grown_test_splits`).
For every cell (model, training split, test split, size, limit-surface factor), mean over seeds:

- ``published``: the published run on its own test split;
- ``rerun, same sequences``: the rerun's models on those sequences alone (their per-sequence sums): equal to
  ``published`` when retraining reproduced the published models;
- ``rerun, grown``: the rerun on the grown split, ± its standard error (sequence bootstrap and seeds,
  `pushjax.paper.statistics.estimate`).

    python benchmarks/grown_test_compare.py work/results150/viewpoint/results.json results/viewpoint/results.json
"""

import json
import sys
from collections import defaultdict

import numpy as np

from pushjax.data import configs
from pushjax.paper import statistics
from pushjax.stats import SEQUENCE_RATIOS

METRICS = ("trans_percent", "rot_percent")
CELL = ("model", "train_split", "test_split", "train_size", "l_scale")


def _dataset(config: dict) -> configs.DatasetConfig:
    return configs.get_config(config["experiment"], config["scale"], config["seed"], config["testbed"],
                              config.get("min_test_sequences", 0))


def _sequence_paths(config: dict, split: str) -> dict[int, str]:
    """sequence id -> raw file name of the split's sequences in the dataset of `config`."""
    plan = configs.plan_splits(_dataset(config), "/unused")
    return {i: plan.jobs[i].path.name for i in plan.splits[split]}


def _restricted(row: dict, ids: set[int], metric: str) -> float:
    """`metric` of `row` over the sequences `ids` alone, from its per-sequence sums."""
    numerator, denominator, factor = SEQUENCE_RATIOS[metric]
    sequences = row["sequences"]
    keep = np.array([i in ids for i in sequences["id"]])
    return factor * float(np.sum(np.asarray(sequences[numerator])[keep])
                          / np.sum(np.asarray(sequences[denominator])[keep]))


def main(rerun_path: str, published_path: str) -> None:
    rerun, published = (json.loads(open(path).read()) for path in (rerun_path, published_path))
    grown_config = rerun["config"].get("test_dataset")
    if not grown_config or not grown_config.get("min_test_sequences"):
        sys.exit(f"{rerun_path}: not a run with --min_test_sequences (its config has no grown test_dataset)")
    own_config = published["config"].get("test_dataset", published["config"]["dataset"])
    cells = defaultdict(lambda: ([], []))
    for index, results in enumerate((rerun, published)):
        for row in results["rows"]:
            cells[tuple(row[key] for key in CELL)][index].append(row)
    print(f"rerun: {rerun_path} (test: {_dataset(grown_config).name}); published: {published_path}\n")
    print("| model | train split | test split | size | l | seeds | sequences | "
          + " | ".join(f"{metric} published | rerun, same sequences | rerun, grown" for metric in METRICS) + " |")
    print("|---|---|---|---:|---:|---|---|" + "---:|---:|---:|" * len(METRICS))
    for cell, (rerun_rows, published_rows) in sorted(cells.items(), key=lambda item: str(item[0])):
        seeds = sorted({row["seed"] for row in rerun_rows} & {row["seed"] for row in published_rows},
                       key=lambda seed: -1 if seed is None else seed)
        if not seeds:
            continue
        rerun_rows = [row for row in rerun_rows if row["seed"] in seeds]
        published_rows = [row for row in published_rows if row["seed"] in seeds]
        split = cell[2]
        own_paths = set(_sequence_paths(own_config, split).values())
        grown_paths = _sequence_paths(grown_config, split)
        same = {i for i, name in grown_paths.items() if name in own_paths}
        parts = []
        for metric in METRICS:
            grown = statistics.estimate(rerun_rows, metric)
            parts.append(f"{np.mean([row[metric] for row in published_rows]):.2f} | "
                         f"{np.mean([_restricted(row, same, metric) for row in rerun_rows]):.2f} | {grown}")
        print(f"| {' | '.join(str(value) for value in cell)} | {','.join(map(str, seeds))} | "
              f"{len(own_paths)} → {len(grown_paths)} | " + " | ".join(parts) + " |")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(*sys.argv[1:])
