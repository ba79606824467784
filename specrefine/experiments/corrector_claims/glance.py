"""glance.png: the corrector at a glance, success per U-chain with its 95 % interval, for the point mass (mild,
moderate) and the Ant (moderate), beside the oracle, ``ours`` and the one-shot, from the same tables the rules read."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...core.agents import get_agent
from ...core.results import wilson_ci
from ..grids import GRIDS, ROOT, SCALING_MAZES
from .ant import ANT_ERRING, ANT_ONESHOT, ANT_REDRAW, ANT_SEEDS, ANT_SPAN, REDRAW
from .common import ORACLE, POINT_SEEDS, SPAN, episodes_of, load
from .frontpage import _maze_label

ANT_FLOOR_LINE = 0.85  # issue 39's floor for the Ant, drawn on its panel
ANT_ORACLE_GRID, ANT_ORACLE_METHOD = "ant-oracle-confirm", "ours-confirm"
#: each curve's role: (legend label, colour, line style, marker)
STYLE = {"oracle": (None, "black", "--", "o"),
         "corrector": (None, "#c62828", "-", "o"),
         "span": (None, "#6a1b9a", "-", "D"),
         "ours": ("ours (the paper's search)", "#1565c0", "-", "s"),
         "vlm-oneshot": ("vlm-oneshot (the paper's baseline)", "#ef6c00", "-", "^")}


def glance_panels(root: Path = ROOT) -> list[dict]:
    """Per panel: its title and, per curve, its role, label and (successes, episodes, runs) per U-chain maze."""
    from .variants import variant_rows

    default = get_agent("point").default_method  # the point mass's --preset best method
    point = variant_rows(default, root)
    panels = []
    for proposer in ("imperfect:mild", "imperfect:moderate"):
        curves = [("oracle", ORACLE), ("corrector", (default, proposer)), ("ours", ("ours", proposer)),
                  ("vlm-oneshot", ("vlm-oneshot", proposer))]
        panels.append(_panel("point mass", proposer, point, curves, POINT_SEEDS, f"{default} (default)"))
    # the Ant's oracle at its correctors' settings (the split's later-round pick confirmed): README's reference there
    ant = load(GRIDS[ANT_REDRAW].tables + GRIDS[ANT_SPAN].tables + GRIDS[ANT_ORACLE_GRID].tables
               + (ANT_ONESHOT, ANT_ERRING), root)
    oracle = next((r["proposer"] for r in ant if r["method"] == ANT_ORACLE_METHOD), "geometric")
    proposer = "imperfect:moderate"
    curves = [("oracle", (ANT_ORACLE_METHOD, oracle)), ("corrector", (REDRAW, proposer)), ("span", (SPAN, proposer)),
              ("ours", ("ours", proposer)), ("vlm-oneshot", ("vlm-oneshot", proposer))]
    rescued = get_agent("ant").default_method != REDRAW  # the rescue, adopted: redraw's runs are its own here
    note = "the default's run: its rescue never fires here" if rescued else "default"
    panels.append(_panel("Ant", proposer, ant, curves, ANT_SEEDS, f"{REDRAW} ({note})", floor=ANT_FLOOR_LINE))
    return panels


def _panel(agent: str, proposer: str, rows: list[dict], curves: list, seeds, corrector: str,
           floor: float | None = None) -> dict:
    out = []
    for role, (method, drawn_by) in curves:
        counts = [episodes_of(rows, maze, method, drawn_by, seeds) for maze in SCALING_MAZES]
        runs, cells = sum(c[2] for c in counts), len(SCALING_MAZES) * len(seeds)
        label = {"corrector": corrector, "span": SPAN, "oracle": f"oracle ({method}, geometric planner)"
                 }.get(role, STYLE[role][0])
        out.append({"role": role, "label": label + (f" ({runs} of {cells} runs)" if runs < cells else ""),
                    "counts": counts})
    return {"agent": agent, "title": f"{agent}, {proposer}", "curves": out, "floor": floor}


def legend_labels(panels: list[dict]) -> dict[str, str]:
    """{role: its legend line}: the label where every agent's panels give it the same one, else each agent's."""
    agents = {panel["agent"] for panel in panels}
    by_role: dict[str, dict[str, str]] = {}
    for panel in panels:
        for curve in panel["curves"]:
            if any(n for _, n, _ in curve["counts"]):
                by_role.setdefault(curve["role"], {}).setdefault(panel["agent"], curve["label"])
    return {role: next(iter(labels.values())) if len(set(labels.values())) == 1 and set(labels) == agents
            else "; ".join(f"{agent}: {label}" for agent, label in labels.items()) for role, labels in by_role.items()}


def glance_figure(panels: list[dict]):
    """One panel per agent and preset: x the U-chains (Un: n rooms, s: with subgoals), y success pooled over seeds
    with its Wilson 95 % interval; a maze a method has not run is a gap in its curve."""
    from ...pictures.render import subplots

    fig, axes = subplots(1, len(panels), figsize=(4.6 * len(panels), 4.4), sharey=True)
    xs = np.arange(len(SCALING_MAZES))
    handles = {}
    for ax, panel in zip(np.atleast_1d(axes), panels):
        for i, curve in enumerate(panel["curves"]):
            _, colour, style, marker = STYLE[curve["role"]]
            if not any(n for _, n, _ in curve["counts"]):
                continue
            # a maze not run is a gap in the curve (NaN), not a line drawn across it
            y, low, high = (np.array(v) for v in zip(*[(k / n, *wilson_ci(k, n)) if n else (np.nan,) * 3
                                                       for k, n, _ in curve["counts"]]))
            shift = (i - (len(panel["curves"]) - 1) / 2) * 0.06  # curves side by side where they overlap
            handles[curve["role"]] = ax.errorbar(xs + shift, y, yerr=[y - low, high - y], color=colour, ls=style,
                                                 marker=marker, ms=4, capsize=2, lw=1.3,
                                                 zorder=3 if curve["role"] == "oracle" else 2)  # seen where tied
        if panel["floor"] is not None:
            ax.axhline(panel["floor"], color="#9e9e9e", ls=":", lw=1)
            ax.text(xs[-1], panel["floor"] - 0.05, f"floor {panel['floor']}", ha="right", fontsize=7,
                    color="#616161")
        ax.set_title(f"{panel['title']} (offline, not a VLM)", fontsize=9)
        ax.set_xticks(xs, [_maze_label(m) for m in SCALING_MAZES], fontsize=8)
        ax.set_xlabel("U-chain (Un: n rooms; s: with subgoals)", fontsize=8)
        ax.set_ylim(-0.03, 1.05)
        ax.grid(alpha=0.3)
    np.atleast_1d(axes)[0].set_ylabel("success, pooled over seeds\n(Wilson 95 % CI of the episodes)")
    labels = legend_labels(panels)
    roles = [role for role in STYLE if role in handles]
    fig.legend([handles[r] for r in roles], [labels[r] for r in roles], loc="lower center", ncol=2, fontsize=8,
               frameon=False)
    fig.tight_layout(rect=(0, 0.14, 1, 1))
    return fig
