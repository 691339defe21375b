"""The report of a learning-while-pushing run (:mod:`pushjax.studies.adapt`): its markdown and the figure of the time
to goal by block, written by :func:`pushjax.studies.adapt.write`."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from pushjax.physics.effects import registry

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
        lines += ["", *_beside_the_truth(results, effect)]
        criterion = comparison.get("criterion_s", {"mean": None, "standard_error": None})
        lines += ["", f"Last block ({comparison['goals']} goals, {comparison['worlds']} worlds): criterion "
                      f"{_format(criterion['mean'], '+.2f')} ± {_format(criterion['standard_error'], '.2f')} s, "
                      f"{_gap_text(comparison)}: **{comparison['verdict']}** ({comparison['reason']})", ""]
        filtered = results["filter_comparison"][effect]
        difference = filtered.get("filtered_minus_plain_s", {"mean": None, "standard_error": None})
        lines += [f"Planning with the filter's friction within each episode ({filtered['goals']} goals, "
                  f"{filtered['worlds']} worlds): filtered − plain {_format(difference['mean'], '+.2f')} ± "
                  f"{_format(difference['standard_error'], '.2f')} s: **{filtered['verdict']}** ({filtered['reason']})",
                  ""]
    lines += [results["filter_rule"], ""]
    return "\n".join(lines)


def _gap_text(comparison: dict) -> str:
    """The plain-oracle gap and what the adaptive arm closed of it (no share where the oracle is not faster)."""
    gap, closed = comparison.get("plain_minus_oracle_s"), comparison.get("plain_minus_adaptive_s")
    if gap is None or closed is None:
        return "no gap measured"
    text = f"plain − oracle {gap:+.2f} s, plain − adaptive {closed:+.2f} s"
    if gap <= 0:
        return text + ", no gap to close (the oracle is not faster than plain)"
    return text + f", gap closed {_format(comparison.get('gap_closed_share'), '.0%')}"


def _model_text(model: dict | None) -> str:
    """A pushing model (:meth:`pushjax.physics.model_file.AugmentedModel.as_dict`; None: plain Lynch at the nominal
    friction) as its effects' physical values (mm, degrees, ratios) and its pusher friction."""
    if model is None:
        return "Lynch"
    values = registry.physical_params({name: {key: np.asarray(value) for key, value in params.items()}
                                       for name, params in model["params"].items()})
    effects = [f"{name} ({', '.join(f'{key} {float(value):.3g}' for key, value in values[name].items())})"
               for name in model["effects"]]
    return f"{' + '.join(effects) or 'Lynch'}, μ {model['pusher_friction']:.3f}"


def _beside_the_truth(results: dict, effect: str) -> list[str]:
    """The table of the loop's model after each block beside each world's truth (its oracle model; the world's drawn
    magnitudes too where the oracle has no effect to show them, e.g. a push-to-push spread)."""
    loops = [row for row in results["loop"] if row["effect"] == effect]
    blocks = sorted({row["block"] for row in loops})
    pushes = {row["block"]: row["pushes"] for row in loops}
    lines = ["The loop's model after each block beside the world's truth:", "",
             "| world | truth | " + " | ".join(f"after block {block + 1} ({pushes[block]} pushes)" for block in blocks)
             + " |", "|---|---|" + "---|" * len(blocks)]
    for world in results["worlds"]:
        if world["effect"] != effect:
            continue
        oracle = next(iter(world["oracle"].values()))
        truth = _model_text(oracle)
        if not oracle["effects"]:
            truth += " (" + ", ".join(f"{key} {value:.3g}" for key, value in world["magnitude"].items()) + ")"
        models = {row["block"]: _model_text(row["model"]) if row["ran"] else "Lynch (too few pushes)"
                  for row in loops if row["world"] == world["seed"]}
        lines.append(f"| {world['seed']} | {truth} | " + " | ".join(models.get(block, "") for block in blocks) + " |")
    return lines


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
