"""The paper's settings, written once. A run's defaults (``runs.config.RunConfig``) and the algorithms called directly
both read them here; this module imports nothing, so every layer may."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class PaperSettings:
    w: int = 3  # candidate edge splits per proposer query (Algorithm 1)
    d: int = 2  # proposer rounds per edge split (Algorithm 1)
    k: int = 5  # subsets sampled per vertex refinement (Algorithm 2)
    rollouts: int = 32  # rollouts per subtask evaluation
    episodes: int = 200  # fresh end-to-end episodes of the final measurement
    goal_points: str = "sampled"  # a leg aims at a point drawn in its goal vertex's set, a new one per rollout
    evaluation: str = "fixed"  # every subtask estimate on `rollouts` rollouts (no adaptive racing)
    split_pick: str = "estimate"  # Algorithm 1 takes the candidate with the best estimate, from whatever round
    method: str = "ours"  # the search of Algorithms 1-3, as the paper states it


PAPER = PaperSettings()
