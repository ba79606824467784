"""Batches run as two halves side by side (rollouts.run_in_lanes) give what one batch gives, bit for bit, and count
their steps as one batch counts them (rollouts.batch_steps)."""

import numpy as np
import pytest

from specrefine.core.mazes import load_maze
from specrefine.core.spec import maze_task
from specrefine.evaluation.evaluator import Evaluator
from specrefine.evaluation.rollouts import batch_steps, rows_stepped
from specrefine.sim.policy import load_policy


def _subtasks(maze):
    task = maze_task(maze)
    S, G, walls = task.region("S"), task.region("G"), maze.walls
    near, corner = maze.cell_box(3, 2), maze.cell_box(3, 3)
    return [(S, near, walls, None), (S, G, walls, None), (S, corner, walls, None)], \
        [(corner, walls, None), (maze.cell_box(1, 3), walls, None), (G, walls, None)]


def _both(agent, n, horizon, run):
    """``run(evaluator)`` on one batch (one MuJoCo thread: no lanes) and in two lanes."""
    maze = load_maze("u_maze").for_agent(agent)
    policy = load_policy(agent)
    one = Evaluator(maze, agent, policy, n=n, horizon=horizon, seed=0, nthread=1)
    two = Evaluator(maze, agent, policy, n=n, horizon=horizon, seed=0, nthread=2)
    assert not one.lanes and two.lanes
    return maze, (one, run(one, maze)), (two, run(two, maze))


def _same(a, b):
    for key in ("success", "outcome", "lengths", "trajectories"):
        np.testing.assert_array_equal(getattr(a, key), getattr(b, key), err_msg=key)
    np.testing.assert_array_equal(a.end_states.states, b.end_states.states)
    assert a.steps == b.steps


@pytest.mark.parametrize("agent,n,horizon", [("point", 40, 60), ("ant", 32, 120)])
def test_two_lanes_give_what_one_batch_gives(agent, n, horizon):
    def run(ev, maze):
        subtasks, legs = _subtasks(maze)
        return ev.evaluate_many(subtasks) + [ev.run_compositional(subtasks[0][0], legs, seed=4)]

    maze, (one, a), (two, b) = _both(agent, n, horizon, run)
    for x, y in zip(a[:-1], b[:-1], strict=True):
        _same(x, y)
    for key in ("legs_done", "outcome", "lengths", "trajectories"):
        np.testing.assert_array_equal(getattr(a[-1], key), getattr(b[-1], key), err_msg=key)
    assert one.sim_steps == two.sim_steps
    assert len({int(r.successes) for r in a[:-1]}) > 1 and len(set(a[0].lengths)) > 3  # mixed: the halves shrink
    assert {s.n for s in two.built_sims} > {8, 16}  # the lanes' own sims, shrinking


def test_batch_steps_count_what_one_batch_steps():
    maze = load_maze("u_maze")
    ev = Evaluator(maze, "point", load_policy("point"), n=40, horizon=60, seed=0, nthread=1)
    subtasks, _ = _subtasks(maze)
    results = ev.evaluate_many(subtasks)
    lengths = np.concatenate([r.lengths for r in results])
    task_of = np.repeat(np.arange(3), 40)
    steps, padding = batch_steps(lengths, task_of, 3, Evaluator.MIN_BATCH)
    assert list(steps) == [r.steps for r in results] and padding > 0  # rows beside the shrunk batch
    assert int(steps.sum()) + padding == ev.sim_steps == rows_stepped(lengths, Evaluator.MIN_BATCH)
    alone = Evaluator(maze, "point", load_policy("point"), n=13, horizon=60, seed=0, nthread=1)
    res = alone.evaluate(*subtasks[0][:3])
    steps, padding = batch_steps(res.lengths, np.zeros(13, dtype=int), 1, Evaluator.MIN_BATCH)
    assert padding > 0 and int(steps[0]) + padding == res.steps == alone.sim_steps  # the task carries its padding
