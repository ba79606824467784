"""The switching rules: at-region (the default, unchanged) and slow-turn (a fast, turned leg start brakes first)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from specrefine.core.errors import SpecrefineError
from specrefine.core.mazes import load_maze
from specrefine.core.regions import Box, Disc
from specrefine.evaluation.compositional import CompositionalPolicy, Leg
from specrefine.evaluation.evaluator import Evaluator
from specrefine.runs.config import RunConfig
from specrefine.sim.policy import PointController
from specrefine.sim.switching import SlowTurn, switching_rule


class Recorder:
    """A goal policy that records the goal (relative to the agent) it is fed and acts as ``inner`` does."""

    fingerprint = None

    def __init__(self, inner=None):
        self.inner, self.seen = inner, []

    def act(self, obs):
        obs = np.asarray(obs)
        self.seen.append(obs.copy())
        return self.inner.act(obs) if self.inner is not None else np.zeros((len(obs), 2))


def point(x, y, vx=0.0, vy=0.0) -> dict:
    """A PointMaze observation of the point mass at (x, y) moving at (vx, vy)."""
    return {"observation": np.array([x, y, vx, vy]), "achieved_goal": np.array([x, y])}


def two_leg_policy(switching: str) -> tuple[CompositionalPolicy, Recorder]:
    maze = load_maze("u_maze").for_agent("point")
    legs = [Leg("a", Disc(1.0, 1.0, 0.3), maze.obstacles, (1.0, 1.0)),
            Leg("b", Disc(1.0, 3.0, 0.3), maze.obstacles, (1.0, 3.0))]  # a 90-degree turn at a
    recorder = Recorder()
    return CompositionalPolicy("point", maze, legs, recorder, horizon=100, switching=switching), recorder


def test_the_hold_needs_speed_a_turn_and_time_left():
    rule = SlowTurn(speed=1.0, turn_deg=45.0, max_hold=20)
    velocity = [[2.0, 0.0], [0.5, 0.0], [2.0, 0.0], [2.0, 0.0], [2.0, 0.0]]
    to_goal = [[0.0, 3.0], [0.0, 3.0], [3.0, 0.5], [0.0, 3.0], [-3.0, 0.0]]
    decisions = [0, 0, 0, 20, 5]
    assert rule.holding(velocity, to_goal, decisions).tolist() == [True, False, False, False, True]
    assert switching_rule("at-region") is None and switching_rule("slow-turn") == SlowTurn()
    with pytest.raises(SpecrefineError, match="switching rule"):
        switching_rule("blend")


def test_slow_turn_holds_the_switch_until_the_speed_drops():
    policy, seen = two_leg_policy("slow-turn")
    policy.reset(seed=0)
    policy.act(point(1.0, 0.0, 0.0, 2.0))  # leg a, straight at its goal: never held
    assert np.allclose(seen.seen[-1][0][2:], [0.0, 1.0])
    policy.act(point(1.0, 1.0, 2.0, 0.0))  # in a's region, moving east at 2 m/s: b lies 90 degrees away
    assert policy.leg == 1 and policy.holding
    assert np.allclose(seen.seen[-1][0][2:], [0.0, 0.0])  # aims at its own position: brakes
    policy.act(point(1.2, 1.0, 1.5, 0.0))
    assert policy.holding and np.allclose(seen.seen[-1][0][2:], [0.0, 0.0])
    policy.act(point(1.3, 1.0, 0.8, 0.0))  # below 1 m/s: the switch is taken
    assert not policy.holding and np.allclose(seen.seen[-1][0][2:], [-0.3, 2.0])
    policy.act(point(1.3, 1.1, 3.0, 0.0))  # fast and turned again, later in the leg: no second hold
    assert not policy.holding and np.allclose(seen.seen[-1][0][2:], [-0.3, 1.9])


def test_slow_turn_lets_go_after_its_longest_hold():
    policy, seen = two_leg_policy("slow-turn")
    policy.reset(point(1.0, 1.0, 2.0, 0.0), seed=0)
    for _ in range(SlowTurn().max_hold + 1):
        policy.act(point(1.0, 1.0, 2.0, 0.0))
    held = [np.allclose(obs[0][2:], 0.0) for obs in seen.seen]
    assert held == [True] * SlowTurn().max_hold + [False]


def test_at_region_is_the_default_and_switches_at_once():
    policy, seen = two_leg_policy("at-region")
    assert CompositionalPolicy("point", policy.maze, policy.legs, seen, horizon=100).switching == "at-region"
    policy.reset(seed=0)
    policy.act(point(1.0, 1.0, 2.0, 0.0))
    assert policy.leg == 1 and not policy.holding and np.allclose(seen.seen[-1][0][2:], [0.0, 2.0])


def test_the_evaluator_holds_as_the_policy_object_does():
    """RolloutLoop: a held decision aims at the agent itself, only at a leg's start, fast and turned away."""
    maze = load_maze("u_maze").for_agent("point")
    recorder = Recorder(PointController())
    start = Disc(-1.0, -1.0, 0.05)  # u_maze's corridor: east to (1, -1), then north to (1, 1)
    far = Box(-9, -9, -8, -8)  # nothing to avoid
    legs = [(Disc(1.0, -1.0, 0.3), far, (1.0, -1.0)), (Disc(1.0, 1.0, 0.3), far, (1.0, 1.0))]
    ev = Evaluator(maze, "point", recorder, n=8, switching="slow-turn")
    ev.run_compositional(start, legs, seed=3)
    obs = np.concatenate([o[:8] for o in recorder.seen])  # the 8 live rows of each decision
    held = np.all(obs[:, 2:] == 0.0, axis=1)
    speed = np.linalg.norm(obs[:, :2], axis=1)
    assert held.any() and (speed[held] > 1.0).all()


def test_at_region_keeps_its_outcomes_and_cache_keys_and_slow_turn_has_its_own():
    maze = load_maze("u_maze").for_agent("point")
    legs = [(Disc(1.0, -1.0, 0.3), Box(-9, -9, -8, -8), (1.0, -1.0)), (Disc(1.0, 1.0, 0.3), Box(-9, -9, -8, -8), None)]
    start = Disc(-1.0, -1.0, 0.2)
    plain, named = (Evaluator(maze, "point", PointController(), n=16, **kw) for kw in ({}, {"switching": "at-region"}))
    a, b = plain.run_compositional(start, legs, seed=5), named.run_compositional(start, legs, seed=5)
    assert np.array_equal(a.outcome, b.outcome) and np.array_equal(a.trajectories, b.trajectories)
    slow = Evaluator(maze, "point", PointController(), n=16, switching="slow-turn")
    key = lambda ev: ev._key("edge", start, legs[:1], 16, 5, "fp")  # noqa: E731
    assert key(plain) == key(named) and "switching" not in key(plain)[1]
    assert key(slow)[0] != key(plain)[0] and json.loads(key(slow)[1])["switching"] == "slow-turn"
    assert slow.fresh_copy().switching == "slow-turn"


def test_a_run_records_its_switching_rule():
    assert RunConfig().switching == "at-region" and "switching" not in RunConfig().resolved().record()
    assert RunConfig(switching="slow-turn").resolved().record()["switching"] == "slow-turn"


def test_the_eight_goal_check_takes_the_rule():
    from specrefine.sim.policy_eval import evaluate_chain

    plain = evaluate_chain(PointController(), episodes=8, goals=3, lo=1.0, hi=2.0, seed=0)
    named = evaluate_chain(PointController(), episodes=8, goals=3, lo=1.0, hi=2.0, seed=0, switching="at-region")
    slow = evaluate_chain(PointController(), episodes=8, goals=3, lo=1.0, hi=2.0, seed=0, switching="slow-turn")
    assert plain == named and "switching" not in plain and slow["switching"] == "slow-turn"
    assert slow["mean_switch_speed_mps"] != plain["mean_switch_speed_mps"]  # the holds changed the episodes
