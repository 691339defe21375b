#!/bin/bash
# The runs behind RESULTS.md: every experiment binary at cpu scale with seeds 0, 1 and 2, then the findings table.
#
#   bash scripts/results.sh [RUNS_DIR]      (default: work/results; SEEDS=0,1,2 and SCALE=cpu by default)
#
# MIN_TEST_SEQUENCES=150 evaluates every experiment on its test splits grown to at least 150 push sequences
# (`--min_test_sequences`; the same training and validation data, seeds and schedule as without it); give it its
# own RUNS_DIR and PUBLISHED_DIR (e.g. results/test150). Fig. 8 (visualize, one repeated push) is not run again then.
#
# Resumable: stop it at any time and run it again. Training resumes from each sweep's last checkpoint, and an
# experiment this script finished is not run again. A finished experiment's tables, curves and figures (results.json,
# results.md, curves.csv, *.png: small files, no checkpoints) are published to `results/<name>/` in the repository,
# to be committed: RESULTS.md is written from them, and a fresh checkout that lacks RUNS_DIR goes on with the next
# experiment (delete `results/<name>/` to redo one; its finished sweeps in RUNS_DIR are reused). Each run's log is
# `<RUNS_DIR>/<name>.log`; every results.json records the git commit and the wall time of every sitting
# (`provenance`).
#
# Sweeps that two experiments share are trained once: error_variants at l = 1 is data_efficiency's hybrid and
# error-variant sweeps, visualize evaluates data_efficiency's models, error_velocities (Fig. 9) reuses the
# velocities sweeps of neural and hybrid trained at 20 mm/s; their finished checkpoints are copied over.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-work/results}
seeds=${SEEDS:-0,1,2}
scale=${SCALE:-cpu}
min_test=${MIN_TEST_SEQUENCES:-0}
export MUJOCO_GL=${MUJOCO_GL:-egl}
python=${PYTHON:-.venv/bin/python}
published=${PUBLISHED_DIR:-results}

run() {
  local name=$1; shift
  if [[ -f "$published/$name/results.json" ]]; then echo "$name: done ($published/$name/results.json)"; return; fi
  echo "$name: running (log $runs/$name.log)"
  mkdir -p "$runs/$name"
  "$python" -m experiments."$name" --workdir="$runs/$name" --scale="$scale" --seeds="$seeds" \
    --min_test_sequences="$min_test" "$@" \
    >> "$runs/$name.log" 2>&1
  mkdir -p "$published/$name.partial"
  find "$runs/$name" -maxdepth 1 -type f \( -name 'results.json' -o -name 'results.md' -o -name 'curves.csv' \
    -o -name '*.png' \) -exec cp {} "$published/$name.partial/" \;
  rm -rf "$published/$name" && mv "$published/$name.partial" "$published/$name"
  echo "$name: published $published/$name/"
}
share() {  # share FROM TO SWEEP...: copy finished sweeps of experiment FROM into experiment TO
  local from=$1 to=$2; shift 2
  for sweep in "$@"; do
    if [[ -d "$runs/$from/$sweep" && ! -e "$runs/$to/$sweep" ]]; then
      mkdir -p "$(dirname "$runs/$to/$sweep")"; cp -r "$runs/$from/$sweep" "$runs/$to/$sweep"
    fi
  done
}

run data_efficiency
# visualize only evaluates data_efficiency's sweeps: run it while they are still in RUNS_DIR. Its test split is one
# repeated push, which no MIN_TEST_SEQUENCES grows.
if [[ "$min_test" == 0 ]]; then
  share data_efficiency visualize train/l1/neural train/l1/hybrid train/l1/simple train/l1/error
  run visualize --sizes=2500,190000
fi
share data_efficiency error_variants train/l1/hybrid train/l1/error_error_grad_error_norm
run viewpoint
run error_variants
run new_pushes
run objects
run velocities
share velocities error_velocities train_20/l1/neural train_20/l1/hybrid
run error_velocities
# With the long-trained models at the full split (scripts/table1_long_run.sh) the findings are decided both ways,
# side by side: as the runs above give them and with those models in place of the criterion's.
long_run=()
if compgen -G "$published/data_efficiency_long/models/*.json" > /dev/null; then
  long_run=(--replace_with="$published/data_efficiency_long")
fi
"$python" -m experiments.findings --workdirs="$(ls -d "$published"/{data_efficiency,data_efficiency_full,new_pushes,velocities,error_velocities,error_variants,objects} 2>/dev/null | paste -sd,)" \
  --output="$published/findings.md" "${long_run[@]}"
