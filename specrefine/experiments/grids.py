"""Every grid this project has run or fixed, defined once: read by ``scripts/run_grid.sh`` (which runs it through
``scripts/pinned_sweep.sh``) and by the analysis of its table (``comparison``, ``repair_claims``).

A grid is parts run in order; a part is one sweep, or one sweep per value of one axis (``split``: seed by seed,
say, so that a table cut short holds whole seeds). ``sweep_args`` gives the ``specrefine.runs.sweep`` arguments of
each step (without ``--out``), ``cells`` the cells they run. The arguments are those of the old per-grid scripts,
option for option, so that a grid pinned to an old commit (``code``) resumes its shipped table with the same cell
ids and parameters (``OUT/sweep.json`` refuses a cell run with another policy, rollouts or episodes)::

    python -m specrefine.experiments.grids list                      # name, agent, cells, where it was fixed
    python -m specrefine.experiments.grids show ant-comparison       # the pinned_sweep.sh commands, in order
    python -m specrefine.experiments.grids args repair --part 0 --step 1    # one step's arguments, shell-quoted
    python -m specrefine.experiments.grids plan repair               # what run_grid.sh reads
    python -m specrefine.experiments.grids status ant-scaling        # done per part (shipped tables), started, running
"""

from __future__ import annotations

import os
import shlex
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

from ..core.errors import SpecrefineError
from ..core.paper import PAPER
from ..runs.sweep import Cell, grid

ROOT = Path(__file__).resolve().parents[2]  # the checkout: a grid's paths are relative to it
SPLITS = ("", "mazes", "methods", "proposers", "seeds")


@dataclass(frozen=True)
class Part:
    """One sweep of a grid (or one per value of ``split``), into ``table`` (None: the grid's) and the sweep folder
    OUT/``out`` (None: the grid's OUT itself). None for ``seeds``, ``mazes``, ``policy``: the grid's."""
    methods: tuple
    proposers: tuple
    seeds: tuple | None = None
    mazes: tuple | None = None
    split: str = ""
    policy: str | None = None
    table: str | None = None
    out: str | None = None


@dataclass(frozen=True)
class ExperimentGrid:
    """A grid: what its sweeps run (``parts``, in order), with which code, into which tables, and what its analysis
    reads (``claim_methods``, ``levels``, ``contrasts``; ``figure_methods``: the methods' order in figures and tables,
    empty = run order)."""
    name: str
    doc: str  # where it was fixed: file and section
    agent: str
    parts: tuple
    seeds: tuple
    mazes: tuple | None = None  # None: every maze of data/mazes (the sweep's default, in the code that runs it)
    policy: str = "shipped"  # or a checkout-relative path to a checkpoint
    policy_in_checkout: bool = False  # the checkout's copy (an absolute path), not the pinned code tree's
    evaluation: str | None = None  # None: the agent's default (the sweep's, not passed)
    goal_points: str | None = None  # None: what the pinned code defaulted to, the paper's sampled points (not passed)
    switching: str | None = None  # None: the pinned code's rule, the paper's at-region (not passed)
    split_pick: str | None = None  # None: the pinned code's rule, the paper's best estimate (not passed)
    rollouts: int | None = None  # None: the sweep's default (not passed)
    episodes: int | None = None
    workers: int = 2
    code: str | None = None  # the commit it runs with (scripts/pinned_sweep.sh); None: the checkout's HEAD
    table: str | None = None  # the shipped table (data/results/...), for parts without their own
    out: str = "runs/sweep"  # the sweep folder, under which parts with their own ``out`` sit
    claim_methods: tuple = ()
    figure_methods: tuple = ()
    levels: tuple = ()
    contrasts: tuple = ()

    @property
    def methods(self) -> tuple:
        return self.figure_methods or tuple(dict.fromkeys(m for part in self.parts for m in part.methods))

    @property
    def proposers(self) -> tuple:
        return tuple(dict.fromkeys(p for part in self.parts for p in part.proposers))

    @property
    def tables(self) -> tuple:
        return tuple(dict.fromkeys(self.part_table(i) for i in range(len(self.parts))))

    def part_table(self, index: int) -> str:
        return self.parts[index].table or self.table

    def part_out(self, index: int, out: str | None = None) -> str:
        """The sweep folder of a part: OUT (the grid's, or ``out``) or its sub-folder."""
        base = out or self.out
        return f"{base}/{self.parts[index].out}" if self.parts[index].out else base


class GridError(SpecrefineError, ValueError):
    """An unknown grid, part or step."""


def _axes(g: ExperimentGrid, part: Part) -> dict:
    return {"mazes": part.mazes if part.mazes is not None else g.mazes, "methods": part.methods,
            "proposers": part.proposers, "seeds": part.seeds if part.seeds is not None else g.seeds}


@dataclass(frozen=True)
class Subset:
    """Some of a grid's cells, the same cells in the same order (``run_grid.sh`` with MAZES or SEEDS): a long cell
    run alone, or short ones in the tail of a session. None: every maze or seed."""
    mazes: tuple | None = None
    seeds: tuple | None = None

    def check(self, g: ExperimentGrid) -> None:
        """A name outside the grid would run a cell the grid does not hold: refused."""
        from ..core.mazes import benchmark_mazes

        for axis, chosen in (("mazes", self.mazes), ("seeds", self.seeds)):
            held = {v for part in g.parts for v in (_axes(g, part)[axis] or sorted(benchmark_mazes()))}
            if chosen is not None and (extra := [v for v in chosen if v not in held]):
                raise GridError(f"grid {g.name} has no {axis} {' '.join(map(str, extra))} "
                                f"(its {axis}: {' '.join(map(str, sorted(held)))})")

    def apply(self, axes: dict) -> dict | None:
        """``axes`` cut to the subset, None where nothing is left."""
        from ..core.mazes import benchmark_mazes

        cut = dict(axes)
        if self.mazes is not None:
            cut["mazes"] = tuple(m for m in (axes["mazes"] or sorted(benchmark_mazes())) if m in self.mazes)
        if self.seeds is not None:
            cut["seeds"] = tuple(s for s in axes["seeds"] if s in self.seeds)
        return None if (self.mazes is not None and not cut["mazes"]) or not cut["seeds"] else cut


EVERY = Subset()


def _steps(g: ExperimentGrid, part: Part, subset: Subset = EVERY) -> list[dict]:
    """The axes of each sweep of a part, in order (those of ``subset``: its steps with something left)."""
    axes = _axes(g, part)
    steps = [axes] if not part.split else [axes | {part.split: (value,)} for value in axes[part.split]]
    return [cut for step in steps if (cut := subset.apply(step)) is not None]


def _policy(g: ExperimentGrid, part: Part, root: Path) -> str:
    """The --policy argument: 'shipped', the checkout's absolute path, or a path the sweep takes from its working
    directory, the pinned code tree."""
    policy = part.policy or g.policy
    if policy == "shipped" or not g.policy_in_checkout:
        return policy
    return str(root / policy)


def _budget(g: ExperimentGrid) -> dict:
    """The rollouts and episodes the grid passes the sweep (those it leaves to the sweep's defaults: none)."""
    return {name: value for name, value in (("rollouts", g.rollouts), ("episodes", g.episodes)) if value}


def _part(g: ExperimentGrid, index: int) -> Part:
    if not 0 <= index < len(g.parts):
        raise GridError(f"grid {g.name} has parts 0-{len(g.parts) - 1}, not {index}")
    return g.parts[index]


def sweep_args(g: ExperimentGrid, index: int, *, root: Path = ROOT, workers: int | None = None,
               subset: Subset = EVERY) -> list[list[str]]:
    """The ``specrefine.runs.sweep`` arguments (no ``--out``) of each step of part ``index``, in order."""
    part = _part(g, index)
    common = ["--agent", g.agent]
    if g.evaluation:
        common += ["--evaluation", g.evaluation]
    if g.goal_points:
        common += ["--goal-points", g.goal_points]
    if g.switching:
        common += ["--switching", g.switching]
    if g.split_pick:
        common += ["--split-pick", g.split_pick]
    if (policy := _policy(g, part, root)) != "shipped":
        common += ["--policy", policy]
    for name, value in _budget(g).items():
        common += [f"--{name}", str(value)]
    common += ["--workers", str(workers or g.workers)]
    out = []
    for axes in _steps(g, part, subset):
        args = list(common)
        if axes["mazes"] is not None:
            args += ["--mazes", *axes["mazes"]]
        args += ["--methods", *axes["methods"], "--proposers", *axes["proposers"],
                 "--seeds", *map(str, axes["seeds"])]
        out.append(args)
    return out


def _recorded_policy(g: ExperimentGrid, part: Part, root: Path) -> str:
    """The policy a cell records when run by run_grid.sh from the checkout ``root``: a relative path is the pinned
    code tree's (scripts/pinned_sweep.sh runs the sweep in runs/code_CODE)."""
    policy = _policy(g, part, root)
    if policy == "shipped" or Path(policy).is_absolute():
        return policy
    return str(root / "runs" / f"code_{g.code}" / policy)


def part_cells(g: ExperimentGrid, index: int, *, root: Path = ROOT) -> list[Cell]:
    """The cells of part ``index``, in the order its sweeps run them (a cell run by an earlier step counts once)."""
    from ..core.mazes import benchmark_mazes

    part = _part(g, index)
    cells = []
    for axes in _steps(g, part):
        mazes = axes["mazes"] if axes["mazes"] is not None else sorted(benchmark_mazes())
        cells += grid(mazes, axes["methods"], axes["proposers"], axes["seeds"], agent=g.agent,
                      evaluation=g.evaluation, policy=_recorded_policy(g, part, root),
                      goal_points=g.goal_points or PAPER.goal_points, split_pick=g.split_pick or PAPER.split_pick,
                      **_budget(g),
                      **({"switching": g.switching} if g.switching else {}))
    return list(dict.fromkeys(cells))


def cells(g: ExperimentGrid, *, root: Path = ROOT, table: str | None = None) -> list[Cell]:
    """Every cell of the grid (or of the parts writing ``table``), in run order, each once."""
    return list(dict.fromkeys(c for i in range(len(g.parts)) if table in (None, g.part_table(i))
                              for c in part_cells(g, i, root=root)))


def get(name: str) -> ExperimentGrid:
    if name not in GRIDS:
        raise GridError(f"no grid {name!r}; grids: {', '.join(GRIDS)}")
    return GRIDS[name]


IMPERFECT = ("imperfect:mild", "imperfect:moderate", "imperfect:severe", "imperfect:moderate,alpha=0.1")
CONTROLS = ("ours-novertex", "ours-notune", "ours-nofeedback")
U_CHAINS = tuple(f"u_chain_{n}" for n in range(1, 6))
SUBGOALS = tuple(f"u_chain_{n}_subgoals" for n in range(2, 6))
GEOMETRIC_48 = "geometric:max_waypoints=48"
OTHER_POINT_MAZES = ("hazard_pool", "or_maze", "split_doorway", "two_doors", "u_maze", "x_maze", "xx_maze_h",
                     "xx_maze_v")  # the point suite beside the U-chains
HELD_OUT_MAZES = ("data/mazes/unseen/spiral.maze", "data/mazes/unseen/zigzag.maze",
                  "data/mazes/unseen/detour_subgoal.maze", "data/mazes/unseen/pillars.maze", "random:3x4:7",
                  "random:4x4:11")
#: fresh held-out layouts and mixes for the centre rule (docs/corrector.md, "Fresh layouts for the centre rule"):
#: generated mazes no run had used, and two more error mixes (C: small, cornered regions and uncapped replies; D:
#: mirrored replies, wrong branches and dropped turns, growing with the turns a query spans)
FRESH_MAZES = ("random:4x5:23", "random:5x5:31", "random:3x6:5", "random:5x4:42")
FRESH_MIXES = ("imperfect:position_sigma=0.25,coord_grid=0.1,radius=0.35,radius_log_sigma=0.45,corner_pull=0.35,"
               "p_drop_turn=0.2,p_uncapped=0.6,p_false_opening=0.2,p_wrong_branch=0.2,p_mirror_y=0.05,"
               "p_unparseable=0.08,rho=0.5",
               "imperfect:position_sigma=0.4,radius_log_sigma=0.25,corner_pull=0.15,p_drop_turn=0.3,p_uncapped=0.4,"
               "p_wrong_branch=0.35,p_mirror_y=0.15,alpha=0.1,rho=0.7")
#: error mixes no method was developed on: (A) small regions pulled to corners and false openings, (B) dropped
#: turns growing with the span of a query, mirrored replies and wrong branches
HELD_OUT_MIXES = ("imperfect:position_sigma=0.35,radius=0.3,radius_log_sigma=0.6,corner_pull=0.5,"
                  "p_false_opening=0.3,p_wrong_branch=0.1,p_drop_turn=0.1,p_uncapped=0.3,p_unparseable=0.05,rho=0.5",
                  "imperfect:position_sigma=0.2,radius_log_sigma=0.3,p_drop_turn=0.35,p_uncapped=0.7,alpha=0.2,"
                  "p_mirror_y=0.1,p_wrong_branch=0.3,rho=0.3")
#: layouts and error mixes no run had used before grid corrector-persist-new (docs/corrector.md, "Corrected until
#: alive"): four larger generated corridor mazes, and two mixes: E (large offsets and regions, false openings,
#: unparseable replies, errors growing with the turns a query spans) and F (coordinates rounded to half cells, wrong
#: branches, mirrored replies, dropped turns)
NEW_MAZES = ("random:6x5:8", "random:5x6:3", "random:4x6:29", "random:6x4:17")
NEW_MIXES = ("imperfect:position_sigma=0.3,radius=0.5,radius_log_sigma=0.4,corner_pull=0.25,p_drop_turn=0.25,"
             "p_false_opening=0.35,p_uncapped=0.5,p_unparseable=0.15,alpha=0.15,rho=0.4",
             "imperfect:position_sigma=0.3,coord_grid=0.5,radius=0.35,radius_log_sigma=0.35,p_wrong_branch=0.4,"
             "p_mirror_y=0.2,p_drop_turn=0.2,p_uncapped=0.5,alpha=0.25,rho=0.6")
#: layouts and error mixes no run had used before grid corrector-snap-new (docs/corrector.md, "Snapped out of the
#: wall"): four more generated mazes, and two mixes: G (large offsets rounded to quarter cells, small regions pulled
#: to corners, false openings, unparseable replies) and H (coordinates rounded to whole cells, wrong branches,
#: mirrored replies, dropped turns growing with the turns a query spans)
SNAP_MAZES = ("random:5x5:64", "random:6x6:12", "random:4x7:3", "random:7x4:21")
SNAP_MIXES = ("imperfect:position_sigma=0.45,coord_grid=0.25,radius=0.3,radius_log_sigma=0.5,corner_pull=0.3,"
              "p_drop_turn=0.15,p_false_opening=0.2,p_uncapped=0.4,p_unparseable=0.1,rho=0.5",
              "imperfect:position_sigma=0.2,coord_grid=1.0,radius=0.45,radius_log_sigma=0.3,p_wrong_branch=0.25,"
              "p_mirror_y=0.1,p_drop_turn=0.3,alpha=0.2,p_uncapped=0.6,rho=0.5")
#: layouts and error mixes no run had used before grid corrector-snap-check (docs/corrector.md, "A last check on
#: layouts and mixes no run had used"): four larger generated mazes, and two mixes: I (coordinates rounded to half
#: cells, large regions, false openings, dropped turns) and J (small regions pulled to corners, mirrored replies,
#: wrong branches, errors growing fast with the turns a query spans)
CHECK_MAZES = ("random:3x8:2", "random:8x3:9", "random:6x7:5", "random:7x6:40")
CHECK_MIXES = ("imperfect:position_sigma=0.35,coord_grid=0.5,radius=0.5,radius_log_sigma=0.2,corner_pull=0.2,"
               "p_drop_turn=0.3,p_false_opening=0.25,p_uncapped=0.6,p_unparseable=0.05,alpha=0.1,rho=0.5",
               "imperfect:position_sigma=0.25,radius=0.2,radius_log_sigma=0.6,corner_pull=0.45,p_wrong_branch=0.35,"
               "p_mirror_y=0.25,p_drop_turn=0.2,p_uncapped=0.3,p_unparseable=0.1,alpha=0.3,rho=0.4")
#: layouts and error mixes no run had used before grid corrector-extend-new (docs/corrector.md, "A budget that grows
#: where the run would end at 0"): four larger generated mazes, and two mixes: K (offsets rounded to half cells, false
#: openings, wrong branches, dropped turns, unparseable replies, errors growing with the turns a query spans) and L
#: (small regions pulled to corners, wrong branches, mirrored replies, dropped turns, errors growing fast with turns)
EXTEND_MAZES = ("random:7x7:11", "random:5x8:27", "random:8x5:33", "random:6x8:50")
EXTEND_MIXES = ("imperfect:position_sigma=0.4,coord_grid=0.5,radius=0.4,radius_log_sigma=0.4,corner_pull=0.3,"
                "p_drop_turn=0.25,p_false_opening=0.3,p_wrong_branch=0.2,p_uncapped=0.5,p_unparseable=0.1,alpha=0.2,"
                "rho=0.5",
                "imperfect:position_sigma=0.3,radius=0.25,radius_log_sigma=0.5,corner_pull=0.4,p_wrong_branch=0.4,"
                "p_mirror_y=0.2,p_drop_turn=0.3,p_uncapped=0.4,alpha=0.35,rho=0.6")
#: layouts and error mixes no run had used before grid corrector-keep-new (docs/corrector.md, "A declined split kept
#: where the path is dead"): four more generated mazes, and two mixes: M (offsets rounded to quarter cells, small
#: cornered regions, false openings, wrong branches, dropped turns, errors growing with the turns a query spans) and
#: N (coordinates rounded to whole cells, wrong branches, mirrored replies, dropped turns, errors growing fast)
KEEP_MAZES = ("random:7x5:19", "random:5x7:44", "random:8x6:3", "random:6x8:71")
KEEP_MIXES = ("imperfect:position_sigma=0.35,coord_grid=0.25,radius=0.3,radius_log_sigma=0.45,corner_pull=0.35,"
              "p_drop_turn=0.3,p_false_opening=0.25,p_wrong_branch=0.3,p_uncapped=0.5,p_unparseable=0.1,alpha=0.25,"
              "rho=0.5",
              "imperfect:position_sigma=0.25,coord_grid=1.0,radius=0.35,radius_log_sigma=0.35,corner_pull=0.25,"
              "p_wrong_branch=0.35,p_mirror_y=0.15,p_drop_turn=0.25,p_uncapped=0.5,alpha=0.3,rho=0.6")
#: layouts and error mixes no run had used before grid corrector-fallback-new (docs/corrector.md, "Given up at half the
#: budget"): four more generated mazes, and two mixes: O (offsets rounded to half cells, wrong branches, false
#: openings, dropped turns, unparseable replies, errors growing with the turns a query spans) and P (large cornered
#: regions, wrong branches, mirrored replies, dropped turns)
FALLBACK_MAZES = ("random:6x6:77", "random:7x6:13", "random:5x9:8", "random:8x7:26")
FALLBACK_MIXES = ("imperfect:position_sigma=0.3,coord_grid=0.5,radius=0.3,radius_log_sigma=0.5,corner_pull=0.3,"
                  "p_drop_turn=0.25,p_false_opening=0.2,p_wrong_branch=0.35,p_uncapped=0.5,p_unparseable=0.1,"
                  "alpha=0.3,rho=0.5",
                  "imperfect:position_sigma=0.4,radius=0.35,radius_log_sigma=0.4,corner_pull=0.35,p_wrong_branch=0.3,"
                  "p_mirror_y=0.2,p_drop_turn=0.3,p_uncapped=0.4,alpha=0.25,rho=0.6")
#: layouts and error mixes no run had used before grid corrector-advance-new (docs/corrector.md, "Ground kept where
#: the path is dead"): four more generated mazes, and two mixes: Q (offsets rounded to half cells, false openings,
#: wrong branches, mirrored replies, dropped turns, errors growing with the turns a query spans) and R (small regions
#: pulled to corners, wrong branches, uncapped legs, dropped turns, unparseable replies, errors growing fast)
ADVANCE_MAZES = ("random:7x7:58", "random:6x8:15", "random:8x6:62", "random:7x6:91")
ADVANCE_MIXES = ("imperfect:position_sigma=0.35,coord_grid=0.5,radius=0.35,radius_log_sigma=0.4,corner_pull=0.25,"
                 "p_drop_turn=0.3,p_false_opening=0.2,p_wrong_branch=0.25,p_mirror_y=0.1,p_uncapped=0.5,"
                 "p_unparseable=0.05,alpha=0.25,rho=0.5",
                 "imperfect:position_sigma=0.3,radius=0.3,radius_log_sigma=0.5,corner_pull=0.4,p_wrong_branch=0.4,"
                 "p_drop_turn=0.35,p_false_opening=0.1,p_uncapped=0.6,p_unparseable=0.1,alpha=0.3,rho=0.4")
#: layouts and error mixes no run had used before grid corrector-advance-check (docs/corrector.md, "A last check
#: after advance-extend's adoption"), made after Q/R had been looked at: four larger generated mazes, and two mixes: S
#: (large offsets rounded to half cells, false openings, wrong branches, mirrored replies, dropped turns, uncapped
#: legs, errors growing with the turns a query spans) and T (coordinates rounded to whole cells, small regions pulled
#: hard to corners, wrong branches, many dropped turns, errors growing fast)
ADVANCE_CHECK_MAZES = ("random:8x8:5", "random:9x6:33", "random:6x9:70", "random:7x8:12")
ADVANCE_CHECK_MIXES = ("imperfect:position_sigma=0.45,coord_grid=0.5,radius=0.3,radius_log_sigma=0.5,corner_pull=0.3,"
                       "p_drop_turn=0.35,p_false_opening=0.25,p_wrong_branch=0.3,p_mirror_y=0.15,p_uncapped=0.6,"
                       "p_unparseable=0.1,alpha=0.3,rho=0.4",
                       "imperfect:position_sigma=0.3,coord_grid=1.0,radius=0.25,radius_log_sigma=0.6,corner_pull=0.5,"
                       "p_wrong_branch=0.45,p_drop_turn=0.4,p_uncapped=0.7,p_unparseable=0.05,alpha=0.35,rho=0.5")
#: layouts and error mixes no run had used before grid corrector-roadmap-new (docs/corrector.md, "Replies pooled into a
#: roadmap"), made after S/T had been looked at: four larger generated mazes, and two mixes: U (large offsets rounded
#: to quarter cells, false openings, wrong branches, mirrored replies, dropped turns, uncapped legs, unparseable
#: replies, errors growing with the turns a query spans) and V (coordinates rounded to whole cells, regions pulled to
#: corners, wrong branches, many dropped turns, false openings, uncapped legs, errors growing fast)
ROADMAP_MAZES = ("random:8x7:44", "random:7x9:21", "random:9x7:60", "random:8x9:3")
ROADMAP_MIXES = ("imperfect:position_sigma=0.4,coord_grid=0.25,radius=0.3,radius_log_sigma=0.5,corner_pull=0.35,"
                 "p_drop_turn=0.35,p_false_opening=0.3,p_wrong_branch=0.35,p_mirror_y=0.1,p_uncapped=0.6,"
                 "p_unparseable=0.1,alpha=0.3,rho=0.4",
                 "imperfect:position_sigma=0.35,coord_grid=1.0,radius=0.35,radius_log_sigma=0.5,corner_pull=0.45,"
                 "p_wrong_branch=0.4,p_drop_turn=0.45,p_false_opening=0.15,p_mirror_y=0.1,p_uncapped=0.7,"
                 "p_unparseable=0.05,alpha=0.4,rho=0.5")
#: layouts and error mixes no run had used before grid corrector-roadmap-check (docs/corrector.md, "A last check after
#: roadmap's adoption"), made after U/V had been looked at: four larger generated mazes, and two mixes: W (offsets
#: rounded to half cells, mirrored replies often, wrong branches, dropped turns, uncapped legs, unparseable replies,
#: errors growing with the turns a query spans) and X (small regions, false openings often, coordinates rounded to
#: whole cells, dropped turns, wrong branches, errors growing fast)
ROADMAP_CHECK_MAZES = ("random:9x9:14", "random:10x7:5", "random:7x10:31", "random:9x8:77")
ROADMAP_CHECK_MIXES = ("imperfect:position_sigma=0.35,coord_grid=0.5,radius=0.35,radius_log_sigma=0.4,corner_pull=0.3,"
                       "p_drop_turn=0.3,p_wrong_branch=0.35,p_mirror_y=0.3,p_uncapped=0.6,p_unparseable=0.15,"
                       "alpha=0.3,rho=0.5",
                       "imperfect:position_sigma=0.3,coord_grid=1.0,radius=0.2,radius_log_sigma=0.5,corner_pull=0.4,"
                       "p_drop_turn=0.35,p_false_opening=0.4,p_wrong_branch=0.3,p_uncapped=0.6,p_unparseable=0.05,"
                       "alpha=0.4,rho=0.4")
#: layouts and error mixes no run had used before grid corrector-sound-new (docs/corrector.md, "Sound legs for the
#: roadmap"), made after W/X had been looked at: four larger generated mazes, and two mixes: Y (offsets rounded to half
#: cells, small regions of spread sizes, many dropped turns, mirrored replies, false openings, wrong branches, uncapped
#: legs, unparseable replies, few follow-ups that repair, errors growing with the turns a query spans) and Z
#: (coordinates rounded to whole cells, regions pulled hard to corners, wrong branches, false openings often, uncapped
#: legs, errors growing fast)
SOUND_MAZES = ("random:10x8:23", "random:8x10:49", "random:9x9:88", "random:10x7:41")
SOUND_MIXES = ("imperfect:position_sigma=0.4,coord_grid=0.5,radius=0.25,radius_log_sigma=0.6,corner_pull=0.35,"
               "p_drop_turn=0.4,p_false_opening=0.2,p_wrong_branch=0.3,p_mirror_y=0.2,p_uncapped=0.5,"
               "p_unparseable=0.1,alpha=0.35,rho=0.3",
               "imperfect:position_sigma=0.25,coord_grid=1.0,radius=0.3,radius_log_sigma=0.4,corner_pull=0.5,"
               "p_drop_turn=0.3,p_false_opening=0.35,p_wrong_branch=0.4,p_uncapped=0.7,p_unparseable=0.1,"
               "alpha=0.45,rho=0.5")
#: layouts and error mixes no run had used before grid corrector-memory-new (docs/corrector.md, "A roadmap that
#: remembers"), made after Y/Z had been looked at: four larger generated mazes, and two mixes: AA (large offsets
#: rounded to quarter cells, regions pulled to corners, many dropped turns, false openings, wrong branches, mirrored
#: replies, uncapped legs, unparseable replies, few follow-ups that repair, errors growing with the turns a query spans)
#: and AB (coordinates rounded to whole cells, small regions, wrong branches often, false openings, dropped turns,
#: uncapped legs, errors growing fast)
MEMORY_MAZES = ("random:10x9:61", "random:9x10:17", "random:11x7:52", "random:8x11:36")
MEMORY_MIXES = ("imperfect:position_sigma=0.45,coord_grid=0.25,radius=0.3,radius_log_sigma=0.5,corner_pull=0.4,"
                "p_drop_turn=0.45,p_false_opening=0.25,p_wrong_branch=0.35,p_mirror_y=0.15,p_uncapped=0.65,"
                "p_unparseable=0.1,alpha=0.35,rho=0.35",
                "imperfect:position_sigma=0.3,coord_grid=1.0,radius=0.25,radius_log_sigma=0.5,corner_pull=0.45,"
                "p_drop_turn=0.35,p_false_opening=0.3,p_wrong_branch=0.45,p_mirror_y=0.1,p_uncapped=0.7,"
                "p_unparseable=0.05,alpha=0.45,rho=0.45")
#: layouts and error mixes no run had used before grid corrector-probe-new (docs/corrector.md, "Probes from the nearest
#: node"), made after AA/AB had been looked at: four larger generated mazes, and two mixes: AC (offsets rounded to half
#: cells, regions pulled to corners, many dropped turns, wrong branches often, mirrored replies, false openings,
#: uncapped legs, unparseable replies, few follow-ups that repair, errors growing with the turns a query spans) and AD
#: (coordinates rounded to whole cells, small regions of spread sizes, wrong branches, false openings often, dropped
#: turns, uncapped legs, errors growing fast)
PROBE_MAZES = ("random:10x10:29", "random:9x11:8", "random:11x8:66", "random:8x10:90")
PROBE_MIXES = ("imperfect:position_sigma=0.4,coord_grid=0.5,radius=0.3,radius_log_sigma=0.5,corner_pull=0.4,"
               "p_drop_turn=0.45,p_false_opening=0.2,p_wrong_branch=0.45,p_mirror_y=0.15,p_uncapped=0.6,"
               "p_unparseable=0.1,alpha=0.35,rho=0.3",
               "imperfect:position_sigma=0.3,coord_grid=1.0,radius=0.25,radius_log_sigma=0.6,corner_pull=0.35,"
               "p_drop_turn=0.35,p_false_opening=0.4,p_wrong_branch=0.35,p_uncapped=0.7,p_unparseable=0.05,"
               "alpha=0.45,rho=0.4")
#: layouts and error mixes no run had used before grid corrector-deep-new (docs/corrector.md, "Longer searches for the
#: probes"), made after AC/AD had been looked at: four larger generated mazes, and two mixes: AE (offsets rounded to
#: half cells, regions pulled to corners, dropped turns, false openings, wrong branches often, mirrored replies often,
#: uncapped legs, unparseable replies, errors growing with the turns a query spans) and AF (coordinates rounded to
#: whole cells, small regions of spread sizes, many dropped turns, false openings often, wrong branches, uncapped legs,
#: errors growing fast)
DEEP_MAZES = ("random:10x11:55", "random:11x10:19", "random:12x9:7", "random:9x12:63")
DEEP_MIXES = ("imperfect:position_sigma=0.35,coord_grid=0.5,radius=0.3,radius_log_sigma=0.5,corner_pull=0.45,"
              "p_drop_turn=0.4,p_false_opening=0.3,p_wrong_branch=0.4,p_mirror_y=0.2,p_uncapped=0.65,"
              "p_unparseable=0.1,alpha=0.4,rho=0.35",
              "imperfect:position_sigma=0.3,coord_grid=1.0,radius=0.2,radius_log_sigma=0.6,corner_pull=0.4,"
              "p_drop_turn=0.45,p_false_opening=0.35,p_wrong_branch=0.4,p_uncapped=0.7,p_unparseable=0.05,"
              "alpha=0.45,rho=0.45")
#: layouts and error mixes no run had used before grid corrector-deep-check (docs/corrector.md, "A last check of
#: deep"), made after AE/AF had been looked at: four larger generated mazes (sizes chosen, seeds drawn by
#: random.Random(20261201)), and two mixes: AG (large offsets rounded to quarter cells, small regions of spread sizes,
#: regions pulled hard to corners, dropped turns, false openings, wrong branches often, mirrored replies, uncapped legs,
#: unparseable replies, errors growing with the turns a query spans) and AH (coordinates rounded to whole cells, many
#: dropped turns, false openings often, wrong branches, uncapped legs, errors growing fast)
DEEP_CHECK_MAZES = ("random:12x10:19", "random:10x12:32", "random:11x11:20", "random:13x9:30")
DEEP_CHECK_MIXES = ("imperfect:position_sigma=0.45,coord_grid=0.25,radius=0.25,radius_log_sigma=0.6,corner_pull=0.5,"
                    "p_drop_turn=0.4,p_false_opening=0.3,p_wrong_branch=0.45,p_mirror_y=0.2,p_uncapped=0.65,"
                    "p_unparseable=0.1,alpha=0.4,rho=0.3",
                    "imperfect:position_sigma=0.3,coord_grid=1.0,radius=0.25,radius_log_sigma=0.6,corner_pull=0.45,"
                    "p_drop_turn=0.45,p_false_opening=0.4,p_wrong_branch=0.4,p_mirror_y=0.1,p_uncapped=0.7,"
                    "p_unparseable=0.05,alpha=0.5,rho=0.45")
SCALING_MAZES = ("u_chain_1", *(m for n in range(2, 6) for m in (f"u_chain_{n}", f"u_chain_{n}_subgoals")))
#: layouts and an error mix no run had used, for the Ant's adopted corrector (docs/corrector.md, "Fresh layouts for
#: the Ant", fixed 2026-12-04 before it ran): four small generated mazes (sizes chosen for about an hour per Ant cell,
#: seeds drawn by random.Random(20261204)), and the mix AI (offsets rounded to quarter cells, regions pulled to
#: corners, dropped turns, false openings, wrong branches, mirrored replies, uncapped legs, unparseable replies, a weak
#: follow-up, errors growing with the turns a query spans), beside the preset the Ant's rule was judged on
ANT_FRESH_MAZES = ("random:3x3:94", "random:3x4:63", "random:4x3:2", "random:3x5:46")
ANT_FRESH_MIXES = ("imperfect:moderate",
                   "imperfect:position_sigma=0.35,coord_grid=0.25,radius=0.35,radius_log_sigma=0.4,corner_pull=0.3,"
                   "p_drop_turn=0.3,p_false_opening=0.2,p_wrong_branch=0.3,p_mirror_y=0.05,p_uncapped=0.5,"
                   "p_unparseable=0.05,rho=0.5,alpha=0.1")

#: Gymnasium-Robotics' own maps and two error mixes no run had used, for the point mass's default method
#: (docs/corrector.md, "The point mass's default on Gymnasium-Robotics' maps", fixed 2026-12-05 before it ran): AJ
#: (offsets rounded to half cells, regions pulled to corners, dropped turns, false openings, wrong branches, mirrored
#: replies, uncapped legs, unparseable replies, a weak follow-up, errors growing with the turns a query spans) and AK
#: (coordinates rounded to whole cells, small regions of spread sizes pulled hard to corners, many dropped turns, false
#: openings and wrong branches often, uncapped legs, errors growing fast, a weak follow-up), beside two presets
GR_MAZES = ("gr:U_MAZE", "gr:MEDIUM_MAZE", "gr:LARGE_MAZE")
GR_MIXES = ("imperfect:moderate", "imperfect:severe",
            "imperfect:position_sigma=0.4,coord_grid=0.5,radius=0.3,radius_log_sigma=0.5,corner_pull=0.35,"
            "p_drop_turn=0.35,p_false_opening=0.3,p_wrong_branch=0.35,p_mirror_y=0.15,p_uncapped=0.6,"
            "p_unparseable=0.1,alpha=0.35,rho=0.4",
            "imperfect:position_sigma=0.25,coord_grid=1.0,radius=0.2,radius_log_sigma=0.7,corner_pull=0.5,"
            "p_drop_turn=0.5,p_false_opening=0.4,p_wrong_branch=0.45,p_uncapped=0.7,p_unparseable=0.05,"
            "alpha=0.5,rho=0.5")

#: layouts and error mixes no run had used before grid corrector-mend-new (docs/corrector.md, "Weak legs mended on the
#: roadmap"), made after corrector-deep-gr had been looked at: four larger generated mazes (sizes chosen, seeds drawn by
#: random.Random(20261205)), and two mixes: AL (offsets rounded to quarter cells, small regions pulled to corners,
#: dropped turns, false openings, wrong branches often, mirrored replies, uncapped legs, unparseable replies, a weak
#: follow-up, errors growing with the turns a query spans) and AM (coordinates rounded to half cells, regions of
#: spread sizes, many dropped turns, false openings often, wrong branches, uncapped legs, errors growing fast)
MEND_MAZES = ("random:12x11:1", "random:11x12:92", "random:13x10:52", "random:10x13:79")
MEND_MIXES = ("imperfect:position_sigma=0.4,coord_grid=0.25,radius=0.25,radius_log_sigma=0.5,corner_pull=0.45,"
              "p_drop_turn=0.35,p_false_opening=0.3,p_wrong_branch=0.45,p_mirror_y=0.15,p_uncapped=0.65,"
              "p_unparseable=0.1,alpha=0.4,rho=0.4",
              "imperfect:position_sigma=0.35,coord_grid=0.5,radius=0.3,radius_log_sigma=0.7,corner_pull=0.3,"
              "p_drop_turn=0.5,p_false_opening=0.4,p_wrong_branch=0.35,p_uncapped=0.7,p_unparseable=0.05,"
              "alpha=0.5,rho=0.6")

#: layouts and error mixes no run had used before grid corrector-mend-check (docs/corrector.md, "A last check of mend:
#: error kinds at their extremes"), made after mend's grids had been looked at: four larger generated mazes (sizes
#: chosen, seeds drawn by random.Random(202612051)), and four mixes, each one kind of error at its extreme over light
#: noise, where every mix before mixed all kinds at middling rates: AN (mirrored and unparseable replies), AO (tiny
#: regions pulled hard into corners), AP (hallucinated routes: most turns dropped, false openings, wrong branches,
#: errors growing with the turns a query spans) and AQ (coarse: offsets of 0.6 cell rounded to whole cells, region
#: sizes spread wide, every leg uncapped, feedback never used)
MEND_CHECK_MAZES = ("random:14x9:33", "random:9x14:57", "random:12x12:61", "random:15x8:29")
MEND_CHECK_MIXES = ("imperfect:position_sigma=0.15,p_mirror_y=0.5,p_unparseable=0.4,rho=0.5",
                    "imperfect:position_sigma=0.2,coord_grid=0.1,radius=0.15,radius_log_sigma=0.3,corner_pull=0.8",
                    "imperfect:position_sigma=0.2,p_drop_turn=0.7,p_false_opening=0.7,p_wrong_branch=0.8,alpha=0.3,"
                    "rho=0.6",
                    "imperfect:position_sigma=0.6,coord_grid=1.0,radius_log_sigma=0.8,p_uncapped=1.0,rho=0.0")

#: layouts and error mixes no run had used before grid corrector-backtrack-new (docs/corrector.md, "Ground given back"),
#: made after corrector-mend-check's mixes AN-AP had been looked at (its run at 0 informed backtrack) and before AQ's:
#: four larger generated mazes (sizes chosen, seeds drawn by random.Random(202612052)), and two mixes: AR (routes
#: that take the wrong branch or a false opening most of the time, half the turns dropped, errors growing with the
#: turns a query spans: pockets near the goal) and AS (coordinates rounded to half cells, regions pulled into corners,
#: wrong branches and dropped turns often, uncapped legs, mirrored and unparseable replies, feedback used a third of
#: the time)
BACKTRACK_MAZES = ("random:13x11:88", "random:11x13:95", "random:14x10:83", "random:10x14:79")
BACKTRACK_MIXES = ("imperfect:position_sigma=0.25,p_drop_turn=0.5,p_false_opening=0.6,p_wrong_branch=0.9,alpha=0.2,"
                   "rho=0.5",
                   "imperfect:position_sigma=0.3,coord_grid=0.5,radius=0.3,radius_log_sigma=0.4,corner_pull=0.5,"
                   "p_drop_turn=0.4,p_false_opening=0.3,p_wrong_branch=0.6,p_mirror_y=0.2,p_uncapped=0.6,"
                   "p_unparseable=0.15,alpha=0.3,rho=0.3")

#: layouts and error mixes no run had used before grid corrector-fine-new (docs/corrector.md, "Finer probes"), made
#: after corrector-backtrack-new had been looked at (its three runs at 0, all on random:14x10:83, informed fine): four
#: larger generated mazes (sizes chosen, seeds drawn by random.Random(202612053)), and two mixes: AT (wrong branches,
#: false openings and dropped turns most of the time, errors growing with the turns a query spans: long detours no
#: reply names) and AU (large offsets rounded to half cells, regions of spread sizes pulled toward corners, most turns
#: dropped, some wrong branches and false openings, uncapped legs, unparseable replies, feedback used a third of the
#: time)
FINE_MAZES = ("random:14x11:10", "random:11x14:75", "random:15x10:38", "random:12x13:64")
FINE_MIXES = ("imperfect:position_sigma=0.2,p_drop_turn=0.6,p_false_opening=0.5,p_wrong_branch=0.8,alpha=0.25,rho=0.4",
              "imperfect:position_sigma=0.45,coord_grid=0.5,radius=0.25,radius_log_sigma=0.5,corner_pull=0.4,"
              "p_drop_turn=0.55,p_false_opening=0.2,p_wrong_branch=0.3,p_uncapped=0.5,p_unparseable=0.1,alpha=0.4,"
              "rho=0.3")

#: layouts and error mixes no run had used before grid corrector-fine-check (docs/corrector.md, "Finer probes", its
#: last check), made after corrector-fine-new had been looked at and before any cell of fine's adoption grids ran: two
#: generated mazes of unusual aspect (sizes chosen, seeds drawn by random.Random(202612054)) and two of
#: Gymnasium-Robotics' maps with diverse goals (the walls of MEDIUM and LARGE, another goal), and two mixes: AV
#: (hallucinated routes read off a mirrored picture: most turns dropped, wrong branches, false openings, mirrored and
#: unparseable replies, errors growing with the turns a query spans, feedback used a third of the time) and AW (coarse
#: and deaf: large offsets rounded to whole cells, region sizes spread wide and pulled hard toward corners, wrong
#: branches often, every leg uncapped, feedback never used)
FINE_CHECK_MAZES = ("random:16x8:17", "random:8x16:4", "gr:LARGE_MAZE_DIVERSE_G", "gr:MEDIUM_MAZE_DIVERSE_GR")
FINE_CHECK_MIXES = ("imperfect:position_sigma=0.3,p_drop_turn=0.6,p_false_opening=0.5,p_wrong_branch=0.7,"
                    "p_mirror_y=0.3,p_unparseable=0.2,alpha=0.3,rho=0.3",
                    "imperfect:position_sigma=0.5,coord_grid=1.0,radius_log_sigma=0.8,corner_pull=0.6,"
                    "p_wrong_branch=0.6,p_uncapped=1.0,rho=0.0")

#: layouts no run had used before grid corrector-fine-random (docs/corrector.md, "A proposer that knows nothing"),
#: made after corrector-fine-check had been looked at: four generated mazes larger than any before (sizes chosen,
#: seeds drawn by random.Random(202612055)); that grid's one proposer is `random` (1-4 random free-space discs, deaf
#: to feedback), no error model at all
RANDOM_CHECK_MAZES = ("random:17x12:40", "random:12x17:58", "random:18x10:27", "random:15x14:40")

#: layouts and error mixes no run had used before grid corrector-span-new (docs/corrector.md, "Weak legs mended past
#: their end"), made after corrector-fine-random's suite cells had been looked at (its four weak runs informed span):
#: four generated mazes (sizes chosen, seeds drawn by random.Random(202612056)), and two proposers: the random one (no
#: route, deaf to feedback) and AX (small regions pulled toward corners, large offsets, dropped turns, wrong branches
#: and false openings, uncapped legs, errors growing with the turns a query spans, feedback used half the time)
SPAN_MAZES = ("random:13x13:48", "random:16x9:91", "random:9x16:32", "random:14x12:90")
SPAN_MIXES = ("random",
              "imperfect:position_sigma=0.4,radius=0.25,radius_log_sigma=0.4,corner_pull=0.5,p_drop_turn=0.4,"
              "p_wrong_branch=0.4,p_false_opening=0.3,p_uncapped=0.5,alpha=0.3,rho=0.5")

#: layouts and error mixes no run had used before grid corrector-span-misread (docs/corrector.md, "Misreadings no lever
#: had met"), made after every grid above had been looked at: four generated mazes (sizes chosen, seeds drawn by
#: random.Random(202612071)) and the two longest U-chains, and two mixes of the error model's misreadings, added on
#: 2026-12-07 after every lever had been designed: AY (the misreadings alone: swapped axes, a bias of a third of a cell
#: for the whole run, waypoints out of order, cut short, or the previous edge's answer again) and AZ (the same, milder,
#: on top of the moderate preset)
MISREAD_MAZES = ("random:12x12:78", "random:17x9:34", "random:9x17:21", "random:15x13:92", "u_chain_5",
                 "u_chain_5_subgoals")
MISREAD_MIXES = ("imperfect:p_swap_xy=0.15,bias=0.3,p_shuffle=0.3,p_truncate=0.3,p_stale=0.2",
                 "imperfect:moderate,p_swap_xy=0.1,bias=0.2,p_shuffle=0.2,p_truncate=0.2,p_stale=0.15")
MISREAD_CODE = "3989efc"  # the commit that added the misreadings (ImperfectConfig.p_swap_xy, ...)

#: the deaf proposer whose pilot cells informed ours-corrector-span-bridge (docs/corrector.md, "Entered another way:
#: span with the bridge"): every turn dropped, feedback never used, so each reply is the straight line capped at the
#: policy's reach
DEAF = "imperfect:p_drop_turn=1,rho=0"
#: layouts and error mixes no run had used before grid corrector-span-bridge-new, made after span-bridge's pilot: four
#: generated mazes (sizes chosen, seeds drawn by random.Random(202612072)) and two deaf mixes: BA (nearly every turn
#: dropped, feedback never used, offsets and regions pulled toward corners) and BB (half the turns dropped, feedback
#: never used, small regions, a bias for the whole run and stale replies)
SPAN_BRIDGE_MAZES = ("random:13x10:24", "random:10x13:99", "random:14x14:2", "random:16x11:5")
SPAN_BRIDGE_MIXES = ("imperfect:position_sigma=0.2,corner_pull=0.3,p_drop_turn=0.9,rho=0",
                     "imperfect:position_sigma=0.15,radius=0.25,p_drop_turn=0.6,bias=0.25,p_stale=0.3,rho=0")
SPAN_BRIDGE_CODE = "77dafe1"  # the commit of ours-corrector-span-bridge (span's settings with roadmap_bridge)
#: issue 39: the Ant's default with two deaf proposers no Ant run had used (docs/corrector.md, "A rescue for the Ant's
#: default"): the error model's deaf extreme and the random proposer; U-chain 1-3 judged, the longer ones described
RESCUE_CODE = "55dd142"  # the commit of ours-corrector-redraw-rescue (SearchConfig.rescue)
#: the code of the point mass's default run again on span's statement grids (docs/corrector.md, "The statements again,
#: with the default"): main after the rescue (55dd142), which left span-bridge's runs as they were
BRIDGE_AGAIN_CODE = "aa6b52b"
RESCUE_MAZES = ("u_chain_1", "u_chain_2", "u_chain_3")
RESCUE_LONG_MAZES = ("u_chain_2_subgoals", "u_chain_3_subgoals", "u_chain_4", "u_chain_4_subgoals", "u_chain_5",
                     "u_chain_5_subgoals")
#: issue 39: the rescue whose weak legs are judged by the path (docs/corrector.md, "Weak legs judged by the path"), on
#: the rescue grid's judged cells; its rescue twins are read from ant_rescue.csv, not run again
FLOOR_CODE = "bf93ae4"  # the commit of ours-corrector-redraw-rescue-floor (SearchConfig.roadmap_floor)

ROADMAP_CODE = "90db56e"  # the commit of ours-corrector-roadmap's code (refine/roadmap.py)
SOUND_CODE = "59178eb"  # the commit of ours-corrector-sound's code (Roadmap.sound)
MEMORY_CODE = "b8d7f64"  # the commit of ours-corrector-memory's code (Roadmap.remember)
PROBE_CODE = "fef6e19"  # the commit of ours-corrector-probe's code (Roadmap.probe)
DEEP_CODE = "d788274"  # the commit of ours-corrector-deep's code (SearchConfig.roadmap_evaluations)
MEND_CODE = "cc4f1d3"  # the commit of ours-corrector-mend's code (SearchConfig.roadmap_weak)
BACKTRACK_CODE = "e3a8950"  # the commit of ours-corrector-backtrack's code (SearchConfig.roadmap_backtrack)
FINE_CODE = "dc68dea"  # the commit of ours-corrector-fine's code (SearchConfig.roadmap_rings)
SPAN_CODE = "968b715"  # the commit of ours-corrector-span's code (SearchConfig.roadmap_span)


def six_cell_grid(name: str, section: str, method: str, **grid) -> ExperimentGrid:
    """A lever's six cells (docs/ant_experiments.md section 5): ``method`` x the oracle, stage 5, adaptive,
    U-chain 3 and 5, seeds 0-2, one sweep per seed; ``grid``: the rest of the grid (code, table, out, ...)."""
    return ExperimentGrid(name, f"docs/ant_experiments.md, section 5, {section}", "ant",
                          parts=(Part((method,), (GEOMETRIC_48,), split="seeds"),), seeds=(0, 1, 2),
                          mazes=("u_chain_3", "u_chain_5"), policy="data/policies/ant_stage5.pt",
                          evaluation="adaptive", **grid)



def corrector_variant_grid(name: str, section: str, method: str, stem: str, code: str,
                           severe_first: bool = False) -> ExperimentGrid:
    """A variant of the corrector (issue 39) on the point mass: the U-chains at mild and moderate, seeds 0-3, seed by
    seed, into data/results/corrector/STEM.csv; then the held-out layouts and mixes (seeds 0-1) into
    STEM_held_out.csv; then severe on the U-chains into STEM_severe.csv (``severe_first``: that part first)."""
    table = f"data/results/corrector/{stem}"
    severe = Part((method,), ("imperfect:severe",), mazes=SCALING_MAZES, table=f"{table}_severe.csv", out="severe")
    parts = (Part((method,), ("imperfect:mild", "imperfect:moderate"), mazes=SCALING_MAZES, split="seeds"),
             Part((method,), HELD_OUT_MIXES, seeds=(0, 1), mazes=HELD_OUT_MAZES, table=f"{table}_held_out.csv",
                  out="held_out"))
    return ExperimentGrid(
        name, f"docs/corrector.md, '{section}' (issue 39; fixed 2026-11-27 before it ran)", "point",
        parts=(severe, *parts) if severe_first else (*parts, severe), seeds=(0, 1, 2, 3), workers=1, code=code,
        table=f"{table}.csv", out=f"runs/corrector_{stem}")


def corrector_suite_grid(name: str, section: str, method: str, stem: str, code: str) -> ExperimentGrid:
    """A variant of the corrector (issue 39) on the rest of the point suite (the mazes beside the U-chains) at mild
    and moderate, seeds 0-3, into data/results/corrector/STEM_suite.csv: with its U-chains, all 17 suite mazes."""
    return ExperimentGrid(
        name, f"docs/corrector.md, '{section}' (issue 39; fixed 2026-11-27 before it ran)", "point",
        parts=(Part((method,), ("imperfect:mild", "imperfect:moderate"), mazes=OTHER_POINT_MAZES),),
        seeds=(0, 1, 2, 3), workers=1, code=code, table=f"data/results/corrector/{stem}_suite.csv",
        out=f"runs/corrector_{stem}_suite")


def fresh_grid(name: str, goal_points: str, methods: tuple) -> ExperimentGrid:
    """``methods`` under the fresh error mixes and the oracle on the fresh layouts, seeds 0-1, with ``goal_points``
    (docs/corrector.md, "Fresh layouts for the centre rule"), into data/results/corrector/GOAL_POINTS_fresh*.csv."""
    table = f"data/results/corrector/{goal_points}_fresh"
    return ExperimentGrid(
        name, "docs/corrector.md, 'Fresh layouts for the centre rule' (issue 39; fixed 2026-11-28 before it ran)",
        "point", parts=(Part(methods, FRESH_MIXES, split="proposers"),
                        Part(("ours",), ("geometric",), table=f"{table}_oracle.csv", out="oracle")),
        seeds=(0, 1), mazes=FRESH_MAZES, goal_points=goal_points, workers=1, code="809c7f3", table=f"{table}.csv",
        out=f"runs/{name.replace('-', '_')}")


def informed_on(method: str, stem: str, mazes: tuple, mixes: tuple, on: str) -> Part:
    """``method`` on the cells of study ``on`` (seeds 0-1), those that informed it, into
    data/results/corrector/STEM_ON.csv."""
    return Part((method,), mixes, seeds=(0, 1), mazes=mazes, table=f"data/results/corrector/{stem}_{on}.csv", out=on)


def centre_variant_grids(name: str, section: str, method: str, stem: str, code: str, informed: Part | None = None,
                         fixed: str = "2026-11-28") -> tuple[ExperimentGrid, ExperimentGrid]:
    """A variant of the corrector at centre goal points (issue 39, docs/corrector.md SECTION): grid NAME, ``informed``
    (the cells that informed it, if any) then severe on the U-chains (STEM_severe.csv) then mild and moderate seed by
    seed (STEM.csv); grid NAME-suite, the other 8 suite mazes at mild and moderate (STEM_suite.csv), then the held-out
    cells (STEM_held_out.csv)."""
    table = f"data/results/corrector/{stem}"
    doc = f"docs/corrector.md, '{section}' (issue 39; fixed {fixed} before it"
    u_chains = (Part((method,), ("imperfect:severe",), mazes=SCALING_MAZES, table=f"{table}_severe.csv", out="severe"),
                Part((method,), ("imperfect:mild", "imperfect:moderate"), mazes=SCALING_MAZES, split="seeds"))
    suite = (Part((method,), ("imperfect:mild", "imperfect:moderate"), mazes=OTHER_POINT_MAZES),
             Part((method,), HELD_OUT_MIXES, seeds=(0, 1), mazes=HELD_OUT_MAZES, table=f"{table}_held_out.csv",
                  out="held_out"))
    common = dict(seeds=(0, 1, 2, 3), goal_points="centre", workers=1, code=code)
    return (ExperimentGrid(name, f"{doc} ran)", "point", parts=(*([informed] if informed else []), *u_chains),
                           table=f"{table}.csv", out=f"runs/{name.replace('-', '_')}", **common),
            ExperimentGrid(f"{name}-suite", f"{doc} ran)", "point", parts=suite, table=f"{table}_suite.csv",
                           out=f"runs/{name.replace('-', '_')}_suite", **common))


def new_layouts_grid(name: str, source: str, methods: tuple, mazes: tuple, mixes: tuple, stem: str, code: str
                     ) -> ExperimentGrid:
    """``methods`` on generated layouts and error mixes no run had used (issue 39, docs/corrector.md), seeds 0-1,
    centre goal points, into data/results/corrector/STEM.csv, and the oracle on the same layouts (STEM_oracle.csv)."""
    table = f"data/results/corrector/{stem}"
    return ExperimentGrid(name, source, "point",
                          parts=(Part(methods, mixes, split="proposers"),
                                 Part(("ours",), ("geometric",), table=f"{table}_oracle.csv", out="oracle")),
                          seeds=(0, 1), mazes=mazes, goal_points="centre", workers=1, code=code, table=f"{table}.csv",
                          out=f"runs/{name.replace('-', '_')}")


def default_oracle_grid(name: str, section: str, method: str, stem: str, code: str, fixed: str = "2026-12-05"
                        ) -> ExperimentGrid:
    """``method`` and ours with the oracle on the 17 suite mazes, seeds 0-3, centre goal points (issue 39: the point
    mass's default rule, docs/corrector.md SECTION), into data/results/corrector/STEM_oracle.csv."""
    return ExperimentGrid(name, f"docs/corrector.md, '{section}' (issue 39; fixed {fixed} before it ran): {method} "
                          "and ours with the oracle on the 17 suite mazes", "point",
                          parts=(Part((method, "ours"), ("geometric",), split="seeds"),),
                          seeds=(0, 1, 2, 3), mazes=SCALING_MAZES + OTHER_POINT_MAZES, goal_points="centre", workers=1,
                          code=code, table=f"data/results/corrector/{stem}_oracle.csv",
                          out=f"runs/{name.replace('-', '_')}")


def bridge_again_grid(statement: str, mazes: tuple, mixes: tuple, seeds: tuple) -> ExperimentGrid:
    """The point mass's default, span-bridge, alone on the cells of span's statement grid corrector-span-STATEMENT
    (docs/corrector.md, "The statements again, with the default"), into data/results/corrector/
    span_bridge_STATEMENT.csv; ``ours`` and the oracle stay span's grid's."""
    return ExperimentGrid(f"corrector-span-bridge-{statement}", "docs/corrector.md, 'The statements again, with the "
                          "default' (issue 39; fixed 2026-12-07 before it ran): ours-corrector-span-bridge on "
                          f"corrector-span-{statement}'s cells", "point",
                          parts=(Part(("ours-corrector-span-bridge",), mixes, split="proposers"),), seeds=seeds,
                          mazes=mazes, goal_points="centre", workers=1, code=BRIDGE_AGAIN_CODE,
                          table=f"data/results/corrector/span_bridge_{statement}.csv",
                          out=f"runs/corrector_span_bridge_{statement}")


def ant_corrector_grid(name: str, source: str, stem: str, code: str, method: str = "ours-corrector",
                       split_pick: str | None = None) -> ExperimentGrid:
    """``method`` on the Ant (issue 39): the U-chains at imperfect:moderate, seeds 0-2 seed by seed, stage 5,
    adaptive evaluation, centre goal points, into data/results/corrector/STEM.csv. ``split_pick``: what a code whose
    preset decides it runs (its cell ids name it), None for a code before the option."""
    part = Part((method,), ("imperfect:moderate",), split="seeds")
    return ExperimentGrid(name, source, "ant", parts=(part,), seeds=(0, 1, 2), mazes=SCALING_MAZES,
                          policy="data/policies/ant_stage5.pt", evaluation="adaptive", goal_points="centre",
                          split_pick=split_pick, workers=1, code=code,
                          table=f"data/results/corrector/{stem}.csv", out=f"runs/{name.replace('-', '_')}")


def ant_oracle_grid(name: str, source: str, method: str, stem: str, code: str, mazes: tuple = SCALING_MAZES,
                    split_pick: str | None = None) -> ExperimentGrid:
    """``method`` x the oracle on the Ant (issue 42): ``mazes`` (the U-chains), seeds 0-2 seed by seed, stage 5,
    adaptive evaluation, centre goal points, into data/results/ant/STEM.csv. ``split_pick``: as ant_corrector_grid's."""
    return ExperimentGrid(name, source, "ant", parts=(Part((method,), (GEOMETRIC_48,), split="seeds"),),
                          seeds=(0, 1, 2), mazes=mazes, policy="data/policies/ant_stage5.pt",
                          evaluation="adaptive", goal_points="centre", split_pick=split_pick, workers=1, code=code,
                          table=f"data/results/ant/{stem}.csv", out=f"runs/{name.replace('-', '_')}")


GRIDS = {g.name: g for g in (
    ExperimentGrid(
        "paper-sweep", "data/results/README.md, the point sweep (the paper's Figures 4-6)", "point",
        parts=(Part(("dirl", "symbolic", "vlm-oneshot", "ours"), ("geometric", "random")),), seeds=(0, 1, 2, 3),
        code="d712821", table="data/results/results.csv", out="runs/sweep_full"),
    ExperimentGrid(
        "ant-uchain-stage3", "docs/ant_experiments.md, section 2 (stage 3; restarted as ant-comparison)", "ant",
        parts=(Part(("ours",), ("geometric",)),), seeds=(0, 1, 2), mazes=U_CHAINS + SUBGOALS, evaluation="adaptive",
        workers=1, code="9031f3b", table="data/results/ant/uchain.csv", out="runs/ant_uchain"),
    ExperimentGrid(
        "point-comparison", "docs/proposers.md, 'The comparison' and 'The controls, redefined'", "point",
        parts=(Part(("ours", "ours-nosearchvertex", "ours-d1", "vlm-oneshot", "vlm-oneshot-matched"), IMPERFECT),
               Part(CONTROLS, IMPERFECT, split="methods")),
        seeds=(0, 1, 2, 3), code="309875a", table="data/results/imperfect/results.csv",
        out="runs/imperfect_comparison", claim_methods=(
            "ours", "ours-novertex", "ours-nosearchvertex", "ours-notune", "ours-nofeedback", "ours-d1",
            "vlm-oneshot", "vlm-oneshot-matched"),
        figure_methods=("ours", "ours-novertex", "ours-nosearchvertex", "ours-notune", "ours-nofeedback", "ours-d1",
                        "vlm-oneshot", "vlm-oneshot-matched"),
        levels=IMPERFECT[:3], contrasts=(("vlm-oneshot-matched", "vlm-oneshot"), ("ours", "ours-novertex"),
                                         ("ours", "ours-nosearchvertex"), ("ours", "ours-notune"),
                                         ("ours", "ours-nofeedback"), ("ours", "ours-d1"))),
    ExperimentGrid(
        "controls", "docs/proposers.md, 'The controls, redefined' (issue 27)", "point",
        parts=(Part(CONTROLS, IMPERFECT, split="methods"),), seeds=(0, 1, 2, 3), code="309875a",
        table="data/results/controls/results.csv", out="runs/controls"),
    ExperimentGrid(
        "repair", "docs/proposers.md, 'Look-ahead repair'", "point",
        parts=(Part(("ours", "ours-repair", "vlm-oneshot"),
                    ("imperfect:moderate", "imperfect:severe", "imperfect:mild"), split="proposers"),),
        seeds=(0, 1, 2, 3), workers=1, code="410997e", table="data/results/repair/results.csv", out="runs/repair",
        claim_methods=("ours", "ours-repair", "vlm-oneshot"), levels=IMPERFECT[:3]),
    ExperimentGrid(
        "repair-tuned", "docs/proposers.md, 'Tuning a repaired chain'", "point",
        parts=(Part(("ours-repair", "ours-repair-tuned"), ("imperfect:moderate", "imperfect:severe"),
                    split="proposers"),),
        seeds=(0, 1, 2, 3), workers=1, code="e72df7a", table="data/results/repair/tuned.csv", out="runs/repair_tuned"),
    ExperimentGrid(
        "ant-comparison", "docs/ant_experiments.md, sections 2, 3 and 3a", "ant",
        parts=(Part(("ours",), ("geometric",), mazes=U_CHAINS + SUBGOALS),
               Part(("dirl", "symbolic", "vlm-oneshot", "ours"), ("geometric", "imperfect:moderate"), split="seeds")),
        seeds=(0, 1, 2), policy="data/policies/ant_stage4.pt", policy_in_checkout=True, evaluation="adaptive",
        code="92ee10e", table="data/results/ant/comparison.csv", out="runs/ant_comparison",
        claim_methods=("ours", "vlm-oneshot"), figure_methods=("dirl", "symbolic", "vlm-oneshot", "ours")),
    ExperimentGrid(
        "ant-levers", "docs/ant_experiments.md, section 4 (issue 30)", "ant",
        parts=tuple(part for maze in ("u_chain_3", "u_chain_5") for part in (
            Part(("ours",), ("geometric",), mazes=(maze,), policy="data/policies/ant_stage4_heading.pt",
                 table="data/results/ant/levers_heading.csv", out="heading"),
            Part(("ours-shortcut",), ("geometric",), mazes=(maze,), table="data/results/ant/levers_shortcut.csv",
                 out="shortcut"),
            Part(("ours-repair",), ("imperfect:moderate",), mazes=(maze,),
                 table="data/results/ant/levers_repair.csv", out="repair"))),
        seeds=(0, 1, 2), policy="data/policies/ant_stage4.pt", evaluation="adaptive", code="5476420",
        out="runs/ant_levers"),
    ExperimentGrid(
        "ant-levers-stage5", "docs/ant_experiments.md, section 4, 'Stage 5'", "ant",
        parts=(Part(("ours",), ("geometric",), mazes=("u_chain_3", "u_chain_5"), split="mazes"),),
        seeds=(0, 1, 2), policy="data/policies/ant_stage5.pt", evaluation="adaptive", code="03f2f78",
        table="data/results/ant/levers_stage5.csv", out="runs/ant_levers/stage5"),
    ExperimentGrid(
        "ant-scaling", "docs/ant_experiments.md, section 5", "ant",
        parts=(Part(("ours",), (GEOMETRIC_48,), split="seeds", table="data/results/ant/scaling/ours_geometric.csv",
                    out="ours_geometric"),
               Part(("vlm-oneshot",), (GEOMETRIC_48, "imperfect:moderate"),
                    table="data/results/ant/scaling/oneshot.csv", out="oneshot"),
               Part(("ours", "ours-repair"), ("imperfect:moderate",), split="seeds",
                    table="data/results/ant/scaling/imperfect.csv", out="imperfect"),
               Part(("ours-repair",), (GEOMETRIC_48,), table="data/results/ant/scaling/repair_geometric.csv",
                    out="repair_geometric")),
        seeds=(0, 1, 2), mazes=SCALING_MAZES, policy="data/policies/ant_stage5.pt",
        evaluation="adaptive", code="fc93db3", out="runs/ant_scaling"),
    six_cell_grid("ant-polish", "'Lever E'", "ours-polish", code="1242800", table="data/results/ant/polish.csv",
                  out="runs/ant_polish"),
    six_cell_grid("ant-centre", "'Lever G'", "ours", goal_points="centre", code="d3488cc",
                  table="data/results/ant/centre.csv", out="runs/ant_centre"),
    ExperimentGrid(
        "ant-scaling-centre", "docs/ant_experiments.md, section 5, 'Lever G' (run only if it helps)", "ant",
        parts=(Part(("ours",), (GEOMETRIC_48,), split="seeds", mazes=("u_chain_1", "u_chain_2", "u_chain_2_subgoals",
                                                                      "u_chain_3_subgoals", "u_chain_4",
                                                                      "u_chain_4_subgoals", "u_chain_5_subgoals"),
                    table="data/results/ant/scaling/ours_centre.csv", out="ours_centre"),
               Part(("vlm-oneshot",), (GEOMETRIC_48, "imperfect:moderate"),
                    table="data/results/ant/scaling/oneshot_centre.csv", out="oneshot_centre"),
               Part(("ours", "ours-repair"), ("imperfect:moderate",), split="seeds",
                    table="data/results/ant/scaling/imperfect_centre.csv", out="imperfect_centre"),
               Part(("ours-repair",), (GEOMETRIC_48,), table="data/results/ant/scaling/repair_geometric_centre.csv",
                    out="repair_geometric_centre")),
        seeds=(0, 1, 2), mazes=SCALING_MAZES, policy="data/policies/ant_stage5.pt", evaluation="adaptive",
        goal_points="centre", code="d3488cc", out="runs/ant_scaling_centre"),
    six_cell_grid("ant-shortcut-centre", "'On top of Lever G'", "ours-shortcut", goal_points="centre",
                  code="d3488cc", table="data/results/ant/shortcut_centre.csv", out="runs/ant_shortcut_centre"),
    ExperimentGrid(
        "ant-rotated-centre", "docs/ant_experiments.md, section 5, 'Held out: the adopted settings travelling west'",
        "ant", parts=(Part(("ours",), (GEOMETRIC_48,)),), seeds=(0, 1, 2),
        mazes=("data/mazes/held_out/u_chain_3_rotated.maze",), policy="data/policies/ant_stage5.pt",
        evaluation="adaptive", goal_points="centre", workers=1, code="ba73885",  # complete; rows renamed at 4ff4cf0
        table="data/results/ant/rotated_centre.csv", out="runs/ant_rotated_centre"),
    ExperimentGrid(
        "ant-polish-erring", "docs/ant_experiments.md, section 5, 'Lever E with the erring proposer'", "ant",
        parts=(Part(("ours-polish",), ("imperfect:moderate",), split="seeds"),), seeds=(0, 1, 2),
        mazes=("u_chain_3", "u_chain_4"), policy="data/policies/ant_stage5.pt", evaluation="adaptive",
        goal_points="centre", code="d3488cc", table="data/results/ant/polish_erring.csv",
        out="runs/ant_polish_erring"),
    six_cell_grid("ant-shortcut-centre-ties", "'B with G, the tie fixed'", "ours-shortcut", goal_points="centre",
                  code="75e52f5", table="data/results/ant/shortcut_centre_ties.csv",
                  out="runs/ant_shortcut_centre_ties"),
    ExperimentGrid(
        "antmaze", "docs/official_env.md, 'The AntMaze grid' (issue 28)", "ant",
        parts=(Part(("dirl", "vlm-oneshot", "ours"), ("geometric", "imperfect:moderate")),),
        seeds=(0, 1, 2), mazes=("gr:U_MAZE", "gr:MEDIUM_MAZE", "gr:LARGE_MAZE"), policy="data/policies/ant_stage5.pt",
        policy_in_checkout=True, evaluation="adaptive", episodes=200, table="data/results/ant/antmaze.csv",
        out="runs/antmaze", code="59e5b8d"),
    ExperimentGrid(
        "antmaze-centre", "docs/official_env.md, 'The AntMaze grid': the best Ant method of the scaling work", "ant",
        parts=(Part(("ours",), ("geometric", "imperfect:moderate")),), seeds=(0, 1, 2),
        mazes=("gr:U_MAZE", "gr:MEDIUM_MAZE", "gr:LARGE_MAZE"), policy="data/policies/ant_stage5.pt",
        policy_in_checkout=True, evaluation="adaptive", episodes=200, goal_points="centre",
        table="data/results/ant/antmaze_centre.csv", out="runs/antmaze_centre", code="d3488cc"),
    ExperimentGrid(
        "antmaze-default", "docs/official_env.md, 'The AntMaze maps at the default settings' (issue 42; fixed "
        "2026-12-04 20:00 UTC before its first cell ran)", "ant", parts=(Part(("ours",), ("geometric",)),),
        seeds=(0, 1, 2), mazes=("gr:U_MAZE", "gr:MEDIUM_MAZE", "gr:LARGE_MAZE"), policy="data/policies/ant_stage5.pt",
        policy_in_checkout=True, evaluation="adaptive", episodes=200, goal_points="centre", split_pick="confirmed",
        code="615bfaa", table="data/results/ant/antmaze_default.csv", out="runs/antmaze_default"),
    ExperimentGrid(
        "taxonomy", "docs/corrector.md, 'The failure taxonomy' (issue 39; fixed 2026-11-27 before it ran)", "point",
        parts=(Part(("ours",), ("geometric",), table="data/results/corrector/taxonomy_oracle.csv", out="oracle"),
               Part(("ours", "ours-repair"), IMPERFECT[:3], split="proposers")),
        seeds=(0, 1, 2, 3), workers=1, code="ceaa05f", table="data/results/corrector/taxonomy.csv",
        out="runs/taxonomy"),
    ExperimentGrid(
        "corrector", "docs/corrector.md, 'The grids' (issue 39; fixed 2026-11-27 before its first cell ran)", "point",
        parts=(Part(("ours-corrector", "vlm-oneshot"), ("imperfect:mild", "imperfect:moderate"), mazes=SCALING_MAZES,
                    split="proposers"),
               Part(("ours-corrector",), ("imperfect:severe",), mazes=SCALING_MAZES),
               Part(("ours-corrector",), ("imperfect:mild", "imperfect:moderate"), mazes=OTHER_POINT_MAZES)),
        seeds=(0, 1, 2, 3), workers=1, code="5356175", table="data/results/corrector/point.csv",
        out="runs/corrector"),
    ExperimentGrid(
        "corrector-held-out", "docs/corrector.md, 'Held out' (issue 39; fixed 2026-11-27 before its first cell ran)",
        "point",
        parts=(Part(("ours",), ("geometric",), table="data/results/corrector/held_out_oracle.csv", out="oracle"),
               Part(("ours", "ours-corrector"), HELD_OUT_MIXES)),
        seeds=(0, 1), mazes=HELD_OUT_MAZES, workers=1, code="5356175",
        table="data/results/corrector/held_out.csv", out="runs/corrector_held_out"),
    ExperimentGrid(
        "corrector-levers", "docs/corrector.md, 'Each lever alone' (issue 39; fixed 2026-11-27 before it ran)",
        "point", parts=(Part(("ours-deeprepair", "ours-feasible", "ours-checked"),
                             ("imperfect:mild", "imperfect:moderate"), split="proposers"),),
        seeds=(0, 1, 2, 3), mazes=("u_chain_3", "u_chain_3_subgoals", "u_chain_5", "u_chain_5_subgoals"), workers=1,
        code="722e118", table="data/results/corrector/levers.csv", out="runs/corrector_levers"),
    ExperimentGrid(
        "corrector-gated", "docs/corrector.md, 'A gate on the correction' (issue 39; fixed 2026-11-27 before it ran)",
        "point", parts=(Part(("ours-corrector-gated",), ("imperfect:mild", "imperfect:moderate"), mazes=SCALING_MAZES,
                             split="seeds"),
                        Part(("ours-corrector-gated",), HELD_OUT_MIXES, seeds=(0, 1), mazes=HELD_OUT_MAZES,
                             table="data/results/corrector/gated_held_out.csv", out="held_out")),
        seeds=(0, 1, 2, 3), workers=1, code="3e309b5", table="data/results/corrector/gated.csv",
        out="runs/corrector_gated"),
    corrector_variant_grid("corrector-lean", "Legs that earn their place", "ours-corrector-lean", "lean",
                           code="4a9804f"),
    corrector_variant_grid("corrector-precise", "A gate on a larger check", "ours-corrector-precise", "precise",
                           code="2cda42b"),
    corrector_variant_grid("corrector-precise-spread", "Chained estimates", "ours-corrector-precise",
                           "precise_spread", code="1d06a16"),
    corrector_suite_grid("corrector-precise-suite", "The whole suite", "ours-corrector-precise", "precise_spread",
                         code="1d06a16"),
    corrector_suite_grid("corrector-recheck-suite", "The whole suite", "ours-corrector-recheck", "recheck",
                         code="8a35865"),
    corrector_variant_grid("corrector-recheck", "A second pass on a fresh draw", "ours-corrector-recheck", "recheck",
                           code="8a35865"),
    corrector_variant_grid("corrector-retry", "Asked again after an empty reply", "ours-corrector-retry", "retry",
                           code="c16285c", severe_first=True),
    corrector_variant_grid("corrector-frugal", "Fewer proposer calls in the correction", "ours-corrector-frugal",
                           "frugal", code="bf8f0cc"),
    corrector_variant_grid("corrector-thrift", "Within 3x: recheck asking less", "ours-corrector-thrift", "thrift",
                           code="093a937"),
    corrector_suite_grid("corrector-thrift-suite", "Within 3x: recheck asking less", "ours-corrector-thrift", "thrift",
                         code="093a937"),
    corrector_variant_grid("corrector-polish", "Polished before corrected", "ours-corrector-polish", "polish",
                           code="5123ff7"),
    corrector_suite_grid("corrector-polish-suite", "Polished before corrected", "ours-corrector-polish", "polish",
                         code="5123ff7"),
    ExperimentGrid(
        "corrector-centre", "docs/corrector.md, 'Aimed at the centre' (issue 39; fixed 2026-11-28 before it ran)",
        "point",
        parts=(Part(("ours-corrector-polish",), ("imperfect:mild", "imperfect:moderate"), mazes=SCALING_MAZES,
                    split="seeds"),
               Part(("ours", "vlm-oneshot"), ("imperfect:mild", "imperfect:moderate"), mazes=SCALING_MAZES,
                    split="proposers"),
               Part(("ours",), ("geometric",), mazes=SCALING_MAZES),
               Part(("ours-corrector-polish", "ours-repair"), ("imperfect:severe",), mazes=SCALING_MAZES,
                    table="data/results/corrector/centre_severe.csv", out="severe"),
               # added 2026-11-28 after the parts above ran, before it ran: ours at severe, for the cost rule's pairs
               Part(("ours",), ("imperfect:severe",), mazes=SCALING_MAZES,
                    table="data/results/corrector/centre_severe.csv", out="severe")),
        seeds=(0, 1, 2, 3), goal_points="centre", workers=1, code="809c7f3",
        table="data/results/corrector/centre.csv", out="runs/corrector_centre"),
    ExperimentGrid(
        "corrector-centre-suite", "docs/corrector.md, 'Aimed at the centre' (issue 39; fixed 2026-11-28 before it "
        "ran)", "point",
        parts=(Part(("ours-corrector-polish", "ours"), ("imperfect:mild", "imperfect:moderate"),
                    mazes=OTHER_POINT_MAZES, split="proposers"),
               Part(("ours-corrector-polish", "ours"), HELD_OUT_MIXES, seeds=(0, 1), mazes=HELD_OUT_MAZES,
                    table="data/results/corrector/centre_held_out.csv", out="held_out"),
               Part(("ours",), ("geometric",), seeds=(0, 1), mazes=HELD_OUT_MAZES,
                    table="data/results/corrector/centre_held_out_oracle.csv", out="held_out_oracle")),
        seeds=(0, 1, 2, 3), goal_points="centre", workers=1, code="809c7f3",
        table="data/results/corrector/centre_suite.csv", out="runs/corrector_centre_suite"),
    fresh_grid("corrector-centre-fresh", "centre", ("ours-corrector-polish", "ours")),
    fresh_grid("corrector-sampled-fresh", "sampled", ("ours-corrector-polish",)),
    # docs/corrector.md, "Corrected until alive" (fixed 2026-11-28 03:18 UTC, before any cell but its pilot ran)
    ExperimentGrid(
        "corrector-persist-new", "docs/corrector.md, 'Corrected until alive' (issue 39; fixed 2026-11-28 before it "
        "ran): polish and persist on layouts and mixes no run had used", "point",
        parts=(Part(("ours-corrector-persist", "ours-corrector-polish", "ours"), NEW_MIXES, split="proposers"),
               Part(("ours",), ("geometric",), table="data/results/corrector/persist_new_oracle.csv", out="oracle")),
        seeds=(0, 1), mazes=NEW_MAZES, goal_points="centre", workers=1, code="ebc78e2",
        table="data/results/corrector/persist_new.csv", out="runs/corrector_persist_new"),
    *centre_variant_grids("corrector-persist", "Corrected until alive", "ours-corrector-persist", "persist",
                          code="ebc78e2"),
    # docs/corrector.md, "Snapped out of the wall" (fixed 2026-11-28 03:31 UTC, before any cell but its pilot ran)
    new_layouts_grid("corrector-snap-new", "docs/corrector.md, 'Snapped out of the wall' (issue 39; fixed 2026-11-28 "
                     "before it ran): snap, persist, polish and ours on layouts and mixes no run had used",
                     ("ours-corrector-snap", "ours-corrector-persist", "ours-corrector-polish", "ours"), SNAP_MAZES,
                     SNAP_MIXES, "snap_new", code="8d73398"),
    *centre_variant_grids("corrector-snap", "Snapped out of the wall", "ours-corrector-snap", "snap", code="8d73398",
                          informed=informed_on("ours-corrector-snap", "snap", NEW_MAZES, NEW_MIXES, "persist_new")),
    # docs/corrector.md, "A last check on layouts and mixes no run had used" (fixed 2026-11-28 04:48 UTC, before it ran)
    ExperimentGrid(
        "corrector-snap-check", "docs/corrector.md, 'A last check on layouts and mixes no run had used' (issue 39; "
        "fixed 2026-11-28 after snap's adoption, before it ran)", "point",
        parts=(Part(("ours-corrector-snap", "ours"), CHECK_MIXES, split="proposers"),
               Part(("ours",), ("geometric",), table="data/results/corrector/snap_check_oracle.csv", out="oracle")),
        seeds=(0, 1), mazes=CHECK_MAZES, goal_points="centre", workers=1, code="8d73398",
        table="data/results/corrector/snap_check.csv", out="runs/corrector_snap_check"),
    # docs/corrector.md, "A budget that grows where the run would end at 0" (fixed 2026-11-28 06:50 UTC, before it ran)
    new_layouts_grid("corrector-extend-new", "docs/corrector.md, 'A budget that grows where the run would end at 0' "
                     "(issue 39; fixed 2026-11-28 before it ran)", ("ours-corrector-extend", "ours-corrector-snap",
                                                                    "ours"), EXTEND_MAZES, EXTEND_MIXES, "extend_new",
                     code="1fa15b9"),
    *centre_variant_grids("corrector-extend", "A budget that grows where the run would end at 0",
                          "ours-corrector-extend", "extend", code="1fa15b9",
                          informed=informed_on("ours-corrector-extend", "extend", CHECK_MAZES, CHECK_MIXES, "check")),
    # docs/corrector.md, "A declined split kept where the path is dead" (fixed 2026-11-28 07:15 UTC, before it ran)
    new_layouts_grid("corrector-keep-new", "docs/corrector.md, 'A declined split kept where the path is dead' (issue "
                     "39; fixed 2026-11-28 before it ran)", ("ours-corrector-keep", "ours-corrector-snap", "ours"),
                     KEEP_MAZES, KEEP_MIXES, "keep_new", code="fe494db"),
    *centre_variant_grids("corrector-keep", "A declined split kept where the path is dead", "ours-corrector-keep",
                          "keep", code="fe494db",
                          informed=informed_on("ours-corrector-keep", "keep",
                                               EXTEND_MAZES, EXTEND_MIXES, "extend_new")),
    # docs/corrector.md, "Given up at half the budget" (fixed 2026-11-28 07:20 UTC, before it ran)
    new_layouts_grid("corrector-fallback-new", "docs/corrector.md, 'Given up at half the budget' (issue 39; fixed "
                     "2026-11-28 before it ran)", ("ours-corrector-fallback", "ours-corrector-snap",
                                                   "ours-corrector-keep", "ours"), FALLBACK_MAZES, FALLBACK_MIXES,
                     "fallback_new", code="c6a590c"),
    *centre_variant_grids("corrector-fallback", "Given up at half the budget", "ours-corrector-fallback", "fallback",
                          code="c6a590c",
                          informed=informed_on("ours-corrector-fallback", "fallback",
                                               KEEP_MAZES, KEEP_MIXES, "keep_new")),
    # docs/corrector.md, "Ground kept where the path is dead" (fixed 2026-11-28 09:23 UTC, before it ran)
    new_layouts_grid("corrector-advance-new", "docs/corrector.md, 'Ground kept where the path is dead' (issue 39; "
                     "fixed 2026-11-28 before it ran)", ("ours-corrector-advance-extend", "ours-corrector-advance",
                                                         "ours-corrector-snap", "ours"), ADVANCE_MAZES, ADVANCE_MIXES,
                     "advance_new", code="66e5948"),
    *centre_variant_grids("corrector-advance", "Ground kept where the path is dead", "ours-corrector-advance-extend",
                          "advance", code="66e5948",
                          informed=informed_on("ours-corrector-advance-extend", "advance",
                                               FALLBACK_MAZES, FALLBACK_MIXES, "fallback_new")),
    # docs/corrector.md, "A last check after advance-extend's adoption" (fixed 2026-11-28 10:07 UTC, before it ran)
    new_layouts_grid("corrector-advance-check", "docs/corrector.md, 'A last check after advance-extend's adoption' "
                     "(issue 39; fixed 2026-11-28 before it ran)", ("ours-corrector-advance-extend",
                                                                    "ours-corrector-snap", "ours"),
                     ADVANCE_CHECK_MAZES, ADVANCE_CHECK_MIXES, "advance_check", code="66e5948"),
    # docs/corrector.md, "Replies pooled into a roadmap" (fixed 2026-11-29 05:40 UTC, before its grids ran)
    new_layouts_grid("corrector-roadmap-new", "docs/corrector.md, 'Replies pooled into a roadmap' (issue 39; fixed "
                     "2026-11-29 before it ran)", ("ours-corrector-roadmap", "ours-corrector-advance-extend",
                                                   "ours-corrector-snap", "ours"), ROADMAP_MAZES, ROADMAP_MIXES,
                     "roadmap_new", code=ROADMAP_CODE),
    *centre_variant_grids("corrector-roadmap", "Replies pooled into a roadmap", "ours-corrector-roadmap", "roadmap",
                          code=ROADMAP_CODE,
                          informed=informed_on("ours-corrector-roadmap", "roadmap",
                                               ADVANCE_CHECK_MAZES, ADVANCE_CHECK_MIXES, "advance_check"),
                          fixed="2026-11-29"),
    # docs/corrector.md, "A last check after roadmap's adoption" (fixed 2026-11-29 06:40 UTC, before it ran)
    new_layouts_grid("corrector-roadmap-check", "docs/corrector.md, 'A last check after roadmap's adoption' (issue 39; "
                     "fixed 2026-11-29 before it ran)", ("ours-corrector-roadmap", "ours-corrector-advance-extend",
                                                         "ours"), ROADMAP_CHECK_MAZES, ROADMAP_CHECK_MIXES,
                     "roadmap_check", code=ROADMAP_CODE),
    # docs/corrector.md, "Sound legs for the roadmap" (fixed 2026-11-29 08:28 UTC, before its grids ran)
    new_layouts_grid("corrector-sound-new", "docs/corrector.md, 'Sound legs for the roadmap' (issue 39; fixed "
                     "2026-11-29 before it ran)", ("ours-corrector-sound", "ours-corrector-roadmap", "ours"),
                     SOUND_MAZES, SOUND_MIXES, "sound_new", code=SOUND_CODE),
    *centre_variant_grids("corrector-sound", "Sound legs for the roadmap", "ours-corrector-sound", "sound",
                          code=SOUND_CODE,
                          informed=informed_on("ours-corrector-sound", "sound",
                                               ROADMAP_CHECK_MAZES, ROADMAP_CHECK_MIXES, "roadmap_check"),
                          fixed="2026-11-29"),
    # docs/corrector.md, "A roadmap that remembers" (fixed 2026-11-29 11:50 UTC, before its grids ran)
    new_layouts_grid("corrector-memory-new", "docs/corrector.md, 'A roadmap that remembers' (issue 39; fixed "
                     "2026-11-29 before it ran)", ("ours-corrector-memory", "ours-corrector-roadmap", "ours"),
                     MEMORY_MAZES, MEMORY_MIXES, "memory_new", code=MEMORY_CODE),
    *centre_variant_grids("corrector-memory", "A roadmap that remembers", "ours-corrector-memory", "memory",
                          code=MEMORY_CODE,
                          informed=informed_on("ours-corrector-memory", "memory",
                                               SOUND_MAZES, SOUND_MIXES, "sound_new"),
                          fixed="2026-11-29"),
    # docs/corrector.md, "Probes from the nearest node" (fixed 2026-11-29 13:10 UTC, before its grids ran)
    new_layouts_grid("corrector-probe-new", "docs/corrector.md, 'Probes from the nearest node' (issue 39; fixed "
                     "2026-11-29 before it ran)", ("ours-corrector-probe", "ours-corrector-memory",
                                                   "ours-corrector-roadmap", "ours"),
                     PROBE_MAZES, PROBE_MIXES, "probe_new", code=PROBE_CODE),
    *centre_variant_grids("corrector-probe", "Probes from the nearest node", "ours-corrector-probe", "probe",
                          code=PROBE_CODE,
                          informed=informed_on("ours-corrector-probe", "probe",
                                               MEMORY_MAZES, MEMORY_MIXES, "memory_new"),
                          fixed="2026-11-29"),
    # docs/corrector.md, "Longer searches for the probes" (fixed 2026-11-29 15:23 UTC, before its grids ran)
    new_layouts_grid("corrector-deep-new", "docs/corrector.md, 'Longer searches for the probes' (issue 39; fixed "
                     "2026-11-29 before it ran)", ("ours-corrector-deep", "ours-corrector-probe", "ours"),
                     DEEP_MAZES, DEEP_MIXES, "deep_new", code=DEEP_CODE),
    *centre_variant_grids("corrector-deep", "Longer searches for the probes", "ours-corrector-deep", "deep",
                          code=DEEP_CODE,
                          informed=informed_on("ours-corrector-deep", "deep", PROBE_MAZES, PROBE_MIXES, "probe_new"),
                          fixed="2026-11-29"),
    # docs/corrector.md, "A last check of deep" (fixed 2026-12-01 23:20 UTC, committed 23:23, before it ran)
    new_layouts_grid("corrector-deep-check", "docs/corrector.md, 'A last check of deep' (issue 39; fixed 2026-12-01 "
                     "before it ran)", ("ours-corrector-deep", "ours-corrector-probe", "ours"),
                     DEEP_CHECK_MAZES, DEEP_CHECK_MIXES, "deep_check", code=DEEP_CODE),
    corrector_variant_grid("corrector-trim", "The larger check and the lean rule together", "ours-corrector-trim",
                           "trim", code="57aa840"),
    ant_corrector_grid("ant-corrector", "docs/corrector.md, 'The Ant' (issue 39; fixed 2026-11-27 before its first "
                       "cell ran)", "ant", code="5356175"),
    ant_corrector_grid("ant-corrector-spread", "docs/corrector.md, 'Chained estimates' (issue 39; fixed 2026-11-27 "
                       "before its first cell ran): ant-corrector's cells at the code with spread start states",
                       "ant_spread", code="1d06a16"),
    ant_corrector_grid("ant-corrector-confirm", "docs/corrector.md, 'The Ant with a confirmed pick' (issue 39; fixed "
                       "2026-11-27 19:55 UTC before its first cell ran)", "ant_confirm", code="c463c3e",
                       method="ours-corrector-confirm"),
    ant_corrector_grid("ant-corrector-reaim", "docs/corrector.md, 'Aimed clear of the walls: the Ant' (issue 39; "
                       "fixed 2026-12-02 03:57 UTC before its first cell ran; one confirm cell's pilot informed it): "
                       "ant-corrector-confirm's cells with the re-aim", "ant_reaim", code="dee7bc8",
                       method="ours-corrector-reaim", split_pick="confirmed"),  # the Ant's default there
    ant_corrector_grid("ant-corrector-redraw", "docs/corrector.md, 'A second draw for the Ant' (issue 39; fixed "
                       "2026-12-02 08:30 UTC before its first cell ran; one confirm cell's pilot informed it): "
                       "ant-corrector-confirm's cells with a second correction pass on a fresh draw", "ant_redraw",
                       code="96e357e", method="ours-corrector-redraw", split_pick="confirmed"),
    ant_corrector_grid("ant-corrector-sparing", "docs/corrector.md, 'A gate for the Ant's corrector' (issue 39; fixed "
                       "2026-12-05 03:30 UTC before its first cell ran; two of redraw's step logs informed it): "
                       "ant-corrector-redraw's cells with the correction's proposer gated at 3 fresh failures",
                       "ant_sparing", code="d0214b6", method="ours-corrector-sparing", split_pick="confirmed"),
    ant_corrector_grid("ant-corrector-sparing-frugal", "docs/corrector.md, 'Sparing and frugal: the Ant' (issue 39; "
                       "fixed 2026-12-05 06:23 UTC before its first cell ran; the same two step logs informed it): "
                       "ant-corrector-redraw's cells with sparing's gate and frugal's asking",
                       "ant_sparing_frugal", code="08bb143", method="ours-corrector-sparing-frugal",
                       split_pick="confirmed"),
    ant_corrector_grid("ant-corrector-wide", "docs/corrector.md, 'The wide pass with an erring proposer' (issues 39 "
                       "and 42; fixed 2026-12-05 06:48 UTC when ant-oracle-wide-scaling's rule 2 held, before its "
                       "first cell ran): ant-corrector-redraw's cells with lever 8's wide pass", "ant_wide",
                       code="adda718", method="ours-corrector-wide", split_pick="confirmed"),
    ExperimentGrid(
        "ant-corrector-rescue", "docs/corrector.md, 'A rescue for the Ant's default' (issue 39; fixed 2026-12-07 11:48 "
        "UTC before its first cell ran; one pilot cell informed it): redraw and its rescue with two deaf proposers",
        "ant", parts=(Part(("ours-corrector-redraw-rescue", "ours-corrector-redraw"), (DEAF, "random")),
                      Part(("ours-corrector-redraw-rescue", "ours-corrector-redraw"), (DEAF, "random"),
                           mazes=RESCUE_LONG_MAZES, table="data/results/corrector/ant_rescue_long.csv", out="long")),
        seeds=(0,), mazes=RESCUE_MAZES, policy="data/policies/ant_stage5.pt", evaluation="adaptive",
        goal_points="centre", split_pick="confirmed", workers=1, code=RESCUE_CODE,
        table="data/results/corrector/ant_rescue.csv", out="runs/ant_corrector_rescue"),
    ExperimentGrid(
        "ant-corrector-floor", "docs/corrector.md, 'Weak legs judged by the path' (issue 39; fixed 2026-12-07 17:30 "
        "UTC before its first cell ran; one rescue cell's steps log informed it): the rescue with the path's floor, "
        "on the rescue grid's judged cells", "ant",
        parts=(Part(("ours-corrector-redraw-rescue-floor",), (DEAF, "random")),), seeds=(0,), mazes=RESCUE_MAZES,
        policy="data/policies/ant_stage5.pt", evaluation="adaptive", goal_points="centre", split_pick="confirmed",
        workers=1, code=FLOOR_CODE, table="data/results/corrector/ant_floor.csv", out="runs/ant_corrector_floor"),
    ant_corrector_grid("ant-corrector-span", "docs/corrector.md, 'The point mass's corrector on the Ant' (issue 39; "
                       "fixed 2026-12-06 01:53 UTC before its first cell ran; one pilot cell informed it): "
                       "ant-corrector-redraw's cells with the point mass's default corrector, ours-corrector-span",
                       "ant_span", code="ac7537b", method="ours-corrector-span", split_pick="confirmed"),
    # docs/corrector.md, "The point mass's default method: deep with the oracle" (fixed 2026-12-05 09:22 UTC)
    default_oracle_grid("corrector-deep-oracle", "The point mass's default method: deep with the oracle",
                        "ours-corrector-deep", "deep", DEEP_CODE),
    # docs/corrector.md, "Weak legs mended on the roadmap" (fixed 2026-12-05 10:19 UTC, before its grids ran)
    new_layouts_grid("corrector-mend-new", "docs/corrector.md, 'Weak legs mended on the roadmap' (issue 39; fixed "
                     "2026-12-05 before it ran)", ("ours-corrector-mend", "ours-corrector-deep", "ours"),
                     MEND_MAZES, MEND_MIXES, "mend_new", code=MEND_CODE),
    *centre_variant_grids("corrector-mend", "Weak legs mended on the roadmap", "ours-corrector-mend", "mend",
                          code=MEND_CODE,
                          informed=Part(("ours-corrector-mend",), GR_MIXES, mazes=GR_MAZES, split="proposers",
                                        table="data/results/corrector/mend_gr.csv", out="gr"),
                          fixed="2026-12-05"),
    # docs/corrector.md, "A last check of mend: error kinds at their extremes" (fixed 2026-12-05 12:29 UTC)
    new_layouts_grid("corrector-mend-check", "docs/corrector.md, 'A last check of mend' (issue 39; fixed 2026-12-05 "
                     "before it ran)", ("ours-corrector-mend", "ours-corrector-deep", "ours"),
                     MEND_CHECK_MAZES, MEND_CHECK_MIXES, "mend_check", code=MEND_CODE),
    # docs/corrector.md, "Ground given back" (fixed 2026-12-05 13:28 UTC, before they ran)
    new_layouts_grid("corrector-backtrack-new", "docs/corrector.md, 'Ground given back' (issue 39; fixed 2026-12-05 "
                     "before it ran)", ("ours-corrector-backtrack", "ours-corrector-mend", "ours"),
                     BACKTRACK_MAZES, BACKTRACK_MIXES, "backtrack_new", code=BACKTRACK_CODE),
    *centre_variant_grids("corrector-backtrack", "Ground given back", "ours-corrector-backtrack", "backtrack",
                          code=BACKTRACK_CODE,
                          informed=Part(("ours-corrector-backtrack",), MEND_CHECK_MIXES, mazes=MEND_CHECK_MAZES,
                                        seeds=(0, 1), split="proposers",
                                        table="data/results/corrector/backtrack_check.csv", out="check"),
                          fixed="2026-12-05"),
    default_oracle_grid("corrector-backtrack-oracle", "Ground given back", "ours-corrector-backtrack", "backtrack",
                        BACKTRACK_CODE),
    # docs/corrector.md, "Finer probes" (fixed 2026-12-05, before they ran)
    new_layouts_grid("corrector-fine-new", "docs/corrector.md, 'Finer probes' (issue 39; fixed 2026-12-05 before it "
                     "ran)", ("ours-corrector-fine", "ours-corrector-backtrack", "ours"),
                     FINE_MAZES, FINE_MIXES, "fine_new", code=FINE_CODE),
    *centre_variant_grids("corrector-fine", "Finer probes", "ours-corrector-fine", "fine", code=FINE_CODE,
                          informed=Part(("ours-corrector-fine",), BACKTRACK_MIXES, mazes=BACKTRACK_MAZES,
                                        seeds=(0, 1), split="proposers",
                                        table="data/results/corrector/fine_backtrack_new.csv", out="informed"),
                          fixed="2026-12-05"),
    default_oracle_grid("corrector-fine-oracle", "Finer probes", "ours-corrector-fine", "fine", FINE_CODE),
    new_layouts_grid("corrector-fine-check", "docs/corrector.md, 'Finer probes' (issue 39; its last check, fixed "
                     "2026-12-05 before it ran)", ("ours-corrector-fine", "ours-corrector-backtrack", "ours"),
                     FINE_CHECK_MAZES, FINE_CHECK_MIXES, "fine_check", code=FINE_CODE),
    # docs/corrector.md, "Weak legs mended past their end" (fixed 2026-12-05 21:35 UTC, before they ran)
    new_layouts_grid("corrector-span-new", "docs/corrector.md, 'Weak legs mended past their end' (issue 39; fixed "
                     "2026-12-05 before it ran)", ("ours-corrector-span", "ours-corrector-fine", "ours"),
                     SPAN_MAZES, SPAN_MIXES, "span_new", code=SPAN_CODE),
    # docs/corrector.md, "Entered another way: span with the bridge" (fixed 2026-12-07, before they ran)
    *centre_variant_grids("corrector-span-bridge", "Entered another way: span with the bridge",
                          "ours-corrector-span-bridge", "span_bridge", code=SPAN_BRIDGE_CODE,
                          informed=Part(("ours-corrector-span-bridge", "ours-corrector-span", "ours"), (DEAF,),
                                        mazes=SCALING_MAZES, seeds=(0, 1), table="data/results/corrector/"
                                        "span_bridge_deaf.csv", out="informed"),
                          fixed="2026-12-07"),
    new_layouts_grid("corrector-span-bridge-new", "docs/corrector.md, 'Entered another way: span with the bridge' "
                     "(issue 39; fixed 2026-12-07 before it ran)",
                     ("ours-corrector-span-bridge", "ours-corrector-span", "ours"), SPAN_BRIDGE_MAZES,
                     SPAN_BRIDGE_MIXES, "span_bridge_new", code=SPAN_BRIDGE_CODE),
    default_oracle_grid("corrector-span-bridge-oracle", "Entered another way: span with the bridge",
                        "ours-corrector-span-bridge", "span_bridge", SPAN_BRIDGE_CODE, fixed="2026-12-07"),
    # docs/corrector.md, "The point mass's default on D4RL's maps, misreadings included" (fixed 2026-12-07, before it
    # ran)
    ExperimentGrid("corrector-span-gr", "docs/corrector.md, 'The point mass's default on D4RL's maps, misreadings "
                   "included' (issue 39; fixed 2026-12-07 before it ran): ours-corrector-span beside ours and the "
                   "oracle on D4RL's three maps, corrector-deep-gr's proposers and the misreadings", "point",
                   parts=(Part(("ours-corrector-span", "ours"), GR_MIXES + MISREAD_MIXES, split="proposers"),
                          Part(("ours",), ("geometric",), table="data/results/corrector/span_gr_oracle.csv",
                               out="oracle")),
                   seeds=(0, 1, 2, 3), mazes=GR_MAZES, goal_points="centre", workers=1, code=MISREAD_CODE,
                   table="data/results/corrector/span_gr.csv", out="runs/corrector_span_gr"),
    # docs/corrector.md, "The statements again, with the default" (fixed 2026-12-07 14:46 UTC in 07c7b98, before they
    # ran): the point mass's default on the cells of span's two statements; ours and the oracle read from span's tables
    bridge_again_grid("misread", MISREAD_MAZES, MISREAD_MIXES, (0, 1)),
    bridge_again_grid("gr", GR_MAZES, GR_MIXES + MISREAD_MIXES, (0, 1, 2, 3)),
    # docs/corrector.md, "Misreadings no lever had met" (fixed 2026-12-07 09:08 UTC in 74d153d, before it ran)
    new_layouts_grid("corrector-span-misread", "docs/corrector.md, 'Misreadings no lever had met' (issue 39; fixed "
                     "2026-12-07 before it ran)", ("ours-corrector-span", "ours"), MISREAD_MAZES, MISREAD_MIXES,
                     "span_misread", code=MISREAD_CODE),
    *centre_variant_grids("corrector-span", "Weak legs mended past their end", "ours-corrector-span", "span",
                          code=SPAN_CODE,
                          informed=Part(("ours-corrector-span",), ("random",), mazes=SCALING_MAZES + OTHER_POINT_MAZES,
                                        seeds=(0, 1), table="data/results/corrector/span_fine_random.csv",
                                        out="informed"),
                          fixed="2026-12-05"),
    default_oracle_grid("corrector-span-oracle", "Weak legs mended past their end", "ours-corrector-span", "span",
                        SPAN_CODE),
    default_oracle_grid("corrector-mend-oracle", "Weak legs mended on the roadmap", "ours-corrector-mend", "mend",
                        MEND_CODE),
    # docs/corrector.md, "A proposer that knows nothing" (fixed 2026-12-05 21:18 UTC, before it ran; described)
    ExperimentGrid("corrector-fine-random", "docs/corrector.md, 'A proposer that knows nothing' (issue 39; fixed "
                   "2026-12-05 before it ran; described): the point mass's default with the random proposer on the "
                   "17 suite mazes and four new layouts", "point",
                   parts=(Part(("ours-corrector-fine", "ours"), ("random",), mazes=SCALING_MAZES + OTHER_POINT_MAZES,
                               split="seeds"),
                          Part(("ours-corrector-fine", "ours-corrector-backtrack", "ours"), ("random",),
                               mazes=RANDOM_CHECK_MAZES, table="data/results/corrector/fine_random_new.csv", out="new"),
                          Part(("ours",), ("geometric",), mazes=RANDOM_CHECK_MAZES,
                               table="data/results/corrector/fine_random_new_oracle.csv", out="oracle")),
                   seeds=(0, 1), goal_points="centre", workers=1, code=FINE_CODE,
                   table="data/results/corrector/fine_random.csv", out="runs/corrector_fine_random"),
    # docs/corrector.md, "The point mass's default on Gymnasium-Robotics' maps" (fixed 2026-12-05 09:52 UTC)
    ExperimentGrid("corrector-deep-gr", "docs/corrector.md, 'The point mass's default on Gymnasium-Robotics' maps' "
                   "(issue 39; fixed 2026-12-05 before it ran; described, no rule): the default, ours-corrector-deep, "
                   "beside ours and the oracle on D4RL's three maps", "point",
                   parts=(Part(("ours-corrector-deep", "ours"), GR_MIXES, split="proposers"),
                          Part(("ours",), ("geometric",), table="data/results/corrector/deep_gr_oracle.csv",
                               out="oracle")),
                   seeds=(0, 1, 2, 3), mazes=GR_MAZES, goal_points="centre", workers=1,
                   code="ac2e7f4", table="data/results/corrector/deep_gr.csv",
                   out="runs/corrector_deep_gr"),
    ant_oracle_grid("ant-oracle-corrector", "docs/ant_experiments.md, 'Issue 42, lever 7' (fixed 2026-12-04 20:40 UTC "
                    "before its first cell ran): the Ant's corrector on the oracle's paths, U-chain 3 and 5",
                    "ours-corrector-redraw", "oracle_corrector", code="2b6a4f7", mazes=("u_chain_3", "u_chain_5"),
                    split_pick="confirmed"),
    ant_oracle_grid("ant-oracle-corrector-scaling", "docs/ant_experiments.md, 'Issue 42, lever 7 on every U-chain' "
                    "(fixed 2026-12-04 21:50 UTC before its first new cell ran): lever 7's corrector with the oracle "
                    "on the nine U-chains; its six U-chain 3 and 5 cells are lever 7's rows (the same code and cells), "
                    "copied into its table, not run again",
                    "ours-corrector-redraw", "oracle_corrector_scaling", code="2b6a4f7", split_pick="confirmed"),
    ant_oracle_grid("ant-oracle-wide", "docs/ant_experiments.md, 'Issue 42, lever 8' (fixed 2026-12-05 00:22 UTC "
                    "before its first cell ran): lever 7's corrector with one more pass on a wide draw, on lever 7's "
                    "six cells", "ours-corrector-wide", "oracle_wide", code="adda718",
                    mazes=("u_chain_3", "u_chain_5"), split_pick="confirmed"),
    ant_oracle_grid("ant-oracle-wide-scaling", "docs/ant_experiments.md, 'Issue 42, lever 8 on every U-chain' (fixed "
                    "2026-12-05 01:56 UTC before its first new cell ran): lever 8's corrector with the oracle on the "
                    "nine U-chains; its six U-chain 3 and 5 cells are lever 8's rows (the same code and cells), copied "
                    "into its table, not run again", "ours-corrector-wide", "oracle_wide_scaling", code="adda718",
                    split_pick="confirmed"),
    ExperimentGrid(
        "ant-oracle-paper", "docs/ant_experiments.md, 'The paper's rule as --preset paper' (issue 42; fixed "
        "2026-12-06 07:07 UTC before its first cell ran): the oracle under every rule of the paper, as `--preset "
        "paper` resolves them for the Ant, on the nine U-chains", "ant",
        parts=(Part((PAPER.method,), (GEOMETRIC_48,), split="seeds"),), seeds=(0, 1, 2), mazes=SCALING_MAZES,
        policy="data/policies/ant_stage5.pt", evaluation=PAPER.evaluation, goal_points=PAPER.goal_points,
        split_pick=PAPER.split_pick, workers=2, code="e22cff8", table="data/results/ant/oracle_paper.csv",
        out="runs/ant_oracle_paper"),
    ExperimentGrid(
        "ant-corrector-fresh", "docs/corrector.md, 'Fresh layouts for the Ant' (issue 39; fixed 2026-12-04 before it "
        "ran): ours-corrector-redraw and its control confirm on layouts and a mix no run had used, and the oracle",
        "ant", parts=(Part(("ours-corrector-redraw", "ours-corrector-confirm"), ANT_FRESH_MIXES, split="proposers"),
                      Part(("ours",), (GEOMETRIC_48,), table="data/results/corrector/ant_fresh_oracle.csv",
                           out="oracle")),
        seeds=(0,), mazes=ANT_FRESH_MAZES, policy="data/policies/ant_stage5.pt", evaluation="adaptive",
        goal_points="centre", split_pick="confirmed", workers=1, code="96e357e",
        table="data/results/corrector/ant_fresh.csv", out="runs/ant_corrector_fresh"),
    ant_oracle_grid("ant-oracle-spread", "docs/ant_experiments.md, 'The oracle at the fixed code' (issue 42; fixed "
                    "2026-11-27 13:45 UTC before its first cell ran)", "ours", "oracle_spread", code="e08c8b9"),
    ant_oracle_grid("ant-oracle-tunecheck", "docs/ant_experiments.md, 'Issue 42, lever 4' (fixed 2026-11-27 18:45 UTC "
                    "before its first cell ran): ant-oracle-spread's cells with ours-tunecheck", "ours-tunecheck",
                    "oracle_tunecheck", code="9b8f8f7"),
    ant_oracle_grid("ant-oracle-confirm", "docs/ant_experiments.md, 'Issue 42, lever 5' (fixed 2026-11-27 19:55 UTC "
                    "before its first cell ran): ant-oracle-spread's cells with ours-confirm", "ours-confirm",
                    "oracle_confirm", code="c463c3e"),
    ExperimentGrid(
        "ant-slow-turn", "docs/ant_experiments.md, 'Issue 42, lever 1', check 5 (fixed 2026-11-27 04:40 UTC before "
        "its first cell ran; started 06:22 by scripts/ant_switching_checks.sh PART=cells)", "ant",
        parts=(Part(("ours",), (GEOMETRIC_48,)),), seeds=(0, 1, 2), mazes=("u_chain_3", "u_chain_5"),
        policy="data/policies/ant_stage5.pt", evaluation="adaptive", goal_points="centre", switching="slow-turn",
        workers=1, code="b6cb752", table="data/results/ant/switching_checks/uchain_slow_turn.csv",
        out="runs/ant_switching"),
    ExperimentGrid(
        "ant-stage8", "docs/ant_experiments.md, 'Issue 42, lever 2', check 6 (fixed 2026-11-27 before its first cell "
        "ran)", "ant",
        parts=(Part(("ours",), (GEOMETRIC_48,)),), seeds=(0, 1, 2), mazes=("u_chain_3", "u_chain_5"),
        policy="data/policies/ant_stage8.pt", evaluation="adaptive", goal_points="centre", workers=1, code="fb28c48",
        table="data/results/ant/stage8_checks/uchain_stage8.csv", out="runs/ant_stage8_uchain"),
)}


def show(g: ExperimentGrid, root: Path = ROOT) -> list[str]:
    """The grid's pinned_sweep.sh commands, in the order run_grid.sh runs them."""
    code = g.code or "HEAD"
    return [f"CODE={code} OUT={g.part_out(i)} SHIPPED={g.part_table(i)} bash scripts/pinned_sweep.sh "
            + shlex.join(args) for i in range(len(g.parts)) for args in sweep_args(g, i, root=root)]


def plan(g: ExperimentGrid, out: str | None = None, shipped: str | None = None, subset: Subset = EVERY) -> list[str]:
    """What run_grid.sh reads, fields separated by tabs (a path may hold spaces): 'code COMMIT' (or 'code -': the
    checkout's HEAD), then 'step PART STEP OUT TABLE' per sweep of ``subset``, in order."""
    subset.check(g)
    if shipped and len(g.tables) > 1:
        raise GridError(f"grid {g.name} writes {len(g.tables)} tables: SHIPPED names one table only")
    for name, path in (("OUT", out), ("SHIPPED", shipped)):
        if path is not None and (not path.strip() or any(ch in path for ch in "\t\n\r")):
            raise GridError(f"{name}={path!r}: name a path (not empty, no tab or line break)")
    lines = [f"code\t{g.code or '-'}"]
    for i in range(len(g.parts)):
        for j in range(len(_steps(g, g.parts[i], subset))):
            lines.append(f"step\t{i}\t{j}\t{g.part_out(i, out)}\t{shipped or g.part_table(i)}")
    return lines


class PartStatus(NamedTuple):
    part: int
    done: int  #: cells done in the part's shipped table
    total: int
    missing: list[str]  #: the ids still to run, in run order
    started: dict[str, int]  #: of those, the ones with a folder in the sweep folder: evaluations in its cache
    running: frozenset = frozenset()  #: of those started, the ones a live run holds now (their folder's lock)
    finished: frozenset = frozenset()  #: of those started, the ones done in the sweep folder's own table, not yet
    #: copied into the shipped one
    paces: dict = {}  #: of those running, simulator steps a second over the last 30 min (``spend.recent_pace``)


def status(g: ExperimentGrid, root: Path | None = None, out: str | None = None) -> list[PartStatus]:
    """Per part: the cells done in its shipped table, the rest, and which of the rest have started in the sweep
    folder (the grid's, or ``out``; relative paths from ``root``, by default the checkout): a cut cell resumes from
    its evaluation cache; of those, which a live run holds now and which the sweep has finished (its own table)."""
    import time

    from ..core.runfolder import live_holder
    from ..runs.sweep import done_ids, is_done, read_checked_table
    from .spend import recent_pace

    root = ROOT if root is None else root
    report = []
    for i in range(len(g.parts)):
        table = root / g.part_table(i)
        done = {r["cell"] for r in read_checked_table(table) if is_done(r)} if table.is_file() else set()
        ids = [c.id for c in part_cells(g, i, root=root)]
        missing = [c for c in ids if c not in done]
        sweep = root / g.part_out(i, out)
        started = {c: _cached(sweep / "cells" / c) for c in missing if (sweep / "cells" / c).is_dir()}
        running = frozenset(c for c in started if live_holder(sweep / "cells" / c))
        finished = frozenset(started) & done_ids(sweep / "results.csv")  # as the sweep reads its own table
        paces = {c: recent_pace(sweep / "cells" / c / "cache", time.time_ns()) for c in running}
        report.append(PartStatus(i, len(ids) - len(missing), len(ids), missing, started, running, finished, paces))
    return report


def _started_note(st: PartStatus, cell: str) -> str:
    """What ``status`` says of a cell beside its id: nothing for one not started."""
    if cell not in st.started:
        return ""
    if cell in st.finished:
        return "  (done in the sweep folder's table, not yet in the shipped one)"
    from .spend import PACE_WINDOW_S

    running = (f"; running now, {st.paces[cell] / 1e3:.1f}k simulator steps/s over the last "
               f"{PACE_WINDOW_S / 60:.0f} min" if cell in st.running else "")
    return f"  (started: {st.started[cell]} evaluations cached{running})"


def _cached(cell: Path) -> int:
    """Evaluations in a cell folder's cache (one ``.npz`` each)."""
    return sum(1 for _ in (cell / "cache").rglob("*.npz"))


def add_arguments(p) -> None:
    from ..core.argtypes import bounded_int

    p.description = __doc__.split("\n\n")[0]
    sub = p.add_subparsers(dest="grids_command", required=True, metavar="{list,show,args,plan,status}")
    sub.add_parser("list", help="every grid: name, agent, cells, where it was fixed")
    for name, what in (("show", "the pinned_sweep.sh commands of a grid, in order"),
                       ("args", "one step's sweep arguments, shell-quoted on one line"),
                       ("plan", "the code and steps run_grid.sh runs"),
                       ("status", "cells done per part, from the shipped tables, and those started in the sweep folder "
                                  "(--missing: every cell not done)")):
        sp = sub.add_parser(name, help=what, description=what)
        sp.add_argument("grid", help="a grid's name (specrefine grids list)")
        if name == "args":
            sp.add_argument("--part", type=int, required=True, help="the part, from 0 (required)")
            sp.add_argument("--step", type=int, default=0, help="the step of the part, from 0")
            sp.add_argument("--workers", type=bounded_int("workers"), default=None,
                            help="local processes of the sweep (default: the grid's)")
        if name in ("args", "plan"):
            sp.add_argument("--mazes", nargs="+", default=None, metavar="MAZE",
                            help="only these of the grid's mazes (the same cells; steps left empty are dropped) "
                                 "(default: all)")
            sp.add_argument("--seeds", nargs="+", type=int, default=None, metavar="SEED",
                            help="only these of the grid's seeds (default: all)")
        if name == "status":
            sp.add_argument("--missing", action="store_true", help="list the cells still to run")
            sp.add_argument("--out", type=_from_cwd, default=None,
                            help="the sweep folder to look for started cells in (parts: under it; a relative path is "
                                 "taken from the working directory) (default: the grid's)")
        if name == "plan":
            sp.add_argument("--out", default=None, help="the sweep folder instead of the grid's (parts: under it; "
                                                        "relative to the checkout's root, where run_grid.sh runs) "
                                                        "(default: the grid's)")
            sp.add_argument("--shipped", default=None, help="the table instead of the grid's (one-table grids; "
                                                            "relative to the checkout's root) (default: the grid's)")


def _from_cwd(path: str) -> str:
    """A folder typed on ``status``'s command line, made absolute from the working directory: the grid's own folders
    are the checkout's, but a folder a user names is where they stand. (``plan``'s are the checkout's: run_grid.sh
    runs from its root and passes them on as given.)"""
    return os.path.abspath(path)


def _subset(args) -> Subset:
    return Subset(tuple(args.mazes) if args.mazes else None, tuple(args.seeds) if args.seeds else None)


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("grids", argv, prog="python -m specrefine.experiments.grids")


def run(args, p) -> int:
    try:
        if args.grids_command == "list":
            for g in GRIDS.values():
                print(f"{g.name}\t{g.agent}\t{len(cells(g))} cells\t{g.doc}")
            return 0
        g = get(args.grid)
        if args.grids_command == "show":
            print("\n".join(show(g)))
        elif args.grids_command == "status":
            for st in status(g, out=args.out):
                part = g.parts[st.part]
                print(f"part {st.part}: {' '.join(part.methods)} x {' '.join(part.proposers)}: {st.done}/{st.total} "
                      f"done, {len(st.started)} started ({g.part_table(st.part)})")
                for cell in st.missing if args.missing else st.started:
                    print(f"  {cell}{_started_note(st, cell)}")
        elif args.grids_command == "plan":
            print("\n".join(plan(g, args.out, args.shipped, _subset(args))))
        else:
            subset = _subset(args)
            subset.check(g)
            steps = sweep_args(g, args.part, workers=args.workers, subset=subset)
            if not 0 <= args.step < len(steps):
                raise GridError(f"part {args.part} of grid {g.name} has steps 0-{len(steps) - 1}, not {args.step}")
            print(shlex.join(steps[args.step]))
    except GridError as exc:
        p.exit(2, f"{p.prog}: error: {exc}\n")
    return 0


if __name__ == "__main__":
    from ..core.argtypes import exit_code_quiet_on_broken_pipe

    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
