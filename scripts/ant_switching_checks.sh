#!/bin/bash
# The checks of the slow-turn switching rule (docs/ant_experiments.md section 6): stage 5 with each switching rule on
# the same episodes; one JSON per check in OUT (default data/results/ant/switching_checks); a check whose file exists
# is skipped, so a killed run resumes.  Order: the held-out U-chain 2 paths with centre goal points (both rules, the
# adoption check), eight goals in a row, the held-out paths with sampled goal points (the stage-5 checks' episodes),
# then U-chain 3 and 5 (PART=all).
#   PART=all bash /tmp/heavy.sh bash scripts/ant_switching_checks.sh
set -euo pipefail
. "$(dirname "$0")/check_lib.sh"
cd "$(dirname "$0")/.."
out=${OUT:-data/results/ant/switching_checks}
py=${PYTHON:-.venv/bin/python}
pol=data/policies/ant_stage5.pt
mkdir -p "$out"
held_out() {  # $1 goal points, $2 rule, $3 seed of the path
    local file="$out/u_chain_2_s${3}_$1_$2.json"
    produce_self "$file" $py -m specrefine.experiments.failures "data/results/ant/u_chain_2_s${3}_result.json" \
        --episodes 300 --seed 77 --policy "$pol" --goal-points "$1" --switching "$2" --walls-only --out "$file" \
        > /dev/null
}
for rule in slow-turn at-region; do  # at-region's runs are also the walls runs of stage 5 with --goal-points centre
    for s in 0 1 2; do held_out centre "$rule" "$s"; done
done
chain8() {  # $1 rule
    produce "$out/chain8_$1.json" $py -m specrefine.sim.train --agent ant --evaluate "$pol" --chain 8 --goal-range 3 5 \
        --episodes 200 --seed 5 --switching "$1"
}
chain8 slow-turn
for s in 0 1 2; do held_out sampled slow-turn "$s"; done
chain8 at-region  # the stage-5 checks' file again (data/results/ant/stage5_checks/chain8_stage5.json)
for s in 0 1 2; do held_out sampled at-region "$s"; done  # the stage-5 checks' runs with walls again
if [ "${PART:-}" = cells ] || [ "${PART:-}" = all ]; then  # U-chain 3 and 5, six cells (section 6)
    $py -m specrefine.runs.sweep --agent ant --methods ours --proposers geometric:max_waypoints=48 --seeds 0 1 2 \
        --mazes u_chain_3 u_chain_5 --switching slow-turn --workers 1 --out runs/ant_switching
    cp runs/ant_switching/results.csv "$out/uchain_slow_turn.csv"
fi
