r"""Which of the paper's qualitative findings hold, from the results of the experiment binaries.

  python -m experiments.findings --workdirs=DIR[,DIR...] [--output=FILE] [--replace_with=DIR]

Each DIR is the --workdir of a finished run of data_efficiency, data_efficiency_full, new_pushes, velocities,
error_velocities, error_variants or objects; prints (and with --output writes) a markdown table: the paper's finding,
the verdict on our testbed (holds / does not hold / not decided / not checked / not reached at N, criteria in
`pushjax.paper.findings`) and the numbers behind it.

With --replace_with=DIR (a ``data_efficiency_full``-style run of some of its cells, e.g. the models at the full split
trained for the paper's 75 000 steps: results/data_efficiency_long), the findings are decided twice: as the workdirs
give them and with the ``data_efficiency_full`` cells DIR recorded replaced by its models
(`pushjax.paper.full_run.with_models_of`), the two verdicts side by side.
"""

from pathlib import Path

from absl import app, flags

import experiments
from pushjax.paper import findings, full_run, paths

_WORKDIRS = flags.DEFINE_list("workdirs", None, "Work directories holding results.json files (required).")
_OUTPUT = flags.DEFINE_string("output", None, "Also write the table to this file (its folder is created).")
_REPLACE_WITH = flags.DEFINE_string("replace_with", None, "A run whose recorded cells replace data_efficiency_full's; "
                                    "the findings are decided both ways, side by side.")


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    if not _WORKDIRS.value:
        raise app.UsageError("--workdirs: expected one or more work directories holding results.json")
    if _OUTPUT.value is not None:
        check_output_file(_OUTPUT.value)
    try:
        results = findings.load(_WORKDIRS.value)
    except (FileNotFoundError, ValueError) as error:
        raise app.UsageError(f"--{error}") from error
    table = findings.markdown(findings.check(results))
    if _REPLACE_WITH.value is not None:
        if "data_efficiency_full" not in results:
            raise app.UsageError("--replace_with: needs a data_efficiency_full run among --workdirs")
        if not full_run.records(_REPLACE_WITH.value):
            raise app.UsageError(f"--replace_with: no model records in {_REPLACE_WITH.value}/models")
        replaced = {**results, "data_efficiency_full": full_run.with_models_of(results["data_efficiency_full"],
                                                                               _REPLACE_WITH.value)}
        table = findings.side_by_side(findings.check(results), findings.check(replaced),
                                      ("as run", f"with {_REPLACE_WITH.value}"))
    print(table)
    if _OUTPUT.value is None:
        print("wrote no files: the table above is the whole output (--output also writes it to a file)")
        return
    output = Path(_OUTPUT.value)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(table + "\n")
    print(f"wrote the table to {output}")


def check_output_file(output: str) -> None:
    """Raises ``app.UsageError`` unless the table can be written to `output`."""
    if Path(output).is_dir() or not Path(output).name:
        raise app.UsageError(f"--output={output}: expected a file name, got a folder")
    try:
        paths.check_writable_folder(Path(output).parent)
    except ValueError as error:
        raise app.UsageError(f"--output={output}: {error}") from None


if __name__ == "__main__":
    experiments.run(main)
