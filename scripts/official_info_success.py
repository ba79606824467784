"""The official environment's own ``info["success"]`` beside ``specrefine official``'s verdict, on the same episodes.

    PYTHONPATH=$PWD python scripts/official_info_success.py [--episodes 200] [--out data/official/info_success.json]

For each run (``specrefine refine gr:MEDIUM_MAZE --agent point --proposer geometric --seed 0``, methods ``ours``
and ``dirl``; seconds each) the loop of docs/official_env.md (:func:`specrefine.runs.official.judged_env`, seed 0)
counts per episode: the judge's ``task_success`` (what ``specrefine official --seed 0`` counts), the environment's
``info["success"]`` at the episode's last step and at any step, and the distance from the agent to the
environment's goal point (``desired_goal``) at the last step.  Writes one JSON record (docs/official_env.md).
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np

MAZE, METHODS = "gr:MEDIUM_MAZE", ("ours", "dirl")


def count(run: Path, episodes: int) -> dict:
    from specrefine.runs.official import judged_env

    env = judged_env(run, seed=0)
    judged, last, ever, distance, outcomes = 0, 0, 0, [], {}
    for episode in range(episodes):
        obs, info = env.reset(seed=0 if episode == 0 else None)
        terminated = truncated = False
        hit = info["success"]
        while not (terminated or truncated):
            obs, _, terminated, truncated, info = env.step(env.policy.act(obs))
            hit = hit or info["success"]
        judged += info["task_success"]
        last += info["success"]
        ever += hit
        distance.append(float(np.linalg.norm(obs["achieved_goal"] - obs["desired_goal"])))
        outcomes[info["outcome"]] = outcomes.get(info["outcome"], 0) + 1
    env.close()
    return {"episodes": episodes, "task_success": int(judged), "info_success_last_step": int(last),
            "info_success_any_step": int(ever), "outcomes": outcomes,
            "last_step_distance_to_desired_goal": {"median": float(np.median(distance)), "min": min(distance),
                                                   "max": max(distance)}}


def main() -> None:
    from specrefine.cli import main as cli
    from specrefine.core.runfolder import writable_parent, write_atomic

    p = argparse.ArgumentParser()
    p.add_argument("--episodes", type=int, default=200)
    p.add_argument("--out", default="data/official/info_success.json")
    args = p.parse_args()
    out = writable_parent(args.out)  # before any run: no link, device or folder
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for method in METHODS:
            run = Path(tmp) / method
            command = ["refine", MAZE, "--agent", "point", "--method", method, "--proposer", "geometric", "--seed",
                       "0", "--out", str(run), "--quiet"]
            assert cli(command) == 0
            rows.append({"maze": MAZE, "method": method, "command": "specrefine " + " ".join(command[:-3]),
                         **count(run, args.episodes)})
            print(json.dumps(rows[-1]), flush=True)
    record = {"script": "scripts/official_info_success.py", "episodes": args.episodes, "seed": 0, "rows": rows,
              "success_radius_m": 0.45}
    write_atomic(out, json.dumps(record, indent=2) + "\n")


if __name__ == "__main__":
    from specrefine.core.argtypes import script_exit_code

    raise SystemExit(script_exit_code(main))
