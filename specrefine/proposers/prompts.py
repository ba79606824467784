"""What the VLM is asked: the prompt templates in ``prompts/`` filled with the maze, the agent and the evaluation.

Templates use ``$name`` placeholders and ``[[image:NAME]]`` markers.  Every fact a prompt states
about the agent, the regions or the evaluation comes from the code that does it: the agent entry
(:mod:`specrefine.core.agents`) and the evaluator.
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from string import Template

import numpy as np

from ..core.agents import get_agent
from ..core.errors import SpecrefineError
from ..core.graph import TaskGraph
from ..core.paths import prompt_dir
from ..core.regions import Region, is_subset
from ..evaluation.evaluator import EvaluationFacts
from ..vlm.messages import build_content
from .base import CandidateFeedback, EdgeQuery, GraphFeedback, GraphQuery, graph_score
from .schema import region_json

_COMMENT = re.compile(r"\A\s*<!--.*?-->\s*", re.DOTALL)


def load_prompt(name: str) -> str:
    """Template text of ``prompts/NAME.md`` without its leading ``<!-- ... -->`` comment."""
    path = prompt_dir() / f"{name}.md"
    try:
        return _COMMENT.sub("", path.read_text(), count=1)
    except OSError as exc:
        raise SpecrefineError(f"{path}: cannot read prompt template ({exc.strerror or exc})") from None


def render_prompt(name: str, **values) -> str:
    """Fill ``prompts/NAME.md`` (``$name`` placeholders; ``$$`` is a literal dollar)."""
    try:
        return Template(load_prompt(name)).substitute({k: str(v) for k, v in values.items()}).strip()
    except KeyError as exc:
        raise SpecrefineError(f"prompts/{name}.md: no value for placeholder ${exc.args[0]}") from None


def _pct(p: float | None) -> str:
    return "not evaluated" if p is None or not np.isfinite(p) else f"{100 * float(p):.1f}%"


def _rj(region: Region) -> str:
    return json.dumps(region_json(region))


def environment_text(maze, agent: str, facts: EvaluationFacts | None = None) -> str:
    """The environment description in every prompt: maze geometry and frame, agent, policy, evaluation.

    Every number comes from the agent entry and the evaluator's ``facts`` (default: an evaluator
    with default settings on this maze), so the prompt says what the code does.
    """
    info = get_agent(agent)
    facts = facts or EvaluationFacts.default(agent, maze)
    r = f"{facts.clearance:.3g}"
    return "\n".join([
        maze.describe(),
        f"Agent: {agent}, {info.description}.",
        f"Policy: a goal-conditioned policy pretrained on an open floor to reach goal points up to "
        f"{info.policy_reach:g} m away; it knows nothing about walls (they are the task graph's job).",
        _target_sentence(facts, r),
        f"Body size: the agent's position is its centre; it counts as touching a wall when its centre comes within "
        f"{r} m of one, so keep waypoints at least that far from walls.",
        f"Time limit: {facts.horizon} control steps ({facts.horizon_seconds:g} s) per subtask.",
        _avoid_sentence(maze),
    ])


def _target_sentence(facts: EvaluationFacts, r: str) -> str:
    if facts.goal_points == "centre":
        aim = "the centre of the next region, in every rollout"
    elif facts.goal_points == "clear":
        aim = ("the point of the next region nearest its centre among those as far from walls as the region allows "
               "(a point half a cell from every wall is far enough), in every rollout")
    else:
        aim = (f"one target point, drawn uniformly at random inside the next region (at least {r} m from walls where "
               f"the region allows), a new draw per rollout")
    return (f"Target point: in each rollout of a subtask the policy steers towards {aim}; the subtask is reached as "
            f"soon as the agent's centre enters that region.")


def _avoid_sentence(maze) -> str:
    if maze.hazards is None:
        return "The maze walls are the avoid set of every subtask."
    return ("Hazards: the '~' cells are free floor without walls, but touching one fails the task like touching a "
            "wall; the walls and the hazards are the avoid set of every subtask, so route waypoints around the "
            "hazards (keep them at least the body size away).")


def _avoid_text(avoid: Region, maze) -> str:
    walls = maze.obstacles
    extra = [p for p in avoid.parts() if not is_subset(p, walls)]
    if not extra and is_subset(walls, avoid):
        return ("the maze walls (black) and hazards (purple in the pictures)" if maze.hazards is not None
                else "the maze walls (black in the pictures)")
    if not extra:
        return "parts of the maze walls: " + _rj(avoid)
    return "the maze walls and " + ", ".join(_rj(p) for p in extra)


def graph_text(graph: TaskGraph) -> str:
    """Vertices with regions and the edges, as shown to the VLM."""
    lines = ["vertices:"]
    for v in graph.vertices():
        tags = []
        if v == graph.initial:
            tags.append("initial")
        if v in graph.finals:
            tags.append("final")
        tag = f" [{', '.join(tags)}]" if tags else ""
        lines.append(f"  {v}{tag}: {_rj(graph.region(v))}")
    lines.append("edges: " + (", ".join(f"{u} -> {v}" for u, v in graph.edges()) or "(none)"))
    return "\n".join(lines)


def _edge_lines(graph: TaskGraph, edge_success: dict | None) -> str:
    edge_success = edge_success or {}
    return "\n".join(f"  {u} -> {v}: {_pct(edge_success.get((u, v)))}" for u, v in graph.edges()) or "  (no edges)"


def system_message() -> dict:
    return {"role": "system", "content": render_prompt("system", spec_api=render_prompt("spec_api"))}


def _edge_values(q: EdgeQuery) -> dict:
    context = ""
    if q.graph is not None:
        context = "\nThe edge belongs to this task graph (for context):\n" + graph_text(q.graph) + "\n"
    return dict(environment=environment_text(q.maze, q.agent, q.facts), start=_rj(q.start), goal=_rj(q.goal),
                avoid=_avoid_text(q.avoid, q.maze), success_pct=_pct(q.success),
                successes=int(round(q.success * q.n)), n=q.n, graph_context=context,
                schema=render_prompt("split_schema"))


def split_messages(q: EdgeQuery, feedback: Sequence[CandidateFeedback] = ()) -> list[dict]:
    """The chat messages of an edge-split query (first query, or follow-up with feedback)."""
    values = _edge_values(q)
    images = {"map": q.image_png}
    if not feedback:
        text = render_prompt("split_first", **values)
    else:
        blocks = []
        for j, fb in enumerate(feedback, start=1):
            legs = ["START"] + [f"x{i}" for i in range(1, len(fb.waypoints) + 1)] + ["GOAL"]
            lines = "\n".join(f"  {a} -> {b}: {_pct(p)}" for a, b, p in zip(legs, legs[1:], fb.subtask_success))
            blocks.append(render_prompt("split_candidate", index=j, round_note="",
                                        waypoints=json.dumps([region_json(w) for w in fb.waypoints]),
                                        subtask_lines=lines, overall_pct=_pct(fb.p)))
            images[f"candidate{j}"] = fb.image_png
        best = max(fb.p for fb in feedback)
        text = render_prompt("split_followup", **values, candidates="\n\n".join(blocks), best_pct=_pct(best))
    return [system_message(), {"role": "user", "content": build_content(text, images)}]


def graph_messages(q: GraphQuery, feedback: Sequence[GraphFeedback] = ()) -> list[dict]:
    """The chat messages of a one-shot whole-graph query (first, or follow-up with feedback)."""
    values = dict(environment=environment_text(q.maze, q.agent, q.facts), graph=graph_text(q.graph),
                  edge_lines=_edge_lines(q.graph, q.edge_success), success_pct=_pct(q.success), n=q.n,
                  example=render_prompt("graph_example"), schema=render_prompt("graph_schema"))
    images = {"map": q.image_png}
    if not feedback:
        text = render_prompt("graph_first", **values)
    else:
        blocks = []
        for j, fb in enumerate(feedback, start=1):
            blocks.append(render_prompt("graph_candidate", index=j, graph=graph_text(fb.graph),
                                        edge_lines=_edge_lines(fb.graph, fb.edge_success),
                                        overall_pct=_pct(graph_score(fb))))
            images[f"candidate{j}"] = fb.image_png
        best = max(graph_score(fb) for fb in feedback)
        text = render_prompt("graph_followup", **values, candidates="\n\n".join(blocks), best_pct=_pct(best))
    return [system_message(), {"role": "user", "content": build_content(text, images)}]
