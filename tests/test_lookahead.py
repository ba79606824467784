"""The look-ahead: a goal policy that also observes the goal after the current one (issue 42, lever 2)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from specrefine.core.errors import PolicyError, SpecrefineError
from specrefine.core.mazes import load_maze
from specrefine.core.regions import Box
from specrefine.evaluation.compositional import CompositionalPolicy, Leg, policy_observation
from specrefine.evaluation.evaluator import Evaluator
from specrefine.sim.policy import GoalPolicy, PointController, load_policy, save_policy, widened
from specrefine.sim.policy_eval import evaluate_chain, evaluate_reach, planned_goals
from specrefine.sim.reach_env import GoalReachEnv
from specrefine.sim.simulator import BatchedSim
from specrefine.sim.train import Trainer, main, make_config


class LookingAhead(PointController):
    """A scripted point policy that aims a tenth of the way from its goal towards the next one (so where it goes
    shows what it was fed), recording every observation."""

    lookahead = True

    def __init__(self):
        super().__init__()
        self.fingerprint = "looking-ahead"
        self.seen = []

    def act(self, obs, deterministic: bool = True) -> np.ndarray:
        obs = np.asarray(obs, dtype=np.float64)
        self.seen.append(obs.copy())
        aim = obs[:, 2:4] + 0.1 * (obs[:, 4:6] - obs[:, 2:4])
        return super().act(np.concatenate([obs[:, :2], aim], axis=1))


def gr_observation(sim: BatchedSim, row: int = 0) -> dict:
    """What PointMaze-v3 / AntMaze-v5 (contact forces off) observe (as in test_compositional)."""
    qpos, qvel = sim.qpos[row], sim.qvel[row]
    body = np.concatenate([qpos, qvel]) if sim.agent == "point" else np.concatenate([qpos[2:], qvel])
    return {"observation": body, "achieved_goal": qpos[:2].copy(), "desired_goal": np.zeros(2)}


def stage5() -> GoalPolicy:
    return load_policy("data/policies/ant_stage5.pt")


def random_ant_states(sim: BatchedSim, rng) -> None:
    state = sim.get_state()
    state[:, 1:3] = rng.uniform(-2, 2, (sim.n, 2))
    state[:, sim._qvel] = rng.normal(size=(sim.n, sim.model.nv))
    quat = rng.normal(size=(sim.n, 4))
    state[:, 4:8] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    sim.reset(states=state)


def test_the_header_round_trips_and_shipped_fingerprints_stay(tmp_path):
    old = stage5()
    assert not old.lookahead and old.obs_dim == 29 and old.fingerprint == "551bfe9a0437"  # data/policies/README.md
    wide = widened(old)
    assert wide.lookahead and wide.obs_dim == 31 and wide.observation_frame == "heading"
    assert wide.fingerprint != old.fingerprint
    save_policy(wide, tmp_path / "la.pt")
    back = load_policy(tmp_path / "la.pt")
    assert back.lookahead and back.fingerprint == wide.fingerprint
    save_policy(old, tmp_path / "plain.pt")
    assert "lookahead" not in torch.load(tmp_path / "plain.pt", weights_only=True)  # old files look as before


@pytest.mark.parametrize("change, match", [({"lookahead": "yes"}, "lookahead"), ({"lookahead": 1}, "lookahead"),
                                           ({"obs_dim": 29}, "shape header"), ({"lookahead": False}, "shape header")])
def test_a_bad_look_ahead_header_is_one_policy_error(tmp_path, change, match):
    save_policy(widened(stage5()), tmp_path / "la.pt")
    blob = torch.load(tmp_path / "la.pt", weights_only=True)
    torch.save({**blob, **change}, tmp_path / "bad.pt")
    with pytest.raises(PolicyError, match=match) as err:
        load_policy(tmp_path / "bad.pt")
    assert "\n" not in str(err.value)


def test_widening_keeps_every_action():
    old = stage5()
    wide = widened(old)
    sim = BatchedSim("ant", None, 16)
    rng = np.random.default_rng(4)
    random_ant_states(sim, rng)
    goals, after = rng.uniform(-5, 5, (16, 2)), rng.uniform(-8, 8, (16, 2))
    plain, ahead = sim.observe(goals, "heading"), sim.observe(goals, "heading", after)
    np.testing.assert_array_equal(ahead[:, :29], plain)
    np.testing.assert_allclose(wide.act(ahead), old.act(plain), rtol=0, atol=1e-6)
    first = wide.state_dict()["net.0.weight"]
    assert first.shape == (256, 31) and not first[:, 29:].any()
    torch.testing.assert_close(wide.norm.mean[29:], old.norm.mean[27:29])  # the next goal's statistics: the goal's


@pytest.mark.parametrize("frame", ["world", "heading"])
def test_the_next_goal_is_observed_in_the_current_goal_s_frame(frame):
    sim = BatchedSim("ant", None, 4)
    rng = np.random.default_rng(1)
    random_ant_states(sim, rng)
    goals, after = rng.uniform(-3, 3, (4, 2)), rng.uniform(-3, 3, (4, 2))
    obs = sim.observe(goals, frame, after)
    np.testing.assert_allclose(sim.observe(after, frame)[:, 27:29], obs[:, 29:31], atol=1e-6)
    np.testing.assert_allclose(sim.observe(goals, frame, goals)[:, 29:31], obs[:, 27:29], atol=1e-6)
    for i in range(4):  # the Gymnasium-Robotics observation gives the same
        np.testing.assert_allclose(policy_observation("ant", gr_observation(sim, i), goals[i], frame, after[i]),
                                   obs[i], atol=1e-6)
    point = BatchedSim("point", None, 2)
    np.testing.assert_allclose(point.observe(goals[:2], "world", after[:2])[:, 4:6], after[:2] - point.xy, atol=1e-6)


def test_the_evaluator_feeds_the_next_leg_s_point_and_the_object_does_the_same():
    """run_compositional looks one leg ahead (the last leg at its own point), a per-leg estimate at its own point,
    and the CompositionalPolicy stepped in a plain loop reproduces the evaluator's trajectory."""
    maze = load_maze("u_maze").for_agent("point")
    points = [np.array([0.9, -1.0]), np.array([1.0, 1.0]), np.array([-1.0, 1.0])]  # S -> (1, -1) -> (1, 1) -> G
    boxes = [Box(0.4, -1.4, 1.4, -0.6), Box(0.6, 0.6, 1.4, 1.4), Box(-1.5, 0.5, -0.5, 1.5)]
    legs = [(b, maze.obstacles, p) for b, p in zip(boxes, points, strict=True)]
    policy = LookingAhead()
    ev = Evaluator(maze, "point", policy, n=1, seed=3)
    run = ev.run_compositional(maze.start, legs, n=1, seed=3)
    assert run.success[0]
    seen = np.concatenate(policy.seen)
    offsets = {tuple(np.round(v, 6)) for v in seen[:, 4:6] - seen[:, 2:4]}
    assert offsets == {tuple(np.round(points[1] - points[0], 6)), tuple(np.round(points[2] - points[1], 6)),
                       (0.0, 0.0)}
    policy.seen.clear()
    ev.evaluate(maze.start, boxes[0], maze.obstacles, n=4, goal_point=points[0])
    assert np.abs(np.concatenate(policy.seen)[:, 4:6] - np.concatenate(policy.seen)[:, 2:4]).max() < 1e-6

    rng = np.random.default_rng(3)
    start = ev.spawn_points(maze.start, 1, rng)
    obj = CompositionalPolicy("point", maze, [Leg(str(i), g, a, tuple(p)) for i, (g, a, p) in enumerate(legs)],
                              LookingAhead(), ev.horizon)
    sim = BatchedSim("point", maze, 1)
    sim.reset(xy=start)
    xy = [sim.xy[0].copy()]
    while not obj.done and len(xy) < run.lengths[0]:
        sim.step(obj.act(gr_observation(sim))[None])
        xy.append(sim.xy[0].copy())
    np.testing.assert_allclose(np.array(xy), run.trajectories[0, :len(xy)], atol=1e-5)


def test_braking_at_a_leg_s_start_looks_ahead_to_that_leg_s_point():
    maze = load_maze("u_maze").for_agent("point")
    legs = [Leg("a", Box(0.0, -1.5, 1.5, 0.5), maze.obstacles, (0.9, -0.6)),
            Leg("b", Box(-1.5, 0.5, 0.0, 1.5), maze.obstacles, (-0.9, 0.9))]
    obj = CompositionalPolicy("point", maze, legs, LookingAhead(), 100, switching="slow-turn")
    obj.reset(seed=0)
    # inside leg a's region, moving fast away from leg b's point: the rule holds, the agent aims at itself
    obj.act({"observation": np.array([0.9, -0.6, 3.0, -1.0]), "achieved_goal": np.array([0.9, -0.6])})
    obs = obj.goal_policy.seen[-1][0]
    assert obj.holding and obj.leg == 1
    np.testing.assert_allclose(obs[2:4], [0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(obs[4:6], np.array([-0.9, 0.9]) - [0.9, -0.6], atol=1e-6)


def test_planned_goals_turn_from_the_leg_before_and_every_policy_meets_them():
    rng = np.random.default_rng(0)
    start = np.zeros((300, 2))
    first = start + np.array([3.0, 0.0])
    plan = planned_goals(start, first, 5, 3.0, 5.0, (90.0, 180.0), rng)
    legs = np.diff(np.concatenate([start[None], plan]), axis=0)
    lengths = np.linalg.norm(legs[1:], axis=2)
    assert lengths.min() >= 3.0 - 1e-9 and lengths.max() <= 5.0 + 1e-9
    cos = (legs[1:] * legs[:-1]).sum(2) / (np.linalg.norm(legs[1:], axis=2) * np.linalg.norm(legs[:-1], axis=2))
    turn = np.degrees(np.arccos(np.clip(cos, -1, 1)))
    assert turn.min() >= 90.0 - 1e-6 and turn.max() <= 180.0 + 1e-6
    plain = evaluate_chain(load_policy("point"), episodes=24, goals=3, seed=2, planned=True)
    ahead = evaluate_chain(widened(load_policy("point")), episodes=24, goals=3, seed=2)
    assert plain["planned_goals"] and ahead["planned_goals"]  # on by default for a look-ahead policy
    assert plain["reached"] == ahead["reached"]  # the widened policy acts as the plain one: the same goals, reached
    assert "planned_goals" not in evaluate_chain(load_policy("point"), episodes=8, goals=2, seed=2)
    one = evaluate_reach(widened(load_policy("point")), episodes=32, seed=1)
    assert one["success_rate"] == evaluate_reach(load_policy("point"), episodes=32, seed=1)["success_rate"]


def test_the_training_env_draws_the_next_goal_ahead():
    from dataclasses import replace

    from specrefine.core.agents import get_agent

    task = replace(get_agent("point").reach_task, goals_per_episode=3)
    env = GoalReachEnv("point", 64, seed=0, task=task, turn=(90.0, 180.0), lookahead=True)
    obs = env.restart(np.arange(64))
    assert obs.shape == (64, 6) and env.obs_dim == 6
    np.testing.assert_allclose(obs[:, 4:6], env.next_goals - env.sim.xy, atol=1e-6)
    first, after, start = env.goals.copy(), env.next_goals.copy(), env.sim.xy.copy()
    cos = ((after - first) * (first - start)).sum(1) / (np.linalg.norm(after - first, axis=1)
                                                        * np.linalg.norm(first - start, axis=1))
    assert np.degrees(np.arccos(np.clip(cos, -1, 1))).min() >= 90.0 - 1e-6
    idx = np.arange(64)
    for k in (1, 2):  # two switches: the goal becomes the one seen ahead; on the last goal, next = current
        env.goal_index[idx] = k
        env._new_goals(idx)
        np.testing.assert_array_equal(env.goals, after)
        after = env.next_goals.copy()
    np.testing.assert_array_equal(env.next_goals, env.goals)
    with pytest.raises(SpecrefineError, match="open floor"):
        make_config("point", lookahead=True, train_maze="random:3x3:0")


def test_init_from_stage5_widens_and_starts_as_stage5(tmp_path, capsys):
    cfg = make_config("ant", frames=2048, seed=9, init="data/policies/ant_stage5.pt", observation_frame="heading",
                      lookahead=True, goals_per_episode=5, turn_goals=(45.0, 180.0), num_envs=4, steps_per_env=8,
                      checkpoint_every_s=1e9)
    trainer = Trainer(cfg, tmp_path / "s8", progress=False)
    assert trainer.policy.lookahead and trainer.policy.fingerprint == widened(stage5()).fingerprint
    batch = trainer.collector.collect()
    obs = batch["observation"].reshape(-1, 31).numpy()
    np.testing.assert_allclose(trainer.policy.act(obs), stage5().act(obs[:, :29]), rtol=0, atol=1e-6)
    trainer.update(batch)  # the critic sees the look-ahead too
    save_policy(trainer.policy, tmp_path / "la.pt")
    assert main(["--agent", "ant", "--out", str(tmp_path / "back"), "--init", str(tmp_path / "la.pt"),
                 "--frames", "64"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--lookahead" in err


def test_a_look_ahead_run_resumes_with_the_same_flags(tmp_path, capsys):
    from specrefine.sim.curves import read_log

    run = tmp_path / "run"
    flags = dict(seed=0, goals_per_episode=3, turn_goals=(45.0, 180.0), lookahead=True, num_envs=8, steps_per_env=64,
                 checkpoint_every_s=1e9)
    Trainer(make_config("point", frames=1024, **flags), run, progress=False).train()
    trainer = Trainer(make_config("point", frames=2048, **flags), run, resume=True, progress=False)
    assert trainer.frames == 1024 and trainer.policy.lookahead
    trainer.train()
    assert read_log(run / "log.jsonl")[-1]["frames"] == 2048 and load_policy(run / "policy.pt").lookahead
    assert main(["--agent", "point", "--out", str(run), "--resume", "--frames", "4096"]) == 2  # --lookahead left out
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--resume" in err
