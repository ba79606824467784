"""The Ant's default with deaf proposers, one paired study per grid (docs/corrector.md):

- "A rescue for the Ant's default": grid ant-corrector-rescue runs ``ours-corrector-redraw-rescue`` and
  ``ours-corrector-redraw`` with the error model's deaf extreme and the ``random`` proposer on the Ant's U-chain 1-3
  (seed 0; the rule's cells), then on the longer U-chains (described);
- "Weak legs judged by the path": grid ant-corrector-floor runs ``ours-corrector-redraw-rescue-floor`` on the rescue
  grid's judged cells, the rescue's own runs read from that grid's table; its rule counts only if the rescue's holds.

Each rule, fixed before its grid ran: the new method takes the base's place as the Ant's default only if, over the
judged cells, the pooled difference new - base (Newcombe 95 %) lies wholly above 0 and no cell's interval lies wholly
below 0."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ...core.results import newcombe_ci, rate_text
from .. import comparison as cmp
from ..grids import DEAF, GRIDS, ROOT
from .ant import ANT_FLOOR, REDRAW
from .common import load, paired_rows
from .formats import _ant_paired_text

GRID = "ant-corrector-rescue"
RESCUE = "ours-corrector-redraw-rescue"
FLOOR = "ours-corrector-redraw-rescue-floor"
NAMES = {DEAF: "deaf", "random": "random"}  # each proposer's short name in the tables


@dataclass(frozen=True)
class Pair:
    """A grid that runs ``new`` against ``base`` (short names ``names``) on its first part's cells; ``base_grid``: the
    grid whose tables hold the base's runs (None: this one's); ``after``: the marker of the study whose rule must hold
    first (None: none)."""

    marker: str
    grid: str
    new: str
    base: str
    names: tuple[str, str]
    section: str
    base_grid: str | None = None
    after: str | None = None


RESCUE_PAIR = Pair("ant-rescue", GRID, RESCUE, REDRAW, ("rescue", "redraw"), "A rescue for the Ant's default")
FLOOR_PAIR = Pair("ant-floor", "ant-corrector-floor", FLOOR, RESCUE, ("floor", "rescue"),
                  "Weak legs judged by the path", base_grid=GRID, after=RESCUE_PAIR.marker)
PAIRS = (RESCUE_PAIR, FLOOR_PAIR)  # a study's ``after`` comes before it


def pair_studies(root: Path = ROOT) -> dict[str, dict | None]:
    """Each pair's study (``pair_study``) by its marker, in ``PAIRS``' order."""
    out: dict[str, dict | None] = {}
    for pair in PAIRS:
        out[pair.marker] = pair_study(pair, root, out.get(pair.after) if pair.after else None)
    return out


def pair_study(pair: Pair, root: Path = ROOT, first: dict | None = None) -> dict | None:
    """Per cell (maze, proposer, seed; the rule's part first): both methods' success, runs at 0, proposer calls and
    evaluations, the new method's Newcombe difference; the pooled difference over the rule's cells and the verdict
    (``first``: the study of ``pair.after``, whose rule must hold first). None before the grid's first finished row."""
    g = GRIDS[pair.grid]
    own = [r for r in load(g.tables, root) if cmp.is_done(r)]
    if not own:
        return None
    rows = own + ([r for r in load(GRIDS[pair.base_grid].tables, root) if cmp.is_done(r) and r["method"] == pair.base]
                  if pair.base_grid else [])
    by = {(r["maze"], r["method"], r["proposer"], int(r["seed"])): r for r in rows}
    judged = _judged(pair)
    described = [(m, p, s) for part in g.parts[1:] for m in part.mazes for p in part.proposers for s in g.seeds]
    cells = [_cell(pair, by, key, key in judged) for key in judged + described]
    pooled = paired_rows(rows, pair.new, pair.base, judged)
    below = [c for c in cells if c["judged"] and c.get("ci_high", 0.0) < 0]
    verdict = ("undecided" if not pooled["complete"] else
               "adopted" if pooled["ci"][0] > 0 and not below else "not adopted")
    if pair.after and verdict == "adopted" and (first is None or first["verdict"] != "adopted"):
        verdict = "undecided" if first is None or first["verdict"] == "undecided" else "moot"
    return {"marker": pair.marker, "grid": pair.grid, "cells": cells, "pooled": pooled, "below": len(below),
            "verdict": verdict, "judged": len(judged), "described": len(described)}


def _judged(pair: Pair) -> list[tuple]:
    """The rule's cells (maze, proposer, seed): the grid's first part."""
    g = GRIDS[pair.grid]
    return [(m, p, s) for m in g.mazes for p in g.parts[0].proposers for s in g.seeds]


def _cell(pair: Pair, by: dict, key: tuple, judged: bool) -> dict:
    maze, proposer, seed = key
    entry = {"maze": maze, "proposer": NAMES.get(proposer, proposer), "seed": seed, "judged": judged}
    for side, method in (("new", pair.new), ("base", pair.base)):
        r = by.get((maze, method, proposer, seed))
        entry[side] = None if r is None else {
            "success": float(r["success_rate"]), "episodes": int(r["episodes"]),
            "successes": round(float(r["success_rate"]) * int(r["episodes"])),
            "proposer_calls": int(float(r["proposer_calls"])), "evaluations": int(float(r["evaluations"]))}
    a, b = entry["new"], entry["base"]
    if a and b:
        lo, hi = newcombe_ci(a["successes"], a["episodes"], b["successes"], b["episodes"])
        entry |= {"difference": a["success"] - b["success"], "ci_low": lo, "ci_high": hi}
    return entry


def pair_text(pair: Pair, d: dict | None) -> str:
    """README's passage (``<!-- front corrector MARKER -->``)."""
    if d is None:
        return "not run yet"
    new, base = pair.names
    judged = [c for c in d["cells"] if c["judged"] and c["new"] and c["base"]]
    described = [c for c in d["cells"] if not c["judged"] and c["new"] and c["base"]]
    text = (f"{len(judged)} of {d['judged']} cells of the rule: {new} "
            f"{_span(judged, 'new')} per cell, {base} {_span(judged, 'base')}; {new} - {base} "
            f"{_ant_paired_text(d['pooled'])}; runs at 0: {new} {_zero(judged, 'new')}, {base} "
            f"{_zero(judged, 'base')}; {new} at least {ANT_FLOOR} on {_floor(judged)} of {len(judged)}: "
            f"**{_verdict_text(pair, d['verdict'])}**")
    if described:
        text += (f"; on the longer U-chains (described, {len(described)} of {d['described']} cells) {new} "
                 f"{_span(described, 'new')}, {base} {_span(described, 'base')}")
    return text


def _verdict_text(pair: Pair, verdict: str) -> str:
    return f"moot ({pair.names[1]} not adopted)" if verdict == "moot" else verdict


def _span(cells: list[dict], side: str) -> str:
    rates = [c[side]["success"] for c in cells]
    return f"{min(rates):.3f}-{max(rates):.3f}" if rates else "—"


def _zero(cells: list[dict], side: str) -> int:
    return sum(c[side]["success"] == 0.0 for c in cells)


def _floor(cells: list[dict]) -> int:
    return sum(c["new"]["success"] >= ANT_FLOOR for c in cells)


def pair_verdict(pair: Pair, d: dict | None) -> dict:
    """The rule's row for README's rules table and claims.json."""
    new, base = pair.names
    value = "no cell in both yet" if d is None else _ant_paired_text(d["pooled"]) + (
        f"; {d['below']} cell(s) wholly below 0" if d["below"] else "; no cell wholly below 0")
    done = 0 if d is None else d["pooled"]["cells"]
    verdict = f"undecided (0 of {len(_judged(pair))} cells)" if d is None else _verdict_text(pair, d["verdict"]) + (
        f" ({done} of {d['judged']} cells)" if d["verdict"] == "undecided" else "")
    after = f", once {base} is adopted" if pair.after else ""
    return {"rule": f"Ant, deaf proposers: {pair.new} in place of {pair.base}{after}: {new} - {base} above 0 "
                    "(pooled, Newcombe 95 %) and no cell below (U-chain 1-3, seed 0)", "value": value,
            "verdict": verdict}


def pair_markdown(pair: Pair, d: dict) -> list[str]:
    """claims.md's table: every cell of the grid, the rule's first."""
    new, base = pair.names
    lines = ["", f"{pair.section} (grid {d['grid']}; docs/corrector.md): {pair.new} against {pair.base} "
             f"with two deaf proposers ({DEAF}: 'deaf'; random), seed 0, 200 episodes a run. Rule (the first part's "
             f"cells): {pair_verdict(pair, d)['value']}: {_verdict_text(pair, d['verdict'])}.", "",
             f"| maze | proposer | seed | judged | {new} | {base} | difference | {new} calls, evaluations | "
             f"{base} calls, evaluations |", "|---|---|---|---|---|---|---|---|---|"]
    for c in d["cells"]:
        a, b = c["new"], c["base"]
        diff = (f"{c['difference']:+.3f} [{c['ci_low']:+.3f}, {c['ci_high']:+.3f}]" if "difference" in c else "—")
        lines.append(f"| {c['maze']} | {c['proposer']} | {c['seed']} | {'yes' if c['judged'] else 'no'} | "
                     f"{_rate(a)} | {_rate(b)} | {diff} | {_spent(a)} | {_spent(b)} |")
    return lines


def _rate(side: dict | None) -> str:
    return "—" if side is None else rate_text(side["successes"], side["episodes"])


def _spent(side: dict | None) -> str:
    return "—" if side is None else f"{side['proposer_calls']}, {side['evaluations']}"
