"""The claims' names and fixed constants (methods, variants and their grids, references, tolerances), and the helpers
every study shares: the shipped tables loaded, episodes pooled per maze, runs at 0, cost ratios, paired differences."""

from __future__ import annotations

import math
from pathlib import Path

from ...core.results import newcombe_ci
from ...runs.sweep import read_checked_table
from .. import comparison as cmp
from ..grids import GRIDS, HELD_OUT_MIXES, ROOT

METHOD = "ours-corrector"
LEVERS = ("ours-deeprepair", "ours-feasible", "ours-checked")
GATED = "ours-corrector-gated"
LEAN = "ours-corrector-lean"
PRECISE = "ours-corrector-precise"
TRIM = "ours-corrector-trim"
SPREAD = "ours-corrector-precise (spread)"  # precise at the code with spread start states (its grid's rows, relabelled)
RECHECK = "ours-corrector-recheck"
FRUGAL = "ours-corrector-frugal"
RETRY = "ours-corrector-retry"
THRIFT = "ours-corrector-thrift"
POLISH = "ours-corrector-polish"
CENTRE = "ours-corrector-polish (centre)"  # polish with every leg aimed at its region's centre (its grid's rows)
PERSIST = "ours-corrector-persist"  # polish at centre points, corrected until no leg is dead (its grids' rows)
SNAP = "ours-corrector-snap"  # persist, a reply's waypoint centred in a wall moved clear of it (its grids' rows)
EXTEND = "ours-corrector-extend"  # snap, a dead path corrected past the search's budget, up to 3x (its grids' rows)
KEEP = "ours-corrector-keep"  # snap, a dead path's edge replaced by its declined split with the longest live start
FALLBACK = "ours-corrector-fallback"  # keep, the kept split given up for the edge it replaced at half the budget
ADVANCE = "ours-corrector-advance-extend"  # snap, a dead path keeping the live legs of a reply, with extend's budget
ROADMAP = "ours-corrector-roadmap"  # advance-extend, a dead leg first offered a chain over every reply's waypoints
SOUND = "ours-corrector-sound"  # roadmap, its chain built only on legs that succeed on at least half their rollouts
MEMORY = "ours-corrector-memory"  # roadmap, each chain search starting from what the ones before it reached
PROBE = "ours-corrector-probe"  # memory, a search that runs out of legs probing from the node nearest the goal
DEEP = "ours-corrector-deep"  # probe, each roadmap search allowed 360 evaluations instead of 120
MEND = "ours-corrector-mend"  # deep, a live leg below 0.9 also offered the roadmap's chain over sound legs
BACKTRACK = "ours-corrector-backtrack"  # mend, a dead leg of a dead path also offered the chain from the path's start
FINE = "ours-corrector-fine"  # backtrack, probes at half the radius once every first ring of a search is spent
SPAN = "ours-corrector-span"  # fine, a weak leg also offered the chains from its start past its end (two vertices)
SPAN_BRIDGE = "ours-corrector-span-bridge"  # span, a weak leg also offered the chain from the leg before it
SHOWN_BESIDE = ("ours-corrector-advance",)  # run beside a variant on its new layouts (advance without the budget)
#: a variant whose adoption counts runs below this success instead of runs at 0 (its docs/corrector.md section)
ADOPTION_FLOOR = {SOUND: 0.5, MEND: 0.9, BACKTRACK: 0.9, FINE: 0.9, SPAN: 0.9, SPAN_BRIDGE: 0.9}
#: a variant whose adoption asks for no more such runs than its reference, not fewer (its docs/corrector.md section)
NO_MORE = {MEND, BACKTRACK, FINE, SPAN, SPAN_BRIDGE}
NON_INFERIORITY = 0.02  # a variant - ours-corrector: the interval's lower end at or above -this (no worse)
#: each variant of the corrector and its grid
VARIANT_GRIDS = {GATED: "corrector-gated", LEAN: "corrector-lean", PRECISE: "corrector-precise",
                 TRIM: "corrector-trim", SPREAD: "corrector-precise-spread", RECHECK: "corrector-recheck",
                 FRUGAL: "corrector-frugal", RETRY: "corrector-retry", THRIFT: "corrector-thrift",
                 POLISH: "corrector-polish", CENTRE: "corrector-centre", PERSIST: "corrector-persist",
                 SNAP: "corrector-snap", EXTEND: "corrector-extend",
                 KEEP: "corrector-keep", FALLBACK: "corrector-fallback", ADVANCE: "corrector-advance",
                 ROADMAP: "corrector-roadmap", SOUND: "corrector-sound", MEMORY: "corrector-memory",
                 PROBE: "corrector-probe", DEEP: "corrector-deep", MEND: "corrector-mend",
                 BACKTRACK: "corrector-backtrack", FINE: "corrector-fine", SPAN: "corrector-span",
                 SPAN_BRIDGE: "corrector-span-bridge"}
#: the method a variant is judged against where it is not ours-corrector (its docs/corrector.md section)
VARIANT_REFERENCE = {TRIM: PRECISE, SPREAD: PRECISE, RECHECK: SPREAD, FRUGAL: SPREAD, RETRY: SPREAD,
                     THRIFT: RECHECK, POLISH: THRIFT, CENTRE: POLISH, PERSIST: CENTRE,
                     SNAP: PERSIST, EXTEND: SNAP, KEEP: SNAP, FALLBACK: SNAP, ADVANCE: SNAP,
                     ROADMAP: ADVANCE, SOUND: ROADMAP, MEMORY: ROADMAP, PROBE: ROADMAP,
                     DEEP: PROBE, MEND: DEEP, BACKTRACK: MEND, FINE: BACKTRACK, SPAN: FINE, SPAN_BRIDGE: SPAN}
#: the grid that runs a variant on the rest of the point suite (docs/corrector.md, "The whole suite")
VARIANT_SUITE = {SPREAD: "corrector-precise-suite", RECHECK: "corrector-recheck-suite",
                 THRIFT: "corrector-thrift-suite", POLISH: "corrector-polish-suite",
                 CENTRE: "corrector-centre-suite", PERSIST: "corrector-persist-suite",
                 SNAP: "corrector-snap-suite", EXTEND: "corrector-extend-suite",
                 KEEP: "corrector-keep-suite", FALLBACK: "corrector-fallback-suite",
                 ADVANCE: "corrector-advance-suite", ROADMAP: "corrector-roadmap-suite",
                 SOUND: "corrector-sound-suite", MEMORY: "corrector-memory-suite",
                 PROBE: "corrector-probe-suite", DEEP: "corrector-deep-suite", MEND: "corrector-mend-suite",
                 BACKTRACK: "corrector-backtrack-suite", FINE: "corrector-fine-suite", SPAN: "corrector-span-suite",
                 SPAN_BRIDGE: "corrector-span-bridge-suite"}
#: the method a variant's grid runs where the claims name it otherwise
VARIANT_RUNS = {SPREAD: PRECISE, CENTRE: POLISH}
#: variants run at other settings, whose grids run their own oracle, ours, ours-repair and one-shot beside them
#: (their rules read those, never the taxonomy and corrector grids' rows); their held-out part is in their suite grid
SELF_CONTAINED = {CENTRE, PERSIST, SNAP, EXTEND, KEEP, FALLBACK, ADVANCE, ROADMAP, SOUND, MEMORY, PROBE, DEEP, MEND,
                  BACKTRACK, FINE, SPAN, SPAN_BRIDGE}
#: each variant by its short name (README's marker, claims.json's key), in the order claims.md shows them
VARIANTS = {"gated": GATED, "lean": LEAN, "precise": PRECISE, "trim": TRIM, "spread": SPREAD, "recheck": RECHECK,
            "frugal": FRUGAL, "retry": RETRY, "thrift": THRIFT, "polish": POLISH, "centre": CENTRE, "persist": PERSIST,
            "snap": SNAP, "extend": EXTEND, "keep": KEEP, "fallback": FALLBACK, "advance": ADVANCE,
            "roadmap": ROADMAP, "sound": SOUND, "memory": MEMORY,
            "probe": PROBE, "deep": DEEP, "mend": MEND, "backtrack": BACKTRACK,
            "fine": FINE, "span": SPAN, "span-bridge": SPAN_BRIDGE}
REPORTED = "centre"  # the variant README reports first (docs/corrector.md, "Aimed at the centre") unless ...
#: ... or the latest of these adopted (reported())
ADOPTABLE = ("span-bridge", "span", "fine", "backtrack", "mend", "deep", "probe", "memory", "sound", "roadmap",
             "advance", "fallback", "keep", "extend", "snap", "persist")
ORACLE = ("ours", "geometric")
TOLERANCE = 0.05  # within this of the oracle, and flat within this
COST_CAP = 3.0
POINT_SEEDS = GRIDS["corrector"].seeds
HELD_OUT_SEEDS = GRIDS["corrector-held-out"].seeds
MIX_NAMES = dict(zip(HELD_OUT_MIXES, ("A", "B")))


def load(paths, root: Path = ROOT) -> list[dict]:
    rows = []
    for path in paths:
        if (root / path).is_file():
            rows += read_checked_table(root / path)
    return rows


def episodes_of(rows, maze, method, proposer, seeds) -> tuple[int, int, int]:
    """(successes, episodes, runs) of ``method`` with ``proposer`` on ``maze`` pooled over ``seeds``."""
    k = n = runs = 0
    for r in rows:
        if (r["maze"], r["method"], r["proposer"]) == (maze, method, proposer) and r["seed"] in seeds \
                and cmp.is_done(r):
            k += round(float(r["success_rate"]) * int(r["episodes"]))
            n += int(r["episodes"])
            runs += 1
    return k, n, runs


def per_maze(rows, proposer, mazes, seeds, reference=ORACLE, method=METHOD) -> list[dict]:
    """Per maze: the method's and the reference's pooled success and their Newcombe difference."""
    out = []
    for maze in mazes:
        k1, n1, r1 = episodes_of(rows, maze, method, proposer, seeds)
        k2, n2, r2 = episodes_of(rows, maze, *reference, seeds) if reference[1] != "*" else \
            episodes_of(rows, maze, reference[0], proposer, seeds)
        entry = {"maze": maze, "proposer": proposer, "method": method, "reference": "/".join(reference),
                 "runs": r1, "reference_runs": r2, "success": k1 / n1 if n1 else math.nan,
                 "reference_success": k2 / n2 if n2 else math.nan}
        if n1 and n2:
            lo, hi = newcombe_ci(k1, n1, k2, n2)
            entry |= {"difference": k1 / n1 - k2 / n2, "ci_low": lo, "ci_high": hi}
        out.append(entry)
    return out


def zero_runs(rows, method, proposer, mazes, rate: float = 0.0) -> tuple[int, int]:
    """(runs of ``method`` with ``proposer`` on ``mazes`` at success ``rate`` exactly, runs done)."""
    done = [r for r in rows if r["method"] == method and r["proposer"] == proposer and r["maze"] in mazes
            and cmp.is_done(r)]
    return sum(1 for r in done if float(r["success_rate"]) == rate), len(done)


def done_cells(rows, proposer) -> dict:
    """(maze, method, seed) -> the finished row of ``proposer`` (the last one, where a cell has several)."""
    return {(r["maze"], r["method"], r["seed"]): r for r in rows if r["proposer"] == proposer and cmp.is_done(r)}


def costs(rows, proposer, mazes, seeds, first=METHOD, second="ours") -> dict:
    """Mean evaluations and proposer calls of ``first`` over those of ``second`` on the cells where both ran."""
    by = done_cells(rows, proposer)
    pairs = [(by[(m, first, s)], by[(m, second, s)]) for m in mazes for s in seeds
             if (m, first, s) in by and (m, second, s) in by]
    return {"proposer": proposer, "pairs": len(pairs), "evaluations_ratio": cmp.mean_ratio(pairs, "evaluations"),
            "proposer_calls_ratio": cmp.mean_ratio(pairs, "proposer_calls"),
            "sim_steps_ratio": cmp.mean_ratio(pairs, "sim_steps")}


def as_ours(cells: dict, method: str) -> dict:
    """The cells with ``method`` in the place of ours (comparison's claims are written about 'ours')."""
    return {(maze, "ours" if m == method else m, p, s): v for (maze, m, p, s), v in cells.items() if m != "ours"}


def table_name(maze: str) -> str:
    """How a sweep table names a maze given as a path under data/mazes/ (its stem, with any sub-folder)."""
    return maze.removeprefix("data/mazes/").removesuffix(".maze")


def paired_across(cells, failed, proposers, first, second, seeds, mazes) -> dict:
    """``first`` - ``second`` paired over the cells of every proposer in ``proposers`` together, each (maze,
    proposer, seed) one cell (``comparison.paired_difference``)."""
    both = {(f"{maze} {p}", m, "both", s): v for (maze, m, p, s), v in cells.items() if p in proposers}
    both_failed = {(f"{maze} {p}", m, "both", s) for (maze, m, p, s) in failed if p in proposers}
    return cmp.paired_difference(both, both_failed, "both", first, second, seeds,
                                 [f"{maze} {p}" for p in proposers for maze in mazes])


def paired_rows(rows: list[dict], first: str, second: str, cells: list[tuple], proposer: str | None = None) -> dict:
    """``first`` - ``second`` (methods) pooled over the finished ``cells`` of ``rows`` both ran
    (``levers.lever_check``): cells (maze, seed) of ``proposer``'s rows (None: every row), or (maze, proposer, seed)."""
    from ..levers import lever_check

    def key(r):
        return (r["maze"], r["proposer"], int(r["seed"])) if len(cells[0]) == 3 else (r["maze"], int(r["seed"]))

    by = {m: {key(r): r for r in rows if r["method"] == m and proposer in (None, r["proposer"]) and cmp.is_done(r)}
          for m in (first, second)}
    return lever_check(by[first], by[second], cells)


def named(rows: list[dict], method: str) -> list[dict]:
    """A variant's grid rows under the variant's name (``VARIANT_RUNS``: a grid that runs a method by another)."""
    runs = VARIANT_RUNS.get(method, method)
    return [r | {"method": method} if r["method"] == runs else r for r in rows]


def reference_of(method: str) -> str:
    """The method a variant is judged against: ours-corrector unless its section names another."""
    return VARIANT_REFERENCE.get(method, METHOD)


def _below_ours(versus: list[dict], proposer: str) -> list[str]:
    """The suite mazes where the method's Newcombe interval against ours lies below 0, at ``proposer``."""
    return [e["maze"] for e in versus if e["proposer"] == proposer and "ci_high" in e and e["ci_high"] < 0]


def _known(variants: dict) -> None:
    unknown = set(variants) - set(VARIANTS)
    if unknown:
        raise TypeError(f"not a variant: {', '.join(sorted(unknown))} (VARIANTS: {', '.join(VARIANTS)})")
