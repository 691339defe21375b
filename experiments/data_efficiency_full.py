r"""Table 1 at the paper's composition and sizes, each model trained to convergence (issue 30).

  python -m experiments.data_efficiency_full --workdir=results/data_efficiency_full --data_dir=work/data \
      [--scale=cpu_full|paper_full] [--sizes=2500,5000,10000,20000,50000,100000,190080] [--seeds=0,1,2] [--nowide] \
      [--max_models=N] [--deadline=2026-11-26T11:00] [--models_at_once=2] [--criterion=eval_every=1000;window=5] \
      [--only=neural_190080_seed0_wide,hybrid_190080_seed0_wide] [--variants=neural,hybrid,error]
      [--schedule=criterion|paper] [--steps=75000]

The paper's training instead of the criterion (``--schedule=paper``: Adam at a constant 10^-4, batch 32, --steps
steps, no early stop, the validation score recorded every 1 000 steps; `pushjax.train.convergence.PAPER_SCHEDULE`),
e.g. the long-trained models of Table 1 at the full split:

  python -m experiments.data_efficiency_full --workdir=results/data_efficiency_long --data_dir=work/data \
      --schedule=paper --sizes=190080 --variants=neural,hybrid,error --nowide

A model of that schedule keeps its training state in ``<workdir>/in_training/``, so the same command with a larger
--steps continues its recorded models to the new length.

Without --scale, --sizes and --seeds: cpu_full, the sizes above and seeds 0, 1 and 2 (paper_full: the same pushes
at the paper's images and widths, for a GPU: benchmarks/paper_full_gpu.sh) (the shared flags of
`pushjax.paper.cli`; --num_steps, --mode and the multi-process flags are not used here).

Trains every model of `pushjax.paper.full_run.plan` that has no record in ``<workdir>/models/`` (neural, hybrid and
error at every size, simple and neural_dyn at 2 500, 20 000 and the full split, 3 seeds, neural and hybrid at the
paper's widths once), each by the convergence criterion of `pushjax.train.convergence`, and writes each model's record
as it finishes (--models_at_once of them at the same time, in threads: on 2 cores two train 1.15-1.4x the steps per
second of one, and a model's record does not depend on it); then results.json, results.md and the figures from every record. Keep (commit) the records and a
later call resumes with the models still missing; the dataset is built from its seed when it is missing.
"""

import dataclasses
import datetime

from absl import app, flags

import experiments
from pushjax.paper import cli, figures, full_run, paths, reference, runner, spec as spec_lib, tables
from pushjax.train import convergence

# --workdir, --data_dir, --scale, --sizes, --seeds, --build, --workers: pushjax.paper.cli's.
flags.adopt_module_key_flags(cli)
_SIDE_SIZES = flags.DEFINE_list("side_sizes", [str(size) for size in full_run.SIDE_SIZES],
                                "Sizes at which simple and neural_dyn train too.")
_WIDE = flags.DEFINE_bool("wide", True, "Train neural and hybrid at the paper's widths at the largest size.")
_MAX_MODELS = flags.DEFINE_integer("max_models", None, "Train at most this many models in this call.", lower_bound=0)
_DEADLINE = flags.DEFINE_string("deadline", None, "Start no model after this UTC time (ISO 8601, e.g. 2026-11-26T11:00).")
_MODELS_AT_ONCE = flags.DEFINE_integer("models_at_once", 2, "Models trained at the same time (threads sharing the "
                                       "training split; the records do not depend on it).", lower_bound=1)
_ONLY = flags.DEFINE_list("only", None, "Train only these models of the plan (their keys, e.g. "
                          "hybrid_190080_seed0_wide), in this order: e.g. the slowest ones on a lent GPU.")
_CRITERION = flags.DEFINE_string("criterion", "", "Overrides of the convergence criterion, 'name=value;...' (tests).")
_SCHEDULE = flags.DEFINE_enum("schedule", "criterion", ["criterion", "paper"],
                              "criterion: the convergence criterion; paper: the paper's constant 1e-4 for --steps steps, "
                              "no early stop.")
_STEPS = flags.DEFINE_integer("steps", convergence.PAPER_STEPS, "Steps of --schedule=paper (a multiple of 1000).",
                              lower_bound=1)


def criterion_from_flag(text: str, base: convergence.Criterion = convergence.CRITERION) -> convergence.Criterion:
    """`base` with the overrides of ``--criterion``; raises ``app.UsageError`` naming a bad one."""
    fields = {field.name: field.type for field in dataclasses.fields(convergence.Criterion)}
    overrides = {}
    for item in filter(None, (part.strip() for part in text.split(";"))):
        name, _, value = item.partition("=")
        if name not in fields:
            raise app.UsageError(f"--criterion: unknown field {name!r}; choose from {', '.join(fields)}")
        try:
            if fields[name] == "bool":
                if value not in ("true", "false"):
                    raise ValueError(value)
                overrides[name] = value == "true"
            else:
                overrides[name] = float(value) if fields[name] == "float" else int(value)
        except ValueError:
            raise app.UsageError(f"--criterion: {name} expects a {fields[name]}, got {value!r}") from None
    try:
        return dataclasses.replace(base, **overrides)
    except ValueError as error:
        raise app.UsageError(f"--criterion: {error}") from None


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {argv[1:]}")
    workdir = cli.WORKDIR.value
    if workdir is None:
        raise app.UsageError("--workdir: expected a value (the flag is required)")
    try:
        paths.check_writable_folder(workdir)
    except ValueError as error:
        raise app.UsageError(f"--workdir={workdir}: {error}") from error
    try:
        reference.tables()
    except ValueError as error:
        raise app.UsageError(str(error)) from error
    given = lambda name: flags.FLAGS[name].present  # noqa: E731
    scale = cli.SCALE.value if given("scale") else full_run.SCALE
    try:
        sizes = spec_lib.parse_sizes(cli.SIZES.value) if given("sizes") else full_run.SIZES
        side_sizes = spec_lib.parse_sizes(_SIDE_SIZES.value)
        seeds = spec_lib.parse_seeds(cli.SEEDS.value) if given("seeds") else full_run.SEEDS
        paper = _SCHEDULE.value == "paper"
        spec = full_run.make_spec(cli.DATA_DIR.value, sizes=sizes, seeds=seeds, scale=scale, build=cli.BUILD.value,
                                  workers=cli.WORKERS.value, paper_training=paper)
        units = full_run.plan(sizes, seeds, side_sizes, _WIDE.value, cli.VARIANTS_FLAG.value or None)
    except ValueError as error:
        raise app.UsageError(f"--{error}") from error
    deadline = None
    if _DEADLINE.value:
        try:
            deadline = datetime.datetime.fromisoformat(_DEADLINE.value).replace(tzinfo=datetime.timezone.utc)
        except ValueError:
            raise app.UsageError(f"--deadline: expected an ISO 8601 time, got {_DEADLINE.value!r}") from None
    base = convergence.CRITERION
    if _SCHEDULE.value == "paper":
        try:
            base = convergence.fixed_budget(_STEPS.value)
        except ValueError as error:
            raise app.UsageError(f"--{error}") from None
    criterion = criterion_from_flag(_CRITERION.value, base)
    if _ONLY.value is not None:
        try:
            units = full_run.select(units, _ONLY.value)
        except ValueError as error:
            raise app.UsageError(f"--only: {error}") from None

    def publish(results):
        tables.write(results, workdir)
        figures.plot(results, workdir)

    try:
        results = full_run.run(spec, workdir, units, max_models=_MAX_MODELS.value, deadline=deadline,
                               criterion=criterion, publish=publish, models_at_once=_MODELS_AT_ONCE.value)
    except runner.DatasetUnavailableError as error:
        raise app.UsageError(f"--{error}") from error
    progress = results["progress"]
    print(f"wrote results.json, results.md and figures to {workdir}: {progress['done']} of "
          f"{progress['planned']} models recorded")


if __name__ == "__main__":
    experiments.run(main)
