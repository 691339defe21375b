"""The paper's qualitative findings, each stated as the paper states it and decided on ``results.json`` files.

The criteria are fixed in this module before the runs they judge, and are not changed after seeing numbers.

Every comparison is between *scores* (`pushjax.paper.statistics.SCORE`: the mean of the translation and rotation
errors in % of the ``zero`` baseline; Fig. 7's finding uses the rotation error alone), averaged over seeds, with
the standard error of the *difference*: a bootstrap over the test split's push sequences, paired between models on
the same split, combined with the spread over seeds (`pushjax.paper.statistics`). Each comparison is decided by the
project's one rule, `pushjax.stats.decide`: more than `pushjax.stats.DECISION_STANDARD_ERRORS` (2) standard errors
of the difference from zero, the push sequences (and the seeds) the unit of resampling. Where the paper says
"clearly", the rule asks no more than it does everywhere else:

* a finding **holds** when every comparison it makes is decided in its favour;
* it **does not hold** when any comparison is decided against it;
* it is **not decided** otherwise (some difference within the errors);
* it is **not checked** when its experiment or models are missing;
* a finding about the paper's full training set (190 k examples) whose largest training size is below
  `FULL_SET_MIN` and that does not hold there is **not reached at N** (N: our largest size), not "does not hold":
  our data stop before the paper's condition.

Many looks: a finding of several comparisons takes one look per comparison, uncorrected; "holds" needs all of
them (conservative), "does not hold" any one (so the more comparisons, the likelier one crosses the bound by chance).
The Table 1 findings have been looked at on successive runs (``data_efficiency``, ``data_efficiency_full``, and
with ``--replace_with`` the longer-trained models of ``results/data_efficiency_long``); each run's table is its own
record, decided at one look's bound, and a verdict that changes between runs is read with that in mind.

The data-efficiency findings read ``data_efficiency_full`` (the paper's composition and sizes, issue 30) when it is
among the results and has trained every model it planned, else ``data_efficiency`` (else an incomplete
``data_efficiency_full``).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from pushjax import stats
from pushjax.paper import statistics, tables
from pushjax.paper.statistics import Estimate
from pushjax.stats import FAILS, HOLDS, UNDECIDED

UNCHECKED = "not checked"
"""The verdict of a finding whose experiment or models are missing (`HOLDS`, `FAILS`, `UNDECIDED`: `pushjax.stats`)."""
NOT_REACHED = "not reached at {size}"
"""The verdict of a full-set finding that does not hold at a largest size below `FULL_SET_MIN`."""

FULL_SET_MIN = 150_000
"""The smallest largest-training-size that counts as the paper's full set (190 k) for the full-set findings."""
SMALL_DATA_MAX = 20_000
"""The paper's "more than 20 k training examples": sizes up to this one are where hybrid is not yet reached."""
DATA_EFFICIENCY_RUNS = ("data_efficiency_full", "data_efficiency")
"""The experiments that decide the Table 1 findings, the first present one is read."""
CROSSOVER_LEVEL = 0.95
"""The coverage of the crossover's bootstrap interval."""

Results = Mapping[str, Mapping]
"""binary name (``data_efficiency``, ``new_pushes``, ``velocities``, ...) -> the contents of its results.json."""


@dataclasses.dataclass(frozen=True)
class Comparison:
    """``better`` should have a lower error than ``worse``; `difference` is better − worse."""

    label: str
    difference: Estimate

    @property
    def verdict(self) -> str:
        """`pushjax.stats.decide` of the difference: `HOLDS` (decided for the finding), `FAILS` or `UNDECIDED`."""
        return stats.decide(self.difference.value, self.difference.se)

    def __str__(self) -> str:
        """``label: difference ± s.e.`` to one decimal; a difference that is not decided although its rounded numbers
        are 2 standard errors apart or more (``-0.6 ± 0.3``) also gives their exact ratio (``(1.99 s.e.)``)."""
        value, se = self.difference.value, self.difference.se or 0.0
        text = f"{self.label}: {value:+.1f} ± {se:.1f}"
        if self.verdict == UNDECIDED and se > 0 and abs(round(value, 1)) >= stats.decision_bound(1) * round(se, 1):
            text += f" ({abs(value) / se:.2f} s.e.)"
        return text


@dataclasses.dataclass(frozen=True)
class Finding:
    """One decided finding: `verdict` is one of holds / does not hold / not decided / not checked / not reached."""

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


def _compare(label: str, better: Estimate, worse: Estimate) -> Comparison:
    return Comparison(label, statistics.difference(better, worse))


def _decide(comparisons: Sequence[Comparison]) -> str:
    verdicts = [comparison.verdict for comparison in comparisons]
    if FAILS in verdicts:
        return FAILS
    return HOLDS if all(verdict == HOLDS for verdict in verdicts) else UNDECIDED


def _pairs(at: Mapping[str, Estimate], better: Sequence[str], worse: Sequence[str],
           prefix: str = "") -> list[Comparison]:
    return [_compare(f"{prefix}{a} − {b}", at[a], at[b]) for a in better for b in worse]


def _listing(named: Mapping[str, Estimate]) -> str:
    return ", ".join(f"{name} {value}" for name, value in named.items())


class _Missing(Exception):
    """A finding's models or splits are not in the results."""


def _need(at: Mapping, models: Sequence[str]) -> Mapping:
    if missing := [model for model in models if model not in at]:
        raise _Missing(f"not in the results: {', '.join(missing)}")
    return at


def _complete(run: Mapping) -> bool:
    """Whether a run trained every model it planned (``progress`` of `pushjax.paper.full_run`; other runs are)."""
    return not run.get("progress", {}).get("missing")


def _choose(results: Results, names: Sequence[str]) -> str | None:
    """The first of `names` in `results` that is complete, else the first present, else None."""
    present = [name for name in names if name in results]
    return next((name for name in present if _complete(results[name])), present[0] if present else None)


def _data_efficiency(results: Results) -> Mapping:
    """The run of `DATA_EFFICIENCY_RUNS` that decides the Table 1 findings (`_choose`)."""
    name = _choose(results, DATA_EFFICIENCY_RUNS)
    if name is None:
        raise _Missing(f"no {' or '.join(DATA_EFFICIENCY_RUNS)} results")
    return results[name]


def _small_data(results: Results):
    run = _data_efficiency(results)
    size = _sizes(run)[0]
    at = _need(cells(run, kind="trained", train_size=size), ("hybrid", "error", "neural", "simple"))
    comparisons = _pairs(at, ("hybrid", "error"), ("neural", "simple"))
    return comparisons, f"at {size} examples: " + _listing({m: at[m] for m in ("hybrid", "error", "neural", "simple")})


def _most_data(results: Results):
    run = _data_efficiency(results)
    size = _sizes(run)[-1]
    at = _need(cells(run, kind="trained", train_size=size), ("neural", "simple", "hybrid", "error"))
    comparisons = _pairs(at, ("neural",), ("simple", "hybrid", "error"))
    return comparisons, f"at {size} examples: " + _listing({m: at[m] for m in ("neural", "simple", "hybrid", "error")})


def _crossing(sizes: Sequence[int], differences: Sequence[float]) -> float | None:
    """Where `differences` (neural − hybrid per size) first turn negative, interpolated in log(size) between the
    last size at which it is >= 0 and the next; the smallest size when it is negative from the start; None when
    it never is."""
    for index, value in enumerate(differences):
        if value < 0:
            if index == 0:
                return float(sizes[0])
            before, after = differences[index - 1], value
            fraction = before / (before - after)
            low, high = math.log(sizes[index - 1]), math.log(sizes[index])
            return float(math.exp(low + fraction * (high - low)))
    return None


def crossover(run: Mapping, better: str = "neural", worse: str = "hybrid") -> dict:
    """Where `better` overtakes `worse` over the training sizes of `run`.

    Returns a dict: ``sizes``; ``differences`` (`Estimate` of better − worse per size, paired over sequences);
    ``decided`` (the smallest size at which `pushjax.stats.decide` finds better better, or None);
    ``estimate`` (`_crossing` of the mean differences, or None); ``interval`` ((low, high) of `_crossing` over
    the sequence-bootstrap replicates of the differences, a `CROSSOVER_LEVEL` percentile interval; None for a
    bound beyond the largest size, i.e. more than (1 − level) / 2 of the replicates do not cross; the whole
    interval None without replicates); ``not_crossing`` (the share of replicates that never cross).
    """
    sizes = _sizes(run)
    differences = []
    for size in sizes:
        at = _need(cells(run, kind="trained", train_size=size), (better, worse))
        differences.append(statistics.difference(at[better], at[worse]))
    decided = next((size for size, d in zip(sizes, differences) if stats.decide(d.value, d.se) == HOLDS), None)
    estimate = _crossing(sizes, [d.value for d in differences])
    interval, not_crossing = None, None
    if differences and all(d.replicates is not None for d in differences):
        replicates = np.stack([d.replicates for d in differences], axis=1)  # [B, sizes]
        crossings = [_crossing(sizes, row) for row in replicates]
        not_crossing = sum(c is None for c in crossings) / len(crossings)
        ordered = np.sort([math.inf if c is None else c for c in crossings])
        tail = (1.0 - CROSSOVER_LEVEL) / 2.0
        bounds = [float(np.quantile(ordered, q, method="lower" if q < 0.5 else "higher")) for q in (tail, 1 - tail)]
        interval = tuple(None if math.isinf(b) else b for b in bounds)
    return {"sizes": sizes, "differences": differences, "decided": decided, "estimate": estimate,
            "interval": interval, "not_crossing": not_crossing}


def _size_text(size: float | None, largest: int) -> str:
    return f"> {largest}" if size is None else f"{size:,.0f}".replace(",", " ")


def _crossover(results: Results):
    run = _data_efficiency(results)
    found = crossover(run)
    sizes, largest = found["sizes"], found["sizes"][-1]
    text = ("neural − hybrid by size: " + ", ".join(f"{size}: {d}" for size, d in zip(sizes, found["differences"]))
            + f"; first size where neural is better by {stats.DECISION_STANDARD_ERRORS:g} s.e.: "
            + ("none" if found["decided"] is None else str(found["decided"]))
            + f"; crossing (log-size interpolation): {_size_text(found['estimate'], largest)}")
    if found["interval"] is not None:
        low, high = found["interval"]
        text += (f", {CROSSOVER_LEVEL:.0%} sequence-bootstrap interval [{_size_text(low, largest)}, "
                 f"{_size_text(high, largest)}] ({found['not_crossing']:.0%} of the replicates do not cross)")
    comparisons = [Comparison(f"{largest}: neural − hybrid", found["differences"][-1])]
    return comparisons, text


def _hybrid_first(results: Results):
    run = _data_efficiency(results)
    small = [size for size in _sizes(run) if size <= SMALL_DATA_MAX]
    if not small:
        raise _Missing(f"no training size up to {SMALL_DATA_MAX}")
    comparisons, parts = [], []
    for size in small:
        at = _need(cells(run, kind="trained", train_size=size), ("hybrid", "neural"))
        others = [model for model in ("neural", "simple", "neural_dyn") if model in at]
        comparisons += _pairs(at, ("hybrid",), others, prefix=f"{size}: ")
        parts.append(f"at {size}: " + _listing({m: at[m] for m in ("hybrid", *others)}))
    return comparisons, "; ".join(parts)


def _only_neural_error(results: Results):
    run = _data_efficiency(results)
    size = _sizes(run)[-1]
    at = dict(_need(cells(run, kind="trained", train_size=size), ("neural", "error", "hybrid", "simple")))
    at.update(_need(cells(run, kind="baseline"), ("physics",)))
    others = [model for model in ("hybrid", "simple", "neural_dyn") if model in at]
    comparisons = _pairs(at, ("neural", "error"), ("physics",)) + _pairs(at, ("physics",), others)
    return comparisons, f"at {size} examples: " + _listing({m: at[m] for m in ("physics", "neural", "error", *others)})


def _neural_dyn(results: Results):
    run = _data_efficiency(results)
    size = _sizes(run)[-1]
    at = _need(cells(run, kind="trained", train_size=size), ("neural", "neural_dyn"))
    return _pairs(at, ("neural",), ("neural_dyn",)), f"at {size} examples: " + _listing(
        {m: at[m] for m in ("neural", "neural_dyn")})


def _error_velocities(results: Results):
    run = results["velocities"]
    several = sorted({row["train_split"] for row in run["rows"] if row["kind"] == "trained"} - {"train_20"})
    if not several:
        raise _Missing("needs models trained on more than one velocity")
    one = _degradation(run, "train_20", ("hybrid", "error"))
    comparisons = [_compare("train_20: hybrid − error", one["hybrid"], one["error"])]
    parts = ["train_20: " + _listing(one)]
    for split in several:
        more = _degradation(run, split, ("error",))
        comparisons.append(_compare(f"error {split} − train_20", more["error"], one["error"]))
        parts.append(f"{split}: error {more['error']}")
    return comparisons, "mean score over the tests faster than 20 mm/s minus the score at 20 mm/s: " + "; ".join(parts)


def _rotation_data(results: Results):
    run = _data_efficiency(results)
    sizes = _sizes(run)
    if len(sizes) < 2:
        raise _Missing("needs two training sizes")
    models = ("neural", "hybrid", "error")
    gains = {}
    for metric in ("trans_percent", "rot_percent"):
        small = _need(cells(run, metric, kind="trained", train_size=sizes[0]), models)
        large = _need(cells(run, metric, kind="trained", train_size=sizes[-1]), models)
        gains[metric] = {model: statistics.difference(small[model], large[model]) for model in models}
    comparisons = [_compare(f"{model}: translation gain − rotation gain", gains["trans_percent"][model],
                            gains["rot_percent"][model]) for model in models]
    return comparisons, (f"points of % of zero gained from {sizes[0]} to {sizes[-1]} examples: " + "; ".join(
        f"{model} translation {gains['trans_percent'][model]}, rotation {gains['rot_percent'][model]}"
        for model in models))


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


# "Improves for all models" is checked on all of the paper's Fig. 6 models, not on a run's subset (``--variants``);
# in the order the evidence lists them.
FIG6_MODELS = ("error", "hybrid", "neural", "neural_dyn", "simple")


def _faster_training(results: Results):
    run = results["velocities"]
    faster = _faster_tests(run, 50.0)
    only_20 = _mean_over(run, faster, kind="trained", train_split="train_20")
    with_50 = _mean_over(run, faster, kind="trained", train_split="train_20_50")
    _need(only_20, FIG6_MODELS)
    _need(with_50, FIG6_MODELS)
    comparisons = [_compare(f"{model} (20 + 50) − (20)", with_50[model], only_20[model]) for model in FIG6_MODELS]
    return comparisons, f"mean over {', '.join(faster)}: " + "; ".join(
        f"{model} {only_20[model]} (20) → {with_50[model]} (20 + 50)" for model in FIG6_MODELS)


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


def view_cost(top_down: Mapping, free: Mapping, metric: str = "trans_percent", model: str = "hybrid") -> dict:
    """What the free camera costs `model` (Sec. V), compared on each view's own test split against physics.

    The two views are tested on different splits (``data_efficiency`` and ``viewpoint``), so each view's error is
    first taken against the physics baseline on the same sequences (a paired bootstrap), and the cost is the
    difference of those two: (free − physics on free's split) − (top-down − physics on top-down's split), their
    standard errors combined as independent. Both at each run's largest training size.

    Returns:
      {"top_down": Estimate, "free": Estimate (model − physics on each split), "cost": Estimate, "sizes": (top, free)}.
    """
    against = {}
    sizes = []
    for name, run in (("top_down", top_down), ("free", free)):
        size = _sizes(run)[-1]
        trained = _need(cells(run, metric, kind="trained", train_size=size), (model,))
        baseline = _need(cells(run, metric, kind="baseline"), ("physics",))
        against[name] = statistics.difference(trained[model], baseline["physics"])
        sizes.append(size)
    return {**against, "cost": statistics.difference(against["free"], against["top_down"]), "sizes": tuple(sizes)}


_DATA_EFFICIENCY = "|".join(DATA_EFFICIENCY_RUNS)

CHECKS: dict[str, tuple[str, str, Callable[[Results], tuple[list[Comparison], str]]]] = {
    "small_data": ("With 2.5 k training examples, hybrid and error beat neural and simple clearly (Table 1).",
                   _DATA_EFFICIENCY, _small_data),
    "most_data": ("With the most training data, neural is best (Table 1: 17.4 / 33.4 % at 190 k).",
                  _DATA_EFFICIENCY, _most_data),
    "crossover": ("With enough data, neural overtakes hybrid (Table 1: hybrid better at 2.5 k, neural at 190 k); "
                  "where it crosses, with its sequence-bootstrap interval.", _DATA_EFFICIENCY, _crossover),
    "hybrid_first": ("It takes more than 20 k training examples for the other models (neural, simple, neural_dyn) "
                     "to reach hybrid: hybrid beats them at every size up to 20 k (Table 1).", _DATA_EFFICIENCY,
                     _hybrid_first),
    "only_neural_error": ("With the full training set only neural and error improve on physics; hybrid, simple and "
                          "neural_dyn do not (Table 1).", _DATA_EFFICIENCY, _only_neural_error),
    "neural_dyn": ("neural_dyn is worse than neural on the full training set (Table 1).", _DATA_EFFICIENCY,
                   _neural_dyn),
    "rotation_data": ("Rotation needs more data than translation: from 2.5 k to the full set neural, hybrid and "
                      "error gain more points (% of zero) in rotation than in translation (Table 1).",
                      _DATA_EFFICIENCY, _rotation_data),
    "new_pushes": ("On new pushes (held-out angles and contact points), hybrid and error beat neural (Table 3).",
                   "new_pushes", _new_pushes),
    "extrapolation": ("Trained at 20 mm/s, hybrid is the most constant over velocities; neural and neural_dyn "
                      "degrade at higher velocities (Fig. 6).", "velocities", _extrapolation),
    "faster_training": ("Adding 50 mm/s to training improves extrapolation for all models (Fig. 6).",
                        "velocities", _faster_training),
    "error_velocities": ("error extrapolates well only when trained on more than one velocity: trained at 20 mm/s "
                         "it degrades more than hybrid, trained on two velocities it degrades less than at 20 mm/s "
                         "alone (Fig. 6).", "velocities", _error_velocities),
    "wrong_l": ("With a wrong l (× 1.5, × 3), error compensates better than hybrid (Table 5).", "error_variants",
                _wrong_l),
    "error_grad": ("Trained at 20 mm/s, error_grad extrapolates worse than neural (Fig. 9).", "error_velocities",
                   _error_grad),
    "error_norm": ("error_norm extrapolates best of the error variants but still worse than hybrid (Fig. 9).",
                   "error_velocities", _error_norm),
    "unseen_objects": ("neural is consistently worse than the others at predicting the rotation of unseen "
                       "objects (Fig. 7).", "objects", _unseen_objects),
}
"""key -> (the paper's finding, the binary whose results decide it (alternatives joined by ``|``, the first present
is read), the comparisons it makes)."""

FULL_SET_CHECKS = frozenset({"most_data", "crossover", "only_neural_error", "neural_dyn", "rotation_data"})
"""The findings whose condition is the paper's full training set: "not reached at N" below `FULL_SET_MIN`."""


def _verdict(key: str, comparisons: Sequence[Comparison], results: Results, experiment: str) -> str:
    verdict = _decide(comparisons)
    if key in FULL_SET_CHECKS and verdict != HOLDS:
        largest = _sizes(results[experiment])[-1]
        if largest < FULL_SET_MIN:
            return NOT_REACHED.format(size=largest)
    return verdict


def check(results: Results) -> list[Finding]:
    """Every finding of `CHECKS` decided on `results` (binary name -> results.json contents)."""
    findings = []
    for key, (statement, experiments, comparisons_of) in CHECKS.items():
        experiment = _choose(results, experiments.split("|"))
        if experiment is None:
            findings.append(Finding(key, statement, experiments.split("|")[-1], UNCHECKED,
                                    f"no {' or '.join(experiments.split('|'))} results"))
            continue
        try:
            comparisons, evidence = comparisons_of(results)
        except _Missing as missing:
            findings.append(Finding(key, statement, experiment, UNCHECKED, str(missing)))
            continue
        evidence += "; differences (better − worse, ± s.e.): " + ", ".join(map(str, comparisons))
        findings.append(Finding(key, statement, experiment, _verdict(key, comparisons, results, experiment), evidence))
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


def side_by_side(before: Sequence[Finding], after: Sequence[Finding], labels: tuple[str, str]) -> str:
    """Two decisions of the same findings (e.g. on models trained two ways) as one markdown table: each finding's
    verdict under `labels[0]` and `labels[1]`, whether it changed, and the second's evidence."""
    by_key = {finding.key: finding for finding in before}
    lines = [_rule_line(), "",
             f"| finding (the paper's) | experiment | {labels[0]} | {labels[1]} | changed | evidence ({labels[1]}) |",
             "|---|---|---|---|---|---|"]
    for finding in after:
        old = by_key.get(finding.key)
        verdict = old.verdict if old is not None else UNCHECKED
        lines.append(f"| {finding.statement} | {finding.experiment} | {verdict} | {finding.verdict} | "
                     f"{'yes' if verdict != finding.verdict else ''} | {finding.evidence} |")
    return "\n".join(lines)


def _rule_line() -> str:
    """How the tables' verdicts are decided, the first line of each."""
    return (f"Decided at {stats.DECISION_STANDARD_ERRORS:g} standard errors of the difference (`pushjax.stats.decide`, "
            "one look per run, comparisons uncorrected); scores are "
            "the mean of trans. and rot. in % of zero, ± s.e. (sequence bootstrap and seed spread); \"not reached at N\": "
            f"a finding about the paper's full set (190 k) that does not hold at our largest size N < {FULL_SET_MIN}.")


def markdown(findings: Sequence[Finding]) -> str:
    """The findings as a markdown table."""
    lines = [_rule_line(), "", "| finding (the paper's) | experiment | on our testbed | evidence |", "|---|---|---|---|"]
    lines += [f"| {f.statement} | {f.experiment} | {f.verdict} | {f.evidence} |" for f in findings]
    return "\n".join(lines)
