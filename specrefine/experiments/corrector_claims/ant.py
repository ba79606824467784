"""The Ant's studies: its rules on the grid they read (``ANT_GRID``, an adopted candidate of ``ANT_CANDIDATES`` or a
``Successor``), the cells beside it, and the fresh layouts."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ...core.results import wilson_ci
from .. import ant_fresh
from .. import comparison as cmp
from ..grids import GRIDS, ROOT, SCALING_MAZES
from .common import (
    COST_CAP,
    METHOD,
    NON_INFERIORITY,
    SPAN,
    as_ours,
    costs,
    done_cells,
    episodes_of,
    load,
    paired_rows,
    zero_runs,
)

ANT_FLOOR = 0.85
#: the Ant's rules read this grid and its method (docs/corrector.md, "The Ant with a confirmed pick")
ANT_GRID, ANT_METHOD = "ant-corrector-confirm", "ours-corrector-confirm"
#: the same cells with ours-corrector at the fixed code (stopped at 10 of 27): shown beside, cell for cell
ANT_BEFORE = "ant-corrector-spread"
ANT_FIRST = "ant-corrector"  # ours-corrector before spread start states (stopped at 10 of 27; ant.csv)
#: the same cells with the re-aiming corrector (docs/corrector.md, "Aimed clear of the walls: the Ant") and with a
#: second correction pass ("A second draw for the Ant"): the Ant's rules read one of them instead of ANT_GRID once it
#: - ANT_METHOD over every paired cell has a 95 % interval above 0; where both do, the one with the higher pooled
#: success
ANT_REAIM, REAIM = "ant-corrector-reaim", "ours-corrector-reaim"
ANT_REDRAW, REDRAW = "ant-corrector-redraw", "ours-corrector-redraw"
ANT_CANDIDATES = {ANT_REAIM: REAIM, ANT_REDRAW: REDRAW}


@dataclass(frozen=True)
class Successor:
    """A corrector run on the cells of the one the Ant's rules read (``follows``, a grid of ANT_CANDIDATES), read in
    its place (while that one is read) once every paired cell ran and its rule holds: at least ANT_FLOOR on every maze;
    its difference from that corrector with a 95 % interval whose lower end is at least -``margin`` (None: whose upper
    end is at least 0, not wholly below); at most ``calls`` times that corrector's mean proposer calls (None: any).
    ``control``: another successor's grid that differs from it by one change; their paired difference is described."""

    method: str
    follows: str
    section: str
    margin: float | None = NON_INFERIORITY
    calls: float | None = None
    control: str | None = None

    def rule(self) -> str:
        bound = (f"above -{self.margin}" if self.margin is not None else "not wholly below 0")
        return (f"at least {ANT_FLOOR} on every maze, the difference's 95 % interval {bound} (every paired cell)"
                + (f", at most {self.calls}x its proposer calls" if self.calls is not None else ""))


ANT_SPARING, SPARING = "ant-corrector-sparing", "ours-corrector-sparing"
ANT_SPARING_FRUGAL, SPARING_FRUGAL = "ant-corrector-sparing-frugal", "ours-corrector-sparing-frugal"
ANT_WIDE, WIDE = "ant-corrector-wide", "ours-corrector-wide"
ANT_SPAN = "ant-corrector-span"  # ours-corrector-span, the point mass's default (common.SPAN)
#: each successor by its grid (docs/corrector.md, "A gate for the Ant's corrector", "Sparing and frugal: the Ant",
#: "The wide pass with an erring proposer", "The point mass's corrector on the Ant")
ANT_SUCCESSORS = {
    ANT_SPARING: Successor(SPARING, ANT_REDRAW, "A gate for the Ant's corrector", calls=0.75),
    ANT_SPARING_FRUGAL: Successor(SPARING_FRUGAL, ANT_REDRAW, "Sparing and frugal: the Ant", calls=0.5,
                                  control=ANT_SPARING),
    ANT_WIDE: Successor(WIDE, ANT_REDRAW, "The wide pass with an erring proposer", margin=None),
    ANT_SPAN: Successor(SPAN, ANT_REDRAW, "The point mass's corrector on the Ant", calls=0.5)}
ANT_SEEDS = GRIDS[ANT_GRID].seeds
ANT_ONESHOT = "data/results/ant/scaling/oneshot_centre.csv"
ANT_ORACLE = "data/results/ant/scaling/ours_centre.csv"
ANT_ERRING = "data/results/ant/scaling/imperfect_centre.csv"


def ant_study(root: Path = ROOT) -> dict | None:
    """The Ant's rules on ``ANT_GRID`` (``ANT_METHOD``), or on the ``ANT_CANDIDATES`` grid adopted, with
    ``ANT_BEFORE``'s cells (ours-corrector) and each candidate's beside and their pooled differences from ANT_METHOD
    on the cells both ran; None while no grid has a cell."""
    confirm, before = _ant_grid_study(ANT_GRID, ANT_METHOD, root), _ant_grid_study(ANT_BEFORE, METHOD, root)
    studies = {grid: _ant_grid_study(grid, method, root) for grid, method in ANT_CANDIDATES.items()}
    if not any(e["runs"] for study in (confirm, before, *studies.values()) for e in study["per_maze"]):
        return None
    candidates = [_ant_candidate(grid, method, studies[grid], root) for grid, method in ANT_CANDIDATES.items()]
    adopted = max((c for c in candidates if c["adopted"]), key=lambda c: c["pooled"], default=None)
    now, grid, method = (studies[adopted["grid"]], adopted["grid"], adopted["method"]) if adopted else \
        (confirm, ANT_GRID, ANT_METHOD)
    successors = [_ant_successor(name, root) for name in ANT_SUCCESSORS]
    following = [s for s in successors if s["adopted"] and s["follows"] == grid]
    if following:  # where several hold, the one with the higher pooled success
        best = max(following, key=lambda s: s["pooled"])
        now, grid, method = best["study"], best["grid"], best["method"]
    return now | {"grid": grid, "method": method, "confirm": confirm["per_maze"], "before": before["per_maze"],
                  "paired": _ant_paired((ANT_GRID, ANT_METHOD), (ANT_BEFORE, METHOD), root), "candidates": candidates,
                  "successors": successors, "confirm_costs": confirm["costs"], "before_costs": before["costs"]}


def ant_fresh_study(root: Path = ROOT) -> dict | None:
    """The Ant's corrector on the fresh layouts (``ant_fresh``), from its grid's tables under ``root``."""
    return ant_fresh.study(load(GRIDS[ant_fresh.GRID].tables, root))


def _ant_candidate(grid: str, method: str, study: dict, root: Path) -> dict:
    """A candidate for the Ant's corrector: its cells per maze, its paired difference from ANT_METHOD, whether its
    rule holds (every paired cell ran, the 95 % interval above 0) and its pooled success."""
    rows = load(GRIDS[grid].tables + GRIDS[ANT_GRID].tables, root)
    paired = _ant_paired_rows(rows, method, ANT_METHOD)
    return {"grid": grid, "method": method, "per_maze": study["per_maze"], "paired": paired,
            "adopted": paired["complete"] and paired["ci"][0] > 0, "pooled": _pooled_success(study["per_maze"]),
            "cost_vs_confirm": costs(rows, "imperfect:moderate", SCALING_MAZES, ANT_SEEDS, method, ANT_METHOD),
            "cost_vs_ours": study["costs"]}


def _ant_successor(grid: str, root: Path) -> dict:
    """A successor (ANT_SUCCESSORS) on the cells of the grid it follows: its cells per maze, its paired difference from
    that corrector, its cost over that corrector's, each part of its rule and whether all hold over every cell."""
    s = ANT_SUCCESSORS[grid]
    base = ANT_CANDIDATES[s.follows]
    study = _ant_grid_study(grid, s.method, root)
    rows = load(GRIDS[grid].tables + GRIDS[s.follows].tables + (ANT_ERRING,), root)  # ours's rows: the forecast's
    paired = _ant_paired_rows(rows, s.method, base)
    cost = costs(rows, "imperfect:moderate", SCALING_MAZES, ANT_SEEDS, s.method, base)
    bounded = bool(paired["cells"]) and (paired["ci"][0] >= -s.margin if s.margin is not None else paired["ci"][1] >= 0)
    parts = {"floor": all(e["episodes"] and e["success"] >= ANT_FLOOR for e in study["per_maze"]),
             "no worse" if s.margin is not None else "not below": bounded}
    if s.calls is not None:
        parts["cheaper"] = cost["proposer_calls_ratio"] <= s.calls
    control = (ANT_SUCCESSORS[s.control].method, _ant_paired((grid, s.method), (s.control,
                                                                             ANT_SUCCESSORS[s.control].method), root)
               ) if s.control else None
    return {"grid": grid, "method": s.method, "follows": s.follows, "followed_method": base, "rule": s.rule(),
            "control": control, "calls_forecast": cost_forecast(rows, s.method, base),
            "evaluations_forecast": cost_forecast(rows, s.method, base, "evaluations"),
            "section": s.section, "study": study, "per_maze": study["per_maze"], "paired": paired, "parts": parts,
            "cost_vs_followed": cost, "cost_vs_ours": study["costs"], "pooled": _pooled_success(study["per_maze"]),
            "adopted": paired["complete"] and all(parts.values())}


def cost_forecast(rows: list[dict], method: str, followed: str, key: str = "proposer_calls",
                  proposer: str = "imperfect:moderate") -> dict:
    """``method``'s spending (``key``: proposer calls or evaluations) over ours's on the cells ``followed`` and ours
    ran (the cost cap's ratio), were the cells ``method`` ran to keep their ratio to ``followed``'s spending on the
    cells it has not: a forecast while its grid runs, not a result. ``forecast`` NaN before its first such cell."""
    by = {cell: float(r[key]) for cell, r in done_cells(rows, proposer).items()}
    cells = [(m, s) for m in SCALING_MAZES for s in ANT_SEEDS if (m, followed, s) in by and (m, "ours", s) in by]
    run = [(m, s) for m, s in cells if (m, method, s) in by]
    spent, theirs = (sum(by[(m, who, s)] for m, s in run) for who in (method, followed))
    rest = sum(by[(m, followed, s)] for m, s in cells if (m, s) not in run)
    ours = sum(by[(m, "ours", s)] for m, s in cells)
    ratio = spent / theirs if theirs else math.nan
    left = len(cells) - len(run)
    return {"cells": len(cells), "run": len(run), "ratio_to_followed": ratio,
            "forecast": (spent + ratio * rest) / ours if run and ours else math.nan,
            # what each cell not run may spend on average for the whole grid to stay within the cap, beside what
            # ``followed`` spent on those cells
            "left_per_cell": (COST_CAP * ours - spent) / left if left else math.nan,
            "followed_left_per_cell": rest / left if left else math.nan}


def _pooled_success(per_maze: list[dict]) -> float:
    """Success pooled over a grid's mazes (their episodes together); NaN before any cell."""
    k, n = (sum(e[key] for e in per_maze) for key in ("successes", "episodes"))
    return k / n if n else math.nan


def _ant_grid_study(grid: str, method: str, root: Path) -> dict:
    rows = load(GRIDS[grid].tables + (ANT_ONESHOT, ANT_ORACLE, ANT_ERRING), root)
    proposer = "imperfect:moderate"
    maze_rows = []
    for maze in SCALING_MAZES:
        k, n, runs = episodes_of(rows, maze, method, proposer, ANT_SEEDS)
        entry = {"maze": maze, "runs": runs, "successes": k, "episodes": n, "success": k / n if n else math.nan}
        if n:
            entry["ci_low"], entry["ci_high"] = wilson_ci(k, n)
        maze_rows.append(entry)
    cells, failed = cmp.table_cells(rows, "ant")
    ratios = [cmp.ratio_claim(as_ours(cells, method), set(as_ours(dict.fromkeys(failed), method)), proposer,
                              ANT_SEEDS) | {"method": f"{method} / vlm-oneshot"},
              cmp.ratio_claim(cells, failed, proposer, ANT_SEEDS) | {"method": "ours / vlm-oneshot"}]
    return {"per_maze": maze_rows, "ratio": ratios,
            "costs": costs(rows, proposer, SCALING_MAZES, ANT_SEEDS, first=method),
            "zero": zero_runs(rows, method, proposer, SCALING_MAZES)}


def _ant_paired(first: tuple[str, str], second: tuple[str, str], root: Path) -> dict:
    """``first`` - ``second`` (each a grid and its method) pooled over the cells both ran (``levers.lever_check``)."""
    return _ant_paired_rows(load(GRIDS[first[0]].tables + GRIDS[second[0]].tables, root), first[1], second[1])


def _ant_paired_rows(rows: list[dict], first: str, second: str) -> dict:
    """``first`` - ``second`` (methods) pooled over the Ant's cells both finished in ``rows``."""
    return paired_rows(rows, first, second, [(m, s) for m in SCALING_MAZES for s in ANT_SEEDS])
