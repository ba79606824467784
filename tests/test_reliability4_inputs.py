"""Issue 40 (reliability, round 4), part B: every file a command reads is checked before any work (one schema for a
run's policy.json and result.json, capped maze sizes, finite observations), and sim_steps is one number however a
run got there."""

from __future__ import annotations

import json
import os
import random
import signal
import stat
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
    counts = lambda: [(step["event"], step["evaluations_so_far"], step["sim_steps_so_far"])  # noqa: E731
                      for step in map(json.loads, (out / "steps.jsonl").read_text().splitlines())]
    assert cli_main([*CHAIN, "--out", str(out)]) == 0
    first, first_counts = record(), counts()
    assert cli_main([*CHAIN, "--out", str(out)]) == 0  # a rerun into the finished folder: every evaluation cached
    rerun, rerun_counts = record(), counts()
    cache = sorted((out / "cache").rglob("*.npz"))
    for entry in random.Random(40).sample(cache, len(cache) // 2):  # as a kill leaves it: part of the work kept
        entry.unlink()
    (out / "result.json").unlink()
    assert cli_main([*CHAIN, "--out", str(out)]) == 0
    resumed = record()
    assert rerun_counts == counts() == first_counts  # the step log counts each phase's work as a run in one go does
    assert first_counts[-1][1] == first["evaluations"] and first_counts[-1][2] <= first["sim_steps"]
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


# --- the property: every file a command reads, in every form, is exit 0 or one line with exit 2 ---------------
KINDS = ("random bytes", "symlink", "fifo", "folder", "device")
TINY_RUN = ["--method", "dirl", "--rollouts", "2", "--episodes", "2", "--quiet"]
SWEEP = ["sweep", "--mazes", "u_maze", "--methods", "dirl", "--seeds", "0", "--rollouts", "2", "--episodes", "2",
         "--workers", "1"]


def _positions(run: Path) -> dict:
    """name -> (where the file goes, its valid bytes, argv(base) with base the case's folder, the folder --out is).
    A case's files live under base/: in/ (inputs), out/ (the output folder or file's folder), outside/ (link
    targets), cwd/ (the working directory)."""
    policy = (ROOT / "data" / "policies" / "point.pt").read_bytes()
    result, record, run_policy = ((run / f).read_bytes() for f in ("result.json", "run.json", "policy.json"))
    maze = (ROOT / "data" / "mazes" / "u_maze.maze").read_bytes()
    refine = lambda b, *more: ["refine", "u_maze", *TINY_RUN, *more, "--out", str(b / "out")]  # noqa: E731
    official = lambda b, *more: ["official", str(b / "out"), "--episodes", "1", *more]  # noqa: E731
    failures = lambda b: ["failures", str(b / "out" / "result.json"), "--episodes", "1",  # noqa: E731
                          "--out", str(b / "out" / "f.json")]
    return {
        "refine MAZE_FILE": ("in/m.maze", maze, lambda b: ["refine", str(b / "in" / "m.maze"), *TINY_RUN, "--out",
                                                             str(b / "out")]),
        "refine --policy": ("in/p.pt", policy, lambda b: refine(b, "--policy", str(b / "in" / "p.pt"))),
        "refine replay recording": ("in/rec.jsonl", b"", lambda b: [
            "refine", "u_maze", "--method", "ours", "--proposer", f"replay:{b / 'in' / 'rec.jsonl'}", "--rollouts",
            "2", "--episodes", "2", "--quiet", "--out", str(b / "out")]),
        "refine OUT/run.json": ("out/run.json", None, refine),
        "official RUN/result.json": ("out/result.json", result, official),
        "official RUN/policy.json": ("out/policy.json", run_policy, official),
        "official --out FILE": ("out/o/official.json", b"{}",
                                lambda b: official(b, "--out", str(b / "out" / "o" / "official.json"))),
        "failures RESULT": ("out/result.json", result, failures),
        "failures RUN/run.json": ("out/run.json", record, failures),
        "sweep OUT/sweep.json": ("out/sweep.json", None, lambda b: [*SWEEP, "--out", str(b / "out")]),
        "sweep OUT/results.csv": ("out/results.csv", None, lambda b: [*SWEEP, "--out", str(b / "out")]),
    }


def _plant(path: Path, kind: str, valid: bytes | None, outside: Path, rng: random.Random) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    if kind == "random bytes":
        path.write_bytes(rng.randbytes(rng.randint(0, 400)))
    elif kind == "symlink":  # to a file outside --out: read through, never written through
        target = outside / f"{path.name}.target"
        target.write_bytes(valid if valid is not None else rng.randbytes(64))
        path.symlink_to(target)
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "folder":
        path.mkdir()
    else:
        try:  # a character device like /dev/null (as root); else a link to /dev/null
            os.mknod(path, stat.S_IFCHR | 0o666, os.makedev(1, 3))
        except PermissionError:
            path.symlink_to(os.devnull)


def _state(base: Path, out: Path) -> dict:
    """Every file under base but outside out: what it is and what it holds."""
    seen = {}
    for path in sorted(base.rglob("*")):
        if path == out or out in path.parents:
            continue
        info = path.lstat()
        held = path.read_bytes() if stat.S_ISREG(info.st_mode) else os.readlink(path) if path.is_symlink() else None
        seen[str(path)] = (stat.S_IFMT(info.st_mode), held)
    return seen


class _Hang(Exception):
    pass


def _run_main(argv) -> tuple[int, str]:
    """specrefine's main in this process, stopped after 90 s (a hang fails the case, it never stalls the suite)."""
    from specrefine.cli import main

    def stop(*_):
        raise _Hang(f"no answer after 90 s: {argv}")
    previous = signal.signal(signal.SIGALRM, stop)
    signal.alarm(90)
    try:
        return main(argv), ""
    except SystemExit as exc:
        return exc.code, ""
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


POSITIONS = ("refine MAZE_FILE", "refine --policy", "refine replay recording", "refine OUT/run.json",
             "official RUN/result.json", "official RUN/policy.json", "official --out FILE", "failures RESULT",
             "failures RUN/run.json", "sweep OUT/sweep.json", "sweep OUT/results.csv")


@pytest.mark.parametrize("position,kind", [(p, k) for p in POSITIONS for k in KINDS])
def test_every_input_in_every_form_is_exit_0_or_one_line_and_nothing_outside_out_changes(
        finished_run, tmp_path, monkeypatch, capsys, position, kind):
    where, valid, argv_of = _positions(finished_run)[position]
    base = tmp_path / "case"
    out = base / "out"
    if position.startswith(("official", "failures")):
        out.mkdir(parents=True)
        for name in ("result.json", "run.json", "policy.json"):
            (out / name).write_bytes((finished_run / name).read_bytes())
    (base / "outside").mkdir(parents=True)
    (base / "cwd").mkdir()
    monkeypatch.chdir(base / "cwd")
    rng = random.Random(f"{position}/{kind}")
    target = base / where
    if target.exists() or target.is_symlink():
        target.unlink()
    _plant(target, kind, valid if valid is not None else (finished_run / "run.json").read_bytes()
           if where.endswith("run.json") else None, base / "outside", rng)
    before, planted = _state(base, out), stat.S_IFMT(target.lstat().st_mode)
    capsys.readouterr()
    code, _ = _run_main(argv_of(base))
    err = capsys.readouterr().err.strip()
    assert code in (0, 2), (code, err[-3000:])
    assert "Traceback" not in err, err[-3000:]
    if code == 2:
        assert len(err.splitlines()) == 1, err[-3000:]
    assert _state(base, out) == before
    if position.endswith("--out FILE") and kind in ("fifo", "folder", "device"):  # only a file may be an output
        assert code == 2 and stat.S_IFMT(target.lstat().st_mode) == planted


def test_a_policy_with_no_whole_horizon_or_acting_with_nan_is_refused():
    from specrefine.core.errors import PolicyError
    from specrefine.evaluation.compositional import CompositionalPolicy, Leg

    maze = load_maze("u_maze")
    legs = [Leg("G", maze.goal, maze.obstacles, None)]
    nan_policy = lambda obs: np.full((len(obs), 2), np.nan)  # noqa: E731 - corrupt weights, say
    for horizon in (0, -5, 2.5, float("inf"), True):
        with pytest.raises(SpecrefineError, match="horizon"):
            CompositionalPolicy("point", maze, legs, nan_policy, horizon)
    policy = CompositionalPolicy("point", maze, legs, nan_policy, 3)
    obs = {"observation": np.array([1.0, -1.0, 0.0, 0.0]), "achieved_goal": np.array([1.0, -1.0])}
    policy.reset(obs, seed=0)
    with pytest.raises(PolicyError, match="NaN"):
        policy.act(obs)
