"""`specrefine official RUN_DIR`: the run's policy in the official Gymnasium-Robotics environment."""

from __future__ import annotations

import json
from pathlib import Path

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


def test_the_package_start_is_the_evaluators_spawn_point_and_writes_where_asked(point_run, tmp_path):
    from specrefine.core.graph import TaskGraph
    from specrefine.evaluation.compositional import CompositionalPolicy
    from specrefine.runs.official import _reset_as_package

    before = (point_run / "official.json").read_text() if (point_run / "official.json").exists() else None
    out = tmp_path / "package_start.json"
    assert main(["official", str(point_run), "--episodes", "4", "--start", "package", "--out", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["settings"]["start"] == "package" and data["settings"]["reset_noise"] == "official"
    assert sum(data["outcomes"].values()) == 4
    after = (point_run / "official.json").read_text() if (point_run / "official.json").exists() else None
    assert after == before  # --out: the run's own official.json is left alone

    policy = CompositionalPolicy.load(point_run)
    result = json.loads((point_run / "result.json").read_text())
    original = TaskGraph.from_dict(result["input_graph"])
    region = original.region(original.initial)
    env = make_env(policy.maze, "point", 10)
    env.reset(seed=0, options={"reset_cell": np.array(policy.maze.cells("S")[0]),
                               "goal_cell": np.array(policy.maze.cells("G")[0])})
    obs = _reset_as_package(env, policy, region, True, np.random.default_rng(5))
    expected = policy.spawn_point(region, np.random.default_rng(5))
    np.testing.assert_allclose(obs["achieved_goal"], expected)  # the point mass has no reset noise to add
    np.testing.assert_allclose(obs["observation"][:2], expected)
    env.close()


def test_the_package_reset_noise_perturbs_the_ants_pose_and_not_its_position():
    from specrefine.runs.official import _reset_as_package

    class AntStandIn:  # _reset_as_package reads the agent's name only when no start region is asked for
        agent = "ant"

    env = make_env(load_maze("gr:U_MAZE").for_agent("ant"), "ant", 10)
    obs, _ = env.reset(seed=0, options={"reset_cell": np.array([1, 1]), "goal_cell": np.array([3, 1])})
    data = env.unwrapped.ant_env.data
    qpos, qvel = data.qpos.copy(), data.qvel.copy()
    noisy = _reset_as_package(env, AntStandIn(), None, True, np.random.default_rng(0))
    np.testing.assert_allclose(noisy["achieved_goal"], obs["achieved_goal"])
    shift = data.qpos[2:] - qpos[2:]
    assert np.all(np.abs(shift) <= 0.1) and np.count_nonzero(shift) == len(shift)
    assert np.count_nonzero(data.qvel - qvel) == len(qvel)
    np.testing.assert_allclose(noisy["observation"], np.concatenate([data.qpos[2:], data.qvel]))
    env.close()


def test_an_unknown_reset_rule_is_one_line_and_exit_2(point_run, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["official", str(point_run), "--start", "mine"])
    assert exit_.value.code == 2 and len(capsys.readouterr().err.strip().splitlines()) == 1
    from specrefine.core.errors import SpecrefineError
    from specrefine.runs.official import run_official

    with pytest.raises(SpecrefineError, match="reset_noise 'x'"):
        run_official(point_run, 1, reset_noise="x")


def test_an_interrupted_official_run_keeps_its_finished_episodes_beside_the_record(point_run, tmp_path, monkeypatch,
                                                                                    capsys):
    import specrefine.runs.official as official

    out = tmp_path / "official.json"
    real, calls = official._episode, []

    def stop_at_the_third(*args):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*args)

    monkeypatch.setattr(official, "_episode", stop_at_the_third)
    assert main(["official", str(point_run), "--episodes", "5", "--out", str(out)]) == 130
    partial = json.loads((tmp_path / "official.partial.json").read_text())
    assert partial["interrupted"] is True and partial["episodes"] == 2 and partial["episodes_asked"] == 5
    assert sum(partial["outcomes"].values()) == 2 and not out.exists()
    assert "official.partial.json" in capsys.readouterr().err
    monkeypatch.setattr(official, "_episode", real)
    assert main(["official", str(point_run), "--episodes", "2", "--out", str(out)]) == 0
    assert out.exists() and not (tmp_path / "official.partial.json").exists()  # a complete run supersedes it


def test_an_out_file_in_a_missing_folder_is_refused_before_any_episode(point_run, tmp_path, capsys):
    assert main(["official", str(point_run), "--out", str(tmp_path / "nowhere" / "x.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "does not exist" in err


@pytest.mark.parametrize("agent", ["point", "ant"])
def test_making_the_official_env_leaves_no_model_file_behind(agent):
    env = make_env(load_maze("gr:U_MAZE").for_agent(agent), agent, 10)
    model_file = Path(env.unwrapped.tmp_xml_file_path)
    env.reset(seed=0)  # the environment still works without it
    env.close()
    assert model_file.name.endswith(".xml") and not model_file.exists()
