"""Correcting the found path (beyond the paper: method ``ours-corrector``, docs/corrector.md).

Algorithm 3 judges each refinement once, on the search's own estimates, against a threshold tau: a leg estimated
at 32 of 32 on a lucky draw is trusted, and a leg at 31 of 32 costs less than tau, so no refinement of it can ever
be accepted although eight such legs lose a fifth of the episodes together. The correction looks at the path the
search found as a whole, on rollouts the search never saw:

1. every leg of the path is estimated again on ``rollouts`` fresh rollouts (a seed apart from the search's and the
   measurement's), each leg started from the end states of the previous leg's successes, as the search does;
2. the weakest leg not tried yet (the lowest fresh estimate below 1) is corrected: its proposer split (Algorithm 1
   on that leg, asked with the picture of its fresh failures; a split with a dead leg is repaired recursively),
   and, where the leg starts or ends at a waypoint of a split, the path without that waypoint (one leg instead of
   two: a shortcut edge of the same split);
3. each alternative path is estimated on the same fresh rollouts (the legs before the change are the same
   estimates), and the best replaces the path when its product of leg estimates is higher;
4. until no leg below 1 is left untried or the correction's budget of proposer splits is spent.

``min_failures`` > 1 (method ``ours-corrector-gated``) asks the proposer about a leg only when at least that many of
its fresh rollouts failed: a leg losing a fraction of a per cent shows one failure in 128 about as often as a sound
one, and splitting it spends proposer calls on noise (docs/corrector.md, 'Where the corrector still loses'). Such a
leg is still offered the bypass, which asks nothing.

Every alternative is a refinement of the same input edge (a longer or shorter chain of waypoints), so the refined
graph still implies the input graph (Theorem 4.1, checked like every refinement). What the correction sees is what
a real proposer's reply gives: waypoints, pictures and rollouts.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from ..core.graph import TaskGraph
from .common import Leg, LegEstimates, SubtaskEvaluator, estimate_legs, start_of
from .shortcut import Shortcut, add_shortcuts, shortcuts

CHECK_SEED_OFFSET = 104_729  # the correction's fresh rollouts: apart from the search's, polish's and the measurement's


@dataclass
class Check(LegEstimates):
    """Fresh estimates of a path's legs: one EdgeResult per leg, each leg started from the previous one's successes."""

    path: list[str] = field(default_factory=list)


def path_legs(graph: TaskGraph, path: list[str]) -> list[Leg]:
    return [Leg(graph.region(b), graph.avoid(a, b), graph.goal_point(b)) for a, b in zip(path, path[1:])]


def check_path(graph: TaskGraph, path: list[str], evaluator: SubtaskEvaluator, *, rollouts: int, seed: int,
               start) -> Check:
    """The legs of ``path`` estimated on ``rollouts`` fresh rollouts each (seed ``seed``), from ``start`` (None:
    nothing reached path[0], every leg unreached)."""
    estimates = estimate_legs(evaluator, start, path_legs(graph, path), seed=seed, n=rollouts)
    return Check(results=estimates.results, path=list(path))


def weakest_untried(check: Check, tried: set) -> int | None:
    """The leg with the lowest fresh estimate below 1 that has not been tried (the first of ties)."""
    legs = [i for i, p in enumerate(check.probabilities) if p < 1.0 and _leg_key(check, i) not in tried]
    return min(legs, key=lambda i: (check.probabilities[i], i)) if legs else None


def failures(result) -> int:
    """How many of a leg's rollouts failed."""
    return result.n - result.successes


def _leg_key(check: Check, i: int) -> tuple:
    return tuple(check.path[i:i + 2])


def bypasses(graph: TaskGraph, path: list[str], leg: int, reach: float, clearance: float) -> list[tuple[int, int]]:
    """(i, j) shortcuts over one waypoint at either end of ``leg`` (j = i + 2) that the shortcut rule allows."""
    allowed = {(s.i, s.j) for s in shortcuts(graph, path, reach, clearance) if s.j == s.i + 2}
    return [(i, i + 2) for i in (leg - 1, leg) if (i, i + 2) in allowed]


def one_split(graph: TaskGraph, path: list[str], i: int) -> bool:
    """Whether path[i] -> path[i+1] -> path[i+2] are legs of one split (path[i+1] a waypoint between them)."""
    a, b, c = path[i:i + 3]
    return (graph.refines(b) is None and graph.parent(a, b) == graph.parent(b, c)
            and graph.avoid(a, b) == graph.avoid(b, c))


def bypassed(graph: TaskGraph, path: list[str], i: int, j: int) -> tuple[TaskGraph, list[str]]:
    """A copy of ``graph`` with the shortcut path[i] -> path[j], and the path through it."""
    alt = graph.copy()
    add_shortcuts(alt, path, [Shortcut(i, j)])
    return alt, path[:i + 1] + path[j:]


def spliced(graph: TaskGraph, path: list[str], i: int, j: int, waypoints) -> tuple[TaskGraph, list[str]]:
    """A copy of ``graph`` with path[i] -> path[j] split through ``waypoints`` (j = i + 2: over the waypoint
    path[i+1], through a shortcut edge of its split), and the path through them."""
    alt = graph.copy()
    if j > i + 1:
        add_shortcuts(alt, path, [Shortcut(i, j)])
    names = alt.split_edge(path[i], path[j], waypoints)
    return alt, path[:i + 1] + names + path[j:]


def correct(graph: TaskGraph, path: list[str], evaluator: SubtaskEvaluator, *, rollouts: int, seed: int,
            split_leg: Callable, may_split: Callable[[], bool], reach: float, clearance: float,
            log: Callable[..., None], min_failures: int = 1) -> tuple[TaskGraph, list[str], Check]:
    """The corrected (graph, path) and its fresh check. ``split_leg(graph, a, b, result, start)`` -> the best
    split candidate of a -> b (repaired if it has a dead leg) or None; ``may_split()``: the budget allows one.

    An alternative is judged on the legs it changes and the leg after them (the window), from the same fresh start
    states as the current path's legs there; it replaces the path when it gains at least one rollout's worth
    (1 / rollouts) over the window, and the path's legs from the window on are then checked again."""
    check = check_path(graph, path, evaluator, rollouts=rollouts, seed=seed, start=graph.region(path[0]))
    log("correct-check", path=path, p=check.p, probabilities=check.probabilities)
    tried: set = set()
    while (leg := weakest_untried(check, tried)) is not None:
        tried.add(_leg_key(check, leg))
        s, e = max(leg - 1, 0), min(leg + 3, len(path) - 1)  # the window: legs s .. e-1, path[s] to path[e]
        start = graph.region(path[0]) if s == 0 else start_of(check.results[s - 1])
        options = [("bypass", *bypassed(graph, path, i, j)) for i, j in bypasses(graph, path, leg, reach, clearance)]
        spans = [(leg, leg + 1)] + ([(leg, leg + 2)] if leg + 2 < len(path) and one_split(graph, path, leg) else [])
        if failures(check.results[leg]) < min_failures:
            spans = []
        for i, j in spans:
            if not may_split():
                break
            leg_start = graph.region(path[0]) if i == 0 else start_of(check.results[i - 1])
            if leg_start is None:  # no fresh rollout reaches the leg: nothing to start its split from
                break
            if j == i + 1:
                result = check.results[i]
            else:  # the span over a waypoint: how its straight edge does, for the proposer's picture
                goal = path_legs(graph, path[j - 1:j + 1])[0]
                result = evaluator.evaluate(leg_start, goal.goal, goal.avoid, goal_point=goal.goal_point, seed=seed,
                                            n=rollouts)
            fix = split_leg(*_with_edge(graph, path, i, j), path[i], path[j], result, leg_start)
            if fix is not None and fix.waypoints:
                options.append(("split" if j == i + 1 else "resplit", *spliced(graph, path, i, j, fix.waypoints)))
        current = math.prod(check.probabilities[s:e])
        judged = [(kind, g, p, check_path(g, p[s:p.index(path[e]) + 1], evaluator, rollouts=rollouts, seed=seed,
                                          start=start)) for kind, g, p in options]
        best = max(judged, key=lambda o: o[3].p, default=None)
        accepted = best is not None and best[3].p >= current + 1.0 / rollouts
        log("correct-leg", leg=leg, edge=path[leg:leg + 2], p_leg=check.probabilities[leg], p_window=current,
            tried=[{"kind": kind, "p_window": c.p, "legs": len(p) - 1} for kind, _, p, c in judged],
            accepted=best[0] if accepted else None)
        if accepted:
            graph, path = best[1], best[2]
            rest = check_path(graph, path[s:], evaluator, rollouts=rollouts, seed=seed, start=start)
            check = Check(results=check.results[:s] + rest.results, path=list(path))
    log("correct-done", path=path, p=check.p, probabilities=check.probabilities)
    return graph, path, check


def _with_edge(graph: TaskGraph, path: list[str], i: int, j: int) -> tuple[TaskGraph]:
    """The graph the proposer is asked about: with the span's shortcut edge path[i] -> path[j] where j > i + 1."""
    if j == i + 1:
        return (graph,)
    alt = graph.copy()
    add_shortcuts(alt, path, [Shortcut(i, j)])
    return (alt,)
