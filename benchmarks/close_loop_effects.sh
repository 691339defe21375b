#!/usr/bin/env bash
# Per-effect table of the closed loop: record each case on the ideal testbed (no unmodelled physics but the case's
# effect, as the loop tests' data sets) with its effect undeclared, run
# `experiments.close_loop` on it, print baseline / after (held-out trans % + rot % of the zero
# baseline), the cut, the selected effects, the test split's noise floor, `explained` and the fallback's error.
#   bash benchmarks/close_loop_effects.sh [WORK_DIR]     (run with the project's venv active)
set -euo pipefail
cd "$(dirname "$0")/.."
work=${1:-/tmp/close_loop_effects}
python=${PYTHON:-python}
declare -A EFFECTS=(
  [clean]=""
  [com_offset]="com_offset=0.015,-0.01"
  [pressure]="pressure_rim=-4"
  [anisotropy]="friction_anisotropy=1,2.5"
  [table_tilt]="table_tilt_deg=6;table_tilt_azimuth_deg=60"
  [pusher_friction]="pusher_friction=0.8"
  [tracking_bias]="tracking_bias=0.01,-0.006,0"
  [tracking_yaw_bias]="tracking_bias=0,0,0.12"
)
echo "| case | baseline | after | cut | selected | noise floor | explained | fallback |"
echo "|---|---:|---:|---:|---|---:|---|---:|"
for name in clean com_offset pressure anisotropy table_tilt pusher_friction tracking_bias tracking_yaw_bias; do
  "$python" -m experiments.record_pushes --out_dir="$work/data/$name" --objects=rect1 --surfaces=pu \
    --velocities=20 --pushes=120 --seed=1 --effects="${EFFECTS[$name]}" --declare_effects=false --testbed=ideal \
    --workers=1 > /dev/null 2>&1
  "$python" -m experiments.close_loop --data_dir="$work/data/$name" --workdir="$work/out/$name" > /dev/null 2>&1
  "$python" - "$work/out/$name/report.json" "$name" <<'PY'
import json, sys
report = json.load(open(sys.argv[1]))
total = lambda errors: errors["trans_percent"] + errors["rot_percent"]
print(f"| {sys.argv[2]} | {total(report['baseline']):.1f} | {total(report['after']):.1f} | "
      f"{1 - total(report['after']) / total(report['baseline']):.0%} | "
      f"{', '.join(report['selected']) or '-'} | {total(report['noise_floor']):.1f} | {report['explained']} | "
      f"{total(report['fallback']):.1f} |", flush=True)
PY
done
