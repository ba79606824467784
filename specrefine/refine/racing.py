"""Adaptive evaluation: rollouts in stages, and a candidate that cannot change the decision is stopped early.

The paper evaluates every subtask on a fixed number of rollouts (32).  Inside the chain vertex
refinement most of those evaluations cannot change what is chosen: the dynamic programme keeps,
for each option of a layer, the best p(prefix) * p(step) over the previous layer's options.
``Racing`` spends rollouts only where they can still change that maximum:

1. Branch and bound over the previous layer in order of decreasing p(prefix): since p(step) <= 1,
   a prefix no more likely than the best value found for a target cannot beat it and is never
   extended to that target (exact; on the point mass most extensions succeed in every rollout,
   and then the first prefix settles the target).
2. Stages: an extension is first run on ``stages[0]`` rollouts; if even the upper end of the 95 %
   Wilson interval of its success rate, times p(prefix), stays at or below the value it has to beat
   (the best so far, or the unrefined chain's probability), it is dropped; the rest get the
   following stages, merged into one estimate of ``sum(stages)`` rollouts (the full budget: the
   paper's 32 by default), from which the choice is made as before.

What is chosen is always estimated on the full budget; what is dropped is never used.  The
stages draw their own seeds (``stage_seed``), so a staged estimate is a different (equally
valid) sample than the fixed protocol's; ``SearchConfig(racing=None)`` is that protocol.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..results import merge_edge_results, wilson_ci
from .common import evaluate_all

STAGE_SEED_OFFSET = 3_000_017  # not the search's seed, the measurement's or the calibration's


@dataclass(frozen=True)
class Racing:
    stages: tuple[int, ...] = (8, 24)  # rollouts per stage; their sum is the full budget of a kept candidate

    def __post_init__(self):
        if not self.stages or any(int(s) < 1 for s in self.stages):
            raise ValueError(f"racing stages must be positive rollout counts, got {self.stages!r}")

    @property
    def budget(self) -> int:
        return int(sum(self.stages))

    @classmethod
    def for_budget(cls, n: int) -> Racing:
        """A first stage of a quarter of ``n`` (at least 4), the rest in a second stage; one stage if n is small."""
        first = max(4, n // 4)
        return cls((first, n - first)) if n - first >= 1 else cls((n,))

    def evaluate(self, evaluator, subtasks: list[tuple], floors: list[float], scale: list[float]) -> list:
        """Staged estimates of ``subtasks``; None for one dropped because ``scale * upper bound <= floor``.

        ``scale[i]`` multiplies subtask i's success rate into the quantity compared with ``floors[i]``
        (p(prefix) in the chain DP).
        """
        if not hasattr(evaluator, "evaluate_many"):  # a stand-in without staged calls: one full estimate each
            return evaluate_all(evaluator, subtasks)
        seed = evaluator.seed
        done: list = [None] * len(subtasks)
        live = list(range(len(subtasks)))
        for j, n in enumerate(self.stages):
            if not live:
                break
            results = evaluator.evaluate_many([subtasks[i] for i in live], seed=stage_seed(seed, j), n=n)
            for i, res in zip(live, results, strict=True):
                done[i] = res if done[i] is None else merge_edge_results(done[i], res)
            if j + 1 < len(self.stages):
                live = [i for i in live if not self._hopeless(done[i], floors[i], scale[i])]
                for i in set(range(len(subtasks))) - set(live):
                    if done[i] is not None and done[i].n < self.budget:
                        done[i] = None  # dropped: a partial estimate is never used
        return done

    @staticmethod
    def _hopeless(result, floor: float, scale: float) -> bool:
        return scale * wilson_ci(result.successes, result.n)[1] <= floor


def stage_seed(seed: int, stage: int) -> int:
    return int(seed) + STAGE_SEED_OFFSET * (stage + 1)

