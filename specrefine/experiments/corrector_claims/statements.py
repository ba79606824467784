"""The point mass's default against the oracle and ``ours`` where a statement was fixed before its grid ran
(docs/corrector.md): "Misreadings no lever had met" (grid corrector-span-misread: the error model's five misreadings,
added after every lever had been designed, on four new layouts and U-chain 5 with and without subgoals) and "The
point mass's default on D4RL's maps, misreadings included" (grid corrector-span-gr); and both again with the default
since, ``ours-corrector-span-bridge`` ("The statements again, with the default": grids corrector-span-bridge-misread
and -gr, whose ``ours`` and oracle rows are span's grids'). Each statement holds only if, per maze and proposer pooled
over the seeds, its method is within 0.05 of the oracle on every one, no run of it ends at 0, and it is below ``ours``
on none (the Newcombe 95 % interval of the difference wholly below 0)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from .. import comparison as cmp
from ..grids import GR_MAZES, GR_MIXES, GRIDS, MISREAD_MAZES, MISREAD_MIXES, ROOT
from .common import ORACLE, SPAN, SPAN_BRIDGE, TOLERANCE, costs, episodes_of, load, per_maze, table_name, zero_runs
from .formats import _cost_table, _diff, _num


@dataclass(frozen=True)
class Statement:
    marker: str  # README's and docs' marker (``<!-- front corrector MARKER -->``) and claims.json's key
    grid: str
    title: str  # its docs/corrector.md section
    mazes: tuple
    names: dict  # proposer -> its short name in the tables
    method: str = SPAN
    label: str = "span"  # the method's name in README's sentence
    reference_grid: str | None = None  # the grid whose tables hold ours's and the oracle's rows (None: ``grid``)


MISREAD_NAMES = dict(zip(MISREAD_MIXES, ("AY", "AZ")))
GR_NAMES = dict(zip(GR_MIXES, ("moderate", "severe", "AJ", "AK"))) | MISREAD_NAMES
AGAIN = "The statements again, with the default"
STATEMENTS = (Statement("misread", "corrector-span-misread", "Misreadings no lever had met", MISREAD_MAZES,
                        MISREAD_NAMES),
              Statement("span-gr", "corrector-span-gr", "The point mass's default on D4RL's maps, misreadings "
                        "included", GR_MAZES, GR_NAMES),
              Statement("misread-bridge", "corrector-span-bridge-misread", f"{AGAIN}: misreadings", MISREAD_MAZES,
                        MISREAD_NAMES, SPAN_BRIDGE, "span-bridge", "corrector-span-misread"),
              Statement("span-gr-bridge", "corrector-span-bridge-gr", f"{AGAIN}: D4RL's maps", GR_MAZES, GR_NAMES,
                        SPAN_BRIDGE, "span-bridge", "corrector-span-gr"))


def statement_study(st: Statement, root: Path = ROOT) -> dict | None:
    """Per maze and proposer: the method's and ours's pooled success, their Newcombe difference, the oracle's, runs at
    0; its cost over ours's per proposer; the statement's verdict. None before the grid's first row of the method."""
    g, method = GRIDS[st.grid], st.method
    rows = load(g.tables, root)
    if not any(r["method"] == method for r in rows):
        return None
    same = None
    if st.reference_grid:
        reference = [r for r in load(GRIDS[st.reference_grid].tables, root) if r["method"] != method]
        same = same_runs(rows, reference)
        rows += reference
    mazes, seeds = tuple(table_name(m) for m in st.mazes), g.seeds
    entries = []
    for proposer, name in st.names.items():
        for e in per_maze(rows, proposer, mazes, seeds, reference=("ours", "*"), method=method):
            k, n, oracle_runs = episodes_of(rows, e["maze"], *ORACLE, seeds)
            entries.append(e | {"mix": name, "oracle": k / n if n else math.nan, "oracle_runs": oracle_runs,
                                "zero": zero_runs(rows, method, proposer, (e["maze"],))[0],
                                "ours_zero": zero_runs(rows, "ours", proposer, (e["maze"],))[0]})
    done = [e for e in entries if e["runs"]]
    misses = [e for e in done if not e["success"] >= e["oracle"] - TOLERANCE]  # no oracle yet: a miss, not a pass
    below = [e for e in done if e.get("ci_high", math.nan) < 0]
    complete = all(e["runs"] == e["reference_runs"] == e["oracle_runs"] == len(seeds) for e in entries)
    zero = sum(e["zero"] for e in done)
    verdict = "does not hold" if zero or complete and (misses or below) else "holds" if complete else "undecided"
    return {"grid": st.grid, "title": st.title, "method": method, "label": st.label, "per_maze": entries,
            "runs": sum(e["runs"] for e in done),
            "zero": zero, "ours_zero": sum(e["ours_zero"] for e in done),
            "misses": [(e["mix"], e["maze"]) for e in misses], "below": [(e["mix"], e["maze"]) for e in below],
            "verdict": verdict, "same_as_span": same,
            "cost": {name: costs(rows, proposer, mazes, seeds, first=method) for proposer, name in st.names.items()}}


def statement_studies(root: Path = ROOT) -> dict[str, dict | None]:
    """Every statement's study, by its marker."""
    return {st.marker: statement_study(st, root) for st in STATEMENTS}


RUN_COLUMNS = ("success_rate", "evaluations", "proposer_calls", "sim_steps")


def same_runs(rows, reference) -> tuple[int, int]:
    """(cells whose run equals span's in the reference rows, column for column in RUN_COLUMNS; cells run)."""
    span = {(r["maze"], r["proposer"], r["seed"]): r for r in reference if r["method"] == SPAN and cmp.is_done(r)}
    done = [r for r in rows if cmp.is_done(r)]
    return sum(all(r[c] == span[key][c] for c in RUN_COLUMNS) for r in done
               if (key := (r["maze"], r["proposer"], r["seed"])) in span), len(done)


def statement_text(d: dict | None) -> str:
    """README's passage for one statement."""
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
    label = d["label"]
    return (f"{label} within {TOLERANCE} of the oracle on {len(done) - len(d['misses'])} of {len(done)} mazes and "
            f"proposers run ({len(d['per_maze'])} in the grid)" + (f", not on {missed}" if missed else "")
            + f"; below ours on {len(d['below'])}" + (f" ({below})" if below else "")
            + f"; runs at 0: {label} {d['zero']} of {d['runs']}, ours {d['ours_zero']}"
            + (f"; ours {min(ours):.3f}-{max(ours):.3f} per maze and proposer" if ours else "")
            + (f"; {label}'s cost over ours's: {cost}" if cost else "")
            + (f"; the same runs as span's (success, evaluations, proposer calls, simulator steps) on "
               f"{d['same_as_span'][0]} of {d['same_as_span'][1]} cells" if d.get("same_as_span") else "")
            + f": the statement {d['verdict']}")


def statement_markdown(d: dict) -> list[str]:
    method = d["method"]
    lines = ["", f"{d['title']} (grid {d['grid']}; docs/corrector.md): {method} and ours, pooled over seeds, the "
             f"oracle beside; {method} - ours (Newcombe 95 %). Within {TOLERANCE} of the oracle everywhere, no run at "
             f"0 and below ours nowhere: {d['verdict']}.", "",
             f"| proposer | maze | runs | {method} | ours | difference | oracle | runs at 0 ({method} / ours) |",
             "|---|---|---|---|---|---|---|---|"]
    lines += [f"| {e['mix']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | {_num(e['reference_success'])} | "
              f"{_diff(e)} | {_num(e['oracle'])} | {e['zero']} / {e['ours_zero']} |" for e in d["per_maze"]]
    return lines + _cost_table("proposer", list(d["cost"].items()))
