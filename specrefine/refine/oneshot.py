"""The one-shot VLM baseline (paper Sec. 5.1).

The proposer refines the WHOLE input graph in one query (with a one-shot example and its
reasoning in the prompt), w samples per query; each proposed graph is evaluated with the
same lazy shortest-path search as DiRL (so Theorem 4.2 holds for it); a second round feeds
the results back.  The best of the rounds x w graphs by predicted success is returned.
Unlike our method nothing guarantees the output implies the input: whether it does is
reported, through the same ``check_refines`` used everywhere (proposals arrive with edge
provenance: ``vlm.parse_graph`` infers it with ``graph.infer_parents``, offline proposers splice).
"""

from __future__ import annotations

import numpy as np

from ..core.graph import check_refines
from ..core.paper import PAPER
from .search import SearchResult, shortest_path


def oneshot(original, evaluator, proposer, *, maze, agent, w=PAPER.w, rounds=PAPER.d, seed=0, on_step=None,
            budget: tuple[int, int] | None = None) -> SearchResult:
    """The paper's baseline; with ``budget = (proposer calls, subtask evaluations)`` instead a best-of-N:
    first-round queries (no feedback) repeated until either budget is spent (the matched control)."""
    from ..proposers import GraphFeedback, GraphQuery

    steps: list[dict] = []

    def log(event, **detail):
        step = {"step": len(steps), "event": event, **detail}
        steps.append(step)
        if on_step:
            on_step(step)

    draw = _picture if getattr(proposer, "sees_images", True) else (lambda *_: None)
    base = shortest_path(original, evaluator, seed=seed)
    query = GraphQuery(maze=maze, agent=agent, graph=original, success=base.predicted_success, n=evaluator.n,
                       image_png=draw(maze, evaluator, original, base), edge_success=_edge_success(base),
                       facts=evaluator.facts())
    log("input-evaluated", predicted_success=base.predicted_success, path=base.path)
    best, feedback = None, []
    for round_, graphs in enumerate(_rounds(proposer, query, w, rounds, feedback, evaluator, budget)):
        for graph in graphs:
            result = shortest_path(graph, evaluator, seed=seed)
            problems = check_refines(graph, original)
            log("candidate", round=round_ + 1, predicted_success=result.predicted_success, path=result.path,
                refines_input=not problems, violations=[str(p) for p in problems[:5]], graph=graph.to_dict())
            if budget is None:
                feedback.append(GraphFeedback(graph=graph, edge_success=_edge_success(result),
                                              success=result.predicted_success,
                                              image_png=draw(maze, evaluator, graph, result)))
            if best is None or result.predicted_success > best.predicted_success:
                best = result
    if best is None:  # every reply was rejected: the input graph is all there is
        log("no-valid-candidate")
        best = base
    best.steps = steps
    log("done", predicted_success=best.predicted_success, path=best.path)
    return best


def _rounds(proposer, query, w, rounds, feedback, evaluator, budget):
    """The proposals of each round: ``rounds`` rounds with feedback, or first rounds until the budget is spent."""
    if budget is None:
        for _ in range(rounds):
            yield proposer.propose_graph(query, w, feedback)
        return
    calls, evaluations = budget
    start = evaluator.evaluations
    while proposer.proposer_calls < calls and evaluator.evaluations - start < evaluations:
        yield proposer.propose_graph(query, w, ())


def _edge_success(result: SearchResult) -> dict:
    if not result.path:
        return {}
    return dict(zip(zip(result.path, result.path[1:]), result.edge_probabilities))


def _picture(maze, evaluator, graph, result):
    """The graph on the map with rollouts of its best path (from the graph's initial set)."""
    from ..pictures.render import render_task, to_png

    if not result.path or len(result.path) < 2:
        return to_png(render_task(maze, graph))
    from ..evaluation.evaluator import path_legs

    n = min(evaluator.n, 32)
    legs = path_legs(graph, result.path)
    pr = evaluator.run_compositional(graph.region(graph.initial), legs, n=n, seed=evaluator.seed)
    fig = render_task(maze, graph, trajectories=pr.trajectories, success=np.asarray(pr.success), lengths=pr.lengths,
                      path=result.path, title=f"predicted success {result.predicted_success:.0%}")
    return to_png(fig)
