#!/usr/bin/env bash
# Issue 30, part 4: neural and hybrid at the paper's images on one GPU, inside a fixed time.
#
#   bash benchmarks/paper_full_gpu.sh OUT_DIR [SECONDS=480] [SIZE=20000]
#
# Builds data_efficiency at scale paper_full (cpu_full's pushes, splits and examples rendered at 128 x 128 px, 80 x 80
# px glimpses; the build on the CPU cores with JAX kept off the GPU), then trains neural and hybrid at SIZE training
# examples, seeds 0, 1 and 2, at the paper's widths by issue 30's convergence criterion
# (experiments.data_efficiency_full --scale=paper_full): no model starts after START_BY seconds (default three quarters
# of SECONDS), and training stops at SECONDS. Models recorded in RECORDS (default
# results/data_efficiency_paper_full/models, the committed ones) are not trained again. Writes OUT_DIR/build.log, OUT_DIR/dataset.sha256 (the built files' digests, to compare with
# a build elsewhere), OUT_DIR/train.log and OUT_DIR/records.tgz (the finished models' records, the training state of
# the unfinished ones in in_training/, results.json and results.md; cut into OUT_DIR/records.tgz.part-* of 15 MiB
# when larger, for the device tool's 16 MiB a file). Environment: PYTHON (default python3), DATA_DIR, WORKDIR
# (default under /tmp); SEEDS (default 0,1,2) and MODELS (default 6: the next six unrecorded models of the plan,
# neural's and hybrid's first; SIZE=190080 SEEDS=0 MODELS=2 is part 4's pair at the full split); SCALE (default
# paper_full; cpu_full with RECORDS=results/data_efficiency_full/models and ARGS='--wide
# --only=neural_190080_seed0_wide,hybrid_190080_seed0_wide' trains the CPU run's wide pair) and ARGS (more flags of the
# training binary, e.g. a tiny --criterion for a dry run on a CPU).
set -uo pipefail
out=${1:?usage: benchmarks/paper_full_gpu.sh OUT_DIR [SECONDS] [SIZE]}
seconds=${2:-480}
size=${3:-20000}
python=${PYTHON:-python3}
data=${DATA_DIR:-/tmp/pushjax_paper_full_data}
work=${WORKDIR:-/tmp/pushjax_paper_full_run}
scale=${SCALE:-paper_full}
records=${RECORDS:-results/data_efficiency_paper_full/models}
start=$(date +%s)
mkdir -p "$out" "$data" "$work/models"
[ -d "$records" ] && cp -n "$records"/*.json "$work/models/" 2>/dev/null
since() { echo $(( $(date +%s) - start )); }

nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader || true
echo "cores $(nproc); $("$python" -c 'import jax; print("jax", jax.__version__, jax.devices())')"

JAX_PLATFORMS=cpu "$python" -m experiments.build_dataset --experiment=data_efficiency --scale="$scale" \
  --data_dir="$data" --workers="$(nproc)" > "$out/build.log" 2>&1
status=$?
echo "build: exit $status after $(since) s; $(du -sm "$data" | cut -f1) MiB in $data"
tail -3 "$out/build.log"
[ $status -eq 0 ] || exit $status
(cd "$data" && sha256sum push_effects/*/*/*array_record*) > "$out/dataset.sha256"

deadline=$(date -u -d "@$(( start + ${START_BY:-$(( seconds * 3 / 4 ))} ))" +%Y-%m-%dT%H:%M:%S)
timeout $(( seconds - $(since) )) "$python" -m experiments.data_efficiency_full --scale="$scale" --sizes="$size" \
  --seeds="${SEEDS:-0,1,2}" --nowide --max_models="${MODELS:-6}" --models_at_once=2 --deadline="$deadline" --workdir="$work" \
  --data_dir="$data" ${ARGS:-} > "$out/train.log" 2>&1
echo "training: exit $? after $(since) s"
grep -E "read |recorded |steps/s" "$out/train.log" | grep -v "^\[" | tail -12
(cd "$work" && tar czf "$out/records.tgz" models in_training results.json results.md 2>/dev/null)
if [ "$(stat -c %s "$out/records.tgz")" -gt $(( 15 * 1024 * 1024 )) ]; then
  split -b 15M "$out/records.tgz" "$out/records.tgz.part-" && rm "$out/records.tgz"
fi
ls -la "$out"
