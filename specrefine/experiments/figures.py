"""The paper's Figures 4-6 from a sweep table (``specrefine.runs.sweep``'s results.csv).

Each figure shows mean and population standard deviation over seeds (``np.std``, as in
the paper) and names the proposer on every panel: results from the offline proposers
are labelled as such and never as a VLM's. Runs whose legs aimed at the goal sets' centres
(``--goal-points centre``) are their method's, labelled with the rule.
"""

from __future__ import annotations

import numpy as np

from ..core.mazes import u_chain
from ..core.paper import PAPER
from ..core.runfolder import locked, save_figure, write_atomic
from ..core.tables import goal_points_of
from ..pictures.render import subplots
from ..runs.methods import METHOD_COLOURS, PROPOSER_METHODS  # colours: each method's registry entry
from ..runs.sweep import summarise

METHOD_ORDER = ["dirl", "symbolic", "vlm-oneshot", "ours"]
CORE_TASKS = ["split_doorway", "or_maze", "u_maze", "x_maze", "xx_maze_h", "xx_maze_v"]
EXTRA_TASKS = ["two_doors", "hazard_pool"]  # beyond the paper: a choice in the spec, a hazard pool


def proposer_label(proposer: str, rows=()) -> str:
    vlm = any(r.get("proposer") == proposer and r.get("proposer_is_vlm") for r in rows)
    if proposer in ("geometric", "random"):
        return f"proposer: {proposer} (offline, not a VLM)"
    if proposer == "imperfect" or proposer.startswith("imperfect:"):
        return f"proposer: {proposer} (offline error model, not a VLM)"
    return f"proposer: {proposer}" + (" (VLM)" if vlm else "")


def _proposers(rows) -> list[str]:
    return sorted({r["proposer"] for r in rows if r.get("status") == "ok" and r["proposer"] != "none"})


def _summary(rows) -> list[dict]:
    """Mean and std over seeds per maze, method, proposer and goal-point rule."""
    return summarise([{**r, "goal_points": goal_points_of(r)} for r in rows],
                     by=("maze", "method", "proposer", "goal_points"))


def _series(summary, methods) -> list[tuple[str, str]]:
    """(method, goal-point rule) for each method and each rule in the runs, the paper's rule first."""
    rules = sorted({s["goal_points"] for s in summary} or {PAPER.goal_points}, key=lambda g: g != PAPER.goal_points)
    return [(method, rule) for method in methods for rule in rules]


def _label(method: str, rule: str) -> str:
    return method if rule == PAPER.goal_points else f"{method}, {rule} goal points"


def _select(summary, maze, method, proposer, rule=PAPER.goal_points):
    prop = proposer if method in PROPOSER_METHODS else "none"
    return next((s for s in summary if (s["maze"], s["method"], s["proposer"], s["goal_points"])
                 == (maze, method, prop, rule)), None)


def figure4(rows, tasks=None, metric="success", methods=METHOD_ORDER, proposers=None, legend_outside=False):
    """Success (or graph size, metric='vertices') per task per method, one panel per proposer.

    ``proposers``: the panels (default: every proposer in ``rows``). ``legend_outside``: the legend right of
    the panels (for many methods or long panel titles, which the legend above the first panel would cover).
    """
    summary = _summary(rows)
    tasks = tasks or [t for t in CORE_TASKS + EXTRA_TASKS if any(s["maze"] == t for s in summary)]
    proposers = proposers or _proposers(rows) or ["none"]
    series = _series(summary, methods)
    fig, axes = subplots(len(proposers), 1, figsize=(max(8.5, 1.4 * len(tasks) + 2), 3.2 * len(proposers)),
                         squeeze=False)
    width = 0.8 / len(series)
    for ax, proposer in zip(axes[:, 0], proposers):
        for i, (method, rule) in enumerate(series):
            stats = [_select(summary, t, method, proposer, rule) for t in tasks]
            mean = [s[f"{metric}_mean"] if s else np.nan for s in stats]
            std = [s[f"{metric}_std"] if s else 0 for s in stats]
            x = np.arange(len(tasks)) + (i - (len(series) - 1) / 2) * width
            ax.bar(x, mean, width, yerr=std, capsize=2, label=_label(method, rule), color=METHOD_COLOURS[method],
                   hatch=None if rule == PAPER.goal_points else "//")
        ax.set_xticks(np.arange(len(tasks)), tasks, rotation=15)
        ax.set_ylabel("success rate" if metric == "success" else "task-graph vertices")
        if metric == "success":
            ax.set_ylim(0, 1.05)
        ax.set_title(proposer_label(proposer, rows), fontsize=10)
        ax.grid(axis="y", alpha=0.3)
    if legend_outside:
        axes[0, 0].legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    else:  # above the first panel, right of its title: inside, it would cover the bars that reach 1.0
        axes[0, 0].legend(ncol=len(series), fontsize=8, loc="lower right", bbox_to_anchor=(1.0, 1.0),
                          frameon=False, borderaxespad=0.2)
    fig.suptitle("Figure 4: success of the output compositional policy (mean ± std over seeds)"
                 if metric == "success" else "Figure 6: size of the output task graph (mean ± std over seeds)",
                 fontsize=11)
    fig.tight_layout()
    return fig


def figure6(rows, tasks=None, methods=METHOD_ORDER, proposers=None, legend_outside=False):
    return figure4(rows, tasks, metric="vertices", methods=methods, proposers=proposers,
                   legend_outside=legend_outside)


DODGE = 0.04  # rooms between neighbouring series in Figure 5


def figure5(rows, methods=METHOD_ORDER, proposers=None, legend_outside=False):
    """U-chain with 1-5 rooms, with and without subgoals: success vs rooms, one panel per proposer.

    ``legend_outside``: one legend right of the last panel instead of one in each (for many methods). Each series
    is shifted sideways by a few hundredths of a room, so that series with equal values do not hide each other.
    """
    summary = _summary(rows)
    proposers = proposers or _proposers(rows) or ["none"]
    fig, axes = subplots(1, len(proposers), figsize=(6 * len(proposers), 4), squeeze=False)
    series = [(method, rule, subgoals, style) for method, rule in _series(summary, methods)
              for subgoals, style in ((False, "-"), (True, "--"))]
    for ax, proposer in zip(axes[0], proposers):
        for i, (method, rule, subgoals, style) in enumerate(series):
            dodge = DODGE * (i - (len(series) - 1) / 2)  # equal series (ours = ours-repair) stay visible
            prop = proposer if method in PROPOSER_METHODS else "none"
            pts = _rooms(summary, method, prop, subgoals, rule)
            if subgoals:  # one room has no doorway: its "with subgoals" task is the plain one
                pts += [p for p in _rooms(summary, method, prop, False, rule) if p[0] == 1]
            if not pts:
                continue
            pts.sort()
            r, mu, sd = map(np.array, zip(*pts))
            ax.errorbar(r + dodge, mu, yerr=sd, ls=style, marker="o" if rule == PAPER.goal_points else "s",
                        capsize=3, color=METHOD_COLOURS[method],
                        label=f"{_label(method, rule)} ({'with' if subgoals else 'no'} subgoals)")
        ax.set_xlabel("rooms")
        ax.set_ylabel("success rate")
        ax.set_ylim(0, 1.05)
        ax.set_xticks(range(1, 6))
        ax.grid(alpha=0.3)
        ax.set_title(proposer_label(proposer, rows), fontsize=10)
        if not legend_outside and ax.get_legend_handles_labels()[0]:  # a panel without runs has no legend
            ax.legend(fontsize=7)
    if legend_outside:  # gathered from every panel: a proposer's panel may have no runs yet
        handles = {label: h for ax in axes[0] for h, label in zip(*ax.get_legend_handles_labels())}
        if handles:
            axes[0, -1].legend(handles.values(), handles.keys(), fontsize=7, loc="upper left",
                               bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.suptitle("Figure 5: U-chain of 1-5 rooms (mean ± std over seeds)")
    fig.tight_layout()
    return fig


def _rooms(summary, method, proposer, subgoals, rule=PAPER.goal_points):
    out = []
    for s in summary:
        chain = u_chain(s["maze"])
        same = (s["method"], s["proposer"], s["goal_points"]) == (method, proposer, rule)
        if chain and chain[1] == subgoals and same:
            out.append((chain[0], s["success_mean"], s["success_std"]))
    return out


def markdown_table(rows, by=("maze", "method", "proposer")) -> str:
    """Mean ± population std of success (and graph size) over seeds, as a markdown table."""
    lines = ["| maze | method | proposer | runs | success (mean ± std) | graph vertices |", "|---|---|---|---|---|---|"]
    for s in summarise(rows, by):
        lines.append(f"| {s['maze']} | {s['method']} | {s['proposer']} | {s['runs']} | "
                     f"{s['success_mean']:.3f} ± {s['success_std']:.3f} | {s['vertices_mean']:.1f} |")
    return "\n".join(lines)


def calibration_figure(tables: dict):
    """Measured success against the calibrated prediction, one marker per run, with both intervals.

    ``tables``: label -> rows with ``success_rate``, ``success_ci_low/high`` (optional) and
    ``predicted_success``, ``predicted_ci_low/high`` (e.g. ``python -m specrefine.runs.calibrate``'s table).
    A run is covered when its measured rate lies inside ``predicted_ci``; the legend gives the count per table.
    """
    from ..runs.calibrate import coverage

    fig, ax = subplots(figsize=(6.4, 6.0))
    for (label, rows), marker in zip(tables.items(), "osD^v<>"):
        rows = [r for r in rows if r.get("predicted_ci_low") not in (None, "")]
        if not rows:
            continue
        pred = np.array([float(r["predicted_success"]) for r in rows])
        meas = np.array([float(r["success_rate"]) for r in rows])
        lo, hi = (np.array([float(r[k]) for r in rows]) for k in ("predicted_ci_low", "predicted_ci_high"))
        inside, total = coverage(rows)
        ax.vlines(pred, lo, hi, color="0.75", lw=0.8, zorder=1)
        covered = (lo <= meas) & (meas <= hi)
        ax.scatter(pred[covered], meas[covered], marker=marker, s=14, label=f"{label}: {inside}/{total} covered",
                   zorder=2)
        ax.scatter(pred[~covered], meas[~covered], marker=marker, s=22, facecolors="none", edgecolors="#c62828",
                   zorder=3)
    ax.plot([0, 1], [0, 1], color="0.4", lw=0.8, ls="--")
    ax.set_xlim(-0.02, 1.02)
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel("predicted success (held-out posterior mean); grey: 95 % predictive interval")
    ax.set_ylabel("measured success (fresh episodes)")
    ax.set_title("Calibration: measured success vs the prediction (red rings: outside predicted_ci)", fontsize=10)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    return fig


def add_arguments(p) -> None:
    from ..core.argtypes import out_path

    p.description = "Figures 4-6 from a sweep table"
    p.add_argument("table", help="results.csv written by specrefine sweep")
    p.add_argument("--out", type=out_path, default=None,
                   help="folder for figure4/5/6.png and summary.md (default: the table's)")


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("figures", argv, prog="python -m specrefine.experiments.figures")


def run(args, p) -> int:
    from pathlib import Path

    from ..core.errors import SpecrefineError
    from ..core.runfolder import ensure_dir
    from ..runs.sweep import read_checked_table

    try:
        rows = read_checked_table(args.table)
        out = ensure_dir(args.out or Path(args.table).parent)
        with locked(out):  # a live sweep there (the default --out) is refused: draw it elsewhere or when it ends
            for name, make in (("figure4", figure4), ("figure5", figure5), ("figure6", figure6)):
                save_figure(make(rows), out / f"{name}.png", dpi=110)
            write_atomic(out / "summary.md", markdown_table(rows) + "\n")
    except SpecrefineError as exc:
        p.exit(2, f"{p.prog}: error: {exc}\n")
    print(f"{len(rows)} rows -> {out}/figure4.png, figure5.png, figure6.png, summary.md")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
