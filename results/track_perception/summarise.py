"""The table of RESULTS.md's "Perception as a second observation": the runs of commands.sh, per seed and their mean.

    python results/track_perception/summarise.py > results/track_perception/summary.md
"""

import json
from pathlib import Path

import numpy as np

FOLDER = Path(__file__).resolve().parent
SETTINGS = (("drop_default", "1 % dropped (the realistic profile)"), ("drop_0.5", "50 % dropped"),
            ("drop_0.5_10hz", "50 % dropped, perception at 10 Hz"), ("drop_0.9", "90 % dropped"))
ROWS = ("ekf", "ekf_perception", "ekf_perception_only", "ekf_prediction_only", "constant_velocity", "raw", "perception")
SEEDS = (0, 1, 2)


def main():
    print("Position RMSE (mm) / yaw RMSE (deg) / NEES in its 95 % band, per seed 0, 1, 2 and their mean; perception "
          "at 2.5 Hz unless said.\n")
    for folder, label in SETTINGS:
        runs = [json.loads((FOLDER / f"seed{seed}_{folder}" / "results.json").read_text()) for seed in SEEDS]
        print(f"### {label}\n")
        print("| estimate | position RMSE (mm) | mean | yaw RMSE (deg) | mean | NEES in band |")
        print("|---|---|---:|---|---:|---|")
        for row in ROWS:
            entries = [run["summary"][row] for run in runs]
            position = [entry["position_rmse_mm"] for entry in entries]
            yaw = [entry.get("yaw_rmse_deg") for entry in entries]
            band = [entry.get("nees_in_95_band") for entry in entries]
            yaw_cells = ("–", "–") if yaw[0] is None else (", ".join(f"{v:.3f}" for v in yaw), f"{np.mean(yaw):.3f}")
            band_cell = "" if band[0] is None else ", ".join(f"{100 * v:.0f} %" for v in band)
            print(f"| {row} | {', '.join(f'{v:.3f}' for v in position)} | {np.mean(position):.3f} | {yaw_cells[0]} "
                  f"| {yaw_cells[1]} | {band_cell} |")
        change = [100 * (run["summary"]["ekf_perception"]["position_rmse_mm"] / run["summary"]["ekf"]["position_rmse_mm"]
                         - 1) for run in runs]
        noise = [", ".join(f"{1e3 * v:.2f}" for v in run["perception"]["std"]) for run in runs]
        print(f"\nekf_perception against ekf, position: {', '.join(f'{v:+.1f}' for v in change)} % (mean "
              f"{np.mean(change):+.1f} %, sd {np.std(change, ddof=1):.1f} %); perception's reading noise (x, y; mm, "
              f"from seed + 1's pushes): {'; '.join(noise)}.\n")


if __name__ == "__main__":
    main()
