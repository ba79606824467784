#!/bin/bash
# The heading row of the lever ablation again with the adopted stage-5 policy (docs/ant_experiments.md section 4):
# Ant, ours, geometric, U-chain 3 then 5, seeds 0-2, one code (CODE), into data/results/ant/levers_stage5.csv:
#   nohup setsid bash scripts/ant_levers_stage5.sh > runs/ant_levers_stage5.log 2>&1 &
set -euo pipefail
cd "$(dirname "$0")/.."
export CODE=${CODE:-$(git rev-parse --short HEAD)} OUT=${OUT:-runs/ant_levers/stage5}
export SHIPPED=${SHIPPED:-data/results/ant/levers_stage5.csv}
for maze in u_chain_3 u_chain_5; do
    bash scripts/pinned_sweep.sh --agent ant --evaluation adaptive --seeds 0 1 2 --workers "${WORKERS:-2}" \
        --mazes "$maze" --methods ours --proposers geometric --policy data/policies/ant_stage5.pt
done
