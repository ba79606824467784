"""Figures of the goal policy: the training curve (``log.jsonl`` of :mod:`specrefine.train`) and the
open-floor evaluation (:mod:`specrefine.policy_eval`): success against goal distance, rollouts.

Figures are :class:`specrefine.render.PngFigure` (no pyplot: no global state; they show as PNGs in notebooks).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .policy_eval import success_by_distance


def read_log(path) -> list[dict]:
    """The lines of a trainer's ``log.jsonl`` as dicts (one per batch); [] when there is no log."""
    path = Path(path)
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()] if path.is_file() else []


def plot_curve(log_path, png_path=None, window: int = 10):
    """Success rate, return and frames/s against frames; saved to ``png_path`` when given."""
    from .render import PngFigure as Figure  # not pyplot: no global state; shows as a PNG in notebooks

    rows = read_log(log_path)
    fig = Figure(figsize=(13, 3.4))
    axes = fig.subplots(1, 3)
    if rows:
        f = np.array([r["frames"] for r in rows])
        for ax, key in zip(axes, ("success_rate", "return", "fps"), strict=True):
            y = np.array([np.nan if r.get(key) is None else r[key] for r in rows], dtype=float)
            ax.plot(f, y, alpha=0.3, color="C0")
            if len(y) >= window:
                ax.plot(f[window - 1:], np.convolve(np.nan_to_num(y), np.ones(window) / window, "valid"), color="C0")
            ax.set_xlabel("frames")
            ax.set_title(key)
            ax.grid(alpha=0.3)
    fig.tight_layout()
    if png_path is not None:
        fig.savefig(png_path, dpi=90)
    return fig


def plot_success_by_distance(result: dict, bins: int = 8):
    from .render import PngFigure as Figure

    rows = success_by_distance(result, bins)
    mid = [(r["from_m"] + r["to_m"]) / 2 for r in rows]
    p = np.array([np.nan if r["success_rate"] is None else r["success_rate"] for r in rows])
    lo, hi = np.array([r["ci95"][0] for r in rows]), np.array([r["ci95"][1] for r in rows])
    fig = Figure(figsize=(5, 3.2))
    ax = fig.subplots()
    ax.errorbar(mid, p, yerr=np.clip([p - lo, hi - p], 0, None), fmt="o-", capsize=3)
    ax.set(xlabel="goal distance (m)", ylabel="success rate", ylim=(0, 1.05),
           title=f"{result['agent']}: {result['success_rate']:.3f} over {result['episodes']} episodes")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def plot_rollouts(result: dict, n: int = 24):
    """Open-floor trajectories of ``evaluate_reach``: green success, red failure, x = goal."""
    from .render import PngFigure as Figure

    fig = Figure(figsize=(5, 5))
    ax = fig.subplots()
    for i in range(min(n, result["episodes"])):
        c = "tab:green" if result["success"][i] else "tab:red"
        tr = result["trajectories"][i, : result["steps"][i] + 1]
        ax.plot(tr[:, 0], tr[:, 1], color=c, lw=1)
        ax.plot(*result["goals"][i], "x", color=c)
    ax.plot(0, 0, "ko")
    ax.set_aspect("equal")
    ax.set(xlabel="x (m)", ylabel="y (m)", title=f"{result['agent']}: {min(n, result['episodes'])} rollouts")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig

