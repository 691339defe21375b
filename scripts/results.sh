#!/bin/bash
# The runs behind RESULTS.md: every experiment binary at cpu scale, then the findings table.
#
#   bash scripts/results.sh [RUNS_DIR]      (default: work/results; about 2 h on 2 CPU cores)
#
# error_variants at l = 1 trains exactly data_efficiency's hybrid and error-variant sweeps (same
# specs, seeds and subsets), so their finished checkpoints are copied over and only the l = 1.5 and
# l = 3 models are trained. velocities and objects run 2 500 steps instead of the cpu
# config's 5 000 to fit the session that produced RESULTS.md.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-work/results}
export MUJOCO_GL=${MUJOCO_GL:-egl}
python=${PYTHON:-.venv/bin/python}
run() { local name=$1; shift; mkdir -p "$runs/$name"; { time "$python" -m experiments.$name --workdir="$runs/$name" "$@"; } > "$runs/$name.log" 2>&1; }
run data_efficiency
mkdir -p "$runs/error_variants/train"
cp -rn "$runs/data_efficiency/train/l1" "$runs/error_variants/train/"
run error_variants
run new_pushes
run velocities --num_steps=2500
run objects --num_steps=2500
"$python" -m experiments.findings --workdirs="$runs/data_efficiency,$runs/new_pushes,$runs/velocities,$runs/error_variants" \
  --output="$runs/findings.md"

# Train vs test error of neural, neural_dyn and hybrid from data_efficiency (RESULTS.md, "most data"):
# the finished sweeps are copied and evaluated on their own training split (no training happens).
for variant in neural neural_dyn hybrid; do
  rm -rf "$runs/analysis/$variant"; mkdir -p "$runs/analysis/$variant/train/l1"
  cp -r "$runs/data_efficiency/train/l1/$variant" "$runs/analysis/$variant/train/l1/"
  "$python" -m experiments.train --variant=$variant --experiment=data_efficiency --scale=cpu \
    --workdir="$runs/analysis/$variant" --sizes=2500,190000 --test_split=train
done
