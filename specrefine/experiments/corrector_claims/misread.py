"""Misreadings no lever had met (docs/corrector.md, the section of that name): grid corrector-span-misread runs the
point mass's default (``ours-corrector-span``) and ``ours`` with the error model's five misreadings (mixes AY and AZ,
added after every lever had been designed) on four new layouts and U-chain 5 with and without subgoals, the oracle
beside. Its statement, fixed before the grid ran: span corrects them only if, per maze and mix pooled over the seeds,
it is within 0.05 of the oracle on every one, no span run ends at 0, and it is below ``ours`` on none (the Newcombe
95 % interval of the difference wholly below 0)."""

from __future__ import annotations

import math
from pathlib import Path

from ..grids import GRIDS, MISREAD_MAZES, MISREAD_MIXES, ROOT
from .common import ORACLE, SPAN, TOLERANCE, costs, episodes_of, load, per_maze, table_name, zero_runs
from .formats import _cost_table, _diff, _num

GRID = "corrector-span-misread"
MIX_NAMES = dict(zip(MISREAD_MIXES, ("AY", "AZ")))


def misread_study(root: Path = ROOT) -> dict | None:
    """Per maze and mix: span's and ours's pooled success, their Newcombe difference, the oracle's, span's runs at 0;
    span's cost over ours's per mix; the statement's verdict. None before the grid's first row of span."""
    g = GRIDS[GRID]
    rows = load(g.tables, root)
    if not any(r["method"] == SPAN for r in rows):
        return None
    mazes, seeds = tuple(table_name(m) for m in MISREAD_MAZES), g.seeds
    entries = []
    for mix, name in MIX_NAMES.items():
        for e in per_maze(rows, mix, mazes, seeds, reference=("ours", "*"), method=SPAN):
            k, n, oracle_runs = episodes_of(rows, e["maze"], *ORACLE, seeds)
            entries.append(e | {"mix": name, "oracle": k / n if n else math.nan, "oracle_runs": oracle_runs,
                                "zero": zero_runs(rows, SPAN, mix, (e["maze"],))[0],
                                "ours_zero": zero_runs(rows, "ours", mix, (e["maze"],))[0]})
    done = [e for e in entries if e["runs"]]
    misses = [e for e in done if not e["success"] >= e["oracle"] - TOLERANCE]  # no oracle yet: a miss, not a pass
    below = [e for e in done if e.get("ci_high", math.nan) < 0]
    complete = all(e["runs"] == e["reference_runs"] == e["oracle_runs"] == len(seeds) for e in entries)
    zero = sum(e["zero"] for e in done)
    verdict = "does not hold" if zero or complete and (misses or below) else "holds" if complete else "undecided"
    return {"grid": GRID, "per_maze": entries, "runs": sum(e["runs"] for e in done), "zero": zero,
            "ours_zero": sum(e["ours_zero"] for e in done), "misses": [(e["mix"], e["maze"]) for e in misses],
            "below": [(e["mix"], e["maze"]) for e in below], "verdict": verdict,
            "cost": {MIX_NAMES[mix]: costs(rows, mix, mazes, seeds, first=SPAN) for mix in MISREAD_MIXES}}


def misread_text(d: dict | None) -> str:
    """README's passage (``<!-- front corrector misread -->``)."""
    if d is None:
        return "not run yet"
    done = [e for e in d["per_maze"] if e["runs"]]
    missed = ", ".join(f"{e['mix']} {e['maze']} {_num(e['success'])} against {_num(e['oracle'])}" for e in done
                       if (e["mix"], e["maze"]) in d["misses"])
    below = ", ".join(f"{mix} {maze}" for mix, maze in d["below"])
    cost = "; ".join(f"{name} {_num(c['proposer_calls_ratio'], '{:.2f}x')} the proposer calls and "
                     f"{_num(c['evaluations_ratio'], '{:.2f}x')} the evaluations over {c['pairs']} pairs"
                     for name, c in d["cost"].items() if c["pairs"])
    ours = [e["reference_success"] for e in done if not math.isnan(e["reference_success"])]
    return (f"span within {TOLERANCE} of the oracle on {len(done) - len(d['misses'])} of {len(done)} mazes and mixes "
            f"run ({len(d['per_maze'])} in the grid)" + (f", not on {missed}" if missed else "")
            + f"; below ours on {len(d['below'])}"
            + (f" ({below})" if below else "")
            + f"; runs at 0: span {d['zero']} of {d['runs']}, ours {d['ours_zero']}"
            + (f"; ours {min(ours):.3f}-{max(ours):.3f} per maze and mix" if ours else "")
            + (f"; span's cost over ours's: {cost}" if cost else "") + f": the statement {d['verdict']}")


def misread_markdown(d: dict) -> list[str]:
    lines = ["", f"Misreadings no lever had met (grid {d['grid']}; docs/corrector.md): {SPAN} and ours with mixes "
             f"{', '.join(MIX_NAMES.values())}, pooled over seeds, the oracle beside; {SPAN} - ours (Newcombe 95 %). "
             f"Within {TOLERANCE} of the oracle everywhere, no run at 0 and below ours nowhere: {d['verdict']}.", "",
             f"| mix | maze | runs | {SPAN} | ours | difference | oracle | runs at 0 ({SPAN} / ours) |",
             "|---|---|---|---|---|---|---|---|"]
    lines += [f"| {e['mix']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | {_num(e['reference_success'])} | "
              f"{_diff(e)} | {_num(e['oracle'])} | {e['zero']} / {e['ours_zero']} |" for e in d["per_maze"]]
    return lines + _cost_table("mix", list(d["cost"].items()))
