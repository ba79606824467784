#!/bin/bash
# The Ant scaling grid with stage 5 (docs/ant_experiments.md section 5), fixed before it ran; one code (CODE), three
# parts in order, each resumable into its own table in data/results/ant/scaling/:
#   CODE=COMMIT nohup setsid bash scripts/ant_scaling_grid.sh > runs/ant_scaling.log 2>&1 &
set -euo pipefail
cd "$(dirname "$0")/.."
export CODE=${CODE:-$(git rev-parse --short HEAD)}
mazes="u_chain_1 u_chain_2 u_chain_2_subgoals u_chain_3 u_chain_3_subgoals u_chain_4 u_chain_4_subgoals u_chain_5
       u_chain_5_subgoals"
common=(--agent ant --evaluation adaptive --workers "${WORKERS:-2}" --policy data/policies/ant_stage5.pt --mazes $mazes)
part() {  # NAME, then the sweep's method and proposer arguments
    local name=$1; shift
    OUT=runs/ant_scaling/$name SHIPPED=data/results/ant/scaling/$name.csv bash scripts/pinned_sweep.sh "${common[@]}" "$@"
}
for seed in 0 1 2; do part ours_geometric --seeds $seed --methods ours --proposers geometric:max_waypoints=48; done
part oneshot --seeds 0 1 2 --methods vlm-oneshot --proposers geometric:max_waypoints=48 imperfect:moderate
for seed in 0 1 2; do part imperfect --seeds $seed --methods ours ours-repair --proposers imperfect:moderate; done
part repair_geometric --seeds 0 1 2 --methods ours-repair --proposers geometric:max_waypoints=48  # part 4, added 22:59 UTC before any cell of it ran
