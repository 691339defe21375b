#!/usr/bin/env bash
# Table 1's long training (RESULTS.md, "Why no learned model overtakes the physics here"), start to end, resumable:
# run it again after any stop and it continues where the committed records and training states are.
#
#   bash scripts/table1_long_run.sh
#
# 1. neural, hybrid and error at the full split, seeds 0-2, the paper's 75 000 steps (convergence.PAPER_SCHEDULE);
# 2. the continuation rule (pushjax.train.stopping.long_run_continues, committed before the run) on every variant's
#    three seeds at 75 000 steps (experiments.stopping_audit -> results/data_efficiency_long/continuation/), the
#    decision kept per variant in continuation/<variant>.txt so that a rerun does not decide again;
# 3. those variants trained on to 150 000 steps, and the rule's record written again; a variant it continues at
#    150 000 steps trains on to 300 000 (the run's cap) and the record is written once more;
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

# decide STEPS SUFFIX VARIANT...: the variants (comma-separated) whose three seeds at STEPS the continuation rule
# continues to twice STEPS. Each variant is decided once, on its three seeds at STEPS, and the decision kept in
# continuation/<variant><SUFFIX>.txt for the reruns (a variant continued beside another still at STEPS is not decided
# again on its longer records).
decide() {
  local steps=$1 suffix=$2 result="" variant decision
  shift 2
  for variant in "$@"; do
    decision="$RUN/continuation/$variant$suffix.txt"
    if [ ! -f "$decision" ]; then
      audit >&2
      if "$PYTHON" - "$RUN/continuation/results.json" "$variant" "$steps" > "$decision.partial" <<'EOF'
import json, sys
steps = int(sys.argv[3])
rows = [row for row in json.load(open(sys.argv[1]))["continuations"] if row["variant"] == sys.argv[2]]
if len(rows) != 1 or rows[0]["steps"] != [steps] * 3:
    sys.exit(3)  # not three seeds at STEPS: undecided
print(f"continues to {2 * steps}" if rows[0]["continues"] else f"stops at {steps}")
EOF
      then mv "$decision.partial" "$decision"; else rm -f "$decision.partial"; echo "$variant: undecided at $steps" >&2; continue; fi
    fi
    if grep -q continues "$decision"; then result="${result:+$result,}$variant"; fi
  done
  echo "$result"
}

train --variants=neural,hybrid,error
continued=$(decide 75000 "" neural hybrid error)
if [ -n "$continued" ]; then
  echo "the continuation rule continues $continued to 150 000 steps ($RUN/continuation/)"
  train --steps=150000 --variants="$continued"
  # At 150 000 steps the rule is applied again; a variant it continues trains on to 300 000 steps, four times the
  # paper's budget and as far as this run goes.
  again=$(decide 150000 .150000 ${continued//,/ })
  if [ -n "$again" ]; then
    echo "the continuation rule continues $again to 300 000 steps ($RUN/continuation/)"
    train --steps=300000 --variants="$again"
  fi
fi
audit
"$PYTHON" -m experiments.findings --workdirs=results/data_efficiency_full --replace_with="$RUN" \
  --output="$RUN/findings.md"
