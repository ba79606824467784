#!/bin/bash
# Stage 9 on a lent device (issue 42, lever 6; docs/ant_experiments.md): stage 5's recipe in 8,192-frame batches
# (256 environments x 32 steps), for as many frames as TRAIN_S seconds give on the machine's cores (a short probe
# of the same command sets the count, so the learning rate anneals to its end as in every stage), then the checks
# 1-4 of stage 8 for stage 9 and stage 5 side by side on that machine, all at once, until CHECK_S seconds are up
# (what does not finish runs later on the 2-core machine: bash scripts/ant_stage8_checks.sh with NEW, TAG, OUT).
# Run through the device tool from the checkout's root, with the wheels of README's device notes in .whl:
#   OUT=$OUT bash scripts/device_stage9.sh      (OUT/stage9: checkpoint, policy, log, curve; OUT/checks.tar)
set -uo pipefail
out=${OUT:?OUT=folder for the policy and the checks}
py=${PYTHON:-python3}
train_s=${TRAIN_S:-380}
check_s=${CHECK_S:-140}
cores=$(nproc)
if ! $py -c "import mujoco, torchrl" 2>/dev/null && [ -d .whl ]; then  # the device has neither
    $py -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl \
        || exit 1
    export PYTHONPATH=/tmp/site:$PWD
fi
export PYTHONUNBUFFERED=1
$py -c "import specrefine.sim.train, specrefine.experiments.failures" || exit 1
recipe=(--agent ant --init data/policies/ant_stage5.pt --observation-frame heading --critic-warmup-frames 500000
        --goals-per-episode 5 --lr 1e-4 --tilt-cost 0.5 --lateral-cost 0.5 --switch-radius 0.5 1.6 --seed 10
        --num-envs 256 --steps-per-env 32 --sim-threads $((cores - 1)) --update-threads "$cores" --no-progress)
batch=8192
probe_frames=$((batch * 24))
start=$(date +%s.%N)
$py -m specrefine.sim.train "${recipe[@]}" --frames $probe_frames --out /tmp/probe > /dev/null || exit 1
probe_s=$($py -c "import time; print(time.time() - $start)")
frames=$($py -c "print(int($probe_frames * $train_s / $probe_s) // $batch * $batch)")
echo "probe: $probe_frames frames in ${probe_s} s on $cores cores; training $frames frames"
$py -m specrefine.sim.train "${recipe[@]}" --frames "$frames" --checkpoint-every-s 60 --out "$out/stage9"
echo "trained: $(date -u +%H:%M:%S)"

checks=/tmp/checks
mkdir -p $checks
for tag in stage9 stage5; do
    pol=data/policies/ant_$tag.pt
    [ $tag = stage9 ] && pol=$out/stage9/policy.pt
    ev=(timeout "$check_s" $py -m specrefine.sim.train --agent ant --evaluate "$pol" --no-progress)
    ("${ev[@]}" --episodes 500 --seed 1 --goal-range 2 6 > $checks/open_floor_$tag.json.tmp \
        && mv $checks/open_floor_$tag.json.tmp $checks/open_floor_$tag.json) &
    ("${ev[@]}" --chain 8 --goal-range 3 5 --episodes 200 --seed 5 --planned-goals > $checks/chain8_$tag.json.tmp \
        && mv $checks/chain8_$tag.json.tmp $checks/chain8_$tag.json) &
    ("${ev[@]}" --chain 8 --goal-range 3 5 --turn-goals 90 180 --episodes 500 --seed 5 --planned-goals \
        > $checks/turn_chain8_$tag.json.tmp && mv $checks/turn_chain8_$tag.json.tmp $checks/turn_chain8_$tag.json) &
    for s in 0 1 2; do
        timeout "$check_s" $py -m specrefine.experiments.failures "data/results/ant/u_chain_2_s${s}_result.json" \
            --episodes 300 --seed 77 --policy "$pol" --goal-points centre --walls-only \
            --out $checks/u_chain_2_s${s}_centre_$tag.json > /dev/null &
    done
done
wait
rm -f $checks/*.tmp
tar -C $checks -cf "$out/checks.tar" .
echo "checks: $(ls $checks | tr '\n' ' ')"
