"""Vertex subset refinement (Algorithm 2) and its chain version with dynamic programming.

For a chain u -> x_1 -> ... -> x_t -> v whose inner vertices have in/out degree 1, each
I(x_j) may be replaced by one of k sampled subsets (or kept).  Layer by layer, the best
path probability to every option is kept together with the end states of its successful
rollouts, which start the next layer (DiRL's propagation).  That evaluates
(k+1) + (k+1)^2 (t-1) + (k+1) subtasks instead of (k+1)^t whole paths.  The unrefined
chain is evaluated first: if it never failed the DP is skipped, and otherwise its
probability bounds the DP (a partial path that is already less likely is not extended).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np

from ..core.regions import Box, Disc, Region
from .common import UNREACHED, Leg, SubtaskEvaluator, estimate_legs, evaluate_all, start_of
from .racing import Racing


def sample_subsets(region: Region, k: int, rng: np.random.Generator, shrink=(0.3, 0.7)) -> list[Region]:
    """k random strict subsets of ``region`` (boxes inside boxes, discs inside discs)."""
    parts = region.parts()
    areas = np.array([p.area for p in parts])
    picks = rng.choice(len(parts), size=k, p=areas / areas.sum())
    return [_subset_of(parts[i], rng, shrink) for i in picks]


def _subset_of(part: Region, rng: np.random.Generator, shrink) -> Region:
    if isinstance(part, Disc):
        rho = part.r * rng.uniform(*shrink)
        angle, dist = rng.uniform(0, 2 * np.pi), (part.r - rho) * np.sqrt(rng.random())
        return Disc(part.cx + dist * np.cos(angle), part.cy + dist * np.sin(angle), rho)
    if isinstance(part, Box):
        w, h = part.xmax - part.xmin, part.ymax - part.ymin
        sw, sh = w * rng.uniform(*shrink), h * rng.uniform(*shrink)
        x0, y0 = part.xmin + rng.random() * (w - sw), part.ymin + rng.random() * (h - sh)
        return Box(x0, y0, x0 + sw, y0 + sh)
    raise TypeError(f"cannot sample subsets of {type(part).__name__}")


@dataclass
class ChainChoice:
    regions: list[Region]  # chosen I'(x_1..x_t)
    results: list  # EdgeResults of the t+1 subtasks along the chosen chain
    p: float
    evaluations: int  # subtask evaluations requested (cache hits included)

    @property
    def probabilities(self) -> list[float]:
        return [r.p for r in self.results]


def refine_chain(evaluator: SubtaskEvaluator, start, inner: list[Region], goal: Region, avoids: list[Region],
                 k: int, rng: np.random.Generator, goal_point=None, racing: Racing | None = None,
                 floor: float = 0.0) -> ChainChoice:
    """Best subsets for the inner vertices of u -> x_1 .. x_t -> v (Algorithm 2, chain DP).

    ``avoids`` has one avoid set per subtask (t + 1 of them); option 0 of each layer is I(x_j) itself.
    ``racing``: evaluate the DP adaptively (:mod:`specrefine.refine.racing`); None = every extension on
    the evaluator's full n rollouts, as in the paper.  ``floor``: a value the chain must beat to matter
    (another candidate's, in an edge split); what cannot beat it is not explored (the unrefined chain
    is returned then, as when nothing beats it).
    """
    if len(avoids) != len(inner) + 1:
        raise ValueError("refine_chain needs one avoid set per subtask")
    options = [[region] + sample_subsets(region, k, rng) for region in inner]
    unrefined = estimate_legs(evaluator, start, [Leg(x, a) for x, a in zip(inner, avoids)] + [Leg(goal, avoids[-1],
                                                                                                 goal_point)])
    calls = len(avoids)
    if unrefined.p >= 1.0:  # the DP cannot beat a chain that never failed
        return ChainChoice(regions=list(inner), results=unrefined.results, p=1.0, evaluations=calls)

    # one Path per option of the current layer: the best way found to reach it
    bound = max(unrefined.p, floor)
    extend = _next_layer if racing is None else partial(_next_layer_racing, racing=racing)
    first_tasks = [(start, opt, avoids[0], None) for opt in options[0]]
    if racing is None:
        first = evaluate_all(evaluator, first_tasks)
    else:
        ones = [1.0] * len(first_tasks)
        first = racing.evaluate(evaluator, first_tasks, floors=[bound] * len(first_tasks), scale=ones)
    calls += len(first)
    layer = [_Path(r.p, [r], [i]) if r is not None else _Path(0.0, [UNREACHED], [i]) for i, r in enumerate(first)]
    for j in range(1, len(inner)):
        layer, asked = extend(evaluator, layer, [(opt, avoids[j], None) for opt in options[j]], bound)
        calls += asked
    (best,), asked = extend(evaluator, layer, [(goal, avoids[-1], goal_point)], bound, last=True)
    calls += asked
    if best.p <= bound:  # nothing beat the chain as proposed
        return ChainChoice(regions=list(inner), results=unrefined.results, p=unrefined.p, evaluations=calls)
    chosen = [options[j][i] for j, i in enumerate(best.choices)]
    return ChainChoice(regions=chosen, results=best.results, p=best.p, evaluations=calls)


@dataclass
class _Path:
    p: float
    results: list
    choices: list[int]


def _next_layer(evaluator, layer: list[_Path], targets: list[tuple], bound: float, last: bool = False
                ) -> tuple[list[_Path], int]:
    """For every target (goal, avoid, point): max over previous options l of p_l * p(l -> target).

    All extensions of a layer are evaluated in one batch.  A partial path no more likely than
    ``bound`` is not extended: probabilities only shrink along a path, so it cannot end above the
    bound (branch and bound; the result is unchanged).  Targets nobody reached keep p = 0.
    """
    alive = [prev for prev in layer if prev.p > bound and start_of(prev.results[-1]) is not None]
    asked = [(prev, i, (start_of(prev.results[-1]), *target)) for i, target in enumerate(targets) for prev in alive]
    results = evaluate_all(evaluator, [subtask for _, _, subtask in asked])
    best: list[_Path | None] = [None] * len(targets)
    for (prev, i, _), step in zip(asked, results, strict=True):
        if best[i] is None or prev.p * step.p > best[i].p:
            best[i] = _Path(prev.p * step.p, prev.results + [step], prev.choices + ([] if last else [i]))
    return _fill(layer, best, last), len(asked)


def _fill(layer: list[_Path], best: list[_Path | None], last: bool) -> list[_Path]:
    """Targets nobody reached keep p = 0."""
    base = layer[0]
    return [b if b is not None else _Path(0.0, base.results + [UNREACHED], base.choices + ([] if last else [i]))
            for i, b in enumerate(best)]


def _next_layer_racing(evaluator, layer: list[_Path], targets: list[tuple], bound: float, last: bool = False, *,
                       racing: Racing) -> tuple[list[_Path], int]:
    """``_next_layer`` by branch and bound over the prefixes, most likely first, with staged estimates.

    A prefix is extended to a target only while it could beat the best value found for that target
    (and ``bound``) by more than ``racing.indifference`` (p(step) <= 1 bounds what it can reach); an
    extension whose first stage shows it cannot is dropped.
    """
    alive = sorted((prev for prev in layer if prev.p > bound and start_of(prev.results[-1]) is not None),
                   key=lambda prev: -prev.p)
    best: list[_Path | None] = [None] * len(targets)
    asked = 0
    for prev in alive:
        floor = [max(bound, b.p if b is not None else 0.0) for b in best]
        open_targets = [i for i in range(len(targets)) if racing.may_beat(prev.p, floor[i])]
        steps = racing.evaluate(evaluator, [(start_of(prev.results[-1]), *targets[i]) for i in open_targets],
                                floors=[floor[i] for i in open_targets], scale=[prev.p] * len(open_targets))
        asked += len(open_targets)
        for i, step in zip(open_targets, steps, strict=True):
            if step is not None and prev.p * step.p > floor[i]:
                best[i] = _Path(prev.p * step.p, prev.results + [step], prev.choices + ([] if last else [i]))
    return _fill(layer, best, last), asked
