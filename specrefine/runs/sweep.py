"""Experiment sweeps: a grid of (maze [x spec] x method x proposer x seed) runs -> one tidy CSV table.

Each cell is one ``refine_maze`` run (the CLI's code path) in its own output directory
``OUT/cells/<cell id>/``; its row is appended to ``OUT/results.csv`` as soon as it
finishes.  Rerunning a sweep skips cells that already have a row with status ``ok``
(resume after a kill), retries failed ones, and keeps each cell's evaluation cache, so
an interrupted cell restarts from what it had evaluated.  A cell's warnings and log records (a proposer's
rejected candidates, a region with little room) go to its own ``OUT/cells/<cell id>/log.txt``, not to the
sweep's stderr, where two workers' lines would interleave around the progress bar.

A cell's ``spec`` (``--specs``, or ``MAZE=SPEC`` in ``--mazes``) is the task as a spec expression
(``specrefine refine --spec``); empty = the maze's own task.  It is part of the cell id only when
given, so the ids of default-task cells (and the rows of older tables, which lack the ``spec``
column) stay valid; rows are appended in the columns of the table they go into.

The search settings ``w``, ``d`` and ``k`` (``-w 3 5 -k 5 10``; defaults and bounds from
:class:`specrefine.runs.config.RunConfig`) are grid axes too: a method gets one cell per combination of the
settings it reads (``methods.Method.knobs``).  A cell with the paper's values keeps the id it always had; any
other value is named in the id (``...__s0__w5``) and recorded in the ``w``, ``d``, ``k`` columns (a table from
before them reads as the paper's values; cells with other values are refused into it).  ``--goal-points centre``
(``RunConfig.goal_points``) likewise ends the id in ``__centre``.  Every row records what it ran with:
``policy_fingerprint`` (the goal policy's weights) and ``commit`` (the code's commit, ``-dirty`` if ``specrefine/``
had uncommitted edits, ``unknown`` outside a git checkout: ``core.paths.code_commit``).

A maze given as a file outside ``data/mazes/`` is run from that file: its rows hold its absolute path in
``maze`` and its cell ids its stem plus a hash of the path (a shipped maze keeps its bare name, so older
ids and tables stay valid; one in a folder of ``data/mazes/`` is named by its path there, ``held_out/x``, id
``held_out-x``, the same on every machine).  ``OUT/sweep.json`` records each cell's ``rollouts`` and
``episodes`` (not part of the id): a rerun into the same ``OUT`` with other values is refused (exit 2) rather
than silently keeping rows measured with the old ones.  A row counts as done only when its status is ``ok`` and its
numbers are all there (a row cut short by a kill is redone), and at the end the table holds one row per
cell (the last ``ok`` one, else the last failure).  Ctrl-C ends the sweep with one line and exit 130,
keeping every finished row; pool workers die with the sweep's process.  Exit 1 when every cell failed.

Backends: ``local`` (a process pool sized to the machine) and ``ray`` (the same cells as
Ray tasks on a cluster: ``--backend ray --address HOST:PORT``).  With Ray, Ctrl-C cancels the cells
still queued or running (``ray.cancel(force=True)``); a sweep killed outright cannot, and leaves its tasks
to Ray's own clean-up of a job whose driver died (not tested here).
"""

from __future__ import annotations

import contextlib
import csv
import hashlib
import itertools
import json
import logging
import math
import os
import signal
import sys
import threading
import time
import traceback
import warnings
from collections.abc import Iterable
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, fields
from pathlib import Path

from ..core.agents import AGENTS
from ..core.argtypes import OneLineParser, bounded_int, out_path
from ..core.errors import SpecrefineError, SweepError
from ..core.paper import PAPER
from ..core.paths import code_commit, regular_file
from ..core.plugins import loaded
from ..core.runfolder import open_append, replacing, write_atomic
from ..core.tables import _NUMBERS, KNOBS, _raw_rows, _typed, read_checked_table, read_table  # noqa: F401 (read here too)
from .config import DEFAULTS, RunConfig, add_run_options, maze_problem, proposer_arg
from .methods import METHODS, PROPOSER_METHODS
from .progress import counted

COLUMNS = [
    "cell", "maze", "agent", "method", "proposer", "proposer_is_vlm", "seed", "status", "error",
    "success_rate", "success_ci_low", "success_ci_high", "episodes", "predicted_success", "path_success_rate",
    "evaluations", "cache_hits", "sim_steps", "vlm_calls", "vlm_cost_usd", "wall_seconds", "refinements",
    "refines_input", "graph_vertices", "graph_edges", "path_edges", "rollouts_per_evaluation", "spec",
    "proposer_calls", "search_estimate", "predicted_ci_low", "predicted_ci_high", "evaluation", "policy",
    "policy_fingerprint", "search_seconds", "measure_seconds", "calibrate_seconds", "w", "d", "k", "goal_points",
    "commit",
]
#: Tables older than a column lack it (``spec``, ``evaluation``, ``policy``, ``policy_fingerprint``, the phases' wall
#: times ``search_seconds``, ``measure_seconds``, ``calibrate_seconds``, ...): readers
#: take a row's missing field as unknown (``row.get``), and rows appended to such a table keep its header, except
#: for PROVENANCE: a row always records the policy and the code it ran with, so a table without those columns gets
#: them (rewritten whole, its older rows empty there: unknown) before the row is appended.
PROVENANCE = ("policy_fingerprint", "commit")


@dataclass(frozen=True)
class Cell:
    """One run of a sweep: a maze and the :class:`RunConfig` it runs with (resolved: what its preset decides filled
    in). Its settings read as its own (``cell.seed``, ``cell.w``, ...); ``proposer`` is "none" for a method that asks
    none and ``spec`` "" for the maze's own task, as the table's rows name them."""

    maze: str  # a shipped maze's name, or the absolute path of any other maze file (see maze_ref)
    config: RunConfig

    @classmethod
    def of(cls, maze: str, agent: str = "point", method: str = "ours", proposer: str = "none", seed: int = 0,
           **settings) -> Cell:
        """A cell from its settings as a row names them (the other RunConfig fields by name)."""
        spec = settings.pop("spec", None) or None
        proposer = DEFAULTS.proposer if proposer == "none" else proposer
        return cls(maze, RunConfig(agent=agent, method=method, proposer=proposer, seed=int(seed), spec=spec,
                                   **settings).resolved())

    def __getattr__(self, name):  # only called for what the cell itself lacks: the configuration's settings
        if name in _SETTINGS:
            return getattr(self.config, name)
        raise AttributeError(name)

    @property
    def proposer(self) -> str:
        return self.config.proposer if self.config.method in PROPOSER_METHODS else "none"

    @property
    def split_pick(self) -> str:  # a method that splits no edge runs the paper's, whatever was asked
        return self.config.split_pick if self.config.method in PROPOSER_METHODS else PAPER.split_pick

    @property
    def spec(self) -> str:
        return self.config.spec or ""

    @property
    def id(self) -> str:
        prop = self.proposer.replace(":", "-").replace("/", "-")
        name = self.maze
        if Path(name).is_absolute():  # a file outside data/mazes: unique by its path
            name = f"{Path(name).stem}-{hashlib.sha256(name.encode()).hexdigest()[:8]}"
        # a standard map 'gr:NAME' -> 'gr-NAME', a shipped folder's 'held_out/x' -> 'held_out-x' (folder names)
        name = name.replace(":", "-").replace("/", "-")
        tail = "" if self.evaluation == PAPER.evaluation else f"__{self.evaluation}"  # older ids stay valid
        tail += "".join(f"__{knob}{getattr(self, knob)}" for knob in KNOBS
                        if getattr(self, knob) != getattr(PAPER, knob))  # the paper's w, d, k: the id they had
        tail += "" if self.goal_points == PAPER.goal_points else f"__{self.goal_points}"
        tail += "".join(f"__{name}-{getattr(self, name)}" for name in OTHER_SETTINGS  # a later setting, when set
                        if getattr(self, name) != getattr(PAPER_RESOLVED[self.agent], name))
        whole = self._id(name, spec_slug(self.spec), prop, tail)
        if len(whole.encode()) <= ID_LIMIT:  # every id a shipped table holds
            return whole
        return self._id(_bounded(name), _bounded(spec_slug(self.spec)), _bounded(prop), tail)

    def _id(self, name: str, spec: str, prop: str, tail: str) -> str:
        task = f"{name}__{spec}" if self.spec else name
        return f"{task}__{self.agent}__{self.method}__{prop}__s{self.seed}{tail}"

    def row(self) -> dict:
        """The cell's own columns of its results row."""
        return {"maze": self.maze, **{name: getattr(self, name) for name in ROW_SETTINGS}, "cell": self.id}


_SETTINGS = frozenset(f.name for f in fields(RunConfig))
#: in the cell id: the agent, method, proposer, seed and spec, then evaluation, w, d, k, goal_points as they always
#: were; not in it: what OUT/sweep.json checks (PARAMS) and the preset (what it decides is); any other setting a
#: RunConfig gains is named in the id whenever it differs from the paper's (what every older id ran), with no
#: change here
OTHER_SETTINGS = tuple(sorted(_SETTINGS - {"agent", "method", "proposer", "seed", "spec", "evaluation", *KNOBS,
                                          "goal_points", "rollouts", "episodes", "policy", "preset"}))
PAPER_RESOLVED = {name: RunConfig(agent=name, preset="paper").resolved() for name in AGENTS}
#: the settings a results row records, in the order of the table's columns
ROW_SETTINGS = ("agent", "method", "proposer", "seed", "rollouts", "episodes", "spec", "evaluation", "policy", "w",
                "d", "k", "goal_points")


ID_LIMIT = 240  # bytes of a cell id kept whole: it is a folder's name (255 bytes at most)
ID_PART = 64  # characters of one part of a longer id (maze, spec, proposer), cut and hashed


def _bounded(part: str) -> str:
    """A part of a cell id that is too long as a whole (an 80-branch spec): as it is when short, a longer one
    cut, and ended with a hash of the whole so that different parts keep different ids."""
    if len(part) <= ID_PART:
        return part
    return f"{part[:ID_PART - 13]}-{hashlib.sha256(part.encode()).hexdigest()[:12]}"


def spec_slug(spec: str) -> str:
    """A spec expression as a file-name-safe id part: '(a | b) -> G' -> 'Pa-or-bQ-then-G'."""
    text = "".join(spec.split())
    for old, new in (("->", "-then-"), ("|", "-or-"), ("(", "P"), (")", "Q")):
        text = text.replace(old, new)
    return text


def maze_ref(arg: str) -> str:
    """What a cell runs: a shipped maze (a name, or a path to the file in data/mazes or a folder of it) by its name
    there (``u_maze``, ``held_out/u_chain_3_rotated``: the same on every machine); any other existing file by its
    absolute path; anything else as given (loading it reports the error)."""
    from ..core.mazes import MAZE_DIR

    path = Path(arg)
    if not path.exists():
        return arg
    resolved = path.resolve()
    try:
        inside = resolved.relative_to(MAZE_DIR.resolve())
    except ValueError:
        return str(resolved)
    return inside.with_suffix("").as_posix() if resolved.suffix == ".maze" else str(resolved)


def split_maze_arg(arg: str) -> tuple[str, str]:
    """'MAZE' -> (MAZE, ''); 'MAZE=SPEC' -> (MAZE, SPEC): a per-maze spec on the command line."""
    maze, _, spec = arg.partition("=")
    return maze, spec.strip()


def grid(mazes: Iterable[str], methods: Iterable[str], proposers: Iterable[str], seeds: Iterable[int], *,
         agent: str = "point", rollouts: int = DEFAULTS.rollouts, episodes: int = DEFAULTS.episodes,
         specs: Iterable[str | None] = (None,), evaluation: str | None = None, policy: str | None = None,
         w: Iterable[int] = (DEFAULTS.w,), d: Iterable[int] = (DEFAULTS.d,), k: Iterable[int] = (DEFAULTS.k,),
         goal_points: str | None = None, preset: str = DEFAULTS.preset, **settings) -> list[Cell]:
    """All cells; methods without a proposer (dirl, symbolic) appear once per seed, not once per proposer.

    ``w``, ``d``, ``k``: the values of each search setting; a method gets one cell per combination of the settings
    it reads (``methods.Method.knobs``: dirl none, symbolic k only), the others at the paper's defaults.

    ``evaluation``, ``goal_points``, ``policy``: every cell's; None = what ``preset`` decides for the agent
    (:meth:`RunConfig.resolved`).

    ``specs``: task expressions run on every maze (None or "" = the maze's own task); a maze given as
    ``MAZE=SPEC`` runs that spec only. ``settings``: any other RunConfig field, for every cell.
    """
    axes = {"w": list(w), "d": list(d), "k": list(k)}
    common = dict(rollouts=rollouts, episodes=episodes, evaluation=evaluation, policy=policy, goal_points=goal_points,
                  preset=preset, **settings)
    cells = []
    for arg in mazes:
        maze, own = split_maze_arg(str(arg))
        for spec in [own] if own else [s or "" for s in specs]:
            for method in methods:
                props = list(proposers) if method in PROPOSER_METHODS else ["none"]
                for proposer in props:
                    for seed in seeds:
                        for knobs in _knob_values(method, axes):
                            cells.append(Cell.of(maze_ref(maze), agent, method, proposer, seed, spec=spec,
                                                 **common, **knobs))
    return cells


def _knob_values(method: str, axes: dict[str, list[int]]) -> list[dict[str, int]]:
    """Each combination of the values of the settings ``method`` reads (an unknown method: all of them); the
    settings it does not read stay at the paper's defaults."""
    reads = METHODS[method].knobs if method in METHODS else KNOBS
    values = [axes[knob] if knob in reads else [getattr(DEFAULTS, knob)] for knob in KNOBS]
    return [dict(zip(KNOBS, combo)) for combo in dict.fromkeys(itertools.product(*values))]


def run_cell(cell: Cell, out_root: str, plugins: tuple[str, ...] = ()) -> dict:
    """Run one cell; never raises: a failure becomes a row with status 'error'. ``plugins``: the ``--plugin``
    modules the sweep loaded (a Ray worker is a fresh process: it loads them, and the entry points, here)."""
    from ..core.plugins import load_plugins
    from .pipeline import refine_maze

    try:
        load_plugins(plugins)  # before the row: a plugin's method names its proposer only once registered
    except SpecrefineError as exc:
        return {**cell.row(), "commit": code_commit(), "status": "error", "error": str(exc)[:300]}
    row = {**cell.row(), "commit": code_commit()}  # a failed cell's row names its code too
    out = Path(out_root) / "cells" / cell.id
    try:
        with cell_log(out / "log.txt"):
            result = refine_maze(cell.maze, cell.config, out=out, progress=False)  # the sweep has its own bar
    except Exception as exc:  # noqa: BLE001 - a sweep records every failure and goes on
        last = traceback.format_exception_only(type(exc), exc)[-1].strip()
        return {**row, "status": "error", "error": last[:300]}
    return result_row(result.data, row) | {"proposer_is_vlm": result.data["proposer_is_vlm"]
                                           if cell.proposer != "none" else False}


@contextlib.contextmanager
def cell_log(path: Path):
    """The package's log records and Python warnings raised inside the block are appended to ``path`` (a rerun
    adds to it), not printed."""
    path.parent.mkdir(parents=True, exist_ok=True)
    logger = logging.getLogger("specrefine")
    handler = logging.StreamHandler(open_append(path, "cell's log"))
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    propagate = logger.propagate
    logger.addHandler(handler)
    logger.propagate = False

    def to_file(message, category, filename, lineno, file=None, line=None):
        handler.stream.write(warnings.formatwarning(message, category, filename, lineno, line))
        handler.flush()

    try:
        with warnings.catch_warnings():
            warnings.showwarning = to_file
            yield
    finally:
        logger.removeHandler(handler)
        logger.propagate = propagate
        handler.close()
        handler.stream.close()


def result_row(data: dict, row: dict | None = None) -> dict:
    """A results-table row (``COLUMNS``) from a run's ``result.json`` dict; ``row`` fields take precedence."""
    row = dict(row or {})
    lo, hi = data["success_ci"]
    row.update({k: data[k] for k in COLUMNS if k in data and k not in row})
    row.update(status="ok", error="", success_ci_low=lo, success_ci_high=hi)
    if "predicted_ci" in data:
        row.update(predicted_ci_low=data["predicted_ci"][0], predicted_ci_high=data["predicted_ci"][1])
    return row


def is_done(row: dict) -> bool:
    """An ``ok`` row with all its numbers (typed as by ``read_table``)."""
    return row.get("status") == "ok" and all(
        isinstance(row.get(k), (int, float)) and not isinstance(row.get(k), bool) for k in _NUMBERS)


def _drop_cut_row(path: Path) -> None:
    """A last row cut off by a kill (no newline at its end) is removed: it was not done, and ending it instead
    could leave an open quote that would swallow every row after it."""
    with os.fdopen(os.open(path, os.O_RDWR | os.O_NOFOLLOW), "rb+") as fh:
        data = fh.read()
        if data and not data.endswith(b"\n"):
            fh.truncate(data.rfind(b"\n") + 1)


def _append(path: Path, row: dict) -> None:
    new = not os.path.lexists(path) or os.lstat(path).st_size == 0
    columns = COLUMNS if new else _header(path)  # an older table (without later columns) keeps its own header
    if not new:
        _check_fits(path, columns, row)
        _drop_cut_row(path)
        if missing := [c for c in PROVENANCE if c not in columns]:
            columns = _add_columns(path, columns, missing)
    with open_append(path, "results table") as fh:  # a link or a FIFO is refused, never written through
        writer = csv.DictWriter(fh, fieldnames=columns, extrasaction="ignore")
        if new:
            writer.writeheader()
        writer.writerow({k: " ".join(str(row.get(k, "")).split()) if k == "error" else row.get(k, "")
                         for k in columns})  # one line per row: a cut row is then always the last line
        fh.flush()
        os.fsync(fh.fileno())


def _header(path: Path) -> list[str]:
    with regular_file(path, "results table").open(newline="") as fh:
        return next(csv.reader(fh), None) or COLUMNS


def _check_fits(path: Path, columns: list[str], row: dict) -> None:
    """A row whose values an older table has no column for is refused (it would be read back as another cell)."""
    if row.get("spec") and "spec" not in columns:
        raise ValueError(f"{path} has no 'spec' column: write cells with a spec to another table")
    if row.get("evaluation", "fixed") != "fixed" and "evaluation" not in columns:
        raise ValueError(f"{path} has no 'evaluation' column: write adaptive cells to another table")
    if row.get("policy", "shipped") != "shipped" and "policy" not in columns:
        raise ValueError(f"{path} has no 'policy' column: write cells with another policy to another table")
    if any(row.get(knob, getattr(PAPER, knob)) != getattr(PAPER, knob) for knob in KNOBS) and "w" not in columns:
        raise ValueError(f"{path} has no 'w', 'd', 'k' columns: write cells with other w, d or k to another table")
    if row.get("goal_points", PAPER.goal_points) != PAPER.goal_points and "goal_points" not in columns:
        raise ValueError(f"{path} has no 'goal_points' column: write cells aiming at centres to another table")


def check_table(table: Path, cells: list[Cell]) -> None:
    """Before any cell runs: a table the sweep can append ``cells``' rows to (a regular file it can write, with the
    sweep's header and the columns those rows need), or none yet; else a one-line SweepError."""
    if not os.path.lexists(table):
        return
    open_append(table, "results table").close()  # a link, read-only: refused now, not after the first cell
    columns = _raw_rows(table)[0]  # a FIFO, a folder, a device, bytes that are not a table: one line
    if columns and not {"cell", "status"} <= set(columns):
        raise SweepError(f"{table}: not a sweep's results table (its header has no 'cell' and 'status' columns): "
                         f"use another --out")
    for cell in cells if columns else []:
        try:
            _check_fits(table, columns, cell.row())
        except ValueError as exc:
            raise SweepError(str(exc)) from None


def _add_columns(path: Path, columns: list[str], missing: list[str]) -> list[str]:
    """The table rewritten whole with ``missing`` columns after its own, empty in its rows; the new header."""
    with path.open(newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))[1:]
    columns = [*columns, *missing]
    with replacing(path, newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(columns)
        writer.writerows(row + [""] * (len(columns) - len(row)) for row in rows if row)
    return columns


def done_ids(table: Path) -> set[str]:
    """The ids of the cells ``table`` holds done rows for (none where there is no table yet)."""
    return {r["cell"] for r in read_table(table) if is_done(r)}


def pending(cells: list[Cell], table: Path) -> list[Cell]:
    done = done_ids(table)
    return [c for c in cells if c.id not in done]


def compact(table: Path) -> None:
    """One row per cell: its last done row, else its last row; first-appearance order, the table's own header."""
    if not table.exists():
        return
    columns, raw = _raw_rows(table)
    if not columns:
        return
    keep: dict[str, dict] = {}
    for row in raw:
        old = keep.get(row["cell"])
        if old is None or is_done(_typed(row)) or not is_done(_typed(old)):
            keep[row["cell"]] = row
    if len(keep) == len(raw):
        return
    with replacing(table, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(keep.values())


PARAMS = ("rollouts", "episodes", "policy")  # what a cell's rows depend on beyond its id


def check_params(cells: list[Cell], out_root: Path) -> None:
    """Refuse cells whose id ``OUT`` already holds with other ``PARAMS`` (``OUT/sweep.json``, or for older
    tables the rows' ``rollouts_per_evaluation``); record the new cells' parameters."""
    record = out_root / "sweep.json"
    known = _recorded_cells(record) if os.path.lexists(record) else {}
    for row in read_table(out_root / "results.csv"):
        if row.get("cell") not in known and isinstance(row.get("rollouts_per_evaluation"), float):
            known[row["cell"]] = {"rollouts": int(row["rollouts_per_evaluation"])}
    for cell in cells:
        old = known.get(cell.id, {})
        diff = [f"--{k} {old[k]}" for k in PARAMS if k in old and old[k] != getattr(cell, k)]
        if diff:
            raise SweepError(f"{out_root} holds cell {cell.id} run with {' '.join(diff)}; rerun with those values "
                             f"or use another --out")
    known.update({c.id: {k: getattr(c, k) for k in PARAMS} for c in cells})
    write_atomic(record, json.dumps({"cells": known}, indent=1, sort_keys=True))


def known_cells(out) -> dict:
    """The cells a sweep folder ``out`` has begun ({cell id: {param: value}} from its ``sweep.json``; {} without
    one), or a one-line SweepError."""
    record = Path(out) / "sweep.json"
    return _recorded_cells(record) if record.exists() or record.is_symlink() else {}


def _recorded_cells(record: Path) -> dict:
    """``sweep.json``'s cells ({cell id: {param: value}}), or a one-line SweepError."""
    try:
        cells = json.loads(regular_file(record, "sweep record").read_text(encoding="utf-8")).get("cells")
    except SpecrefineError as exc:
        raise SweepError(str(exc)) from None
    except (OSError, UnicodeDecodeError, ValueError, AttributeError) as exc:
        raise SweepError(f"{record}: not a sweep record ({type(exc).__name__}): remove it to start over, or use "
                         f"another --out") from None
    if not isinstance(cells, dict) or not all(isinstance(v, dict) for v in cells.values()):
        raise SweepError(f"{record}: not a sweep record ('cells' is not a mapping of cell ids to their settings): "
                         f"remove it to start over, or use another --out")
    return cells


def run_sweep(cells: list[Cell], out_root, *, backend: str = "local", workers: int | None = None,
              address: str | None = None, retries: int = 1) -> Path:
    """Run every pending cell, appending rows to OUT/results.csv; returns the table's path.

    Raises :class:`SweepError` (before any cell runs) when ``OUT`` holds a cell run with other parameters, or its
    ``sweep.json`` or ``results.csv`` cannot be read back or written (``check_table``).
    """
    from ..core.runfolder import ensure_dir, locked

    out_root = ensure_dir(out_root)
    with locked(out_root):  # a second sweep here would race this one's rows and compaction of the table
        return _run_locked(cells, out_root, backend, workers, address, retries)


def _run_locked(cells: list[Cell], out_root: Path, backend: str, workers, address, retries: int) -> Path:
    table = out_root / "results.csv"
    check_table(table, cells)
    check_params(cells, out_root)
    try:
        for attempt in range(retries + 1):
            todo = pending(cells, table)
            if not todo:
                break
            runner = _run_ray if backend == "ray" else _run_local
            where = (str(out_root), *([tuple(loaded())] if loaded() else []))  # run_cell's arguments after the cell
            for row in counted(runner(todo, where, workers, address), len(todo),
                               f"sweep ({backend}, try {attempt + 1})", "cell", every=1):
                _append(table, row)
    finally:
        compact(table)
    return table


def _run_local(cells, where, workers, _address):
    """``where``: run_cell's arguments after the cell (the sweep folder, and its plugins if any)."""
    workers = workers or max(1, (os.cpu_count() or 1))
    if workers == 1:
        for cell in cells:
            yield run_cell(cell, *where)
        return
    # Imported once here, before the fork: importing mujoco starts a short-lived `python -c` (glfw's library
    # probe); in a worker, Ctrl-C could end the worker under it and the orphan printed a BrokenPipeError.
    import mujoco  # noqa: F401

    pool = ProcessPoolExecutor(max_workers=workers, initializer=_worker_init, initargs=(os.getpid(),),
                               mp_context=_mp_context())
    finished = False
    try:
        futures = {pool.submit(run_cell, cell, *where): cell for cell in cells}
        for fut in as_completed(futures):
            yield _row_of(fut, futures[fut])
        finished = True
    finally:
        if not finished:  # interrupted: no waiting for running cells
            _stop(pool)
        pool.shutdown(wait=True, cancel_futures=True)


def _row_of(fut, cell: Cell) -> dict:
    try:
        return fut.result()
    except BrokenProcessPool:  # a worker was killed (out of memory?) or crashed: the cell failed, the sweep goes on
        return {**cell.row(), "status": "error",
                "error": "the worker process running this cell died (killed or crashed)"}


def _stop(pool: ProcessPoolExecutor) -> None:
    procs = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in procs:
        proc.terminate()
    for proc in procs:
        proc.join(timeout=5)


def _mp_context():
    """fork where there is one (Linux's default before Python 3.14): a worker's parent is then the sweep itself."""
    import multiprocessing

    return multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else None)


def _worker_init(parent: int):
    """A pool worker: Ctrl-C is the parent's to handle, and the worker ends when its parent (the sweep) is gone."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_exit_with_parent, args=(parent,), daemon=True, name="sweep-parent").start()
    import torch

    torch.set_num_threads(1)


def _exit_with_parent(parent: int, every: float = 0.5) -> None:
    while os.getppid() == parent:
        time.sleep(every)
    os._exit(1)  # orphaned: the sweep that started this worker was killed


def _run_ray(cells, where, _workers, address):
    from ..core.extras import require

    ray = require("ray", "ray", "--backend ray")

    if not ray.is_initialized():
        ray.init(address=address, ignore_reinit_error=True, log_to_driver=False)
    remote = ray.remote(num_cpus=1)(run_cell)
    refs = [remote.remote(cell, *where) for cell in cells]
    try:
        while refs:
            ready, refs = ray.wait(refs, num_returns=1)
            yield ray.get(ready[0])
    finally:
        for ref in refs:  # Ctrl-C or an error: the cells still queued or running must not go on without the sweep
            with contextlib.suppress(Exception):
                ray.cancel(ref, force=True)


def summarise(rows: list[dict], by=("maze", "method", "proposer")) -> list[dict]:
    """Mean and population std (np.std's, as in the paper) of success over seeds, per group (``mean_std``)."""
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        if r.get("status") == "ok":
            if r.get("spec") and "maze" in by:  # a task other than the maze's own is its own group
                r = {**r, "maze": f"{r['maze']} [{r['spec']}]"}
            tuned = [f"{knob}={r[knob]}" for knob in (*KNOBS, "goal_points")
                     if knob not in by and r.get(knob) not in (None, "", getattr(PAPER, knob))]
            if tuned and "method" in by:  # so is a method run with other w, d or k than the paper's
                r = {**r, "method": f"{r['method']} [{', '.join(tuned)}]"}
            groups.setdefault(tuple(r[k] for k in by), []).append(r)
    out = []
    for key, rs in sorted(groups.items()):
        s_mean, s_std = mean_std([r["success_rate"] for r in rs])
        v_mean, v_std = mean_std([r["graph_vertices"] for r in rs])
        out.append({**dict(zip(by, key)), "runs": len(rs), "success_mean": s_mean, "success_std": s_std,
                    "vertices_mean": v_mean, "vertices_std": v_std, "seeds": sorted(int(r["seed"]) for r in rs)})
    return out


def mean_std(values, ddof: int = 0) -> tuple[float, float]:
    """Mean and standard deviation (population by default, np.std's) that do not depend on the values' order.

    A float sum rounds differently in another order: the same four runs listed by seed in two orders gave
    0.9875 and 0.98749999999999993, printed 0.988 and 0.987. math.fsum is exactly rounded, so equal runs give
    equal numbers whichever order their rows come in."""
    v = [float(x) for x in values]
    mean = math.fsum(v) / len(v)
    if len(v) <= ddof:
        return mean, 0.0
    return mean, math.sqrt(math.fsum((x - mean) ** 2 for x in v) / (len(v) - ddof))


def _check_specs(cells: list[Cell]) -> str | None:
    """The first bad (maze, spec) pair's or unknown standard map's one-line message, before any cell runs
    (None: all fine)."""
    from ..core.mazes import load_maze
    from ..core.spec import maze_task
    from ..core.standard_maps import PREFIX

    for maze in sorted({c.maze for c in cells if c.maze.startswith(PREFIX)}):
        try:
            load_maze(maze)
        except SpecrefineError as exc:
            return str(exc)
    for maze, spec in sorted({(c.maze, c.spec) for c in cells if c.spec}):
        try:
            maze_task(load_maze(maze), spec)
        except SpecrefineError as exc:
            return f"{maze}: {exc}"
    return None


def _check_policy(cells: list[Cell]) -> str | None:
    """One line if a cell's policy is not a usable checkpoint for its agent (before any cell runs)."""
    from .experiment import load_goal_policy

    for agent, policy in sorted({(c.agent, c.policy) for c in cells if c.policy != "shipped"}):
        try:
            load_goal_policy(agent, policy)
        except SpecrefineError as exc:
            return f"--policy {exc}"
    return None


PROG = "python -m specrefine.runs.sweep"  # its older path; `specrefine sweep` is the same command


def parser() -> OneLineParser:
    """The sweep's command line (as its older path names it)."""
    from ..core.commands import command_parser

    return command_parser("sweep", PROG)


def add_arguments(p) -> None:
    """The sweep's options (``specrefine sweep``)."""
    from .pipeline import METHODS

    p.description = __doc__.split("\n\n")[0]
    p.add_argument("--mazes", nargs="+", default=None,
                   help="maze names or files, gr:NAME (a Gymnasium-Robotics map, e.g. gr:U_MAZE) or random:RxC:SEED; "
                        "MAZE=SPEC runs that maze with the task SPEC (e.g. 'x=(a | b) -> G') (default: none: name "
                        "them, or give --all)")
    p.add_argument("--all", action="store_true",
                   help="every benchmark maze of data/mazes/ (what a sweep without --mazes ran before it was refused)")
    p.add_argument("--specs", nargs="+", default=[None], metavar="SPEC",
                   help="task expressions run on every maze without its own =SPEC (as specrefine refine --spec; "
                        "'' = the maze's own task; default: the maze's own task)")
    p.add_argument("--methods", nargs="+", choices=list(METHODS), default=["dirl", "symbolic", "vlm-oneshot", "ours"],
                   metavar="METHOD", help=f"methods, of: {', '.join(METHODS)}")
    p.add_argument("--proposers", nargs="+", type=proposer_arg, default=["geometric", "random"],
                   help="proposer strings, as specrefine refine --proposer (methods that ask none run once)")
    p.add_argument("--seeds", nargs="+", type=bounded_int("seed"), default=[0, 1, 2, 3], help="seeds")
    p.add_argument("--agent", default="point", choices=list(AGENTS), help="the agent of every cell")
    add_run_options(p, ["rollouts", "episodes"], suffix=" of every cell")
    add_run_options(p, ["goal_points"], suffix=" (every cell; named in the cell id when not sampled)")
    add_run_options(p, ["preset", *OTHER_SETTINGS], suffix=" (every cell)")
    add_run_options(p, KNOBS, many=KNOBS, suffix="; several values: one cell each (a method gets the values of those "
                                               "of w, d, k it reads)")
    p.add_argument("--evaluation", choices=["fixed", "adaptive"], default=None,
                   help="subtask evaluation of every cell (as specrefine refine --evaluation; part of the cell id "
                        "when adaptive) (default: the preset's: best: fixed for point, adaptive for ant; paper: fixed)")
    p.add_argument("--policy", default=None,
                   help="goal-conditioned policy of every cell: 'shipped' (data/policies/AGENT.pt), a shipped one's "
                        "name (ant_stage5) or a checkpoint path (recorded in OUT/sweep.json and the 'policy' column) "
                        "(default: the agent's adopted one: shipped for point, ant_stage5 for ant)")
    p.add_argument("--out", type=out_path, default="runs/sweep", help="the sweep folder (results.csv, cells/)")
    p.add_argument("--backend", choices=["local", "ray"], default="local",
                   help="local: a process pool; ray: Ray tasks (Ctrl-C cancels them; a killed sweep leaves them to "
                        "Ray; needs the 'ray' extra)")
    p.add_argument("--address", default=None, help="Ray cluster address (e.g. 127.0.0.1:6379; default: a local one)")
    p.add_argument("--workers", type=bounded_int("workers"), default=None, help="local processes (default: CPU count)")


def cells_of(args) -> list[Cell]:
    """The cells of parsed sweep arguments (no ``--mazes``: every benchmark maze; a relative ``--policy`` is taken
    from the working directory)."""
    from ..core.mazes import benchmark_mazes

    mazes = args.mazes if args.mazes is not None else sorted(benchmark_mazes())
    return grid(mazes, args.methods, args.proposers, args.seeds, agent=args.agent, rollouts=args.rollouts,
                episodes=args.episodes, specs=args.specs, evaluation=args.evaluation, w=args.w, d=args.d, k=args.k,
                goal_points=args.goal_points, preset=args.preset, policy=_policy_ref(args.policy),
                **{name: getattr(args, name) for name in OTHER_SETTINGS})


def _policy_ref(policy: str | None) -> str | None:
    """A --policy as cells record it: a name (None, 'shipped', a shipped checkpoint's) as given, a path absolute."""
    from ..core.paths import shipped_name

    return policy if policy in (None, "shipped") or shipped_name(policy) else str(Path(policy).resolve())


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("sweep", argv, prog=PROG)


def run(args, parser) -> int:
    if args.mazes is None and not args.all:
        return _fail(parser.prog, f"name the mazes (--mazes u_maze u_chain_2 ...), or give --all for every benchmark "
                                  f"maze ({len(cells_of(args))} cells with these options)", 2)
    if args.mazes is not None and args.all:
        return _fail(parser.prog, "--mazes and --all: give one of them", 2)
    if args.backend == "ray":  # before any work: a missing extra is one line, not a failed sweep
        from ..core.extras import require

        require("ray", "ray", "--backend ray")
    cells = cells_of(args)
    bad = maze_problem(args.mazes or []) or _check_specs(cells) or _check_policy(cells)
    if bad:
        return _fail(parser.prog, bad, 2)
    t0 = time.time()
    try:
        table = run_sweep(cells, args.out, backend=args.backend, workers=args.workers, address=args.address)
    except SpecrefineError as exc:
        return _fail(parser.prog, str(exc), 2)
    except KeyboardInterrupt:
        return _fail(parser.prog, f"interrupted; finished cells are kept in {Path(args.out) / 'results.csv'}: rerun "
                                  f"the same command to resume", 130)
    done = {r["cell"] for r in read_table(table) if is_done(r)}
    failed = sum(c.id not in done for c in cells)
    print(f"{len(cells)} cells -> {table} ({failed} failed) in {time.time() - t0:.0f} s")
    return 1 if cells and failed == len(cells) else 0


def _fail(prog: str, message: str, code: int) -> int:
    print(f"{prog}: error: {message}", file=sys.stderr)
    return code


if __name__ == "__main__":
    raise SystemExit(main())
