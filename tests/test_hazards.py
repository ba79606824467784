"""Hazard cells ``~``: free floor the body can cross, avoided by every subtask (parsing, the checker, the
avoid sets, the monitor, the simulator, the offline proposers, the prompt text and the pictures)."""

from __future__ import annotations

import io
import re

import numpy as np
import pytest
from matplotlib.image import imread

from specrefine import cli
from specrefine.core.errors import MazeError
from specrefine.core.mazes import load_maze, parse_maze
from specrefine.core.regions import is_subset
from specrefine.core.results import AVOID
from specrefine.core.spec import maze_task
from specrefine.evaluation.evaluator import Evaluator
from specrefine.evaluation.monitor import satisfies
from specrefine.pictures.render import render_task, to_png
from specrefine.proposers import EdgeQuery, environment_text, make_proposer, segment_clear
from specrefine.sim.policy import PointController

# hazard_pool at point scale: a 4 x 3 pool of '~' (x in [-1.5, 1.5], y in [-2, 2]) between S (x ~ -4) and G (x ~ 4)


@pytest.fixture(scope="module")
def pool():
    return load_maze("hazard_pool")


def test_hazard_cells_parse_as_free_but_not_passable(pool):
    cells = pool.cells("~")
    assert len(cells) == 12
    assert set(cells) <= set(pool.free_cells())  # free floor: the body can be there
    assert not any(pool.passable(*c) for c in cells) and set(pool.passable_cells()) == set(pool.free_cells()) - set(
        cells)
    centres = pool.cell_to_xy(*np.array(cells).T)
    assert pool.hazards.contains(centres).all() and not pool.walls.contains(centres).any()
    assert pool.obstacles.contains(centres).all()
    assert is_subset(pool.walls, pool.obstacles) and is_subset(pool.hazards, pool.obstacles)
    assert pool.hazards.area == pytest.approx(12.0)
    plain = load_maze("u_maze")
    assert plain.hazards is None and plain.obstacles is plain.walls  # nothing changes without hazards


@pytest.mark.parametrize("text,where,words", [
    ("#####\n#S~G#\n#####\n", "2:4", "goal cell 'G' is not reachable from the start through free cells (only "
                                     "through hazard cells '~'"),
    ("#######\n#S.~a.#\n#.G####\n#######\n", "2:5", "subgoal 'a' is not reachable from the start through free "
                                                  "cells (only through hazard"),
    ("#######\n#S~.G.#\n#.~...#\n#######\n", "2:5", "only through hazard cells"),
])
def test_goal_reachable_only_through_hazards_is_rejected(text, where, words, tmp_path, capsys):
    with pytest.raises(MazeError, match=re.escape(f"wet.maze:{where}: ") + ".*" + re.escape(words)):
        parse_maze(text, "wet.maze")
    path = tmp_path / "wet.maze"
    path.write_text(text)
    code = cli.main(["refine", str(path), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and f"{path}:{where}:" in err


def test_hazard_beside_a_dry_route_is_accepted():
    m = parse_maze("#######\n#S~~~G#\n#.....#\n#######\n", "dry.maze")
    assert m.hazards is not None and m.cells("G") == [(1, 5)]


def test_every_edge_avoids_walls_and_hazards(pool):
    for spec in (None, "G"):
        g = maze_task(pool, spec)
        for u, v in g.edges():
            assert is_subset(pool.hazards, g.avoid(u, v)) and is_subset(pool.walls, g.avoid(u, v))
    d = load_maze("two_doors")
    assert all(maze_task(d).avoid(u, v) == d.walls for u, v in maze_task(d).edges())


def test_the_simulator_builds_no_walls_for_hazards(pool):
    from specrefine.sim.simulator import build_model

    dry = parse_maze("\n".join(pool.grid).replace("~", "."), "dry.maze")
    assert build_model("point", pool).ngeom == build_model("point", dry).ngeom
    # the body physically crosses the pool: with only the walls to avoid, the straight line reaches G
    ev = Evaluator(pool, "point", PointController(), n=8, horizon=120)
    crossing = ev.evaluate(pool.start, pool.goal, pool.walls, seed=0)
    assert crossing.p == 1.0
    xy = crossing.trajectories.reshape(-1, 2)
    assert pool.hazards.contains(xy).any()  # ... right through the hazards
    # the task avoids the hazards: the same rollouts fail by touching one, and the monitor agrees
    g = maze_task(pool)
    res = ev.evaluate_edge(g, "S", "G", seed=0)
    assert res.p == 0.0 and np.all(res.outcome == AVOID)
    last = res.trajectories[np.arange(res.n), res.lengths - 1]
    assert np.all(pool.hazards.signed_distance(last) < ev.clearance)
    assert np.all(pool.walls.signed_distance(last) > ev.clearance)  # not a wall: the hazard ended it
    assert not satisfies(g, crossing.trajectories, crossing.lengths, ev.clearance).any()


def test_monitor_counts_a_hazard_touch_as_failure(pool):
    g = maze_task(pool)
    s, gl = np.array(pool.start.centre()), np.array(pool.goal.centre())
    around = np.array([s, [-3.0, 2.5], [3.0, 2.5], gl])  # above the pool, in the free row
    graze = np.array([s, [-3.0, 2.5], [0.0, 2.05], [3.0, 2.5], gl])  # 0.05 m above the pool's top edge
    through = np.array([s, gl])

    def dense(p, k=40):
        return np.concatenate([p[i] + (p[i + 1] - p[i]) * np.linspace(0, 1, k, endpoint=False)[:, None]
                               for i in range(len(p) - 1)] + [p[-1:]])

    trajs = [dense(t) for t in (around, graze, through)]
    T = max(len(t) for t in trajs)
    arr = np.stack([np.concatenate([t, np.repeat(t[-1:], T - len(t), 0)]) for t in trajs])
    lengths = np.array([len(t) for t in trajs])
    assert satisfies(g, arr, lengths, clearance=0.0).tolist() == [True, True, False]
    assert satisfies(g, arr, lengths, clearance=0.1).tolist() == [True, False, False]  # the body touches it


def test_geometric_route_goes_around_the_pool(pool):
    q = EdgeQuery(pool, "point", pool.start, pool.goal, pool.obstacles, 0.0, 32, None)
    for seed in range(3):
        for cand in make_proposer("geometric", seed=seed).propose_split(q, 3):
            pts = [pool.start.centre(), *[r.centre() for r in cand], pool.goal.centre()]
            assert all(segment_clear(pool, a, b, 0.0) for a, b in zip(pts, pts[1:])), pts
            assert not any(pool.hazards.contains(r.centre()) for r in cand)
    for cand in make_proposer("random", seed=0).propose_split(q, 3):
        assert not any(pool.obstacles.contains(r.centre()) for r in cand)


def test_geometric_refinement_beats_the_straight_line(pool):
    from specrefine.runs.pipeline import refine_maze

    ev = Evaluator(pool, "point", PointController(), n=8, horizon=120)
    # the evaluator aims at sampled goal points (the paper's rule): so do the runs
    dirl = refine_maze("hazard_pool", method="dirl", evaluator=ev, episodes=16, preset="paper", out=_tmp("dirl"))
    ours = refine_maze("hazard_pool", method="ours", evaluator=ev, episodes=16, preset="paper", out=_tmp("ours"))
    assert dirl.data["success_rate"] == 0.0 and ours.data["success_rate"] >= 0.75
    assert ours.data["refines_input"] is True
    # where the episodes ended: the straight line runs into the pool (the avoid set) on its only leg
    assert dirl.data["episode_outcomes"] == {"avoid": 16} and dirl.data["leg_success"] == [0.0]
    outcomes, legs = ours.data["episode_outcomes"], ours.data["leg_success"]
    assert sum(outcomes.values()) == 16 and outcomes.get("success", 0) / 16 == ours.data["path_success_rate"]
    assert len(legs) == ours.data["path_edges"] and all(p is None or 0.0 <= p <= 1.0 for p in legs)


def _tmp(name):
    import tempfile
    from pathlib import Path

    return Path(tempfile.mkdtemp(prefix=f"hazard_{name}_"))


def test_prompt_text_mentions_hazards_only_when_present(pool):
    text = environment_text(pool, "point")
    assert "Hazards" in text and "'~'" in text and "avoid set" in text
    assert "'~' hazard" in pool.describe() and "~~~" in pool.describe()
    plain = environment_text(load_maze("u_maze"), "point")
    assert "hazard" not in plain.lower() and "The maze walls are the avoid set of every subtask." in plain


def test_picture_draws_hazards_in_purple(pool):
    img = imread(io.BytesIO(to_png(render_task(pool, maze_task(pool), size_px=512))), format="png")[..., :3]
    purple = (img[..., 0] > 0.45) & (img[..., 2] > 0.5) & (img[..., 1] < 0.45)
    assert purple.sum() > 2000  # the pool (and its legend swatch)
    plain = imread(io.BytesIO(to_png(render_task(load_maze("or_maze"), size_px=512))), format="png")[..., :3]
    assert ((plain[..., 0] > 0.45) & (plain[..., 2] > 0.5) & (plain[..., 1] < 0.45)).sum() == 0
