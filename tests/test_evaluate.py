"""Subtask evaluator, compositional runs and the task-graph monitor (point mass, scripted controller)."""


import numpy as np
import pytest

from specrefine.core.errors import SpecrefineError
from specrefine.core.graph import TaskGraph
from specrefine.core.mazes import load_maze
from specrefine.core.regions import Box, CompiledRegion, Disc, union
from specrefine.core.results import AVOID, SUCCESS, StartStates, wilson_ci
from specrefine.core.spec import maze_task
from specrefine.evaluation.evaluator import Evaluator, path_legs, spread_draw
from specrefine.evaluation.monitor import satisfies
from specrefine.sim.policy import PointController

# Floats computed through different batch shapes, thread counts or CPUs agree only to a tolerance
# (batched matrix products may round differently); discrete outcomes are compared exactly.
FLOAT_ATOL = 1e-4

# u_maze at point scale:   #####
#                          #G..#    G = cell (1, 1) centred at (-1, 1)
#                          ###.#
#                          #S..#    S = cell (3, 1) centred at (-1, -1)
#                          #####


@pytest.fixture(scope="module")
def maze():
    return load_maze("u_maze")


class Constant:
    """A policy that always pushes the same way."""

    def __init__(self, a):
        self.a = np.asarray(a, dtype=float)
        self.fingerprint = f"const{list(self.a)}"

    def __call__(self, obs):
        return np.tile(self.a, (len(obs), 1))


def make(maze, policy=None, n=16, horizon=60, **kw):
    return Evaluator(maze, "point", policy or PointController(), n=n, horizon=horizon, **kw)


def test_agent_placed_in_goal_counts_as_reached(maze):
    ev = make(maze, Constant([0.0, 0.0]))
    inside = Box(-1.2, 0.8, -0.8, 1.2)  # inside G
    res = ev.evaluate(inside, maze.goal, maze.walls)
    assert res.p == 1.0 and res.successes == 16
    assert np.all(res.lengths == 1) and np.all(res.outcome == SUCCESS)
    assert res.steps == 0  # nothing had to be simulated


def test_reached_goal_agrees_with_simulator_state(maze):
    ev = make(maze)
    goal = maze.cell_box(3, 3)
    res = ev.evaluate(maze.start, goal, maze.walls)
    assert res.p >= 0.8
    last = res.trajectories[np.arange(res.n), res.lengths - 1]
    assert np.all(goal.contains(last[res.success]))
    assert not np.any(goal.contains(last[~res.success]))
    # restore the recorded end states in a fresh simulator: its (x, y) lies in the goal region
    sim = ev.sim(res.successes)
    sim.reset(states=res.end_states.states)
    assert np.all(goal.contains(sim.xy))
    np.testing.assert_allclose(sim.xy, res.end_states.xy)


def test_wall_contact_ends_rollout_as_failure(maze):
    ev = make(maze, Constant([0.0, 1.0]), horizon=80)  # straight up from S into the wall below G
    res = ev.evaluate(maze.start, maze.goal, maze.walls)
    assert res.p == 0.0
    assert np.all(res.outcome == AVOID)
    assert np.all(res.lengths < 81)  # ended early, not by the horizon
    last = res.trajectories[np.arange(res.n), res.lengths - 1]
    assert np.all(maze.walls.signed_distance(last) < ev.clearance)
    before = res.trajectories[np.arange(res.n), res.lengths - 2]
    assert np.all(maze.walls.signed_distance(before) >= ev.clearance)
    # frozen after the failure: the padded tail repeats the last point
    np.testing.assert_array_equal(res.trajectories[:, -1], last)


def test_same_seed_same_numbers(maze):
    a = make(maze).evaluate(maze.start, maze.cell_box(1, 3), maze.walls, seed=7)
    b = make(maze).evaluate(maze.start, maze.cell_box(1, 3), maze.walls, seed=7)
    c = make(maze).evaluate(maze.start, maze.cell_box(1, 3), maze.walls, seed=8)
    assert not a.cached and not b.cached
    np.testing.assert_array_equal(a.trajectories, b.trajectories)
    np.testing.assert_array_equal(a.success, b.success)
    assert a.p == b.p and a.ci == b.ci
    assert not np.array_equal(a.trajectories[:, 0], c.trajectories[:, 0])


def test_start_state_propagation(maze):
    ev = make(maze)
    first = ev.evaluate(maze.start, maze.cell_box(3, 3), maze.walls)
    assert first.successes > 0 and len(first.end_states) == first.successes
    second = ev.evaluate(first.end_states, maze.cell_box(1, 3), maze.walls)
    starts = second.trajectories[:, 0].astype(float)
    # every start of the second edge is one of the first edge's end states, each used once or twice (spread_draw)
    d = np.linalg.norm(starts[:, None, :] - first.end_states.xy[None, :, :], axis=-1).min(axis=1)
    assert np.all(d < 1e-5)
    assert len(np.unique(starts.round(5), axis=0)) == len(np.unique(first.end_states.xy.round(5), axis=0))
    assert np.all(maze.cell_box(3, 3).contains(starts))
    # full physics states: the velocity at the end of edge 1 is carried into edge 2
    sim = ev.sim(first.successes)
    sim.reset(states=first.end_states.states)
    assert np.abs(sim.qvel).max() > 0.0
    # an empty start distribution (nothing reached the vertex) gives p = 0 without simulating
    steps = ev.sim_steps
    empty = StartStates(first.end_states.states[:0], first.end_states.xy[:0])
    res = ev.evaluate(empty, maze.goal, maze.walls)
    assert res.p == 0.0 and res.n == 0 and ev.sim_steps == steps


def test_evaluations_are_counted_once_however_often_the_disk_is_read(maze, tmp_path):
    # a memory cache of one: each result is read back from disk when asked again, which is no new evaluation
    from specrefine.refine.search import evaluator_counts

    cells = ((3, 3), (1, 3), (3, 3), (1, 3))
    ev = make(maze, cache_dir=tmp_path)
    ev.cache.memo_size = 1
    for cell in cells:
        ev.evaluate(maze.start, maze.cell_box(*cell), maze.walls)
    assert ev.evaluations == 2 and ev.disk_hits == 2 and ev.run_evaluations == 2
    assert evaluator_counts(ev) == {"evaluations": 2, "sim_steps": ev.sim_steps}
    again = make(maze, cache_dir=tmp_path)  # a resumed run: both read back, each counted once
    again.cache.memo_size = 1
    for cell in cells:
        again.evaluate(maze.start, maze.cell_box(*cell), maze.walls)
    assert again.evaluations == 0 and again.disk_hits == 4 and evaluator_counts(again) == evaluator_counts(ev)


def test_cache_hits_identical_and_free(maze, tmp_path):
    ev = make(maze, cache_dir=tmp_path)
    a = ev.evaluate(maze.start, maze.cell_box(3, 3), maze.walls)
    counters = (ev.evaluations, ev.sim_steps)
    b = ev.evaluate(maze.start, maze.cell_box(3, 3), maze.walls)
    assert b.cached and (ev.evaluations, ev.sim_steps) == counters
    np.testing.assert_array_equal(a.trajectories, b.trajectories)
    # a fresh evaluator finds the entry on disk
    ev2 = make(maze, cache_dir=tmp_path)
    c = ev2.evaluate(maze.start, maze.cell_box(3, 3), maze.walls)
    assert c.cached and ev2.evaluations == 0 and ev2.sim_steps == 0
    assert c.p == a.p and c.ci == a.ci
    np.testing.assert_array_equal(c.trajectories, a.trajectories)
    np.testing.assert_array_equal(c.end_states.states, a.end_states.states)
    # anything in the key changes the entry: seed, n, goal point
    d = ev2.evaluate(maze.start, maze.cell_box(3, 3), maze.walls, seed=1)
    e = ev2.evaluate(maze.start, maze.cell_box(3, 3), maze.walls, goal_point=(1.0, -1.0))
    assert not d.cached and not e.cached and ev2.evaluations == 2


def test_corrupt_cache_entry_is_ignored(maze, tmp_path, caplog):
    ev = make(maze, cache_dir=tmp_path)
    a = ev.evaluate(maze.start, maze.cell_box(3, 3), maze.walls)
    files = list(tmp_path.rglob("*.npz"))
    assert len(files) == 1
    files[0].write_bytes(b"not an npz file")
    ev2 = make(maze, cache_dir=tmp_path)
    b = ev2.evaluate(maze.start, maze.cell_box(3, 3), maze.walls)
    assert "ignoring unreadable cache entry" in caplog.text  # a log record (one line), not a Python warning
    assert not b.cached and ev2.evaluations == 1
    np.testing.assert_array_equal(a.trajectories, b.trajectories)
    assert make(maze, cache_dir=tmp_path).evaluate(maze.start, maze.cell_box(3, 3), maze.walls).cached  # rewritten


def test_a_fifo_in_a_cache_entrys_place_is_never_opened(maze, tmp_path):
    import os
    import signal

    ev = make(maze, cache_dir=tmp_path)
    a = ev.evaluate(maze.start, maze.cell_box(3, 3), maze.walls)
    entry = next(tmp_path.rglob("*.npz"))
    entry.unlink()
    os.mkfifo(entry)  # opening it to read would wait for a writer forever

    fired = []

    def hung(signum, frame):
        fired.append(signum)
        raise TimeoutError("the cache opened a FIFO")

    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(10)
    try:
        b = make(maze, cache_dir=tmp_path).evaluate(maze.start, maze.cell_box(3, 3), maze.walls)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    assert not fired  # not even a wait that a caught error ended
    assert not b.cached and b.p == a.p and entry.is_file()  # recomputed, and the entry written whole in its place


def test_maze_scale_must_match_agent(maze):
    with pytest.raises(SpecrefineError, match="for_agent"):
        Evaluator(maze, "ant", PointController())


def test_run_path_and_monitor_agree(maze):
    ev = make(maze, n=24)
    graph = maze_task(maze)
    legs = [(maze.cell_box(3, 3), maze.walls, None), (maze.cell_box(1, 3), maze.walls, None),
            (maze.goal, maze.walls, None)]
    res = ev.run_compositional(maze.start, legs, seed=3)
    assert res.n == 24 and res.legs_done.max() <= 3
    assert res.successes > 0
    ok = satisfies(graph, res.trajectories, res.lengths, ev.clearance)
    np.testing.assert_array_equal(ok, res.success)  # reaching G without touching walls = the original task
    assert len(res.leg_success) == 3
    # the direct single edge with a straight-line controller runs into the wall
    direct = ev.run_compositional(maze.start, path_legs(graph, ["S", "G"]), seed=3)
    assert direct.p < res.p


def test_wilson_ci():
    lo, hi = wilson_ci(0, 32)
    assert lo == 0.0 and hi == pytest.approx(0.1072, abs=1e-3)
    lo, hi = wilson_ci(16, 32)
    assert lo == pytest.approx(1 - hi) and lo == pytest.approx(0.336, abs=1e-3)
    assert wilson_ci(0, 0) == (0.0, 1.0)


def test_compiled_region_matches_region():
    region = union([Box(0, 0, 1, 1), Box(2, -1, 3, 0.5), Disc(-1, 2, 0.7)])
    pts = np.random.default_rng(0).uniform(-3, 4, size=(500, 2))
    np.testing.assert_allclose(CompiledRegion(region).signed_distance(pts), region.signed_distance(pts))
    np.testing.assert_array_equal(CompiledRegion(region).contains(pts), region.contains(pts))
    # the bucketed threshold test on a big wall set is exact, including points right at the threshold
    walls = load_maze("xx_maze_h").walls
    compiled = CompiledRegion(walls)
    assert len(walls.parts()) >= CompiledRegion.BUCKET_MIN_PARTS
    x0, y0, x1, y1 = walls.bounds()
    pts = np.random.default_rng(1).uniform((x0, y0), (x1, y1), size=(5000, 2))
    pts[:50, 1] = 0.5 + 0.1  # exactly 0.1 above a wall edge (rows end at half-integers)
    pts[50:100, 0] = np.round(pts[50:100, 0] * 2) / 2  # exactly on vertical cell edges
    for thr in (0.0, 0.1, 0.5):
        np.testing.assert_array_equal(compiled.below(pts, thr), walls.signed_distance(pts) < thr)
    np.testing.assert_array_equal(compiled.contains(pts), walls.contains(pts))


# --- the monitor on hand-made trajectories ---------------------------------------------------------
S, A, B, G = Box(0, 0, 1, 1), Box(4, 0, 5, 1), Box(0, 4, 1, 5), Box(4, 4, 5, 5)
X = Box(2, 2, 3, 3)  # hazard avoided on A -> G only
Y = Box(6, 6, 7, 7)  # hazard avoided everywhere


def choice_graph():
    """S -> A -> G or S -> B -> G; the edge A -> G must also avoid X."""
    tg = TaskGraph("S")
    for name, region in (("S", S), ("A", A), ("B", B), ("G", G)):
        tg.add_vertex(name, region)
    tg.add_edge("S", "A", Y)
    tg.add_edge("S", "B", Y)
    tg.add_edge("A", "G", union([X, Y]))
    tg.add_edge("B", "G", Y)
    tg.finals = {"G"}
    return tg


def poly(*pts, k=10):
    """A densely sampled polyline through the points."""
    pts = np.asarray(pts, dtype=float)
    segs = [pts[i] + (pts[i + 1] - pts[i]) * np.linspace(0, 1, k, endpoint=False)[:, None] for i in range(len(pts) - 1)]
    return np.concatenate(segs + [pts[-1:]])


def check(*trajs, lengths=None, r=0.0):
    T = max(len(t) for t in trajs)
    arr = np.stack([np.concatenate([t, np.repeat(t[-1:], T - len(t), 0)]) for t in trajs])
    lengths = np.array([len(t) for t in trajs]) if lengths is None else np.asarray(lengths)
    return satisfies(choice_graph(), arr, lengths, r).tolist()


def test_satisfies_accepts_either_branch():
    via_a = poly((0.5, 0.5), (4.5, 0.5), (4.5, 4.5))  # S -> A -> G along the right side (misses X)
    via_b = poly((0.5, 0.5), (0.5, 4.5), (4.5, 4.5))  # S -> B -> G along the left side
    assert check(via_a, via_b) == [True, True]


def test_satisfies_rejects_skipping_or_unsafe_or_wrong_start():
    direct = poly((0.5, 0.5), (3.5, 1.5), (4.5, 4.5))  # reaches G without visiting A or B
    unsafe = poly((0.5, 0.5), (4.5, 0.5), (6.5, 6.5), (4.5, 4.5))  # through Y, avoided on every edge
    wrong_start = poly((2.0, 0.5), (4.5, 0.5), (4.5, 4.5))  # does not start in I(S)
    assert check(direct, unsafe, wrong_start) == [False, False, False]


def test_satisfies_resolves_choices_nondeterministically():
    # visits A first, then crosses X (forbidden on A -> G) on the way to B, then G: the B branch holds
    a_then_x_then_b = poly((0.5, 0.5), (4.5, 0.5), (2.5, 2.5), (0.5, 4.5), (4.5, 4.5))
    # visits A, crosses X, and goes to G without B: no branch holds
    a_then_x_then_g = poly((0.5, 0.5), (4.5, 0.5), (2.5, 2.5), (4.5, 4.5))
    assert check(a_then_x_then_b, a_then_x_then_g) == [True, False]


def test_satisfies_respects_lengths_and_body_radius():
    via_a = poly((0.5, 0.5), (4.5, 0.5), (4.5, 4.5))
    assert check(via_a, lengths=[len(via_a) - 15]) == [False]  # cut before G
    near_x = poly((0.5, 0.5), (4.5, 0.5), (4.5, 3.5), (3.2, 3.2), (4.5, 4.5))  # passes 0.2 from X on A -> G
    assert check(near_x, r=0.0) == [True]
    assert check(near_x, r=0.3) == [False]


def test_compaction_of_finished_rollouts_changes_nothing_but_cost(maze):
    plain = make(maze, n=32, horizon=60)
    plain.MIN_BATCH = 32  # never compact
    compact = make(maze, n=32, horizon=60)
    # mixed lengths: most reach the nearby cell quickly, the straight line to G hits the wall early or late
    for goal in (maze.cell_box(3, 3), maze.goal):
        a = plain.evaluate(maze.start, goal, maze.walls, seed=5)
        b = compact.evaluate(maze.start, goal, maze.walls, seed=5)
        np.testing.assert_array_equal(a.outcome, b.outcome)  # compaction changes the policy's batch shape
        np.testing.assert_allclose(a.trajectories, b.trajectories, atol=FLOAT_ATOL)
        np.testing.assert_allclose(a.end_states.states, b.end_states.states, atol=FLOAT_ATOL)
    assert compact.sim_steps < plain.sim_steps


def test_ant_starts_clear_of_walls_by_its_legs_reach(maze):
    ant_maze = maze.for_agent("ant")
    ev = Evaluator(ant_maze, "ant", Constant([0.0] * 8), n=8)
    assert ev.spawn_radius > 2 * ev.clearance  # legs reach further than the torso
    walls = CompiledRegion(ant_maze.walls)
    rng = np.random.default_rng(0)
    start = maze_task(ant_maze).region("S")
    pts = ev.spawn_points(start, 200, rng)
    assert walls.signed_distance(pts).min() >= ev.spawn_radius - 1e-9
    assert walls.signed_distance(ev.sample_free(start, 200, rng)).min() < ev.spawn_radius  # goals: the torso only
    x0, y0, x1, y1 = start.bounds()
    tight = Box(x0, y0 + 1.0, x0 + 0.9, y1 - 1.0)  # a strip along the wall: no room for the legs, fall back
    tight_pts = ev.spawn_points(tight, 50, rng)
    assert len(tight_pts) == 50 and walls.signed_distance(tight_pts).min() >= ev.clearance - 1e-9


def test_point_spawns_where_its_body_fits(maze):
    ev = Evaluator(maze, "point", Constant([0.0, 0.0]), n=8)
    assert ev.spawn_radius == ev.clearance


def test_evaluate_many_equals_one_evaluate_per_subtask(maze):
    from specrefine.sim.policy import load_policy

    task, policy = maze_task(maze), load_policy("point")
    S, G, walls = task.region("S"), task.region("G"), maze.walls
    corner = Disc(1, -1, 0.4)
    alone = Evaluator(maze, "point", policy, n=32, seed=0)
    first = alone.evaluate(S, corner, walls)
    subtasks = [(S, corner, walls, None), (S, G, walls, None), (first.end_states, Disc(1, 1, 0.4), walls, None),
                (S, corner, walls, (1.0, -1.0)), (S, corner, walls, None)]
    expected = [first] + [alone.evaluate(*s) for s in subtasks[1:4]]
    together = Evaluator(maze, "point", policy, n=32, seed=0)
    got = together.evaluate_many(subtasks)
    for want, res in zip(expected, got[:4], strict=True):  # outcomes exactly; floats to a tolerance (batch shapes)
        assert res.p == want.p and np.array_equal(res.success, want.success)
        np.testing.assert_allclose(res.trajectories, want.trajectories, atol=FLOAT_ATOL)
        np.testing.assert_allclose(res.end_states.states, want.end_states.states, atol=FLOAT_ATOL)
    assert got[4].cached and got[4].p == got[0].p  # asked twice: simulated once
    assert together.evaluations == 4 and together.cache_hits == 1
    assert [r.cached for r in together.evaluate_many(subtasks)] == [True] * 5 and together.evaluations == 4


@pytest.mark.parametrize("m, n", [(5, 5), (5, 12), (7, 3), (128, 128), (127, 128), (40, 128)])
def test_spread_draw_uses_every_start_state_as_evenly_as_n_allows(m, n):
    """A chained estimate's n rollouts stay as many distinct ones as the previous leg's successes: with replacement,
    leg after leg, they would descend from ever fewer states (deterministic policy and physics)."""
    idx = spread_draw(m, n, np.random.default_rng(3))
    counts = np.bincount(idx, minlength=m)
    assert len(idx) == n and counts.sum() == n
    assert set(np.unique(counts)) <= {n // m, n // m + 1}
    assert (counts > 0).sum() == min(m, n)


def test_a_chain_of_spread_draws_keeps_its_rollouts_distinct():
    """Twenty legs that every rollout survives: drawn with replacement, 64 rollouts would descend from about
    2 * 64 / 20 first states; spread, from all 64."""
    rng = np.random.default_rng(0)
    lineage = np.arange(64)
    for _ in range(20):
        lineage = lineage[spread_draw(len(lineage), 64, rng)]
    assert len(np.unique(lineage)) == 64
    lineage = np.arange(64)
    for _ in range(20):
        lineage = lineage[rng.integers(len(lineage), size=64)]
    assert len(np.unique(lineage)) < 20
