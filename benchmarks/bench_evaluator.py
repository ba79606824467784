"""Evaluator throughput vs raw mujoco.rollout vs TorchRL GymEnv around Gymnasium-Robotics, in one run.

    .venv/bin/python benchmarks/bench_evaluator.py --agent ant      # ~1-2 minutes on 2 cores
    .venv/bin/python benchmarks/bench_evaluator.py --agent point --batch 256

Prints one JSON line.  The three figures come from the same process, one after another:

* ``evaluator``: ``specrefine.bench.bench_evaluator`` (Evaluator.evaluate with the 2x256 policy in the
  loop, batch ``--batch``), and in the same rounds the raw ``mujoco.rollout`` ceiling of the same model;
* ``gymenv``: ``torchrl.envs.GymEnv("AntMaze_UMaze-v5")`` (or ``PointMaze_UMaze-v3``), one environment,
  random actions, ``env.rollout`` -- the usual "one gym env per rollout" way, for comparison.  Skipped
  with a note when Gymnasium-Robotics' env cannot be built here.
"""

from __future__ import annotations

import argparse
import json
import time
import warnings

GYM_IDS = {"ant": "AntMaze_UMaze-v5", "point": "PointMaze_UMaze-v3"}


def bench_gymenv(agent: str, steps: int = 2000) -> dict:
    try:
        import gymnasium as gym
        import gymnasium_robotics
        from torchrl.envs import GymEnv

        gym.register_envs(gymnasium_robotics)
        env = GymEnv(GYM_IDS[agent])
        env.set_seed(0)
        env.rollout(50, break_when_any_done=False)  # warm-up
        t = time.perf_counter()
        env.rollout(steps, break_when_any_done=False)
        dt = time.perf_counter() - t
        env.close()
        return {"env": GYM_IDS[agent], "steps": steps, "env_steps_per_s": round(steps / dt, 1)}
    except Exception as e:  # not installed / cannot build here
        return {"env": GYM_IDS[agent], "skipped": f"{type(e).__name__}: {str(e)[:200]}"}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--agent", choices=("point", "ant"), default="ant")
    ap.add_argument("--batch", type=int, default=32)
    ap.add_argument("--seconds", type=float, default=9.0)
    ap.add_argument("--gym-steps", type=int, default=2000)
    args = ap.parse_args(argv)
    warnings.filterwarnings("ignore")
    from specrefine.bench import bench_evaluator

    ev = bench_evaluator(args.agent, args.batch, args.seconds)
    gym = bench_gymenv(args.agent, args.gym_steps)
    out = {"evaluator": ev, "gymenv": gym}
    if "env_steps_per_s" in gym:
        out["evaluator_over_gymenv"] = round(ev["env_steps_per_s"] / gym["env_steps_per_s"], 2)
    out["evaluator_over_raw_rollout"] = ev["ratio_vs_raw_rollout"]
    print(json.dumps(out), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
