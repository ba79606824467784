#!/bin/bash
# The checks of lever A (docs/ant_experiments.md section 4): the heading-frame policy beside stage 4 on the same
# episodes; one JSON per check in OUT (default data/results/ant/heading_checks); a check whose file exists is skipped.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${OUT:-data/results/ant/heading_checks}
py=${PYTHON:-.venv/bin/python}
mkdir -p "$out"
for tag in stage4 heading; do
    pol=$([ "$tag" = stage4 ] && echo data/policies/ant_stage4.pt || echo data/policies/ant_stage4_heading.pt)
    [ -s "$out/open_floor_$tag.json" ] || $py -m specrefine.train --agent ant --evaluate "$pol" --episodes 500 \
        --seed 1 --goal-range 2 6 > "$out/open_floor_$tag.json"
    [ -s "$out/chain8_$tag.json" ] || $py -m specrefine.train --agent ant --evaluate "$pol" --chain 8 \
        --goal-range 3 5 --episodes 200 --seed 5 > "$out/chain8_$tag.json"
    for s in 0 1 2; do
        file="$out/u_chain_2_s${s}_$tag.json"
        [ -s "$file" ] || $py -m specrefine.failures "data/results/ant/u_chain_2_s${s}_result.json" --episodes 300 \
            --seed 77 --policy "$pol" --out "$file" > /dev/null
    done
done
