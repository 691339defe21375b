#!/bin/sh
# The runs of RESULTS.md's "Perception as a second observation" (issue 31): experiments.track at cpu scale with the
# committed hybrid's perception (results/track_perception/model) beside the motion capture, three seeds each.
# Run from the repository root: sh results/track_perception/commands.sh
set -e
export MUJOCO_GL=egl
for seed in 0 1 2; do
  python -m experiments.track --scale=cpu --filters=ekf --seed=$seed --perception=results/track_perception/model \
    --perception_scale=cpu_full --workdir=results/track_perception/seed${seed}_drop_default
  python -m experiments.track --scale=cpu --filters=ekf --seed=$seed --perception=results/track_perception/model \
    --perception_scale=cpu_full --testbed_overrides='drop_rate=0.5' --workdir=results/track_perception/seed${seed}_drop_0.5
  python -m experiments.track --scale=cpu --filters=ekf --seed=$seed --perception=results/track_perception/model \
    --perception_scale=cpu_full --testbed_overrides='drop_rate=0.5' --perception_hz=10 \
    --workdir=results/track_perception/seed${seed}_drop_0.5_10hz
  python -m experiments.track --scale=cpu --filters=ekf --seed=$seed --perception=results/track_perception/model \
    --perception_scale=cpu_full --testbed_overrides='drop_rate=0.9' --workdir=results/track_perception/seed${seed}_drop_0.9
done
python results/track_perception/summarise.py > results/track_perception/summary.md
