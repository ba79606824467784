"""The offline comparison of docs/proposers.md ("The comparison"): its figures and the paper's two claims.

The proposer of every run here is ``imperfect:*``, an error model standing in for a VLM: it is NOT a VLM,
and every figure and table says so. Claims, per preset, with 95 % bootstrap intervals (percentile,
``BOOTSTRAP_RESAMPLES`` resamples, numpy seed ``BOOTSTRAP_SEED``):

* "ours >= 2x one-shot on multi-room tasks": mean success of ``ours`` over that of ``vlm-oneshot`` on
  ``MULTI_ROOM_MAZES``, resampling (maze, seed) cells;
* "flat over 1-5 rooms": for each method, the least-squares change of success from 1 to 5 rooms
  (slope x 4) on u_chain_1..5, resampling seeds within each room; flat when its interval lies within
  +-``FLAT_TOLERANCE`` (the paper says ``ours`` is flat and ``vlm-oneshot`` falls).

A cell of the fixed grid without an ``ok`` row is reported as missing: every entry states the cells
it used (``n_cells`` of ``n_expected``), the seeds, and which are missing. An entry with a missing cell
is ``complete = False`` and is not the comparison the grid fixed.

``python -m specrefine.experiments.comparison TABLE --out DIR`` writes the figures, ``claims.md`` and ``claims.json``;
``--grid ant`` reads the Ant comparison of docs/ant_experiments.md instead (the paper's four methods, proposers
``geometric`` and ``imperfect:moderate``, seeds 0-2; the claims on ``ours`` and ``vlm-oneshot``), ``--grid NAME``
any grid of ``specrefine.experiments.grids`` with claim methods; a grid's cells are that module's.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ..core.runfolder import save_figure, write_atomic
from ..pictures.render import subplots
from ..runs.sweep import is_done, mean_std
from .figures import METHOD_COLOURS, figure4, figure5, proposer_label
from .grids import GRIDS as REGISTRY
from .grids import ExperimentGrid as Grid
from .grids import cells as run_cells

#: The offline comparison of docs/proposers.md (point mass, eight methods, four presets, four seeds).
POINT_GRID = REGISTRY["point-comparison"]
#: The Ant comparison of docs/ant_experiments.md section 3: the paper's methods, claims on ours and one-shot.
ANT_GRID = REGISTRY["ant-comparison"]
#: ``--grid``: the two comparisons by their short names, and every grid of the registry with claim methods
GRIDS = {"point": POINT_GRID, "ant": ANT_GRID} | {name: g for name, g in REGISTRY.items() if g.claim_methods}
COMPARISON_METHODS = list(POINT_GRID.methods)
ERROR_LEVELS = list(POINT_GRID.levels)  # alpha = 0: the x axis, in order
PRESETS = list(POINT_GRID.proposers)
#: imperfect:moderate,alpha=0.1 builds the paper's hypothesis into the model: shown apart from the levels
ALPHA_PRESET = next(p for p in PRESETS if p not in ERROR_LEVELS)
SEEDS = POINT_GRID.seeds
U_CHAIN_ROOMS = {n: f"u_chain_{n}" for n in range(1, 6)}  # rooms -> the maze without subgoals

#: The multi-room tasks of claim (i): the U-chains of 2-5 rooms, with and without subgoals at the doorways.
#: docs/proposers.md fixed the claim on "U-chain 2-5" before any result, and the paper's multi-room study
#: (its Figure 5) is the U-chain with and without subgoals. or_maze (one room, a block in the middle),
#: x_maze / xx_maze_* (rooms around a cross of walls) are left out: counting them would change the claim
#: after the grid was fixed. ``ratio_claim(..., mazes=...)`` computes it on any other set.
MULTI_ROOM_MAZES = tuple(f"u_chain_{n}{suffix}" for n in range(2, 6) for suffix in ("", "_subgoals"))
RATIO_CLAIM = 2.0
#: Largest change of success from 1 to 5 rooms (either way) that still counts as flat: about the half-width
#: of one run's 95 % Wilson interval at 200 episodes and p = 0.9 (0.042), i.e. what one run can resolve.
FLAT_TOLERANCE = 0.05
PAPER_ROOM_CLAIMS = {"ours": "flat", "vlm-oneshot": "falls"}
BOOTSTRAP_RESAMPLES = 10_000
BOOTSTRAP_SEED = 0



RATIO_CLAIM_TEXT = "ours >= 2x one-shot on multi-room tasks"
ROOMS_CLAIM_TEXT = "success over 1-5 rooms"  # the paper: flat for ours, falling for vlm-oneshot
OFFLINE_NOTE = "every proposer here is offline, NOT a VLM (geometric: a planner on the map; imperfect:*: error model)"


def mean_ratio(pairs: list[tuple[dict, dict]], key: str) -> float:
    """Mean of ``key`` over the first rows of ``pairs`` over its mean over the second (NaN without pairs): a cost
    ratio over paired cells, as the corrector claims state proposer calls and evaluations."""
    if not pairs:
        return math.nan
    return float(np.mean([float(a[key]) for a, _ in pairs]) / np.mean([float(b[key]) for _, b in pairs]))


def _task_rows(rows, agent: str) -> list[dict]:
    """The rows of ``agent`` on each maze's own task (not another task or agent, nor a row cut short before its
    seed)."""
    return [r for r in rows if not r.get("spec") and r.get("agent", agent) == agent and isinstance(r.get("seed"), int)]


def table_cells(rows, agent: str = "point") -> tuple[dict, set]:
    """(maze, method, proposer, seed) -> success of the last ``ok`` row of the maze's own task; and the cells
    whose rows all failed (a failed run has no success to report)."""
    ok, tried = {}, set()
    for r in _task_rows(rows, agent):
        key = (r["maze"], r["method"], r["proposer"], r["seed"])
        tried.add(key)
        if is_done(r):
            ok[key] = float(r["success_rate"])
    return ok, tried - set(ok)


def _missing_text(maze, seed, methods, failed, proposer) -> str:
    why = ["failed" if (maze, m, proposer, seed) in failed else "no row" for m in methods]
    return f"{maze} s{seed}: " + ", ".join(f"{m} ({w})" for m, w in zip(methods, why))


def _entry(claim, proposer, method, estimate, ci, verdict, n_expected, seeds, missing, note="") -> dict:
    kind = "ratio" if claim == RATIO_CLAIM_TEXT else "rooms"
    paper = "ours >= 2x" if kind == "ratio" else PAPER_ROOM_CLAIMS.get(method, "")
    return {"claim": claim, "kind": kind, "proposer": proposer, "method": method, "paper": paper,
            "estimate": float(estimate), "ci_low": float(ci[0]), "ci_high": float(ci[1]), "verdict": verdict,
            "n_cells": n_expected - len(missing), "n_expected": n_expected, "seeds": sorted(seeds),
            "missing": missing, "complete": not missing, "note": note}


def _percentile_ci(boot) -> tuple[float, float]:
    if np.isnan(boot).any():  # an undefined resample (0/0) makes the interval undefined, not narrower
        return (math.nan, math.nan)
    lo, hi = np.quantile(boot, [0.025, 0.975], method="inverted_cdf")  # no interpolation: inf stays inf
    return float(lo), float(hi)


def _ratio(num, den):
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1), np.where(num > 0, np.inf, np.nan))


def ratio_claim(cells, failed, proposer, seeds=SEEDS, mazes=MULTI_ROOM_MAZES) -> dict:
    """Claim (i): mean success of ours / vlm-oneshot over the (maze, seed) cells where both ran."""
    pairs, missing, used_seeds = [], [], set()
    for maze in mazes:
        for seed in seeds:
            values = [cells.get((maze, m, proposer, seed)) for m in ("ours", "vlm-oneshot")]
            lacking = [m for m, v in zip(("ours", "vlm-oneshot"), values) if v is None]
            if lacking:
                missing.append(_missing_text(maze, seed, lacking, failed, proposer))
            else:
                pairs.append(values)
                used_seeds.add(seed)
    n_expected = len(mazes) * len(seeds)
    if not pairs:
        return _entry(RATIO_CLAIM_TEXT, proposer, "ours / vlm-oneshot", math.nan, (math.nan, math.nan),
                      "undecided", n_expected, used_seeds, missing, "no cell with both methods")
    num, den = np.array(pairs, dtype=float).T
    ratio, ci, undefined = bootstrap_ratio(num, den)
    note = f"ratio undefined (0/0: both methods at 0) in {undefined} of {BOOTSTRAP_RESAMPLES} resamples" \
        if undefined else ""
    return _entry(RATIO_CLAIM_TEXT, proposer, "ours / vlm-oneshot", ratio, ci,
                  threshold_verdict(ci, RATIO_CLAIM), n_expected, used_seeds, missing, note) | {
        "ceiling": float(_ratio(1.0, den.mean())), "oneshot_mean": float(den.mean())}


def ratio_rule_text(entry) -> str:
    """The ratio with its interval and, where the one-shot's mean on these cells leaves no method room to reach
    RATIO_CLAIM (every cell at 1 gives 1 / its mean), that ceiling: the claim cannot be shown there."""
    text = _interval_text(entry)
    ceiling = entry.get("ceiling", math.inf)
    if ceiling < RATIO_CLAIM:
        text += (f"; at most {ceiling:.3f} is possible here (the one-shot's mean {entry['oneshot_mean']:.3f}, "
                 "every cell at 1.000 would give that)")
    return text


def bootstrap_ratio(num: np.ndarray, den: np.ndarray) -> tuple[float, tuple[float, float], int]:
    """mean(num) / mean(den) over paired cells, its 95 % percentile bootstrap interval (cells resampled, the claims'
    seed) and how many resamples left it undefined (0/0: both means 0, which makes the interval undefined)."""
    idx = np.random.default_rng(BOOTSTRAP_SEED).integers(0, len(num), (BOOTSTRAP_RESAMPLES, len(num)))
    boot = _ratio(num[idx].mean(axis=1), den[idx].mean(axis=1))
    return float(_ratio(num.mean(), den.mean())), _percentile_ci(boot), int(np.isnan(boot).sum())


def paired_difference(cells, failed, proposer, first, second, seeds=SEEDS, mazes=MULTI_ROOM_MAZES) -> dict:
    """Mean of the paired success difference ``first`` - ``second`` over the (maze, seed) cells where both ran, with
    its 95 % bootstrap interval (cells resampled); verdict ``higher`` if the interval lies above 0, ``lower`` if
    below, else ``undecided``."""
    diffs, missing, used_seeds = [], [], set()
    for maze in mazes:
        for seed in seeds:
            pair = [cells.get((maze, m, proposer, seed)) for m in (first, second)]
            if None in pair:
                lacking = [m for m, v in zip((first, second), pair) if v is None]
                missing.append(_missing_text(maze, seed, lacking, failed, proposer))
            else:
                diffs.append(pair[0] - pair[1])
                used_seeds.add(seed)
    entry = {"claim": f"{first} - {second}", "kind": "paired", "proposer": proposer, "method": first, "paper": "",
             "n_expected": len(mazes) * len(seeds), "n_cells": len(diffs), "seeds": sorted(used_seeds),
             "missing": missing, "complete": not missing, "note": ""}
    if not diffs:
        return entry | {"estimate": math.nan, "ci_low": math.nan, "ci_high": math.nan, "verdict": "undecided",
                        "note": "no cell with both methods"}
    d = np.array(diffs)
    idx = np.random.default_rng(BOOTSTRAP_SEED).integers(0, len(d), (BOOTSTRAP_RESAMPLES, len(d)))
    lo, hi = _percentile_ci(d[idx].mean(axis=1))
    verdict = "higher" if lo > 0 else "lower" if hi < 0 else "undecided"
    return entry | {"estimate": float(d.mean()), "ci_low": lo, "ci_high": hi, "verdict": verdict}


def threshold_verdict(ci, threshold) -> str:
    lo, hi = ci
    if lo >= threshold:
        return "holds"
    if hi < threshold:
        return "does not hold"
    return "undecided"  # the interval straddles the threshold (or is undefined)


def _change_1_to_5(rooms, means):
    """Least-squares slope of success on rooms, times 4: the fitted change from 1 to 5 rooms (per row of means)."""
    x = np.asarray(rooms, float) - np.mean(rooms)
    means = np.asarray(means, float)
    centred = means - means.mean(axis=-1, keepdims=True)
    return 4 * (centred @ x) / (x @ x)


def rooms_verdict(ci, tolerance=FLAT_TOLERANCE) -> str:
    lo, hi = ci
    if -tolerance <= lo and hi <= tolerance:
        return "flat"
    if hi < -tolerance:
        return "falls"
    if lo > tolerance:
        return "rises"
    return "undecided"


def rooms_claim(cells, failed, proposer, method, seeds=SEEDS) -> dict:
    """Claim (ii) for one method: the change of success from 1 to 5 rooms on u_chain_1..5, CI over seeds."""
    by_room, missing, used_seeds = {}, [], set()
    for rooms, maze in U_CHAIN_ROOMS.items():
        values = []
        for seed in seeds:
            value = cells.get((maze, method, proposer, seed))
            if value is None:
                missing.append(_missing_text(maze, seed, [method], failed, proposer))
            else:
                values.append(value)
                used_seeds.add(seed)
        if values:
            by_room[rooms] = np.array(values)
    n_expected = len(U_CHAIN_ROOMS) * len(seeds)
    claim = f"{method} {ROOMS_CLAIM_TEXT}"
    absent = [r for r in U_CHAIN_ROOMS if r not in by_room]
    note = f"rooms with no run: {absent}" if absent else ""
    if len(by_room) < 2:
        return _entry(claim, proposer, method, math.nan, (math.nan, math.nan), "undecided", n_expected,
                      used_seeds, missing, note or "fewer than two room counts")
    rooms = sorted(by_room)
    rng = np.random.default_rng(BOOTSTRAP_SEED)
    boot_means = np.stack([by_room[r][rng.integers(0, len(by_room[r]), (BOOTSTRAP_RESAMPLES, len(by_room[r])))]
                           .mean(axis=1) for r in rooms], axis=1)  # seeds resampled within each room
    ci = _percentile_ci(_change_1_to_5(rooms, boot_means))
    estimate = _change_1_to_5(rooms, [by_room[r].mean() for r in rooms])
    return _entry(claim, proposer, method, estimate, ci, rooms_verdict(ci), n_expected, used_seeds, missing, note)


def claims(rows, grid: Grid = POINT_GRID) -> list[dict]:
    """Both claims for every proposer of ``grid``: the ratio entry, then the rooms entry of each claim method."""
    cells, failed = table_cells(rows, grid.agent)
    out = []
    for proposer in grid.proposers:
        out.append(ratio_claim(cells, failed, proposer, grid.seeds))
        out += [rooms_claim(cells, failed, proposer, method, grid.seeds) for method in grid.claim_methods]
    return out


def contrasts(rows, grid: Grid = POINT_GRID) -> list[dict]:
    """The grid's control contrasts (``paired_difference`` on the multi-room cells), per proposer: descriptive, not
    claims the grid fixed."""
    cells, failed = table_cells(rows, grid.agent)
    return [paired_difference(cells, failed, proposer, first, second, grid.seeds)
            for proposer in grid.proposers for first, second in grid.contrasts]


def contrasts_markdown(entries) -> str:
    lines = ["Control contrasts (descriptive, not claims the grid fixed): mean paired difference of success on the "
             "multi-room (maze, seed) cells, 95 % bootstrap percentile interval (the claims' resamples and seed).", "",
             "| proposer | difference | estimate [95 % CI] | verdict | cells (seeds) | missing |",
             "|---|---|---|---|---|---|"]
    for e in entries:
        seeds = ",".join(map(str, e["seeds"])) or "none"
        estimate = "—" if math.isnan(e["estimate"]) else \
            f"{e['estimate']:+.3f} [{e['ci_low']:+.3f}, {e['ci_high']:+.3f}]"
        lines.append(f"| {e['proposer']} | {e['claim']} | {estimate} | {e['verdict']} | {e['n_cells']}/"
                     f"{e['n_expected']} ({seeds}) | {_missing_summary(e['missing'])} |")
    return "\n".join(lines)


def _interval_text(entry) -> str:
    e, lo, hi = entry["estimate"], entry["ci_low"], entry["ci_high"]
    if math.isnan(e):
        return "—"
    prefix = "ratio" if entry["kind"] == "ratio" else "change 1→5 rooms"
    sign = "" if entry["kind"] == "ratio" else "+"
    return f"{prefix} {e:{sign}.3f} [{lo:{sign}.3f}, {hi:{sign}.3f}]"


def _missing_summary(missing, shown: int = 3) -> str:
    if not missing:
        return "none"
    more = f"; … {len(missing) - shown} more" if len(missing) > shown else ""
    return f"{len(missing)}: " + "; ".join(missing[:shown]) + more


def markdown(entries) -> str:
    """A README table of ``claims(...)``: estimate with its 95 % interval, verdict, cells used and missing."""
    lines = [f"{OFFLINE_NOTE}. 95 % bootstrap percentile intervals ({BOOTSTRAP_RESAMPLES} resamples, numpy seed "
             f"{BOOTSTRAP_SEED}): the ratio over (maze, seed) cells of {', '.join(MULTI_ROOM_MAZES)}; the change "
             f"from 1 to 5 rooms (least-squares slope x 4 on u_chain_1..5) resampling seeds within each room, "
             f"flat when its interval lies within ±{FLAT_TOLERANCE}. An entry marked *partial* lacks cells of "
             "the fixed grid and is not the comparison the grid fixed.", "",
             "| proposer | claim | paper | estimate [95 % CI] | verdict | cells (seeds) | missing |",
             "|---|---|---|---|---|---|---|"]
    for e in entries:
        verdict = e["verdict"] + ("" if e["complete"] else " (*partial*)")
        note = f" ({e['note']})" if e["note"] else ""
        seeds = ",".join(map(str, e["seeds"])) or "none"
        lines.append(f"| {e['proposer']} | {e['claim']} | {e['paper'] or '—'} | {_interval_text(e)}{note} | "
                     f"{verdict} | {e['n_cells']}/{e['n_expected']} ({seeds}) | {_missing_summary(e['missing'])} |")
    return "\n".join(lines)


T_975 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160, 2.145, 2.131,
         2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042]


def mean_ci(values) -> tuple[float, float, float]:
    """Mean with a 95 % Student-t interval over seeds, clipped to [0, 1]; no interval from one seed."""
    if len(values) == 0:
        return (math.nan, math.nan, math.nan)
    mean, std = mean_std(values, ddof=1)  # order-free, as summary.md's means
    if len(values) < 2:
        return (mean, mean, mean)
    df = len(values) - 1
    t = T_975[df - 1] if df <= len(T_975) else 1.96 + (1.96**3 + 1.96) / (4 * df)  # Cornish-Fisher beyond the table
    half = t * std / math.sqrt(len(values))
    return (mean, max(0.0, mean - half), min(1.0, mean + half))


def _level_label(proposer: str) -> str:
    return proposer.split(":", 1)[1].replace(",", "\n")


def error_level_figure(rows, methods=COMPARISON_METHODS, levels=ERROR_LEVELS, extra=ALPHA_PRESET,
                       rooms=tuple(U_CHAIN_ROOMS), agent: str = "point"):
    """End-to-end success against proposer error level, one panel per U-chain length (no subgoals): per method,
    the mean over seeds with a 95 % t-interval band over ``levels``, and ``extra`` as a separate marker."""
    cells, _ = table_cells(rows, agent)
    fig, axes = subplots(1, len(rooms), figsize=(3.4 * len(rooms), 4.2), sharey=True, squeeze=False)
    x_extra = len(levels) - 0.4
    counts = []
    for ax, n in zip(axes[0], rooms):
        maze = U_CHAIN_ROOMS[n]
        for i, method in enumerate(methods):
            colour, shift = METHOD_COLOURS.get(method), (i - (len(methods) - 1) / 2) * 0.04
            stats = []
            for proposer in [*levels, extra]:
                values = [v for (m, me, prop, _), v in cells.items() if (m, me, prop) == (maze, method, proposer)]
                counts.append(len(values))
                stats.append(mean_ci(values))
            mean, lo, hi = map(np.array, zip(*stats))
            x = np.arange(len(levels)) + shift
            ax.plot(x, mean[:-1], marker="o", color=colour, label=method)
            ax.fill_between(x, lo[:-1], hi[:-1], color=colour, alpha=0.12, linewidth=0)
            ax.errorbar([x_extra + shift], mean[-1:], yerr=[mean[-1:] - lo[-1:], hi[-1:] - mean[-1:]], fmt="D",
                        mfc="none", color=colour, capsize=2)
        ax.axvline(len(levels) - 0.7, color="k", lw=0.6, ls=":")
        ax.set_xticks([*range(len(levels)), x_extra], [_level_label(p) for p in [*levels, extra]], fontsize=8)
        ax.set_ylim(0, 1.05)
        ax.grid(alpha=0.3)
        ax.set_title(f"{maze} ({n} room{'s' * (n > 1)})\n{proposer_label('imperfect')}", fontsize=8)
    axes[0, 0].set_ylabel("end-to-end success")
    axes[0, 0].legend(fontsize=7, loc="lower left")
    seeds = f"{min(counts)}" if min(counts) == max(counts) else f"{min(counts)}-{max(counts)}"
    fig.suptitle("Success against the offline proposer's error level, U-chain of 1-5 rooms "
                 f"(mean over seeds, 95 % t-interval; seeds per point: {seeds})", fontsize=10)
    fig.tight_layout()
    return fig


def comparison_figures(rows, grid: Grid = POINT_GRID) -> dict:
    """name -> figure: Figures 4 and 5 of the grid's methods, one panel per proposer, and (for a grid with error
    levels) the error-level figure."""
    rows = [r for r in rows if r.get("agent", grid.agent) == grid.agent]
    present = [p for p in grid.proposers if any(r.get("proposer") == p for r in rows)]
    if not present:
        return {}
    figures = {"figure4": figure4(rows, methods=list(grid.methods), proposers=present, legend_outside=True),
               "figure5": figure5(rows, methods=list(grid.methods), proposers=present, legend_outside=True)}
    if grid.levels:
        figures["error_levels"] = error_level_figure(rows, methods=list(grid.methods), levels=list(grid.levels),
                                                     agent=grid.agent)
    return figures


def grid_cells(grid: Grid = POINT_GRID) -> set:
    """The fixed grid's (maze, method, proposer, seed) keys (``grids.cells``: a method without a proposer, dirl or
    symbolic, once per seed, with proposer ``none``, as ``specrefine.runs.sweep`` runs it)."""
    return {(c.maze, c.method, c.proposer, c.seed) for c in run_cells(grid)}


def expected_cells(grid: Grid = POINT_GRID) -> int:
    return len(grid_cells(grid))


def table_note(path, rows, grid: Grid = POINT_GRID) -> str:
    """One line on how much of the fixed grid a table holds (a missing or partial table is no error)."""
    if not Path(path).exists():
        return f"no comparison table at {path}: nothing to draw (its sweep has not run here)"
    cells, _ = table_cells(rows, grid.agent)
    done, expected = len(grid_cells(grid) & set(cells)), expected_cells(grid)
    if done < expected:
        return (f"{path}: PARTIAL, {done} of {expected} runs of the fixed grid have an ok row; "
                "what follows is not the comparison the grid fixed")
    return f"{path}: all {done} runs of the fixed grid have an ok row"


def _seed_runs(rows, grid: Grid, seed: int) -> dict:
    """The grid agent's done runs of one seed, by (maze, method, proposer)."""
    return {(r["maze"], r["method"], r["proposer"]): r for r in _task_rows(rows, grid.agent)
            if r["seed"] == seed and is_done(r)}


def seed_table(rows, grid: Grid, seed: int) -> tuple[str, int, int]:
    """One seed of the grid as markdown (a line per maze; success [95 % Wilson CI] per method and proposer, "—"
    where the cell has no ok row), with the number of cells it shows and the grid's number at that seed."""
    from ..core.mazes import benchmark_mazes
    from ..runs.pipeline import PROPOSER_METHODS

    done = _seed_runs(rows, grid, seed)
    columns = [(m, "none") for m in grid.methods if m not in PROPOSER_METHODS]
    columns += [(m, p) for p in grid.proposers for m in grid.methods if m in PROPOSER_METHODS]
    lines = ["| maze | " + " | ".join(m if p == "none" else f"{m}, {p}" for m, p in columns) + " |",
             "|---" * (len(columns) + 1) + "|"]
    shown, mazes = 0, benchmark_mazes()
    for maze in mazes:
        cells = [done.get((maze, m, p)) for m, p in columns]
        shown += sum(r is not None for r in cells)
        lines.append(f"| {maze} | " + " | ".join(
            "—" if r is None else f"{r['success_rate']:.3f} [{r['success_ci_low']:.3f}, {r['success_ci_high']:.3f}]"
            for r in cells) + " |")
    return "\n".join(lines), shown, len(mazes) * len(columns)


def _named(mazes) -> str:
    return f"{len(mazes)} maze{'s' * (len(mazes) != 1)}" + (f" ({', '.join(mazes)})" if mazes else "")


def seed_contrast(rows, grid: Grid, seed: int) -> list[str]:
    """One seed, a line per proposer: the mazes where the first claim method (``ours``) is above or below the
    second (``vlm-oneshot``) with disjoint 95 % CIs, how many overlap, and where the first measures 0 (descriptive:
    one seed, one run per maze; the claims pool the seeds). Mazes without both runs are left out and counted."""
    from ..core.mazes import benchmark_mazes

    first, second = grid.claim_methods[:2]
    done = _seed_runs(rows, grid, seed)
    lines = []
    for proposer in grid.proposers:
        above, below, overlap, zero, absent = [], [], [], [], 0
        for maze in benchmark_mazes():
            a, b = done.get((maze, first, proposer)), done.get((maze, second, proposer))
            if a is None or b is None:
                absent += 1
                continue
            side = (above if a["success_ci_low"] > b["success_ci_high"]
                    else below if a["success_ci_high"] < b["success_ci_low"] else overlap)
            side.append(maze)
            if a["success_rate"] == 0:
                zero.append(maze)
        lines.append(f"- `{proposer}`: `{first}` above `{second}` (disjoint 95 % CIs) on {_named(above)}, below on "
                     f"{_named(below)}, overlapping on {len(overlap)}; `{first}` at 0.000 on {_named(zero)}"
                     + (f"; {absent} mazes without both runs" if absent else "") + ".")
    return lines


def _jsonable(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_jsonable(v) for v in value]
    return value


def write_claims(entries, out: Path, table, grid: Grid = POINT_GRID, contrast_entries=()) -> None:
    about = {"table": str(table), "note": OFFLINE_NOTE, "agent": grid.agent,
             "multi_room_mazes": list(MULTI_ROOM_MAZES),
             "ratio_threshold": RATIO_CLAIM, "flat_tolerance": FLAT_TOLERANCE, "seeds": list(grid.seeds),
             "bootstrap_resamples": BOOTSTRAP_RESAMPLES, "bootstrap_seed": BOOTSTRAP_SEED}
    record = {"about": about, "claims": entries} | ({"contrasts": list(contrast_entries)} if contrast_entries else {})
    write_atomic(out / "claims.json", json.dumps(_jsonable(record), indent=1) + "\n")
    extra = f"\n{contrasts_markdown(contrast_entries)}\n" if contrast_entries else ""
    write_atomic(out / "claims.md", markdown(entries) + "\n" + extra)


def main(argv=None) -> int:
    from ..core.argtypes import OneLineParser, out_path
    from ..core.errors import SpecrefineError
    from ..core.runfolder import ensure_dir
    from ..runs.sweep import read_checked_table

    p = OneLineParser(prog="python -m specrefine.experiments.comparison", description=__doc__.split("\n")[0])
    p.add_argument("table", help="results.csv of the comparison sweep (specrefine.runs.sweep)")
    p.add_argument("--out", required=True, type=out_path,
                   help="folder for figure4.png, figure5.png, error_levels.png, claims.md, claims.json and "
                        "seedS.md (one table per seed)")
    p.add_argument("--grid", choices=sorted(GRIDS), default="point",
                   help="point: docs/proposers.md's comparison (default); ant: docs/ant_experiments.md section 3; "
                        "or a grid of specrefine.experiments.grids with claim methods")
    args = p.parse_args(argv)
    grid = GRIDS[args.grid]
    try:
        rows = read_checked_table(args.table)
        out = ensure_dir(args.out)
    except SpecrefineError as exc:
        p.exit(2, f"{p.prog}: error: {exc}\n")
    for name, fig in comparison_figures(rows, grid).items():
        save_figure(fig, out / f"{name}.png", dpi=110)
    entries = claims(rows, grid)
    write_claims(entries, out, args.table, grid, contrasts(rows, grid))
    for seed in grid.seeds:
        table, shown, expected = seed_table(rows, grid, seed)
        contrast = "\n".join(seed_contrast(rows, grid, seed))
        write_atomic(out / f"seed{seed}.md", f"Seed {seed}: {shown} of {expected} cells ({OFFLINE_NOTE}; success "
                                             f"over fresh episodes, 95 % Wilson CI).\n\n{table}\n\n{contrast}\n")
    partial = sum(not e["complete"] for e in entries)
    print(table_note(args.table, rows, grid))  # after the files: a closed stdout (`| head`) loses none of them
    print(f"{len(rows)} rows -> {out}: figures, claims.md, claims.json ({partial} of {len(entries)} entries partial)")
    return 0


if __name__ == "__main__":
    from ..core.argtypes import exit_code_quiet_on_broken_pipe

    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
