"""`specrefine official RUN_DIR`: the run's policy in the official Gymnasium-Robotics environment."""

from __future__ import annotations

import json

import numpy as np
import pytest

from specrefine.cli import main
from specrefine.core.mazes import load_maze
from specrefine.runs.official import env_id, make_env

FAST = ["--rollouts", "8", "--episodes", "8"]


@pytest.fixture(scope="module")
def point_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("official") / "run"
    assert main(["refine", "gr:U_MAZE", "--agent", "point", "--method", "dirl", "--seed", "0", "--out", str(out),
                 *FAST]) == 0
    return out


def test_official_writes_its_record_and_prints_both_rates(point_run, capsys):
    capsys.readouterr()
    assert main(["official", str(point_run), "--episodes", "6", "--seed", "1"]) == 0
    data = json.loads((point_run / "official.json").read_text())
    result = json.loads((point_run / "result.json").read_text())
    assert data["env_id"] == "PointMaze_UMaze-v3" and data["episodes"] == 6 and data["seed"] == 1
    lo, hi = data["success_ci"]
    assert 0.0 <= lo <= data["success_rate"] <= hi <= 1.0
    assert data["sim_success_rate"] == result["success_rate"] and data["sim_episodes"] == 8
    assert sum(data["outcomes"].values()) == 6
    assert data["settings"]["hold"] == 5 and data["settings"]["continuing_task"] is True
    out = capsys.readouterr().out
    assert "official PointMaze_UMaze-v3" in out and "this package's simulator" in out


def test_official_is_reproducible_by_seed(point_run):
    rates = []
    for _ in range(2):
        assert main(["official", str(point_run), "--episodes", "4", "--seed", "3"]) == 0
        rates.append(json.loads((point_run / "official.json").read_text())["outcomes"])
    assert rates[0] == rates[1]


@pytest.mark.parametrize("what,needle", [("missing", "not found"), ("no_policy", "no compositional policy"),
                                         ("garbled", "unreadable")])
def test_official_bad_run_folders_exit_2_with_one_line(tmp_path, capsys, point_run, what, needle):
    run = tmp_path / what
    if what != "missing":
        run.mkdir()
        (run / "result.json").write_text((point_run / "result.json").read_text() if what == "no_policy" else "{x")
    assert main(["official", str(run), "--episodes", "2"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and needle in err, err


def test_the_official_env_starts_in_the_start_cell_and_observes_what_the_policy_needs():
    maze = load_maze("gr:LARGE_MAZE")
    assert env_id(maze.for_agent("ant"), "ant") == "AntMaze_Large-v5"
    assert env_id(load_maze("split_doorway"), "point").startswith("PointMaze_UMaze-v3 (maze_map")
    env = make_env(maze, "ant", 10)
    obs, _ = env.reset(seed=0, options={"reset_cell": np.array([1, 1]), "goal_cell": np.array([7, 9])})
    ant = maze.for_agent("ant")
    assert tuple(ant.xy_to_cell(obs["achieved_goal"])) == (1, 1)
    assert obs["observation"].shape == (27,)  # qpos without x, y (13) + qvel (14): contact forces off
    env.close()
