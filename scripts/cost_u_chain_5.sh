#!/bin/bash
# Issue 30's cost goal, measured: Ant U-chain 5 runs with the paper's rule, one at a time from a cold cache, then
# their time split (search / measurement / calibration) by python -m specrefine.experiments.cost into TABLE.
# Stop every other job first (kill -STOP -- -PGID): the runs are timed.
#   bash scripts/cost_u_chain_5.sh
# Environment: SEEDS ("0 1"), OUT (the run folders' parent, /tmp/cost_u5), TABLE (the JSON written,
# data/results/ant/scaling/cost_u_chain_5.json), EXTRA (more refine options, e.g. "--goal-points centre"), PYTHON.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
py=${PYTHON:-$root/.venv/bin/python}
out=${OUT:-/tmp/cost_u5}
table=${TABLE:-$root/data/results/ant/scaling/cost_u_chain_5.json}
options="--agent ant --method ours --proposer geometric:max_waypoints=48 --policy data/policies/ant_stage5.pt
         --evaluation adaptive ${EXTRA:-}"
results=() elapsed=()
for seed in ${SEEDS:-0 1}; do
    dir=$out/s$seed
    rm -rf "$dir" && mkdir -p "$out"
    # shellcheck disable=SC2086 # options are words
    /usr/bin/time -o "$dir.time" -f "%P CPU, %E elapsed" "$py" -m specrefine.cli refine u_chain_5 $options \
        --seed "$seed" --out "$dir" --quiet
    results+=("$dir/result.json") elapsed+=("seed $seed: $(cat "$dir.time")")
done
cpu=$(lscpu | sed -n 's/^Model name: *//p' | head -1)
"$py" -m specrefine.experiments.cost "${results[@]}" --out "$table" \
    --about "what=Ant U-chain 5, one run at a time, every other job stopped, cold evaluation cache" \
    --about "command=specrefine refine u_chain_5 $(echo $options) --seed SEED --out DIR --quiet" \
    --about "code=$(git rev-parse --short HEAD)$(git diff --quiet HEAD -- specrefine || echo ' with local changes')" \
    --about "machine=$(nproc) cores, $cpu; /usr/bin/time: ${elapsed[*]}"
