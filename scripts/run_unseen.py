"""Run the off-suite mazes in data/mazes/unseen/ into a sweep-style table (data/results/unseen/).

    .venv/bin/python scripts/run_unseen.py --out runs/unseen            # point, ours, geometric, seed 0
    cp runs/unseen/results.csv data/results/unseen/

Why not ``python -m specrefine.runs.sweep --mazes data/mazes/unseen/*.maze``: it works now (a maze file outside
data/mazes/ gets cells named by its stem and a hash of its path), but the shipped table was written when the sweep could
not load subfolders, with the bare stems as names; this script keeps those names. It runs the cells one at a time
with the full path and writes the same layout as the sweep: ``OUT/results.csv`` (columns
``specrefine.runs.sweep.COLUMNS``, one row per run, built by ``specrefine.runs.sweep.result_row``) and
``OUT/cells/<cell id>/`` (each run's ``result.json``, pictures, step log, cache). Cells that already have an ``ok``
row are skipped.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from specrefine.core.runfolder import ensure_dir, locked  # noqa: E402
from specrefine.runs.pipeline import refine_maze  # noqa: E402
from specrefine.runs.sweep import Cell, _append, pending, result_row  # noqa: E402


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--mazes", nargs="+", default=sorted(str(f) for f in (ROOT / "data/mazes/unseen").glob("*.maze")))
    p.add_argument("--agent", default="point")
    p.add_argument("--method", default="ours")
    p.add_argument("--proposer", default="geometric")
    p.add_argument("--seeds", nargs="+", type=int, default=[0])
    p.add_argument("--rollouts", type=int, default=32)
    p.add_argument("--episodes", type=int, default=200)
    p.add_argument("--out", default="runs/unseen")
    args = p.parse_args(argv)

    out = ensure_dir(Path(args.out))
    with locked(out):  # a second run_unseen (or a sweep) on OUT would race its table
        table = out / "results.csv"
        files = {Path(m).stem: Path(m) for m in args.mazes}
        cells = [Cell.of(name, args.agent, args.method, args.proposer, seed, rollouts=args.rollouts,
                         episodes=args.episodes)
                 for name in files for seed in args.seeds]
        for cell in pending(cells, table):
            result = refine_maze(files[cell.maze], agent=cell.agent, method=cell.method, proposer=cell.proposer,
                                 seed=cell.seed, out=out / "cells" / cell.id, rollouts=cell.rollouts,
                                 episodes=cell.episodes)
            d = result.data
            # the row as specrefine.runs.sweep.run_cell builds it
            _append(table, result_row(d, {**asdict(cell), "cell": cell.id}) | {"proposer_is_vlm": d["proposer_is_vlm"]})
            lo, hi = d["success_ci"]
            print(f"{cell.id}: {d['success_rate']:.3f} [{lo:.3f}, {hi:.3f}] over {d['episodes']} episodes, "
                  f"{d['evaluations']} evaluations, {d['wall_seconds']:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    from specrefine.core.argtypes import script_exit_code

    raise SystemExit(script_exit_code(main))
