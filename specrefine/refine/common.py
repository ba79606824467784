"""Shared pieces of the refinement algorithms: edge weights and leg-by-leg estimates with start propagation."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

from ..core.regions import Region
from ..core.results import unreached


class SubtaskEvaluator(Protocol):
    """What the refinement algorithms need from `specrefine.evaluation.evaluator.Evaluator` (tests may stub it)."""

    n: int

    def evaluate(self, start, goal: Region, avoid: Region, goal_point=None, seed=None): ...


def evaluate_all(evaluator: SubtaskEvaluator, subtasks: list[tuple]) -> list:
    """``evaluate`` each ``(start, goal, avoid, goal_point)``, simulated side by side where the evaluator can."""
    if hasattr(evaluator, "evaluate_many"):
        return evaluator.evaluate_many(subtasks)
    return [evaluator.evaluate(start, goal, avoid, goal_point=point) for start, goal, avoid, point in subtasks]


def weight(p: float, n: int) -> float:
    """Edge weight -log p, with p = 0 guarded by half a success in n rollouts."""
    return -math.log(max(p, 0.5 / max(n, 1)))


def live_start(probabilities) -> int:
    """How many legs succeed at all before the first that never does."""
    return next((i for i, p in enumerate(probabilities) if p <= 0.0), len(probabilities))


def start_of(result):
    """Start distribution for the next subtask: the end states of this one's successful rollouts."""
    return result.end_states if result is not None and result.successes > 0 else None


UNREACHED = unreached()  # a subtask whose start nothing reached: p = 0, nothing simulated


@dataclass
class Leg:
    goal: Region
    avoid: Region
    goal_point: object = None


@dataclass
class LegEstimates:
    """Success estimates of a sequence of subtasks, evaluated one after another (DiRL-style start propagation).

    Not a run of the compositional policy (that is ``Evaluator.run_compositional``): each leg is
    estimated on its own ``n`` rollouts, started from the previous leg's successful end states.
    """

    results: list = field(default_factory=list)

    @property
    def probabilities(self) -> list[float]:
        return [r.p for r in self.results]

    @property
    def p(self) -> float:
        return math.prod(self.probabilities) if self.results else 0.0

    def cost(self, n: int) -> float:
        return sum(weight(r.p, n) for r in self.results)


def estimate_legs(evaluator: SubtaskEvaluator, start, legs: list[Leg], *, seed=None, n=None) -> LegEstimates:
    """Estimate legs in order; a leg with no successes ends the estimation (the rest has p = 0). ``seed``, ``n``:
    the rollouts' seed and number instead of the evaluator's own (passed on only when given)."""
    own = {name: value for name, value in (("seed", seed), ("n", n)) if value is not None}
    out = LegEstimates()
    for leg in legs:
        if start is None:
            result = UNREACHED
        else:
            result = evaluator.evaluate(start, leg.goal, leg.avoid, goal_point=leg.goal_point, **own)
        out.results.append(result)
        start = start_of(result)
    return out


evaluate_path, PathEvaluation = estimate_legs, LegEstimates  # the former names (notebooks written against them)
