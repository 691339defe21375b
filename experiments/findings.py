r"""Which of the paper's qualitative findings hold, from the results of the experiment binaries.

  python -m experiments.findings --workdirs=DIR[,DIR...] [--output=FILE]

Each DIR is the --workdir of a finished run of data_efficiency, data_efficiency_full, new_pushes, velocities,
error_velocities, error_variants or objects; prints (and with --output writes) a markdown table: the paper's finding,
the verdict on our testbed (holds / does not hold / not decidable / not checked / not reached at N, criteria in
`pushjax.paper.findings`) and the numbers behind it.
"""

from pathlib import Path

from absl import app, flags

import experiments
from pushjax.paper import findings, paths

_WORKDIRS = flags.DEFINE_list("workdirs", None, "Work directories holding results.json files (required).")
_OUTPUT = flags.DEFINE_string("output", None, "Also write the table to this file (its folder is created).")


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
