#!/usr/bin/env bash
# A benchmark's output kept as its committed record: runs the command and writes what it prints to stdout, under a
# header with the command, the commit, the date and the host's load before and after, to
# results/benchmarks/<name>_<date>.md (and to the terminal).
#
#   bash scripts/benchmark_record.sh NAME COMMAND...
#   e.g. bash scripts/benchmark_record.sh quasi_static .venv/bin/python benchmarks/quasi_static.py
#
# Timings depend on the load: record them on idle cores and say so in BENCHMARKS.md beside the number.
set -euo pipefail
cd "$(dirname "$0")/.."
# The measured code is this checkout's (a script under benchmarks/ would otherwise import an installed pushjax).
export PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}"
if [ $# -lt 2 ]; then
  echo "usage: bash scripts/benchmark_record.sh NAME COMMAND..." >&2
  exit 2
fi
name=$1
shift
commit=$(git rev-parse --short HEAD)
if ! git diff --quiet HEAD -- pushjax benchmarks experiments; then commit="$commit+changes"; fi
record="results/benchmarks/${name}_$(date -u +%F).md"
mkdir -p results/benchmarks
before=$(uptime)
output=$(MUJOCO_GL="${MUJOCO_GL:-egl}" "$@")
{
  echo "# $* at commit $commit, $(date -u '+%F %H:%M UTC'), $(nproc) cores; uptime before and after"
  echo "$before"
  echo
  echo "$output"
  echo
  uptime
} | tee "$record"
echo "wrote $record" >&2
