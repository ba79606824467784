#!/bin/bash
# The checks of docs/ant_experiments.md section 2a: a new Ant policy against the shipped one, on the same episodes.
#   bash scripts/ant_stage4_checks.sh NEW_POLICY RUNS_DIR OUT_DIR
# RUNS_DIR: the cells folder of the Ant U-chain grid (runs/ant_uchain/cells); OUT_DIR receives one JSON per check
# (a check whose file exists is skipped: rerun to resume).
set -euo pipefail
. "$(dirname "$0")/check_lib.sh"
new=$1 cells=$2 out=$3
py=${PYTHON:-.venv/bin/python}
mkdir -p "$out"
for tag in stage3 stage4; do
    pol=$([ "$tag" = stage3 ] && echo data/policies/ant.pt || echo "$new")
    produce "$out/open_floor_$tag.json" $py -m specrefine.sim.train --agent ant --evaluate "$pol" --episodes 500 \
        --seed 1 --goal-range 2 6
    produce "$out/chain8_$tag.json" $py -m specrefine.sim.train --agent ant --evaluate "$pol" --chain 8 \
        --goal-range 3 5 --episodes 200 --seed 5
    for run in u_chain_3__ant__ours__geometric__s0__adaptive u_chain_2__ant__ours__geometric__s1__adaptive \
               u_chain_2__ant__ours__geometric__s2__adaptive; do
        seed=${run##*geometric__}
        file="$out/${run%%__ant*}_${seed%%__*}_$tag.json"
        produce_self "$file" $py -m specrefine.experiments.failures "$cells/$run/result.json" --episodes 300 \
            --seed 77 --policy "$pol" --out "$file" > /dev/null
    done
done
