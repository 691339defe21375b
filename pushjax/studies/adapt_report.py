"""The report of a learning-while-pushing run (:mod:`pushjax.studies.adapt`): its markdown and the figure of the time
to goal by block, written by :func:`pushjax.studies.adapt.write`."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt

__all__ = ["figure", "markdown"]


def _format(value: float | None, spec: str, missing: str = "n/a") -> str:
    return missing if value is None else format(value, spec)


def markdown(results: dict) -> str:
    """Markdown of a run's results (:func:`pushjax.studies.adapt.run`): per effect the arms by block, what the loop
    selected, the two comparison rules' verdicts, and the filter rule."""
    lines = ["# Learn while pushing", "", results["comparison_rule"], ""]
    for effect, comparison in results["comparison"].items():
        lines += [f"## {effect}", "", "| arm | block | episodes | success | time to goal (s) | path length (m) |",
                  "|---|---:|---:|---:|---:|---:|"]
        for row in results["rows"]:
            if row["effect"] == effect:
                error = row["time_to_goal_se_s"]
                spread = "" if error is None else f" ± {error:.1f}"
                lines.append(f"| {row['arm']} | {row['block'] + 1} | {row['episodes']} | {row['success_rate']:.0%} | "
                             f"{row['time_to_goal_s']:.1f}{spread} | {row['path_length_m']:.3f} |")
        lines += ["", "What the adaptive arm plans with after each block:", ""]
        lines += [f"- world {row['world']}, after block {row['block'] + 1} ({row['pushes']} pushes): {row['reason']}"
                  for row in results["loop"] if row["effect"] == effect]
        criterion = comparison.get("criterion_s", {"mean": None, "standard_error": None})
        lines += ["", f"Last block ({comparison['goals']} goals, {comparison['worlds']} worlds): criterion "
                      f"{_format(criterion['mean'], '+.2f')} ± {_format(criterion['standard_error'], '.2f')} s, gap "
                      f"closed {_format(comparison.get('gap_closed_share'), '.0%')}: **{comparison['verdict']}** "
                      f"({comparison['reason']})", ""]
        filtered = results["filter_comparison"][effect]
        difference = filtered.get("filtered_minus_plain_s", {"mean": None, "standard_error": None})
        lines += [f"Planning with the filter's friction within each episode ({filtered['goals']} goals, "
                  f"{filtered['worlds']} worlds): filtered − plain {_format(difference['mean'], '+.2f')} ± "
                  f"{_format(difference['standard_error'], '.2f')} s: **{filtered['verdict']}** ({filtered['reason']})",
                  ""]
    lines += [results["filter_rule"], ""]
    return "\n".join(lines)


def figure(results: dict, path: Path) -> None:
    """Time to goal by block, per effect (a panel each) and arm, with standard errors over world seeds, to `path`."""
    effects = list(results["comparison"])
    figure, axes = plt.subplots(1, len(effects), figsize=(4.5 * len(effects), 3.5), squeeze=False)
    for axis, effect in zip(axes[0], effects):
        for arm in dict.fromkeys(row["arm"] for row in results["rows"]):  # in the study's order of arms
            rows = [row for row in results["rows"] if row["effect"] == effect and row["arm"] == arm]
            blocks = [row["block"] + 1 for row in rows]
            errors = [row["time_to_goal_se_s"] or 0.0 for row in rows]
            axis.errorbar(blocks, [row["time_to_goal_s"] for row in rows], yerr=errors, marker="o", capsize=3,
                          label=arm)
        axis.set_title(effect)
        axis.set_xlabel("block")
        axis.set_ylabel("time to goal (s; failure = max time)")
        axis.set_xticks(sorted({row["block"] + 1 for row in results["rows"]}))
    axes[0][0].legend()
    figure.tight_layout()
    figure.savefig(path, dpi=100, metadata={"Software": None})
    plt.close(figure)
