#!/bin/bash
# The Ant grids of docs/ant_experiments.md (sections 2 and 3), in the order they were fixed, into one resumable table:
#   mkdir -p runs && nohup setsid bash scripts/ant_comparison.sh > runs/ant_comparison.log 2>&1 &
# 1. the U-chain grid (ours + geometric, U-chain 1-5 with and without subgoals, seeds 0-2; the paper's Figure 5);
# 2. the comparison, one seed at a time (all 17 mazes x dirl, symbolic, vlm-oneshot, ours x geometric,
#    imperfect:moderate), so that an interrupted run leaves whole seeds behind it.
# Stage 1's cells are also stage 2's (same ids), so they run once. Every done row is copied to SHIPPED every two
# minutes: a new machine resumes from it (the table is copied back into OUT when OUT has none).
set -euo pipefail
py=${PYTHON:-.venv/bin/python}
out=${OUT:-runs/ant_comparison}
shipped=${SHIPPED:-data/results/ant/comparison.csv}
workers=${WORKERS:-2}
mkdir -p "$out"
[ -s "$out/results.csv" ] || { [ -s "$shipped" ] && cp "$shipped" "$out/results.csv"; } || true

ship() {  # the table's done rows only (a row being appended is never half-copied)
    $py - "$out/results.csv" "$shipped" <<'EOF'
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
EOF
    mv "$shipped.tmp" "$shipped"
}
( while sleep 120; do [ -s "$out/results.csv" ] && ship || true; done ) &
watcher=$!
trap 'kill $watcher 2>/dev/null; [ -s "$out/results.csv" ] && ship' EXIT

common=(--agent ant --evaluation adaptive --policy data/policies/ant_stage4.pt --workers "$workers" --out "$out")
$py -m specrefine.sweep "${common[@]}" --methods ours --proposers geometric --seeds 0 1 2 \
    --mazes u_chain_1 u_chain_2 u_chain_3 u_chain_4 u_chain_5 u_chain_2_subgoals u_chain_3_subgoals \
            u_chain_4_subgoals u_chain_5_subgoals
for seed in 0 1 2; do
    $py -m specrefine.sweep "${common[@]}" --methods dirl symbolic vlm-oneshot ours \
        --proposers geometric imperfect:moderate --seeds "$seed"
done
