"""A lever's check against its baseline on the same cells (docs/ant_experiments.md sections 4-5): success pooled over
the lever's runs and over the baseline's runs of the same (maze, seed) cells, and the difference with Newcombe's 95 %
interval; the lever helps when that interval lies above 0.

    python -m specrefine.experiments.levers data/results/ant/polish.csv --method ours-polish \\
        --baseline data/results/ant/scaling/ours_geometric.csv --baseline-method ours \\
        --mazes u_chain_3 u_chain_5 --seeds 0 1 2 --out data/results/ant/polish_check.md

A cell missing from either table makes the check partial (its verdict so far is still printed). Every proposer here
is offline, NOT a VLM.
"""

from __future__ import annotations

from pathlib import Path

from ..core.argtypes import OneLineParser, exit_code_quiet_on_broken_pipe
from ..core.errors import SpecrefineError
from ..core.paper import PAPER
from ..core.results import newcombe_ci, rate_text
from ..core.runfolder import output_file, write_atomic
from ..core.tables import goal_points_of
from ..runs.sweep import is_done, read_checked_table
from .legs import pooled


def _by_cell(table, method: str, proposer: str | None) -> dict[tuple[str, int], dict]:
    return {(r["maze"], int(r["seed"])): r for r in read_checked_table(table)
            if is_done(r) and r["method"] == method and proposer in (None, r["proposer"])}


def label(method: str, rows: dict, policy: bool = False) -> str:
    """The method's name, with its goal-point rule when its runs aimed at the sets' centres, its switching rule
    when not the paper's (the table has no column for it: a cell id ends in ``__switching-RULE``) and, with
    ``policy``, its policy file's name."""
    rules = sorted({goal_points_of(r) for r in rows.values()})
    switching = sorted({r["cell"].split("__switching-")[1] for r in rows.values() if "__switching-" in r["cell"]})
    notes = ([] if rules in ([], [PAPER.goal_points]) else [f"{', '.join(rules)} goal points"]) + \
        [f"{', '.join(switching)} switching"] * bool(switching) + \
        [f"policy {', '.join(policies(rows))}"] * (policy and bool(policies(rows)))
    return f"{method} ({'; '.join(notes)})" if notes else method


def policies(rows: dict) -> list[str]:
    """The stems of the policy files the rows ran (a table from before the column: none)."""
    return sorted({Path(r["policy"]).stem for r in rows.values() if r.get("policy")})


def lever_check(lever: dict, baseline: dict, cells: list[tuple[str, int]]) -> dict:
    """Pooled success of both sides on the cells both have; ``complete`` when both have every cell."""
    both = [c for c in cells if c in lever and c in baseline]
    if not both:
        return {"cells": 0, "expected": len(cells), "complete": False, "verdict": "no cell yet"}
    (k1, n1), (k2, n2) = pooled([lever[c] for c in both]), pooled([baseline[c] for c in both])
    lo, hi = newcombe_ci(k1, n1, k2, n2)
    verdict = "helps" if lo > 0 else "hurts" if hi < 0 else "no difference shown"
    return {"cells": len(both), "expected": len(cells), "complete": len(both) == len(cells),
            "lever": (k1, n1), "baseline": (k2, n2), "difference": k1 / n1 - k2 / n2, "ci": (lo, hi),
            "verdict": verdict if len(both) == len(cells) else f"partial ({verdict} so far)",
            "rows": [(c, lever[c]["success_rate"], baseline[c]["success_rate"]) for c in both]}


def shown(maze: str) -> str:
    """A maze as a table shows it: a file outside data/mazes/ (recorded by its full path) by its file name."""
    return Path(maze).stem if maze.endswith(".maze") else maze


def markdown(check: dict, lever_name: str, baseline_name: str) -> str:
    if not check["cells"]:
        return f"**{lever_name} against {baseline_name}: no cell yet** (0 of {check['expected']}).\n"
    lo, hi = check["ci"]
    lines = [f"**{lever_name} against {baseline_name}, {check['cells']} of {check['expected']} cells: "
             f"{check['verdict']}.** Pooled {rate_text(*check['lever'])} against {rate_text(*check['baseline'])}: "
             f"difference "
             f"{check['difference']:+.3f} [{lo:+.3f}, {hi:+.3f}] (Newcombe 95 %).", "",
             f"| maze | seed | {lever_name} | {baseline_name} |", "|---|---|---|---|"]
    lines += [f"| {shown(maze)} | {seed} | {a:.3f} | {b:.3f} |" for (maze, seed), a, b in check["rows"]]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    p = OneLineParser(prog="python -m specrefine.experiments.levers", description=__doc__.split("\n")[0])
    p.add_argument("table", help="the lever's sweep table")
    p.add_argument("--method", required=True, help="the lever's method in it")
    p.add_argument("--baseline", required=True, help="the baseline's sweep table")
    p.add_argument("--baseline-method", required=True)
    p.add_argument("--proposer", default=None, help="both sides' proposer (default: any)")
    p.add_argument("--mazes", nargs="+", required=True)
    p.add_argument("--baseline-mazes", nargs="+", default=None, metavar="MAZE",
                   help="the baseline's maze paired with each of --mazes, in order (default: the same mazes), e.g. "
                        "a layout turned round against the shipped one")
    p.add_argument("--seeds", nargs="+", type=int, required=True)
    p.add_argument("--out", type=Path, default=None, help="write the markdown here (default: print it only)")
    args = p.parse_args(argv)
    baseline_mazes = args.baseline_mazes or args.mazes
    if len(baseline_mazes) != len(args.mazes):
        p.error(f"--baseline-mazes names {len(baseline_mazes)} mazes for the {len(args.mazes)} of --mazes")
    pairs = dict(zip(args.mazes, baseline_mazes, strict=True))
    try:
        if args.out is not None:
            output_file(args.out)
        lever = _by_cell(args.table, args.method, args.proposer)
        by_maze = _by_cell(args.baseline, args.baseline_method, args.proposer)
    except SpecrefineError as exc:
        p.exit(2, f"{p.prog}: error: {exc}\n")
    baseline = {(m, s): by_maze[(b, s)] for m, b in pairs.items() for s in args.seeds if (b, s) in by_maze}
    cells = [(m, s) for m in args.mazes for s in args.seeds]
    other = sorted({shown(b) for m, b in pairs.items() if b != m})
    named = policies(lever) != policies(baseline)  # a policy lever: name each side's
    text = markdown(lever_check(lever, baseline, cells), label(args.method, lever, named),
                    label(args.baseline_method, baseline, named) + (f" on {', '.join(other)}" if other else ""))
    if args.out is not None:
        write_atomic(args.out, text)
    print(text, end="")
    return 0


if __name__ == "__main__":
    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
