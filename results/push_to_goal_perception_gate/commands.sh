#!/bin/sh
# The gated run of RESULTS.md's "The controller's state from depth-image perception" (issue 32): as
# results/push_to_goal_perception/commands.sh, with a perception reading skipped when its squared innovation exceeds
# 13.8 (chi-square, 2 degrees of freedom, 99.9 %). 132 episodes, 11 min on the shared 2-core machine.
# Run from the repository root: sh results/push_to_goal_perception_gate/commands.sh
set -e
export MUJOCO_GL=egl
python -m experiments.push_to_goal --scale=cpu --models=lynch \
  --states=mocap,mocap+perception,perception --perception=results/track_perception/model --perception_scale=cpu_full \
  --perception_gate=13.8 --workdir=results/push_to_goal_perception_gate
