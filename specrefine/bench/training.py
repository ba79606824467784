"""Training throughput (frames/s including PPO updates): our config vs the reference TorchRL config.

    python -m specrefine.bench train [--agent ant] [--batches 4]

Both run in this process, one after the other, on the same batched env (``GoalReachEnv``); only the learner
settings differ.  The reference is TorchRL's ``sota-implementations/ppo`` MuJoCo config: 2048 frames
per batch, minibatch 64, 10 epochs (one torch thread too: with 2 threads on this shared 2-core machine
a 64-sample PPO step took 508 ms instead of 17 ms, which would make the comparison meaningless).
Ours: ``specrefine.sim.train.make_config`` (large minibatches, few epochs, one torch thread).
:func:`bench_train` returns one dict (the subcommand prints it as one JSON line); the figure is the median
over the measured batches (the first batch of each run is warm-up and not counted).
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from pathlib import Path


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
    return {"frames_per_batch": cfg.frames_per_batch, "minibatch": cfg.minibatch, "epochs": cfg.epochs,
            "torch_threads": cfg.torch_threads, "fps_median": statistics.median(fps), "fps_per_batch": fps,
            "wall_s": round(wall, 1)}


def bench_train(agent: str = "ant", batches: int = 4) -> dict:
    ours = measure(agent, batches)
    ref = measure(agent, batches, **reference_overrides())
    return {"agent": agent, "cpus": os.cpu_count(), "ours": ours, "reference_minibatch64": ref,
            "ratio": round(ours["fps_median"] / ref["fps_median"], 2)}
