"""Training throughput (frames/s including PPO updates): our config vs the reference TorchRL config.

    python benchmarks/bench_train.py [--agent ant] [--batches 4]

Both run in this process, one after the other, on the same batched env (``GoalReachEnv``); only the learner
settings differ.  The reference is TorchRL's ``sota-implementations/ppo`` MuJoCo config: 2048 frames
per batch, minibatch 64, 10 epochs (one torch thread too: with 2 threads on this shared 2-core machine
a 64-sample PPO step took 508 ms instead of 17 ms, which would make the comparison meaningless).
Ours: ``specrefine.train.make_config`` (large minibatches, few epochs, one torch thread).
Prints one JSON line; the figure is the median over the measured batches (the first batch of each
run is warm-up and not counted).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from specrefine.train import Trainer, make_config, read_log  # noqa: E402


def reference_overrides() -> dict:
    return dict(num_envs=32, steps_per_env=64, minibatch=64, epochs=10, torch_threads=1)


def measure(agent: str, batches: int, **overrides) -> dict:
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


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--agent", choices=["point", "ant"], default="ant")
    ap.add_argument("--batches", type=int, default=4, help="measured batches per configuration")
    args = ap.parse_args(argv)
    ours = measure(args.agent, args.batches)
    ref = measure(args.agent, args.batches, **reference_overrides())
    print(json.dumps({"agent": args.agent, "cpus": os.cpu_count(), "ours": ours, "reference_minibatch64": ref,
                      "ratio": round(ours["fps_median"] / ref["fps_median"], 2)}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
