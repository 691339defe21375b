"""The paper's qualitative findings, checked on the ``results.json`` of the experiment binaries.

Every finding compares models by their *score*: the mean of the translation and rotation errors in % of
the ``zero`` baseline (trained models averaged over seeds, `tables.aggregate`), with the standard error
``sqrt(se_trans^2 + se_rot^2) / 2``. "Clearly better" means lower by more than twice the standard error
of the difference; "improves" means no model clearly worse and at least one clearly better. A finding
whose experiment or models are missing is reported as not checked.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from pushjax.paper import tables

Results = Mapping[str, Mapping]
"""binary name (``data_efficiency``, ``new_pushes``, ``velocities``, ``error_variants``, ...) -> results."""


@dataclasses.dataclass(frozen=True)
class Score:
    """Mean of trans. and rot. [% of zero] and its standard error (None when a seed lacked one)."""

    value: float
    se: float | None

    def clearly_below(self, other: Score) -> bool:
        se = math.hypot(self.se or 0.0, other.se or 0.0)
        return self.value + 2.0 * se < other.value

    def __str__(self) -> str:
        return f"{self.value:.1f}" + (f" ± {self.se:.1f}" if self.se is not None else "")


@dataclasses.dataclass(frozen=True)
class Finding:
    """One checked finding: `holds` is None when it could not be checked; `evidence` gives the numbers."""

    key: str
    statement: str
    experiment: str
    holds: bool | None
    evidence: str


def score(row: Mapping) -> Score | None:
    """The `Score` of an aggregated results row, or None when its errors are undefined."""
    trans, rot = row.get("trans_percent"), row.get("rot_percent")
    if trans is None or rot is None:
        return None
    errors = (row.get("trans_percent_se"), row.get("rot_percent_se"))
    se = None if None in errors else math.hypot(*errors) / 2.0
    return Score((trans + rot) / 2.0, se)


def scores(results: Mapping, **criteria) -> dict[str, Score]:
    """model -> `Score` of the aggregated rows of `results` matching `criteria` (row key -> value)."""
    selected = {}
    for row in tables.aggregate(results["rows"]):
        if all(row.get(key) == value for key, value in criteria.items()):
            value = score(row)
            if value is not None:
                selected[row["model"]] = value
    return selected


def _sizes(results: Mapping) -> list[int]:
    return sorted({row["train_size"] for row in results["rows"] if row.get("train_size") is not None})


def _velocity(test_split: str) -> float | None:
    prefix = "test_"
    try:
        return float(test_split[len(prefix):]) if test_split.startswith(prefix) else None
    except ValueError:
        return None


def _listing(named: Mapping[str, Score]) -> str:
    return ", ".join(f"{name} {value}" for name, value in named.items())


def _missing(models: Sequence[str], available: Mapping) -> list[str]:
    return [model for model in models if model not in available]


def _small_data(results: Results) -> tuple[bool | None, str]:
    run = results["data_efficiency"]
    size = _sizes(run)[0]
    at_size = scores(run, kind="trained", train_size=size)
    better, worse = ("hybrid", "error"), ("neural", "simple")
    if missing := _missing(better + worse, at_size):
        return None, f"not trained: {', '.join(missing)}"
    holds = all(at_size[a].clearly_below(at_size[b]) for a in better for b in worse)
    return holds, f"at {size} examples: " + _listing({m: at_size[m] for m in better + worse})


def _most_data(results: Results) -> tuple[bool | None, str]:
    run = results["data_efficiency"]
    size = _sizes(run)[-1]
    at_size = {model: value for model, value in scores(run, kind="trained", train_size=size).items()
               if model != "neural_dyn"}
    if "neural" not in at_size or len(at_size) < 2:
        return None, "neural and another perception variant are needed"
    best = min(at_size, key=lambda model: at_size[model].value)
    ranked = dict(sorted(at_size.items(), key=lambda item: item[1].value))
    return best == "neural", f"at {size} examples, best first: {_listing(ranked)}"


def _new_pushes(results: Results) -> tuple[bool | None, str]:
    run = results["new_pushes"]
    holds, parts = True, []
    for size in _sizes(run):
        at_size = scores(run, kind="trained", train_size=size)
        if missing := _missing(("neural", "hybrid", "error"), at_size):
            return None, f"not trained: {', '.join(missing)}"
        holds &= all(at_size[model].value < at_size["neural"].value for model in ("hybrid", "error"))
        parts.append(f"at {size}: " + _listing({m: at_size[m] for m in ("hybrid", "error", "neural")}))
    return holds, "; ".join(parts)


def _mean_over(run: Mapping, test_splits: Sequence[str], **criteria) -> dict[str, Score]:
    """model -> `Score` averaged over `test_splits` (models present in all of them)."""
    per_split = [scores(run, test_split=split, **criteria) for split in test_splits]
    models = set.intersection(*(set(split) for split in per_split)) if per_split else set()
    averaged = {}
    for model in sorted(models):
        values = [split[model] for split in per_split]
        se = None if any(v.se is None for v in values) else math.sqrt(sum(v.se ** 2 for v in values)) / len(values)
        averaged[model] = Score(sum(v.value for v in values) / len(values), se)
    return averaged


def _faster_tests(run: Mapping, than: float) -> list[str]:
    return sorted((split for split in run["config"]["test_splits"] if (_velocity(split) or 0.0) > than),
                  key=_velocity)


def _extrapolation(results: Results) -> tuple[bool | None, str]:
    run = results["velocities"]
    faster = _faster_tests(run, 20.0)
    trained = _mean_over(run, faster, kind="trained", train_split="train_20")
    physics = _mean_over(run, faster, kind="baseline").get("physics")
    if physics is None or _missing(("neural", "hybrid"), trained):
        return None, "needs physics, neural and hybrid"
    gap = {model: value.value - physics.value for model, value in trained.items()}
    holds = gap["neural"] > 0 and abs(gap["hybrid"]) < 0.5 * gap["neural"]
    return holds, (f"trained at 20 mm/s, mean over {', '.join(faster)}: physics {physics}, "
                   + _listing(trained) + "; simple and neural_dyn are not trained in this experiment")


def _faster_training(results: Results) -> tuple[bool | None, str]:
    run = results["velocities"]
    faster = _faster_tests(run, 50.0)
    only_20 = _mean_over(run, faster, kind="trained", train_split="train_20")
    with_50 = _mean_over(run, faster, kind="trained", train_split="train_20_50")
    models = sorted(set(only_20) & set(with_50))
    if not models:
        return None, "needs models trained on train_20 and train_20_50"
    holds = (not any(only_20[model].clearly_below(with_50[model]) for model in models)
             and any(with_50[model].clearly_below(only_20[model]) for model in models))
    return holds, f"mean over {', '.join(faster)}: " + "; ".join(
        f"{model} {only_20[model]} (20) -> {with_50[model]} (20 + 50)" for model in models)


def _wrong_l(results: Results) -> tuple[bool | None, str]:
    run = results["error_variants"]
    holds, parts = True, []
    for l_scale in sorted({row["l_scale"] for row in run["rows"]} - {1.0}):
        for size in _sizes(run):
            at = scores(run, kind="trained", train_size=size, l_scale=l_scale)
            if _missing(("hybrid", "error"), at):
                return None, "needs hybrid and error trained with a scaled l"
            holds &= at["error"].value < at["hybrid"].value
            parts.append(f"l × {l_scale:g}, {size}: error {at['error']}, hybrid {at['hybrid']}")
    if not parts:
        return None, "no scaled l in the results"
    return holds, "; ".join(parts)


CHECKS: dict[str, tuple[str, str, Callable[[Results], tuple[bool | None, str]]]] = {
    "small_data": ("At 2.5 k examples hybrid and error beat neural and simple clearly.", "data_efficiency",
                   _small_data),
    "most_data": ("With the most data, neural is best inside the training distribution.", "data_efficiency",
                  _most_data),
    "new_pushes": ("On held-out pushes hybrid and error beat neural.", "new_pushes", _new_pushes),
    "extrapolation": ("Extrapolating to faster pushes, hybrid stays near physics while the learned models "
                      "degrade.", "velocities", _extrapolation),
    "faster_training": ("Training with 20 + 50 mm/s improves extrapolation.", "velocities", _faster_training),
    "wrong_l": ("With a wrong l, error compensates better than hybrid.", "error_variants", _wrong_l),
}
"""key -> (the paper's finding, the binary whose results check it, the check)."""


def check(results: Results) -> list[Finding]:
    """Every finding of `CHECKS` on `results` (binary name -> results.json contents)."""
    findings = []
    for key, (statement, experiment, check_fn) in CHECKS.items():
        if experiment in results:
            holds, evidence = check_fn(results)
        else:
            holds, evidence = None, f"no {experiment} results"
        findings.append(Finding(key, statement, experiment, holds, evidence))
    return findings


def load(workdirs: Sequence[str | os.PathLike]) -> dict[str, dict]:
    """binary name -> results.json of each work directory (named by the file's ``name`` field)."""
    results = {}
    for workdir in workdirs:
        path = Path(workdir) / "results.json"
        if not path.is_file():
            raise FileNotFoundError(f"workdirs: {path} does not exist; run the experiment binary first")
        contents = json.loads(path.read_text())
        if not isinstance(contents, dict) or "name" not in contents or "rows" not in contents:
            raise ValueError(f"workdirs: {path} is not a results.json of an experiment binary")
        results[contents["name"]] = contents
    return results


def markdown(findings: Sequence[Finding]) -> str:
    """The findings as a markdown table."""
    verdict = {True: "holds", False: "does not hold", None: "not checked"}
    lines = ["| finding | experiment | on our testbed | evidence (score: mean of trans. and rot. % of zero) |",
             "|---|---|---|---|"]
    lines += [f"| {f.statement} | {f.experiment} | {verdict[f.holds]} | {f.evidence} |" for f in findings]
    return "\n".join(lines)
