#!/bin/bash
# The offline comparison's controls run again with one code (issue 27: ours-novertex redefined as "no vertex
# refinement anywhere", and the two parts of Algorithm 1's later round each removed alone): point mass, all 17
# mazes, presets mild / moderate / severe / moderate,alpha=0.1, seeds 0-3, 32 rollouts, 200 episodes, the grid of
# data/results/imperfect/ (docs/proposers.md). One method at a time, ours-novertex first, into one table:
#   nohup setsid bash scripts/controls_grid.sh > runs/controls.log 2>&1 &
set -euo pipefail
cd "$(dirname "$0")/.."
export CODE=${CODE:-309875a} OUT=${OUT:-runs/controls} SHIPPED=${SHIPPED:-data/results/controls/results.csv}
for method in ours-novertex ours-notune ours-nofeedback; do
    nice -n 5 bash scripts/pinned_sweep.sh --methods "$method" \
        --proposers imperfect:mild imperfect:moderate imperfect:severe imperfect:moderate,alpha=0.1 \
        --seeds 0 1 2 3 --workers 2
done
