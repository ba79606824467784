"""The compositional policy object: observation mapping, goal switching, save/load through a run folder."""

from __future__ import annotations

import json

import numpy as np
import pytest

from specrefine.cli import main
from specrefine.core.errors import PolicyError
from specrefine.core.mazes import load_maze
from specrefine.core.regions import Box
from specrefine.evaluation.compositional import POLICY_JSON, CompositionalPolicy, Leg, policy_observation
from specrefine.evaluation.evaluator import Evaluator
from specrefine.sim.policy import PointController
from specrefine.sim.simulator import BatchedSim


def gr_observation(sim: BatchedSim, row: int = 0) -> dict:
    """What PointMaze-v3 / AntMaze-v5 (contact forces off) observe, read from this package's simulator."""
    qpos, qvel = sim.qpos[row], sim.qvel[row]
    body = np.concatenate([qpos, qvel]) if sim.agent == "point" else np.concatenate([qpos[2:], qvel])
    return {"observation": body, "achieved_goal": qpos[:2].copy(), "desired_goal": np.zeros(2)}


@pytest.mark.parametrize("frame", ["world", "heading"])
@pytest.mark.parametrize("agent", ["point", "ant"])
def test_policy_observation_is_the_simulators(agent, frame):
    sim = BatchedSim(agent, None, 3)
    rng = np.random.default_rng(0)
    state = sim.get_state()
    state[:, 1:3] = rng.uniform(-2, 2, (3, 2))
    state[:, sim._qvel] = rng.normal(size=(3, sim.model.nv))
    if agent == "ant":
        quat = rng.normal(size=(3, 4))
        state[:, 4:8] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    sim.reset(states=state)
    goals = rng.uniform(-3, 3, (3, 2))
    ours = sim.observe(goals, frame)
    for i in range(3):
        assert np.allclose(policy_observation(agent, gr_observation(sim, i), goals[i], frame), ours[i], atol=1e-6)


def test_goal_switching_follows_the_evaluator_rule():
    maze = load_maze("u_maze").for_agent("point")
    legs = [Leg("a", Box(0.0, 0.0, 1.0, 1.0), maze.obstacles, (0.5, 0.5)),
            Leg("b", Box(0.5, 0.0, 1.0, 1.0), maze.obstacles, (0.8, 0.2)),  # inside a: both are passed at once
            Leg("c", Box(-1.0, -1.0, -0.5, -0.5), maze.obstacles, None)]
    policy = CompositionalPolicy("point", maze, legs, PointController(), horizon=3)
    policy.reset(seed=0)
    assert policy.goal_points[2][0] <= -0.5 and policy.goal_points[2][1] <= -0.5  # drawn inside c
    at = lambda x, y: {"observation": np.array([x, y, 0.0, 0.0]), "achieved_goal": np.array([x, y])}  # noqa: E731
    policy.act(at(-2.0, 2.0))
    assert policy.leg == 0 and policy.decisions_in_leg == 1
    policy.act(at(0.7, 0.7))
    assert policy.leg == 2 and not policy.done
    policy.act(at(-0.7, -0.7))
    assert policy.done
    policy.reset(at(0.9, 0.9), seed=0)  # reset checks the start position too
    assert policy.leg == 2
    policy.act(at(2.0, 2.0)), policy.act(at(2.0, 2.0)), policy.act(at(2.0, 2.0))
    assert policy.timed_out and policy.touching([2.3, -0.3]) and not policy.touching([0.0, -1.0])


def test_hold_keeps_the_control_period():
    maze = load_maze("u_maze").for_agent("point")
    policy = CompositionalPolicy("point", maze, [Leg("g", maze.goal, maze.obstacles, (-1.0, 1.0))], PointController(),
                                 horizon=100, env_dt=0.01)
    assert policy.hold == 5
    xs = np.linspace(0, 0.5, 10)
    actions = [policy.act({"observation": np.array([x, -1, 0, 0]), "achieved_goal": np.array([x, -1.0])}) for x in xs]
    assert all(np.array_equal(actions[0], a) for a in actions[1:5]) and not np.array_equal(actions[4], actions[5])
    assert all(np.linalg.norm(a) <= 1.0 + 1e-12 for a in actions)  # the point's unit disc


@pytest.mark.parametrize("switching", ["at-region", "slow-turn"])
def test_the_object_reproduces_run_compositional_in_this_simulator(switching):
    """Driven step by step, the object gives the evaluator's own trajectory (scripted policy: bit-exact), under
    either switching rule (slow-turn holds the turn towards the goal at the end of the first leg)."""
    maze = load_maze("u_maze").for_agent("point")
    legs = [(Box(0.0, -1.5, 1.5, 0.5), maze.obstacles, np.array([0.9, -0.6])), (maze.goal, maze.obstacles, None)]
    ev = Evaluator(maze, "point", PointController(), n=1, seed=3, switching=switching)
    run = ev.run_compositional(maze.start, legs, n=1, seed=3)
    rng = np.random.default_rng(3)
    start = ev.spawn_points(maze.start, 1, rng)
    policy = CompositionalPolicy("point", maze, [Leg(str(i), g, a, None if p is None else tuple(p))
                                                 for i, (g, a, p) in enumerate(legs)], PointController(), ev.horizon,
                                    switching=switching)
    policy.reset(seed=None)
    policy.goal_points[1] = ev.sample_free(maze.goal, 1, rng)[0]  # the evaluator's draw, in its order
    sim = BatchedSim("point", maze, 1)
    sim.reset(xy=start)
    xy = [sim.xy[0].copy()]
    while not policy.done and len(xy) < run.lengths[0]:
        sim.step(policy.act(gr_observation(sim))[None])
        xy.append(sim.xy[0].copy())
    policy.update({"achieved_goal": xy[-1]})
    assert policy.done == bool(run.success[0])
    np.testing.assert_allclose(np.array(xy), run.trajectories[0, :len(xy)], atol=1e-5)


def test_refine_writes_a_policy_that_loads(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["refine", "u_maze", "--method", "dirl", "--out", str(out), "--rollouts", "8", "--episodes", "8"]) == 0
    data = json.loads((out / POLICY_JSON).read_text())
    result = json.loads((out / "result.json").read_text())
    assert data["path"] == result["path"] and len(data["legs"]) == len(result["path"]) - 1
    assert data["goal_policy"]["checkpoint"] == "shipped"
    assert data["goal_policy"]["fingerprint"] == result["policy_fingerprint"]
    policy = CompositionalPolicy.load(out)
    assert policy.agent == "point" and policy.maze.grid == load_maze("u_maze").grid and policy.horizon == 100
    data["goal_policy"]["fingerprint"] = "0" * 12
    (out / POLICY_JSON).write_text(json.dumps(data))
    with pytest.raises(PolicyError, match="fingerprint"):
        CompositionalPolicy.load(out)
    (out / POLICY_JSON).write_text("{not json")
    with pytest.raises(PolicyError, match="unreadable"):
        CompositionalPolicy.load(out)
    with pytest.raises(PolicyError, match="no compositional policy"):
        CompositionalPolicy.load(tmp_path)


def test_a_run_saves_its_switching_rule_and_official_runs_it(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["refine", "u_maze", "--method", "dirl", "--out", str(out), "--rollouts", "8", "--episodes", "8",
                 "--switching", "slow-turn"]) == 0
    assert json.loads((out / "run.json").read_text())["switching"] == "slow-turn"
    assert json.loads((out / "result.json").read_text())["config"]["switching"] == "slow-turn"
    data = json.loads((out / POLICY_JSON).read_text())
    assert data["switching_rule"] == "slow-turn" and CompositionalPolicy.load(out).switching == "slow-turn"
    capsys.readouterr()
    assert main(["official", str(out), "--episodes", "2"]) == 0
    assert "; switching: slow-turn)" in capsys.readouterr().out
    assert json.loads((out / "official.json").read_text())["settings"]["switching"] == "slow-turn"
    (out / POLICY_JSON).write_text(json.dumps({**data, "switching_rule": "blend"}))
    with pytest.raises(PolicyError, match="switching_rule"):
        CompositionalPolicy.load(out)
    del data["switching_rule"]  # a policy saved before the rules were named: the paper's
    (out / POLICY_JSON).write_text(json.dumps(data))
    assert CompositionalPolicy.load(out).switching == "at-region"
