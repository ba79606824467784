"""Look-ahead repair of an edge split (beyond the paper: method ``ours-repair``).

Algorithm 3 keeps a split only if its legs' product of success beats the unsplit edge, and Algorithm 1 applies
to the components of a split only once it is kept. So when no candidate of an edge split succeeds end to end,
the search keeps none, and a candidate whose one leg cuts through a wall is never repaired: with an erring
proposer a run ends with the input graph (success 0) where a single further split would have carried it.

The repair looks one split ahead. When no candidate succeeds end to end, the candidate with the cheapest legs
(the longest run of feasible legs) has its first never-succeeding leg split by Algorithm 1 itself (a query for
that leg, started from where the legs before it end); a split that makes the leg feasible is spliced into the
candidate and the legs after it are estimated again, and the next failing leg is repaired in turn, while the
search's budget of edge splits lasts. The repaired candidate is then judged by the paper's rule like any other,
and it refines the input graph as any split does (a longer chain of waypoints on the same edge).
"""

from __future__ import annotations

from collections.abc import Callable

from ..core.graph import TaskGraph
from .common import SubtaskEvaluator, estimate_legs, start_of, weight
from .edge_split import SplitCandidate, SplitOutcome, split_legs

#: (graph holding the candidate's chain, a, b, the leg's EdgeResult, start of the leg) -> Algorithm 1 on a -> b
SplitLeg = Callable[[TaskGraph, str, str, object, object], SplitOutcome]


def cheapest(candidates: list[SplitCandidate], n: int) -> SplitCandidate:
    """The candidate with the smallest sum of leg weights (among failures: the most that succeeds before a wall)."""
    return min(candidates, key=lambda c: sum(weight(p, n) for p in c.probabilities))


def repair(candidate: SplitCandidate, graph: TaskGraph, u: str, v: str, *, start, evaluator: SubtaskEvaluator,
           split_leg: SplitLeg, may_split: Callable[[], bool], depth: int = 1) -> SplitCandidate | None:
    """``candidate`` (a split of u -> v in ``graph``, started from ``start``) with its failing legs split once
    more, first to last; None when no leg could be repaired. ``may_split()``: whether the budget allows a split.
    ``depth`` > 1: a leg's split that has a dead leg of its own is repaired in turn, to that many levels
    (method ``ours-corrector``; ``ours-repair`` repairs one level)."""
    waypoints, results = list(candidate.waypoints), list(candidate.results)
    repaired, i = 0, _first_failing(results, 0)
    while i is not None and may_split():
        chain_graph = graph.copy()
        chain = [u, *chain_graph.split_edge(u, v, waypoints), v]
        leg_start = start_of(results[i - 1]) if i else start
        outcome = split_leg(chain_graph, chain[i], chain[i + 1], results[i], leg_start)
        fix = outcome.best
        if fix is not None and fix.p <= 0.0 and depth > 1 and outcome.candidates:
            fix = repair(cheapest(outcome.candidates, evaluator.n), chain_graph, chain[i], chain[i + 1],
                         start=leg_start, evaluator=evaluator, split_leg=split_leg, may_split=may_split,
                         depth=depth - 1)
        if fix is None or fix.p <= 0.0:
            break
        waypoints[i:i] = fix.waypoints
        rest = split_legs(waypoints, graph.region(v), graph.avoid(u, v), graph.goal_point(v))[i + len(fix.results):]
        results = results[:i] + fix.results + estimate_legs(evaluator, start_of(fix.results[-1]), rest).results
        repaired += 1
        i = _first_failing(results, i + len(fix.results))
    if not repaired:
        return None
    return SplitCandidate(waypoints, results, candidate.round, candidate.tuned, repaired=repaired)


def _first_failing(results: list, begin: int) -> int | None:
    return next((j for j in range(begin, len(results)) if results[j].successes == 0), None)

