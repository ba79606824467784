"""Look back at a recorded search: the graph at any step, a picture per step, a slider.

A search's step log (``steps.jsonl`` next to ``result.json``, or ``SearchResult.steps``)
records every expansion, evaluation, generated and accepted refinement; accepted ones
carry a snapshot of the graph, so any step can be redrawn without rerunning anything.
"""

from __future__ import annotations

import json
from pathlib import Path

from ..core.graph import TaskGraph

EVENT_TEXT = {
    "expand": "close {vertex} (cost {cost:.2f})",
    "evaluate": "evaluate {edge[0]} -> {edge[1]}: p = {p:.2f}",
    "split-generated": "edge split proposed for {edge[0]} -> {edge[1]} ({n_candidates} candidates)",
    "vertex-generated": "vertex subset for {vertex}: p {p_current:.2f} -> {p_best:.2f}",
    "refine-accept": "ACCEPT {kind} on {edge[0]} -> {edge[1]} (cost {cost:.2f} < {c_progress:.2f} - tau {tau:.2f})",
    "refine-declined": "decline {kind} on {edge[0]} -> {edge[1]} (cost {cost:.2f} vs {c_progress:.2f} - tau {tau:.2f})",
    "done": "done: path {path}, predicted success {predicted_success:.2f}",
    "split-repaired": "repair the split of {edge[0]} -> {edge[1]}: {legs_repaired} leg(s) split again",
    "correct-check": "check the path on fresh rollouts{pass_text}: p = {p:.3f} over {n_legs} legs",
    "correct-leg": "correct leg {leg} ({edge[0]} -> {edge[1]}, fresh p {p_leg:.3f}, window {p_window:.3f}): "
                   "tried {tried_text}; accepted {accepted_text}{floor_text}",
    "correct-done": "correction done{pass_text}: p = {p:.3f} over {n_legs} legs (on the rollouts that chose them)",
    "rescue": "rescue: {reason}; the path corrected once more, {n_changes} settings changed",
    "roadmap": "roadmap for {edge[0]} -> {edge[1]} over {pooled} pooled waypoints: a chain of {waypoints}, "
               "{reach_text} ({evaluations} evaluations)",
}


def load_steps(path) -> list[dict]:
    return [json.loads(line) for line in Path(path).read_text().splitlines() if line.strip()]


def graph_at(steps: list[dict], input_graph: TaskGraph, i: int) -> TaskGraph:
    """The task graph as it was after step ``i``."""
    for step in reversed(steps[: i + 1]):
        if step.get("event") == "refine-accept" and "graph" in step:
            return TaskGraph.from_dict(step["graph"])
    return input_graph


def describe(step: dict) -> str:
    detail = dict(step)
    if "candidates" in detail:
        detail["n_candidates"] = len(detail["candidates"])
    if "probabilities" in detail:
        detail["n_legs"] = len(detail["probabilities"])
    if "reaches_end" in detail:
        detail["reach_text"] = "to the leg's end" if detail["reaches_end"] else "short of the leg's end"
    if "changes" in detail:
        detail["n_changes"] = len(detail["changes"])
    detail["pass_text"] = f" (pass {detail['correct_pass']})" if "correct_pass" in detail else ""
    if "tried" in detail:
        detail["tried_text"] = ", ".join(f"{t['kind']} {t['p_window']:.3f}" + _nearer(t) for t in detail["tried"]) \
            or "nothing"
        detail["accepted_text"] = detail.get("accepted") or "none"
        detail["floor_text"] = (f" (weak below {detail['weak_below']:.3f}: the path is below its floor)"
                                if "weak_below" in detail else "")
    try:
        return f"step {step['step']}: " + EVENT_TEXT[step["event"]].format(**detail)
    except (KeyError, IndexError, TypeError, ValueError):
        return f"step {step.get('step')}: {step.get('event')}"


def draw_step(maze, steps: list[dict], input_graph: TaskGraph, i: int, size_px: int = 640):
    from ..pictures.render import render_task

    step = steps[i]
    graph = graph_at(steps, input_graph, i)
    edge = step.get("edge")
    highlight = [edge[0], edge[1]] if edge and all(v in graph for v in edge) else step.get("path")
    fig = render_task(maze, graph, path=highlight, title=describe(step), size_px=size_px, legend=False)
    fig.axes[0].text(0.01, 0.01, f"open {step.get('open', [])}   closed {step.get('closed', [])}",
                     transform=fig.axes[0].transAxes, fontsize=8, va="bottom",
                     bbox={"facecolor": "white", "alpha": 0.85, "edgecolor": "none"})
    return fig


def step_png(maze, steps: list[dict], input_graph: TaskGraph, i: int, size_px: int = 640) -> bytes:
    """Step ``i`` of the search drawn as PNG bytes (``draw_step``'s figure)."""
    from ..pictures.render import to_png

    return to_png(draw_step(maze, steps, input_graph, i, size_px))


def search_slider(maze, steps: list[dict], input_graph: TaskGraph, size_px: int = 640):
    """An ipywidgets slider that redraws the search at each recorded step.

    The picture is an ``Image`` widget whose bytes the slider replaces, not an ``Output`` widget redrawn in place:
    executed headless (papermill, the notebook tests), an ``Output`` widget makes nbclient send the captured display
    back to the kernel while it waits for the cell's reply, and that exchange hung about one run in ten here
    (jupyter/nbclient#312)."""
    import ipywidgets as widgets

    last = len(steps) - 1
    image = widgets.Image(value=step_png(maze, steps, input_graph, last, size_px), format="png")
    slider = widgets.IntSlider(value=last, min=0, max=last, description="step", continuous_update=False,
                               layout=widgets.Layout(width="90%"))

    def show(change):
        image.value = step_png(maze, steps, input_graph, change["new"], size_px)

    slider.observe(show, names="value")
    return widgets.VBox([slider, image])


def _nearer(tried: dict) -> str:
    """How much nearer the dead leg's end an ``advance`` gets (ours-corrector-advance), where it was measured."""
    return f" ({tried['nearer']:+.2f} m nearer)" if tried.get("nearer") is not None else ""
