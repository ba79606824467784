"""The cost of a refinement run, fixed vs adaptive evaluation, side by side in one process.

For each (maze, seed), ``refine_maze`` runs with ``evaluation="fixed"`` (the paper's 32 rollouts per
subtask estimate) and ``evaluation="adaptive"`` (:mod:`specrefine.refine.racing`), each from an empty
run folder (no cache shared), after one untimed warm-up run, the order alternating with the seed.
Each row records the run's simulator steps (search, calibration and the 200-episode measurement),
wall and process CPU seconds, evaluations and the measured success with its CI.  Rows are appended
to ``--table`` as each run finishes; a rerun skips the (maze, seed, evaluation) rows already there,
so a long Ant benchmark can be interrupted and resumed.
"""

from __future__ import annotations

import csv
import os
import shutil
import tempfile
import time
from pathlib import Path

from tqdm.auto import tqdm

from ..core.runfolder import appending_alone
from ..runs.config import DEFAULTS

COLUMNS = ["maze", "agent", "method", "proposer", "seed", "evaluation", "success_rate", "success_ci_low",
           "success_ci_high", "predicted_success", "predicted_ci_low", "predicted_ci_high", "evaluations",
           "sim_steps", "wall_seconds", "cpu_seconds", "path_edges", "refinements"]
EVALUATIONS = ("fixed", "adaptive")


def bench_refinement(mazes, seeds, agent: str = "ant", method: str = "ours", proposer: str = "geometric",
                     table=None, episodes: int = DEFAULTS.episodes) -> dict:
    """Run the grid (resuming ``table``, held by this run alone) and return totals and ratios per maze and overall."""
    if not table:
        return _bench(mazes, seeds, agent, method, proposer, episodes, [], None)
    Path(table).parent.mkdir(parents=True, exist_ok=True)
    with appending_alone(table, "table") as fh:  # never through a link; a second bench on this table is refused
        return _bench(mazes, seeds, agent, method, proposer, episodes, _read(table), fh)


def _bench(mazes, seeds, agent, method, proposer, episodes, rows: list[dict], fh) -> dict:
    done = {(r["maze"], int(r["seed"]), r["evaluation"]) for r in rows}
    todo = [(m, s, e) for m in mazes for s in seeds for e in _order(s) if (m, s, e) not in done]
    if todo:  # untimed: imports, policy, simulator builds, so that neither side pays them
        _run(todo[0][0], 0, "fixed", agent, "dirl", proposer, 8)
    writer = csv.DictWriter(fh, fieldnames=COLUMNS) if fh else None
    if writer and os.fstat(fh.fileno()).st_size == 0:
        writer.writeheader()
    for maze, seed, evaluation in tqdm(todo, desc=f"bench refinement ({agent})"):
        row = _run(maze, seed, evaluation, agent, method, proposer, episodes)
        rows.append(row)
        if writer:  # flushed row by row: an interrupted bench keeps what it measured
            writer.writerow(row)
            fh.flush()
    return summary([r for r in rows if r["maze"] in mazes and int(r["seed"]) in seeds])


def _order(seed: int) -> tuple[str, ...]:
    """Which evaluation runs first alternates with the seed (what warms up in the process is shared)."""
    return EVALUATIONS if seed % 2 == 0 else EVALUATIONS[::-1]


def _run(maze, seed, evaluation, agent, method, proposer, episodes) -> dict:
    from ..runs.pipeline import refine_maze

    out = Path(tempfile.mkdtemp(prefix="bench_refine_"))
    try:
        wall, cpu = time.perf_counter(), time.process_time()
        d = refine_maze(maze, agent=agent, method=method, proposer=proposer, seed=seed, out=out / "run",
                        episodes=episodes, evaluation=evaluation, progress=False).data
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    finally:
        shutil.rmtree(out, ignore_errors=True)
    return {"maze": d["maze"], "agent": agent, "method": method, "proposer": proposer, "seed": seed,
            "evaluation": evaluation, "success_rate": d["success_rate"], "success_ci_low": d["success_ci"][0],
            "success_ci_high": d["success_ci"][1], "predicted_success": d["predicted_success"],
            "predicted_ci_low": d["predicted_ci"][0], "predicted_ci_high": d["predicted_ci"][1],
            "evaluations": d["evaluations"], "sim_steps": d["sim_steps"], "wall_seconds": round(wall, 2),
            "cpu_seconds": round(cpu, 2), "path_edges": d["path_edges"], "refinements": d["refinements"]}


def summary(rows: list[dict]) -> dict:
    """Totals per evaluation and the fixed / adaptive ratios, per maze and over every (maze, seed) run by both."""
    pairs = {}
    for r in rows:
        pairs.setdefault((r["maze"], int(r["seed"])), {})[r["evaluation"]] = r
    both = {k: v for k, v in pairs.items() if set(EVALUATIONS) <= set(v)}
    out = {"pairs": len(both), "per_maze": {}}
    for maze in sorted({m for m, _ in both}):
        out["per_maze"][maze] = _ratios([v for (m, _), v in both.items() if m == maze])
    out["overall"] = _ratios(list(both.values()))
    return out


def markdown(rows: list[dict]) -> str:
    """One line per (maze, seed) run by both evaluations: steps, wall, success with CI, and the ratios."""
    pairs = {}
    for r in rows:
        pairs.setdefault((r["maze"], int(r["seed"])), {})[r["evaluation"]] = r
    lines = ["| maze | seed | sim steps fixed / adaptive (ratio) | wall s fixed / adaptive (ratio) | evaluations "
             "fixed / adaptive | success fixed [95 % CI] | success adaptive [95 % CI] |", "|" + " --- |" * 7]
    for (maze, seed), p in sorted(pairs.items()):
        if set(EVALUATIONS) - set(p):
            continue
        f, a = p["fixed"], p["adaptive"]
        cell = [maze, str(seed), _ratio_text(f, a, "sim_steps", "{:,.0f}"), _ratio_text(f, a, "wall_seconds", "{:.0f}"),
                f"{int(float(f['evaluations']))} / {int(float(a['evaluations']))}", _success_text(f), _success_text(a)]
        lines.append("| " + " | ".join(cell) + " |")
    return "\n".join(lines)


def _ratio_text(f: dict, a: dict, key: str, fmt: str) -> str:
    x, y = float(f[key]), float(a[key])
    return f"{fmt.format(x)} / {fmt.format(y)} ({x / y:.2f}x)"


def _success_text(r: dict) -> str:
    return f"{float(r['success_rate']):.3f} [{float(r['success_ci_low']):.3f}, {float(r['success_ci_high']):.3f}]"


def _ratios(pairs: list[dict]) -> dict:
    res = {}
    for key in ("sim_steps", "wall_seconds", "cpu_seconds", "evaluations"):
        fixed = sum(float(p["fixed"][key]) for p in pairs)
        adaptive = sum(float(p["adaptive"][key]) for p in pairs)
        res[key] = {"fixed": fixed, "adaptive": adaptive, "ratio": round(fixed / adaptive, 2) if adaptive else None}
    for ev in EVALUATIONS:
        res[f"success_{ev}"] = [round(float(p[ev]["success_rate"]), 3) for p in pairs]
    return res


def _read(path) -> list[dict]:
    path = Path(path)
    if not path.exists():
        return []
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))
