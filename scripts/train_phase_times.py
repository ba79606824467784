"""Where a PPO iteration's wall time goes (Ant, ``make_config`` defaults): per batch, the physics (``BatchedSim.step``),
the policy during the collection (``GoalPolicy.forward``), the rest of the collection, and the update. One JSON line.
Works on the trainer before and after issue 42 (run it with PYTHONPATH at the checkout to time); time it quietly:

    bash /tmp/quiet.sh env PYTHONPATH=$PWD .venv/bin/python scripts/train_phase_times.py [THREADS [UPDATE_THREADS]]
"""

import json
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

from specrefine.sim import policy, simulator
from specrefine.sim.train import Trainer, make_config

seconds = {"physics": 0.0, "policy_collect": 0.0, "update": 0.0}
calls = {"step": 0}
updating = [False]


def timed(cls, name, key, counted=False):
    inner = getattr(cls, name)

    def wrapper(*args, **kwargs):
        if key == "policy_collect" and updating[0]:
            return inner(*args, **kwargs)
        calls["step"] += counted
        t = time.perf_counter()
        try:
            return inner(*args, **kwargs)
        finally:
            seconds[key] += time.perf_counter() - t

    setattr(cls, name, wrapper)


def main() -> None:
    warnings.filterwarnings("ignore")
    timed(simulator.BatchedSim, "step", "physics", counted=True)
    timed(policy.GoalPolicy, "forward", "policy_collect")
    update = Trainer.update

    def timed_update(self, batch):
        updating[0] = True
        t = time.perf_counter()
        try:
            return update(self, batch)
        finally:
            seconds["update"] += time.perf_counter() - t
            updating[0] = False

    Trainer.update = timed_update
    threads = int(sys.argv[1]) if len(sys.argv) > 1 else 1
    extra = {"update_threads": int(sys.argv[2])} if len(sys.argv) > 2 else {}
    cfg = make_config("ant", checkpoint_every_s=1e9, torch_threads=threads, **extra)
    cfg.frames = cfg.frames_per_batch * 5
    with tempfile.TemporaryDirectory() as out:
        trainer = Trainer(cfg, out, progress=False)
        trainer.save_checkpoint = lambda: None
        trainer.train()
        rows = [json.loads(line) for line in (Path(out) / "log.jsonl").read_text().splitlines()]
    collections = calls["step"] / cfg.steps_per_env  # the old trainer collected one batch more than it logged
    batch = statistics.median(cfg.frames_per_batch / r["fps"] for r in rows[1:])
    per = {"physics": seconds["physics"] / collections, "policy_collect": seconds["policy_collect"] / collections,
           "update": seconds["update"] / len(rows), "batch_wall_median": batch}
    per["collection"] = batch - per["update"]
    per["collection_other"] = per["collection"] - per["physics"] - per["policy_collect"]
    print(json.dumps({"torch_threads": threads, **extra, "batches": len(rows), "collections": collections,
                      "fps_log": [r["fps"] for r in rows],
                      "fps_median": round(statistics.median(r["fps"] for r in rows[1:]), 1),
                      **{k: round(v, 3) for k, v in per.items()}}))


if __name__ == "__main__":
    main()
