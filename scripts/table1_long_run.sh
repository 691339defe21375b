#!/usr/bin/env bash
# Table 1's long training (RESULTS.md, "Why no learned model overtakes the physics here"), start to end, resumable:
# run it again after any stop and it continues where the committed records and training states are.
#
#   bash scripts/table1_long_run.sh
#
# 1. neural, hybrid and error at the full split, seeds 0-2, the paper's 75 000 steps (convergence.PAPER_SCHEDULE);
# 2. the continuation rule (pushjax.train.stopping.long_run_continues, committed before the run) on every variant's
#    three seeds at 75 000 steps (experiments.stopping_audit -> results/data_efficiency_long/continuation/), the
#    variants it continues kept in continuation/continued_to_150000.txt so that a rerun does not decide again;
# 3. those variants trained on to 150 000 steps, and the rule's record written again;
# 4. the Table 1 findings decided with the long-trained models beside the criterion's
#    (experiments.findings --replace_with), written to results/data_efficiency_long/findings.md.
# Niced; the dataset is rebuilt from its seed when work/data lacks it. Commit results/data_efficiency_long (records
# and in_training/) at the end of a sitting.
set -euo pipefail
cd "$(dirname "$0")/.."
RUN=results/data_efficiency_long
PYTHON=.venv/bin/python
export MUJOCO_GL="${MUJOCO_GL:-egl}" PUSHJAX_PAPER_TABLES="${PUSHJAX_PAPER_TABLES:-../shared/data/paper_tables.json}"
mkdir -p work/data

train() {
  nice -n 19 "$PYTHON" -m experiments.data_efficiency_full --workdir="$RUN" --data_dir=work/data --schedule=paper \
    --sizes=190080 --nowide "$@"
}
audit() {
  "$PYTHON" -m experiments.stopping_audit --run="$RUN" --workdir="$RUN/continuation"
}

train --variants=neural,hybrid,error
decision="$RUN/continuation/continued_to_150000.txt"
if [ ! -f "$decision" ]; then  # decided once, on the nine models at 75 000 steps, and kept for the reruns
  audit
  "$PYTHON" - "$RUN/continuation/results.json" > "$decision.partial" <<'EOF'
import json, sys
rows = json.load(open(sys.argv[1]))["continuations"]
print(",".join(row["variant"] for row in rows if row["continues"] and row["variant"] in ("neural", "hybrid", "error")
               and row["steps"] == [75000, 75000, 75000]))
EOF
  mv "$decision.partial" "$decision"
fi
continued=$(cat "$decision")
if [ -n "$continued" ]; then
  echo "the continuation rule continues $continued to 150 000 steps ($decision)"
  train --steps=150000 --variants="$continued"
fi
audit
"$PYTHON" -m experiments.findings --workdirs=results/data_efficiency_full --replace_with="$RUN" \
  --output="$RUN/findings.md"
