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

import numpy as np

from ..regions import Box, Disc, Region
from .common import UNREACHED, Leg, SubtaskEvaluator, evaluate_path, start_of


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
                 k: int, rng: np.random.Generator, goal_point=None) -> ChainChoice:
    """Best subsets for the inner vertices of u -> x_1 .. x_t -> v (Algorithm 2, chain DP).

    ``avoids`` has one avoid set per subtask (t + 1 of them); option 0 of each layer is I(x_j) itself.
    """
    if len(avoids) != len(inner) + 1:
        raise ValueError("refine_chain needs one avoid set per subtask")
    options = [[region] + sample_subsets(region, k, rng) for region in inner]
    calls = 0

    def run(start_, goal_, avoid_, point=None):
        nonlocal calls
        calls += 1
        return evaluator.evaluate(start_, goal_, avoid_, goal_point=point)

    unrefined = evaluate_path(evaluator, start, [Leg(x, a) for x, a in zip(inner, avoids)] + [Leg(goal, avoids[-1],
                                                                                                 goal_point)])
    calls += len(avoids)
    if unrefined.p >= 1.0:  # the DP cannot beat a chain that never failed
        return ChainChoice(regions=list(inner), results=unrefined.results, p=1.0, evaluations=calls)

    # one Path per option of the current layer: the best way found to reach it
    bound = unrefined.p
    layer = [_Path(r.p, [r], [i]) for i, r in enumerate(run(start, opt, avoids[0]) for opt in options[0])]
    for j in range(1, len(inner)):
        layer = [_best_extension(layer, i, lambda last, o=opt, a=avoids[j]: run(start_of(last), o, a), bound)
                 for i, opt in enumerate(options[j])]
    best = _best_extension(layer, None, lambda last: run(start_of(last), goal, avoids[-1], goal_point), bound)
    if best.p <= bound:  # nothing beat the chain as proposed
        return ChainChoice(regions=list(inner), results=unrefined.results, p=unrefined.p, evaluations=calls)
    chosen = [options[j][i] for j, i in enumerate(best.choices)]
    return ChainChoice(regions=chosen, results=best.results, p=best.p, evaluations=calls)


@dataclass
class _Path:
    p: float
    results: list
    choices: list[int]


def _best_extension(layer: list[_Path], option: int | None, extend, bound: float = 0.0) -> _Path:
    """max over previous options l of p_l * p(l -> option); options nobody reached keep p = 0.

    A partial path no more likely than ``bound`` is not extended: probabilities only shrink along a
    path, so it cannot end above the bound (branch and bound; the result is unchanged).
    """
    best = None
    for prev in layer:
        if prev.p <= bound or start_of(prev.results[-1]) is None:
            continue
        step = extend(prev.results[-1])
        if best is None or prev.p * step.p > best.p:
            tail = [option] if option is not None else []
            best = _Path(prev.p * step.p, prev.results + [step], prev.choices + tail)
    if best is None:
        base = layer[0]
        best = _Path(0.0, base.results + [UNREACHED], base.choices + ([option] if option is not None else []))
    return best
