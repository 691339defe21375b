r"""Decompose the physics baseline's error on Table 1's test split into tracking noise, push-to-push randomness
and what is left (issue 50).

  python -m experiments.residual_decomposition --data_dir=work/data --workdir=results/residual_decomposition
      [--scale=cpu_full] [--max_sequences=N]

Simulates every test push of the built ``data_efficiency`` dataset again (checking that it reproduces its stored file
bit for bit) for its true poses and drawn parameters, scores Lynch's model told more and more of them on the same
examples (``pushjax.paper.residual``), and writes ``results.json`` and ``results.md`` to ``--workdir``.
``--max_sequences`` keeps every k-th test sequence (k the smallest that keeps at most N).
"""

from absl import app, flags

import experiments
from pushjax.paper import cli, residual

# --workdir (where results.json and results.md go), --data_dir (the built dataset and its raw push cache), --scale
# (default here: cpu_full): pushjax.paper.cli's.
flags.adopt_module_key_flags(cli)
_MAX_SEQUENCES = flags.DEFINE_integer("max_sequences", None, "At most this many test sequences, every k-th of the "
                                      "split (default: all).", lower_bound=1)


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {argv[1:]}")
    for name in ("workdir", "data_dir"):
        if flags.FLAGS[name].value is None:
            raise app.UsageError(f"--{name}: expected a value (the flag is required)")
    scale = cli.SCALE.value if flags.FLAGS["scale"].present else residual.DEFAULT_SCALE
    try:
        residual.dataset_builder(cli.DATA_DIR.value, scale)
    except ValueError as error:
        raise app.UsageError(f"--{error}") from None
    results = residual.decompose(cli.DATA_DIR.value, scale, _MAX_SEQUENCES.value)
    paths = residual.write(results, cli.WORKDIR.value)
    rows = {row["component"]: row for row in results["rows"]}
    print(f"physics {rows['physics']['trans_percent']:.1f} / {rows['physics']['rot_percent']:.1f} % of zero; "
          f"noise-free {rows['clean_state']['trans_percent']:.1f} / {rows['clean_state']['rot_percent']:.1f}; with the "
          f"drawn parameters {rows['drawn_load']['trans_percent']:.1f} / {rows['drawn_load']['rot_percent']:.1f} "
          f"({results['sequences']} sequences); wrote {', '.join(map(str, paths))}")


if __name__ == "__main__":
    experiments.run(main)
