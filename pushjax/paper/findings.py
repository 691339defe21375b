"""The paper's qualitative findings, each stated as the paper states it and decided on ``results.json`` files.

The criteria are fixed in this module before the runs they judge, and are not changed after seeing numbers.

Every comparison is between *scores* (`pushjax.paper.statistics.SCORE`: the mean of the translation and rotation
errors in % of the ``zero`` baseline; Fig. 7's finding uses the rotation error alone), averaged over seeds, with
the standard error of the *difference*: a bootstrap over the test split's push sequences, paired between models on
the same split, combined with the spread over seeds (`pushjax.paper.statistics`). "A beats B" is decided when
the difference exceeds `MARGIN` standard errors (`CLEAR_MARGIN` when the paper says "clearly"):

* a finding **holds** when every comparison it makes is decided in its favour;
* it **does not hold** when any comparison is decided against it;
* it is **not decidable** otherwise (some difference within the errors);
* it is **not checked** when its experiment or models are missing.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from pushjax.paper import statistics, tables
from pushjax.paper.statistics import Estimate

MARGIN = 1.0
"""Standard errors of the difference by which a model must be better (or worse) for a comparison to be decided."""
CLEAR_MARGIN = 2.0
"""The margin of a finding the paper states as "clearly"."""

HOLDS, FAILS, UNDECIDED, UNCHECKED = "holds", "does not hold", "not decidable", "not checked"

Results = Mapping[str, Mapping]
"""binary name (``data_efficiency``, ``new_pushes``, ``velocities``, ...) -> the contents of its results.json."""


@dataclasses.dataclass(frozen=True)
class Comparison:
    """``better`` should have a lower error than ``worse``; `difference` is better − worse."""

    label: str
    difference: Estimate
    margin: float

    @property
    def outcome(self) -> int:
        """-1: decided for the finding, +1: decided against it, 0: within the errors."""
        se = self.difference.se or 0.0
        if self.difference.value < -self.margin * se:
            return -1
        return 1 if self.difference.value > self.margin * se else 0

    def __str__(self) -> str:
        return f"{self.label}: {self.difference.value:+.1f} ± {self.difference.se or 0.0:.1f}"


@dataclasses.dataclass(frozen=True)
class Finding:
    """One decided finding: `verdict` is one of holds / does not hold / not decidable / not checked."""

    key: str
    statement: str
    experiment: str
    verdict: str
    evidence: str


def cells(results: Mapping, metric: str = statistics.SCORE, **criteria) -> dict[str, Estimate]:
    """model -> `Estimate` of `metric` over the seeds of the cells of `results` matching `criteria`."""
    selected = {}
    for key, members in tables.group(results["rows"]).items():
        cell = dict(zip(tables.GROUP_KEYS, key))
        if all(cell.get(name) == value for name, value in criteria.items()):
            estimate = statistics.estimate(members, metric)
            if estimate is not None:
                selected[cell["model"]] = estimate
    return selected


def _sizes(results: Mapping) -> list[int]:
    return sorted({row["train_size"] for row in results["rows"] if row.get("train_size") is not None})


def _velocity(test_split: str) -> float | None:
    prefix = "test_"
    try:
        return float(test_split[len(prefix):]) if test_split.startswith(prefix) else None
    except ValueError:
        return None


def _faster_tests(run: Mapping, than: float) -> list[str]:
    return sorted((split for split in run["config"]["test_splits"] if (_velocity(split) or 0.0) > than),
                  key=_velocity)


def _mean_over(run: Mapping, test_splits: Sequence[str], **criteria) -> dict[str, Estimate]:
    """model -> the mean of its `Estimate`s over `test_splits` (models present in all of them)."""
    per_split = [cells(run, test_split=split, **criteria) for split in test_splits]
    models = set.intersection(*(set(split) for split in per_split)) if per_split else set()
    return {model: statistics.mean_over([split[model] for split in per_split]) for model in sorted(models)}


def _compare(label: str, better: Estimate, worse: Estimate, margin: float = MARGIN) -> Comparison:
    return Comparison(label, statistics.difference(better, worse), margin)


def _decide(comparisons: Sequence[Comparison]) -> str:
    outcomes = [comparison.outcome for comparison in comparisons]
    if any(outcome > 0 for outcome in outcomes):
        return FAILS
    return HOLDS if all(outcome < 0 for outcome in outcomes) else UNDECIDED


def _pairs(at: Mapping[str, Estimate], better: Sequence[str], worse: Sequence[str], margin: float = MARGIN,
           prefix: str = "") -> list[Comparison]:
    return [_compare(f"{prefix}{a} − {b}", at[a], at[b], margin) for a in better for b in worse]


def _listing(named: Mapping[str, Estimate]) -> str:
    return ", ".join(f"{name} {value}" for name, value in named.items())


class _Missing(Exception):
    """A finding's models or splits are not in the results."""


def _need(at: Mapping, models: Sequence[str]) -> Mapping:
    if missing := [model for model in models if model not in at]:
        raise _Missing(f"not in the results: {', '.join(missing)}")
    return at


def _small_data(results: Results):
    run = results["data_efficiency"]
    size = _sizes(run)[0]
    at = _need(cells(run, kind="trained", train_size=size), ("hybrid", "error", "neural", "simple"))
    comparisons = _pairs(at, ("hybrid", "error"), ("neural", "simple"), CLEAR_MARGIN)
    return comparisons, f"at {size} examples: " + _listing({m: at[m] for m in ("hybrid", "error", "neural", "simple")})


def _most_data(results: Results):
    run = results["data_efficiency"]
    size = _sizes(run)[-1]
    at = _need(cells(run, kind="trained", train_size=size), ("neural", "simple", "hybrid", "error"))
    comparisons = _pairs(at, ("neural",), ("simple", "hybrid", "error"))
    return comparisons, f"at {size} examples: " + _listing({m: at[m] for m in ("neural", "simple", "hybrid", "error")})


def _new_pushes(results: Results):
    run = results["new_pushes"]
    comparisons, parts = [], []
    for size in _sizes(run):
        at = _need(cells(run, kind="trained", train_size=size), ("hybrid", "error", "neural"))
        comparisons += _pairs(at, ("hybrid", "error"), ("neural",), prefix=f"{size}: ")
        parts.append(f"at {size}: " + _listing({m: at[m] for m in ("hybrid", "error", "neural")}))
    return comparisons, "; ".join(parts)


def _degradation(run: Mapping, train_split: str, models: Sequence[str]) -> dict[str, Estimate]:
    """model -> its mean score over the tests faster than 20 mm/s minus its score at 20 mm/s."""
    faster = _mean_over(run, _faster_tests(run, 20.0), kind="trained", train_split=train_split)
    at_20 = cells(run, kind="trained", train_split=train_split, test_split="test_20")
    _need(faster, models), _need(at_20, models)
    return {model: statistics.difference(faster[model], at_20[model]) for model in models}


def _extrapolation(results: Results):
    run = results["velocities"]
    models = ("hybrid", "neural", "neural_dyn")
    degradation = _degradation(run, "train_20", models)
    comparisons = _pairs(degradation, ("hybrid",), ("neural", "neural_dyn"))
    return comparisons, ("trained at 20 mm/s, mean score over the faster tests minus the score at 20 mm/s: "
                         + _listing(degradation))


def _faster_training(results: Results):
    run = results["velocities"]
    faster = _faster_tests(run, 50.0)
    only_20 = _mean_over(run, faster, kind="trained", train_split="train_20")
    with_50 = _mean_over(run, faster, kind="trained", train_split="train_20_50")
    models = sorted(set(only_20) & set(with_50))
    if not models:
        raise _Missing("needs models trained on train_20 and train_20_50")
    comparisons = [_compare(f"{model} (20 + 50) − (20)", with_50[model], only_20[model]) for model in models]
    return comparisons, f"mean over {', '.join(faster)}: " + "; ".join(
        f"{model} {only_20[model]} (20) → {with_50[model]} (20 + 50)" for model in models)


def _wrong_l(results: Results):
    run = results["error_variants"]
    size = _sizes(run)[-1]
    comparisons, parts = [], []
    for l_scale in sorted({row["l_scale"] for row in run["rows"]} - {1.0}):
        at = _need(cells(run, kind="trained", train_size=size, l_scale=l_scale), ("hybrid", "error"))
        comparisons.append(_compare(f"l × {l_scale:g}: error − hybrid", at["error"], at["hybrid"]))
        parts.append(f"l × {l_scale:g}, {size}: error {at['error']}, hybrid {at['hybrid']}")
    if not parts:
        raise _Missing("no scaled l in the results")
    return comparisons, "; ".join(parts)


def _error_variants_faster(results: Results) -> dict[str, Estimate]:
    run = results["error_velocities"]
    return _need(_mean_over(run, _faster_tests(run, 20.0), kind="trained", train_split="train_20"),
                 ("neural", "hybrid", "error", "error_grad", "error_norm"))


def _error_grad(results: Results):
    at = _error_variants_faster(results)
    return _pairs(at, ("neural",), ("error_grad",)), "trained at 20 mm/s, mean over the faster tests: " + _listing(at)


def _error_norm(results: Results):
    at = _error_variants_faster(results)
    comparisons = _pairs(at, ("error_norm",), ("error", "error_grad")) + _pairs(at, ("hybrid",), ("error_norm",))
    return comparisons, "trained at 20 mm/s, mean over the faster tests: " + _listing(at)


def _unseen_objects(results: Results):
    run = results["objects"]
    comparisons, parts = [], []
    for train_split in run["config"]["train_splits"]:
        for test_split in run["config"]["test_splits"]:
            at = cells(run, "rot_percent", kind="trained", train_split=train_split, test_split=test_split)
            _need(at, ("neural", "hybrid", "error"))
            comparisons += _pairs(at, ("hybrid", "error"), ("neural",), prefix=f"{train_split} → {test_split}: ")
            parts.append(f"{train_split} → {test_split}: " + _listing({m: at[m] for m in ("neural", "hybrid", "error")}))
    return comparisons, "rotation error [%]: " + "; ".join(parts)


CHECKS: dict[str, tuple[str, str, Callable[[Results], tuple[list[Comparison], str]]]] = {
    "small_data": ("With 2.5 k training examples, hybrid and error beat neural and simple clearly (Table 1).",
                   "data_efficiency", _small_data),
    "most_data": ("With the most training data, neural is best (Table 1: 17.4 / 33.4 % at 190 k).",
                  "data_efficiency", _most_data),
    "new_pushes": ("On new pushes (held-out angles and contact points), hybrid and error beat neural (Table 3).",
                   "new_pushes", _new_pushes),
    "extrapolation": ("Trained at 20 mm/s, hybrid is the most constant over velocities; neural and neural_dyn "
                      "degrade at higher velocities (Fig. 6).", "velocities", _extrapolation),
    "faster_training": ("Adding 50 mm/s to training improves extrapolation for all models (Fig. 6).",
                        "velocities", _faster_training),
    "wrong_l": ("With a wrong l (× 1.5, × 3), error compensates better than hybrid (Table 5).", "error_variants",
                _wrong_l),
    "error_grad": ("Trained at 20 mm/s, error_grad extrapolates worse than neural (Fig. 9).", "error_velocities",
                   _error_grad),
    "error_norm": ("error_norm extrapolates best of the error variants but still worse than hybrid (Fig. 9).",
                   "error_velocities", _error_norm),
    "unseen_objects": ("neural is consistently worse than the others at predicting the rotation of unseen "
                       "objects (Fig. 7).", "objects", _unseen_objects),
}
"""key -> (the paper's finding, the binary whose results decide it, the comparisons it makes)."""


def check(results: Results) -> list[Finding]:
    """Every finding of `CHECKS` decided on `results` (binary name -> results.json contents)."""
    findings = []
    for key, (statement, experiment, comparisons_of) in CHECKS.items():
        if experiment not in results:
            findings.append(Finding(key, statement, experiment, UNCHECKED, f"no {experiment} results"))
            continue
        try:
            comparisons, evidence = comparisons_of(results)
        except _Missing as missing:
            findings.append(Finding(key, statement, experiment, UNCHECKED, str(missing)))
            continue
        evidence += "; differences (better − worse, ± s.e.): " + ", ".join(map(str, comparisons))
        findings.append(Finding(key, statement, experiment, _decide(comparisons), evidence))
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
    lines = [f"Decided at {MARGIN:g} standard error of the difference ({CLEAR_MARGIN:g} for \"clearly\"); scores are "
             "the mean of trans. and rot. in % of zero, ± s.e. (sequence bootstrap and seed spread).", "",
             "| finding (the paper's) | experiment | on our testbed | evidence |", "|---|---|---|---|"]
    lines += [f"| {f.statement} | {f.experiment} | {f.verdict} | {f.evidence} |" for f in findings]
    return "\n".join(lines)
