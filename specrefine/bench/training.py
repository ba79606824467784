"""Training throughput (frames/s including PPO updates) against raw ``mujoco.rollout`` of the same model, and our
config against the reference TorchRL config.

    python -m specrefine.bench train [--agent ant] [--batches 4] [--no-reference]

All in this process: our config (``specrefine.sim.train.make_config``: large minibatches, few epochs), then the raw
physics ceiling, ``mujoco.rollout`` stepping the training env's model (open floor) with random controls in the same
batch shape (``num_envs`` rollouts, ``steps_per_env`` control steps, ``sim_threads`` threads), as one long call
(``raw_rollout_steps_per_s``) and as one call per control step (``raw_per_step_steps_per_s``), each the median of
``batches`` repeats; ``ratio_vs_raw_rollout`` = ours / the long call.  Then the reference, TorchRL's
``sota-implementations/ppo`` MuJoCo config on the same env: 2048 frames per batch, minibatch 64, 10 epochs (one
torch thread: with 2 threads on this shared 2-core machine a 64-sample PPO step took 508 ms instead of 17 ms).
A configuration's figure is the median over its measured batches (the first batch of each run is warm-up and not
counted). :func:`bench_train` returns one dict (the subcommand prints it as one JSON line).
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np


def reference_overrides() -> dict:
    return dict(num_envs=32, steps_per_env=64, minibatch=64, epochs=10, torch_threads=1)


def measure(agent: str, batches: int, **overrides) -> dict:
    from ..sim.curves import read_log
    from ..sim.train import Trainer, make_config

    cfg = make_config(agent, checkpoint_every_s=1e9, **overrides)
    cfg.frames = cfg.frames_per_batch * (batches + 1)
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        Trainer(cfg, out, progress=False).train()
        wall = time.perf_counter() - t0
        fps = [r["fps"] for r in read_log(Path(out) / "log.jsonl")[1:]]
    return {"frames_per_batch": cfg.frames_per_batch, "num_envs": cfg.num_envs, "steps_per_env": cfg.steps_per_env,
            "minibatch": cfg.minibatch, "epochs": cfg.epochs, "torch_threads": cfg.torch_threads,
            "sim_threads": cfg.sim_threads, "fps_median": statistics.median(fps), "fps_per_batch": fps,
            "wall_s": round(wall, 1)}


def raw_rollout(agent: str, num_envs: int, steps: int, nthread: int, repeats: int) -> dict:
    """Steps/s of ``mujoco.rollout`` alone on the training env's model, random controls, in a batch's shape."""
    from ..sim.simulator import BatchedSim
    from .evaluator import _raw_rollout

    sim = BatchedSim(agent, None, num_envs, nthread=nthread)
    rng = np.random.default_rng(0)
    runs = [_raw_rollout(sim.model, num_envs, sim.frame_skip, sim.nthread, steps, rng) for _ in range(repeats)]
    long_call, per_step, _ = (statistics.median(x) for x in zip(*runs, strict=True))
    return {"raw_rollout_steps_per_s": round(long_call, 1), "raw_per_step_steps_per_s": round(per_step, 1),
            "raw_rollout_runs": [round(r[0], 1) for r in runs], "raw_nthread": sim.nthread}


def bench_train(agent: str = "ant", batches: int = 4, reference: bool = True) -> dict:
    import mujoco
    import torch

    from .evaluator import _cpu_name

    ours = measure(agent, batches)
    raw = raw_rollout(agent, ours["num_envs"], ours["steps_per_env"], ours["sim_threads"], batches)
    out = {"bench": "train", "agent": agent, "ours": ours, **raw,
           "ratio_vs_raw_rollout": round(ours["fps_median"] / raw["raw_rollout_steps_per_s"], 3),
           "ratio_vs_raw_per_step": round(ours["fps_median"] / raw["raw_per_step_steps_per_s"], 3)}
    if reference:
        ref = measure(agent, batches, **reference_overrides())
        out |= {"reference_minibatch64": ref, "ratio": round(ours["fps_median"] / ref["fps_median"], 2)}
    return out | {"cpus": os.cpu_count(), "cpu": _cpu_name(), "load_avg_1m": round(os.getloadavg()[0], 2),
                  "mujoco": mujoco.__version__, "torch": torch.__version__}
