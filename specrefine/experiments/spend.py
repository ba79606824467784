"""Where runs' simulator steps went, phase by phase, read from their evaluation caches (issue 39's cost).

    specrefine spend runs/ant_corrector_span --out data/results/corrector/diagnosis/spend.csv

Descriptive, no rule. Each phase of a search draws its rollouts at a fixed offset from the run's seed: the search's
own estimates (and each racing stage of adaptive evaluation, ``refine/racing.py``), polish's, the split
confirmation's, the tuning check's, each correction pass's (its fresh check and its alternatives judged on that draw)
and crosscheck's second draw. An evaluation cache entry names its draw's seed, so its offset names its phase; an
offset none of them makes is counted as ``other``. The correction's own Algorithm 1 calls and roadmap searches
estimate at the run's own seed, as the search does: such an entry is counted in the pass that was running when it was
written (the last whose first entry, its fresh check, was written before it; file times), as "pass N at the run's
seed". Runs logged since every step carried the counts so far (``specrefine show`` reads those) need none of this; it
serves the run folders written before (the Ant's corrector grids), and reads a run still going (or interrupted) as far
as its cache goes. Evaluations here are cache entries: each racing stage is one, as the evaluator counts it. Simulator
steps are each entry's own (the batch rows its episodes held); the run's counters also count the padding rows of
batches that several subtasks shared, so they sum to a few per cent less than ``result.json``'s search steps.
"""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import numpy as np

from ..core.errors import SpecrefineError
from ..refine.correct import CHECK_SEED_OFFSET, CROSS_SEED_OFFSET, PASS_SEED_STEP
from ..refine.racing import STAGE_SEED_OFFSET
from ..refine.search import CONFIRM_SEED_OFFSET, POLISH_SEED_OFFSET, TUNE_CHECK_SEED_OFFSET
from .taxonomy import run_folders

OWN_SEED = "at the run's seed"  # a pass's draws made as the search's: its Algorithm 1 calls and roadmap searches
PASSES = 4  # correction passes told apart (a pass beyond them counts as other)
STAGES = 4  # racing stages told apart
PACE_WINDOW_S = 1800.0  # the window a run still going is paced over
COLUMNS = ("cell", "maze", "method", "seed", "finished", "phase", "evaluations", "sim_steps", "share_of_steps")


def phase_offsets(passes: int = PASSES, stages: int = STAGES) -> dict[int, str]:
    """{seed offset from the run's seed: the phase that draws there}, racing stages included."""
    draws = {"search": 0, "polish": POLISH_SEED_OFFSET, "confirm": CONFIRM_SEED_OFFSET,
             "tune-check": TUNE_CHECK_SEED_OFFSET}
    for p in range(passes):
        draws[f"pass {p + 1}"] = CHECK_SEED_OFFSET + p * PASS_SEED_STEP
        draws[f"pass {p + 1} second draw"] = CHECK_SEED_OFFSET + p * PASS_SEED_STEP + CROSS_SEED_OFFSET
    offsets = {}
    for name, offset in draws.items():
        for stage in range(stages + 1):  # stage 0: the draw itself; stage s: racing's s-th stage of it
            at = offset + stage * STAGE_SEED_OFFSET
            if at in offsets:
                raise AssertionError(f"{name} and {offsets[at]} draw at the same offset {at}")
            offsets[at] = name
    return offsets


def cache_spend(folder: Path, seed: int) -> dict[str, Counter]:
    """{phase: Counter(evaluations=..., sim_steps=...)} over the cache entries under ``folder``; an unreadable entry
    is skipped (the run recomputes those too). An entry drawn at the run's own seed belongs to the search, or to the
    correction pass that was running when it was written (:func:`by_time`)."""
    spend: dict[str, Counter] = {}
    for phase, _, steps in by_time(cache_entries(folder, seed)):
        spend.setdefault(phase, Counter()).update(evaluations=1, sim_steps=steps)
    return spend


def cache_entries(folder: Path, seed: int, written_after: int = -1) -> list[tuple[str, int, int]]:
    """(phase by its draw's seed, file time in ns, simulator steps) per readable cache entry under ``folder``, of those
    written after ``written_after`` (ns; by default all: an older one is not opened)."""
    offsets = phase_offsets()
    entries = []  # (phase by seed, file time, steps)
    for entry in sorted(folder.rglob("*.npz")):
        if entry.is_symlink() or not entry.is_file():  # a FIFO would block the read; a link is not the run's own
            continue
        try:
            if (written := entry.stat().st_mtime_ns) <= written_after:
                continue
            with np.load(entry, allow_pickle=False) as z:
                key, steps = json.loads(str(z["key"])), int(z["steps"])
        except (OSError, ValueError, KeyError, TypeError):
            continue
        drawn = key.get("seed") if isinstance(key, dict) else None
        entries.append((offsets.get(drawn - seed, "other") if isinstance(drawn, int) else "other", written, steps))
    return entries


def recent_pace(folder: Path, now_ns: int, window_s: float = PACE_WINDOW_S) -> float:
    """Simulator steps a second over the last ``window_s`` seconds before ``now_ns``, from the cache entries written
    in it: how fast a run still going advances (an entry counts when its evaluation ends, so a window much shorter
    than the longest evaluation reads unevenly; time the run was not running counts too)."""
    return sum(steps for _, _, steps in cache_entries(folder, 0, now_ns - int(window_s * 1e9))) / window_s


def by_time(entries: list[tuple[str, int, int]]) -> list[tuple[str, int, int]]:
    """The entries with those drawn at the run's own seed ("search") moved to the correction pass that was running
    when they were written ("pass 1 at the run's seed"): the correction's Algorithm 1 calls and roadmap searches
    estimate as the search does, and a pass begins with its fresh check, the first entry written at its own draw. File
    times advance by the kernel's clock tick (a few ms), so an entry written in the tick a pass began counts in the
    phase before it: the check simulates its first leg before it writes, so what shares that tick came before."""
    starts = sorted((min(w for p, w, _ in entries if p == phase), phase)
                    for phase in {p for p, _, _ in entries if p.startswith("pass ") and "second" not in p})
    moved = []
    for phase, written, steps in entries:
        running = next((name for start, name in reversed(starts) if start < written), None)
        moved.append((f"{running} {OWN_SEED}" if phase == "search" and running else phase, written, steps))
    return moved


def run_rows(record: dict, folder: Path, finished: bool = True) -> list[dict]:
    """One row per phase of the run in ``folder`` (``record``: its result.json, or its run.json while it is not
    finished), most steps first."""
    seed = int(record["seed"])
    spend = cache_spend(folder / "cache", seed)
    total = sum(c["sim_steps"] for c in spend.values())
    return [{"cell": folder.name, "maze": record.get("maze", ""), "method": record.get("method", ""), "seed": seed,
             "finished": finished, "phase": phase, "evaluations": c["evaluations"], "sim_steps": c["sim_steps"],
             "share_of_steps": round(c["sim_steps"] / total, 4) if total else 0.0}
            for phase, c in sorted(spend.items(), key=lambda item: -item[1]["sim_steps"])]


def cell_rows(cell: Path) -> list[dict]:
    """A run folder's rows: finished (result.json), or still going or interrupted (its run.json names the seed)."""
    from ..core.records import read_json, read_result

    if (cell / "result.json").is_file():
        return run_rows(read_result(cell / "result.json"), cell)
    if not (cell / "run.json").is_file():
        return []
    record = read_json(cell / "run.json", "run.json")
    if not isinstance(record, dict) or not isinstance(record.get("seed"), int):
        raise SpecrefineError(f"{cell / 'run.json'}: not a run's record (no integer seed)")
    return run_rows(record, cell, finished=False)


def spend_rows(folders: list[Path]) -> list[dict]:
    rows = []
    for folder in folders:
        rows += [row for cell in run_folders(folder) if cell.is_dir() for row in cell_rows(cell)]
    if not rows:
        raise SpecrefineError("no run with an evaluation cache in the folders given")
    return rows


def unfinished_paces(folders: list[Path], rows: list[dict]) -> dict[str, float]:
    """{cell: recent_pace} for the runs of ``rows`` not finished, found again under ``folders``."""
    import time

    going = {row["cell"] for row in rows if not row["finished"]}
    cells = [cell for folder in folders for cell in run_folders(folder) if cell.name in going]
    return {cell.name: recent_pace(cell / "cache", time.time_ns()) for cell in cells}


def summary(rows: list[dict], paces: dict[str, float] | None = None) -> str:
    """Each run's phases as shares of its simulator steps, one line a run; ``paces`` ({cell: steps/s}, runs still
    going) a line under it."""
    paces = paces or {}
    lines, by_cell = [], {}
    for row in rows:
        by_cell.setdefault(row["cell"], []).append(row)
    for cell, phases in by_cell.items():
        total = sum(r["sim_steps"] for r in phases)
        parts = ", ".join(f"{r['phase']} {r['share_of_steps']:.0%} ({r['evaluations']} entries)" for r in phases)
        so_far = "" if phases[0]["finished"] else " so far (not finished)"
        lines.append(f"{cell}: {total / 1e6:.1f}M simulator steps{so_far}: {parts}")
        if cell in paces:
            lines.append(f"  {paces[cell] / 1e3:.1f}k simulator steps/s over the last {PACE_WINDOW_S / 60:.0f} min "
                         "(the steps its cache gained then)")
    return "\n".join(lines) + "\n"


def add_arguments(p) -> None:
    from ..core.argtypes import out_path

    p.description = __doc__.split("\n\n")[0]
    p.add_argument("runs", nargs="+", type=Path, help="sweep folders (their cells/) or run folders")
    p.add_argument("--out", type=out_path, default=None, help="a CSV of every run's phases (default: printed only)")


def run(args, p) -> int:
    from contextlib import nullcontext

    from ..core.runfolder import write_atomic, writing_into
    from ..core.tables import csv_text

    for folder in args.runs:
        if not folder.is_dir():
            raise SpecrefineError(f"{folder}: not a folder")
    with nullcontext() if args.out is None else writing_into(args.out) as out:  # checked before any work
        rows = spend_rows(args.runs)
        print(summary(rows, unfinished_paces(args.runs, rows)), end="")
        if out is not None:
            write_atomic(out, csv_text(rows, COLUMNS))
    return 0


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("spend", argv, prog="python -m specrefine.experiments.spend")


if __name__ == "__main__":
    raise SystemExit(main())
