#!/bin/bash
# The lever ablation of docs/ant_experiments.md section 4 (issue 30): each lever alone on Ant U-chain 3, then 5,
# seeds 0-2, one code (CODE), into one table (data/results/ant/levers.csv), resumable:
#   nohup setsid bash scripts/ant_levers.sh > runs/ant_levers.log 2>&1 &
set -euo pipefail
cd "$(dirname "$0")/.."
export CODE=${CODE:-$(git rev-parse --short HEAD)} OUT=${OUT:-runs/ant_levers} SHIPPED=${SHIPPED:-data/results/ant/levers.csv}
common=(--agent ant --evaluation adaptive --seeds 0 1 2 --workers 2)
for maze in u_chain_3 u_chain_5; do
    OUT=$OUT/heading SHIPPED=${SHIPPED%.csv}_heading.csv bash scripts/pinned_sweep.sh "${common[@]}" --mazes "$maze" \
        --methods ours --proposers geometric --policy data/policies/ant_stage4_heading.pt
    OUT=$OUT/shortcut SHIPPED=${SHIPPED%.csv}_shortcut.csv bash scripts/pinned_sweep.sh "${common[@]}" \
        --mazes "$maze" --methods ours-shortcut --proposers geometric --policy data/policies/ant_stage4.pt
    OUT=$OUT/repair SHIPPED=${SHIPPED%.csv}_repair.csv bash scripts/pinned_sweep.sh "${common[@]}" \
        --mazes "$maze" --methods ours-repair --proposers imperfect:moderate --policy data/policies/ant_stage4.pt
done
