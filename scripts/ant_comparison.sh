#!/bin/bash
# The Ant grids of docs/ant_experiments.md (sections 2 and 3), in the order they were fixed, into one resumable table:
#   mkdir -p runs && nohup setsid bash scripts/ant_comparison.sh > runs/ant_comparison.log 2>&1 &
# 1. the U-chain grid (ours + geometric, U-chain 1-5 with and without subgoals, seeds 0-2; the paper's Figure 5);
# 2. the comparison, one seed at a time (all 17 mazes x dirl, symbolic, vlm-oneshot, ours x geometric,
#    imperfect:moderate), so that an interrupted run leaves whole seeds behind it.
# Stage 1's cells are also stage 2's (same ids), so they run once. Each sweep runs the code of one commit, CODE
# (GRID_CODE), from a detached worktree (runs/grid_code), whatever the checkout holds, and its done rows are copied
# to data/results/ant/comparison.csv every two minutes (scripts/pinned_sweep.sh); a new machine resumes from
# that table. The policy file is the checkout's (data, not code; its path is part of each cell's parameters in
# OUT/sweep.json).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
# behaves as every commit since 7c398f5, where the grid started (specrefine/ diffs since: options, warnings)
export CODE=${GRID_CODE:-92ee10e} TREE=$root/runs/grid_code
export OUT=${OUT:-$root/runs/ant_comparison} SHIPPED=${SHIPPED:-$root/data/results/ant/comparison.csv}
common=(--agent ant --evaluation adaptive --policy "$root/data/policies/ant_stage4.pt" --workers "${WORKERS:-2}")
bash "$root/scripts/pinned_sweep.sh" "${common[@]}" --methods ours --proposers geometric --seeds 0 1 2 \
    --mazes u_chain_1 u_chain_2 u_chain_3 u_chain_4 u_chain_5 u_chain_2_subgoals u_chain_3_subgoals \
            u_chain_4_subgoals u_chain_5_subgoals
for seed in 0 1 2; do
    bash "$root/scripts/pinned_sweep.sh" "${common[@]}" --methods dirl symbolic vlm-oneshot ours \
        --proposers geometric imperfect:moderate --seeds "$seed"
done
