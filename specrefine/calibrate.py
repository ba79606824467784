"""A calibrated prediction of the output policy's success, with a 95 % interval.

The search keeps the candidates that looked best, so the product of its own estimates along the
chosen path is biased upward (the winner's curse), and a leg estimated at 32/32 still fails now and
then. ``predict`` re-estimates the chosen path's legs on HELD-OUT rollouts (a seed the search never
used; start states propagated leg to leg from the original initial set, as the compositional policy
runs), puts a Jeffreys Beta(s + 1/2, n - s + 1/2) posterior on each leg, and reports the posterior
mean of the product (each extra leg is charged, even at 32/32) with two 95 % intervals (Monte Carlo
over independent legs): ``p_ci`` for the path's success probability itself, and ``ci`` for what the
run then measures, the success rate over ``episodes`` fresh episodes (the posterior predictive: the
product's draws, each passed through a binomial of ``episodes``), which is the interval that the
measured ``success_rate`` should fall in. The held-out rollouts run on a copy of the evaluator, so
the run's own counters (``evaluations``, ``sim_steps``) are those of the search and the measurement.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

HOLDOUT_SEED_OFFSET = 2_000_029  # neither the search's seed nor the measurement's
DRAWS = 20_000


@dataclass
class Prediction:
    p: float  # posterior mean of the path's success
    ci: tuple[float, float]  # 95 % predictive interval of the success rate measured over `episodes` episodes
    p_ci: tuple[float, float]  # 95 % credible interval of the path's success probability
    successes: list[int]  # per leg, held-out
    rollouts: list[int]  # per leg
    sim_steps: int  # simulated for the held-out estimates

    def to_dict(self) -> dict:
        return {"predicted_success": self.p, "predicted_ci": list(self.ci), "predicted_p_ci": list(self.p_ci),
                "predicted_leg_successes":
                self.successes, "predicted_leg_rollouts": self.rollouts, "prediction_sim_steps": self.sim_steps}


def product_posterior(successes, rollouts, seed: int = 0, draws: int = DRAWS,
                      episodes: int | None = None) -> tuple[float, tuple[float, float]]:
    """Posterior mean and 95 % interval of a product of independent success probabilities (Jeffreys prior);
    with ``episodes``, the interval is the posterior predictive one of a success rate over that many episodes."""
    s, n = np.asarray(successes, dtype=float), np.asarray(rollouts, dtype=float)
    if not len(s):
        return 0.0, (0.0, 0.0)
    a, b = s + 0.5, n - s + 0.5
    rng = np.random.default_rng(seed)
    samples = rng.beta(a, b, size=(draws, len(a))).prod(axis=1)
    if episodes:
        samples = rng.binomial(int(episodes), samples) / int(episodes)
    lo, hi = np.quantile(samples, [0.025, 0.975])
    return float(np.prod(a / (a + b))), (float(lo), float(hi))


def predict(evaluator, graph, path, start, seed: int = 0, episodes: int = 200) -> Prediction:
    """Held-out estimate of the compositional policy along ``path`` of ``graph``, started from ``start``."""
    from .evaluate import path_legs

    if not path or len(path) < 2:
        return Prediction(0.0, (0.0, 0.0), (0.0, 0.0), [], [], 0)
    holdout = evaluator.fresh_copy()
    successes, rollouts = [], []
    for goal, avoid, point in path_legs(graph, path):
        if start is None:  # nothing reached this leg: unknown, the prior alone (the product is ~0 anyway)
            successes.append(0)
            rollouts.append(0)
            continue
        res = holdout.evaluate(start, goal, avoid, goal_point=point, seed=seed + HOLDOUT_SEED_OFFSET)
        successes.append(int(res.successes))
        rollouts.append(int(res.n))
        start = res.end_states if res.successes else None
    p, p_ci = product_posterior(successes, rollouts, seed=seed)
    _, ci = product_posterior(successes, rollouts, seed=seed, episodes=episodes)
    return Prediction(p, ci, p_ci, successes, rollouts, int(holdout.sim_steps))


def coverage(rows) -> tuple[int, int]:
    """(runs whose measured success lies inside predicted_ci, runs with a predicted_ci)."""
    inside = total = 0
    for r in rows:
        lo, hi = r.get("predicted_ci_low"), r.get("predicted_ci_high")
        if lo in (None, "") or hi in (None, ""):
            continue
        total += 1
        inside += float(lo) <= float(r["success_rate"]) <= float(hi)
    return inside, total
