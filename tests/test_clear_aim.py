"""``goal_points="clear"`` (beyond the paper): each leg aims at the point of its goal region nearest the region's
centre among those as clear of walls as the region allows, up to half a cell (``evaluator.clearest_point``)."""

import json

import numpy as np
import pytest

from specrefine.core.graph import TaskGraph
from specrefine.core.mazes import load_maze
from specrefine.core.regions import Box, CompiledRegion, Disc
from specrefine.core.spec import maze_task
from specrefine.evaluation.evaluator import Evaluator, clearest_point
from specrefine.proposers import EdgeQuery, split_messages
from specrefine.runs.config import RunConfig
from specrefine.runs.pipeline import refine_maze
from specrefine.sim.policy import PointController
from specrefine.vlm import messages_to_text

STEP = 4.0 / 40  # the Ant's grid step


@pytest.fixture(scope="module")
def ant_walls():
    maze = load_maze("u_chain_4").for_agent("ant")  # 4 m cells; the top corridor (row 1) spans y 2..6
    return maze, CompiledRegion(maze.obstacles)


def test_a_centre_near_a_corridor_wall_moves_across_to_the_middle_line(ant_walls):
    maze, walls = ant_walls
    point = clearest_point(Disc(-17.2, 2.8, 1.47), walls, maze.cell_size)  # 0.8 m above the wall block below
    assert point[1] == pytest.approx(4.0, abs=STEP)  # the corridor's middle line
    assert point[0] == pytest.approx(-17.2, abs=STEP)  # moved across the corridor, not along it
    assert walls.signed_distance(point[None])[0] == pytest.approx(2.0, abs=STEP)


@pytest.mark.parametrize("region", [Disc(-12.0, 0.0, 3.29), Disc(-20.0, 4.0, 1.0), Box(-21.0, 3.0, -19.0, 5.0)])
def test_a_centre_already_half_a_cell_clear_stays_however_big_the_region(ant_walls, region):
    maze, walls = ant_walls  # (-12, 0): a vertical corridor's middle, 2 m from both walls; a junction 3 m away is
    # clearer still, and is not taken: half a cell is clear enough
    assert clearest_point(region, walls, maze.cell_size) == pytest.approx(region.centre())


def test_a_region_too_small_for_half_a_cell_goes_as_far_from_the_walls_as_it_reaches(ant_walls):
    maze, walls = ant_walls
    region = Disc(18.2, 3.24, 0.5)
    point = clearest_point(region, walls, maze.cell_size)
    assert region.contains(point[None])[0]
    grid = np.stack(np.meshgrid(np.linspace(17.7, 18.7, 41), np.linspace(2.74, 3.74, 41)), -1).reshape(-1, 2)
    inside = grid[region.contains(grid)]
    assert walls.signed_distance(point[None])[0] >= walls.signed_distance(inside).max() - 1.0 / 40 - 0.01


def test_the_evaluator_aims_at_it_keys_it_as_a_fixed_point_and_tells_the_proposer():
    maze = load_maze("split_doorway").for_agent("point")
    ev = {rule: Evaluator(maze, "point", PointController(), n=16, seed=3, goal_points=rule)
          for rule in ("centre", "clear")}
    graph = maze_task(maze)
    u, v = graph.edges()[0]
    start, goal, avoid = graph.region(u), graph.region(v), graph.avoid(u, v)
    aim = ev["clear"].aim(goal)
    assert aim == pytest.approx(clearest_point(goal, CompiledRegion(maze.obstacles), maze.cell_size))
    assert ev["clear"].aim(goal, np.array([0.1, 0.2])) == pytest.approx([0.1, 0.2])  # a vertex's own point wins
    clear = ev["clear"].evaluate(start, goal, avoid)
    fixed = ev["centre"].evaluate(start, goal, avoid, goal_point=aim)
    assert clear.successes == fixed.successes and np.array_equal(clear.success, fixed.success)
    query = EdgeQuery(maze=maze, agent="point", start=start, goal=goal, avoid=avoid, success=0.25, n=8,
                      image_png=None, graph=graph, facts=ev["clear"].facts())
    assert "nearest its centre among those as far from walls as the region allows" in messages_to_text(
        split_messages(query))


def test_a_clear_run_records_the_rule_and_its_policy_aims_where_the_search_did(tmp_path):
    out = tmp_path / "run"
    result = refine_maze("u_chain_1", RunConfig(agent="point", method="ours", goal_points="clear", rollouts=8,
                                                episodes=16), out=out).data
    assert result["config"]["goal_points"] == "clear" == json.loads((out / "run.json").read_text())["goal_points"]
    graph, maze = TaskGraph.from_dict(result["graph"]), load_maze("u_chain_1").for_agent("point")
    walls = CompiledRegion(maze.obstacles)
    saved = [leg["point"] for leg in json.loads((out / "policy.json").read_text())["legs"]]
    expected = [graph.goal_point(v) if graph.goal_point(v) is not None
                else clearest_point(graph.region(v), walls, maze.cell_size) for v in result["path"][1:]]
    assert len(saved) == len(expected) and all(np.allclose(p, e) for p, e in zip(saved, expected))
