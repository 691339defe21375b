#!/bin/sh
# The run of RESULTS.md's "Prediction over time" (issue 31): experiments.rollouts at cpu scale (10 000 training steps,
# all eight test velocities, 3 seeds), resumable; then its results.json, results.md and rollouts.png copied here.
# Run from the repository root: sh results/rollouts/commands.sh
set -e
export MUJOCO_GL=egl
mkdir -p work/data
nice -n 19 python -m experiments.rollouts --scale=cpu --seeds=0,1,2 --data_dir=work/data --workdir=work/rollouts_cpu_full
cp work/rollouts_cpu_full/results.json work/rollouts_cpu_full/results.md work/rollouts_cpu_full/rollouts.png results/rollouts/
