"""The point mass in this package's simulator and in the official PointMaze-v3, on the same runs.

    PYTHONPATH=$PWD python scripts/official_gap.py [--episodes 1000] [--out data/official/point_gap.json]

For each maze: one ``specrefine refine --agent point --method ours --proposer geometric --seed 0`` run
(seconds), then the run's compositional policy on ``--episodes`` fresh episodes in both simulators: this
package's (``monitor.measure``, the run's own measurement with more episodes) and the official
environment (``specrefine official``).  Writes one JSON record (see docs/official_env.md).
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

MAZES = ["u_maze", "gr:U_MAZE", "gr:MEDIUM_MAZE", "gr:LARGE_MAZE"]
SIM_SEED = 777  # fresh episodes: neither the search's seed nor the run's measurement seed


def sim_side(run: Path, episodes: int) -> dict:
    import specrefine
    from specrefine.core.graph import TaskGraph
    from specrefine.core.results import wilson_ci
    from specrefine.evaluation.monitor import measure

    result = json.loads((run / "result.json").read_text())
    exp = specrefine.setup(json.loads((run / "run.json").read_text())["maze"], agent="point")
    m = measure(exp.evaluator, exp.graph, TaskGraph.from_dict(result["graph"]), result["path"], episodes, SIM_SEED)
    k = int(m.success.sum())
    return {"success_rate": k / episodes, "success_ci": list(wilson_ci(k, episodes)), "episodes": episodes,
            "outcomes": m.path_result.counts()}


def gap_table(record: dict) -> str:
    """The record as docs/official_env.md shows it: both simulators per maze, and official - this simulator."""
    from specrefine.core.results import difference_text, rate_text

    lines = ["| maze | official environment | legs | this simulator [95 % CI] (episodes) | official [95 % CI] "
             "(episodes) | official - this simulator [95 % CI] |", "|---|---|---|---|---|---|"]
    for row in record["rows"]:
        here, there = row["this_simulator"], row["official"]
        (ks, ns), (ko, no) = [(round(s["success_rate"] * s["episodes"]), s["episodes"]) for s in (here, there)]
        lines.append(f"| `{row['maze']}` | `{row['env_id']}` | {len(row['path']) - 1} | {rate_text(ks, ns)} | "
                     f"{rate_text(ko, no)} | {difference_text(ko, no, ks, ns)} |")
    return "\n".join(lines)


def main() -> None:
    from specrefine.cli import main as cli
    from specrefine.core.runfolder import writable_parent, write_atomic
    from specrefine.runs.official import run_official

    p = argparse.ArgumentParser()
    p.add_argument("--episodes", type=int, default=1000)
    p.add_argument("--out", default="data/official/point_gap.json")
    args = p.parse_args()
    out = writable_parent(args.out)  # before any run: no link, device or folder
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for maze in MAZES:
            run = Path(tmp) / maze.replace(":", "-")
            assert cli(["refine", maze, "--agent", "point", "--method", "ours", "--proposer", "geometric", "--seed",
                        "0", "--out", str(run)]) == 0
            official = run_official(run, episodes=args.episodes, seed=1)
            rows.append({"maze": maze, "env_id": official["env_id"], "path": json.loads((run / "result.json")
                                                                                       .read_text())["path"],
                         "this_simulator": sim_side(run, args.episodes),
                         "official": {k: official[k] for k in ("success_rate", "success_ci", "episodes", "outcomes")}})
    record = {"command": f"PYTHONPATH=$PWD python scripts/official_gap.py --episodes {args.episodes}",
              "agent": "point", "method": "ours", "proposer": "geometric", "seed": 0, "rows": rows}
    write_atomic(out, json.dumps(record, indent=1) + "\n")
    print(gap_table(record))


if __name__ == "__main__":
    from specrefine.core.argtypes import script_exit_code

    raise SystemExit(script_exit_code(main))
