"""One refinement timed in-process after a warm-up run (imports, first model builds), to compare two commits.

Run it back to back in both checkouts (the old one through PYTHONPATH, so that its own package is imported):

    cd OLD_WORKTREE && PYTHONPATH=$PWD /path/to/.venv/bin/python /path/to/scripts/ab_refine_speed.py old
    cd NEW_CHECKOUT && .venv/bin/python scripts/ab_refine_speed.py new

Each prints one JSON line: which package ran, wall and CPU seconds, success, evaluations, simulator steps
(equal counts say both commits did the same work).
"""
import argparse
import json
import shutil
import tempfile
import time
from pathlib import Path

import specrefine
from specrefine.runs.pipeline import refine_maze


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("label")
    ap.add_argument("--maze", default="data/mazes/u_chain_5.maze")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--evaluation", default="adaptive")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        refine_maze("data/mazes/split_doorway.maze", seed=0, episodes=8, out=Path(tmp) / "warm")
        shutil.rmtree(Path(tmp) / "warm")
        t, c = time.time(), time.process_time()
        r = refine_maze(args.maze, seed=args.seed, evaluation=args.evaluation, out=Path(tmp) / "run")
        wall, cpu = time.time() - t, time.process_time() - c
    print(json.dumps({"label": args.label, "package": str(Path(specrefine.__file__).parent), "maze": args.maze,
                      "seed": args.seed, "evaluation": args.evaluation, "wall_s": round(wall, 2),
                      "cpu_s": round(cpu, 2), **{k: r.data[k] for k in ("success_rate", "evaluations", "sim_steps")}}))


if __name__ == "__main__":
    from specrefine.core.argtypes import script_exit_code

    raise SystemExit(script_exit_code(main))
