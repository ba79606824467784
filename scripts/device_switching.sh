#!/bin/bash
# Issue 42, lever 1 at scale (docs/ant_experiments.md, "slow-turn against at-region on thousands of held-out
# episodes"): stage 5 on the three held-out U-chain 2 paths, centre goal points, walls only, both switching rules on
# the same episode seeds (SEEDS, 300 episodes each), as many jobs at once as the machine has cores, until DEADLINE_S
# seconds after the start; a job not finished by then is dropped (the table pairs only what both rules finished).
# Meant for a lent device (the device tool's `run`, with the wheels it lacks in .whl), runs on any machine:
#   OUT=$OUT bash scripts/device_switching.sh      (OUT/switching.tar: one failures report per job; OUT/device.log)
# Tables: python scripts/switching_scale_table.py FOLDER (the tar unpacked there).
set -uo pipefail
out=${OUT:?OUT=folder for the reports}
py=${PYTHON:-python3}
deadline=$(($(date +%s) + ${DEADLINE_S:-420}))
seeds=${SEEDS:-"1001 1002 1003 1004 1005 1006 1007 1008 1009 1010"}
episodes=${EPISODES:-300}
cores=$(nproc)  # before OMP_NUM_THREADS=1, which nproc obeys
if ! $py -c "import mujoco, torchrl" 2>/dev/null && [ -d .whl ]; then  # the device has neither
    $py -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl \
        || exit 1
    export PYTHONPATH=/tmp/site:$PWD
fi
export PYTHONUNBUFFERED=1 OMP_NUM_THREADS=1 PY=$py DEADLINE=$deadline EPISODES=$episodes
$py -c "import mujoco, torch, specrefine.experiments.failures" || exit 1
reports=/tmp/switching
mkdir -p $reports
export REPORTS=$reports
job() {  # SEED PATH RULE: one failures report, or nothing if the deadline comes first
    local left=$((DEADLINE - $(date +%s))) file=$REPORTS/u_chain_2_s$2_centre_$3_seed$1.json
    [ "$left" -gt 20 ] || { echo "skipped $1 s$2 $3"; return 0; }
    timeout "$left" $PY -m specrefine.experiments.failures "data/results/ant/u_chain_2_s$2_result.json" \
        --episodes "$EPISODES" --seed "$1" --policy data/policies/ant_stage5.pt --goal-points centre \
        --switching "$3" --walls-only --out "$file.tmp" > /dev/null 2>&1 && mv "$file.tmp" "$file" \
        && echo "done $1 s$2 $3 $(date -u +%H:%M:%S)"
}
export -f job
for seed in $seeds; do for s in 0 1 2; do for rule in at-region slow-turn; do echo "$seed $s $rule"; done; done; done \
    | xargs -P "$cores" -L 1 bash -c 'job "$@"' _ | tee "$out/device.log"
rm -f $reports/*.tmp
tar -C $reports -cf "$out/switching.tar" .
echo "$(ls $reports | wc -l) reports on $cores cores ($(lscpu | sed -n 's/^Model name: *//p'))" | tee -a "$out/device.log"
