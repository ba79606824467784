"""``specrefine show RUN_DIR``: a finished run at a glance, from its files alone (nothing is simulated).

    specrefine show runs/demo

prints the run's summary (the input task beside the refined one), its path leg by leg (each subtask's estimate
from the search's rollouts and its measured success among the episodes that started it), where the wall time
went, what it asked of the proposer and the evaluator (and where: the search, a corrector's correction, the
measurement), the official environment's result if ``specrefine official`` has run, and the paths of its pictures
and files.  A run not finished yet (still going, or interrupted) is shown from its step log so far: whether a live
process holds the folder, the search's steps and proposer calls, and the correction's progress; a sweep's folder,
cell by cell.  A folder no run has started in is one line (exit 2).
"""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

from ..core.errors import SpecrefineError
from .pipeline import RunResult

SO_FAR = ("evaluations_so_far", "sim_steps_so_far")  # what each step of steps.jsonl counts so far (with proposer_calls)
PHASES = (("search_seconds", "search"), ("measure_seconds", "measurement"), ("calibrate_seconds", "calibration"),
          ("input_seconds", "input task (after the run's counters)"))
FILES = (("refined.png", "the refined task and the measured episodes"), ("graph.png", "the refined task graph"),
         ("roadmap.png", "the correction's roadmap: pooled waypoints, probes and what its searches reached"),
         ("policy.json", "the compositional policy, docs/official_env.md"),
         ("steps.jsonl", "the search, step by step"),
         ("official.json", "the policy in the official Gymnasium-Robotics environment"),
         ("result.json", "everything above, as data"))


def load_run(run_dir) -> dict:
    """``RUN_DIR/result.json`` checked by the records' schema (``core.records``: a FIFO, a folder or a device is
    refused unopened), or one SpecrefineError line saying why it is not a finished run."""
    from ..core.records import read_result

    path = Path(run_dir) / "result.json"
    if not path.exists() and not path.is_symlink():
        raise SpecrefineError(f"{path}: not found: RUN_DIR must be a finished 'specrefine refine' run folder")
    data = read_result(path)
    missing = [key for key in ("success_rate", "success_ci", "episodes", "path") if key not in data]
    if missing:
        raise SpecrefineError(f"{path}: not a finished run's result (no {', '.join(missing)})")
    return data


def show(run_dir) -> str:
    run_dir = Path(run_dir)
    if not (run_dir / "result.json").exists() and not (run_dir / "result.json").is_symlink():
        unfinished = sweep_text(run_dir) or unfinished_text(run_dir)
        if unfinished:
            return unfinished
    data = load_run(run_dir)
    try:
        parts = [RunResult(data, run_dir).summary(), path_text(data), time_text(data), cost_text(run_dir, data),
                 official_text(run_dir), files_text(run_dir)]
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise SpecrefineError(f"{run_dir / 'result.json'}: malformed ({type(exc).__name__}: {exc})") from None
    return "\n".join(part for part in parts if part)


def path_text(data: dict) -> str:
    """The chosen path, one subtask a line: the search's estimate and the measured success of that leg."""
    path = data.get("path")
    if not path:
        return "path: none found (no compositional policy)"
    estimates, measured = data.get("edge_probabilities", []), data.get("leg_success", [])
    lines = [f"path, leg by leg (estimate: the search's rollouts; measured: the {data['episodes']} episodes, among "
             "those that started the leg):"]
    width = max(len(f"{u} -> {v}") for u, v in zip(path, path[1:]))
    for i, (u, v) in enumerate(zip(path, path[1:])):
        estimate = f"{estimates[i]:.3f}" if i < len(estimates) else "  -  "
        leg = measured[i] if i < len(measured) else None
        lines.append(f"  {i + 1:>2}. {f'{u} -> {v}':<{width}}  estimate {estimate}  measured "
                     f"{'  -  ' if leg is None else f'{leg:.3f}'}")
    outcomes = data.get("episode_outcomes")
    if outcomes:
        lines.append("  episodes ended: " + ", ".join(f"{name} {count}" for name, count in outcomes.items()))
    before = data.get("input_task")
    if before and before.get("path"):
        lines.append(f"  the input task's path: {' -> '.join(before['path'])}, estimate {before['estimate']:.3f}, "
                     f"measured {before['success_rate']:.3f} ({before['episodes']} episodes; ended: "
                     + ", ".join(f"{name} {count}" for name, count in before.get("episode_outcomes", {}).items())
                     + ")")
    return "\n".join(lines)


def time_text(data: dict) -> str:
    """Where the wall time went: each phase's seconds and the rest (loading the policy, building the simulator)."""
    wall = float(data.get("wall_seconds", 0.0))
    phases = [(label, float(data[key])) for key, label in PHASES if key in data]
    if not phases:
        return f"time: {wall:.1f} s (no phase times recorded)"
    inside = sum(seconds for label, seconds in phases if not label.startswith("input"))
    shown = [f"{label} {seconds:.1f} s" for label, seconds in phases]
    return (f"time: {wall:.1f} s = " + ", ".join(shown[:3]) + f", setup {max(wall - inside, 0.0):.1f} s"
            + "".join(f"; then {part}" for part in shown[3:]))


def cost_text(run_dir: Path, data: dict) -> str:
    """What the run asked of the proposer and the evaluator, and where it spent it (:func:`spend_text`); where the run
    corrected its path, the proposer calls before and in the correction (steps.jsonl's steps carry the counts so
    far)."""
    calls = data.get("proposer_calls")
    if calls is None:
        return ""
    text = f"cost: {calls} proposer calls, {data.get('evaluations', '?')} evaluations"
    marks = phase_marks(run_dir / "steps.jsonl")
    before = marks.get("correction", {}).get("proposer_calls")
    rescued = marks.get("rescue", {}).get("proposer_calls")
    if isinstance(before, int) and isinstance(rescued, int):
        text += (f" (proposer calls: {before} in the search, {rescued - before} in the correction, {calls - rescued} "
                 "in its rescue)")
    elif isinstance(before, int):
        text += f" (proposer calls: {before} in the search, {calls - before} in the correction)"
    spend = spend_text(marks, data)
    return text + (f"\n{spend}" if spend else "")


def phase_marks(path: Path) -> dict[str, dict]:
    """The steps that end a run's phases, from its step log: ``correction`` the 'correct-begin' step (logged as the
    correction begins; in a log from before it, the first 'correct-check'), ``rescue`` the 'rescue' step (where the
    correction left a dead leg and the method rescues it), ``end`` the last step (the search's end); {} for a file
    that is not a readable regular one."""
    if not path.is_file() or path.is_symlink():
        return {}
    steps = _steps(path)
    marks = {"end": steps[-1]} if steps else {}
    begun = next((s for s in steps if s.get("event") in ("correct-begin", "correct-check")), None)
    rescue = next((s for s in steps if s.get("event") == "rescue"), None)
    return marks | ({"correction": begun} if begun is not None else {}) | ({"rescue": rescue} if rescue else {})


def spend_text(marks: dict[str, dict], data: dict) -> str:
    """Where the evaluations and simulator steps went: the search (up to the correction, where there is one), the
    correction, then the measurement and calibration (simulator steps only); "" where the log predates the counts."""
    end, check, rescue = marks.get("end", {}), marks.get("correction"), marks.get("rescue")
    ends = [step for step in (check, rescue, end) if step is not None]
    if not ends or not all(isinstance(step.get(key), int) for step in ends for key in SO_FAR):
        return ""
    labels = ["search", "correction", "rescue"][:len(ends)]  # a rescue follows a correction
    before = dict.fromkeys(SO_FAR, 0)
    parts = []
    for label, step in zip(labels, ends):
        evaluations, steps = (step[key] - before[key] for key in SO_FAR)
        parts.append(f"{label} {evaluations:,} evaluations ({_steps_count(steps)} simulator steps)")
        before = step
    total, searched = data.get("sim_steps"), end["sim_steps_so_far"]
    if isinstance(total, int) and total >= searched:
        parts.append(f"measurement and calibration {_steps_count(total - searched)} simulator steps")
    return "spent: " + ", ".join(parts)


def _steps_count(n: int) -> str:
    return f"{n / 1e6:.1f}M" if n >= 1_000_000 else f"{n:,}"


def unfinished_text(run_dir: Path) -> str | None:
    """A run started in ``run_dir`` and not finished (no result.json): what it runs, whether a live process still
    holds the folder, and its step log so far (the temporary file ``.steps.jsonl.PID.tmp`` that becomes steps.jsonl
    once the run is measured); None where no run has started here."""
    from ..core.records import read_json
    from ..core.runfolder import live_holder

    try:
        record = read_json(run_dir / "run.json", "run.json")
    except SpecrefineError:
        record = None
    pid, log = live_holder(run_dir), _step_log(run_dir)
    if not isinstance(record, dict) and log is None:
        return None
    record = record if isinstance(record, dict) else {}
    what = " · ".join(str(record[key]) for key in ("maze", "agent", "method", "proposer") if key in record)
    lines = [f"{what or run_dir}" + (f" · seed {record['seed']}" if "seed" in record else "") + ": not finished"]
    lines.append(f"state: running (pid {pid})" if pid is not None else
                 "state: interrupted (no live process holds the folder): the same command resumes it from its cache")
    return "\n".join(lines + _progress(log))


def _progress(log: Path | None, counts: bool = True) -> list[str]:
    """What a run's step log says so far: its steps by kind with the proposer calls and evaluations (``counts``), the
    correction, the phase."""
    steps = _steps(log) if log is not None else []
    if not steps:
        return ["no search step logged yet"]
    lines = [_counts(steps)] if counts else []
    return lines + [line for line in (_correction_so_far(steps), _phase(steps, log)) if line]


def _counts(steps: list[dict]) -> str:
    """The steps logged by kind, with the proposer calls and evaluations so far."""
    counts = Counter(str(step.get("event", "?")) for step in steps)
    so_far = [f"{last} {noun}" for key, noun in (("proposer_calls", "proposer calls"),
                                                 ("evaluations_so_far", "evaluations"))
              if (last := next((s[key] for s in reversed(steps) if isinstance(s.get(key), int)), None)) is not None]
    return (f"so far: {len(steps)} search steps (" + ", ".join(f"{event} {n}" for event, n in counts.items()) + ")"
            + "".join(f", {part}" for part in so_far))


def sweep_text(out: Path) -> str | None:
    """A sweep folder at a glance: each cell it has begun (``sweep.json``), done (its success, path legs and proposer
    calls from ``results.csv``), failed, running (its progress so far), stopped midway (a killed sweep's: the same
    command resumes it) or waiting; None where ``out`` is no sweep."""
    from ..core.runfolder import live_holder
    from ..core.tables import read_table
    from .sweep import is_done, known_cells

    cells = known_cells(out)
    if not cells:
        return None
    table = out / "results.csv"
    rows = {r["cell"]: r for r in read_table(table)} if table.is_file() else {}
    lines, states = [], Counter()
    for cell in cells:
        row, folder = rows.get(cell), out / "cells" / cell
        state = ("done" if is_done(row) else "failed") if row else "running" if live_holder(folder) else \
            "stopped" if (folder / "run.json").exists() else "waiting"
        states[state] += 1
        lines.append(f"  {state:<9}{cell}  {_cell_detail(state, row, folder)}".rstrip())
    counts = ", ".join(f"{n} {state}" for state, n in states.items())
    return "\n".join([f"sweep {out}: {len(cells)} cells begun ({counts})"] + lines)


def _cell_detail(state: str, row: dict | None, folder: Path) -> str:
    if state == "done":
        return (f"{row['success_rate']:.3f} [{row['success_ci_low']:.3f}, {row['success_ci_high']:.3f}], "
                f"{_whole(row.get('path_edges'))} legs, {_whole(row.get('proposer_calls'))} proposer calls, "
                f"{_whole(row.get('wall_seconds'))} s")
    if state == "failed":
        return str(row.get("error") or row.get("status"))
    if state in ("running", "stopped"):
        return "; ".join(_progress(_step_log(folder), counts=False))
    return ""


def _whole(count) -> str:
    return f"{count:.0f}" if isinstance(count, (int, float)) and not isinstance(count, bool) else "?"


def _step_log(run_dir: Path) -> Path | None:
    """The newest step log a run is writing (or a killed one left) in ``run_dir``, else its steps.jsonl once
    measured: a regular file, never a link."""
    import re
    import stat

    logs = []
    for path in run_dir.glob(".steps.jsonl.*.tmp"):
        try:
            st = path.lstat()
        except OSError:
            continue
        if re.fullmatch(r"\.steps\.jsonl\.\d+\.tmp", path.name) and stat.S_ISREG(st.st_mode):
            logs.append((st.st_mtime, path))
    if not logs:  # measured already: the log has its own name while the run draws its pictures and writes its result
        final = run_dir / "steps.jsonl"
        return final if final.is_file() and not final.is_symlink() else None
    return max(logs)[1]


def _steps(path: Path) -> list[dict]:
    """The step log's whole lines (the last may be half-written while the run goes)."""
    try:
        lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError:
        return []
    steps = []
    for line in lines:
        try:
            step = json.loads(line)
        except ValueError:
            continue
        if isinstance(step, dict):
            steps.append(step)
    return steps


def _correction_so_far(steps: list[dict]) -> str:
    """The correction's fresh check of the found path (and the latest pass's, where a later pass began) and the legs
    it has tried, where it has begun."""
    checks = [s for s in steps if s.get("event") == "correct-check"]
    if not checks:
        return ""
    legs = [s for s in steps if s.get("event") == "correct-leg"]
    taken = Counter(str(s["accepted"]) for s in legs if s.get("accepted"))
    latest = checks[-1]
    later = (f"; pass {latest.get('correct_pass', len(checks))}'s fresh check {_rate(latest.get('p'))} over "
             f"{_legs(latest)} legs" if len(checks) > 1 else "")
    return (f"correction: the found path's fresh check {_rate(checks[0].get('p'))} over {_legs(checks[0])} legs"
            f"{later}; {_n(len(legs), 'leg')} tried, {_n(sum(taken.values()), 'alternative')} taken"
            + (" (" + ", ".join(f"{kind} {n}" for kind, n in taken.items()) + ")" if taken else ""))


def _n(count: int, noun: str) -> str:
    return f"{count} {noun}" + ("" if count == 1 else "s")


def _legs(step: dict) -> int:
    return max(len(step.get("path") or []) - 1, 0)


def _phase(steps: list[dict], log: Path) -> str:
    """Where the run is after its last logged step, and how long ago the log was written."""
    import time

    try:
        ago = f", {_duration(time.time() - log.stat().st_mtime)} ago"
    except OSError:
        ago = ""
    last = steps[-1].get("event")
    if log.name == "steps.jsonl":
        return f"search, measurement and calibration done{ago}: measuring the input task, drawing, writing its result"
    if last == "done":  # a correction pass's end ("correct-done") may be followed by another pass
        return f"search done{ago}: measuring the found path (then calibration)"
    return f"last step: {last} (#{steps[-1].get('step', len(steps) - 1)}){ago}"


def _duration(seconds: float) -> str:
    seconds = max(seconds, 0.0)
    return f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.0f} min" if seconds < 7200 else \
        f"{seconds / 3600:.1f} h"


def _rate(p) -> str:
    return f"{p:.3f}" if isinstance(p, (int, float)) else "?"


def official_text(run_dir: Path) -> str:
    path = run_dir / "official.json"
    if not path.exists():
        return f"official environment: not run (specrefine official {run_dir})"
    try:
        from .official import summary

        return summary(json.loads(path.read_text(encoding="utf-8")))
    except (OSError, ValueError, KeyError, TypeError):
        return f"official environment: {path} unreadable"


def files_text(run_dir: Path) -> str:
    lines = ["files:"]
    for name, what in FILES:
        if (run_dir / name).exists():
            lines.append(f"  {run_dir / name}  ({what})")
    return "\n".join(lines)


# --- the command (specrefine show) ---------------------------------------------------------------------------
def add_arguments(parser) -> None:
    parser.description = ("A finished run at a glance: its summary (the input task beside the refined one), its path "
                          "leg by leg with estimates and measured success, where the time went, and its pictures. "
                          "A run not finished yet (running or interrupted) is shown from its step log so far.")
    parser.add_argument("run_dir", metavar="RUN_DIR", type=Path,
                        help="a 'specrefine refine' output folder (finished, running or interrupted)")


def run(args, parser=None) -> int:
    print(show(args.run_dir), flush=True)
    return 0
