r"""Which of the paper's qualitative findings hold, from the results of the experiment binaries.

  python -m experiments.findings --workdirs=DIR[,DIR...] [--output=FILE]

Each DIR is the --workdir of a finished run of data_efficiency, new_pushes, velocities or error_variants;
prints (and with --output writes) a markdown table: finding, verdict and the numbers behind it.
"""

from absl import app, flags

from pushjax.experiments import findings

_WORKDIRS = flags.DEFINE_list("workdirs", None, "Work directories holding results.json files.", required=True)
_OUTPUT = flags.DEFINE_string("output", None, "Also write the table to this file.")


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    try:
        results = findings.load(_WORKDIRS.value)
    except (FileNotFoundError, ValueError) as error:
        raise app.UsageError(str(error)) from error
    table = findings.markdown(findings.check(results))
    print(table)
    if _OUTPUT.value:
        with open(_OUTPUT.value, "w") as file:
            file.write(table + "\n")


if __name__ == "__main__":
    app.run(main)
