#!/bin/bash
# Tuning a repaired chain (docs/proposers.md, "Tuning a repaired chain"), fixed before it ran, one resumable table:
#   CODE=COMMIT nohup setsid bash scripts/repair_tuned_grid.sh > runs/repair_tuned.log 2>&1 &
# Point mass, 17 mazes, ours-repair / ours-repair-tuned, seeds 0-3; presets moderate, then severe.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
export CODE=${CODE:-$(git -C "$root" rev-parse --short HEAD)} OUT=${OUT:-$root/runs/repair_tuned}
export SHIPPED=${SHIPPED:-$root/data/results/repair/tuned.csv}
for preset in moderate severe; do
    bash "$root/scripts/pinned_sweep.sh" --agent point --methods ours-repair ours-repair-tuned \
        --proposers "imperfect:$preset" --seeds 0 1 2 3 --workers "${WORKERS:-1}"
done
