"""The corrector grids' claims (docs/corrector.md, "The rules"), decided as fixed there.

    specrefine corrector-claims --out data/results/corrector

Reads the shipped tables of the grids ``taxonomy`` (ours, ours-repair and the oracle), ``corrector`` (ours-corrector
and the one-shot), ``corrector-held-out`` (described, no rule) and, where present, ``corrector-levers`` (each lever
alone), the corrector variants' grids and ``ant-corrector-confirm`` (``ant-corrector-spread`` and
``ant-corrector-reaim`` and ``ant-corrector-redraw`` beside it; one of them read instead once its adoption rule holds)
with the
Ant scaling grid's one-shot;
writes claims.md and claims.json (every rule with its estimate, interval and verdict, every cell counted) and
rooms.png (success over rooms per method and preset, point mass). A rule with a cell missing is
marked partial. ``--fill FILE ...`` also rewrites the ``<!-- front corrector NAME -->`` passages of those files
(README.md, docs/corrector.md) from the same studies::

    specrefine corrector-claims --out data/results/corrector --fill README.md docs/corrector.md
"""

from __future__ import annotations

import json
import math
import re
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.errors import SpecrefineError
from ..core.results import newcombe_ci, wilson_ci
from ..core.runfolder import ensure_dir, locked, save_figure, write_atomic
from ..runs.sweep import read_checked_table
from . import ant_fresh
from . import comparison as cmp
from .grids import (
    ADVANCE_CHECK_MAZES,
    ADVANCE_CHECK_MIXES,
    ADVANCE_MAZES,
    ADVANCE_MIXES,
    CHECK_MAZES,
    CHECK_MIXES,
    DEEP_CHECK_MAZES,
    DEEP_CHECK_MIXES,
    DEEP_MAZES,
    DEEP_MIXES,
    EXTEND_MAZES,
    EXTEND_MIXES,
    FALLBACK_MAZES,
    FALLBACK_MIXES,
    FRESH_MAZES,
    FRESH_MIXES,
    GRIDS,
    HELD_OUT_MAZES,
    HELD_OUT_MIXES,
    KEEP_MAZES,
    KEEP_MIXES,
    MEMORY_MAZES,
    MEMORY_MIXES,
    NEW_MAZES,
    NEW_MIXES,
    OTHER_POINT_MAZES,
    PROBE_MAZES,
    PROBE_MIXES,
    ROADMAP_CHECK_MAZES,
    ROADMAP_CHECK_MIXES,
    ROADMAP_MAZES,
    ROADMAP_MIXES,
    ROOT,
    SCALING_MAZES,
    SNAP_MAZES,
    SNAP_MIXES,
    SOUND_MAZES,
    SOUND_MIXES,
)

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
SHOWN_BESIDE = ("ours-corrector-advance",)  # run beside a variant on its new layouts (advance without the budget)
#: a variant whose adoption counts runs below this success instead of runs at 0 (its docs/corrector.md section)
ADOPTION_FLOOR = {SOUND: 0.5}
NON_INFERIORITY = 0.02  # a variant - ours-corrector: the interval's lower end at or above -this (no worse)
#: each variant of the corrector and its grid
VARIANT_GRIDS = {GATED: "corrector-gated", LEAN: "corrector-lean", PRECISE: "corrector-precise",
                 TRIM: "corrector-trim", SPREAD: "corrector-precise-spread", RECHECK: "corrector-recheck",
                 FRUGAL: "corrector-frugal", RETRY: "corrector-retry", THRIFT: "corrector-thrift",
                 POLISH: "corrector-polish", CENTRE: "corrector-centre", PERSIST: "corrector-persist",
                 SNAP: "corrector-snap", EXTEND: "corrector-extend",
                 KEEP: "corrector-keep", FALLBACK: "corrector-fallback", ADVANCE: "corrector-advance",
                 ROADMAP: "corrector-roadmap", SOUND: "corrector-sound", MEMORY: "corrector-memory",
                 PROBE: "corrector-probe", DEEP: "corrector-deep"}
#: the method a variant is judged against where it is not ours-corrector (its docs/corrector.md section)
VARIANT_REFERENCE = {TRIM: PRECISE, SPREAD: PRECISE, RECHECK: SPREAD, FRUGAL: SPREAD, RETRY: SPREAD,
                     THRIFT: RECHECK, POLISH: THRIFT, CENTRE: POLISH, PERSIST: CENTRE,
                     SNAP: PERSIST, EXTEND: SNAP, KEEP: SNAP, FALLBACK: SNAP, ADVANCE: SNAP,
                     ROADMAP: ADVANCE, SOUND: ROADMAP, MEMORY: ROADMAP, PROBE: ROADMAP,
                     DEEP: PROBE}
#: the grid that runs a variant on the rest of the point suite (docs/corrector.md, "The whole suite")
VARIANT_SUITE = {SPREAD: "corrector-precise-suite", RECHECK: "corrector-recheck-suite",
                 THRIFT: "corrector-thrift-suite", POLISH: "corrector-polish-suite",
                 CENTRE: "corrector-centre-suite", PERSIST: "corrector-persist-suite",
                 SNAP: "corrector-snap-suite", EXTEND: "corrector-extend-suite",
                 KEEP: "corrector-keep-suite", FALLBACK: "corrector-fallback-suite",
                 ADVANCE: "corrector-advance-suite", ROADMAP: "corrector-roadmap-suite",
                 SOUND: "corrector-sound-suite", MEMORY: "corrector-memory-suite",
                 PROBE: "corrector-probe-suite", DEEP: "corrector-deep-suite"}
#: the method a variant's grid runs where the claims name it otherwise
VARIANT_RUNS = {SPREAD: PRECISE, CENTRE: POLISH}
#: variants run at other settings, whose grids run their own oracle, ours, ours-repair and one-shot beside them
#: (their rules read those, never the taxonomy and corrector grids' rows); their held-out part is in their suite grid
SELF_CONTAINED = {CENTRE, PERSIST, SNAP, EXTEND, KEEP, FALLBACK, ADVANCE, ROADMAP, SOUND, MEMORY, PROBE, DEEP}
#: each variant by its short name (README's marker, claims.json's key), in the order claims.md shows them
VARIANTS = {"gated": GATED, "lean": LEAN, "precise": PRECISE, "trim": TRIM, "spread": SPREAD, "recheck": RECHECK,
            "frugal": FRUGAL, "retry": RETRY, "thrift": THRIFT, "polish": POLISH, "centre": CENTRE, "persist": PERSIST,
            "snap": SNAP, "extend": EXTEND, "keep": KEEP, "fallback": FALLBACK, "advance": ADVANCE,
            "roadmap": ROADMAP, "sound": SOUND, "memory": MEMORY,
            "probe": PROBE, "deep": DEEP}
REPORTED = "centre"  # the variant README reports first (docs/corrector.md, "Aimed at the centre") unless ...
#: ... or the latest of these adopted (reported())
ADOPTABLE = ("deep", "probe", "memory", "sound", "roadmap", "advance", "fallback", "keep", "extend", "snap", "persist")
MARKER = re.compile(r"(<!-- front corrector ([\w-]+) -->)(.*?)(<!-- /front corrector \2 -->)", re.S)
ORACLE = ("ours", "geometric")
TOLERANCE = 0.05  # within this of the oracle, and flat within this
ANT_FLOOR = 0.85
COST_CAP = 3.0
POINT_SEEDS = GRIDS["corrector"].seeds
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
    end is at least 0, not wholly below); at most ``calls`` times that corrector's mean proposer calls (None: any)."""

    method: str
    follows: str
    section: str
    margin: float | None = NON_INFERIORITY
    calls: float | None = None

    def rule(self) -> str:
        bound = (f"above -{self.margin}" if self.margin is not None else "not wholly below 0")
        return (f"at least {ANT_FLOOR} on every maze, the difference's 95 % interval {bound} (every paired cell)"
                + (f", at most {self.calls}x its proposer calls" if self.calls is not None else ""))


ANT_SPARING, SPARING = "ant-corrector-sparing", "ours-corrector-sparing"
#: each successor by its grid (docs/corrector.md, "A gate for the Ant's corrector")
ANT_SUCCESSORS = {ANT_SPARING: Successor(SPARING, ANT_REDRAW, "A gate for the Ant's corrector", calls=0.75)}
ANT_SEEDS = GRIDS[ANT_GRID].seeds
HELD_OUT_SEEDS = GRIDS["corrector-held-out"].seeds
MIX_NAMES = dict(zip(HELD_OUT_MIXES, ("A", "B")))
ANT_ONESHOT = "data/results/ant/scaling/oneshot_centre.csv"
ANT_ORACLE = "data/results/ant/scaling/ours_centre.csv"
ANT_ERRING = "data/results/ant/scaling/imperfect_centre.csv"


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


def costs(rows, proposer, mazes, seeds, first=METHOD, second="ours") -> dict:
    """Mean evaluations and proposer calls of ``first`` over those of ``second`` on the cells where both ran."""
    by = {(r["maze"], r["method"], r["seed"]): r for r in rows if r["proposer"] == proposer and cmp.is_done(r)}
    pairs = [(by[(m, first, s)], by[(m, second, s)]) for m in mazes for s in seeds
             if (m, first, s) in by and (m, second, s) in by]
    return {"proposer": proposer, "pairs": len(pairs), "evaluations_ratio": cmp.mean_ratio(pairs, "evaluations"),
            "proposer_calls_ratio": cmp.mean_ratio(pairs, "proposer_calls"),
            "sim_steps_ratio": cmp.mean_ratio(pairs, "sim_steps")}


def as_ours(cells: dict, method: str) -> dict:
    """The cells with ``method`` in the place of ours (comparison's claims are written about 'ours')."""
    return {(maze, "ours" if m == method else m, p, s): v for (maze, m, p, s), v in cells.items() if m != "ours"}


def point_study(root: Path = ROOT) -> dict:
    tax, cor = GRIDS["taxonomy"], GRIDS["corrector"]
    rows = load(tax.tables + cor.tables, root)
    if not rows:
        raise SpecrefineError("no corrector or taxonomy table found: run the grids (docs/corrector.md)")
    cells, failed = cmp.table_cells(rows, "point")
    study = {"per_maze": [], "rooms": [], "ratio": [], "zero": [], "costs": [], "versus_ours": [],
             "severe_vs_repair": None}
    for proposer in ("imperfect:mild", "imperfect:moderate"):
        study["per_maze"] += per_maze(rows, proposer, SCALING_MAZES, POINT_SEEDS)
        study["versus_ours"] += per_maze(rows, proposer, SCALING_MAZES + OTHER_POINT_MAZES, POINT_SEEDS,
                                         reference=("ours", "*"))
        for method in (METHOD, "ours", "ours-repair", "vlm-oneshot"):
            study["rooms"].append(cmp.rooms_claim(cells, failed, proposer, method, POINT_SEEDS))
        study["ratio"].append(cmp.ratio_claim(as_ours(cells, METHOD), set(as_ours(dict.fromkeys(failed), METHOD)),
                                              proposer, POINT_SEEDS) | {"method": f"{METHOD} / vlm-oneshot"})
        study["ratio"].append(cmp.ratio_claim(cells, failed, proposer, POINT_SEEDS) | {"method": "ours / vlm-oneshot"})
        study["costs"].append(costs(rows, proposer, SCALING_MAZES + OTHER_POINT_MAZES, POINT_SEEDS))
    for proposer in ("imperfect:mild", "imperfect:moderate", "imperfect:severe"):
        study["zero"].append({"proposer": proposer} | {m: zero_runs(rows, m, proposer, SCALING_MAZES)
                                                        for m in (METHOD, "ours", "ours-repair")})
    study["curves"] = {p: {"/".join(m): [episodes_of(rows, f"u_chain_{n}", m[0], m[1] if m[1] != "*" else p,
                                                     POINT_SEEDS) for n in range(1, 6)]
                           for m in (ORACLE, (METHOD, "*"), ("ours", "*"), ("ours-repair", "*"), ("vlm-oneshot", "*"))}
                       for p in ("imperfect:mild", "imperfect:moderate", "imperfect:severe")}
    study["severe_vs_repair"] = cmp.paired_difference(cells, failed, "imperfect:severe", METHOD, "ours-repair",
                                                      POINT_SEEDS, SCALING_MAZES)
    study["severe"] = per_maze(rows, "imperfect:severe", SCALING_MAZES, POINT_SEEDS)
    study["costs"].append(costs(rows, "imperfect:severe", SCALING_MAZES, POINT_SEEDS))
    return study


def held_out_study(root: Path = ROOT) -> dict | None:
    """Descriptive (no rule was fixed beyond reporting every cell): per held-out maze and error mix, ours-corrector
    beside ours and the oracle, pooled over the seeds; and the cost ratios."""
    rows = load(GRIDS["corrector-held-out"].tables, root)
    if not any(r["method"] == METHOD for r in rows):
        return None
    mazes = tuple(table_name(m) for m in HELD_OUT_MAZES)
    entries = []
    for mix in HELD_OUT_MIXES:
        for e in per_maze(rows, mix, mazes, HELD_OUT_SEEDS, reference=("ours", "*")):
            k, n, _ = episodes_of(rows, e["maze"], *ORACLE, HELD_OUT_SEEDS)
            entries.append(e | {"mix": MIX_NAMES[mix], "oracle": k / n if n else math.nan})
    zeros = {m: sum(zero_runs(rows, m, mix, mazes)[0] for mix in HELD_OUT_MIXES) for m in (METHOD, "ours")}
    return {"per_maze": entries, "zero": zeros, "runs": sum(e["runs"] for e in entries),
            "costs": [costs(rows, mix, mazes, HELD_OUT_SEEDS) | {"proposer": f"mix {MIX_NAMES[mix]}"}
                      for mix in HELD_OUT_MIXES]}


def table_name(maze: str) -> str:
    """How a sweep table names a maze given as a path under data/mazes/ (its stem, with any sub-folder)."""
    return maze.removeprefix("data/mazes/").removesuffix(".maze")


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
                  "successors": successors}


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
    rows = load(GRIDS[grid].tables + GRIDS[s.follows].tables, root)
    paired = _ant_paired_rows(rows, s.method, base)
    cost = costs(rows, "imperfect:moderate", SCALING_MAZES, ANT_SEEDS, s.method, base)
    bounded = bool(paired["cells"]) and (paired["ci"][0] >= -s.margin if s.margin is not None else paired["ci"][1] >= 0)
    parts = {"floor": all(e["episodes"] and e["success"] >= ANT_FLOOR for e in study["per_maze"]),
             "no worse" if s.margin is not None else "not below": bounded}
    if s.calls is not None:
        parts["cheaper"] = cost["proposer_calls_ratio"] <= s.calls
    return {"grid": grid, "method": s.method, "follows": s.follows, "followed_method": base, "rule": s.rule(),
            "section": s.section, "study": study, "per_maze": study["per_maze"], "paired": paired, "parts": parts,
            "cost_vs_followed": cost, "cost_vs_ours": study["costs"], "pooled": _pooled_success(study["per_maze"]),
            "adopted": paired["complete"] and all(parts.values())}


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
    from .levers import lever_check

    by = {m: {(r["maze"], int(r["seed"])): r for r in rows if r["method"] == m and cmp.is_done(r)}
          for m in (first, second)}
    return lever_check(by[first], by[second], [(m, s) for m in SCALING_MAZES for s in ANT_SEEDS])


def levers_study(root: Path = ROOT) -> dict | None:
    """Each lever alone against ours (and ours-repair for the deep repair) and against ours-corrector on the
    corrector-levers grid's cells: pooled success, paired difference (bootstrap over cells), cost."""
    grid = GRIDS["corrector-levers"]
    rows = load(GRIDS["taxonomy"].tables + GRIDS["corrector"].tables + grid.tables, root)
    if not any(r["method"] in LEVERS for r in rows):
        return None
    cells, failed = cmp.table_cells(rows, "point")
    entries = []
    for proposer in grid.proposers:
        for lever in LEVERS:
            references = ("ours",) + (("ours-repair",) if lever == "ours-deeprepair" else ()) + (METHOD,)
            k, n, runs = pooled(rows, grid.mazes, lever, proposer, grid.seeds)
            entries.append({"proposer": proposer, "lever": lever, "runs": runs, "success": k / n if n else math.nan,
                            "versus": {ref: cmp.paired_difference(cells, failed, proposer, lever, ref, grid.seeds,
                                                                  grid.mazes) for ref in references},
                            "same": {ref: same_cells(cells, proposer, lever, ref, grid.mazes, grid.seeds)
                                     for ref in references},
                            "costs": costs(rows, proposer, grid.mazes, grid.seeds, first=lever)})
    return {"mazes": list(grid.mazes), "seeds": list(grid.seeds), "entries": entries,
            "n_expected": len(grid.mazes) * len(grid.seeds)}


def same_cells(cells, proposer, first, second, mazes, seeds) -> int:
    """Cells where both ran with the same success (the lever never acted: its code path is the reference's)."""
    pairs = [(cells.get((m, first, proposer, s)), cells.get((m, second, proposer, s))) for m in mazes for s in seeds]
    return sum(1 for a, b in pairs if a is not None and a == b)


def pooled(rows, mazes, method, proposer, seeds) -> tuple[int, int, int]:
    """(successes, episodes, runs) of ``method`` over ``mazes``, pooled."""
    counts = [episodes_of(rows, maze, method, proposer, seeds) for maze in mazes]
    return tuple(sum(c[i] for c in counts) for i in range(3))


def variant_study(method: str, root: Path = ROOT) -> dict | None:
    """A variant of the corrector (``VARIANT_GRIDS``) by the rules of its docs/corrector.md section: against its
    reference (``VARIANT_REFERENCE``, else ours-corrector; paired, U-chains, mild and moderate), the corrector's own
    rules, its cost beside the reference's, the held-out cells and, where its grid ran severe, severe against
    ours-repair."""
    grid, ref = GRIDS[VARIANT_GRIDS[method]], reference_of(method)
    rows = _base_rows(method, root) + _reference_rows(method, root) + named(load(grid.tables, root), method)
    if not any(r["method"] == method for r in rows):
        return None
    cells, failed = cmp.table_cells(rows, "point")
    presets = ("imperfect:mild", "imperfect:moderate")
    study = {"method": method, "grid": grid.name, "reference": ref, "per_maze": [], "rooms": [], "zero": [],
             "costs": [], "corrector_costs": [], "ratio": [],
             "versus_corrector": paired_across(cells, failed, presets, method, ref, POINT_SEEDS, SCALING_MAZES)}
    for proposer in presets:
        study["per_maze"] += per_maze(rows, proposer, SCALING_MAZES, POINT_SEEDS, method=method)
        study["rooms"].append(cmp.rooms_claim(cells, failed, proposer, method, POINT_SEEDS))
        study["ratio"].append(cmp.ratio_claim(as_ours(cells, method), set(as_ours(dict.fromkeys(failed), method)),
                                              proposer, POINT_SEEDS) | {"method": f"{method} / vlm-oneshot"})
        study["zero"].append({"proposer": proposer, "runs": zero_runs(rows, method, proposer, SCALING_MAZES)})
        study["costs"].append(costs(rows, proposer, SCALING_MAZES, POINT_SEEDS, first=method))
        ran = {(r["maze"], r["seed"]) for r in rows if r["method"] == method and r["proposer"] == proposer
               and cmp.is_done(r)}  # the reference's cost on the cells the variant ran
        study["corrector_costs"].append(costs([r for r in rows if (r["maze"], r["seed"]) in ran], proposer,
                                              SCALING_MAZES, POINT_SEEDS, first=ref))
    if method in VARIANT_SUITE:
        suite = rows + named(load(GRIDS[VARIANT_SUITE[method]].tables, root), method)
        if method in SELF_CONTAINED:  # ours at the same settings: the suite grid of the variant whose grids run it
            suite += [r for r in load(GRIDS[VARIANT_SUITE[CENTRE]].tables, root) if r["method"] == "ours"]
        study["versus_ours"] = [e for p in presets for e in per_maze(suite, p, SCALING_MAZES + OTHER_POINT_MAZES,
                                                                     POINT_SEEDS, reference=("ours", "*"),
                                                                     method=method)]
    study["held_out"] = variant_held_out(method, root)
    study["held_out_costs"] = variant_held_out_costs(method, root)
    if method in SELF_CONTAINED:
        study["every_episode"] = {p: zero_runs(rows, method, p, SCALING_MAZES, rate=1.0) for p in presets}
    if method == CENTRE:
        study["oracle_versus_paper"] = _oracle_versus_paper(rows, root)
        study["fresh"] = fresh_study(root)
    if "imperfect:severe" in grid.proposers:
        study["severe"] = per_maze(rows, "imperfect:severe", SCALING_MAZES, POINT_SEEDS, method=method)
        study["severe_vs_repair"] = cmp.paired_difference(cells, failed, "imperfect:severe", method, "ours-repair",
                                                          POINT_SEEDS, SCALING_MAZES)
        study["severe_vs_corrector"] = cmp.paired_difference(cells, failed, "imperfect:severe", method, ref,
                                                             POINT_SEEDS, SCALING_MAZES)
        study["severe_zero"] = {m: zero_runs(rows, m, "imperfect:severe", SCALING_MAZES) for m in (method, ref)}
        study["costs"].append(costs(rows, "imperfect:severe", SCALING_MAZES, POINT_SEEDS, first=method))
    if method == SNAP:  # on persist's new cells, which informed it, and a last check (described)
        study["informed"] = new_study(SNAP, root, on=PERSIST)
        study["check"] = new_study(SNAP, root, on="check", reference="ours")
    if method in INFORMED_ON:  # on the cells that informed it
        study["informed"] = new_study(method, root, on=INFORMED_ON[method])
    if method in LAST_CHECK:  # a last check after its adoption (described)
        study["check"] = new_study(method, root, on=LAST_CHECK[method])
    if method in NEW_STUDIES:
        study["new"] = new_study(method, root)
        study["adoption"] = adoption(study, cells, failed, root)
    return study


#: a variant run on layouts and mixes no run had used, beside its reference: (grid, mazes, mixes, mix names)
NEW_STUDIES = {PERSIST: ("corrector-persist-new", NEW_MAZES, NEW_MIXES, ("E", "F")),
               SNAP: ("corrector-snap-new", SNAP_MAZES, SNAP_MIXES, ("G", "H")),
               "check": ("corrector-snap-check", CHECK_MAZES, CHECK_MIXES, ("I", "J")),  # a last check, described
               EXTEND: ("corrector-extend-new", EXTEND_MAZES, EXTEND_MIXES, ("K", "L")),
               KEEP: ("corrector-keep-new", KEEP_MAZES, KEEP_MIXES, ("M", "N")),
               FALLBACK: ("corrector-fallback-new", FALLBACK_MAZES, FALLBACK_MIXES, ("O", "P")),
               ADVANCE: ("corrector-advance-new", ADVANCE_MAZES, ADVANCE_MIXES, ("Q", "R")),
               "advance-check": ("corrector-advance-check", ADVANCE_CHECK_MAZES, ADVANCE_CHECK_MIXES, ("S", "T")),
               ROADMAP: ("corrector-roadmap-new", ROADMAP_MAZES, ROADMAP_MIXES, ("U", "V")),
               "roadmap-check": ("corrector-roadmap-check", ROADMAP_CHECK_MAZES, ROADMAP_CHECK_MIXES, ("W", "X")),
               SOUND: ("corrector-sound-new", SOUND_MAZES, SOUND_MIXES, ("Y", "Z")),
               MEMORY: ("corrector-memory-new", MEMORY_MAZES, MEMORY_MIXES, ("AA", "AB")),
               PROBE: ("corrector-probe-new", PROBE_MAZES, PROBE_MIXES, ("AC", "AD")),
               DEEP: ("corrector-deep-new", DEEP_MAZES, DEEP_MIXES, ("AE", "AF")),
               "deep-check": ("corrector-deep-check", DEEP_CHECK_MAZES, DEEP_CHECK_MIXES, ("AG", "AH"))}  # as made
NEW_GRIDS = tuple(grid for grid, *_ in NEW_STUDIES.values())
#: the new-layout study of a last check after a variant's adoption
LAST_CHECK = {ADVANCE: "advance-check", ROADMAP: "roadmap-check", DEEP: "deep-check"}
#: the new-layout study whose cells informed a variant (beside snap's, which names its own)
INFORMED_ON = {EXTEND: "check", KEEP: EXTEND, FALLBACK: KEEP, ADVANCE: FALLBACK, ROADMAP: "advance-check",
               SOUND: "roadmap-check", MEMORY: SOUND, PROBE: MEMORY,
               DEEP: PROBE}
#: a variant's studies on cells beside its new ones (README's markers NAME-PART): those that informed it, a last check
INFORMED_PARTS = {m: ("informed", "check") if m in LAST_CHECK or m == SNAP else ("informed",)
                  for m in (SNAP, *INFORMED_ON)}


def new_study(method: str, root: Path = ROOT, on: str | None = None, reference: str | None = None) -> dict | None:
    """Described (docs/corrector.md, "Corrected until alive", "Snapped out of the wall"): the variant beside its
    reference, polish at centre points, ours and the oracle on layouts and mixes no run had used; runs at 0; the
    variant - its reference paired over the cells (and the reference - polish where polish is not it)."""
    grid, mazes, mixes, names = NEW_STUDIES[on or method]
    rows, ref = _new_rows(grid, root), reference or reference_of(method)
    if on:  # the variant's own cells there come from its grid's part on them
        rows += [r for r in load(GRIDS[VARIANT_GRIDS[method]].tables, root) if r["proposer"] in mixes]
    if not any(r["method"] == method for r in rows):
        return None
    mazes, seeds = tuple(table_name(m) for m in mazes), GRIDS[grid].seeds
    polish = ref not in (CENTRE, "ours") and any(r["method"] == CENTRE for r in rows)  # a grid that ran polish
    others = [("ours", "ours"), ("oracle", ORACLE)] + ([("polish", CENTRE)] if polish else [])
    entries = []
    for mix, name in zip(mixes, names):
        for e in per_maze(rows, mix, mazes, seeds, reference=(ref, "*"), method=method):
            extra = {key: episodes_of(rows, e["maze"], *((m, mix) if isinstance(m, str) else m), seeds)
                     for key, m in others}
            entries.append(e | {"mix": name} | {k: c[0] / c[1] if c[1] else math.nan for k, c in extra.items()})
    cells, failed = cmp.table_cells(rows, "point")
    beside = tuple(sorted({r["method"] for r in rows} & ({*VARIANTS.values(), *SHOWN_BESIDE}) - {method, ref, CENTRE}))
    shown = tuple(dict.fromkeys((method, ref) + ((CENTRE,) if polish else ()) + beside + ("ours",)))
    study = {"grid": grid, "method": method, "reference": ref, "names": list(names), "per_maze": entries,
             "zero": {m: sum(zero_runs(rows, m, mix, mazes)[0] for mix in mixes) for m in shown},
             "runs": sum(e["runs"] for e in entries),
             "paired": paired_across(cells, failed, mixes, method, ref, seeds, mazes)}
    if polish:
        study["reference_paired"] = paired_across(cells, failed, mixes, ref, CENTRE, seeds, mazes)
    return study


def _new_rows(grid: str, root: Path) -> list[dict]:
    """A new-layout grid's rows, polish named as the centre variant it is."""
    return named(load(GRIDS[grid].tables, root), CENTRE)


def adoption(study: dict, cells: dict, failed: set, root: Path = ROOT) -> dict:
    """A variant's adoption rule against its reference (docs/corrector.md, "Corrected until alive" and "Snapped out
    of the wall"): (1) no worse on the U-chains at mild and moderate (paired lower end >= -NON_INFERIORITY) and below
    ours on no suite maze; (2) fewer runs at 0 over the severe U-chain cells and its new cells together, and their
    paired difference >= 0."""
    method, ref = study["method"], study["reference"]
    grid, mazes, mixes, _ = NEW_STUDIES[method]
    new_cells, new_failed = cmp.table_cells(_new_rows(grid, root), "point")
    groups = [(cells, failed, "imperfect:severe", SCALING_MAZES, POINT_SEEDS)]
    groups += [(new_cells, new_failed, mix, tuple(table_name(m) for m in mazes), GRIDS[grid].seeds) for mix in mixes]
    both = {(f"{maze} {p} s{seed}", m, "all", 0): v for c, _, p, names, seeds in groups
            for (maze, m, q, seed), v in c.items() if q == p and maze in names and seed in seeds}
    both_failed = {(f"{maze} {p} s{seed}", m, "all", 0) for _, f, p, names, seeds in groups
                   for (maze, m, q, seed) in f if q == p}
    labels = [f"{maze} {p} s{seed}" for _, _, p, names, seeds in groups for maze in names for seed in seeds]
    paired = cmp.paired_difference(both, both_failed, "all", method, ref, (0,), labels)
    floor = ADOPTION_FLOOR.get(method, 0.0)  # runs at 0, or below the floor (a dead run is one), over the same cells
    zero = {m: sum(1 for (_, who, _, _), v in both.items() if who == m and (v <= 0.0 or v < floor))
            for m in (method, ref)}
    versus, suite = study["versus_corrector"], study.get("versus_ours", [])
    below = [e for p in ("imperfect:mild", "imperfect:moderate") for e in _below_ours(suite, p)]
    first = (not math.isnan(versus["estimate"]) and versus["ci_low"] >= -NON_INFERIORITY and not below)
    second = zero[method] < zero[ref] and not math.isnan(paired["estimate"]) and paired["estimate"] >= 0
    suite_done = bool(suite) and all(e["runs"] == len(POINT_SEEDS) for e in suite)
    complete = versus["complete"] and paired["complete"] and suite_done
    return {"no_worse": first, "fewer_zero": second, "zero": zero, "floor": floor, "paired": paired,
            "below_ours": below, "complete": complete, "adopted": first and second and complete}


FRESH_GRIDS = ("corrector-centre-fresh", "corrector-sampled-fresh")  # docs/corrector.md, "Fresh layouts ..."
FRESH_NAMES = dict(zip(FRESH_MIXES, ("C", "D")))


def fresh_study(root: Path = ROOT) -> dict | None:
    """Described (docs/corrector.md, "Fresh layouts for the centre rule"): polish at centre points beside polish at
    sampled points, ours (centre) and the oracle at both, per fresh layout and mix; runs at 0; the paired difference
    of the two polish runs over the cells both ran (bootstrap over cells)."""
    centre, sampled = (load(GRIDS[name].tables, root) for name in FRESH_GRIDS)
    rows = [r | {"method": CENTRE} if r["method"] == POLISH else r for r in centre]
    rows += [r | {"method": "oracle (sampled)"} if r["method"] == ORACLE[0] else r for r in sampled]
    if not any(r["method"] == CENTRE for r in rows):
        return None
    mazes, seeds = tuple(table_name(m) for m in FRESH_MAZES), GRIDS[FRESH_GRIDS[0]].seeds
    entries = []
    for mix in FRESH_MIXES:
        for e in per_maze(rows, mix, mazes, seeds, reference=(POLISH, "*"), method=CENTRE):
            refs = (("ours", ("ours", mix)), ("oracle", ORACLE), ("oracle_sampled", ("oracle (sampled)", ORACLE[1])))
            extra = {name: episodes_of(rows, e["maze"], *ref, seeds) for name, ref in refs}
            entries.append(e | {"mix": FRESH_NAMES[mix]} | {k: c[0] / c[1] if c[1] else math.nan
                                                              for k, c in extra.items()})
    cells, failed = cmp.table_cells(rows, "point")
    zero = {m: sum(zero_runs(rows, m, mix, mazes)[0] for mix in FRESH_MIXES) for m in (CENTRE, POLISH, "ours")}
    return {"per_maze": entries, "zero": zero, "runs": sum(e["runs"] for e in entries),
            "paired": paired_across(cells, failed, FRESH_MIXES, CENTRE, POLISH, seeds, mazes)}


def fresh_markdown(fresh: dict) -> list[str]:
    lines = ["", "Fresh layouts for the centre rule (described; docs/corrector.md): per generated maze and mix "
             f"(C, D), pooled over seeds; polish at centre - polish at sampled (Newcombe 95 %); {CENTRE} - "
             f"{POLISH} paired over the cells: {_paired_text(fresh['paired'])}. Runs at 0: "
             + ", ".join(f"{m} {z}" for m, z in fresh["zero"].items()) + f" (of {fresh['runs']} each).", "",
             "| mix | maze | runs | polish (centre) | polish (sampled) | difference | ours (centre) | oracle (centre) "
             "| oracle (sampled) |", "|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {e['mix']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | {_num(e['reference_success'])} | "
              f"{_diff(e)} | {_num(e['ours'])} | {_num(e['oracle'])} | {_num(e['oracle_sampled'])} |"
              for e in fresh["per_maze"]]
    return lines


def new_markdown(new: dict, informed: bool = False) -> list[str]:
    method, ref = new["method"], new["reference"]
    polish = " | polish (centre)" if "reference_paired" in new else ""
    what = "The cells that informed it, not held out" if informed else "Layouts and mixes no run had used"
    lines = ["", f"{what} (grid `{new['grid']}`; docs/corrector.md): per generated maze and "
             f"mix ({', '.join(new['names'])}), pooled over seeds; {method} - {ref} (Newcombe 95 %), paired over the "
             f"cells: {_paired_text(new['paired'])}"
             + (f"; {ref} - {CENTRE}: {_paired_text(new['reference_paired'])}" if "reference_paired" in new else "")
             + ". Runs at 0: " + ", ".join(f"{m} {z}" for m, z in new["zero"].items()) + f" (of {new['runs']} each).",
             "", f"| mix | maze | runs | {method} | {ref} | difference{polish} | ours (centre) | oracle (centre) |",
             "|---|---|---|---|---|---|" + "---|" * (2 + bool(polish))]
    lines += [f"| {e['mix']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | {_num(e['reference_success'])} | "
              f"{_diff(e)}" + (f" | {_num(e['polish'])}" if polish else "") + f" | {_num(e['ours'])} | "
              f"{_num(e['oracle'])} |" for e in new["per_maze"]]
    return lines


def _new_text(new: dict) -> str:
    short = lambda m: m.removeprefix(f"{METHOD}-")  # noqa: E731
    mine, ref = short(new["method"]), short(new["reference"])
    return _layouts_text(new, f"{mine} ", f", {ref} ", f"; {mine} - {ref} ")


def _layouts_text(study: dict, first: str, second: str, paired: str) -> str:
    """A new-layout or fresh study in one line: the first method's range per layout and mix, the second's, their
    paired difference and the runs at 0 (``first``, ``second``, ``paired``: the words before each)."""
    done = [e for e in study["per_maze"] if e["runs"]]
    both = [e for e in done if e["reference_runs"]]
    text = (f"{first}{min(e['success'] for e in done):.3f}-{max(e['success'] for e in done):.3f} per layout and mix "
            f"over {study['runs']} runs ({len(done)} of {len(study['per_maze'])} layouts and mixes run)")
    if both:
        text += (f"{second}{min(e['reference_success'] for e in both):.3f}-"
                 f"{max(e['reference_success'] for e in both):.3f}{paired}{_paired_text(study['paired'])}")
    return text + "; runs at 0: " + ", ".join(f"{m} {z}" for m, z in study["zero"].items())


def _adoption_text(study: dict) -> str:
    rows = _adoption_rows(study)
    return (f"(1) no worse on the U-chains, {rows[0]['value']} ({rows[0]['verdict']}); (2) {rows[1]['value']} "
            f"({rows[1]['verdict']}): **{rows[2]['verdict']}**")


def _fresh_text(fresh: dict) -> str:
    return _layouts_text(fresh, "", "; at sampled points ", "; centre - sampled ")


def _oracle_versus_paper(rows: list[dict], root: Path) -> dict:
    """The oracle of a self-contained variant's grid (its settings) against the taxonomy grid's oracle (the paper's
    settings), paired over the U-chain cells (bootstrap over cells), described beside its rules."""
    mine = [r | {"method": "oracle (its settings)"} for r in rows if (r["method"], r["proposer"]) == ORACLE]
    paper = [r | {"method": "oracle (paper)"} for r in load(GRIDS["taxonomy"].tables, root)
             if (r["method"], r["proposer"]) == ORACLE]
    cells, failed = cmp.table_cells(mine + paper, "point")
    return cmp.paired_difference(cells, failed, ORACLE[1], "oracle (its settings)", "oracle (paper)", POINT_SEEDS,
                                 SCALING_MAZES)


def paired_across(cells, failed, proposers, first, second, seeds, mazes) -> dict:
    """``first`` - ``second`` paired over the cells of every proposer in ``proposers`` together, each (maze,
    proposer, seed) one cell (``comparison.paired_difference``)."""
    both = {(f"{maze} {p}", m, "both", s): v for (maze, m, p, s), v in cells.items() if p in proposers}
    both_failed = {(f"{maze} {p}", m, "both", s) for (maze, m, p, s) in failed if p in proposers}
    return cmp.paired_difference(both, both_failed, "both", first, second, seeds,
                                 [f"{maze} {p}" for p in proposers for maze in mazes])


def _base_rows(method: str, root: Path) -> list[dict]:
    """The oracle's, ours's, ours-repair's and the one-shot's rows a variant is judged with: the taxonomy and
    corrector grids', or none for a variant whose grid runs its own (``SELF_CONTAINED``)."""
    return [] if method in SELF_CONTAINED else load(GRIDS["taxonomy"].tables + GRIDS["corrector"].tables, root)


def variant_studies(root: Path = ROOT) -> dict[str, dict | None]:
    """Every variant's study by its short name (README's marker, claims.json's key)."""
    studies = {name: variant_study(method, root) for name, method in VARIANTS.items()}
    snap, persist = studies.get("snap"), studies.get("persist")
    if snap:  # snap is adopted only where persist is, or would be but for its second part ("Snapped out of the wall")
        held = bool(persist) and persist["adoption"]["no_worse"]
        snap["adoption"] |= {"reference_no_worse": held, "adopted": snap["adoption"]["adopted"] and held}
    short = {method: name for name, method in VARIANTS.items()}
    for name in ADOPTABLE[::-1][2:]:  # in the order made, after persist and snap: adopted only where its reference is
        later, reference = studies.get(name), studies.get(short[reference_of(VARIANTS[name])])
        if later:
            held = bool(reference) and reference["adoption"]["adopted"]
            later["adoption"] |= {"reference_adopted": held, "adopted": later["adoption"]["adopted"] and held}
    return studies


def named(rows: list[dict], method: str) -> list[dict]:
    """A variant's grid rows under the variant's name (``VARIANT_RUNS``: a grid that runs a method by another)."""
    runs = VARIANT_RUNS.get(method, method)
    return [r | {"method": method} if r["method"] == runs else r for r in rows]


def reference_of(method: str) -> str:
    """The method a variant is judged against: ours-corrector unless its section names another."""
    return VARIANT_REFERENCE.get(method, METHOD)


def _reference_rows(method: str, root: Path, held_out: bool = False) -> list[dict]:
    """The rows of the variant's reference where that is another variant, under its name (``held_out``: its
    held-out part's only)."""
    ref = reference_of(method)
    if ref == METHOD:
        return []
    rows = named(load(_held_out_tables(ref) if held_out else GRIDS[VARIANT_GRIDS[ref]].tables, root), ref)
    if ref in SELF_CONTAINED and reference_of(ref) in SELF_CONTAINED:  # its oracle, ours, ... are its reference's
        rows += _reference_rows(ref, root, held_out)
    return rows


def _held_out_tables(method: str) -> tuple:
    """The tables of the held-out part(s) of a variant's grids (a self-contained variant's: its suite grid's,
    its own oracle's included)."""
    grid = GRIDS[(VARIANT_SUITE if method in SELF_CONTAINED else VARIANT_GRIDS)[method]]
    return tuple(grid.part_table(i) for i, part in enumerate(grid.parts)
                 if set(part.proposers) <= set(HELD_OUT_MIXES) | {ORACLE[1]} and part.mazes == HELD_OUT_MAZES)


def _held_out_rows(method: str, root: Path) -> list[dict]:
    base = [] if method in SELF_CONTAINED else load(GRIDS["corrector-held-out"].tables, root)
    return (base + _reference_rows(method, root, held_out=True)
            + named(load(_held_out_tables(method), root), method))


def variant_held_out_costs(method: str, root: Path = ROOT) -> list[dict]:
    """Per held-out mix: the variant's and its reference's mean cost over ours's on the same cells."""
    rows = _held_out_rows(method, root)
    mazes = tuple(table_name(m) for m in HELD_OUT_MAZES)
    return [costs(rows, mix, mazes, HELD_OUT_SEEDS, first=m) | {"proposer": f"mix {MIX_NAMES[mix]}", "method": m}
            for mix in HELD_OUT_MIXES for m in (method, reference_of(method))]


def variant_held_out(method: str, root: Path = ROOT) -> list[dict]:
    rows = _held_out_rows(method, root)
    mazes = tuple(table_name(m) for m in HELD_OUT_MAZES)
    out = []
    for mix in HELD_OUT_MIXES:
        for e in per_maze(rows, mix, mazes, HELD_OUT_SEEDS, reference=(reference_of(method), "*"), method=method):
            k, n, _ = episodes_of(rows, e["maze"], "ours", mix, HELD_OUT_SEEDS)
            out.append(e | {"mix": MIX_NAMES[mix], "ours": k / n if n else math.nan})
    return out


def _num(x, fmt="{:.3f}") -> str:
    return "—" if x is None or (isinstance(x, float) and math.isnan(x)) else fmt.format(x)


def _diff(e) -> str:
    if "difference" not in e:
        return "—"
    return f"{e['difference']:+.3f} [{e['ci_low']:+.3f}, {e['ci_high']:+.3f}]"


def verdicts(point: dict, ant: dict | None) -> list[dict]:
    """Each rule of docs/corrector.md with its verdict ("partial" while a cell is missing)."""
    out = []
    for proposer in ("imperfect:mild", "imperfect:moderate"):
        mazes = [e for e in point["per_maze"] if e["proposer"] == proposer]
        complete = all(e["runs"] == len(POINT_SEEDS) for e in mazes)
        within = [e for e in mazes if e["success"] >= e["reference_success"] - TOLERANCE]
        out.append({"rule": f"{proposer}: within {TOLERANCE} of the oracle on every U-chain",
                    "value": f"{len(within)} of {len(mazes)} mazes", "verdict": _verdict(len(within) == len(mazes),
                                                                                        complete)})
        rooms = next(e for e in point["rooms"] if e["proposer"] == proposer and e["method"] == METHOD)
        out.append({"rule": f"{proposer}: flat from 1 to 5 rooms", "value": cmp._interval_text(rooms),
                    "verdict": rooms["verdict"] + ("" if rooms["complete"] else " (partial)")})
        zero = next(z for z in point["zero"] if z["proposer"] == proposer)[METHOD]
        out.append({"rule": f"{proposer}: no run at 0", "value": f"{zero[0]} of {zero[1]} runs at 0",
                    "verdict": _verdict(zero[0] == 0, complete)})
        out.append(_suite_rule(point["versus_ours"], proposer, f"{proposer}"))
        ratio = next(e for e in point["ratio"] if e["proposer"] == proposer and e["method"].startswith(METHOD))
        out.append({"rule": f"{proposer}: {METHOD} >= 2x the one-shot on multi-room (point)",
                    "value": cmp._interval_text(ratio), "verdict": ratio["verdict"]
                    + ("" if ratio["complete"] else " (partial)")})
    severe = point["severe_vs_repair"]
    out.append({"rule": "imperfect:severe: no worse than ours-repair (paired, U-chains)",
                "value": _paired_text(severe), "verdict": ("no worse" if severe["verdict"] != "lower"
                                                                  else "worse") + ("" if severe["complete"]
                                                                                   else " (partial)")})
    for c in point["costs"]:
        out.append({"rule": f"{c['proposer']}: cost at most {COST_CAP}x ours (evaluations, proposer calls)",
                    "value": f"{_num(c['evaluations_ratio'], '{:.2f}x')}, {_num(c['proposer_calls_ratio'], '{:.2f}x')}"
                             f" over {c['pairs']} pairs",
                    "verdict": _cost_verdict(c)})
    if ant:
        out += _ant_verdicts(ant)
    return out


def _ant_verdicts(ant: dict) -> list[dict]:
    """The Ant's floor and ratio rules on the adopted grid, and each candidate corrector's adoption rule."""
    floor = f"Ant ({ant['method']}), imperfect:moderate: at least {ANT_FLOOR} on every maze"
    if not any(e["runs"] for e in ant["per_maze"]):
        out = [{"rule": floor, "value": f"{ant['grid']}: no cell yet", "verdict": "not run yet"}]
    else:
        complete = all(e["runs"] == len(ANT_SEEDS) for e in ant["per_maze"])
        ran = [e for e in ant["per_maze"] if e["runs"]]
        low = [e["maze"] for e in ran if e["success"] < ANT_FLOOR]
        ratio = ant["ratio"][0]
        scope = "" if complete else f" run so far (of {len(ant['per_maze'])})"
        out = [{"rule": floor, "value": f"below on {len(low)} of the {len(ran)} mazes{scope}"
                + (f": {', '.join(low)}" if low else ""),
                "verdict": _verdict(not low, complete)},
               {"rule": f"Ant: {ant['method']} >= 2x the one-shot on multi-room", "value": cmp._interval_text(ratio),
                "verdict": ratio["verdict"] + ("" if ratio["complete"] else " (partial)")}]
    return out + [_candidate_verdict(c, ant["method"]) for c in ant["candidates"]] + \
        [_successor_verdict(s, ant["method"]) for s in ant["successors"]]


def _successor_verdict(s: dict, read: str) -> dict:
    """A successor's rule: "adopted" when the Ant's rules read it, the parts missed where its rule does not hold."""
    e, calls = s["paired"], s["cost_vs_followed"]["proposer_calls_ratio"]
    if not e["complete"]:
        verdict = f"undecided ({e['cells']} of {e['expected']} cells)"
    elif not s["adopted"]:
        verdict = f"not adopted ({', '.join(part for part, held in s['parts'].items() if not held)} missed)"
    else:
        verdict = "adopted" if s["method"] == read else f"holds; {read} read"
    value = _ant_paired_text(e) + ("" if math.isnan(calls) else f"; proposer calls {calls:.2f}x")
    return {"rule": f"Ant: {s['method']} in place of {s['followed_method']}: {s['rule']}", "value": value,
            "verdict": verdict}


def _candidate_verdict(candidate: dict, read: str) -> dict:
    """A candidate's adoption rule: "adopted" when the Ant's rules read it, "holds" when its rule holds but another
    candidate with a higher pooled success is read."""
    e = candidate["paired"]
    if not e["complete"]:
        verdict = f"undecided ({e['cells']} of {e['expected']} cells)"
    else:
        verdict = "not adopted" if not candidate["adopted"] else "adopted" if candidate["method"] == read else \
            f"holds; {read} read (higher pooled success)"
    return {"rule": f"Ant: {candidate['method']} - {ANT_METHOD} above 0 (95 % interval, every paired cell; adopted "
                    "as the Ant's corrector)", "value": _ant_paired_text(e), "verdict": verdict}


def _paired_text(e: dict) -> str:
    if math.isnan(e["estimate"]):
        return "—"
    return f"difference {e['estimate']:+.3f} [{e['ci_low']:+.3f}, {e['ci_high']:+.3f}] over {e['n_cells']} cells"


def _cost_verdict(c: dict) -> str:
    worst = max(c["evaluations_ratio"], c["proposer_calls_ratio"])
    if math.isnan(worst):
        return "undecided (no pairs)"
    return "holds" if worst <= COST_CAP else "does not hold"


def _verdict(ok: bool, complete: bool) -> str:
    return ("holds" if ok else "does not hold") + ("" if complete else " (partial)")


def markdown(point: dict, ant: dict | None, held_out: dict | None = None, levers: dict | None = None,
             **variants: dict | None) -> str:
    """claims.md; ``variants``: the studies by their ``VARIANTS`` name (absent or None: not run)."""
    _known(variants)
    lines = [f"{cmp.OFFLINE_NOTE}. Point mass unless named; pooled over seeds {list(POINT_SEEDS)} (Ant: "
             f"{list(ANT_SEEDS)}), 200 fresh episodes per run; rules fixed in docs/corrector.md before the grids ran.",
             "", "| rule | estimate | verdict |", "|---|---|---|"]
    lines += [f"| {v['rule']} | {v['value']} | {v['verdict']} |" for v in verdicts(point, ant)]
    lines += ["", "Per U-chain (point): ours-corrector vs the oracle (ours x geometric), pooled over seeds; Newcombe "
              "95 % interval of the difference.", "",
              "| proposer | maze | runs | ours-corrector | oracle | difference |", "|---|---|---|---|---|---|"]
    for e in point["per_maze"] + point["severe"]:
        lines.append(f"| {e['proposer']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | "
                     f"{_num(e['reference_success'])} | {_diff(e)} |")
    lines += ["", "Every suite maze (point): ours-corrector - ours, pooled over seeds (Newcombe 95 %).", "",
              "| proposer | maze | runs (ours) | ours-corrector | ours | difference |", "|---|---|---|---|---|---|"]
    for e in point["versus_ours"]:
        lines.append(f"| {e['proposer']} | {e['maze']} | {e['runs']} ({e['reference_runs']}) | {_num(e['success'])} | "
                     f"{_num(e['reference_success'])} | {_diff(e)} |")
    lines += ["", "Change from 1 to 5 rooms (least-squares slope x 4 on u_chain_1..5; 95 % bootstrap over seeds), and "
              "runs at 0 on the U-chains.", "", "| proposer | method | change 1→5 rooms | verdict |",
              "|---|---|---|---|"]
    for e in point["rooms"]:
        lines.append(f"| {e['proposer']} | {e['method']} | {cmp._interval_text(e)} | {e['verdict']} |")
    lines += ["", "| proposer | " + " | ".join(f"{m} at 0" for m in (METHOD, "ours", "ours-repair")) + " |",
              "|---|---|---|---|"]
    for z in point["zero"]:
        lines.append(f"| {z['proposer']} | " + " | ".join(f"{z[m][0]}/{z[m][1]}" for m in
                                                          (METHOD, "ours", "ours-repair")) + " |")
    lines += ["", "| proposer | ratio | estimate [95 % CI] | verdict |", "|---|---|---|---|"]
    for e in point["ratio"]:
        lines.append(f"| {e['proposer']} | {e['method']} | {cmp._interval_text(e)} | {e['verdict']} |")
    lines += ["", "Cost: mean of ours-corrector over mean of ours on the same cells.", "",
              "| proposer | pairs | evaluations | proposer calls | simulator steps |", "|---|---|---|---|---|"]
    for c in point["costs"] + ([ant["costs"] | {"proposer": "Ant " + ant["costs"]["proposer"]}] if ant else []):
        lines.append(f"| {c['proposer']} | {c['pairs']} | {_num(c['evaluations_ratio'], '{:.2f}x')} | "
                     f"{_num(c['proposer_calls_ratio'], '{:.2f}x')} | {_num(c['sim_steps_ratio'], '{:.2f}x')} |")
    if held_out:
        lines += ["", "Held out (descriptive; the grid was fixed before it ran, no rule beyond reporting every cell): "
                  "layouts outside the suite and two error mixes no method was developed on (`HELD_OUT_MIXES` in "
                  "specrefine/experiments/grids.py, A and B), pooled over seeds "
                  f"{list(HELD_OUT_SEEDS)}; Newcombe 95 % interval of ours-corrector - ours. Runs at 0: "
                  + ", ".join(f"{m} {z}" for m, z in held_out["zero"].items()) + f" (of {held_out['runs']} each).",
                  "", "| mix | maze | runs | ours-corrector | ours | ours-corrector - ours | oracle |",
                  "|---|---|---|---|---|---|---|"]
        for e in held_out["per_maze"]:
            lines.append(f"| {e['mix']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | "
                         f"{_num(e['reference_success'])} | {_diff(e)} | {_num(e['oracle'])} |")
        lines += ["", "| held-out mix | pairs | evaluations | proposer calls | simulator steps |",
                  "|---|---|---|---|---|"]
        for c in held_out["costs"]:
            lines.append(f"| {c['proposer']} | {c['pairs']} | {_num(c['evaluations_ratio'], '{:.2f}x')} | "
                         f"{_num(c['proposer_calls_ratio'], '{:.2f}x')} | {_num(c['sim_steps_ratio'], '{:.2f}x')} |")
    if ant:
        lines += ant_markdown(ant)
    if levers:
        lines += levers_markdown(levers)
    for name in VARIANTS:
        if variants.get(name):
            lines += variant_markdown(variants[name])
    return "\n".join(lines) + "\n"


def ant_markdown(ant: dict) -> list[str]:
    """The Ant's cells per maze in ANT_GRID, each of ANT_CANDIDATES and ANT_BEFORE, their paired differences and
    ratios."""
    candidates = ant["candidates"]
    lines = ["", f"The Ant (imperfect:moderate, stage 5, centre goal points), pooled per maze (Wilson 95 %): "
             f"`{ANT_GRID}` ({ANT_METHOD}); " + "; ".join(f"`{c['grid']}` ({c['method']}, the Ant's corrector if "
                                                          "its rule holds)" for c in candidates)
             + " (docs/corrector.md, 'Aimed clear of the walls: the Ant' and 'A second draw for the Ant'); "
             f"`{ANT_BEFORE}`, ours-corrector on the same cells (stopped at its 10; 'The Ant with a confirmed pick'), "
             f"described. The rules read `{ant['grid']}`.", "",
             f"| maze | {ANT_METHOD}: runs | success [95 % CI] | "
             + "".join(f"{c['method']}: runs | success [95 % CI] | " for c in candidates)
             + f"{ANT_BEFORE}: runs | success |", "|---|---|---|" + "---|---|" * len(candidates) + "---|---|"]
    for i, (e, old) in enumerate(zip(ant["confirm"], ant["before"])):
        new = "".join(f"{c['per_maze'][i]['runs']} | {_rate_ci(c['per_maze'][i])} | " for c in candidates)
        lines.append(f"| {e['maze']} | {e['runs']} | {_rate_ci(e)} | {new}{old['runs']} | {_num(old['success'])} |")
    lines += [""] + [f"{c['method']} - {ANT_METHOD} on the cells both ran: {_ant_paired_text(c['paired'])}."
                     for c in candidates] + [
              f"{ANT_METHOD} - ours-corrector on the cells both ran: {_ant_paired_text(ant['paired'])}.",
              "", "Cost of each candidate: mean proposer calls and evaluations over those of "
              f"{ANT_METHOD} and of ours on the cells both ran.", "",
              "| method | pairs with confirm | calls | evaluations | pairs with ours | calls | evaluations |",
              "|---|---|---|---|---|---|---|"] + [
              f"| {c['method']} | {_cost_cells(c['cost_vs_confirm'])} | {_cost_cells(c['cost_vs_ours'])} |"
              for c in candidates] + [
              "", "| ratio | estimate [95 % CI] | verdict |", "|---|---|---|"]
    lines += [f"| {e['method']} | {cmp._interval_text(e)} | {e['verdict']} |" for e in ant["ratio"]]
    return lines + [line for s in ant["successors"] for line in successor_markdown(s)]


def successor_markdown(s: dict) -> list[str]:
    """A successor's cells per maze, its difference from the corrector it follows and its cost."""
    return ["", f"`{s['grid']}` ({s['method']}, in place of {s['followed_method']} if its rule holds; "
            f"docs/corrector.md, '{s['section']}'), pooled per maze (Wilson 95 %):", "",
            "| maze | runs | success [95 % CI] |", "|---|---|---|"] + [
            f"| {e['maze']} | {e['runs']} | {_rate_ci(e)} |" for e in s["per_maze"]] + [
            "", f"{s['method']} - {s['followed_method']} on the cells both ran: "
            f"{_ant_paired_text(s['paired'])}. Its mean cost over {s['followed_method']}'s: "
            f"{_cost_text(s['cost_vs_followed'])}; over ours's: {_cost_text(s['cost_vs_ours'])}."]


def _cost_cells(c: dict) -> str:
    """A cost's pairs, proposer calls and evaluations ratios as three table cells."""
    return " | ".join([str(c["pairs"])] + ["—" if math.isnan(c[key]) else f"{c[key]:.2f}x"
                                           for key in ("proposer_calls_ratio", "evaluations_ratio")])


def _rate_ci(e: dict) -> str:
    return _num(e["success"]) + (f" [{e['ci_low']:.3f}, {e['ci_high']:.3f}]" if "ci_low" in e else "")


def _helps(entry: dict) -> str:
    """The lever-alone rule's word for a paired difference against the method without it."""
    word = {"higher": "helps", "lower": "hurts"}.get(entry["verdict"], "undecided")
    return word + ("" if entry["complete"] else f" (partial: {entry['n_cells']} of {entry['n_expected']} cells)")


def _sided(entry: dict) -> str:
    return entry["verdict"] + ("" if entry["complete"] else f" (partial: {entry['n_cells']} of "
                                                             f"{entry['n_expected']} cells)")


def levers_markdown(lv: dict) -> list[str]:
    lines = ["", f"Each lever alone (grid `corrector-levers`: {', '.join(lv['mazes'])}, seeds {lv['seeds']}): pooled "
             "success, and the paired difference lever - reference over the same cells (95 % bootstrap over cells); "
             "against the method without the lever: helps above 0, hurts below, else undecided.", "",
             "| proposer | lever | runs | success | - ours | - ours-repair | - ours-corrector | proposer calls / ours "
             "| cells with the same success as ours / ours-corrector |",
             "|---|---|---|---|---|---|---|---|---|"]
    for e in lv["entries"]:
        v = e["versus"]
        repair = f"{_signed(v['ours-repair'])} {_helps(v['ours-repair'])}" if "ours-repair" in v else "—"
        lines.append(f"| {e['proposer']} | {e['lever']} | {e['runs']} | {_num(e['success'])} | "
                     f"{_signed(v['ours'])} {_helps(v['ours'])} | {repair} | {_signed(v[METHOD])} {_sided(v[METHOD])}"
                     f" | {_num(e['costs']['proposer_calls_ratio'], '{:.2f}x')} | {e['same']['ours']} / "
                     f"{e['same'][METHOD]} |")
    return lines


def versus_corrector(vs: dict) -> tuple[str, str]:
    """(rule, verdict) of a variant against its reference, as its section of docs/corrector.md fixed it: the gate
    is to be no worse (lower end >= -NON_INFERIORITY); the later variants help (lower end > 0), are no worse, or are
    worse."""
    v, method = vs["versus_corrector"], vs["method"]
    scope = f"{method} - {vs['reference']} (paired, U-chains, mild and moderate)"
    known = not math.isnan(v["estimate"])
    no_worse = known and v["ci_low"] >= -NON_INFERIORITY
    if method == GATED:
        return f"{scope}: lower end >= -{NON_INFERIORITY}", _verdict(no_worse, v["complete"])
    word = "helps" if known and v["ci_low"] > 0 else "no worse" if no_worse else "worse" if known else "undecided"
    return (f"{scope}: helps if the lower end > 0, no worse if >= -{NON_INFERIORITY}",
            word + ("" if v["complete"] else " (partial)"))


def _below_ours(versus: list[dict], proposer: str) -> list[str]:
    """The suite mazes where the method's Newcombe interval against ours lies below 0, at ``proposer``."""
    return [e["maze"] for e in versus if e["proposer"] == proposer and "ci_high" in e and e["ci_high"] < 0]


def _mazes_run(versus: list[dict], proposer: str) -> str:
    """How many suite mazes the method has runs on at ``proposer``: 'N' when all of them, else 'N run (of M)'."""
    mine = [e for e in versus if e["proposer"] == proposer]
    ran = sum(1 for e in mine if e["runs"])
    return f"{ran}" if ran == len(mine) else f"{ran} run (of {len(mine)})"


def _suite_rule(versus: list[dict], proposer: str, name: str) -> dict:
    """The issue's rule 'not below ours on any suite maze' at ``proposer``, its row named ``name``."""
    mine, below = [e for e in versus if e["proposer"] == proposer], _below_ours(versus, proposer)
    return {"rule": f"{name}: not below ours on any suite maze (Newcombe)",
            "value": f"below on {len(below)} of {_mazes_run(versus, proposer)}" + (f" ({', '.join(below)})" if below
                                                                                   else ""),
            "verdict": _verdict(not below, all(e["runs"] == len(POINT_SEEDS) for e in mine))}


def variant_verdicts(vs: dict) -> list[dict]:
    """The rules of the variant's section of docs/corrector.md."""
    method, out = vs["method"], []
    for c in vs["costs"]:
        ratios = f"{_num(c['proposer_calls_ratio'], '{:.2f}x')}, {_num(c['evaluations_ratio'], '{:.2f}x')}"
        out.append({"rule": f"{method}, {c['proposer']}: cost at most {COST_CAP}x ours (proposer calls, evaluations)",
                    "value": f"{ratios} over {c['pairs']} pairs", "verdict": _cost_verdict(c)})
    rule, verdict = versus_corrector(vs)
    out.append({"rule": rule, "value": _paired_text(vs["versus_corrector"]), "verdict": verdict})
    for proposer in ("imperfect:mild", "imperfect:moderate"):
        mazes = [e for e in vs["per_maze"] if e["proposer"] == proposer]
        within = [e for e in mazes if e["runs"] and e["success"] >= e["reference_success"] - TOLERANCE]
        complete = all(e["runs"] == len(POINT_SEEDS) and e["reference_runs"] for e in mazes)
        out.append({"rule": f"{method}, {proposer}: within {TOLERANCE} of the oracle on every U-chain",
                    "value": f"{len(within)} of {len(mazes)} mazes", "verdict": _verdict(len(within) == len(mazes),
                                                                                        complete)})
        rooms = next(e for e in vs["rooms"] if e["proposer"] == proposer)
        out.append({"rule": f"{method}, {proposer}: flat from 1 to 5 rooms", "value": cmp._interval_text(rooms),
                    "verdict": rooms["verdict"] + ("" if rooms["complete"] else " (partial)")})
        zero = next(z for z in vs["zero"] if z["proposer"] == proposer)["runs"]
        out.append({"rule": f"{method}, {proposer}: no run at 0", "value": f"{zero[0]} of {zero[1]} runs at 0",
                    "verdict": _verdict(zero[0] == 0, complete)})
        if vs.get("versus_ours"):
            out.append(_suite_rule(vs["versus_ours"], proposer, f"{method}, {proposer}"))
        ratio = next((e for e in vs.get("ratio", []) if e["proposer"] == proposer), None)
        if ratio is not None:
            out.append({"rule": f"{method}, {proposer}: >= 2x the one-shot on multi-room (point)",
                        "value": cmp._interval_text(ratio),
                        "verdict": ratio["verdict"] + ("" if ratio["complete"] else " (partial)")})
    if "severe_vs_repair" in vs:
        severe = vs["severe_vs_repair"]
        verdict = "not run" if math.isnan(severe["estimate"]) else \
            ("no worse" if severe["verdict"] != "lower" else "worse") + ("" if severe["complete"] else " (partial)")
        out.append({"rule": f"{method}, imperfect:severe: no worse than ours-repair (paired, U-chains)",
                    "value": _paired_text(severe), "verdict": verdict})
    if "adoption" in vs:
        out += _adoption_rows(vs)
    return out


def _adoption_rows(vs: dict) -> list[dict]:
    """The two parts of persist's adoption rule (docs/corrector.md, "Corrected until alive") and its outcome."""
    a, method, ref = vs["adoption"], vs["method"], vs["reference"]
    pending = "" if a["complete"] else " (partial)"
    runs = f"runs below {a['floor']:g}" if a.get("floor") else "runs at 0"
    below = f"; below ours on {', '.join(a['below_ours'])}" if a["below_ours"] else "; below ours on no suite maze"
    return [{"rule": f"{method}, adoption 1: no worse than {ref} (U-chains, mild and moderate) and below ours on no "
                     "suite maze", "value": _paired_text(vs["versus_corrector"]) + below,
             "verdict": ("holds" if a["no_worse"] else "does not hold") + pending},
            {"rule": f"{method}, adoption 2: fewer {runs} than {ref} over the severe and new cells, paired "
                     "difference >= 0", "value": f"{runs}: {a['zero'][method]} against {a['zero'][ref]}; "
                                                 f"{_paired_text(a['paired'])}",
             "verdict": ("holds" if a["fewer_zero"] else "does not hold") + pending},
            {"rule": f"{method}: adopted (README's rules table reads it)", "value": "both parts hold"
             if a["no_worse"] and a["fewer_zero"] else "not both parts",
             "verdict": ("adopted" if a["adopted"] else "not adopted") + pending}]


def variant_markdown(vs: dict) -> list[str]:
    method, grid, ref = vs["method"], vs["grid"], vs["reference"]
    short = method.removeprefix(f"{METHOD}-")
    lines = ["", f"`{method}` (grid `{grid}`; its rules fixed before it ran, docs/corrector.md):", "",
             "| rule | estimate | verdict |", "|---|---|---|"]
    lines += [f"| {v['rule']} | {v['value']} | {v['verdict']} |" for v in variant_verdicts(vs)]
    lines += ["", f"Cost beside {ref}'s on the same cells (mean over the mean of ours):", "",
              "| proposer | method | pairs | evaluations | proposer calls | simulator steps |",
              "|---|---|---|---|---|---|"]
    for mine, full in zip(vs["costs"], vs["corrector_costs"]):
        for name, c in ((method, mine), (ref, full)):
            lines.append(f"| {c['proposer']} | {name} | {c['pairs']} | {_num(c['evaluations_ratio'], '{:.2f}x')} | "
                         f"{_num(c['proposer_calls_ratio'], '{:.2f}x')} | {_num(c['sim_steps_ratio'], '{:.2f}x')} |")
    lines += ["", f"Per U-chain: {method} vs the oracle, pooled over seeds (Newcombe 95 %).", "",
              f"| proposer | maze | runs | {short} | oracle | difference |", "|---|---|---|---|---|---|"]
    lines += [f"| {e['proposer']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | "
              f"{_num(e['reference_success'])} | {_diff(e)} |" for e in vs["per_maze"] + vs.get("severe", [])]
    if vs.get("versus_ours"):
        whose = "its grids' code and settings" if method in SELF_CONTAINED else \
            "its own grids' code, before the spread start states"
        lines += ["", f"Every suite maze: {method} - ours, pooled over seeds (Newcombe 95 %; ours at {whose}).", "",
                  f"| proposer | maze | runs (ours) | {short} | ours | difference |", "|---|---|---|---|---|---|"]
        lines += [f"| {e['proposer']} | {e['maze']} | {e['runs']} ({e['reference_runs']}) | {_num(e['success'])} | "
                  f"{_num(e['reference_success'])} | {_diff(e)} |" for e in vs["versus_ours"]]
    if vs.get("fresh"):
        lines += fresh_markdown(vs["fresh"])
    if vs.get("new"):
        lines += new_markdown(vs["new"])
    if vs.get("informed"):
        lines += new_markdown(vs["informed"], informed=True)
    if vs.get("check"):
        lines += new_markdown(vs["check"])
    if "oracle_versus_paper" in vs:
        lines += ["", "Described beside its rules: the oracle (ours, geometric) as this grid runs it, against the "
                  f"oracle at the paper's settings (grid taxonomy) {_paired_text(vs['oracle_versus_paper'])} "
                  "(paired, U-chains, 95 % bootstrap)."]
    if "severe_vs_corrector" in vs:
        lines += ["", f"Severe (described): {method} - {ref} {_paired_text(vs['severe_vs_corrector'])}; - "
                  f"ours-repair {_paired_text(vs['severe_vs_repair'])} (paired, U-chains, 95 % bootstrap)."]
    if any(e["runs"] for e in vs["held_out"]):
        lines += ["", f"Held out (descriptive): {method} - {ref} per layout and mix (Newcombe 95 %), ours beside.",
                  "", f"| mix | maze | runs | {short} | {ref} | difference | ours |",
                  "|---|---|---|---|---|---|---|"]
        lines += [f"| {e['mix']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | {_num(e['reference_success'])}"
                  f" | {_diff(e)} | {_num(e['ours'])} |" for e in vs["held_out"]]
        lines += ["", "| held-out mix | method | pairs | evaluations | proposer calls | simulator steps |",
                  "|---|---|---|---|---|---|"]
        lines += [f"| {c['proposer']} | {c['method']} | {c['pairs']} | {_num(c['evaluations_ratio'], '{:.2f}x')} | "
                  f"{_num(c['proposer_calls_ratio'], '{:.2f}x')} | {_num(c['sim_steps_ratio'], '{:.2f}x')} |"
                  for c in vs["held_out_costs"]]
    return lines


def add_arguments(p) -> None:
    from ..core.argtypes import out_path

    p.description = __doc__.split("\n\n")[0]
    p.add_argument("--out", type=out_path, default=Path("data/results/corrector"),
                   help="folder for claims.md and claims.json (default: data/results/corrector)")
    p.add_argument("--fill", type=Path, nargs="+", default=[], metavar="FILE",
                   help="rewrite the '<!-- front corrector NAME -->' passages of these files (README.md, "
                        "docs/corrector.md) from the same studies")


def run(args, p) -> int:
    for path in args.fill:  # before any work: a file to fill is a regular file that exists
        if not path.is_file() or path.is_symlink():
            print(f"{p.prog}: error: --fill {path}: not a regular file", file=sys.stderr)
            return 2
    point, ant, held_out = point_study(), ant_study(), held_out_study()
    levers = levers_study()
    variants = variant_studies()
    fresh = ant_fresh_study()
    record = {"point": point, "held_out": held_out, "ant": ant, "levers": levers, "ant_fresh": fresh, **variants,
              "rules": verdicts(point, ant) + [v for vs in variants.values() if vs for v in variant_verdicts(vs)],
              "front": front(point, held_out, levers=levers, ant=ant, fresh=fresh, **variants)}
    with locked(ensure_dir(args.out)):
        fresh_lines = "\n".join(ant_fresh.markdown(fresh)) + "\n" if fresh else ""
        write_atomic(args.out / "claims.md", markdown(point, ant, held_out, levers, **variants) + fresh_lines)
        write_atomic(args.out / "claims.json", json.dumps(record, indent=1, default=float) + "\n")
        save_figure(rooms_figure(point), args.out / "rooms.png", dpi=110)
    for path in args.fill:
        fill(path, record["front"])
    print(f"-> {args.out}/claims.md")
    return 0


def fill(path: Path, texts: dict[str, str]) -> None:
    """Rewrite every ``<!-- front corrector NAME -->`` passage of ``path`` with ``texts[NAME]`` (whole file, atomic;
    a marker with no text is an error, and nothing is written). A text of several lines keeps the indentation of its
    marker's line, so that a table stays inside its list item."""
    source = path.read_text()
    unknown = sorted({m.group(2) for m in MARKER.finditer(source)} - set(texts))
    if unknown:
        raise SpecrefineError(f"{path}: no text for the marker(s) {', '.join(unknown)}")

    def text(m: re.Match) -> str:
        line = source[source.rfind("\n", 0, m.start()) + 1:m.start()]
        indent = line if not line.strip() else ""
        body = re.sub(r"\n[ \t]+(?=\n)", "\n", texts[m.group(2)].replace("\n", "\n" + indent))
        return m.group(1) + body + m.group(4)

    with locked(path.parent):
        write_atomic(path, MARKER.sub(text, source))


def rules_table(variant: dict | None, point: dict, ant: dict | None) -> str:
    """Issue 39's rules for the reported variant, the held-out cells it is described on, and the Ant's rules, as one
    markdown table (README's front page)."""
    if not variant:
        return "not run yet"
    method = variant["method"]
    rows = [dict(v, rule=v["rule"].removeprefix(f"{method}, ")) for v in variant_verdicts(variant)]
    order = [v for v in rows if "cost at most" not in v["rule"] and not v["rule"].startswith(method)]
    order += [v for v in rows if "cost at most" in v["rule"]] + [v for v in rows if v["rule"].startswith(method)]
    order += [row for mix in MIX_NAMES.values() if (row := _held_out_row(variant, mix))]
    order += [v for v in verdicts(point, ant) if v["rule"].startswith("Ant")]
    table = [f"| rule ({method} unless named) | estimate [95 % CI] | verdict |", "|---|---|---|"]
    table += [f"| {v['rule']} | {v['value']} | {v['verdict']} |" for v in order]
    return "\n" + "\n".join(table) + "\n\n"  # the markers on lines of their own, around the table


def _held_out_row(variant: dict, mix: str) -> dict | None:
    """The variant's held-out cells of one error mix as a described row: success per layout, cost over ours."""
    method = variant["method"]
    held = [e for e in variant["held_out"] if e["runs"] and e["mix"] == mix]
    cost = next((c for c in variant.get("held_out_costs", []) if c["method"] == method
                 and c["proposer"] == f"mix {mix}" and c["pairs"]), None)
    if not (held and cost):
        return None
    return {"rule": f"held out, mix {mix} ({len(held)} layouts, seeds {list(HELD_OUT_SEEDS)}): success per layout; "
                    "proposer calls, evaluations over ours",
            "value": f"{min(e['success'] for e in held):.3f}-{max(e['success'] for e in held):.3f}; "
                     f"{_num(cost['proposer_calls_ratio'], '{:.2f}x')}, {_num(cost['evaluations_ratio'], '{:.2f}x')} "
                     f"over {cost['pairs']} pairs",
            "verdict": "described" + (f" (over {COST_CAP}x)" if _cost_verdict(cost) != "holds" else "")}


def progress(name: str, root: Path = ROOT) -> tuple[int, int]:
    """(cells done in the shipped tables, cells) of grid ``name``."""
    from .grids import status

    done = [(d, total) for _, d, total, _ in status(GRIDS[name], root)]
    return sum(d for d, _ in done), sum(t for _, t in done)


def front(point: dict, held_out: dict | None, root: Path = ROOT, levers: dict | None = None,
          ant: dict | None = None, fresh: dict | None = None, **variants: dict | None) -> dict[str, str]:
    """README's sentences, by marker name (``<!-- front corrector NAME -->``), from the studies (``variants`` by
    their ``VARIANTS`` name; ``fresh``: ``ant_fresh_study``'s)."""
    _known(variants)
    grids = ("corrector", "taxonomy", "corrector-held-out", ANT_FIRST, "corrector-levers",
             *(VARIANT_GRIDS[m] for m in VARIANTS.values()), *VARIANT_SUITE.values(), *FRESH_GRIDS, *NEW_GRIDS,
             ANT_BEFORE, ANT_GRID, *ANT_CANDIDATES)
    counts = {name: progress(name, root) for name in grids}
    out = {"status": "cells done: " + ", ".join(f"{name} {d} of {t}" for name, (d, t) in counts.items())
                     + ("" if all(d == t for d, t in counts.values()) else "; the grids resume next session")}
    for proposer in ("imperfect:mild", "imperfect:moderate", "imperfect:severe"):
        level = proposer.split(":")[1]
        mazes = [e for e in point["per_maze"] + point["severe"] if e["proposer"] == proposer]
        ran = [e for e in mazes if e["runs"]]
        if not ran:
            out[level] = "not run yet"
            continue
        within = sum(1 for e in ran if e["success"] >= e["reference_success"] - TOLERANCE)
        rooms = next((e for e in point["rooms"] if e["proposer"] == proposer and e["method"] == METHOD), None)
        zero = next(z for z in point["zero"] if z["proposer"] == proposer)
        curve = [f"{k / n:.3f}" for k, n, _ in point["curves"][proposer]["/".join((METHOD, "*"))] if n]
        text = (f"1-5 rooms {', '.join(curve)}; within {TOLERANCE} of the oracle on {within} of {len(ran)} "
                f"U-chains" + ("" if len(ran) == len(mazes) else f" run so far (of {len(mazes)})"))
        if rooms is not None:
            text += f", {cmp._interval_text(rooms)} ({rooms['verdict']}{_partial(rooms)})"
        text += (f"; runs at 0: {zero[METHOD][0]} of {zero[METHOD][1]} (ours {zero['ours'][0]} of "
                 f"{zero['ours'][1]}, ours-repair {zero['ours-repair'][0]} of {zero['ours-repair'][1]})")
        out[level] = text
    ratios = [e for e in point["ratio"] if e["method"].startswith(METHOD)]
    out["ratio"] = "; ".join(f"{e['proposer'].split(':')[1]} {cmp._interval_text(e)} ({e['verdict']}{_partial(e)})"
                             for e in ratios)
    out["cost"] = "; ".join(_cost_text(c) for c in point["costs"] if c["pairs"])
    out["levers"] = _levers_text(levers) if levers else "not run yet"
    for name in VARIANTS:
        study = variants.get(name)
        out[name] = ((_gated_text if name == "gated" else _variant_text)(study)) if study else "not run yet"
        if study:
            v = study["versus_corrector"]
            out[f"{name}-paired"] = f"{_signed(v)} over {v['n_cells']} paired U-chain cells"
        if study and "oracle_versus_paper" in study:
            out[f"{name}-oracle"] = _paired_text(study["oracle_versus_paper"])
            out[f"{name}-runs"] = "; ".join(f"{p.split(':')[1]} {k} of {n}" for p, (k, n) in
                                            study["every_episode"].items())
            out[f"{name}-fresh"] = _fresh_text(study["fresh"]) if study.get("fresh") else "not run yet"
            if study.get("severe_zero", {}).get(study["method"], (0, 0))[1]:
                k, n = study["severe_zero"][study["method"]]
                out[f"{name}-severe-zero"] = f"{k} of {n}"
        if VARIANTS[name] in NEW_STUDIES:
            out[f"{name}-new"] = _new_text(study["new"]) if study and study.get("new") else "not run yet"
            out[f"{name}-adoption"] = _adoption_text(study) if study else "not run yet"
        for part in INFORMED_PARTS.get(VARIANTS[name], ()):
            out[f"{name}-{part}"] = _new_text(study[part]) if study and study.get(part) else "not run yet"
    out["ant"] = _ant_text(ant) if ant else "not run yet"
    out["unseen"] = _unseen_text(unseen(root))
    out["table"] = rules_table(variants.get(reported(variants)), point, ant)
    out["reported"] = f"`{VARIANTS[reported(variants)]}`"
    if held_out:
        done = [e for e in held_out["per_maze"] if e["runs"]]
        lo = min(e["success"] for e in done)
        hi = max(e["success"] for e in done)
        lo_o, hi_o = min(e["reference_success"] for e in done), max(e["reference_success"] for e in done)
        out["held-out"] = (f"ours-corrector {lo:.3f}-{hi:.3f} per layout and mix where ours gives {lo_o:.3f}-"
                           f"{hi_o:.3f}; runs at 0: {held_out['zero'][METHOD]} of {held_out['runs']} against "
                           f"{held_out['zero']['ours']} of {held_out['runs']}")
    out["ant-fresh"] = ant_fresh.front_text(fresh)
    return out


def unseen(root: Path = ROOT, method: str = SNAP) -> list[dict]:
    """``method`` (README's reported corrector) on every set of new layouts and mixes that ran it, in the order the
    sets were made: its runs at 0 and done, the oracle's lowest success there."""
    out = []
    for grid, mazes, mixes, names in NEW_STUDIES.values():
        rows = load(GRIDS[grid].tables, root)
        if not any(r["method"] == method for r in rows):
            continue
        mazes = tuple(table_name(m) for m in mazes)
        zero = [zero_runs(rows, method, mix, mazes) for mix in mixes]
        oracle = [float(r["success_rate"]) for r in rows if (r["method"], r["proposer"]) == ORACLE and cmp.is_done(r)]
        out.append({"grid": grid, "mixes": "/".join(names), "zero": sum(z for z, _ in zero),
                    "runs": sum(n for _, n in zero), "oracle_min": min(oracle) if oracle else math.nan})
    return out


def _unseen_text(sets: list[dict]) -> str:
    if not sets:
        return "not run yet"
    return "; ".join(f"{e['mixes']} {e['zero']} of {e['runs']}" for e in sets) + " (the oracle at least " + \
        f"{min(e['oracle_min'] for e in sets):.3f} on every one of those runs' cells)"


def reported(variants: dict) -> str:
    """The variant README's rules table reads: the latest of ``ADOPTABLE`` adopted by its rule, else ``REPORTED``."""
    return next((name for name in ADOPTABLE if (variants.get(name) or {}).get("adoption", {}).get("adopted")),
                REPORTED)


def _known(variants: dict) -> None:
    unknown = set(variants) - set(VARIANTS)
    if unknown:
        raise TypeError(f"not a variant: {', '.join(sorted(unknown))} (VARIANTS: {', '.join(VARIANTS)})")


def _ant_text(ant: dict) -> str:
    """The Ant's cells per maze in ANT_GRID, ANT_BEFORE and each of ANT_CANDIDATES, with their pooled differences
    from ANT_GRID."""
    def cells(per_maze):
        ran = [e for e in per_maze if e["runs"]]
        low = sum(e["success"] < ANT_FLOOR for e in ran)
        return (", ".join(f"{e['maze']} {e['success']:.3f} ({e['runs']} run{'s' * (e['runs'] > 1)})" for e in ran)
                + f"; below {ANT_FLOOR} on {low} of {len(ran)} mazes run") if ran else "no cell yet"
    return (f"{ANT_GRID} ({ANT_METHOD}): {cells(ant['confirm'])}. {ANT_BEFORE} (ours-corrector, stopped): "
            f"{cells(ant['before'])}. Difference on the cells both ran: {_ant_paired_text(ant['paired'])}. "
            + ". ".join(f"{c['grid']} ({c['method']}): {cells(c['per_maze'])}; {c['method']} - {ANT_METHOD} on the "
                        f"cells both ran: {_ant_paired_text(c['paired'])}"
                        + (f" (adopted: the Ant's rules read {c['grid']})" if c["grid"] == ant["grid"] else "")
                        for c in ant["candidates"])
            + "".join(f". {c['grid']} ({c['method']}): {cells(c['per_maze'])}" + (
                          f"; {c['method']} - {c['followed_method']} on the cells both ran: "
                          f"{_ant_paired_text(c['paired'])}; its mean cost over {c['followed_method']}'s: "
                          f"{_cost_text(c['cost_vs_followed'])}" if c["paired"]["cells"] else "")
                      + (f" (adopted: the Ant's rules read {c['grid']})" if c["grid"] == ant["grid"] else "")
                      for c in ant["successors"]))


def _ant_paired_text(e: dict) -> str:
    if not e["cells"]:
        return "no cell in both yet"
    lo, hi = e["ci"]
    return (f"{e['difference']:+.3f} [{lo:+.3f}, {hi:+.3f}] over {e['cells']} "
            f"cell{'s' * (e['cells'] > 1)} (Newcombe 95 %, pooled)")


def _levers_text(lv: dict) -> str:
    parts = []
    for proposer in dict.fromkeys(e["proposer"] for e in lv["entries"]):
        here = [e for e in lv["entries"] if e["proposer"] == proposer and e["runs"]]
        parts.append(f"{proposer.split(':')[1]}: " + ("; ".join(
            f"{e['lever']} {_num(e['success'])} ({_signed(e['versus']['ours'])} over ours, "
            f"{_helps(e['versus']['ours'])}; {_signed(e['versus'][METHOD])} against {METHOD}, {_proposer_calls(e)})"
            for e in here) or "not run yet"))
    return ". ".join(parts)


def _signed(e: dict) -> str:
    return "—" if math.isnan(e["estimate"]) else f"{e['estimate']:+.3f} [{e['ci_low']:+.3f}, {e['ci_high']:+.3f}]"


def _proposer_calls(e: dict) -> str:
    return f"{_num(e['costs']['proposer_calls_ratio'], '{:.1f}x')} the proposer calls of ours"


def _gated_text(gs: dict) -> str:
    v = gs["versus_corrector"]
    costs = "; ".join(f"{c['proposer'].split(':')[1]} {_num(c['proposer_calls_ratio'], '{:.1f}x')} ({c['pairs']} pairs)"
                      for c in gs["costs"])
    ok = not math.isnan(v["estimate"]) and v["ci_low"] >= -NON_INFERIORITY
    return (f"proposer calls over ours: {costs}; {GATED} - {METHOD} {_signed(v)} over {v['n_cells']} of "
            f"{v['n_expected']} paired cells (no worse by -{NON_INFERIORITY}: {_verdict(ok, v['complete'])})")


def _variant_text(vs: dict) -> str:
    """A variant against its reference, its change over rooms per preset and its proposer calls."""
    _, verdict = versus_corrector(vs)
    v, ref = vs["versus_corrector"], vs["reference"]
    parts = [f"{vs['method']} - {ref} {_signed(v)} over {v['n_cells']} of {v['n_expected']} paired cells "
             f"({verdict})"]
    for rooms, c, zero in zip(vs["rooms"], vs["costs"], vs["zero"]):
        level = rooms["proposer"].split(":")[1]
        mazes = [e for e in vs["per_maze"] if e["proposer"] == rooms["proposer"] and e["runs"]]
        within = sum(1 for e in mazes if e["success"] >= e["reference_success"] - TOLERANCE)
        parts.append(f"{level}: within {TOLERANCE} of the oracle on {within} of {len(mazes)} U-chains, "
                     f"{cmp._interval_text(rooms)} ({rooms['verdict']}{_partial(rooms)}), runs at 0: "
                     f"{zero['runs'][0]} of {zero['runs'][1]}, "
                     f"{_num(c['proposer_calls_ratio'], '{:.1f}x')} the proposer calls of ours"
                     + "".join(f", one-shot {cmp._interval_text(r)} ({r['verdict']}{_partial(r)})"
                               for r in vs.get("ratio", []) if r["proposer"] == rooms["proposer"]))
    if "severe_zero" in vs and vs["severe_zero"][vs["method"]][1]:
        zero = vs["severe_zero"]
        parts.append(f"severe: runs at 0 {zero[vs['method']][0]} of {zero[vs['method']][1]} ({ref} "
                     f"{zero[ref][0]} of {zero[ref][1]}), - {ref} {_signed(vs['severe_vs_corrector'])}, - "
                     f"ours-repair {_signed(vs['severe_vs_repair'])}{_partial(vs['severe_vs_repair'])}")
    if vs.get("versus_ours"):
        below = {level: _below_ours(vs["versus_ours"], f"imperfect:{level}") for level in ("mild", "moderate")}
        parts.append("every suite maze: below ours on " + ", ".join(
            f"{len(m)} of {_mazes_run(vs['versus_ours'], f'imperfect:{level}')} at {level}"
            + (f" ({', '.join(m)})" if m else "") for level, m in below.items()))
    held = [e for e in vs["held_out"] if e["runs"]]
    if held:
        both = [e for e in held if e["reference_runs"]]
        beside = (f"{ref} {min(e['reference_success'] for e in both):.3f}-"
                  f"{max(e['reference_success'] for e in both):.3f}; higher on "
                  f"{sum(e['success'] > e['reference_success'] for e in both)}, lower on "
                  f"{sum(e['success'] < e['reference_success'] for e in both)} of {len(both)}"
                  + ("" if len(both) == len(held) else " run by both") if both else f"{ref} not run there")
        parts.append(f"held out: {min(e['success'] for e in held):.3f}-{max(e['success'] for e in held):.3f} per "
                     f"layout and mix ({beside})")
        mine = [c for c in vs.get("held_out_costs", []) if c["method"] == vs["method"] and c["pairs"]]
        if mine:
            parts[-1] += ", " + ", ".join(f"{c['proposer']} {_num(c['proposer_calls_ratio'], '{:.1f}x')}"
                                          for c in mine) + " the proposer calls of ours"
    return "; ".join(parts)


def _cost_text(c: dict) -> str:
    return (f"{c['proposer'].split(':')[1]} ({c['pairs']} pairs) {_num(c['evaluations_ratio'], '{:.1f}x')} the "
            f"evaluations, {_num(c['proposer_calls_ratio'], '{:.1f}x')} the proposer calls, "
            f"{_num(c['sim_steps_ratio'], '{:.1f}x')} the simulator steps")


def _partial(entry: dict) -> str:
    return "" if entry["complete"] else f", partial: {entry['n_cells']} of {entry['n_expected']} cells"


def rooms_figure(point: dict):
    """Success over rooms (U-chain 1-5 without subgoals, pooled over seeds) per method, one panel per preset."""
    from ..pictures.render import subplots
    from .figures import METHOD_COLOURS

    curves = point["curves"]
    fig, axes = subplots(1, len(curves), figsize=(4.2 * len(curves), 3.4), sharey=True)
    for ax, (proposer, methods) in zip(np.atleast_1d(axes), curves.items()):
        for name, points in methods.items():
            method = name.split("/")[0]
            xs = [n for n, (k, total, _) in zip(range(1, 6), points) if total]
            ys = [k / total for k, total, _ in points if total]
            if xs:
                oracle = name == "/".join(ORACLE)
                ax.plot(xs, ys, marker="o", color="black" if oracle else METHOD_COLOURS.get(method, "#757575"),
                        ls="--" if oracle else "-", label="oracle (ours, geometric)" if oracle else method)
        ax.set_title(f"{proposer} (offline, not a VLM)", fontsize=9)
        ax.set_xlabel("rooms (U-chain, no subgoals)")
        ax.set_xticks(range(1, 6))
        ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
    np.atleast_1d(axes)[0].set_ylabel("success (pooled over seeds)")
    np.atleast_1d(axes)[0].legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    return fig


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("corrector-claims", argv, prog="python -m specrefine.experiments.corrector_claims")


if __name__ == "__main__":
    raise SystemExit(main())
