"""Per-leg failure reports of a finished run's path (specrefine.experiments.failures)."""

import json

import numpy as np
import pytest

from specrefine.core.mazes import load_maze
from specrefine.core.results import OUTCOMES
from specrefine.experiments.failures import leg_table, main, open_floor, path_failures, turn_angles
from specrefine.runs.pipeline import refine_maze


def test_open_floor_frees_inner_walls_and_keeps_the_border_and_coordinates():
    maze = load_maze("u_chain_2")
    bare = open_floor(maze)
    assert bare.grid[0] == maze.grid[0] and bare.grid[-1] == maze.grid[-1]
    assert all(row[0] == "#" and row[-1] == "#" for row in bare.grid)
    inner = [row[1:-1] for row in bare.grid[1:-1]]
    assert "#" not in "".join(inner) and "#" in "".join(row[1:-1] for row in maze.grid[1:-1])
    assert bare.cells("S") == maze.cells("S") and bare.cells("G") == maze.cells("G")
    np.testing.assert_allclose(bare.cell_to_xy(1, 1), maze.cell_to_xy(1, 1))


def test_turn_angles_of_a_polyline():
    angles = turn_angles([(0, 0), (1, 0), (1, 1), (2, 2), (3, 3), (2, 2)])
    assert angles[0] is None
    np.testing.assert_allclose(angles[1:], [90.0, 45.0, 0.0, 180.0], atol=1e-9)


def test_leg_table_counts_where_and_how_episodes_end():
    class Run:  # 5 episodes over 3 legs: two succeed, one flips on leg 0, one touches a wall on leg 2, one times out
        legs_done = np.array([3, 0, 2, 3, 1])
        success = legs_done == 3
        outcome = np.array([OUTCOMES.index(o) for o in ("success", "flipped", "avoid", "success", "timeout")])

    rows = leg_table(Run, 3)
    assert [r["started"] for r in rows] == [5, 4, 3]
    assert [(r["flipped"], r["avoid"], r["timeout"]) for r in rows] == [(1, 0, 0), (0, 0, 1), (0, 1, 0)]


def test_a_finished_runs_path_is_rerun_with_and_without_inner_walls(tmp_path, capsys):
    data = refine_maze("u_chain_1", agent="point", method="ours", proposer="geometric", seed=0, rollouts=8,
                       episodes=20, out=tmp_path / "run").data
    report = path_failures(data, episodes=40, seed=5)
    assert len(report["legs"]) == len(data["path"]) - 1
    for variant in ("walls", "no_inner_walls"):
        r = report[variant]
        failed = sum(leg["flipped"] + leg["avoid"] + leg["timeout"] for leg in r["per_leg"])
        assert r["success"] + failed == 40 and sum(r["outcomes"].values()) == 40
        assert r["per_leg"][0]["started"] == 40
    out = tmp_path / "failures.json"
    assert main([str(tmp_path / "run" / "result.json"), "--episodes", "16", "--out", str(out)]) == 0
    assert json.loads(out.read_text())["episodes"] == 16 and "no_inner_walls" in capsys.readouterr().out


def test_a_result_without_a_path_is_one_line(tmp_path, capsys):
    bad = tmp_path / "result.json"
    bad.write_text(json.dumps({"maze": "u_chain_1", "agent": "point", "path": []}))
    assert main([str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "no selected path" in err


@pytest.mark.parametrize("text", ["{", "[]"])
def test_an_unreadable_result_is_one_line(tmp_path, capsys, text):
    bad = tmp_path / "result.json"
    bad.write_text(text)
    assert main([str(bad)]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_goal_points_at_the_centres_aim_every_leg_at_its_sets_centre(monkeypatch, tmp_path):
    from specrefine.core.errors import SpecrefineError
    from specrefine.core.graph import TaskGraph
    from specrefine.evaluation.evaluator import Evaluator
    from specrefine.experiments import failures

    seen = []
    real = Evaluator._rollout

    def spy(self, start, legs, n, seed):  # the legs as simulated, each with the point it aims at
        seen.append([None if p is None else tuple(np.round(p, 9)) for _, _, p in legs])
        return real(self, start, legs, n, seed)

    monkeypatch.setattr(Evaluator, "_rollout", spy)
    result = refine_maze("u_chain_1", agent="point", method="ours", proposer="geometric", seed=0, rollouts=8,
                         episodes=20, preset="paper", out=tmp_path / "run").data  # a sampled run (the paper's rule)
    seen.clear()  # the run's own measurement
    report = failures.path_failures(result, episodes=8, seed=1, goal_points="centre")
    graph = TaskGraph.from_dict(result["graph"])
    centres = [tuple(np.round(graph.region(v).centre(), 9)) for v in result["path"][1:]]
    assert report["goal_points"] == "centre" and seen and all(points == centres for points in seen)
    seen.clear()
    assert failures.path_failures(result, episodes=8, seed=1)["goal_points"] == "sampled"
    assert all(p is None or graph.goal_point(v) is not None for points in seen
               for p, v in zip(points, result["path"][1:]))
    with pytest.raises(SpecrefineError, match="goal points"):
        failures.path_failures(result, episodes=8, seed=1, goal_points="corner")


def test_the_legs_are_estimated_again_along_the_chain_once_per_seed(tmp_path, capsys):
    from specrefine.experiments.failures import leg_estimates

    data = refine_maze("u_chain_1", agent="point", method="ours", proposer="geometric", seed=0, rollouts=8,
                       episodes=20, out=tmp_path / "run").data
    report = leg_estimates(data, [3, 4, 3])
    legs = len(data["path"]) - 1
    assert report["rollouts"] == 8 and report["search"] == data["edge_probabilities"]
    assert [len(run) for run in report["fresh"]] == [legs] * 3 and report["fresh"][0] == report["fresh"][2]
    assert all(p in {k / 8 for k in range(9)} for run in report["fresh"] for p in run)  # 8 rollouts a leg
    out = tmp_path / "estimates.json"
    assert main([str(tmp_path / "run" / "result.json"), "--estimates", "3", "4", "--out", str(out)]) == 0
    assert json.loads(out.read_text())["fresh"] == report["fresh"][:2]
    text = capsys.readouterr().out.splitlines()
    assert "seed 3  seed 4" in text[1] and len(text) == 2 + legs
