"""The whole loop on a directory of pushes: examples → baseline → diagnosis → effects → report."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import numpy as np
import tqdm

from pushjax.loop import correction as correction_lib
from pushjax.loop import diagnose as diagnose_lib
from pushjax.loop import fit as fit_lib
from pushjax.loop import metrics
from pushjax.loop import report as report_lib
from pushjax.loop import select as select_lib
from pushjax.loop.windows import NOMINAL_PUSHER_FRICTION, build_examples, split_by_sequence
from pushjax.mit.files import iter_pushes


@dataclasses.dataclass(frozen=True)
class LoopSettings:
    """Settings of :func:`close_loop`.

    Attributes:
      horizon: prediction window, s.
      stride: time between window starts, s (default ``horizon / 2``).
      heldout_fraction: share of push sequences held out.
      pusher_friction: nominal pusher-object friction coefficient.
      min_gain: relative held-out error cut an effect must reach at its lower bound to be selected.
      min_strength: share of the error a variable's correction must remove to count as structure.
      alpha: family-wise error level of the selection and diagnosis decisions.
      n_bootstrap: bootstrap resamplings of push sequences.
      fit: optimiser settings of the effect fits.
      correction: training settings of the fallback error term.
    """

    horizon: float = 0.5
    stride: float | None = None
    heldout_fraction: float = 0.3
    pusher_friction: float = NOMINAL_PUSHER_FRICTION
    min_gain: float = select_lib.MIN_GAIN
    min_strength: float = diagnose_lib.MIN_STRENGTH
    alpha: float = 0.05
    n_bootstrap: int = 1000
    fit: fit_lib.FitSettings = fit_lib.FitSettings()
    correction: correction_lib.CorrectionSettings = correction_lib.CorrectionSettings()


def _dependences(dependences: list[diagnose_lib.Dependence]) -> list[dict]:
    return [dataclasses.asdict(d) for d in dependences]


def close_loop(
    data_dir: str | os.PathLike,
    workdir: str | os.PathLike,
    settings: LoopSettings = LoopSettings(),
    seed: int = 0,
    progress: bool = True,
) -> dict:
    """Runs the loop and writes ``report.json``, ``details.json``, ``report.md`` and figures to ``workdir``.

    Args:
      data_dir: root of pushes in the raw MIT layout (``<surface>/<object>/motion_surface=...h5``).
      workdir: output directory (created).
      settings: the loop's settings.
      seed: seed of the split, the bootstraps, the cross-fitting folds and the error term.
      progress: show tqdm progress bars.

    Returns:
      The content of ``report.json``.

    Raises:
      ValueError: ``data_dir`` is not a directory or holds no usable push.
    """
    data_dir = Path(data_dir)
    if not data_dir.is_dir():
        raise ValueError(f"data_dir: {str(data_dir)!r} is not a directory")
    pushes = iter_pushes(data_dir)
    if not pushes.paths:
        raise ValueError(f"data_dir: no push files (motion_surface=...h5) below {str(data_dir)!r}; "
                         f"{pushes.summary()}")
    workdir = Path(workdir)
    (workdir / report_lib.FIGURE_DIR).mkdir(parents=True, exist_ok=True)
    stages = tqdm.tqdm(total=6, desc="close loop", unit="stage", disable=not progress)

    def stage(message: str) -> None:
        stages.set_postfix_str(message)

    stage("loading pushes")
    loading = tqdm.tqdm(pushes, total=len(pushes.paths), desc="pushes", unit="push", disable=not progress,
                        leave=False)
    try:
        examples, build = build_examples(loading, horizon=settings.horizon, stride=settings.stride,
                                         pusher_friction=settings.pusher_friction)
    except ValueError as error:
        raise ValueError(f"data_dir: {error}") from None
    n_skipped = pushes.n_skipped + build.n_skipped
    fit, heldout = split_by_sequence(examples, settings.heldout_fraction, seed)
    stages.update()

    stage("diagnosing the plain model")
    baseline_all = fit_lib.predict([None], examples)[0]
    diagnose = dict(min_strength=settings.min_strength, n_bootstrap=settings.n_bootstrap, alpha=settings.alpha,
                    seed=seed)
    variables = [name for name, values in examples.variables.items() if len(np.unique(values)) > 1]
    before = diagnose_lib.diagnose(examples, baseline_all, variables, **diagnose)
    stages.update()

    selection = select_lib.select_effects(
        fit, heldout, settings=settings.fit, min_gain=settings.min_gain, alpha=settings.alpha,
        n_bootstrap=settings.n_bootstrap, seed=seed, progress=stage)
    stages.update()

    stage("diagnosing the selected model")
    final = selection.final
    final_all = fit_lib.predict([final.fit], examples)[0]
    after = diagnose_lib.diagnose(examples, final_all, variables, **diagnose)
    structured = [d for d in after if d.beyond_noise]
    stages.update()

    fallback = None
    if structured:
        stage("fitting the error-correction fallback")
        fit_prediction = fit_lib.predict([final.fit], fit)[0]
        heldout_prediction = fit_lib.predict([final.fit], heldout)[0]
        correction = correction_lib.fit_error_correction(fit, fit_prediction, settings.correction, seed)
        corrected = correction(heldout, heldout_prediction)
        fallback = {"heldout": report_lib.as_summary(metrics.summarize(
            metrics.window_errors(corrected, heldout.target, heldout.sequence)))}
    stages.update()

    stage("writing the report")
    report = {
        "n_pushes": {"fit": fit.n_pushes, "heldout": heldout.n_pushes, "skipped": int(n_skipped)},
        "baseline": report_lib.as_summary(selection.baseline.heldout),
        "diagnosis": [{"variable": d.variable, "strength": d.strength} for d in before],
        "ranking": [{"effect": c.effects[0], "params": c.fit.physical[c.effects[0]],
                     "heldout": report_lib.as_summary(c.heldout)} for c in selection.ranking],
        "selected": selection.selected,
        "after": report_lib.as_summary(final.heldout),
        "explained": not structured,
        "fallback": fallback,
    }
    details = {
        "data_dir": str(data_dir),
        "horizon": settings.horizon,
        "seed": seed,
        "pusher_friction": settings.pusher_friction,
        "min_gain": settings.min_gain,
        "n_windows": {"fit": len(fit), "heldout": len(heldout)},
        "skipped": {**{reason: [p.name for p in paths] for reason, paths in pushes.skipped.items()},
                    **build.skipped},
        "diagnosis_before": _dependences(before),
        "diagnosis_after": _dependences(after),
        "unexplained_variable": dataclasses.asdict(structured[0]) if structured else None,
        "rounds": [{"gains": dict(zip(r.additions, r.gains)), "lower": r.lower, "accepted": r.accepted}
                   for r in selection.rounds],
        "selected_params": final.fit.physical if final.fit is not None else {},
    }
    report_lib.write_json(workdir / "report.json", report)
    report_lib.write_json(workdir / "details.json", details)
    figures = workdir / report_lib.FIGURE_DIR
    report_lib.residual_figure(figures / "residual_baseline.png", examples, baseline_all,
                               "Residual of the plain model (median per bin)", variables)
    report_lib.residual_figure(figures / "residual_after.png", examples, final_all,
                               "Residual after the fix: " + (" + ".join(selection.selected) or "nothing selected"),
                               variables)
    report_lib.strength_figure(figures / "diagnosis.png", before, after)
    (workdir / "report.md").write_text(report_lib.markdown(report, details))
    stages.update()
    stages.close()
    return report
