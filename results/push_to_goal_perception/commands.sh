#!/bin/sh
# The run of RESULTS.md's "The controller's state from depth-image perception" (issue 32): plain Lynch at the cpu
# scale (11 objects x 2 goals, both planners, realistic testbed) with motion capture, motion capture + the committed
# hybrid's perception (results/track_perception/model, trained on data_efficiency cpu_full), and perception only.
# It ran in two steps in the same folder (the first, --goals=1 --planners=gradient, 7 min; then this command, which
# resumed those 33 episodes and added 99, 13 min, on the shared 2-core machine); this command alone gives the same rows.
# Run from the repository root: sh results/push_to_goal_perception/commands.sh
set -e
export MUJOCO_GL=egl
python -m experiments.push_to_goal --scale=cpu --models=lynch \
  --states=mocap,mocap+perception,perception --perception=results/track_perception/model --perception_scale=cpu_full \
  --workdir=results/push_to_goal_perception
