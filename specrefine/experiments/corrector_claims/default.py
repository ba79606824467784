"""The point mass's default method (docs/corrector.md, "The point mass's default method: deep with the oracle"):
a corrector against ours with the oracle on the 17 suite mazes, and the rule that makes it the point's ``--preset
best`` method: ours-corrector-deep (grid corrector-deep-oracle), then ours-corrector-mend (corrector-mend-oracle)."""

from __future__ import annotations

import math
from pathlib import Path

from ..grids import GR_MIXES, GRIDS, ROOT
from .common import (
    BACKTRACK,
    DEEP,
    FINE,
    MEND,
    SPAN,
    SPAN_BRIDGE,
    costs,
    episodes_of,
    load,
    paired_rows,
    per_maze,
    zero_runs,
)
from .formats import _ant_paired_text, _cost_table, _diff, _num

GRID = "corrector-deep-oracle"
MEND_ORACLE_GRID = "corrector-mend-oracle"
#: each candidate's oracle grid, in the order they were adopted or fixed
DEFAULTS = ((GRID, DEEP), (MEND_ORACLE_GRID, MEND), ("corrector-backtrack-oracle", BACKTRACK),
            ("corrector-fine-oracle", FINE), ("corrector-span-oracle", SPAN),
            ("corrector-span-bridge-oracle", SPAN_BRIDGE))
PROPOSER = "geometric"
MARGIN = 0.01  # the pooled difference's lower end at or above -MARGIN


def default_study(root: Path = ROOT, grid: str = GRID, method: str = DEEP) -> dict | None:
    """``method`` and ours with the oracle per maze (grid ``grid``), pooled over the paired cells, runs at 0 and the
    method's cost over ours's; None before the grid's first row."""
    g = GRIDS[grid]
    rows = load(g.tables, root)
    if not rows:
        return None
    paired = paired_rows(rows, method, "ours", [(m, s) for m in g.mazes for s in g.seeds], proposer=PROPOSER)
    entries = per_maze(rows, PROPOSER, g.mazes, g.seeds, reference=("ours", "*"), method=method)
    below = [e["maze"] for e in entries if "ci_high" in e and e["ci_high"] < 0]
    holds = {"below on no maze": not below, f"pooled lower end >= -{MARGIN}": paired["cells"] > 0
             and paired["ci"][0] >= -MARGIN}
    return {"grid": grid, "method": method, "per_maze": entries, "paired": paired, "below": below, "parts": holds,
            "adopted": paired["complete"] and all(holds.values()),
            "zero": {m: zero_runs(rows, m, PROPOSER, g.mazes) for m in (method, "ours")},
            "costs": costs(rows, PROPOSER, g.mazes, g.seeds, first=method)}


def default_studies(root: Path = ROOT) -> list[dict]:
    """``default_study`` of each candidate in ``DEFAULTS`` whose grid has a row."""
    return [d for grid, method in DEFAULTS if (d := default_study(root, grid, method))]


def default_marker(method: str) -> str:
    """README's marker for a candidate's passage: ``point-default`` for deep, the first, then by name."""
    return "point-default" if method == DEFAULTS[0][1] else f"point-default-{method.rsplit('-', 1)[1]}"


def default_verdict(d: dict) -> dict:
    """The rule's row: "adopted" once every paired cell ran and both parts hold."""
    e = d["paired"]
    if not e["complete"]:
        verdict = f"undecided ({e['cells']} of {e['expected']} cells)"
    else:
        verdict = "adopted" if d["adopted"] else \
            f"not adopted ({', '.join(part for part, held in d['parts'].items() if not held)} missed)"
    return {"rule": f"point, the oracle: {d['method']} as --preset best's method in place of ours: below ours on no "
                    f"suite maze (Newcombe), the pooled difference's lower end at or above -{MARGIN}",
            "value": f"below on {len(d['below'])} of {len(d['per_maze'])}"
                     + (f" ({', '.join(d['below'])})" if d["below"] else "") + f"; {_ant_paired_text(e)}",
            "verdict": verdict}


def default_markdown(d: dict) -> list[str]:
    c, z, v = d["costs"], d["zero"], default_verdict(d)
    lines = ["", f"Rule: {v['rule']}: {v['value']}: **{v['verdict']}**.", "",
             f"The point mass's default method (grid {d['grid']}, the oracle `{PROPOSER}`, centre points): "
             f"{d['method']} - ours per suite maze, pooled over seeds (Newcombe 95 %). Runs at 0: "
             + ", ".join(f"{m} {k} of {n}" for m, (k, n) in z.items())
             + f". Cost of {d['method']} over ours ({c['pairs']} pairs): {_num(c['proposer_calls_ratio'], '{:.2f}x')} "
             f"the proposer calls, {_num(c['evaluations_ratio'], '{:.2f}x')} the evaluations, "
             f"{_num(c['sim_steps_ratio'], '{:.2f}x')} the simulator steps.", "",
             f"| maze | runs (ours) | {d['method']} | ours | difference |", "|---|---|---|---|---|"]
    lines += [f"| {e['maze']} | {e['runs']} ({e['reference_runs']}) | {_num(e['success'])} | "
              f"{_num(e['reference_success'])} | {_diff(e)} |" for e in d["per_maze"]]
    return lines


def default_text(d: dict | None) -> str:
    """README's passage on the point mass's default method (``<!-- front corrector point-default -->``)."""
    if d is None:
        return "not run yet"
    c, z = d["costs"], d["zero"]
    return (f"{d['method']} - ours with the oracle {_ant_paired_text(d['paired'])}; below ours on {len(d['below'])} of "
            f"{len(d['per_maze'])} suite mazes; runs at 0: " + ", ".join(f"{m} {k}" for m, (k, _) in z.items())
            + f"; {_num(c['proposer_calls_ratio'], '{:.2f}x')} the proposer calls and "
              f"{_num(c['evaluations_ratio'], '{:.2f}x')} the evaluations of ours: {default_verdict(d)['verdict']}")


GR_GRID = "corrector-deep-gr"
MEND_GRID = "corrector-mend"  # its first part runs ours-corrector-mend on GR_GRID's cells (they informed it)
GR_NAMES = ("moderate", "severe", "AJ", "AK")  # GR_MIXES by name: two presets, then the two mixes made for the grid


def gr_study(root: Path = ROOT) -> dict | None:
    """Described (docs/corrector.md, "The point mass's default on Gymnasium-Robotics' maps"): deep beside ours and
    the oracle per map and proposer, runs at 0, deep - ours pooled over the cells both ran, deep's cost over ours's;
    None before the grid's first row of deep."""
    g = GRIDS[GR_GRID]
    rows = load(g.tables + (GRIDS[MEND_GRID].part_table(0),), root)  # mend on these cells: its grid's first part
    if not any(r["method"] == DEEP for r in rows):
        return None
    mixes = dict(zip(GR_MIXES, GR_NAMES))
    entries = []
    for mix, name in mixes.items():
        for e in per_maze(rows, mix, g.mazes, g.seeds, reference=("ours", "*"), method=DEEP):
            k, n, _ = episodes_of(rows, e["maze"], "ours", PROPOSER, g.seeds)
            km, nm, rm = episodes_of(rows, e["maze"], MEND, mix, g.seeds)
            entries.append(e | {"mix": name, "oracle": k / n if n else math.nan,
                                "mend": km / nm if nm else math.nan, "mend_runs": rm})
    cells = [(m, p, s) for p in GR_MIXES for m in g.mazes for s in g.seeds]
    return {"grid": GR_GRID, "per_maze": entries, "paired": paired_rows(rows, DEEP, "ours", cells),
            "zero": {m: sum(zero_runs(rows, m, mix, g.mazes)[0] for mix in GR_MIXES) for m in (DEEP, "ours")},
            "mend_runs": sum(e["mend_runs"] for e in entries),
            "runs": sum(e["runs"] for e in entries),
            "costs": [costs(rows, mix, g.mazes, g.seeds, first=DEEP) | {"proposer": name}
                      for mix, name in mixes.items()]}


def gr_text(d: dict | None) -> str:
    """README's passage on the gr check (``<!-- front corrector point-default-gr -->``)."""
    if d is None:
        return "not run yet"
    done = [e for e in d["per_maze"] if e["runs"]]
    return (f"deep {min(e['success'] for e in done):.3f}-{max(e['success'] for e in done):.3f} per map and proposer "
            f"over {d['runs']} runs ({len(done)} of {len(d['per_maze'])} maps and proposers run), ours "
            f"{min(e['reference_success'] for e in done):.3f}-{max(e['reference_success'] for e in done):.3f}; deep - "
            f"ours {_ant_paired_text(d['paired'])}; runs at 0: " + ", ".join(f"{m} {k}" for m, k in d["zero"].items()))


def gr_markdown(d: dict) -> list[str]:
    lines = ["", f"The point mass's default on Gymnasium-Robotics' maps (grid {d['grid']}, described, no rule): "
             f"{DEEP} beside ours and the oracle, pooled over seeds; Newcombe 95 % interval of {DEEP} - ours. Runs at "
             "0: " + ", ".join(f"{m} {k} of {d['runs']}" for m, k in d["zero"].items()) + f". Paired over the cells "
             f"both ran: {_ant_paired_text(d['paired'])}.", "",
             f"| proposer | map | runs | {DEEP} | ours | difference | oracle | {MEND} (runs; informed by this grid) |",
             "|---|---|---|---|---|---|---|---|"]
    lines += [f"| {e['mix']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | {_num(e['reference_success'])} | "
              f"{_diff(e)} | {_num(e['oracle'])} | {_num(e['mend'])} ({e['mend_runs']}) |" for e in d["per_maze"]]
    return lines + _cost_table("proposer", [(c["proposer"], c) for c in d["costs"]])
