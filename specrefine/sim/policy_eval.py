"""Open-floor evaluation of a goal policy: reach one goal, or a chain of goals, with no maze around.

    python -m specrefine.sim.train --agent ant --evaluate data/policies/ant.pt --episodes 500
    python -m specrefine.sim.train --agent ant --evaluate ant --chain 8 --goal-range 3 5   # goals in a row

Episodes start at the origin in the default pose; goals lie at a uniform distance in the agent's reach
range (``specrefine.core.agents``' ``reach_task``) unless given.  The figures of these results are in
:mod:`specrefine.sim.curves`.
"""

from __future__ import annotations

import numpy as np
import torch

from ..core.agents import get_agent
from ..core.results import wilson_ci
from .policy import GoalPolicy, wants_lookahead
from .simulator import BatchedSim, direction_of_travel, sample_goals, sample_turn_goals
from .switching import AT_REGION, switching_rule


def _frame(policy) -> str:
    return getattr(policy, "observation_frame", "world")  # a scripted controller has none


def _observe(sim: BatchedSim, policy, goals: np.ndarray, next_goals: np.ndarray) -> np.ndarray:
    """The policy's observation; the next goals only for a policy that looks ahead."""
    return sim.observe(goals, _frame(policy), next_goals if wants_lookahead(policy) else None)


def _open_floor(policy: GoalPolicy, episodes: int, lo, hi, seed: int, horizon, nthread=None):
    """The evaluation setup: episodes at the origin in the default pose, one goal each in [lo, hi] m."""
    task = get_agent(policy.agent).reach_task
    lo = task.goal_min if lo is None else lo
    hi = task.goal_max if hi is None else hi
    rng = np.random.default_rng(seed)
    sim = BatchedSim(policy.agent, None, episodes, nthread=nthread)
    sim.reset(xy=np.zeros((episodes, 2)), rng=rng)
    return task, lo, hi, rng, sim, horizon or sim.default_horizon, sample_goals(sim.xy, lo, hi, rng)


def evaluate_reach(policy: GoalPolicy, episodes: int = 500, lo: float | None = None, hi: float | None = None,
                   seed: int = 0, horizon: int | None = None, nthread: int | None = None) -> dict:
    """Deterministic policy, open floor, goals at uniform distance in [lo, hi]: success within the horizon."""
    task, lo, hi, rng, sim, horizon, goals = _open_floor(policy, episodes, lo, hi, seed, horizon, nthread)
    dist0 = np.linalg.norm(goals - sim.xy, axis=1)
    active = np.ones(episodes, dtype=bool)
    success, flipped = np.zeros(episodes, bool), np.zeros(episodes, bool)
    steps = np.full(episodes, horizon)
    traj = np.zeros((episodes, horizon + 1, 2))
    traj[:, 0] = sim.xy
    for t in range(horizon):
        sim.step(np.where(active[:, None], policy.act(_observe(sim, policy, goals, goals)), 0.0))
        xy = sim.xy
        traj[:, t + 1] = np.where(active[:, None], xy, traj[:, t])
        hit = active & (np.linalg.norm(goals - xy, axis=1) < task.success_radius)
        flip = active & sim.flipped & ~hit
        success |= hit
        flipped |= flip
        steps[hit | flip] = t + 1
        active &= ~(hit | flip)
        if not active.any():
            break
    sim.close()
    k = int(success.sum())
    return {"agent": policy.agent, "episodes": episodes, "seed": seed, "goal_range_m": [lo, hi], "horizon": horizon,
            "success_radius_m": task.success_radius, "success_rate": k / episodes,
            "success_ci95": wilson_ci(k, episodes), "flip_rate": float(flipped.mean()),
            "mean_steps_success": float(steps[success].mean()) if k else None,
            "distance": dist0, "success": success, "flipped": flipped, "steps": steps, "trajectories": traj,
            "goals": goals}


def evaluate_chain(policy: GoalPolicy, episodes: int = 200, goals: int = 8, lo: float | None = None,
                   hi: float | None = None, seed: int = 0, horizon: int | None = None,
                   turn: tuple[float, float] | None = None, switching: str = AT_REGION,
                   planned: bool | None = None) -> dict:
    """Open floor, ``goals`` goals in a row: each new goal drawn where the last was reached, no reset.

    This is how a compositional policy uses the goal policy (the next subtask starts from a moving
    state); per goal it reports how many episodes got there and how many flipped on the way, and the mean planar
    speed at the switches.  ``turn`` = (lo, hi) degrees: every goal after the first turns by that much from the
    direction of travel at the switch (``simulator.sample_turn_goals``); None: any direction.  ``switching``: when
    the policy is fed a new goal (:mod:`specrefine.sim.switching`, as a compositional policy's legs).

    ``planned`` (default: whether the policy looks ahead, ``GoalPolicy.lookahead``): every episode's goals are drawn
    before it starts, each from the goal before it (turning from the line between the two goals before it), so
    every policy meets the same goals and a look-ahead policy is fed the next one (the last goal's own on the last).
    """
    hold = switching_rule(switching)
    task, lo, hi, rng, sim, horizon, goal = _open_floor(policy, episodes, lo, hi, seed, horizon)
    planned = wants_lookahead(policy) if planned is None else planned
    plan = planned_goals(sim.xy, goal, goals, lo, hi, turn, rng) if planned else None
    index, t = np.zeros(episodes, dtype=np.int64), np.zeros(episodes, dtype=np.int64)
    alive, holding = np.ones(episodes, dtype=bool), np.full(episodes, hold is not None)
    reached, flips, timeouts = np.zeros(goals, np.int64), np.zeros(goals, np.int64), np.zeros(goals, np.int64)
    switch_speeds = []
    with torch.inference_mode():
        while alive.any():
            after = goal if plan is None else plan[np.minimum(index + 1, goals - 1), np.arange(episodes)]
            aim = goal if hold is None else _held_aim(hold, sim, goal, t, holding)
            after = np.where(holding[:, None], goal, after) if hold is not None else after  # braking: the leg's goal
            sim.step(np.where(alive[:, None], policy.act(_observe(sim, policy, aim, after)), 0.0))
            t += 1
            flip = alive & sim.flipped
            np.add.at(flips, index[flip], 1)
            alive &= ~flip
            hit = alive & (np.linalg.norm(sim.xy - goal, axis=1) < task.success_radius)
            np.add.at(reached, index[hit], 1)
            index[hit] += 1
            t[hit] = 0
            holding[hit] = hold is not None
            switch = hit & (index < goals)
            velocity = sim.qvel[switch, :2]
            switch_speeds.extend(np.linalg.norm(velocity, axis=1))
            if plan is not None:
                goal[switch] = plan[index[switch], np.flatnonzero(switch)]
            elif turn is None:
                goal[hit] = sample_goals(sim.xy[hit], lo, hi, rng)
            else:
                travel = direction_of_travel(velocity, goal[switch] - sim.xy[switch])
                goal[switch] = sample_turn_goals(sim.xy[switch], travel, lo, hi, turn, rng)
            alive &= index < goals
            late = alive & (t >= horizon)
            np.add.at(timeouts, index[late], 1)
            alive &= ~late
    sim.close()
    k = int(reached[-1])
    return {"agent": policy.agent, "episodes": episodes, "seed": seed, "goals": goals, "goal_range_m": [lo, hi],
            "horizon": horizon, "success_rate": k / episodes, "success_ci95": wilson_ci(k, episodes),
            "reached": reached.tolist(), "flipped": flips.tolist(), "timed_out": timeouts.tolist(),
            "flips_per_goal": float(flips.sum() / max(1, reached.sum() + flips.sum() + timeouts.sum())),
            **({} if turn is None else {"turn_degrees": list(turn)}),
            "mean_switch_speed_mps": float(np.mean(switch_speeds)) if switch_speeds else None,
            **({} if hold is None else {"switching": switching}), **({"planned_goals": True} if planned else {})}


def planned_goals(start: np.ndarray, first: np.ndarray, goals: int, lo: float, hi: float,
                  turn: tuple[float, float] | None, rng: np.random.Generator) -> np.ndarray:
    """``(goals, n, 2)``: each episode's goals in a row, ``first`` then each drawn from the one before it at [lo, hi]
    m, in any direction or (``turn``) turning from the direction of the leg before it (from ``start`` for the
    first)."""
    plan = np.empty((goals, len(first), 2))
    plan[0] = first
    for k in range(1, goals):
        before = start if k == 1 else plan[k - 2]
        plan[k] = sample_goals(plan[k - 1], lo, hi, rng) if turn is None else \
            sample_turn_goals(plan[k - 1], plan[k - 1] - before, lo, hi, turn, rng)
    return plan


def _held_aim(hold, sim: BatchedSim, goal: np.ndarray, t: np.ndarray, holding: np.ndarray) -> np.ndarray:
    """The goals fed this step: each row's own position while the switching rule holds its new goal's start."""
    xy, rows = sim.xy, np.flatnonzero(holding)
    holding[rows] = hold.holding(sim.qvel[rows, :2], goal[rows] - xy[rows], t[rows])
    return np.where(holding[:, None], xy, goal)


def success_by_distance(result: dict, bins: int = 8) -> list[dict]:
    lo, hi = result["goal_range_m"]
    edges = np.linspace(lo, hi, bins + 1)
    rows = []
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        m = (result["distance"] >= a) & (result["distance"] < b if b < hi else result["distance"] <= b)
        k, n = int(result["success"][m].sum()), int(m.sum())
        rows.append({"from_m": round(float(a), 3), "to_m": round(float(b), 3), "n": n,
                     "success_rate": k / n if n else None, "ci95": wilson_ci(k, n)})
    return rows


def summary(result: dict) -> dict:
    keep = ("agent", "episodes", "seed", "goal_range_m", "horizon", "success_radius_m", "success_rate",
            "success_ci95", "flip_rate", "mean_steps_success")
    return {k: result[k] for k in keep} | {"by_distance": success_by_distance(result)}

