"""Batched MuJoCo simulation: shapes, seeding, walls, flips, state round trip, TorchRL env."""

import numpy as np
import pytest
import torch

from specrefine.core.errors import SpecrefineError
from specrefine.core.mazes import parse_maze
from specrefine.sim.reach_env import GoalReachEnv
from specrefine.sim.simulator import BatchedSim

CORRIDOR = parse_maze("#####\n#S.G#\n#####", "corridor")


@pytest.mark.parametrize("agent,obs_dim,act_dim", [("point", 4, 2), ("ant", 29, 8)])
def test_shapes_and_spaces(agent, obs_dim, act_dim):
    sim = BatchedSim(agent, CORRIDOR, 3, nthread=1)
    assert (sim.obs_dim, sim.act_dim) == (obs_dim, act_dim)
    assert sim.dt == pytest.approx(0.05) and sim.default_horizon > 0 and sim.body_radius > 0
    obs = sim.observe(np.zeros((3, 2)))
    assert obs.shape == (3, obs_dim) and obs.dtype == np.float32
    sim.step(np.zeros((3, act_dim)))
    assert sim.xy.shape == (3, 2) and sim.flipped.shape == (3,) and sim.get_state().shape == (3, sim.state_dim)


def test_relative_goal_in_observation():
    sim = BatchedSim("point", None, 2, nthread=1)
    sim.reset(xy=np.array([[0.0, 0.0], [1.0, -1.0]]))
    obs = sim.observe(np.array([[2.0, 0.5], [1.0, 1.0]]))
    np.testing.assert_allclose(obs[:, 2:], [[2.0, 0.5], [0.0, 2.0]], atol=1e-6)


@pytest.mark.parametrize("agent", ["point", "ant"])
def test_seeded_runs_reproduce(agent):
    def run(seed):
        sim = BatchedSim(agent, None, 4, nthread=2)
        rng = np.random.default_rng(seed)
        sim.reset(xy=rng.uniform(-1, 1, (4, 2)), rng=rng)
        for _ in range(20):
            sim.step(rng.uniform(-1, 1, (4, sim.act_dim)))
        return sim.get_state()

    np.testing.assert_array_equal(run(3), run(3))
    assert not np.array_equal(run(3), run(4))


def test_walls_block_the_point():
    maze = CORRIDOR.for_agent("point")
    sim = BatchedSim("point", maze, 1, nthread=1)
    start = maze.cell_to_xy(1, 1)
    sim.reset(xy=start[None])
    for _ in range(60):  # push full force into the wall above the start cell
        sim.step(np.array([[0.0, 1.0]]))
    wall_y = start[1] + maze.cell_size / 2
    assert sim.xy[0, 1] < wall_y and sim.xy[0, 1] > wall_y - 0.2  # pressed against it, not through
    open_sim = BatchedSim("point", None, 1, nthread=1)
    open_sim.reset(xy=start[None])
    for _ in range(60):
        open_sim.step(np.array([[0.0, 1.0]]))
    assert open_sim.xy[0, 1] > wall_y + 5


def test_flipped_ant_is_detected():
    sim = BatchedSim("ant", None, 2, nthread=1)
    state = sim.get_state()
    qw = slice(4, 8)  # state = [time, x, y, z, qw, qx, qy, qz, ...]
    state[1, qw] = [0.0, 1.0, 0.0, 0.0]  # rotated 180 degrees about x: upside down
    sim.reset(states=state)
    assert sim.flipped.tolist() == [False, True]
    sim.step(np.zeros((2, 8)))
    assert sim.flipped.tolist() == [False, True]


@pytest.mark.parametrize("agent", ["point", "ant"])
def test_state_round_trip(agent):
    rng = np.random.default_rng(0)
    a = BatchedSim(agent, None, 3, nthread=1)
    a.reset(xy=rng.uniform(-2, 2, (3, 2)), rng=rng)
    for _ in range(5):
        a.step(rng.uniform(-1, 1, (3, a.act_dim)))
    b = BatchedSim(agent, None, 3, nthread=1)
    b.reset(states=a.get_state())
    acts = rng.uniform(-1, 1, (10, 3, a.act_dim))
    for u in acts:
        a.step(u)
        b.step(u)
    np.testing.assert_array_equal(a.get_state(), b.get_state())


def test_bad_input_is_one_line_error():
    with pytest.raises(SpecrefineError, match="unknown agent"):
        BatchedSim("humanoid", None, 2)
    sim = BatchedSim("point", None, 2, nthread=1)
    with pytest.raises(SpecrefineError, match=r"xy must have shape \(2, 2\)"):
        sim.reset(xy=np.zeros((3, 2)))


def test_torchrl_env_partial_reset_and_termination():
    from torchrl.envs.utils import check_env_specs

    env = GoalReachEnv("point", 4, seed=0, nthread=1)
    check_env_specs(env)
    td = env.reset()
    assert td["observation"].shape == (4, 4)
    goals_before = env.goals.copy()
    env.goals[0] = env.sim.xy[0]  # env 0 is already at its goal -> success on the next step
    td["action"] = torch.zeros(4, 2)
    out, nxt = env.step_and_maybe_reset(td)
    assert bool(out["next", "success"][0]) and bool(out["next", "terminated"][0])
    assert not out["next", "done"][1:].any()
    assert out["next", "reward"][0].item() > 0.5  # success bonus
    assert not np.allclose(env.goals[0], env.sim.xy[0])  # env 0 was reset with a new goal
    np.testing.assert_array_equal(env.goals[1:], goals_before[1:])


def test_chained_goals_continue_without_reset_until_the_last():
    from dataclasses import replace

    from specrefine.core.agents import AGENTS

    env = GoalReachEnv("point", 2, seed=0, nthread=1, task=replace(AGENTS["point"].reach_task, goals_per_episode=2))
    td = env.reset()
    td["action"] = torch.zeros(2, 2)
    env.goals[0] = env.sim.xy[0]  # goal 1 of 2 reached on the next step
    xy = env.sim.xy[0].copy()
    out, td = env.step_and_maybe_reset(td)
    assert bool(out["next", "success"][0]) and not bool(out["next", "done"][0])
    assert env.goal_index[0] == 1 and not np.allclose(env.goals[0], xy)  # a new goal, drawn from here
    np.testing.assert_allclose(env.sim.xy[0], xy, atol=1e-6)  # no reset: still where goal 1 was reached
    env.goals[0] = env.sim.xy[0]  # goal 2 of 2: now the episode ends
    td["action"] = torch.zeros(2, 2)
    out, _ = env.step_and_maybe_reset(td)
    assert bool(out["next", "terminated"][0]) and env.goal_index[0] == 0  # done, and reset for the next episode


def test_ant_spawned_at_its_footprint_radius_does_not_touch_a_wall():
    import mujoco

    from specrefine.sim.simulator import build_model, footprint_radius

    maze = parse_maze("###\n#S#\n#G#\n###", name="t").for_agent("ant")
    model = build_model("ant", maze)
    reach = footprint_radius(model)
    assert reach > 2 * 0.5  # the legs reach much further than the torso's body radius

    cell = maze.cell_box(1, 1)  # S; its left neighbour is a wall

    def wall_contacts(gap):  # torso `gap` metres right of the wall
        data = mujoco.MjData(model)
        data.qpos[:2] = [cell.xmin + gap, (cell.ymin + cell.ymax) / 2]
        mujoco.mj_forward(model, data)
        names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or "" for c in data.contact[:data.ncon]
                 for g in (c.geom1, c.geom2)]
        return sum(nm.startswith("wall_") for nm in names)

    assert wall_contacts(reach + 0.02) == 0
    assert wall_contacts(0.6) > 0


def test_tilt_cost_charges_an_ant_on_its_side():
    from dataclasses import replace

    from specrefine.core.agents import AGENTS

    rewards = {}
    for tilt in (0.0, 0.5):
        env = GoalReachEnv("ant", 2, seed=0, nthread=1, task=replace(AGENTS["ant"].reach_task, tilt_cost=tilt))
        td = env.reset()
        state = env.sim.get_state()
        state[1, 4:8] = [np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0]  # 90 degrees about x: on its side
        env.sim.reset(states=state)
        td["action"] = torch.zeros(2, 8)
        out, _ = env.step_and_maybe_reset(td)
        rewards[tilt] = out["next", "reward"].squeeze(-1).numpy()
        assert env.sim.up[0] > 0.9 and abs(env.sim.up[1]) < 0.4  # after one step of falling
    extra = rewards[0.0] - rewards[0.5]
    assert extra[1] > 0.3 and extra[0] < 0.05  # about tilt_cost x 1 on its side, next to nothing upright


def test_goal_radius_draws_each_goals_own_radius_and_success_uses_it():
    from dataclasses import replace

    from specrefine.core.agents import AGENTS

    task = replace(AGENTS["point"].reach_task, goals_per_episode=3, goal_radius=(0.5, 1.6))
    env = GoalReachEnv("point", 64, seed=0, nthread=1, task=task)
    td = env.reset()
    assert ((env.radius >= 0.5) & (env.radius <= 1.6)).all() and env.radius.std() > 0.1
    first = env.radius.copy()
    env.goals[:] = env.sim.xy + np.stack([env.radius - 0.05, np.zeros(64)], axis=1)  # just inside each radius
    td["action"] = torch.zeros(64, 2)
    out, _ = env.step_and_maybe_reset(td)
    assert out["next", "success"].all() and (env.goal_index == 1).all()  # all reached within their own radius
    assert not np.allclose(env.radius, first)  # the next goals drew radii of their own
    plain = GoalReachEnv("point", 64, seed=0, nthread=1)
    plain.reset()
    assert (plain.radius == AGENTS["point"].reach_task.success_radius).all()


def _turned(state: np.ndarray, goals: np.ndarray, angle: np.ndarray, nq: int):
    """The same Ant states and goals turned by ``angle`` about the vertical axis through the origin."""
    import mujoco

    s, g = state.copy(), goals.copy()
    c, n = np.cos(angle), np.sin(angle)
    for cols, arr in (((1, 2), s), ((1 + nq, 2 + nq), s)):  # position and linear velocity (world frame)
        x, y = arr[:, cols[0]].copy(), arr[:, cols[1]].copy()
        arr[:, cols[0]], arr[:, cols[1]] = c * x - n * y, n * x + c * y
    g[:, 0], g[:, 1] = c * goals[:, 0] - n * goals[:, 1], n * goals[:, 0] + c * goals[:, 1]
    for i, a in enumerate(angle):  # the torso's orientation; the body-frame angular velocity is unchanged
        mujoco.mju_mulQuat(s[i, 4:8], np.array([np.cos(a / 2), 0, 0, np.sin(a / 2)]), state[i, 4:8].copy())
    return s, g


def test_heading_frame_observation_does_not_depend_on_the_direction_of_travel():
    rng = np.random.default_rng(0)
    a, b = BatchedSim("ant", None, 8, nthread=1), BatchedSim("ant", None, 8, nthread=1)
    a.reset(xy=np.zeros((8, 2)), rng=rng)
    for _ in range(20):  # moving, tilted, turned: a state that is not the default pose
        a.step(rng.uniform(-1, 1, (8, 8)))
    goals = a.xy + rng.uniform(-5, 5, (8, 2))
    turned, turned_goals = _turned(a.get_state(), goals, rng.uniform(-np.pi, np.pi, 8), a.model.nq)
    b.reset(states=turned)
    assert np.abs(a.observe(goals, "world") - b.observe(turned_goals, "world")).max() > 0.1  # world: it differs
    actions = rng.uniform(-1, 1, (8, 8))
    for _ in range(10):  # the physics agrees too: the same actions keep the observations equal
        np.testing.assert_allclose(a.observe(goals, "heading"), b.observe(turned_goals, "heading"), atol=1e-4)
        a.step(actions)
        b.step(actions)


def test_heading_and_world_frames_agree_at_heading_zero_and_for_the_point():
    ant = BatchedSim("ant", None, 4, nthread=1)
    ant.reset(xy=np.zeros((4, 2)))  # default pose: heading 0
    goals = np.array([[3.0, 1.0], [-2.0, 0.5], [0.0, -4.0], [1.0, 1.0]])
    np.testing.assert_array_equal(ant.observe(goals, "heading"), ant.observe(goals, "world"))
    point = BatchedSim("point", None, 4, nthread=1)
    np.testing.assert_array_equal(point.observe(goals, "heading"), point.observe(goals, "world"))
    with pytest.raises(SpecrefineError, match="observation frame"):
        ant.observe(goals, "compass")


def test_random_maze_is_connected_seeded_and_none_of_the_benchmark():
    from specrefine.core.errors import MazeError
    from specrefine.core.mazes import benchmark_mazes, load_maze, random_maze, reachable_cells

    maze = random_maze((4, 6), seed=3)
    assert maze == random_maze((4, 6), seed=3) and maze.grid != random_maze((4, 6), seed=4).grid
    assert (maze.rows, maze.cols) == (9, 13) and maze.cells("S") == [(1, 1)] and maze.cells("G") == [(7, 11)]
    assert reachable_cells(maze, maze.cells("S")) == set(maze.free_cells())  # one corridor system
    assert all(maze.grid[r][c] == "#" for r in range(0, 9, 2) for c in range(0, 13, 2))  # pillars stay
    assert maze.grid not in {load_maze(p).grid for p in benchmark_mazes().values()}
    with pytest.raises(MazeError):
        random_maze((1, 5), seed=0)


def test_training_among_walls_walks_goals_along_the_corridors_and_ends_on_a_wall():
    from dataclasses import replace

    from specrefine.core.agents import AGENTS
    from specrefine.core.mazes import random_maze

    maze = random_maze((3, 3), seed=1)
    task = replace(AGENTS["point"].reach_task, goals_per_episode=50, wall_penalty=2.0)
    env = GoalReachEnv("point", 6, seed=0, nthread=1, task=task, maze=maze)
    td = env.reset()
    scaled = env.maze
    centres = {tuple(np.round(scaled.cell_to_xy(r, c), 6)) for r, c in scaled.free_cells()}
    for _ in range(30):  # each reached goal: the next is the centre of a free neighbouring cell
        before = env.cell.copy()
        assert {tuple(np.round(g, 6)) for g in env.goals} <= centres
        env.goals[:] = env.sim.xy  # every env reaches its goal on this step
        td["action"] = torch.zeros(6, 2)
        out, td = env.step_and_maybe_reset(td)
        moved = np.abs(env.cell - before).sum(axis=1)
        assert set(moved.tolist()) <= {1} and not out["next", "wall"].any()
    wall = scaled.cell_to_xy(0, 1)  # the outer wall above the first room
    near = wall + np.array([[0.0, -0.55], [0.0, -1.0]])  # 0.05 m below it (within the clearance), and a cell centre
    assert env.touching(near).tolist() == [True, False]
    assert not GoalReachEnv("point", 2, seed=0, nthread=1).touching(near).any()  # the open floor has no walls
    env.touching = lambda xy: np.arange(len(xy)) == 0  # env 0 touches a wall on the next step (contacts push a
    td["action"] = torch.zeros(6, 2)  # body out within a step, so the test forces the touch)
    out, _ = env.step_and_maybe_reset(td)
    assert bool(out["next", "wall"][0]) and bool(out["next", "terminated"][0]) and not bool(out["next", "flipped"][0])
    assert not bool(out["next", "success"][0]) and out["next", "reward"][0].item() < out["next", "reward"][1].item() - 1
    assert not out["next", "wall"][1:].any() and not out["next", "done"][1:].any()


def _turn_degrees(travel: np.ndarray, step: np.ndarray) -> np.ndarray:
    cos = (travel * step).sum(1) / (np.linalg.norm(travel, axis=1) * np.linalg.norm(step, axis=1))
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def test_turn_goals_turn_within_their_range_either_side_at_the_distances_asked():
    from specrefine.sim.simulator import sample_turn_goals

    rng = np.random.default_rng(0)
    xy = rng.normal(size=(2000, 2))
    travel = rng.normal(size=(2000, 2)) * rng.uniform(0.1, 5.0, size=(2000, 1))  # any direction, any speed
    goals = sample_turn_goals(xy, travel, 3.0, 5.0, (45.0, 180.0), rng)
    dist = np.linalg.norm(goals - xy, axis=1)
    assert dist.min() >= 3.0 - 1e-9 and dist.max() <= 5.0 + 1e-9
    turn = _turn_degrees(travel, goals - xy)
    assert turn.min() >= 45.0 - 1e-6 and turn.max() <= 180.0 + 1e-6
    assert turn.min() < 50 and turn.max() > 175  # the whole range is drawn
    side = np.sign(travel[:, 0] * (goals - xy)[:, 1] - travel[:, 1] * (goals - xy)[:, 0])
    assert 0.45 < (side > 0).mean() < 0.55  # left and right alike
    still = sample_turn_goals(np.zeros((500, 2)), np.zeros((500, 2)), 1.0, 1.0, (90.0, 90.0), rng)
    np.testing.assert_allclose(np.abs(still[:, 1]), 1.0, atol=1e-9)  # no travel: turns from east, to north or south


def test_turn_goals_are_the_same_for_the_same_seed():
    from specrefine.sim.simulator import sample_turn_goals

    xy, travel = np.zeros((50, 2)), np.ones((50, 2))
    draw = lambda seed: sample_turn_goals(xy, travel, 1.0, 8.0, (45.0, 180.0), np.random.default_rng(seed))  # noqa: E731
    np.testing.assert_array_equal(draw(3), draw(3))
    assert not np.allclose(draw(3), draw(4))


def test_direction_of_travel_is_the_velocity_unless_nearly_still():
    from specrefine.sim.simulator import direction_of_travel

    velocity = np.array([[1.0, 0.0], [0.05, 0.0]])
    fallback = np.array([[0.0, 1.0], [0.0, 1.0]])
    np.testing.assert_array_equal(direction_of_travel(velocity, fallback), [[1.0, 0.0], [0.0, 1.0]])


def test_chained_goals_turn_from_the_direction_of_travel_with_turn():
    from dataclasses import replace

    from specrefine.core.agents import AGENTS

    task = replace(AGENTS["point"].reach_task, goals_per_episode=3)
    env = GoalReachEnv("point", 64, seed=0, nthread=1, task=task, turn=(90.0, 180.0))
    td = env.reset()
    state = env.sim.get_state()
    state[:, 1 + env.sim.model.nq:1 + env.sim.model.nq + 2] = [0.6, 0.0]  # east, below arrive_speed
    env.sim.reset(states=state)
    env.goals[:] = env.sim.xy  # every goal 1 reached on the next step
    td["action"] = torch.zeros(64, 2)
    before = env.sim.xy.copy()
    env.step_and_maybe_reset(td)
    assert (env.goal_index == 1).all()
    turn = _turn_degrees(env.sim.qvel[:, :2], env.goals - env.sim.xy)
    assert turn.min() >= 90.0 - 1e-6 and (env.sim.xy[:, 0] > before[:, 0]).all()  # turned from where it moved
    with pytest.raises(SpecrefineError, match="open floor"):
        GoalReachEnv("point", 2, seed=0, nthread=1, maze=CORRIDOR, turn=(45.0, 180.0))


def test_sampled_training_goals_spread_over_the_cell_and_keep_off_its_walls():
    from dataclasses import replace

    from specrefine.core.agents import AGENTS
    from specrefine.core.mazes import random_maze

    task = replace(AGENTS["point"].reach_task, goals_per_episode=50)
    env = GoalReachEnv("point", 64, seed=0, nthread=1, task=task, maze=random_maze((3, 3), seed=1),
                       goal_points="sampled")
    env.reset()
    centres = env.maze.cell_to_xy(env.cell[:, 0], env.cell[:, 1]).reshape(64, 2)
    offset = np.abs(env.goals - centres)
    assert offset.max() <= env.maze.cell_size / 2 - env.clearance + 1e-9 and offset.max() > 0.1
    assert not env.touching(env.goals).any()
    for bad in ({"goal_points": "sampled"}, {"goal_points": "corner", "maze": random_maze((3, 3), seed=1)}):
        with pytest.raises(SpecrefineError, match="goal points"):
            GoalReachEnv("point", 2, seed=0, nthread=1, **bad)
