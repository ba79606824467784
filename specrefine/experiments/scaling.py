"""The Ant scaling grid's decision rules (docs/ant_experiments.md section 5), computed from its tables.

    python -m specrefine.experiments.scaling data/results/ant/scaling/*.csv --out data/results/ant/scaling

Writes ``claims.md`` (the rules' verdicts, every cell's run listed), ``legs.md`` (legs per room, per-leg failure
and cost per maze), ``erring_seeds.md`` (the erring proposer's three methods, seed by seed) and ``figure5.png``
(success against rooms). Every proposer here is offline, NOT a VLM.

* *Flat at 0.90*: ``ours`` x ``geometric:max_waypoints=48``, success pooled over the seeds (600 episodes) at least
  0.90 on every maze, and the change from 1 to 5 rooms flat (:func:`comparison.rooms_claim`).
* *Erring proposer*: per maze, the better of ``ours`` and ``ours-repair`` x ``imperfect:moderate`` (higher mean
  over seeds) reaches at least 2x ``vlm-oneshot``'s mean success on the multi-room cells, and no run of the chosen
  method sits at 0 on a maze where the one-shot's mean is above 0.5.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..core.argtypes import OneLineParser, exit_code_quiet_on_broken_pipe
from ..core.errors import SpecrefineError
from ..core.results import wilson_ci
from ..core.runfolder import ensure_dir, save_figure, write_atomic
from ..core.tables import goal_points_of
from ..runs.sweep import is_done, read_checked_table
from . import comparison as cmp
from .figures import figure5
from .grids import SCALING_MAZES
from .legs import HEADER as LEGS_HEADER
from .legs import line as legs_line
from .legs import pooled, rooms

ORACLE = "geometric:max_waypoints=48"
ERRING = "imperfect:moderate"
SEEDS = (0, 1, 2)
MAZES = SCALING_MAZES  # the scaling grids' (experiments/grids.py)
LEVEL = 0.90
RATIO = 2.0
ONESHOT_HIGH = 0.5
METHODS = ("ours", "ours-repair", "vlm-oneshot")


def read_rows(tables) -> list[dict]:
    """The done Ant rows of every table, all run with one goal-point rule (two would be two grids in one)."""
    rows = [r for t in tables for r in read_checked_table(t) if is_done(r) and r["agent"] == "ant"]
    rules = sorted({goal_points_of(r) for r in rows})
    if len(rules) > 1:
        raise SpecrefineError(f"the tables mix goal-point rules ({', '.join(rules)}): judge each grid on its own")
    return rows


def _runs(rows, maze, method, proposer) -> list[dict]:
    return sorted((r for r in rows if (r["maze"], r["method"], r["proposer"]) == (maze, method, proposer)
                   and int(r["seed"]) in SEEDS), key=lambda r: int(r["seed"]))


def flat_claim(rows, method: str = "ours", level: float = LEVEL, tolerance: float = cmp.FLAT_TOLERANCE) -> dict:
    """The first rule on ``method`` x ORACLE: every maze pooled at least ``level``, and the 1-5 room change flat
    (its interval within +-``tolerance``)."""
    per_maze, complete = {}, True
    for maze in MAZES:
        runs = _runs(rows, maze, method, ORACLE)
        complete &= len(runs) == len(SEEDS)
        if runs:
            ok, n = pooled(runs)
            per_maze[maze] = {"success": ok / n, "ci": list(wilson_ci(ok, n)), "episodes": n, "seeds": len(runs),
                              "runs": [r["success_rate"] for r in runs]}
    cells, failed = cmp.table_cells(rows, "ant")
    change = cmp.rooms_claim(cells, failed, ORACLE, method, SEEDS)
    change_verdict = cmp.rooms_verdict((change["ci_low"], change["ci_high"]), tolerance)
    level_met = len(per_maze) == len(MAZES) and all(m["success"] >= level for m in per_maze.values())
    verdict = "holds" if level_met and change_verdict == "flat" else "not met"
    return {"claim": f"{method} x {ORACLE}: at least {level:.2f} on every maze, flat (+-{tolerance:.2f}) from 1 to "
                     "5 rooms",
            "verdict": verdict if complete else f"partial ({verdict} so far)", "complete": complete,
            "per_maze": per_maze, "below_level": sorted(m for m, v in per_maze.items() if v["success"] < level),
            "change_1_to_5": change["estimate"], "change_ci": [change["ci_low"], change["ci_high"]],
            "change_verdict": change_verdict}


def _mean(runs) -> float | None:
    return sum(r["success_rate"] for r in runs) / len(runs) if runs else None


def erring_claim(rows) -> dict:
    """The second rule on ERRING: the better of ours / ours-repair per maze against the one-shot."""
    chosen, zeros, pairs, complete, at_zero, ours_runs = {}, [], [], True, [], 0
    for maze in MAZES:
        by = {m: _runs(rows, maze, m, ERRING) for m in METHODS}
        complete &= all(len(v) == len(SEEDS) for v in by.values())
        ours_runs += len(by["ours"])
        repaired = {r["seed"]: r["success_rate"] for r in by["ours-repair"]}
        at_zero += [{"maze": maze, "seed": r["seed"], "ours_repair": repaired.get(r["seed"])}
                    for r in by["ours"] if r["success_rate"] == 0.0]
        means = {m: _mean(by[m]) for m in ("ours", "ours-repair") if by[m]}
        if not means:
            continue
        best = max(means, key=lambda m: (means[m], m == "ours"))  # a tie keeps the paper's method
        chosen[maze] = {"method": best, "mean": means[best], "oneshot": _mean(by["vlm-oneshot"])}
        oneshot = chosen[maze]["oneshot"]
        if oneshot is not None and oneshot > ONESHOT_HIGH:
            zeros += [f"{maze} seed {r['seed']}" for r in by[best] if r["success_rate"] == 0.0]
        if maze != "u_chain_1" and oneshot is not None:
            shots = {r["seed"]: r["success_rate"] for r in by["vlm-oneshot"]}
            pairs += [(maze, r["success_rate"], shots[r["seed"]]) for r in by[best] if r["seed"] in shots]
    ratio, ci = _ratio_with_ci(pairs)
    met = ratio >= RATIO and not zeros
    return {"claim": f"better of ours / ours-repair x {ERRING} >= {RATIO:g}x vlm-oneshot on multi-room mazes, no "
                     f"run at 0 where the one-shot is above {ONESHOT_HIGH}",
            "verdict": "not run" if not chosen else ("holds" if met else "not met") if complete else "partial",
            "complete": complete,
            "ratio": ratio, "ratio_ci": list(ci), "cells": len(pairs), "mazes": len({m for m, _, _ in pairs}),
            "zeros": zeros, "chosen": chosen, "ours_runs": ours_runs,
            "ours_at_zero": at_zero}


def _repaired_text(at_zero) -> str:
    ran = [z for z in at_zero if z["ours_repair"] is not None]
    lifted = [z for z in ran if z["ours_repair"] > 0]
    cells = ", ".join(f"{z['maze']} seed {z['seed']} {z['ours_repair']:.3f}" for z in ran)
    return f"above 0 on {len(lifted)} of {len(ran)}" + (f" ({cells})" if cells else "")


def _ratio_with_ci(pairs) -> tuple[float, tuple[float, float]]:
    """Mean success of the chosen method over the one-shot's on the paired (maze, seed) cells, with the
    comparison's 95 % percentile bootstrap interval (cells resampled; reported beside the rule, which the docs fixed
    on the point estimate)."""
    if not pairs:
        return float("nan"), (float("nan"), float("nan"))
    ratio, ci, _ = cmp.bootstrap_ratio(*np.array([(a, b) for _, a, b in pairs], dtype=float).T)
    return ratio, ci


def legs_table(rows) -> str:
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        policy = str(r.get("policy") or "shipped").rsplit("/", 1)[-1]
        groups.setdefault((r["maze"], r["method"], r["proposer"], policy), []).append(r)
    order = sorted(groups, key=lambda k: (k[2], k[1], rooms(k[0]) or 0, k))
    return "\n".join([LEGS_HEADER, *(legs_line(k, groups[k]) for k in order)])


PHASES = ("search_seconds", "measure_seconds", "calibrate_seconds")


def _rate(row) -> str:
    return "—" if row is None else f"{row['success_rate']:.3f}"


def seed_table(baseline_rows, rows, seed: int) -> str:
    """One seed of ``ours`` x ORACLE beside the same seed of the stage-4 comparison (``ours`` x ``geometric``)."""
    def run(table, proposer, maze):
        return next((r for r in table if (r["maze"], r["method"], r["proposer"], r["seed"]) ==
                     (maze, "ours", proposer, seed) and is_done(r)), None)

    lines = [f"| maze | stage 4, seed {seed} | stage 5, seed {seed} | legs (stage 5) | search / measure / calibrate s "
             "(stage 5) |", "|---|---|---|---|---|"]
    for maze in MAZES:
        old, new = run(baseline_rows, "geometric", maze), run(rows, ORACLE, maze)
        cells = [_rate(old), _rate(new), "—" if new is None else f"{new['path_edges']:.0f}",
                 "—" if new is None else " / ".join(f"{new[k]:.0f}" for k in PHASES)]
        lines.append(f"| {maze} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def erring_seed_table(rows, seed: int) -> str:
    """One seed of the erring proposer's three methods per maze: success (legs on the measured path)."""
    def cell(method, maze):
        run = next((r for r in _runs(rows, maze, method, ERRING) if r["seed"] == seed), None)
        return "—" if run is None else f"{run['success_rate']:.3f} ({run['path_edges']:.0f})"

    lines = [f"| maze | {' | '.join(f'{m}, seed {seed}' for m in METHODS)} |", "|---|---|---|---|"]
    lines += [f"| {maze} | " + " | ".join(cell(m, maze) for m in METHODS) + " |" for maze in MAZES]
    return "\n".join(lines)


def markdown(flat: dict, erring: dict, rule: str = "sampled") -> str:
    aim = ("each leg aims at its goal set's centre (--goal-points centre, beyond the paper)" if rule == "centre"
           else "each episode aims at a point sampled in the goal set (the paper's rule)")
    lines = [f"{cmp.OFFLINE_NOTE}. Ant, stage 5, {aim}, seeds {', '.join(map(str, SEEDS))}, 200 fresh episodes per "
             "run; "
             "Wilson 95 % intervals on pooled episodes; the change from 1 to 5 rooms as in the comparison "
             "(least-squares slope x 4, seeds resampled within each room).", "",
             f"**{flat['claim']}: {flat['verdict']}.** Change from 1 to 5 rooms {flat['change_1_to_5']:+.3f} "
             f"[{flat['change_ci'][0]:+.3f}, {flat['change_ci'][1]:+.3f}] ({flat['change_verdict']}); below "
             f"{LEVEL:.2f}: {', '.join(flat['below_level']) or 'none'}.", "",
             "| maze | seeds | success pooled [95 % CI] | runs |", "|---|---|---|---|"]
    for maze, m in flat["per_maze"].items():
        lines.append(f"| {maze} | {m['seeds']} | {m['success']:.3f} [{m['ci'][0]:.3f}, {m['ci'][1]:.3f}] | "
                     f"{', '.join(f'{x:.3f}' for x in m['runs'])} |")
    if not erring["chosen"]:
        return "\n".join(lines + ["", f"**{erring['claim']}: not run** (no ours or ours-repair x {ERRING} run in "
                                       "these tables)."]) + "\n"
    lo, hi = erring["ratio_ci"]
    lines += ["", f"**{erring['claim']}: {erring['verdict']}.** Ratio {erring['ratio']:.2f} [{lo:.2f}, {hi:.2f}] "
                  f"(95 % bootstrap, {erring['cells']} paired cells resampled) over {erring['mazes']} multi-room "
                  f"mazes; runs at 0 where the one-shot is above {ONESHOT_HIGH}: "
                  f"{', '.join(erring['zeros']) or 'none'}.", "",
              f"`ours` runs at 0: {len(erring['ours_at_zero'])} of {erring['ours_runs']}; `ours-repair` on the same "
              f"cells: {_repaired_text(erring['ours_at_zero'])}.", "",
              "| maze | chosen | its mean | one-shot mean |", "|---|---|---|---|"]
    for maze, c in erring["chosen"].items():
        shot = "—" if c["oneshot"] is None else f"{c['oneshot']:.3f}"
        lines.append(f"| {maze} | {c['method']} | {c['mean']:.3f} | {shot} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    p = OneLineParser(prog="python -m specrefine.experiments.scaling", description=__doc__.split("\n")[0])
    p.add_argument("tables", nargs="+", help="the grid's sweep tables (data/results/ant/scaling/*.csv)")
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--baseline", help="the stage-4 comparison's table (data/results/ant/comparison.csv): seeds.md sets "
                                      "each seed beside it")
    args = p.parse_args(argv)
    try:
        rows = read_rows(args.tables)
        baseline = read_rows([args.baseline]) if args.baseline else None
        out = ensure_dir(args.out)
    except SpecrefineError as exc:
        p.exit(2, f"{p.prog}: error: {exc}\n")
    if baseline is not None:
        write_atomic(out / "seeds.md", "\n\n".join(seed_table(baseline, rows, s) for s in SEEDS) + "\n")
    flat, erring = flat_claim(rows), erring_claim(rows)
    rule = goal_points_of(rows[0] if rows else {})
    write_atomic(out / "claims.md", markdown(flat, erring, rule))
    write_atomic(out / "claims.json", json.dumps({"flat": flat, "erring": erring}, indent=1, default=float) + "\n")
    write_atomic(out / "legs.md", legs_table(rows) + "\n")
    if erring["chosen"]:
        write_atomic(out / "erring_seeds.md", "\n\n".join(erring_seed_table(rows, s) for s in SEEDS) + "\n")
    save_figure(figure5(rows, methods=list(METHODS), proposers=[ORACLE, ERRING]), out / "figure5.png", dpi=110)
    seeds = ", erring_seeds.md" if erring["chosen"] else ""
    print(f"{len(rows)} rows -> {out}: claims.md ({flat['verdict']}; {erring['verdict']}), legs.md{seeds}, figure5.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
