"""rooms.png: success over rooms per method, one panel per preset (point mass)."""

from __future__ import annotations

import numpy as np

from .common import ORACLE


def rooms_figure(point: dict):
    """Success over rooms (U-chain 1-5 without subgoals, pooled over seeds) per method, one panel per preset."""
    from ...pictures.render import subplots
    from ..figures import METHOD_COLOURS

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
