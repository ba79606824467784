#!/bin/bash
# The checks of lever A, of stage 5 (docs/ant_experiments.md section 4) and of stage 6 (section 5): a new policy
# (NEW, default A's file; TAG names its files, default heading) beside a baseline (BASE, default stage 4; BASE_TAG,
# default stage4) on the same episodes; one JSON per check in OUT (default data/results/ant/heading_checks); a check
# whose file exists is skipped.
#   NEW=data/policies/ant_stage5.pt TAG=stage5 OUT=data/results/ant/stage5_checks bash scripts/ant_heading_checks.sh
#   NEW=data/policies/ant_stage6.pt TAG=stage6 BASE=data/policies/ant_stage5.pt BASE_TAG=stage5 \
#       OUT=data/results/ant/stage6_checks bash scripts/ant_heading_checks.sh
set -euo pipefail
. "$(dirname "$0")/check_lib.sh"
cd "$(dirname "$0")/.."
out=${OUT:-data/results/ant/heading_checks}
new=${NEW:-data/policies/ant_stage4_heading.pt}
new_tag=${TAG:-heading}
base=${BASE:-data/policies/ant_stage4.pt}
base_tag=${BASE_TAG:-stage4}
py=${PYTHON:-.venv/bin/python}
mkdir -p "$out"
for tag in "$base_tag" "$new_tag"; do
    pol=$([ "$tag" = "$base_tag" ] && echo "$base" || echo "$new")
    produce "$out/open_floor_$tag.json" $py -m specrefine.sim.train --agent ant --evaluate "$pol" --episodes 500 \
        --seed 1 --goal-range 2 6
    produce "$out/chain8_$tag.json" $py -m specrefine.sim.train --agent ant --evaluate "$pol" --chain 8 \
        --goal-range 3 5 --episodes 200 --seed 5
    for s in 0 1 2; do
        file="$out/u_chain_2_s${s}_$tag.json"
        produce_self "$file" $py -m specrefine.experiments.failures "data/results/ant/u_chain_2_s${s}_result.json" \
            --episodes 300 --seed 77 --policy "$pol" --out "$file" > /dev/null
    done
done
