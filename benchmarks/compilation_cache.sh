#!/usr/bin/env bash
# The persistent compilation cache (pushjax.compilation_cache): wall time of a first and a second run of the same
# smoke command, each in a fresh work directory, against a cache folder that starts empty.
#   bash benchmarks/compilation_cache.sh   (BINARIES="push_to_goal track" by default)
set -u
cd "$(dirname "$0")/.."
for binary in ${BINARIES:-push_to_goal track}; do
  cache=$(mktemp -d /tmp/pushjax_cc_XXXX)
  rm -rf work/bench_cache/$binary-cold work/bench_cache/$binary-warm && mkdir -p work/bench_cache
  for run in cold warm; do
    start=$(date +%s.%N)
    PUSHJAX_COMPILATION_CACHE=$cache MUJOCO_GL=egl .venv/bin/python -m experiments.$binary --scale=smoke --workdir=work/bench_cache/$binary-$run > work/bench_cache/$binary-$run.log 2>&1
    rc=$?
    end=$(date +%s.%N)
    echo "$binary $run rc=$rc $(echo "$end - $start" | bc) s, cache $(du -sh $cache | cut -f1)"
  done
done
