#!/bin/bash
# The Ant grids of docs/ant_experiments.md (sections 2 and 3), in the order they were fixed, into one resumable table:
#   mkdir -p runs && nohup setsid bash scripts/ant_comparison.sh > runs/ant_comparison.log 2>&1 &
# 1. the U-chain grid (ours + geometric, U-chain 1-5 with and without subgoals, seeds 0-2; the paper's Figure 5);
# 2. the comparison, one seed at a time (all 17 mazes x dirl, symbolic, vlm-oneshot, ours x geometric,
#    imperfect:moderate), so that an interrupted run leaves whole seeds behind it.
# Stage 1's cells are also stage 2's (same ids), so they run once. Every done row is copied to SHIPPED every two
# minutes: a new machine resumes from it (the table is copied back into OUT when OUT has none).
# The cells run the code of one commit, GRID_CODE, from a detached worktree (runs/grid_code), whatever the checkout
# holds: a session may edit specrefine/ while the job runs and the table stays one code's. The policy file is the
# checkout's (data, not code; its path is part of each cell's parameters in OUT/sweep.json).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
code=${GRID_CODE:-92ee10e}  # behaves as every commit since 7c398f5, where the grid started (specrefine/ diffs since: options, warnings)
py=${PYTHON:-$root/.venv/bin/python}
out=${OUT:-$root/runs/ant_comparison}
shipped=${SHIPPED:-$root/data/results/ant/comparison.csv}
workers=${WORKERS:-2}
tree=$root/runs/grid_code
[ -d "$tree" ] || git -C "$root" worktree add -q --detach "$tree" "$code"
if [ "$(git -C "$tree" rev-parse HEAD)" != "$(git -C "$root" rev-parse "$code^{commit}")" ]; then
    echo "$tree is not at GRID_CODE $code: remove it (git worktree remove --force $tree) and start again" >&2
    exit 2
fi
export PYTHONPATH=$tree  # before the checkout's editable install on sys.path
cd "$tree"
mkdir -p "$out"
[ -s "$out/results.csv" ] || { [ -s "$shipped" ] && cp "$shipped" "$out/results.csv"; } || true

ship() {  # the table's done rows only (a row being appended is never half-copied)
    $py - "$out/results.csv" "$shipped" <<'PY'
import csv, sys
from specrefine.sweep import _typed, is_done
src, dst = sys.argv[1:]
with open(src, newline="") as fh:
    reader = csv.DictReader(fh)
    rows = [r for r in reader if None not in r and None not in r.values() and is_done(_typed(r))]
with open(dst + ".tmp", "w", newline="") as fh:
    w = csv.DictWriter(fh, reader.fieldnames)
    w.writeheader()
    w.writerows(rows)
PY
    mv "$shipped.tmp" "$shipped"
}
( while sleep 120; do [ -s "$out/results.csv" ] && ship || true; done ) &
watcher=$!
trap 'kill $watcher 2>/dev/null; [ -s "$out/results.csv" ] && ship' EXIT

echo "grid code $(git -C "$tree" rev-parse --short HEAD) in $tree; table $out/results.csv -> $shipped"
common=(--agent ant --evaluation adaptive --policy "$root/data/policies/ant_stage4.pt" --workers "$workers"
        --out "$out")
$py -m specrefine.sweep "${common[@]}" --methods ours --proposers geometric --seeds 0 1 2 \
    --mazes u_chain_1 u_chain_2 u_chain_3 u_chain_4 u_chain_5 u_chain_2_subgoals u_chain_3_subgoals \
            u_chain_4_subgoals u_chain_5_subgoals
for seed in 0 1 2; do
    $py -m specrefine.sweep "${common[@]}" --methods dirl symbolic vlm-oneshot ours \
        --proposers geometric imperfect:moderate --seeds "$seed"
done
