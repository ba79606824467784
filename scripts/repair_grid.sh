#!/bin/bash
# The look-ahead repair grid of docs/proposers.md ("Look-ahead repair"), fixed before it ran, into one resumable table:
#   mkdir -p runs && nohup setsid bash scripts/repair_grid.sh > runs/repair_grid.log 2>&1 &
# Point mass, 17 mazes, ours / ours-repair / vlm-oneshot, seeds 0-3; presets moderate, then severe, then mild.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
export CODE=${CODE:-410997e} OUT=${OUT:-$root/runs/repair} SHIPPED=${SHIPPED:-$root/data/results/repair/results.csv}
for preset in moderate severe mild; do
    bash "$root/scripts/pinned_sweep.sh" --agent point --methods ours ours-repair vlm-oneshot \
        --proposers "imperfect:$preset" --seeds 0 1 2 3 --workers "${WORKERS:-1}"
done
