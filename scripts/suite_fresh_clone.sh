#!/usr/bin/env bash
# The README's two commands verbatim in a fresh clone of a branch, timed, kept as a committed record: clones BRANCH
# (default main) of this repository into a temporary folder beside it (so that ../shared is its neighbour too), runs
# the commands of README.md's "The two commands" section under /usr/bin/time, then .ci/run's lint step, and writes
# the last lines of each with the host's load before and after to results/benchmarks/suite_fresh_clone_<date>.md
# (NAME_SUFFIX, e.g. _idle, is appended to the name).
#
#   bash scripts/suite_fresh_clone.sh [BRANCH]
#
# The CPU time (user + system) is the figure to compare on shared cores; say in BENCHMARKS.md what else ran.
set -euo pipefail
cd "$(dirname "$0")/.."
branch=${1:-main}
here=$PWD
clone=$(mktemp -d "$(dirname "$here")/fresh_clone.XXXXXX")
trap 'rm -rf "$clone"' EXIT
git clone -q -b "$branch" "$here" "$clone"
commit=$(git -C "$clone" rev-parse --short HEAD)
# The fenced blocks of README.md's "The two commands" section, in order.
mapfile -t commands < <(awk '/^## The two commands/{on=1; next} /^## /{on=0} on && /^   ```/{fence=!fence; next} on && fence {sub(/^ +/, ""); print}' README.md)
if [ ${#commands[@]} -ne 2 ]; then
  echo "README.md: expected two commands under \"## The two commands\", found ${#commands[@]}" >&2
  exit 1
fi
record="$here/results/benchmarks/suite_fresh_clone_$(date -u +%F)${NAME_SUFFIX:-}.md"
log() { echo "$@" >> "$record.partial"; }
: > "$record.partial"
log "# The README's two commands verbatim in a fresh clone (git clone -b $branch) of commit $commit, $(nproc) cores, each under /usr/bin/time -f \"%e s wall, %U s user, %S s sys\"; $(date -u '+%F') UTC. Written by \`bash scripts/suite_fresh_clone.sh\`: the last lines of each command, the uptime before and after."
for index in 0 1; do
  log ""
  log "## command $((index + 1)), started $(date -u +%T) UTC"
  log ""
  log '```'
  log "$(uptime)"
  set +e
  output=$(cd "$clone" && /usr/bin/time -f "%e s wall, %U s user, %S s sys" bash -c "${commands[$index]}" 2>&1)
  status=$?
  set -e
  log "$(echo "$output" | tail -n 3)"
  log "$(uptime)"
  log "rc $status"
  log '```'
done
log ""
log "## lint (.ci/run's last step): .venv/bin/ruff check ."
log ""
log '```'
log "$(cd "$clone" && .venv/bin/ruff check . 2>&1 | tail -n 3)"
log '```'
mv "$record.partial" "$record"
cat "$record"
