"""Issue 13: no silently wrong result, no hang, one line for every bad input, a run folder that cannot lie."""

from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from specrefine.bench.__main__ import main as bench_main
from specrefine.cli import main as cli_main
from specrefine.runs import sweep

TINY = ["--rollouts", "2", "--episodes", "2"]


def exit_code(main, args) -> int:
    try:
        return main(args)
    except SystemExit as exc:  # argparse errors
        return exc.code


def assert_one_line_exit_2(main, args, capsys, needle=""):
    code = exit_code(main, args)
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1 and needle in err and "Traceback" not in err, err


# --- nonsense numbers: one line, exit 2, before anything runs ------------------------------------------
@pytest.mark.parametrize("args", [
    ["-w", "0"], ["-d", "0"], ["-w", "-1"], ["-d", "-2"], ["-k", "-1"], ["-k", "0"], ["--rollouts", "0"],
    ["--rollouts", "-3"], ["--episodes", "0"], ["--episodes", "-1"], ["--seed", "-1"], ["-w", "1000000"],
    ["--seed", str(2**40)], ["--rollouts", "lots"],
])
def test_refine_rejects_nonsense_numbers(tmp_path, capsys, args):
    out = tmp_path / "o"
    assert_one_line_exit_2(cli_main, ["refine", "u_maze", "--out", str(out), *TINY, *args], capsys,
                           "out of range" if args[1].lstrip("-").isdigit() else "not a whole number")
    assert not out.exists()  # refused before anything was written


@pytest.mark.parametrize("args", [
    ["--rollouts", "0"], ["--episodes", "-1"], ["--seeds", "0", "-1"], ["--workers", "0"], ["--rollouts", "99999"],
])
def test_sweep_rejects_nonsense_numbers(tmp_path, capsys, args):
    out = tmp_path / "s"
    assert_one_line_exit_2(sweep.main, ["--mazes", "u_maze", "--methods", "dirl", "--out", str(out), *args], capsys,
                           "out of range")
    assert not out.exists()


@pytest.mark.parametrize("args", [["--batch", "0"], ["--batch", "-4"], ["--rounds", "0"], ["--seconds", "0"]])
def test_bench_rejects_nonsense_numbers(capsys, args):
    assert_one_line_exit_2(bench_main, ["evaluator", *args], capsys, "error")


# --- the sweep: maze files, parameters, truncated rows, exit codes ------------------------------------
SWEEP = ["--methods", "dirl", "--seeds", "0", "--rollouts", "2", "--episodes", "2", "--workers", "1"]
ROOM = "; an open room, not the shipped u_maze\n#######\n#S...G#\n#######\n"


def test_sweep_runs_maze_files_from_their_path(tmp_path, capsys):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "u_maze.maze").write_text(ROOM)  # the shipped name, another maze
    (elsewhere / "my_room.maze").write_text(ROOM)  # a name data/mazes does not have
    out = tmp_path / "s"
    code = sweep.main(["--mazes", str(elsewhere / "u_maze.maze"), str(elsewhere / "my_room.maze"), "u_maze",
                       "--out", str(out), *SWEEP, "--preset", "paper"])  # the paper's: ids without a suffix
    rows = {r["maze"]: r for r in sweep.read_table(out / "results.csv")}
    assert code == 0, capsys.readouterr().err
    assert set(rows) == {str(elsewhere / "u_maze.maze"), str(elsewhere / "my_room.maze"), "u_maze"}
    assert all(r["status"] == "ok" for r in rows.values()), rows
    assert len({r["cell"] for r in rows.values()}) == 3 and rows["u_maze"]["cell"] == "u_maze__point__dirl__none__s0"
    ran = json.loads((out / "cells" / rows[str(elsewhere / "u_maze.maze")]["cell"] / "run.json").read_text())
    assert ran["maze_grid"] == ROOM.splitlines()[1:]  # the file's maze, not the shipped u_maze


def test_a_maze_in_a_folder_of_data_mazes_has_the_same_name_and_cell_on_every_machine(monkeypatch, tmp_path):
    from specrefine.core.mazes import MAZE_DIR

    by_path = sweep.maze_ref(str(MAZE_DIR / "held_out" / "u_chain_3_rotated.maze"))
    monkeypatch.chdir(tmp_path)  # from anywhere, by its path there or by its name
    assert by_path == sweep.maze_ref("held_out/u_chain_3_rotated") == "held_out/u_chain_3_rotated"
    assert sweep.maze_ref(str(MAZE_DIR / "u_maze.maze")) == "u_maze"
    cell = sweep.Cell.of(by_path, "ant", "ours", "geometric", 0, preset="paper")
    assert cell.id == "held_out-u_chain_3_rotated__ant__ours__geometric__s0"


def test_sweep_refuses_a_rerun_with_other_parameters(tmp_path, capsys):
    out = tmp_path / "s"
    assert sweep.main(["--mazes", "u_maze", "--out", str(out), *SWEEP]) == 0
    before = (out / "results.csv").read_text()
    capsys.readouterr()
    assert_one_line_exit_2(sweep.main, ["--mazes", "u_maze", "--out", str(out), *SWEEP, "--episodes", "3"], capsys,
                           "--episodes 2")
    assert (out / "results.csv").read_text() == before


def test_sweep_redoes_a_truncated_ok_row(tmp_path):
    out = tmp_path / "s"
    out.mkdir()
    cell = "u_maze__point__dirl__none__s0"
    (out / "results.csv").write_text(",".join(sweep.COLUMNS) + f"\r\n{cell},u_maze,point,dirl,none,False,0,ok")
    assert sweep.main(["--mazes", "u_maze", "--out", str(out), *SWEEP, "--preset", "paper"]) == 0
    (row,) = sweep.read_table(out / "results.csv")  # one row per cell, complete
    assert row["cell"] == cell and sweep.is_done(row) and 0 <= row["success_rate"] <= 1


def test_sweep_exits_1_when_every_cell_failed(tmp_path, capsys, monkeypatch):
    import specrefine.runs.pipeline

    def fails(*args, **kw):  # a cell that fails while it runs (a bad maze is refused before any cell: exit 2)
        raise RuntimeError("the simulator fell over")

    monkeypatch.setattr(specrefine.runs.pipeline, "refine_maze", fails)
    code = sweep.main(["--mazes", "u_maze", "--out", str(tmp_path / "s"), *SWEEP])
    assert code == 1 and "1 failed" in capsys.readouterr().out


# --- the sweep's processes: Ctrl-C and a killed parent ------------------------------------------------
def _group(pgid: int, command: bytes = b"") -> list[int]:
    """Live (non-zombie) processes of a process group (whose command line holds ``command``)."""
    pids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            if int(fields[2]) == pgid and fields[0] != "Z" and command in (stat.parent / "cmdline").read_bytes():
                pids.append(int(stat.parent.name))
        except OSError:
            continue
    return pids


def _pool_started(pgid: int) -> bool:
    """The sweep and both its workers (forks, so the same command line) are up; a helper process that a
    library starts for a moment (glfw's `python -c` probe, for one) is not a worker."""
    return len(_group(pgid, b"specrefine.runs.sweep")) >= 3


def _sweep_proc(out: Path):
    seeds = [str(s) for s in range(40)]  # enough cells that the sweep is still running when the test interrupts it
    cmd = [sys.executable, "-m", "specrefine.runs.sweep", "--mazes", "u_maze", "--methods", "dirl", "--seeds", *seeds,
           "--rollouts", "8", "--episodes", "16", "--workers", "2", "--out", str(out)]
    # Ctrl-C must reach the sweep even when the suite itself was started in the background of a non-interactive
    # shell, which starts it with SIGINT ignored (inherited through exec: the sweep would then never see it)
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _wait_for(condition, seconds=120):
    deadline = time.time() + seconds
    while time.time() < deadline and not condition():
        time.sleep(0.2)
    return condition()


def test_sweep_ctrl_c_ends_with_one_line_and_keeps_rows(tmp_path):
    done = {k: 1 for k in sweep.COLUMNS} | {"cell": "u_maze__point__dirl__none__s0", "status": "ok", "seed": 0,
                                           "rollouts_per_evaluation": 8}
    sweep._append(tmp_path / "results.csv", done)  # a finished cell from before
    proc = _sweep_proc(tmp_path)
    try:
        assert _wait_for(lambda: _pool_started(proc.pid), 60), "no pool workers"
        time.sleep(1)
        os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C: the whole foreground group, workers included
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130 and "Traceback" not in err, err
    assert err.strip().splitlines()[-1].startswith("python -m specrefine.runs.sweep: error: interrupted"), err
    assert sweep.read_table(tmp_path / "results.csv")[0]["cell"] == done["cell"]  # finished rows kept
    assert _wait_for(lambda: not _group(proc.pid), 10), "pool workers outlived the sweep"


def test_sweep_workers_die_with_a_killed_parent(tmp_path):
    proc = _sweep_proc(tmp_path)
    try:
        assert _wait_for(lambda: _pool_started(proc.pid), 60), "no pool workers"
        proc.kill()  # the parent only: its workers are orphaned
        proc.wait(timeout=10)
        assert _wait_for(lambda: not _group(proc.pid), 20), "pool workers outlived the sweep"
    finally:
        for pid in _group(proc.pid):
            os.kill(pid, signal.SIGKILL)


# --- a run folder that cannot lie ---------------------------------------------------------------------
def refine(out, *args):
    return ["refine", "u_maze", "--method", "dirl", "--out", str(out), *TINY, *args]


def test_rerun_with_other_arguments_is_refused_and_leaves_the_folder_alone(tmp_path, capsys):
    assert cli_main(refine(tmp_path)) == 0
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    assert json.loads((tmp_path / "run.json").read_text())["episodes"] == 2
    capsys.readouterr()
    assert_one_line_exit_2(cli_main, refine(tmp_path, "--seed", "1"), capsys, "holds another run (seed 0")
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()} == before
    assert cli_main(refine(tmp_path)) == 0  # the same arguments resume
    assert not (tmp_path / ".lock").exists()


def test_a_folder_in_use_by_a_live_run_is_refused(tmp_path, capsys):
    (tmp_path / ".lock").write_text(f"{os.getppid()}\n")  # a live process that is not this one
    assert_one_line_exit_2(cli_main, refine(tmp_path), capsys, "in use by another run")
    assert not (tmp_path / "result.json").exists()


def test_a_dead_runs_lock_is_taken_over(tmp_path, capsys):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    (tmp_path / ".lock").write_text(f"{dead.pid}\n")
    assert cli_main(refine(tmp_path)) == 0, capsys.readouterr().err
    assert (tmp_path / "result.json").exists() and not (tmp_path / ".lock").exists()


@pytest.mark.parametrize("where", ["{file}", "/dev/null", "{file}/sub", "/proc/no-such-folder"])
def test_out_that_is_not_a_writable_folder_is_one_line(tmp_path, capsys, where):
    (tmp_path / "file").write_text("not a folder")
    out = where.replace("{file}", str(tmp_path / "file"))
    assert_one_line_exit_2(cli_main, refine(out), capsys, out)
    assert_one_line_exit_2(sweep.main, ["--mazes", "u_maze", "--out", out, *SWEEP], capsys, out)


# --- secrets: every configured key is scrubbed, whatever its length -----------------------------------
def test_short_api_keys_are_scrubbed_without_mangling_text(monkeypatch, tmp_path):
    from specrefine.vlm.messages import one_line
    from specrefine.vlm.recording import Recorder

    monkeypatch.setenv("OPENAI_API_KEY", "sk-12")
    monkeypatch.setenv("MY_SERVICE_TOKEN", "ab")
    monkeypatch.setenv("TOKENIZERS_PARALLELISM", "false")  # a flag, not a key
    msg = one_line("auth failed for key sk-12 (token ab); the table is false")
    assert "sk-12" not in msg and " ab)" not in msg, msg
    assert msg == "auth failed for key *** (token ***); the table is false"
    rec = Recorder(tmp_path / "r.jsonl")
    rec.write({"error": "key sk-12 rejected", "n": 2}, [{"role": "user", "content": "go to ab then b"}])
    line = (tmp_path / "r.jsonl").read_text()
    assert "sk-12" not in line and "to ab " not in line and json.loads(line)["n"] == 2


# --- property: any argument vector gives a valid result or exactly one line, never a traceback --------
def values(valid, invalid):
    """An option's value: as often valid as not."""
    return st.one_of(st.sampled_from(valid), st.sampled_from(invalid))


NUMBER = values(["1", "2"], ["0", "-1", "21", "2147483648", "x", "", "1.5"])
OPTIONS = {
    "--method": values(["dirl", "symbolic", "ours", "vlm-oneshot"], ["best"]),
    "--proposer": values(["geometric", "random", "imperfect:mild"], ["imperfect:nope", "replay:/no/file", "gpt"]),
    "--agent": values(["point"], ["walker"]),
    "--spec": values(["G"], ["a -> G", "->", "(G"]),
    "--seed": values(["0", "7", "2147483647"], ["-1", "2147483648", "x"]),
    "--rollouts": values(["1", "2"], ["0", "-2", "y"]), "--episodes": values(["1", "2"], ["0", "z"]),
    "-w": NUMBER, "-d": NUMBER, "-k": NUMBER, "--policy": values(["data/policies/point.pt"], ["/no/policy.pt"]),
}


@st.composite
def argv(draw):
    maze = draw(values(["u_maze", "data/mazes/u_maze.maze"], ["no_such_maze", "/dev/null"]))
    args = ["refine", maze, "--rollouts", "2", "--episodes", "2"]
    for name in draw(st.lists(st.sampled_from(sorted(OPTIONS)), max_size=3, unique=True)):
        args += [name, draw(OPTIONS[name])]
    extra = draw(st.sampled_from([None, None, None, "--bogus", "extra", "-w"]))
    return args + ([extra] if extra else [])


@settings(max_examples=30, deadline=None, derandomize=True)
@given(args=argv())
def test_any_argument_vector_gives_a_result_or_one_line(args):
    out = Path(tempfile.mkdtemp(prefix="prop_"))
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = exit_code(cli_main, [*args, "--out", str(out)])
        if code == 0:
            data = json.loads((out / "result.json").read_text())
            lo, hi = data["success_ci"]
            assert 0 <= lo <= data["success_rate"] <= hi <= 1 and data["episodes"] <= 2, data
        else:
            lines = err.getvalue().strip().splitlines()
            assert code == 2 and len(lines) == 1 and "Traceback" not in lines[0], (args, err.getvalue())
    finally:
        shutil.rmtree(out, ignore_errors=True)


# --- more bad input: one line each ----------------------------------------------------------------------
@pytest.mark.parametrize("agent,policy", [("ant", "point"), ("point", "ant")])
def test_a_policy_for_the_other_agent_is_one_line(tmp_path, capsys, agent, policy):
    from specrefine.core.paths import data_dir

    path = data_dir() / "policies" / f"{policy}.pt"
    assert_one_line_exit_2(cli_main, refine(tmp_path, "--agent", agent, "--policy", str(path)), capsys,
                           f"holds a {policy} policy")
    assert not (tmp_path / "run.json").exists()  # a refused run leaves no record


@pytest.mark.parametrize("lines", [[b"\xff\xfe not utf-8"], [b"[1, 2]", b'"text"', b'{"response": "x"}',
                                                              b'{"response": {"choices": "no"}}',
                                                              b'{"response": {"choices": [{"text": 3}]}}']])
def test_a_replay_file_of_the_wrong_shape_is_one_line(tmp_path, capsys, lines):
    rec = tmp_path / "rec.jsonl"
    rec.write_bytes(b"\n".join(lines) + b"\n")
    assert_one_line_exit_2(cli_main, ["refine", "u_maze", "--out", str(tmp_path / "o"), *TINY, "--proposer",
                                      f"replay:{rec}"], capsys, "unreadable lines")


def test_a_maze_file_with_a_utf8_bom_is_read(tmp_path, capsys):
    maze = tmp_path / "bom.maze"
    maze.write_bytes(b"\xef\xbb\xbf" + ROOM.encode())
    assert cli_main(["refine", str(maze), "--method", "dirl", "--out", str(tmp_path / "o"), *TINY]) == 0, \
        capsys.readouterr().err
    assert json.loads((tmp_path / "o" / "run.json").read_text())["maze_grid"] == ROOM.splitlines()[1:]


def test_a_closed_stdout_is_no_traceback(tmp_path):
    cmd = [sys.executable, "-c", "import sys; from specrefine.cli import main; sys.exit(main())",
           *refine(tmp_path)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # as `| head` does once it has its lines
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 0 and "Traceback" not in err, err


@pytest.mark.parametrize("value", [float("nan"), float("inf")])
def test_a_policy_with_nan_or_inf_weights_is_refused_at_load(tmp_path, capsys, value):
    import torch

    from specrefine.sim.policy import GoalPolicy, save_policy

    policy = GoalPolicy("point")
    with torch.no_grad():
        policy.net[2].weight[3, 5] = value
    path = tmp_path / "broken.pt"
    save_policy(policy, path)
    assert_one_line_exit_2(cli_main, refine(tmp_path / "o", "--policy", str(path)), capsys,
                           f"{path}: weights hold NaN or infinite values (net.2.weight)")
    assert not (tmp_path / "o" / "run.json").exists()


def test_ctrl_c_cancels_a_ray_sweeps_tasks(tmp_path, monkeypatch):
    """The Ray backend left its queued and running cells to go on after Ctrl-C (the local pool stops its workers)."""
    from types import SimpleNamespace

    def wait(refs, num_returns):
        raise KeyboardInterrupt

    cancelled = []
    fake = SimpleNamespace(is_initialized=lambda: True, wait=wait,
                           remote=lambda **_: lambda fn: SimpleNamespace(remote=lambda cell, out: f"ref:{cell.id}"),
                           cancel=lambda ref, force=False: cancelled.append((ref, force)))
    monkeypatch.setitem(sys.modules, "ray", fake)
    cells = sweep.grid(["u_maze"], ["dirl"], ["none"], [0, 1, 2], rollouts=2, episodes=2)
    with pytest.raises(KeyboardInterrupt):
        sweep.run_sweep(cells, tmp_path / "s", backend="ray")
    assert cancelled == [(f"ref:{c.id}", True) for c in cells]
