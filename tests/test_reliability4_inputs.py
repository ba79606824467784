"""Issue 40 (reliability, round 4), part B: every file a command reads is checked before any work (one schema for a
run's policy.json and result.json, capped maze sizes, finite observations), and sim_steps is one number however a
run got there."""

from __future__ import annotations

import json
import os
import random
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from specrefine.cli import main as cli_main
from specrefine.core.errors import MazeError, SpecrefineError
from specrefine.core.mazes import Maze, load_maze

ROOT = Path(__file__).resolve().parent.parent


# --- item 17: sim_steps after a rerun or a resume ------------------------------------------------------------
CHAIN = ["refine", "u_chain_3", "--agent", "point", "--method", "ours", "--proposer", "imperfect:moderate", "--seed",
         "0", "--rollouts", "8", "--episodes", "20", "--quiet"]


def test_sim_steps_are_the_same_after_a_rerun_and_after_a_resume_from_part_of_the_cache(tmp_path):
    out = tmp_path / "run"
    record = lambda: json.loads((out / "result.json").read_text())  # noqa: E731
    assert cli_main([*CHAIN, "--out", str(out)]) == 0
    first = record()
    assert cli_main([*CHAIN, "--out", str(out)]) == 0  # a rerun into the finished folder: every evaluation cached
    rerun = record()
    cache = sorted((out / "cache").rglob("*.npz"))
    for entry in random.Random(40).sample(cache, len(cache) // 2):  # as a kill leaves it: part of the work kept
        entry.unlink()
    (out / "result.json").unlink()
    assert cli_main([*CHAIN, "--out", str(out)]) == 0
    resumed = record()
    assert first["sim_steps"] == first["sim_steps_simulated"]
    assert rerun["sim_steps"] == resumed["sim_steps"] == first["sim_steps"]
    assert rerun["sim_steps_simulated"] < resumed["sim_steps_simulated"] < first["sim_steps_simulated"]
    assert rerun["path"] == resumed["path"] == first["path"]
    assert rerun["evaluations"] == resumed["evaluations"] == first["evaluations"]


# --- item 13: maze sizes are capped where they are parsed ---------------------------------------------------------
def _cli(*args, timeout=60) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-m", "specrefine.cli", *map(str, args)], capture_output=True, text=True,
                          cwd=ROOT, env=env, timeout=timeout)


def _one_line_2(proc: subprocess.CompletedProcess, needle: str = "") -> str:
    err = proc.stderr.strip()
    assert proc.returncode == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, (proc.returncode, err)
    assert needle in err, err
    return err


def test_a_huge_random_maze_or_maze_file_is_refused_in_one_line_before_any_work(tmp_path):
    _one_line_2(_cli("refine", "random:3000x3000:0", "--out", tmp_path / "r"), "at most 49x49 rooms")
    big = tmp_path / "big.maze"
    big.write_text("\n".join(["S" + "." * 100, *["." * 101] * 99, "." * 100 + "G"]))
    _one_line_2(_cli("refine", big, "--out", tmp_path / "f"), "larger than 100 x 100")
    assert not (tmp_path / "r").exists() and not (tmp_path / "f").exists()


def test_a_huge_gymnasium_map_is_refused_and_the_largest_allowed_parses():
    with pytest.raises(MazeError, match="larger than 100 x 100"):
        Maze.from_gymnasium([["r"] * 300] * 300)
    with pytest.raises(MazeError, match="at most 49x49 rooms"):
        load_maze("random:50x2:0")
    edge = Maze.from_gymnasium([[1] + [0] * 98 + [1]] * 100)
    assert (edge.rows, edge.cols) == (100, 100) and edge.cells("S") == [(0, 1)]
    assert (load_maze("random:49x49:0").rows, load_maze("random:49x49:0").cols) == (99, 99)


# --- items 8 and 9: one schema for a run's policy.json and result.json, before any episode -------------------
@pytest.fixture(scope="module")
def finished_run(tmp_path_factory) -> Path:
    """A finished point run (u_maze, ours, geometric), read-only to the tests: they tamper with copies."""
    out = tmp_path_factory.mktemp("reliability4") / "run"
    assert cli_main(["refine", "u_maze", "--method", "ours", "--proposer", "geometric", "--rollouts", "8",
                     "--episodes", "8", "--quiet", "--out", str(out)]) == 0
    return out


def _grid(f):
    return lambda d: d.update(maze_grid=[f(row) for row in d["maze_grid"]])


def _leg(key, value):
    return lambda d: d["legs"][0]["goal"].update({key: value})


def _deep(_):
    return "[" * 50_000 + "]" * 50_000


POLICY_CASES = {  # name: (a change of policy.json's data, or its whole text, a word the one line must hold)
    "ragged grid": (lambda d: d["maze_grid"].__setitem__(1, "#G."), "ragged"),
    "no S": (_grid(lambda row: row.replace("S", ".")), "no start"),
    "no G": (_grid(lambda row: row.replace("G", ".")), "no goal"),
    "grid a string": (lambda d: d.update(maze_grid="#####"), "maze_grid"),
    "grid empty": (lambda d: d.update(maze_grid=[]), "maze_grid"),
    "walls drawn X": (_grid(lambda row: row.replace("#", "X")), "unknown character 'X'"),
    "horizon 1e999": (lambda d: json.dumps(d).replace('"horizon": 100', '"horizon": 1e999'), "horizon"),
    "horizon -5": (lambda d: d.update(horizon=-5), "horizon"),
    "horizon 0": (lambda d: d.update(horizon=0), "horizon"),
    "horizon 2.5": (lambda d: d.update(horizon=2.5), "horizon"),
    "50,000-deep": (_deep, "nested too deeply"),
    "cx NaN": (_leg("cx", float("nan")), "finite"),
    "r Infinity": (_leg("r", float("inf")), "finite"),
    "region [1,2]": (lambda d: d["legs"][0].update(avoid=[1, 2]), "region"),
    "no legs": (lambda d: d.update(legs=[]), "legs"),
    "Ant's cell size": (lambda d: d.update(cell_size=4.0), "cell_size"),
}
RESULT_CASES = {
    "input region [1,2]": (lambda d: d["input_graph"]["vertices"][0].update(region=[1, 2]), "region"),
    "finals nope": (lambda d: d["input_graph"].update(finals=["nope"]), "'nope'"),
    "success_ci [0.5]": (lambda d: d.update(success_ci=[0.5]), "success_ci"),
    "success_rate high": (lambda d: d.update(success_rate="high"), "success_rate"),
    "50,000-deep": (_deep, "nested too deeply"),
    "no input_graph": (lambda d: d.pop("input_graph"), "input_graph"),
    "path off the graph": (lambda d: d.update(path=["S", "nowhere"]), "nowhere"),
}


def _tampered(run: Path, tmp_path: Path, name: str, change) -> Path:
    copy = tmp_path / "run"
    copy.mkdir()
    for f in ("result.json", "policy.json", "run.json"):
        (copy / f).write_text((run / f).read_text())
    data = json.loads((copy / name).read_text())
    text = change(data)
    (copy / name).write_text(text if isinstance(text, str) else json.dumps(data))
    return copy


def _refused(main, argv, capsys, needle: str) -> str:
    capsys.readouterr()
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, (code, err[-2000:])
    assert needle in err, err
    return err


@pytest.mark.parametrize("case", POLICY_CASES)
def test_a_tampered_policy_json_is_one_line_before_any_episode(finished_run, tmp_path, capsys, case):
    change, needle = POLICY_CASES[case]
    run = _tampered(finished_run, tmp_path, "policy.json", change)
    _refused(cli_main, ["official", str(run), "--episodes", "2"], capsys, needle)
    assert not (run / "official.json").exists()


@pytest.mark.parametrize("case", RESULT_CASES)
def test_a_tampered_result_json_is_one_line_before_any_episode_in_every_reader(finished_run, tmp_path, capsys, case):
    from specrefine.experiments.failures import main as failures_main
    from specrefine.runs.calibrate import main as calibrate_main

    change, needle = RESULT_CASES[case]
    run = _tampered(finished_run, tmp_path, "result.json", change)
    _refused(cli_main, ["official", str(run), "--episodes", "2"], capsys, needle)
    assert not (run / "official.json").exists()
    if case != "no input_graph":  # official's own need: the other readers ask for what they use
        _refused(failures_main, [str(run / "result.json"), "--episodes", "2", "--out", str(tmp_path / "f.json")],
                 capsys, needle)
        _refused(calibrate_main, [str(run), "--table", str(tmp_path / "p.csv")], capsys, needle)
        assert not (tmp_path / "f.json").exists() and not (tmp_path / "p.csv").exists()


def test_every_shipped_result_passes_the_schema_and_the_fixture_too(finished_run):
    from specrefine.core.records import read_policy, read_result

    shipped = [p for p in (ROOT / "data").rglob("*.json") if p.name.endswith("result.json")]
    assert len(shipped) >= 10
    for path in [*shipped, finished_run / "result.json"]:
        assert read_result(path)["maze"]
    assert read_policy(finished_run / "policy.json")["horizon"] == 100


# --- item 16: the Python API refuses what has no meaning ------------------------------------------------------
@pytest.mark.parametrize("env_dt", [-0.01, 0, 0.0, float("nan"), float("inf"), "0.01", True])
def test_a_policy_loaded_with_a_meaningless_env_dt_is_refused(finished_run, env_dt):
    from specrefine.evaluation.compositional import CompositionalPolicy

    with pytest.raises(SpecrefineError, match="env_dt"):
        CompositionalPolicy.load(finished_run, env_dt=env_dt)
    assert CompositionalPolicy.load(finished_run, env_dt=0.01).hold == 5


@pytest.mark.parametrize("where", ["observation", "achieved_goal"])
@pytest.mark.parametrize("bad", [float("nan"), float("inf")])
def test_acting_on_a_non_finite_observation_is_refused(finished_run, where, bad):
    from specrefine.evaluation.compositional import CompositionalPolicy

    policy = CompositionalPolicy.load(finished_run)
    obs = {"observation": np.array([1.0, -1.0, 0.0, 0.0]), "achieved_goal": np.array([1.0, -1.0])}
    policy.reset(obs, seed=0)
    assert np.isfinite(policy.act(obs)).all()
    obs[where] = obs[where].copy()
    obs[where][0] = bad
    with pytest.raises(SpecrefineError, match="NaN or infinite"):
        policy.act(obs)


def test_torso_flipped_on_a_non_finite_observation_is_refused():
    from specrefine.evaluation.compositional import torso_flipped

    upright = np.zeros(27)
    upright[1] = 1.0  # the quaternion (1, 0, 0, 0)
    assert torso_flipped("ant", {"observation": upright}) is False
    upright[2] = np.nan
    with pytest.raises(SpecrefineError, match="NaN or infinite"):
        torso_flipped("ant", {"observation": upright})
