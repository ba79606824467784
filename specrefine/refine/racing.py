"""Adaptive evaluation: rollouts in stages, and a candidate that cannot change the decision is stopped early.

The paper evaluates every subtask on a fixed number of rollouts (32).  Inside the chain vertex
refinement most of those evaluations cannot change what is chosen: the dynamic programme keeps,
for each option of a layer, the best p(prefix) * p(step) over the previous layer's options.
``Racing`` spends rollouts only where they can still change that maximum:

1. Branch and bound over the previous layer, one prefix at a time in order of decreasing p(prefix):
   since p(step) <= 1, a prefix cannot lift a target above p(prefix); it is extended to a target only
   if p(prefix) beats the best value found for that target (or the unrefined chain's probability),
   by more than ``indifference`` if one is set (relative; default 0).  A margin of one rollout
   (1/32) saved only 4 % more steps on the point mass's 5-room U-chain (seed 0) and lets the loss
   compound over a long chain (0.930 measured vs 0.965 without it, one run each): off by default.
2. Stages: an extension is first run on ``stages[0]`` rollouts; if even the upper end of the 95 %
   Wilson interval of its success rate, times p(prefix), cannot beat that value (by the same margin),
   it is dropped; the rest get the following stages, merged into one estimate of ``sum(stages)``
   rollouts (the full budget: the paper's 32 by default), from which the choice is made as before.

What is chosen is always estimated on the full budget; what is dropped is never used.  With
exact estimates the chosen chain is the fixed protocol's optimum (within a factor
(1 - indifference) per layer with a margin).  The stages draw their own seeds
(``stage_seed``), so a staged estimate is a different (equally valid) sample than the fixed
protocol's; ``SearchConfig(evaluation="fixed")`` is that protocol.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.results import merge_edge_results, wilson_ci
from .common import evaluate_all

STAGE_SEED_OFFSET = 3_000_017  # not the search's seed, the measurement's or the calibration's


@dataclass(frozen=True)
class Racing:
    stages: tuple[int, ...] = (8, 24)  # rollouts per stage; their sum is the full budget of a kept candidate
    indifference: float = 0.0  # relative margin a candidate must be able to win by (0: any improvement counts)

    def __post_init__(self):
        if not self.stages or any(int(s) < 1 for s in self.stages):
            raise ValueError(f"racing stages must be positive rollout counts, got {self.stages!r}")
        if not 0.0 <= self.indifference < 1.0:
            raise ValueError(f"indifference must lie in [0, 1), got {self.indifference!r}")

    def may_beat(self, best_possible: float, floor: float) -> bool:
        """Whether a candidate that can reach ``best_possible`` may beat ``floor`` by more than the margin."""
        return best_possible * (1.0 - self.indifference) > floor

    @property
    def budget(self) -> int:
        return int(sum(self.stages))

    @classmethod
    def for_budget(cls, n: int) -> Racing:
        """A first stage of a quarter of ``n`` (at least 4), the rest in a second stage; one stage if n is small."""
        first = max(4, n // 4)
        return cls((first, n - first)) if n - first >= 1 else cls((n,))

    def evaluate(self, evaluator, subtasks: list[tuple], floors: list[float], scale: list[float]) -> list:
        """Staged estimates of ``subtasks``; None for one dropped because ``scale * upper bound`` cannot beat ``floor``.

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
                live = [i for i in live if self.may_beat(scale[i] * wilson_ci(done[i].successes, done[i].n)[1],
                                                         floors[i])]
                for i in set(range(len(subtasks))) - set(live):
                    if done[i] is not None and done[i].n < self.budget:
                        done[i] = None  # dropped: a partial estimate is never used
        return done


def stage_seed(seed: int, stage: int) -> int:
    return int(seed) + STAGE_SEED_OFFSET * (stage + 1)

