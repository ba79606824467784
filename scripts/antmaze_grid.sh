#!/bin/bash
# The AntMaze grid of issue 28 (NOT RUN YET: many hours of Ant simulation on a 2-core machine): the D4RL AntMaze
# maps U, MEDIUM and LARGE (gr:NAME, start and goal as in specrefine/core/standard_maps.py) with the Ant, the methods
# dirl, vlm-oneshot and ours, the proposers geometric and imperfect:moderate, seeds 0-2, 200 episodes per cell:
#   mkdir -p runs && nohup setsid bash scripts/antmaze_grid.sh > runs/antmaze.log 2>&1 &
# Resumable (rerun the same command). POLICY defaults to the goal policy of the Ant comparison
# (scripts/ant_comparison.sh), so the rows compare with data/results/ant/; POLICY=shipped uses data/policies/ant.pt.
# Afterwards, each cell's policy in the official AntMaze-v5:
#   for run in runs/antmaze/cells/*/; do specrefine official "$run" --episodes 200; done
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
policy=${POLICY:-$root/data/policies/ant_stage4.pt}
python -m specrefine.runs.sweep --agent ant --mazes gr:U_MAZE gr:MEDIUM_MAZE gr:LARGE_MAZE \
    --methods dirl vlm-oneshot ours --proposers geometric imperfect:moderate --seeds 0 1 2 \
    --episodes 200 --policy "$policy" --workers "${WORKERS:-2}" --out "${OUT:-$root/runs/antmaze}"
