#!/bin/bash
# The checks of stage 8, the look-ahead (docs/ant_experiments.md, "Issue 42, lever 2"): a new policy (NEW, default
# data/policies/ant_stage8.pt; TAG, default stage8) beside stage 5 (BASE, BASE_TAG) on the same episodes; one JSON
# per check in OUT (default data/results/ant/stage8_checks); a check whose file exists is skipped (rerun to resume).
# Stage 5's open-floor and held-out files are those of data/results/ant/stage7_checks (copied: a policy without the
# look-ahead runs the same code as then); its two chains run here with planned goals, as the new policy's do. Order:
# the deciding checks 1-4 first (open floor; eight goals; eight turning goals; held-out U-chain 2 paths with centre
# goal points), then 5 (descriptive: the held-out paths with sampled goal points). Then the lost episodes by kind of
# leg into OUT/leg_kinds.md.
#   bash /tmp/heavy.sh bash scripts/ant_stage8_checks.sh
set -euo pipefail
. "$(dirname "$0")/check_lib.sh"
cd "$(dirname "$0")/.."
out=${OUT:-data/results/ant/stage8_checks}
new=${NEW:-data/policies/ant_stage8.pt}
new_tag=${TAG:-stage8}
base=${BASE:-data/policies/ant_stage5.pt}
base_tag=${BASE_TAG:-stage5}
py=${PYTHON:-.venv/bin/python}
mkdir -p "$out"
if [ "$base_tag" = stage5 ]; then
    for f in open_floor_stage5.json u_chain_2_s{0,1,2}_centre_stage5.json u_chain_2_s{0,1,2}_stage5.json; do
        produce "$out/$f" cat "data/results/ant/stage7_checks/$f"
    done
fi
policy_of() { [ "$1" = "$base_tag" ] && echo "$base" || echo "$new"; }
produce "$out/open_floor_$new_tag.json" $py -m specrefine.sim.train --agent ant --evaluate "$new" --episodes 500 \
    --seed 1 --goal-range 2 6
for tag in "$base_tag" "$new_tag"; do
    pol=$(policy_of "$tag")
    produce "$out/chain8_$tag.json" $py -m specrefine.sim.train --agent ant --evaluate "$pol" --chain 8 \
        --goal-range 3 5 --episodes 200 --seed 5 --planned-goals
    produce "$out/turn_chain8_$tag.json" $py -m specrefine.sim.train --agent ant --evaluate "$pol" --chain 8 \
        --goal-range 3 5 --turn-goals 90 180 --episodes 500 --seed 5 --planned-goals
done
for points in centre sampled; do
    for tag in "$base_tag" "$new_tag"; do
        pol=$(policy_of "$tag")
        for s in 0 1 2; do
            prefix=""
            [ "$points" = centre ] && prefix=centre_
            file="$out/u_chain_2_s${s}_$prefix$tag.json"
            produce_self "$file" $py -m specrefine.experiments.failures "data/results/ant/u_chain_2_s${s}_result.json" \
                --episodes 300 --seed 77 --policy "$pol" --goal-points "$points" --walls-only --out "$file" > /dev/null
        done
    done
done
leg_kinds_md "$out" "$py" "$base_tag $new_tag" "centre sampled"
