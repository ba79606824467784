"""The AntMaze grid's table (docs/official_env.md, "The AntMaze grid"): each map and method in this package's
simulator and in the official ``AntMaze_*-v5``, pooled over seeds, with Wilson 95 % intervals.

    python -m specrefine.experiments.antmaze runs/antmaze runs/antmaze_centre --official 200 \\
        --out data/results/ant/antmaze

Reads every finished run folder of the grid's sweep (``RUN/result.json``); with ``--official N`` it first runs
``specrefine official RUN --episodes N`` where a run has no ``official.json`` yet (minutes per run), on episode seed
``--seed`` (0), or each run's own with ``--seed run``. Writes
``official.csv`` (one row per run: both simulators' success), ``table.md`` (pooled per map, method and proposer,
with the difference official - this simulator over the runs measured in both) and ``figure.png``. Every proposer
here is offline, NOT a VLM.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from ..core.argtypes import OneLineParser, exit_code_quiet_on_broken_pipe
from ..core.errors import SpecrefineError
from ..core.paper import PAPER
from ..core.results import difference_text, rate_text, wilson_ci
from ..core.runfolder import ensure_dir, locked, read_result, save_figure, write_atomic
from ..core.tables import csv_text, goal_points_of
from ..pictures.render import subplots
from ..runs.methods import METHOD_COLOURS, PROPOSER_METHODS
from ..runs.official import OFFICIAL_JSON, run_official

FIELDS = ["maze", "method", "proposer", "seed", "sim_successes", "sim_episodes", "official_successes",
          "official_episodes", "env_id"]


def run_rows(sweep_dirs, official_episodes: int | None = None, seed: int | str = 0) -> list[dict]:
    """One row per finished run under each ``sweep_dir/cells``; runs without official.json get one first if asked,
    on episode seed ``seed``, or on each run's own seed with ``seed="run"`` (runs of a deterministic proposer often
    save one policy, and one episode seed for all of them would repeat the same episodes)."""
    rows = []
    folders = [sweep_dirs] if isinstance(sweep_dirs, (str, Path)) else sweep_dirs
    for run in [r for folder in folders for r in sorted(Path(folder, "cells").glob("*/"))]:
        if not (run / "result.json").is_file():
            continue
        result = read_result(run / "result.json")
        official = run / OFFICIAL_JSON
        if not official.is_file() and official_episodes:
            run_official(run, official_episodes, int(result["seed"]) if seed == "run" else seed)
        off = json.loads(official.read_text()) if official.is_file() else None
        proposer = result["proposer"] if result["method"] in PROPOSER_METHODS else "none"  # as the sweep's table
        rows.append({"maze": result["maze"], "method": method_label(result), "proposer": proposer,
                     "seed": result["seed"], "sim_successes": round(result["success_rate"] * result["episodes"]),
                     "sim_episodes": result["episodes"],
                     "official_successes": "" if off is None else round(off["success_rate"] * off["episodes"]),
                     "official_episodes": "" if off is None else off["episodes"],
                     "env_id": "" if off is None else off["env_id"]})
    return rows


def method_label(result: dict) -> str:
    """The run's method, named with its goal-point rule when it aimed at the sets' centres (``--goal-points``)."""
    rule = goal_points_of(result)
    return result["method"] if rule == PAPER.goal_points else f"{result['method']} ({rule})"


def _pooled(rows, side: str) -> tuple[int, int]:
    done = [r for r in rows if r[f"{side}_episodes"] != ""]
    return sum(int(r[f"{side}_successes"]) for r in done), sum(int(r[f"{side}_episodes"]) for r in done)


MAP_ORDER = ("gr:U_MAZE", "gr:MEDIUM_MAZE", "gr:LARGE_MAZE")  # small to large, as the grid runs them


def groups(rows) -> dict[tuple, list[dict]]:
    """Runs by (map, method, proposer): the grid's maps small to large (others after them, by name)."""
    out: dict[tuple, list[dict]] = {}
    for r in sorted(rows, key=lambda r: (MAP_ORDER.index(r["maze"]) if r["maze"] in MAP_ORDER else len(MAP_ORDER),
                                         r["maze"])):
        out.setdefault((r["maze"], r["method"], r["proposer"]), []).append(r)
    return out


def table(rows) -> str:
    lines = ["| map | method | proposer | seeds | this simulator [95 % CI] (episodes) | official [95 % CI] "
             "(episodes) | official - this simulator [95 % CI] |", "|---|---|---|---|---|---|---|"]
    for (maze, method, proposer), runs in groups(rows).items():
        runs = sorted(runs, key=lambda r: int(r["seed"]))
        seeds = ",".join(str(r["seed"]) for r in runs)
        official = [str(r["seed"]) for r in runs if r["official_episodes"] != ""]
        if len(official) < len(runs):
            seeds += f" (official: {','.join(official) or 'none yet'})"
        lines.append(f"| {maze} | {method} | {proposer} | {seeds} | {rate_text(*_pooled(runs, 'sim'))} | "
                     f"{rate_text(*_pooled(runs, 'official'))} | {_difference(runs)} |")
    return "\n".join(lines)


def headline(rows, method: str, proposer: str) -> str:
    """'MAP here / official' pooled success per map of one method and proposer, as the README quotes it."""
    parts = []
    for (maze, m, p), runs in groups(rows).items():
        if (m, p) == (method, proposer):
            (ks, ns), (ko, no) = _pooled(runs, "sim"), _pooled(runs, "official")
            official = f"{ko / no:.3f}" if no else "—"
            parts.append(f"{maze.removeprefix('gr:')} {ks / ns:.3f} / {official}")
    return ", ".join(parts)


def _difference(runs) -> str:
    """Official minus this simulator over the runs measured in both, with Newcombe's 95 % interval."""
    both = [r for r in runs if r["official_episodes"] != ""]
    if not both:
        return "—"
    return difference_text(*_pooled(both, "official"), *_pooled(both, "sim"))


def figure(rows):
    by = groups(rows)
    maps = list(dict.fromkeys(k[0] for k in by))
    fig, axes = subplots(1, max(1, len(maps)), figsize=(5.5 * max(1, len(maps)), 4.2), squeeze=False, sharey=True)
    for ax, maze in zip(axes[0], maps):
        keys = [k for k in by if k[0] == maze]
        x = np.arange(len(keys))
        for offset, side, hatch in ((-0.2, "sim", ""), (0.2, "official", "//")):
            counts = [_pooled(by[k], side) for k in keys]
            rates = np.array([k / n if n else np.nan for k, n in counts])
            bounds = np.array([wilson_ci(k, n) if n else (np.nan, np.nan) for k, n in counts]).reshape(-1, 2)
            colours = [METHOD_COLOURS.get(k[1].split()[0], "grey") for k in keys]  # "ours (centre)": ours's
            ax.bar(x + offset, rates, 0.4, color=colours, hatch=hatch, edgecolor="black", linewidth=0.5,
                   yerr=np.abs(bounds.T - rates), capsize=2, error_kw={"linewidth": 0.8},
                   label="this simulator" if side == "sim" else "official env")
        ax.set_xticks(x, [f"{k[1]}\n{k[2]}" for k in keys], fontsize=7, rotation=30, ha="right")
        ax.set_ylim(0, 1.05)
        ax.set_title(f"{maze} (offline proposers, not a VLM)", fontsize=9)
        ax.grid(axis="y", alpha=0.3)
    axes[0, 0].set_ylabel("success rate, pooled over seeds (Wilson 95 %)")
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    return fig


def episode_seed(text: str) -> int | str:
    """``--seed``: an integer, or 'run' for each run's own seed."""
    if text == "run":
        return text
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: an integer or 'run'") from None


def main(argv=None) -> int:
    p = OneLineParser(prog="python -m specrefine.experiments.antmaze", description=__doc__.split("\n")[0])
    p.add_argument("sweep_dirs", nargs="+", help="the AntMaze grids' sweep folders (runs/antmaze runs/antmaze_centre)")
    p.add_argument("--official", type=int, default=None, metavar="N",
                   help="run the official environment on N episodes where a run has no official.json yet")
    p.add_argument("--seed", type=episode_seed, default=0,
                   help="the official episodes' seed, or 'run': each run's own seed, so that runs which saved the "
                        "same policy meet different episodes (default 0, as the shipped AntMaze tables ran)")
    p.add_argument("--out", type=Path, required=True)
    args = p.parse_args(argv)
    try:
        out = ensure_dir(args.out)  # before minutes of official episodes
        rows = run_rows(args.sweep_dirs, args.official, args.seed)
        with locked(out):
            write_atomic(out / "official.csv", csv_text(rows, FIELDS))
            write_atomic(out / "table.md", table(rows) + "\n")
            save_figure(figure(rows), out / "figure.png", dpi=110)
    except SpecrefineError as exc:
        p.exit(2, f"{p.prog}: error: {exc}\n")
    print(f"{len(rows)} runs -> {out}: official.csv, table.md, figure.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
