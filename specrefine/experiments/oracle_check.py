"""Issue 42's oracle rules on one Ant grid, and a lever's grid against its baseline, cell for cell
(docs/ant_experiments.md, 'The oracle at the fixed code' and 'lever 4').

    python -m specrefine.experiments.oracle_check data/results/ant/oracle_tunecheck.csv --method ours-tunecheck \\
        --baseline data/results/ant/oracle_spread.csv --out data/results/ant/oracle_tunecheck_check.md

The rule: at least ``--level`` (0.97) on every maze pooled over seeds 0-2 and the change from 1 to 5 rooms within
+-``--tolerance`` (0.03). Against a baseline (``ours`` on the same cells): the pooled difference over the cells both
ran with Newcombe's 95 % interval, per maze too; the lever is adopted if, complete, the pooled difference is above 0
and no maze is more than ``--margin`` (0.03) below. ``--costs`` adds, per maze and pooled, the grid's proposer calls,
subtask evaluations and simulator steps as multiples of the baseline's on the same cells (described, no rule). Every
proposer here is offline, NOT a VLM.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..core.argtypes import OneLineParser, exit_code_quiet_on_broken_pipe
from ..core.errors import SpecrefineError
from ..core.results import newcombe_ci, rate_text
from ..core.runfolder import write_atomic, writing_into
from .comparison import U_CHAIN_ROOMS, mean_ratio
from .legs import pooled
from .scaling import MAZES, ORACLE, SEEDS, _runs, flat_claim, read_rows

#: what a run spends, as result.json and the sweep's table name it, and as the check's column names it
COSTS = {"proposer_calls": "calls", "evaluations": "evaluations", "sim_steps": "simulator steps"}


def _cells(rows, method: str) -> dict[tuple[str, int], dict]:
    return {(maze, int(r["seed"])): r for maze in MAZES for r in _runs(rows, maze, method, ORACLE)}


def against(rows, base_rows, method: str, base_method: str, margin: float | None, costs: bool = False) -> dict:
    """``method`` - ``base_method`` on the cells both ran: pooled and per maze (Newcombe 95 %), with ``costs`` each
    side's spending as a multiple of the baseline's, and the verdict (None with ``margin`` None: described, no
    rule)."""
    mine, base = _cells(rows, method), _cells(base_rows, base_method)
    common = sorted(set(mine) & set(base))

    def diff(keys):
        (k1, n1), (k2, n2) = pooled([mine[c] for c in keys]), pooled([base[c] for c in keys])
        d = {"cells": len(keys), "lever": (k1, n1), "base": (k2, n2), "difference": k1 / n1 - k2 / n2,
             "ci": newcombe_ci(k1, n1, k2, n2)}
        if costs:
            d["costs"] = {k: _ratio([(mine[c], base[c]) for c in keys], k) for k in COSTS}
        return d

    per_maze = {m: diff([c for c in common if c[0] == m]) for m in MAZES if any(c[0] == m for c in common)}
    total = diff(common) if common else None
    if margin is None:
        return {"total": total, "per_maze": per_maze, "verdict": None, "margin": None}
    complete = len(common) == len(MAZES) * len(SEEDS)
    worst = min((v["difference"] for v in per_maze.values()), default=0.0)
    adopted = total is not None and total["difference"] > 0 and worst >= -margin
    verdict = ("adopted" if adopted else "not adopted") if complete else \
        f"partial ({'adopted' if adopted else 'not adopted'} so far, {len(common)} of {len(MAZES) * len(SEEDS)} cells)"
    return {"total": total, "per_maze": per_maze, "verdict": verdict, "margin": margin}


def _ratio(pairs, field: str) -> float | None:
    """``comparison.mean_ratio`` of ``field`` over the paired cells (None where the baseline spent none)."""
    try:
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = mean_ratio(pairs, field)
    except (KeyError, TypeError, ValueError):
        raise SpecrefineError(f"--costs: a cell has no {field} (a table from before it was recorded?)") from None
    return ratio if math.isfinite(ratio) else None


def _costs_text(d) -> str:
    return " / ".join("—" if r is None else f"{r:.2f}x" for r in d["costs"].values())


def _diff_text(d) -> str:
    lo, hi = d["ci"]
    return f"{d['difference']:+.3f} [{lo:+.3f}, {hi:+.3f}]"


def summary(flat: dict, vs: dict | None, base_method: str) -> str:
    """One line: the cells run, the mazes below the level, the change; against the baseline, the pooled difference
    (README quotes it)."""
    cells = sum(m["seeds"] for m in flat["per_maze"].values())
    below = flat["below_level"]
    text = (f"{cells} of {len(MAZES) * len(SEEDS)} cells; below the level on {len(below)} of "
            f"{len(flat['per_maze'])} mazes run{': ' + ', '.join(below) if below else ''}; change from 1 to 5 rooms "
            f"{change_text(flat)}")
    if vs and vs["total"]:
        text += f"; against {base_method} on the same {vs['total']['cells']} cells {_diff_text(vs['total'])}"
    return text


def change_text(flat: dict, verdict: bool = False) -> str:
    """The 1-5 room change with its interval (and ``verdict``); a partial grid's says which U-chains it has no run of
    yet (its slope is then fitted to the others and extrapolated)."""
    lo, hi = flat["change_ci"]
    notes = [flat["change_verdict"]] if verdict else []
    if missing := [rooms for rooms, maze in U_CHAIN_ROOMS.items() if maze not in flat["per_maze"]]:
        notes.append(f"extrapolated: no run yet of {', '.join(f'U-chain {r}' for r in missing)}")
    return f"{flat['change_1_to_5']:+.3f} [{lo:+.3f}, {hi:+.3f}]" + (f" ({'; '.join(notes)})" if notes else "")


def markdown(flat: dict, vs: dict | None, method: str, base_method: str) -> str:
    lines = ["Every proposer here is offline, NOT a VLM (geometric: a planner on the map). Ant, pooled over seeds "
             f"{', '.join(map(str, SEEDS))}, 200 fresh episodes per run; Wilson 95 % intervals.", "",
             f"**{flat['claim']}: {flat['verdict']}.** Change from 1 to 5 rooms {change_text(flat, verdict=True)}"
             "; below the level: "
             f"{', '.join(flat['below_level']) or 'none'}.", "", f"Summary: {summary(flat, vs, base_method)}.", ""]
    header = "| maze | seeds | " + method + " |" + (f" {base_method} (baseline) | difference |" if vs else "")
    costs = bool(vs and vs["total"] and "costs" in vs["total"])
    header += f" {' / '.join(COSTS.values())} (x baseline) |" if costs else ""
    lines += [header, "|---" * (header.count("|") - 1) + "|"]
    for maze, m in flat["per_maze"].items():
        k, n = round(m["success"] * m["episodes"]), m["episodes"]
        row = f"| {maze} | {m['seeds']} | {rate_text(k, n)} |"
        if vs:
            d = vs["per_maze"].get(maze)
            row += (f" {rate_text(*d['base'])} | {_diff_text(d)} |" if d else " — | — |")
            row += (f" {_costs_text(d)} |" if d else " — |") if costs else ""
        lines.append(row)
    if vs and vs["total"]:
        t = vs["total"]
        rule = (f": {vs['verdict']}** (adopted if, complete, the pooled difference is above 0 and no maze is more than "
                f"{vs['margin']:.2f} below)." if vs["verdict"] else " (described, no rule).**")
        lines += ["", f"**Against {base_method} on the same {t['cells']} cells{rule} "
                  f"Pooled {rate_text(*t['lever'])} against {rate_text(*t['base'])}: difference {_diff_text(t)} "
                  "(Newcombe 95 %)." + (f" It spent {_costs_text(t)} the baseline's {' / '.join(COSTS.values())}."
                                         if costs else "")]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    p = OneLineParser(prog="python -m specrefine.experiments.oracle_check", description=__doc__.split("\n")[0])
    p.add_argument("table", help="the grid's table")
    p.add_argument("--method", default="ours")
    p.add_argument("--baseline", help="the baseline grid's table (cells matched by maze and seed)")
    p.add_argument("--baseline-method", default="ours")
    p.add_argument("--baseline-label", help="how the tables name the baseline (default: its method)")
    p.add_argument("--level", type=float, default=0.97)
    p.add_argument("--tolerance", type=float, default=0.03)
    p.add_argument("--margin", type=float, default=0.03)
    p.add_argument("--describe", action="store_true", help="the comparison with the baseline only, no adoption rule "
                                                           "(e.g. the same cells before a fix)")
    p.add_argument("--costs", action="store_true", help="with --baseline: proposer calls, evaluations and simulator "
                                                        "steps as multiples of the baseline's (described, no rule)")
    p.add_argument("--out", type=Path, required=True)
    args = p.parse_args(argv)
    if args.costs and not args.baseline:
        p.error("--costs compares with a baseline: give --baseline TABLE")
    try:
        with writing_into(args.out) as out:  # checked before any work; a run folder's lock held while writing there
            rows = read_rows([args.table])
            base = read_rows([args.baseline]) if args.baseline else None
            flat = flat_claim(rows, args.method, args.level, args.tolerance)
            margin = None if args.describe else args.margin
            vs = against(rows, base, args.method, args.baseline_method, margin, args.costs) if base is not None \
                else None
            write_atomic(out, markdown(flat, vs, args.method, args.baseline_label or args.baseline_method))
    except SpecrefineError as exc:
        p.exit(2, f"{p.prog}: error: {exc}\n")
    print(f"{args.out}: {flat['verdict']}" + (f"; against {args.baseline_method}: {vs['verdict'] or 'described'}"
                                               if vs else ""))
    return 0


if __name__ == "__main__":
    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
