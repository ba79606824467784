"""What an evaluation returns: start distributions, per-subtask and end-to-end results, their intervals.

Shared by the evaluator (which fills them) and the refinement algorithms (which read ``p``,
``successes`` and ``end_states``); :func:`unreached` is the one result of a subtask that nothing
reached (p = 0, nothing simulated).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field

import numpy as np

SUCCESS, AVOID, FLIPPED, TIMEOUT, UNFINISHED = 0, 1, 2, 3, 4
OUTCOMES = ("success", "avoid", "flipped", "timeout", "unfinished")


@dataclass
class StartStates:
    """A start distribution given by full physics states (drawn by ``evaluation.evaluator.spread_draw``)."""

    states: np.ndarray  # (m, state_dim)
    xy: np.ndarray  # (m, 2)

    def __len__(self) -> int:
        return len(self.states)

    def digest(self) -> str:
        h = hashlib.sha256(np.ascontiguousarray(self.states, dtype=np.float64).tobytes())
        h.update(str(self.states.shape).encode())
        return h.hexdigest()[:32]


@dataclass
class EdgeResult:
    """``n`` rollouts of the goal policy on one subtask (``Evaluator.evaluate``)."""

    p: float
    ci: tuple[float, float]
    n: int
    successes: int
    success: np.ndarray  # (n,) bool
    trajectories: np.ndarray  # (n, T, 2) float32; row i is valid up to lengths[i], then padded with its last point
    lengths: np.ndarray  # (n,) int: number of valid points (1 + control steps taken)
    end_states: StartStates | None  # states of the successful rollouts at the moment they reached the goal
    steps: int  # environment steps simulated (the batch is stepped together: n x loop iterations)
    cached: bool = False
    outcome: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int8))  # per rollout, see OUTCOMES

    @property
    def weight(self) -> float:
        """-log p (inf for p = 0)."""
        return -math.log(self.p) if self.p > 0 else math.inf

    def counts(self) -> dict[str, int]:
        return {name: int(np.sum(self.outcome == i)) for i, name in enumerate(OUTCOMES) if np.any(self.outcome == i)}


@dataclass
class CompositionalResult:
    """Episodes of the compositional policy run end to end (``Evaluator.run_compositional``)."""

    p: float
    ci: tuple[float, float]
    n: int
    successes: int
    success: np.ndarray  # (n,) bool: every leg completed
    legs_done: np.ndarray  # (n,) int: legs completed by each episode
    trajectories: np.ndarray  # (n, T, 2) float32, padded like EdgeResult's
    lengths: np.ndarray  # (n,)
    steps: int
    outcome: np.ndarray  # (n,) int8, see OUTCOMES

    n_legs: int = 1

    def counts(self) -> dict[str, int]:
        return {name: int(np.sum(self.outcome == i)) for i, name in enumerate(OUTCOMES) if np.any(self.outcome == i)}

    @property
    def leg_success(self) -> list[float | None]:
        """Empirical success probability of each leg among the episodes that started it (None: none did)."""
        out = []
        for k in range(self.n_legs):
            started = self.legs_done >= k
            out.append(float(np.mean(self.legs_done[started] > k)) if started.any() else None)
        return out


def wilson_ci(successes, n, z: float = 1.96) -> tuple[float, float]:
    """Wilson score interval for a binomial proportion (95 % by default); (0, 1) when n = 0."""
    n = int(n)
    if n <= 0:
        return (0.0, 1.0)
    p = successes / n
    z2 = z * z
    denom = 1 + z2 / n
    centre = (p + z2 / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / denom
    return (max(0.0, centre - half), min(1.0, centre + half))


def rate_text(k: int, n: int) -> str:
    """'k/n [Wilson 95 % interval] (n)' as the result tables write a pooled rate; '—' without episodes."""
    if not n:
        return "—"
    lo, hi = wilson_ci(k, n)
    return f"{k / n:.3f} [{lo:.3f}, {hi:.3f}] ({n})"


def difference_text(k1: int, n1: int, k2: int, n2: int) -> str:
    """'k1/n1 - k2/n2 [Newcombe 95 % interval]' with signs, as the result tables write a difference of two rates."""
    lo, hi = newcombe_ci(k1, n1, k2, n2)
    return f"{k1 / n1 - k2 / n2:+.3f} [{lo:+.3f}, {hi:+.3f}]"


def newcombe_ci(k1, n1, k2, n2, z: float = 1.96) -> tuple[float, float]:
    """Newcombe's hybrid score interval (his method 10) for p1 - p2 of two independent proportions, from their
    Wilson intervals."""
    p1, p2 = k1 / n1, k2 / n2
    (l1, u1), (l2, u2) = wilson_ci(k1, n1, z), wilson_ci(k2, n2, z)
    d = p1 - p2
    return (d - math.sqrt((p1 - l1) ** 2 + (u2 - p2) ** 2), d + math.sqrt((u1 - p1) ** 2 + (p2 - l2) ** 2))


PathResult = CompositionalResult  # the former name (notebooks written against it)


def unreached(state_dim: int = 0) -> EdgeResult:
    """The result of a subtask whose start nothing reached: p = 0 from zero rollouts, nothing simulated."""
    return EdgeResult(0.0, wilson_ci(0, 0), 0, 0, np.zeros(0, bool), np.zeros((0, 1, 2), np.float32),
                      np.zeros(0, np.int64), StartStates(np.zeros((0, state_dim)), np.zeros((0, 2))), 0,
                      outcome=np.zeros(0, np.int8))


def merge_edge_results(a: EdgeResult, b: EdgeResult) -> EdgeResult:
    """One estimate from two independent batches of rollouts of the same subtask (a's rollouts first)."""
    T = max(a.trajectories.shape[1], b.trajectories.shape[1])
    success = np.concatenate([a.success, b.success])
    k, n = int(success.sum()), a.n + b.n
    ends = StartStates(np.concatenate([a.end_states.states, b.end_states.states]),
                       np.concatenate([a.end_states.xy, b.end_states.xy]))
    traj = np.concatenate([pad_trajectories(a.trajectories, T), pad_trajectories(b.trajectories, T)])
    return EdgeResult(p=k / n if n else 0.0, ci=wilson_ci(k, n), n=n, successes=k, success=success, trajectories=traj,
                      lengths=np.concatenate([a.lengths, b.lengths]), end_states=ends, steps=a.steps + b.steps,
                      cached=a.cached and b.cached, outcome=np.concatenate([a.outcome, b.outcome]))


def pad_trajectories(traj: np.ndarray, T: int) -> np.ndarray:
    """Trajectories padded to T points with each row's last point (rows are already padded that way)."""
    if traj.shape[1] >= T:
        return traj
    return np.concatenate([traj, np.repeat(traj[:, -1:], T - traj.shape[1], axis=1)], axis=1)
