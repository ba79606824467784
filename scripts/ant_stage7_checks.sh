#!/bin/bash
# The checks of stage 7 (docs/ant_experiments.md, "Lever 3 of issue 42"): a new policy (NEW, default
# data/policies/ant_stage7.pt; TAG, default stage7) beside a baseline (BASE, default stage 5; BASE_TAG, default stage5)
# on the same episodes; one JSON per check in OUT (default data/results/ant/stage7_checks); a check whose file exists
# is skipped (rerun to resume). Checks 1-3 are those of scripts/ant_heading_checks.sh; 4 is a chain of eight goals
# that each turn 90-180 degrees from the direction of travel; 5 (descriptive) the held-out paths with centre goal
# points. Then the lost episodes by kind of leg, per policy and goal-point rule, into OUT/leg_kinds.md.
#   bash scripts/ant_stage7_checks.sh
set -euo pipefail
. "$(dirname "$0")/check_lib.sh"
cd "$(dirname "$0")/.."
out=${OUT:-data/results/ant/stage7_checks}
new=${NEW:-data/policies/ant_stage7.pt}
new_tag=${TAG:-stage7}
base=${BASE:-data/policies/ant_stage5.pt}
base_tag=${BASE_TAG:-stage5}
py=${PYTHON:-.venv/bin/python}
mkdir -p "$out"
for tag in "$new_tag" "$base_tag"; do
    pol=$([ "$tag" = "$base_tag" ] && echo "$base" || echo "$new")
    produce "$out/open_floor_$tag.json" $py -m specrefine.sim.train --agent ant --evaluate "$pol" --episodes 500 \
        --seed 1 --goal-range 2 6
    produce "$out/chain8_$tag.json" $py -m specrefine.sim.train --agent ant --evaluate "$pol" --chain 8 \
        --goal-range 3 5 --episodes 200 --seed 5
    produce "$out/turn_chain8_$tag.json" $py -m specrefine.sim.train --agent ant --evaluate "$pol" --chain 8 \
        --goal-range 3 5 --turn-goals 90 180 --episodes 500 --seed 5
    for s in 0 1 2; do
        file="$out/u_chain_2_s${s}_$tag.json"
        produce_self "$file" $py -m specrefine.experiments.failures "data/results/ant/u_chain_2_s${s}_result.json" \
            --episodes 300 --seed 77 --policy "$pol" --out "$file" > /dev/null
    done
done
for tag in "$new_tag" "$base_tag"; do
    pol=$([ "$tag" = "$base_tag" ] && echo "$base" || echo "$new")
    for s in 0 1 2; do
        file="$out/u_chain_2_s${s}_centre_$tag.json"
        produce_self "$file" $py -m specrefine.experiments.failures "data/results/ant/u_chain_2_s${s}_result.json" \
            --episodes 300 --seed 77 --policy "$pol" --goal-points centre --out "$file" > /dev/null
    done
done
leg_kinds_md "$out" "$py" "$base_tag $new_tag" "sampled centre"
