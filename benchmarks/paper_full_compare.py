"""Two runs of ``experiments.data_efficiency_full`` compared on the models both recorded (issue 30, part 4).

For every (model, size) with seeds recorded in both work directories (e.g. ``paper_full`` from
``benchmarks/paper_full_gpu.sh`` against the ``cpu_full`` run): each run's mean over those seeds and the difference
``first - second`` with its standard error. Where both runs evaluated the same test sequences (``paper_full`` renders
``cpu_full``'s pushes), the difference is paired over sequences (`pushjax.paper.statistics.difference`); the seeds'
part is the spread of each run's seeds, taken as independent. The same compares the GPU twins of the ``cpu_full``
run (``results/data_efficiency_full/h200``: models trained on a lent H200 with its own build of the dataset) with the
run's own models: what the device changes.

    python benchmarks/paper_full_compare.py results/data_efficiency_paper_full results/data_efficiency_full
"""

import sys
from collections import defaultdict

from pushjax.paper import full_run, statistics

METRICS = {"trans_percent": 1, "rot_percent": 1, "pos_mm": 2}
"""metric -> decimals shown."""


def _text(estimate: statistics.Estimate, decimals: int) -> str:
    return f"{estimate.value:.{decimals}f}" + (f" ± {estimate.se:.{decimals}f}" if estimate.se is not None else "")


def main(first: str, second: str) -> None:
    records = [full_run.records(folder) for folder in (first, second)]
    cells = defaultdict(list)
    for key in sorted(set(records[0]) & set(records[1])):
        row = records[0][key]["row"]
        cells[(row["model"], row["train_size"])].append(key)
    if not cells:
        sys.exit(f"{first} and {second} have no model recorded in both")
    print(f"first: {first}; second: {second}\n")
    print("| model | size | seeds | " + " | ".join(f"{metric} first | second | first - second" for metric in METRICS)
          + " |")
    print("|---|---:|---|" + "---:|---:|---:|" * len(METRICS))
    for (model, size), keys in sorted(cells.items()):
        seeds = ",".join(str(records[0][key]["row"]["seed"]) for key in keys)
        parts = []
        for metric, decimals in METRICS.items():
            first_estimate, second_estimate = (statistics.estimate([run[key]["row"] for key in keys], metric)
                                               for run in records)
            if first_estimate is None or second_estimate is None:  # a metric the model has not (neural_dyn: pos_mm)
                parts += ["–"] * 3
                continue
            difference = statistics.difference(first_estimate, second_estimate)
            paired = " (paired)" if difference.replicates is not None else ""
            parts += [_text(first_estimate, decimals), _text(second_estimate, decimals),
                      _text(difference, decimals) + paired]
        print(f"| {model} | {size} | {seeds} | " + " | ".join(parts) + " |")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__.strip().splitlines()[-1].strip().replace("python ", "usage: python ", 1))
    main(*sys.argv[1:])
