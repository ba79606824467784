"""Polishing the found path (beyond the paper: method ``ours-polish``).

The search estimates every leg on the evaluator's n rollouts (32), so a leg that loses 2-4 % of its episodes
reaches the path on 32 of 32 about a third to a half of the time; on the Ant the worst fifth of a path's legs carries
about half of its loss (docs/ant_experiments.md section 5). Polishing looks at the found path again: walking it from
the start, each leg is estimated on ``rollouts`` rollouts (a seed of its own), and where a leg into an inner waypoint
fails at least ``min_failures`` times, that waypoint is tuned by Algorithm 2 (k subsets of its region, chosen on the
same larger estimates of its two legs). A subset replaces the waypoint only when it raises the two legs' product.
Every change narrows a vertex, so it is a refinement (Theorem 4.1 holds; ``check_refines`` checks it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.graph import TaskGraph
from .common import Leg, SubtaskEvaluator, estimate_legs, start_of
from .vertex import refine_chain


class Rollouts:
    """``evaluator`` asked on another number of rollouts and seed (a SubtaskEvaluator in its own right)."""

    def __init__(self, evaluator, n: int, seed: int):
        self.evaluator, self.n, self.seed = evaluator, int(n), seed

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None):
        return self.evaluator.evaluate(start, goal, avoid, goal_point=goal_point, seed=self.seed, n=self.n)

    def evaluate_many(self, subtasks):
        return self.evaluator.evaluate_many(subtasks, seed=self.seed, n=self.n)


@dataclass
class Polished:
    vertex: str
    p_before: float  # the product of the waypoint's two legs on the larger estimates
    p_after: float
    changed: bool


def polish(graph: TaskGraph, path: list[str], evaluator: SubtaskEvaluator, *, rollouts: int, k: int,
           rng: np.random.Generator, seed: int, min_failures: int = 2) -> list[Polished]:
    """Tune the weak inner waypoints of ``path`` in ``graph`` (narrowed in place), first to last."""
    ev = Rollouts(evaluator, rollouts, seed)
    done, arrival = [], graph.region(path[0])
    for u, v, w in zip(path, path[1:], path[2:]):
        if arrival is None:
            break
        legs = [Leg(graph.region(v), graph.avoid(u, v), graph.goal_point(v)),
                Leg(graph.region(w), graph.avoid(v, w), graph.goal_point(w))]
        current = estimate_legs(ev, arrival, legs)
        into = current.results[0]
        if into.n - into.successes < min_failures or not graph.is_chain_vertex(v):
            arrival = start_of(into)
            continue
        choice = refine_chain(ev, arrival, [graph.region(v)], graph.region(w), [legs[0].avoid, legs[1].avoid], k, rng,
                              graph.goal_point(w))
        changed = choice.p > current.p and choice.regions[0] != graph.region(v)
        if changed:
            graph.narrow_vertex(v, choice.regions[0])
        done.append(Polished(v, current.p, choice.p if changed else current.p, changed))
        arrival = start_of(choice.results[0] if changed else into)
    return done
