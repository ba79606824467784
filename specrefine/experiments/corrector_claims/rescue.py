"""The Ant's default with deaf proposers (docs/corrector.md, "A rescue for the Ant's default"): grid
ant-corrector-rescue runs ``ours-corrector-redraw-rescue`` and ``ours-corrector-redraw`` with the error model's deaf
extreme and the ``random`` proposer on the Ant's U-chain 1-3 (seed 0; the rule's cells), then on the longer U-chains
(described). The rule, fixed before the grid ran: the rescue takes redraw's place as the Ant's default only if, over
the first part's paired cells, the pooled difference rescue - redraw (Newcombe 95 %) lies wholly above 0 and no
cell's interval lies wholly below 0."""

from __future__ import annotations

from pathlib import Path

from ...core.results import newcombe_ci, rate_text
from .. import comparison as cmp
from ..grids import DEAF, GRIDS, ROOT
from .ant import ANT_FLOOR, REDRAW
from .common import load, paired_rows
from .formats import _ant_paired_text

GRID = "ant-corrector-rescue"
RESCUE = "ours-corrector-redraw-rescue"
NAMES = {DEAF: "deaf", "random": "random"}  # each proposer's short name in the tables


def rescue_study(root: Path = ROOT) -> dict | None:
    """Per cell (maze, proposer, seed; the rule's part first): both methods' success, runs at 0, proposer calls and
    evaluations, the rescue's Newcombe difference; the pooled difference over the rule's cells and the verdict. None
    before the grid's first finished row."""
    g = GRIDS[GRID]
    rows = [r for r in load(g.tables, root) if cmp.is_done(r)]
    if not rows:
        return None
    by = {(r["maze"], r["method"], r["proposer"], int(r["seed"])): r for r in rows}
    judged = _judged()
    described = [(m, p, s) for m in g.parts[1].mazes for p in g.parts[1].proposers for s in g.seeds]
    cells = [_cell(by, key, key in judged) for key in judged + described]
    pooled = paired_rows(rows, RESCUE, REDRAW, judged)
    below = [c for c in cells if c["judged"] and c.get("ci_high", 0.0) < 0]
    verdict = ("undecided" if not pooled["complete"] else
               "adopted" if pooled["ci"][0] > 0 and not below else "not adopted")
    return {"grid": GRID, "cells": cells, "pooled": pooled, "below": len(below), "verdict": verdict,
            "judged": len(judged), "described": len(described)}


def _judged() -> list[tuple]:
    """The rule's cells (maze, proposer, seed): the grid's first part."""
    g = GRIDS[GRID]
    return [(m, p, s) for m in g.mazes for p in g.parts[0].proposers for s in g.seeds]


def _cell(by: dict, key: tuple, judged: bool) -> dict:
    maze, proposer, seed = key
    entry = {"maze": maze, "proposer": NAMES.get(proposer, proposer), "seed": seed, "judged": judged}
    for name, method in (("rescue", RESCUE), ("redraw", REDRAW)):
        r = by.get((maze, method, proposer, seed))
        entry[name] = None if r is None else {
            "success": float(r["success_rate"]), "episodes": int(r["episodes"]),
            "successes": round(float(r["success_rate"]) * int(r["episodes"])),
            "proposer_calls": int(float(r["proposer_calls"])), "evaluations": int(float(r["evaluations"]))}
    a, b = entry["rescue"], entry["redraw"]
    if a and b:
        lo, hi = newcombe_ci(a["successes"], a["episodes"], b["successes"], b["episodes"])
        entry |= {"difference": a["success"] - b["success"], "ci_low": lo, "ci_high": hi}
    return entry


def rescue_text(d: dict | None) -> str:
    """README's passage (``<!-- front corrector ant-rescue -->``)."""
    if d is None:
        return "not run yet"
    judged = [c for c in d["cells"] if c["judged"] and c["rescue"] and c["redraw"]]
    described = [c for c in d["cells"] if not c["judged"] and c["rescue"] and c["redraw"]]
    text = (f"{len(judged)} of {d['judged']} cells of the rule: rescue "
            f"{_span(judged, 'rescue')} per cell, redraw {_span(judged, 'redraw')}; rescue - redraw "
            f"{_ant_paired_text(d['pooled'])}; runs at 0: rescue {_zero(judged, 'rescue')}, redraw "
            f"{_zero(judged, 'redraw')}; rescue at least {ANT_FLOOR} on {_floor(judged)} of {len(judged)}: "
            f"**{d['verdict']}**")
    if described:
        text += (f"; on the longer U-chains (described, {len(described)} of {d['described']} cells) rescue "
                 f"{_span(described, 'rescue')}, redraw {_span(described, 'redraw')}")
    return text


def _span(cells: list[dict], side: str) -> str:
    rates = [c[side]["success"] for c in cells]
    return f"{min(rates):.3f}-{max(rates):.3f}" if rates else "—"


def _zero(cells: list[dict], side: str) -> int:
    return sum(c[side]["success"] == 0.0 for c in cells)


def _floor(cells: list[dict]) -> int:
    return sum(c["rescue"]["success"] >= ANT_FLOOR for c in cells)


def rescue_verdict(d: dict | None) -> dict:
    """The rule's row for README's rules table and claims.json."""
    value = "no cell in both yet" if d is None else _ant_paired_text(d["pooled"]) + (
        f"; {d['below']} cell(s) wholly below 0" if d["below"] else "; no cell wholly below 0")
    done = 0 if d is None else d["pooled"]["cells"]
    verdict = f"undecided (0 of {len(_judged())} cells)" if d is None else d["verdict"] + (
        f" ({done} of {d['judged']} cells)" if d["verdict"] == "undecided" else "")
    return {"rule": f"Ant, deaf proposers: {RESCUE} in place of {REDRAW}: rescue - redraw above 0 (pooled, Newcombe "
                    "95 %) and no cell below (U-chain 1-3, seed 0)", "value": value, "verdict": verdict}


def rescue_markdown(d: dict) -> list[str]:
    """claims.md's table: every cell of the grid, the rule's first."""
    lines = ["", f"A rescue for the Ant's default (grid {d['grid']}; docs/corrector.md): {RESCUE} against {REDRAW} "
             f"with two deaf proposers ({DEAF}: 'deaf'; random), seed 0, 200 episodes a run. Rule (the first part's "
             f"cells): {rescue_verdict(d)['value']}: {d['verdict']}.", "",
             "| maze | proposer | seed | judged | rescue | redraw | difference | rescue calls, evaluations | "
             "redraw calls, evaluations |", "|---|---|---|---|---|---|---|---|---|"]
    for c in d["cells"]:
        a, b = c["rescue"], c["redraw"]
        diff = (f"{c['difference']:+.3f} [{c['ci_low']:+.3f}, {c['ci_high']:+.3f}]" if "difference" in c else "—")
        lines.append(f"| {c['maze']} | {c['proposer']} | {c['seed']} | {'yes' if c['judged'] else 'no'} | "
                     f"{_rate(a)} | {_rate(b)} | {diff} | {_spent(a)} | {_spent(b)} |")
    return lines


def _rate(side: dict | None) -> str:
    return "—" if side is None else rate_text(side["successes"], side["episodes"])


def _spent(side: dict | None) -> str:
    return "—" if side is None else f"{side['proposer_calls']}, {side['evaluations']}"
