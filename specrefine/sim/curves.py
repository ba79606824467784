"""Figures of the goal policy: the training curve (``log.jsonl`` of :mod:`specrefine.sim.train`) and the
open-floor evaluation (:mod:`specrefine.sim.policy_eval`): success against goal distance, rollouts.

Figures are :class:`specrefine.pictures.render.PngFigure` (no pyplot: no global state; they show as PNGs in notebooks).
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


#: the panels of the training curve, log.jsonl keys: progress, then the PPO diagnostics of specrefine.sim.train
CURVE_PANELS = ("success_rate", "return", "fps", "approx_kl", "clip_fraction", "entropy", "explained_variance",
                "value_loss")


def plot_curve(log_path, png_path=None, window: int = 10):
    """One panel per :data:`CURVE_PANELS` key against frames (success rate, return, frames/s and the PPO
    diagnostics: approximate KL, clip fraction, entropy, explained variance, value loss); raw values faint,
    a ``window``-batch moving average on top; saved to ``png_path`` when given."""
    from ..pictures.render import PngFigure as Figure  # not pyplot: no global state; shows as a PNG in notebooks

    rows = read_log(log_path)
    fig = Figure(figsize=(13, 6.4))
    axes = fig.subplots(2, 4).ravel()
    f = np.array([r["frames"] for r in rows])
    for ax, key in zip(axes, CURVE_PANELS, strict=True):
        y = np.array([np.nan if r.get(key) is None else r[key] for r in rows], dtype=float)
        if any(key in r for r in rows):
            ax.plot(f, y, alpha=0.3, color="C0")
            if len(y) >= window:
                ax.plot(f[window - 1:], np.convolve(np.nan_to_num(y), np.ones(window) / window, "valid"), color="C0")
        elif rows:  # a log from before the diagnostics were logged
            ax.text(0.5, 0.5, "not in this log", ha="center", va="center", transform=ax.transAxes, color="0.5")
        ax.set_xlabel("frames")
        ax.locator_params(axis="x", nbins=4)  # frame counts are wide labels
        ax.set_title(key)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    if png_path is not None:
        from ..core.runfolder import save_figure

        save_figure(fig, png_path, dpi=90)
    return fig


def plot_success_by_distance(result: dict, bins: int = 8):
    from ..pictures.render import PngFigure as Figure

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
    from ..pictures.render import PngFigure as Figure

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

