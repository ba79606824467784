"""Issue 29 (reliability, round 3): no code from a checkpoint, no half-written file, one lock, and every command's
bad input in one line (exit 2) before any long work."""

from __future__ import annotations

import json
import os
import pickle
import subprocess
import sys
import time
from pathlib import Path

import pytest

from specrefine.cli import main as cli_main
from specrefine.core.errors import RunFolderError
from specrefine.core.runfolder import claim
from specrefine.experiments.comparison import main as comparison_main
from specrefine.experiments.failures import main as failures_main
from specrefine.runs import sweep

ROOT = Path(__file__).resolve().parent.parent
TINY = ["--rollouts", "2", "--episodes", "2"]
SWEEP = ["--methods", "dirl", "--seeds", "0", "--rollouts", "2", "--episodes", "2", "--workers", "1"]
ROOM = "; the user's own maze\n#######\n#S.a.G#\n#######\n"


def run_module(module: str, *args, cwd=None, env=None, timeout=120) -> subprocess.CompletedProcess:
    """``python -m MODULE ARGS`` with this checkout on the path (stdout, stderr as text)."""
    full_env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
                **(env or {})}
    return subprocess.run([sys.executable, "-m", module, *map(str, args)], capture_output=True, text=True,
                          cwd=cwd or ROOT, env=full_env, timeout=timeout)


def assert_one_line_2(proc: subprocess.CompletedProcess, needle: str = "") -> str:
    err = proc.stderr.strip()
    assert proc.returncode == 2, (proc.returncode, err[-2000:])
    assert len(err.splitlines()) == 1 and "Traceback" not in err and needle in err, err[-2000:]
    return err


def one_line_2(main, argv, capsys) -> str:
    """The one line on stderr of ``main(argv)`` (in-process), which must exit 2."""
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse
        code = exc.code
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, (code, err[-2000:])
    return err


# --- security: a checkpoint never runs code -------------------------------------------------------------
class _MakesAFile:
    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):  # what an attacker's checkpoint does on unpickling: here, create a file
        return (open, (self.path, "w"))


TRAIN_TINY = ["--agent", "point", "--frames", "64", "--num-envs", "2", "--steps-per-env", "4", "--no-progress"]


@pytest.mark.parametrize("how", ["--init", "--resume"])
def test_a_malicious_checkpoint_runs_no_code_and_is_one_line(tmp_path, how):
    marker = tmp_path / "pwned"
    evil = tmp_path / "out" / "checkpoint.pt"
    evil.parent.mkdir()
    evil.write_bytes(pickle.dumps({"loss": _MakesAFile(marker)}))
    extra = ["--init", evil] if how == "--init" else ["--resume"]
    proc = run_module("specrefine.sim.train", *TRAIN_TINY, "--out", tmp_path / "out", *extra)
    assert not marker.exists()  # the pickle's code never ran
    assert_one_line_2(proc, f"{how} {evil}")


def test_resume_from_a_foreign_checkpoint_is_one_line(tmp_path):
    import torch

    torch.save({"weights": torch.zeros(3)}, tmp_path / "checkpoint.pt")  # safe to load, but not ours
    proc = run_module("specrefine.sim.train", *TRAIN_TINY, "--out", tmp_path, "--resume")
    assert "KeyError" not in assert_one_line_2(proc, "not a trainer checkpoint")


# --- the run folder's lock holds under a race -------------------------------------------------------------
RACERS = 4


def _race(out, barrier, tried, held, outcomes):
    """Released together with the other racers: try to claim ``out``; a holder keeps the lock until every racer
    has tried, so that a second holder could not hide behind the first one's release."""
    barrier.wait()
    try:
        with claim(out, {"race": 1}):
            with held.get_lock():
                held.value += 1
            with tried.get_lock():
                tried.value += 1
            deadline = time.time() + 20
            while tried.value < RACERS and time.time() < deadline:
                time.sleep(0.005)
        outcomes.put("held")
    except RunFolderError:
        with tried.get_lock():
            tried.value += 1
        outcomes.put("refused")


@pytest.mark.parametrize("stale", [False, True], ids=["fresh", "stale-lock"])
def test_the_run_folder_lock_has_one_holder_under_a_barrier_race(tmp_path, stale):
    import multiprocessing

    ctx = multiprocessing.get_context("fork")
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    for attempt in range(20):
        out = tmp_path / f"run{attempt}"
        out.mkdir()
        if stale:  # left by a killed run: its pid is gone
            (out / ".lock").write_text(f"{dead.pid}\n")
        barrier, tried, held, outcomes = ctx.Barrier(RACERS), ctx.Value("i", 0), ctx.Value("i", 0), ctx.Queue()
        procs = [ctx.Process(target=_race, args=(out, barrier, tried, held, outcomes)) for _ in range(RACERS)]
        for proc in procs:
            proc.start()
        for proc in procs:
            proc.join(60)
        results = sorted(outcomes.get(timeout=5) for _ in procs)
        assert held.value == 1 and results == ["held"] + ["refused"] * (RACERS - 1), (attempt, results)
        assert not (out / ".lock").exists()


# --- lost or wrong data ---------------------------------------------------------------------------------
def refine_args(out, *args, maze="u_maze"):
    return ["refine", maze, "--method", "dirl", "--out", str(out), *TINY, *args]


def test_a_rerun_stopped_midway_keeps_the_finished_runs_record(tmp_path, monkeypatch):
    import specrefine.runs.pipeline as pipeline

    assert cli_main(refine_args(tmp_path, maze="u_chain_1")) == 0
    before = {name: (tmp_path / name).read_bytes() for name in ("steps.jsonl", "result.json", "run.json")}
    real = pipeline.run_search

    def stopped(config, graph, evaluator, proposer, maze, on_step=None):  # logs a step, then is stopped (a kill)
        on_step({"step": 0, "event": "expand"})
        raise KeyboardInterrupt

    monkeypatch.setattr(pipeline, "run_search", stopped)
    assert cli_main(refine_args(tmp_path, maze="u_chain_1")) == 130
    monkeypatch.setattr(pipeline, "run_search", real)
    assert {name: (tmp_path / name).read_bytes() for name in before} == before
    assert not [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")]  # no temporary file left behind


def test_a_malformed_row_in_a_sweep_table_is_named_and_nothing_is_run(tmp_path, capsys):
    out = tmp_path / "s"
    assert sweep.main(["--mazes", "u_maze", "--out", str(out), *SWEEP, "--seeds", "0", "1"]) == 0
    table = out / "results.csv"
    lines = table.read_text().splitlines(keepends=True)
    lines.insert(1, lines[1].replace(",ok,", ',"ok,', 1))  # an unterminated quote before the finished rows
    table.write_text("".join(lines))
    broken = table.read_bytes()
    capsys.readouterr()
    err = one_line_2(sweep.main, ["--mazes", "u_maze", "--out", str(out), *SWEEP, "--seeds", "0", "1"], capsys)
    assert f"{table}:2: a malformed row" in err
    assert table.read_bytes() == broken  # nothing appended, dropped or rerun


@pytest.mark.parametrize("command", ["refine", "sweep", "failures", "comparison"])
def test_an_empty_out_is_refused(tmp_path, monkeypatch, capsys, command):
    monkeypatch.chdir(tmp_path)
    argv = {"refine": (cli_main, refine_args("")), "sweep": (sweep.main, ["--mazes", "u_maze", "--out", "", *SWEEP]),
            "failures": (failures_main, ["result.json", "--out", ""]),
            "comparison": (comparison_main, ["results.csv", "--out", ""])}[command]
    assert "an empty path" in one_line_2(*argv, capsys)
    assert list(tmp_path.iterdir()) == []  # nothing written where the user stands


@pytest.mark.parametrize("tensor,value,needle", [("norm.var", -1.0, "variance is negative"),
                                                 ("norm.count", 0.0, "count is 0")])
def test_a_policy_with_an_unusable_normaliser_is_refused_at_load(tmp_path, monkeypatch, capsys, tensor, value,
                                                                  needle):
    import torch

    from specrefine.sim.policy import GoalPolicy, save_policy

    policy = GoalPolicy("point")
    with torch.no_grad():
        policy.get_buffer(tensor).fill_(value)
    save_policy(policy, tmp_path / "broken.pt")
    monkeypatch.chdir(tmp_path)
    assert needle in one_line_2(cli_main, refine_args(tmp_path / "o", "--policy", str(tmp_path / "broken.pt")), capsys)
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists() and not (tmp_path / "o" / "run.json").exists()


def test_a_policy_missing_weights_is_refused_naming_them(tmp_path, capsys):
    import torch

    from specrefine.sim.policy import GoalPolicy, save_policy

    save_policy(GoalPolicy("point"), tmp_path / "p.pt")
    blob = torch.load(tmp_path / "p.pt", weights_only=True)
    del blob["state_dict"]["net.2.weight"], blob["state_dict"]["norm.mean"]
    torch.save(blob, tmp_path / "p.pt")
    err = one_line_2(cli_main, refine_args(tmp_path / "o", "--policy", str(tmp_path / "p.pt")), capsys)
    assert "missing net.2.weight, norm.mean" in err


def test_a_policy_acting_with_nan_stops_the_run_without_a_mujoco_log(tmp_path, monkeypatch):
    import numpy as np

    from specrefine.core.errors import PolicyError
    from specrefine.core.mazes import load_maze
    from specrefine.evaluation.evaluator import Evaluator

    monkeypatch.chdir(tmp_path)
    maze = load_maze("u_maze")
    ev = Evaluator(maze, "point", lambda obs: np.full((len(obs), 2), np.nan), n=4)
    with pytest.raises(PolicyError, match="NaN"):
        ev.evaluate(maze.start, maze.goal, maze.walls)
    assert list(tmp_path.iterdir()) == []


def test_sim_steps_mean_the_same_in_a_run_a_resumed_run_and_a_sweep_cell(tmp_path):
    assert cli_main(refine_args(tmp_path / "run", maze="u_chain_1")) == 0
    first = json.loads((tmp_path / "run" / "result.json").read_text())
    (tmp_path / "run" / "result.json").unlink()  # as after a kill before the end: the cache is kept
    assert cli_main(refine_args(tmp_path / "run", maze="u_chain_1")) == 0
    resumed = json.loads((tmp_path / "run" / "result.json").read_text())
    assert sweep.main(["--mazes", "u_chain_1", "--out", str(tmp_path / "s"), *SWEEP]) == 0
    (cell,) = sweep.read_table(tmp_path / "s" / "results.csv")
    assert first["sim_steps"] == first["sim_steps_simulated"] > 0
    assert resumed["sim_steps"] == first["sim_steps"] == cell["sim_steps"]
    assert resumed["sim_steps_simulated"] < resumed["sim_steps"]  # the search's evaluations came from the cache
    assert resumed["success_rate"] == first["success_rate"]


def test_failures_with_zero_episodes_is_refused(tmp_path, capsys):
    assert "out of range" in one_line_2(failures_main, [str(tmp_path / "result.json"), "--episodes", "0"], capsys)


def test_a_finished_run_of_the_users_own_maze_is_reopened_from_its_record(tmp_path, capsys):
    from specrefine.runs.calibrate import main as calibrate_main

    maze = tmp_path / "mine.maze"
    maze.write_text(ROOM)
    assert cli_main(["refine", str(maze), "--method", "ours", "--out", str(tmp_path / "run"), *TINY]) == 0
    maze.unlink()  # the record alone must do
    capsys.readouterr()
    assert failures_main([str(tmp_path / "run" / "result.json"), "--episodes", "4"]) == 0, capsys.readouterr().err
    by_file = capsys.readouterr().out
    assert failures_main([str(tmp_path / "run"), "--episodes", "4"]) == 0, capsys.readouterr().err  # its folder
    assert capsys.readouterr().out == by_file
    assert calibrate_main([str(tmp_path / "run"), "--table", str(tmp_path / "p.csv")]) == 0, capsys.readouterr().err
    assert sweep.read_table(tmp_path / "p.csv")[0]["cell"] == "run"


# --- hangs: a FIFO is no input file ------------------------------------------------------------------------
def test_a_fifo_given_as_an_input_file_is_refused_without_opening_it(tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    for module, args, needle in [
            ("specrefine.cli", ["refine", fifo, "--out", tmp_path / "o1", *TINY], "a FIFO"),
            ("specrefine.cli", ["refine", "u_maze", "--policy", fifo, "--out", tmp_path / "o2", *TINY], "policy"),
            ("specrefine.cli", ["refine", "u_maze", "--proposer", f"replay:{fifo}", "--out", tmp_path / "o3", *TINY],
             "a FIFO"),
            ("specrefine.experiments.comparison", [fifo, "--out", tmp_path / "o4"], "a FIFO"),
            ("specrefine.experiments.failures", [fifo], "a FIFO")]:
        assert_one_line_2(run_module(module, *args, timeout=60), needle)  # a hang would time out


# --- tracebacks and exit codes: one line, exit 2, before any long work ------------------------------------
def test_a_spec_nested_too_deep_is_one_line(tmp_path, capsys):
    deep = "(" * 330 + "G" + ")" * 330
    assert "nested more than 100 deep" in one_line_2(cli_main, refine_args(tmp_path / "o", "--spec", deep), capsys)
    maze = tmp_path / "deep.maze"
    maze.write_text(f"; spec: {deep}\n#####\n#S.G#\n#####\n")
    assert "nested more than 100 deep" in one_line_2(cli_main, ["refine", str(maze), "--out", str(tmp_path / "p")],
                                                     capsys)


def test_calibrate_bad_input_is_one_line_exit_2(tmp_path, capsys):
    from specrefine.runs.calibrate import main as calibrate_main

    (tmp_path / "list").mkdir()
    (tmp_path / "list" / "result.json").write_text("[]")
    (tmp_path / "empty.json").write_text("")
    (tmp_path / "binary.csv").write_bytes(b"\x89PNG\r\n\x1a\n\x00\xff")
    (tmp_path / "garbage.csv").write_text("a,b\n1,2\n")
    (tmp_path / "none.csv").write_text("")
    table = ["--table", str(tmp_path / "t.csv")]
    assert "a JSON list" in one_line_2(calibrate_main, [str(tmp_path / "list"), *table], capsys)
    assert "empty.json" in one_line_2(calibrate_main, [str(tmp_path / "empty.json"), *table], capsys)
    for name, needle in [("binary.csv", "not UTF-8"), ("garbage.csv", "not a predictions table"),
                         ("none.csv", "empty")]:
        assert needle in one_line_2(calibrate_main, ["--coverage", str(tmp_path / name)], capsys)


def test_failures_bad_input_is_one_line_exit_2_before_the_rerun(tmp_path, capsys):
    result = tmp_path / "result.json"
    result.write_text(json.dumps({"maze": "u_maze", "agent": "point", "path": ["S", "G"], "graph": {"nodes": 1}}))
    assert "malformed" in one_line_2(failures_main, [str(result), "--episodes", "2"], capsys)
    assert "out of range" in one_line_2(failures_main, [str(result), "--episodes", "-5"], capsys)
    (tmp_path / "file").write_text("")
    assert "not a directory" in one_line_2(failures_main, [str(result), "--out", str(tmp_path / "file" / "r.json")],
                                           capsys)


def test_comparison_bad_input_is_one_line_exit_2(tmp_path, capsys):
    (tmp_path / "binary.csv").write_bytes(b"\x00\x01\xff" * 50)
    (tmp_path / "file").write_text("")
    row = {k: "1" for k in sweep.COLUMNS} | {"cell": "c", "status": "ok", "success_rate": "high"}
    sweep._append(tmp_path / "words.csv", row)
    sweep._append(tmp_path / "fine.csv", row | {"success_rate": "0.5"})
    assert "not UTF-8" in one_line_2(comparison_main, [str(tmp_path / "binary.csv"), "--out", str(tmp_path / "o")],
                                     capsys)
    assert "not a directory" in one_line_2(comparison_main, [str(tmp_path / "fine.csv"), "--out",
                                                             str(tmp_path / "file")], capsys)
    assert "success_rate is 'high', not a number" in one_line_2(
        comparison_main, [str(tmp_path / "words.csv"), "--out", str(tmp_path / "o")], capsys)


@pytest.mark.parametrize("args,needle", [(["--method", "best"], "invalid choice"),
                                         (["--proposer", "gpt"], "invalid proposer"),
                                         (["--mazes", "no_such_maze"], "no_such_maze"),
                                         (["--table", "{tmp}"], "is a folder")])
def test_bench_refine_bad_input_is_one_line_before_any_setup(tmp_path, capsys, args, needle):
    from specrefine.bench.__main__ import main as bench_main

    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    assert needle in one_line_2(bench_main, ["refine", "--agent", "point", "--episodes", "2", *args], capsys)


def test_a_bad_mplbackend_is_one_line_before_any_work(tmp_path):
    proc = run_module("specrefine.cli", *refine_args(tmp_path / "o"), env={"MPLBACKEND": "nonsense"})
    assert_one_line_2(proc, "MPLBACKEND='nonsense' is not a matplotlib backend")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("name,value", [("ROLLOUTS", -1), ("ROLLOUTS", 0), ("SEEDS", [0, -2]), ("AGENT", "walker"),
                                        ("PROPOSER", "gpt"), ("EPISODES", 2.5), ("GOAL_POINTS", "corner")])
def test_notebook_parameters_are_checked_by_the_cli_rules(name, value):
    from specrefine.core.errors import SpecrefineError
    from specrefine.runs.notebook import check_parameters

    with pytest.raises(SpecrefineError, match=f"notebook parameter {name} = "):
        check_parameters({"ROLLOUTS": 8, "SEED": 0, name: value})
    check_parameters({"ROLLOUTS": 8, "SEEDS": [0, 1], "AGENT": "ant", "PROPOSER": "imperfect:mild",
                      "GOAL_POINTS": "centre"})  # all fine


def test_a_notebook_run_with_rollouts_0_names_the_parameter(tmp_path):
    from specrefine.runs.notebook import NB_DIR, execute, kernel_env

    env = kernel_env(tmp_path / "k")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    code, log = execute(NB_DIR / "02_task_graphs_and_evaluation.ipynb", tmp_path / "nb.ipynb", {"ROLLOUTS": 0},
                        env=env, timeout=300)
    assert code != 0 and "notebook parameter ROLLOUTS = 0" in log, log[-3000:]
    assert "negative dimensions" not in log and "ZeroDivisionError" not in log


def test_every_proposer_the_library_accepts_the_cli_accepts(tmp_path, capsys):
    assert cli_main(refine_args(tmp_path / "o", "--method", "ours", "--proposer", "geometric:max_waypoints=48")) == 0
    assert json.loads((tmp_path / "o" / "result.json").read_text())["proposer"] == "geometric:max_waypoints=48"


@pytest.mark.parametrize("args,needle", [(["--methods", "nonsense"], "invalid choice"),
                                         (["--proposers", "gpt"], "invalid proposer"),
                                         (["--mazes", "no_such_maze"], "no_such_maze")])
def test_a_sweep_with_a_bad_method_proposer_or_maze_is_refused_before_any_cell(tmp_path, capsys, args, needle):
    base = ["--mazes", "u_maze", "--methods", "ours", "--seeds", "0", "--rollouts", "2", "--episodes", "2",
            "--workers", "1", "--out", str(tmp_path / "s")]
    assert needle in one_line_2(sweep.main, base + args, capsys)
    assert not (tmp_path / "s").exists()


# --- kill anywhere: every folder complete and parseable, or resumable to the same result --------------------
KILL_RUN = ["refine", "u_chain_1", "--method", "ours", "-w", "1", "-d", "1", "--rollouts", "4", "--episodes", "8"]
KILLS = int(os.environ.get("KILL_N", "3"))  # per kind of run; KILL_N=50 searches longer


def _record(folder: Path) -> dict | None:
    """result.json's data (None where there is none), after checking that every record file in the folder parses:
    no 0-byte file, no cut line, steps.jsonl beside every result.json."""
    for name in ("run.json", "result.json", "steps.jsonl"):
        path = folder / name
        assert not path.exists() or path.stat().st_size > 0, f"{path} is empty"
    if (folder / "run.json").exists():
        json.loads((folder / "run.json").read_text())
    if not (folder / "result.json").exists():
        return None
    steps = (folder / "steps.jsonl").read_text().splitlines()
    assert all(isinstance(json.loads(line), dict) for line in steps)
    return json.loads((folder / "result.json").read_text()) | {"_steps": len(steps)}


def test_a_run_killed_anywhere_is_complete_or_resumes_to_the_same_result(tmp_path):
    import random
    import shutil
    import signal

    reference = tmp_path / "reference"
    assert cli_main([*KILL_RUN, "--out", str(reference)]) == 0
    want = _record(reference)
    rng = random.Random(29)
    for i in range(2 * KILLS):
        folder = tmp_path / f"kill{i}"
        rerun = i % 2 == 1  # every other one: a rerun into a finished folder
        if rerun:
            shutil.copytree(reference, folder)
        env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
        proc = subprocess.Popen([sys.executable, "-m", "specrefine.cli", *KILL_RUN, "--out", str(folder)], env=env,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(rng.uniform(0.3, 5.0))  # from the interpreter's start to past the run's end
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=60)
        got = _record(folder)
        if rerun:
            assert got is not None  # the finished run's record is never lost
        if got is None:  # resumable: a rerun finishes with the same result
            assert cli_main([*KILL_RUN, "--out", str(folder)]) == 0
            got = _record(folder)
        assert (got["success_rate"], got["_steps"], got["sim_steps"]) == \
            (want["success_rate"], want["_steps"], want["sim_steps"]), (i, rerun)
