"""The point mass's default with a proposer that knows nothing (docs/corrector.md, "A proposer that knows nothing"):
grid corrector-fine-random runs ours-corrector-fine and ours with the ``random`` proposer (random free-space discs,
no route, deaf to feedback) on the 17 suite mazes and four new layouts; the oracle beside it is fine's own oracle grid
on the suite and the grid's own part on the new layouts. Described, with the one statement README may make from it,
fixed before the grid ran: fine corrects a proposer that knows nothing only if, pooled over its seeds, it is within
0.05 of the oracle on every maze and no run of it ends at 0."""

from __future__ import annotations

import math
from pathlib import Path

from .. import comparison as cmp
from ..grids import GRIDS, RANDOM_CHECK_MAZES, ROOT
from .common import FINE, ORACLE, TOLERANCE, costs, episodes_of, load, table_name
from .formats import _num

GRID = "corrector-fine-random"
ORACLE_GRID = "corrector-fine-oracle"  # the oracle on the suite mazes (seeds 0-3; the grid's seeds are read)
PROPOSER = "random"
WEAK = 0.9  # a run below this is counted beside the runs at 0


def any_study(root: Path = ROOT) -> dict | None:
    """Per maze: fine's and ours's pooled success with the random proposer, the oracle's, fine's runs at 0 and below
    0.9; fine's cost over ours's; whether the statement holds. None before the grid's first row of fine."""
    g = GRIDS[GRID]
    rows = load(g.tables, root)
    if not any(r["method"] == FINE for r in rows):
        return None
    oracle_rows = load(GRIDS[ORACLE_GRID].tables, root) + rows
    new = {table_name(m) for m in RANDOM_CHECK_MAZES}
    mazes = tuple(table_name(m) for m in g.parts[0].mazes + RANDOM_CHECK_MAZES)
    entries = []
    for maze in mazes:
        runs = [float(r["success_rate"]) for r in rows if (r["maze"], r["method"], r["proposer"]) ==
                (maze, FINE, PROPOSER) and r["seed"] in g.seeds and cmp.is_done(r)]
        entries.append({"maze": maze, "new": maze in new, "runs": len(runs),
                        "success": _rate(episodes_of(rows, maze, FINE, PROPOSER, g.seeds)),
                        "ours": _rate(episodes_of(rows, maze, "ours", PROPOSER, g.seeds)),
                        "oracle": _rate(episodes_of(oracle_rows, maze, *ORACLE, g.seeds)),
                        "zero": sum(p == 0.0 for p in runs), "weak": sum(p < WEAK for p in runs)})
    done = [e for e in entries if e["runs"]]
    misses = [e for e in done if not e["success"] >= e["oracle"] - TOLERANCE]  # no oracle yet: a miss, not a pass
    complete = all(e["runs"] == len(g.seeds) and not math.isnan(e["oracle"]) for e in entries)
    zero = sum(e["zero"] for e in done)
    verdict = ("does not hold" if misses and complete or zero else "holds" if complete else "undecided")
    return {"grid": GRID, "per_maze": entries, "runs": sum(e["runs"] for e in done), "zero": zero,
            "weak": sum(e["weak"] for e in done), "misses": [e["maze"] for e in misses], "verdict": verdict,
            "cost": costs(rows, PROPOSER, mazes, g.seeds, first=FINE)}


def _rate(counts: tuple[int, int, int]) -> float:
    k, n, _ = counts
    return k / n if n else math.nan


def any_text(d: dict | None) -> str:
    """README's passage on the random proposer (``<!-- front corrector any-proposer -->``)."""
    if d is None:
        return "not run yet"
    done = [e for e in d["per_maze"] if e["runs"]]
    missed = ", ".join(f"{e['maze']} {_num(e['success'])} against {_num(e['oracle'])}" for e in done
                       if e["maze"] in d["misses"])
    cost = d["cost"]
    return (f"fine within {TOLERANCE} of the oracle on {len(done) - len(d['misses'])} of {len(done)} mazes run "
            f"({len(d['per_maze'])} in the grid)" + (f", not on {missed}" if missed else "")
            + f"; runs below {WEAK}: {d['weak']} of {d['runs']}, at 0: {d['zero']}; ours "
            f"{min(e['ours'] for e in done):.3f}-{max(e['ours'] for e in done):.3f} per maze; fine's cost over "
            f"ours's {_num(cost['proposer_calls_ratio'], '{:.2f}x')} the proposer calls and "
            f"{_num(cost['evaluations_ratio'], '{:.2f}x')} the evaluations over {cost['pairs']} pairs: the statement "
            f"{d['verdict']}")


def any_markdown(d: dict) -> list[str]:
    lines = ["", f"A proposer that knows nothing (grid {d['grid']}, described; docs/corrector.md): {FINE} and ours "
             f"with the random proposer, pooled over seeds, the oracle beside (fine's oracle grid on the suite). "
             f"Within {TOLERANCE} of the oracle on every maze with no run at 0: {d['verdict']}.", "",
             f"| maze | new layout | runs | {FINE} | runs below {WEAK} | runs at 0 | ours | oracle |",
             "|---|---|---|---|---|---|---|---|"]
    lines += [f"| {e['maze']} | {'yes' if e['new'] else 'no'} | {e['runs']} | {_num(e['success'])} | {e['weak']} | "
              f"{e['zero']} | {_num(e['ours'])} | {_num(e['oracle'])} |" for e in d["per_maze"]]
    return lines
