#!/bin/bash
# One grid of specrefine/experiments/grids.py (python -m specrefine.experiments.grids list), its parts in order, each
# step through scripts/pinned_sweep.sh with the grid's code, sweep folder and shipped table; resumable (run it again):
#   mkdir -p runs && nohup setsid bash scripts/run_grid.sh NAME > runs/NAME.log 2>&1 &
# The grid's definition is the checkout's, read once before the first step; the sweep is the pinned commit's.
# Environment: CODE (instead of the grid's commit; a grid without one runs the checkout's HEAD), OUT (the sweep
# folder; parts with their own sit under it), SHIPPED (the table; grids with one table only), WORKERS, PYTHON,
# TREE (scripts/pinned_sweep.sh), DRY_RUN=1 (print the pinned_sweep.sh commands, run nothing). Relative paths are
# taken from the checkout's root.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
name=${1:?usage: bash scripts/run_grid.sh NAME (python -m specrefine.experiments.grids list)}
py=${PYTHON:-$root/.venv/bin/python}
grids() { PYTHONPATH=$root "$py" -m specrefine.experiments.grids "$@"; }

plan=$(grids plan "$name" ${OUT:+--out "$OUT"} ${SHIPPED:+--shipped "$SHIPPED"})  # a bad name: its line, exit 2
code=${CODE:-$(awk '$1 == "code" {print $2}' <<<"$plan")}
[ "$code" != - ] || code=$(git rev-parse --short HEAD)
commands=()
while read -r part step out table; do
    args=$(grids args "$name" --part "$part" --step "$step" ${WORKERS:+--workers "$WORKERS"})
    commands+=("CODE=$code OUT=$out SHIPPED=$table bash scripts/pinned_sweep.sh $args")
done < <(awk '$1 == "step" {print $2, $3, $4, $5}' <<<"$plan")

for command in "${commands[@]}"; do
    if [ -n "${DRY_RUN:-}" ]; then echo "$command"; else eval "$command" </dev/null; fi
done
