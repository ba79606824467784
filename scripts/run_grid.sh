#!/bin/bash
# One grid of specrefine/experiments/grids.py (python -m specrefine.experiments.grids list), its parts in order, each
# step through scripts/pinned_sweep.sh with the grid's code, sweep folder and shipped table; resumable (run it again):
#   mkdir -p runs && nohup setsid bash scripts/run_grid.sh NAME > runs/NAME.log 2>&1 &
# The grid's definition is the checkout's, read once before the first step; the sweep is the pinned commit's.
# Environment: CODE (instead of the grid's commit; a grid without one runs the checkout's HEAD), OUT (the sweep
# folder; parts with their own sit under it), SHIPPED (the table; grids with one table only), WORKERS, PYTHON,
# TREE (scripts/pinned_sweep.sh), DRY_RUN=1 (print the pinned_sweep.sh commands, run nothing), MAZES and SEEDS
# (space-separated: only those of the grid's cells, the same cells in the same folder and table; a name the grid
# does not hold is refused). Relative paths are taken from the checkout's root. Every value is passed as one
# argument, never run as shell code (no eval).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
if [ -z "${1:-}" ]; then
    echo "usage: bash scripts/run_grid.sh NAME (python -m specrefine.experiments.grids list)" >&2
    exit 2
fi
name=$1
py=${PYTHON:-$root/.venv/bin/python}
grids() { PYTHONPATH=$root "$py" -m specrefine.experiments.grids "$@"; }
split() { "$py" -c 'import shlex, sys; sys.stdout.write("".join(a + "\0" for a in shlex.split(sys.argv[1])))' "$1"; }

subset=()  # MAZES, SEEDS: split on spaces only, never globbed
read -ra mazes <<<"${MAZES:-}"
read -ra seeds <<<"${SEEDS:-}"
[ "${#mazes[@]}" -eq 0 ] || subset+=(--mazes "${mazes[@]}")
[ "${#seeds[@]}" -eq 0 ] || subset+=(--seeds "${seeds[@]}")
options=()
[ -z "${OUT:-}" ] || options+=(--out "$OUT")
[ -z "${SHIPPED:-}" ] || options+=(--shipped "$SHIPPED")
plan=$(grids plan "$name" ${options[@]+"${options[@]}"} ${subset[@]+"${subset[@]}"})  # a bad name: its line, exit 2
code=${CODE:-}
steps=()  # per step: OUT, TABLE and the sweep's arguments (shell-quoted, as grids args prints them)
while IFS=$'\t' read -r kind part step out table; do
    case $kind in
        code) [ -n "$code" ] || code=$part ;;
        step) steps+=("$out" "$table" "$(grids args "$name" --part "$part" --step "$step" \
                                         ${WORKERS:+--workers "$WORKERS"} ${subset[@]+"${subset[@]}"})") ;;
    esac
done <<<"$plan"
[ "$code" != - ] || code=$(git rev-parse --short HEAD)

for ((i = 0; i < ${#steps[@]}; i += 3)); do
    out=${steps[i]} table=${steps[i + 1]} args=${steps[i + 2]}
    if [ -n "${DRY_RUN:-}" ]; then
        printf 'CODE=%q OUT=%q SHIPPED=%q bash scripts/pinned_sweep.sh %s\n' "$code" "$out" "$table" "$args"
    else
        mapfile -d '' -t argv < <(split "$args")
        [ "${#argv[@]}" -gt 0 ] || { echo "run_grid.sh: no sweep arguments for step $((i / 3)) of $name" >&2; exit 2; }
        CODE=$code OUT=$out SHIPPED=$table bash scripts/pinned_sweep.sh "${argv[@]}" </dev/null
    fi
done
