"""What a proposer is shown: the edge query with its picture (Algorithm 1's question) and a candidate's picture
(its feedback).  Methods that ask a proposer build their queries here; notebooks 03 and 04 use them directly."""

from __future__ import annotations

import numpy as np


def edge_query_builder(maze, agent, facts=None, *, images: bool = True):
    """(graph, u, v, EdgeResult) -> EdgeQuery with the picture of the edge's evaluated rollouts.

    ``facts``: the evaluator's ``facts()``, what the prompt says about the evaluation (default: an
    evaluator with default settings on ``maze``). ``images=False``: no picture (``image_png`` None).
    """
    from ..pictures.render import render_task, to_png
    from ..proposers import EdgeQuery

    def picture(graph, u, v, result):
        if not images:
            return None
        fig = render_task(maze, _edge_graph(graph, u, v), trajectories=getattr(result, "trajectories", None),
                          success=getattr(result, "success", None), lengths=getattr(result, "lengths", None),
                          title=f"{u} -> {v}: {result.p:.0%} of {result.n} rollouts succeed")
        return to_png(fig)

    def build(graph, u, v, result):
        return EdgeQuery(maze=maze, agent=agent, start=graph.region(u), goal=graph.region(v),
                         avoid=graph.avoid(u, v), success=result.p, n=result.n,
                         image_png=picture(graph, u, v, result), graph=graph, facts=facts)

    return build


def _edge_graph(graph, u, v):
    from ..core.graph import TaskGraph

    sub = TaskGraph(u)
    sub.add_vertex(u, graph.region(u), label=graph.label(u))
    sub.add_vertex(v, graph.region(v), label=graph.label(v))
    sub.add_edge(u, v, graph.avoid(u, v))
    sub.finals = {v}
    return sub


def candidate_picture(maze):
    """SplitCandidate -> PNG of its waypoints and the rollouts of each of its subtasks; ``picture(candidate,
    proposed=regions, title=...)`` also outlines the sets as proposed under a tuned candidate's subsets (Figure 3)."""
    from ..pictures.render import render_task, to_png

    def picture(candidate, proposed=None, title=None):
        legs = [r for r in candidate.results if getattr(r, "trajectories", None) is not None and r.n]
        if not legs:
            return None
        width = max(r.trajectories.shape[1] for r in legs)
        from ..core.results import pad_trajectories

        traj = np.concatenate([pad_trajectories(r.trajectories, width) for r in legs])
        fig = render_task(maze, trajectories=traj, success=np.concatenate([r.success for r in legs]),
                          lengths=np.concatenate([r.lengths for r in legs]), waypoints=candidate.waypoints,
                          proposed=proposed, title=title or "subtask success: " + ", ".join(
                              f"{p:.2f}" for p in candidate.probabilities))
        return to_png(fig)

    return picture
