"""The Ant's corrector on layouts and an error mix no run had used (grid ``ant-corrector-fresh``; issue 39).

Described, no rule (docs/corrector.md, "Fresh layouts for the Ant"): success per layout and proposer of
``ours-corrector-redraw``, its control ``ours-corrector-confirm`` and the oracle; redraw - confirm pooled over the
cells both ran (Newcombe 95 %); the runs below 0.85 and at 0; proposer calls and evaluations over confirm's. Read by
``specrefine corrector-claims``, which appends :func:`markdown` to claims.md.
"""

from __future__ import annotations

import math

from .comparison import is_done, mean_ratio
from .grids import GEOMETRIC_48, GRIDS
from .levers import lever_check

GRID = "ant-corrector-fresh"
REDRAW, CONFIRM = "ours-corrector-redraw", "ours-corrector-confirm"
FLOOR = 0.85


def mix_name(proposer: str) -> str:
    """A proposer as the tables name it: the preset, or AI for the new mix."""
    return proposer if "=" not in proposer else "AI"


def study(rows: list[dict]) -> dict | None:
    """The grid's cells in ``rows`` (its tables), or None while it has none."""
    grid = GRIDS[GRID]
    done = [r for r in rows if is_done(r) and r["maze"] in grid.mazes and int(r["seed"]) in grid.seeds]
    if not done:
        return None
    mixes = grid.parts[0].proposers
    by = {(r["method"], r["proposer"], r["maze"]): r for r in done}
    cells = [(maze, mix) for mix in mixes for maze in grid.mazes]

    def rate(method, proposer, maze):
        row = by.get((method, proposer, maze))
        return float(row["success_rate"]) if row else math.nan

    per_cell = [{"mix": mix_name(mix), "maze": maze, REDRAW: rate(REDRAW, mix, maze),
                 CONFIRM: rate(CONFIRM, mix, maze), "oracle": rate("ours", GEOMETRIC_48, maze)}
                for maze, mix in cells]
    sides = {m: {(maze, mix): by[(m, mix, maze)] for maze, mix in cells if (m, mix, maze) in by}
             for m in (REDRAW, CONFIRM)}
    pairs = [(sides[REDRAW][c], sides[CONFIRM][c]) for c in cells if c in sides[REDRAW] and c in sides[CONFIRM]]
    return {"cells": per_cell, "expected": len(cells), "paired": lever_check(sides[REDRAW], sides[CONFIRM], cells),
            "below": {m: _count(sides[m], lambda r: r < FLOOR) for m in (REDRAW, CONFIRM)},
            "zero": {m: _count(sides[m], lambda r: r == 0.0) for m in (REDRAW, CONFIRM)},
            "cost": {key: mean_ratio(pairs, key) for key in ("proposer_calls", "evaluations")}, "pairs": len(pairs)}


def _count(side: dict, test) -> tuple[int, int]:
    return sum(1 for r in side.values() if test(float(r["success_rate"]))), len(side)


def _num(x: float, fmt: str = "{:.3f}") -> str:
    return "—" if math.isnan(x) else fmt.format(x)


def markdown(fresh: dict) -> list[str]:
    """claims.md's section: every cell, the paired difference, the counts and the cost."""
    p = fresh["paired"]
    paired = ("no cell in both yet" if not p["cells"] else
              f"{p['difference']:+.3f} [{p['ci'][0]:+.3f}, {p['ci'][1]:+.3f}] over {p['cells']} of "
              f"{p['expected']} paired cells (Newcombe 95 %, pooled; {p['verdict']})")
    lines = ["", f"The Ant on layouts and a mix no run had used (`{GRID}`, docs/corrector.md 'Fresh layouts for the "
             f"Ant'; described, no rule; seed 0, 200 episodes per run; AI is the new mix in "
             "specrefine/experiments/grids.py, `ANT_FRESH_MIXES`).", "",
             f"| mix | maze | {REDRAW} | {CONFIRM} | oracle |", "|---|---|---|---|---|"]
    lines += [f"| {c['mix']} | {c['maze']} | {_num(c[REDRAW])} | {_num(c[CONFIRM])} | {_num(c['oracle'])} |"
              for c in fresh["cells"]]
    counts = "; ".join(f"{m}: below {FLOOR} {fresh['below'][m][0]} of {fresh['below'][m][1]}, at 0 "
                       f"{fresh['zero'][m][0]}" for m in (REDRAW, CONFIRM))
    cost = fresh["cost"]
    return lines + ["", f"{REDRAW} - {CONFIRM}: {paired}. Runs {counts}. Cost over {CONFIRM} on the "
                        f"{fresh['pairs']} paired cells: proposer calls {_num(cost['proposer_calls'], '{:.2f}x')}, "
                        f"evaluations {_num(cost['evaluations'], '{:.2f}x')}."]


def front_text(fresh: dict | None) -> str:
    """README's one line: how much has run, redraw's range per cell, its difference from confirm, the runs at 0 and,
    once it has run, the oracle's range over the layouts."""
    if fresh is None:
        return "no cell yet"
    redraw = [c[REDRAW] for c in fresh["cells"] if not math.isnan(c[REDRAW])]
    p = fresh["paired"]
    runs = sum(not math.isnan(c[m]) for c in fresh["cells"] for m in (REDRAW, CONFIRM))
    span = f"redraw {min(redraw):.3f}-{max(redraw):.3f} per cell" if redraw else "redraw: no cell yet"
    paired = (f"redraw - confirm {p['difference']:+.3f} [{p['ci'][0]:+.3f}, {p['ci'][1]:+.3f}] over {p['cells']} "
              f"cell{'' if p['cells'] == 1 else 's'}" if p["cells"] else "no paired cell yet")
    oracle = {c["maze"]: c["oracle"] for c in fresh["cells"] if not math.isnan(c["oracle"])}
    beside = (f"; the oracle (`ours`, geometric) {min(oracle.values()):.3f}-{max(oracle.values()):.3f} on "
              f"{len(oracle)} layout{'' if len(oracle) == 1 else 's'}" if oracle else "")
    return (f"{runs} of {2 * fresh['expected']} runs; {span}; {paired}; runs at 0: redraw {fresh['zero'][REDRAW][0]}, "
            f"confirm {fresh['zero'][CONFIRM][0]}{beside}")

