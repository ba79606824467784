"""Issue 40 (reliability, round 4), part A: nothing written through a link or onto a device, one lock for every
command writing into a run folder, every input opened as a regular file, outputs checked before any work.

"RUN" is a finished point run (u_maze, ours, geometric, 8 rollouts, 20 episodes), copied before a test changes it.
"""

from __future__ import annotations

import csv
import errno
import json
import os
import shutil
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from test_reliability3 import ROOM, assert_one_line_2, one_line_2, run_module

from specrefine.cli import main as cli_main
from specrefine.experiments.failures import main as failures_main
from specrefine.runs import sweep
from specrefine.runs.sweep import COLUMNS

ROOT = Path(__file__).resolve().parent.parent
RUN_ARGS = ["u_maze", "--agent", "point", "--method", "ours", "--proposer", "geometric", "--seed", "0",
            "--rollouts", "8", "--episodes", "20", "--quiet"]
TINY = ["u_maze", "--method", "dirl", "--rollouts", "2", "--episodes", "2", "--quiet"]
SWEEP = ["--mazes", "u_maze", "--methods", "dirl", "--seeds", "0", "--rollouts", "2", "--episodes", "2",
         "--workers", "1"]


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("rel4") / "RUN"
    assert cli_main(["refine", *RUN_ARGS, "--out", str(out)]) == 0
    return out


@pytest.fixture
def run(finished, tmp_path) -> Path:
    """A copy of the finished run, for a test to change."""
    return Path(shutil.copytree(finished, tmp_path / "RUN"))


def snapshot(folder: Path) -> dict:
    """Every file under ``folder`` (links not followed) and its bytes or kind."""
    out = {}
    for path in sorted(folder.rglob("*")):
        mode = path.lstat().st_mode
        out[str(path.relative_to(folder))] = path.read_bytes() if stat.S_ISREG(mode) else stat.S_IFMT(mode)
    return out


def device(path: Path) -> Path:
    """A character device like /dev/null at ``path`` (skips where this user cannot make one)."""
    try:
        os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    except OSError as exc:
        pytest.skip(f"cannot make a device node here ({exc.strerror})")
    return path


def immutable(path: Path):
    """``path`` made read-only even for root (chattr +i); undone by the returned callable."""
    done = subprocess.run(["chattr", "+i", str(path)], capture_output=True)
    if done.returncode != 0:
        pytest.skip("chattr +i is not available here")
    return lambda: subprocess.run(["chattr", "-i", str(path)], check=True)


# --- 1. a lock or a temporary file that is a link is never followed ------------------------------------
def test_a_lock_that_is_a_link_is_refused_and_its_target_untouched(tmp_path, capsys):
    victim = tmp_path / "victim"
    victim.write_text("precious\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / ".lock").symlink_to(victim)
    err = one_line_2(cli_main, ["refine", *TINY, "--out", str(out)], capsys)
    assert ".lock" in err and "link" in err
    assert victim.read_text() == "precious\n" and not (out / "result.json").exists()


def test_a_link_planted_at_a_temporary_files_name_is_not_followed(run, tmp_path, capsys):
    victim = tmp_path / "victim"
    victim.write_text("precious\n")
    target = tmp_path / "elsewhere" / "official.json"
    target.parent.mkdir()
    (target.parent / f".official.json.{os.getpid()}.tmp").symlink_to(victim)  # this process writes through it
    assert cli_main(["official", str(run), "--episodes", "2", "--out", str(target)]) == 0, capsys.readouterr().err
    assert victim.read_text() == "precious\n"
    assert json.loads(target.read_text())["episodes"] == 2 and not target.is_symlink()


# --- 2. only a regular file or a new path is an output ----------------------------------------------
@pytest.mark.parametrize("command", ["official", "failures"])
def test_a_device_as_out_is_refused_and_stays_a_device(run, tmp_path, capsys, command):
    null = device(tmp_path / "null")
    argv = (["official", str(run), "--episodes", "2"] if command == "official"
            else [str(run / "result.json"), "--episodes", "2"]) + ["--out", str(null)]
    err = one_line_2(cli_main if command == "official" else failures_main, argv, capsys)
    assert "a device" in err and stat.S_ISCHR(null.lstat().st_mode)


@pytest.mark.parametrize("kind", ["link", "device"])
def test_train_evaluate_plot_is_checked_before_any_episode(tmp_path, capsys, kind):
    victim = tmp_path / "victim"
    victim.write_text("precious\n")
    plot = tmp_path / "plot.png"
    if kind == "link":
        plot.symlink_to(victim)
    else:
        device(plot)
    err = one_line_2(cli_main, ["train", "--agent", "point", "--evaluate", "point", "--episodes", "2",
                                "--no-progress", "--plot", str(plot)], capsys)
    assert f"--plot {plot}: a {kind}" in err and victim.read_text() == "precious\n"
    assert (plot.is_symlink() if kind == "link" else stat.S_ISCHR(plot.lstat().st_mode))


def test_train_evaluate_plot_is_written_whole(tmp_path, capsys):
    plot = tmp_path / "plot.png"
    assert cli_main(["train", "--agent", "point", "--evaluate", "point", "--episodes", "2", "--no-progress",
                     "--plot", str(plot)]) == 0, capsys.readouterr().err
    assert plot.read_bytes().startswith(b"\x89PNG") and sorted(p.name for p in tmp_path.iterdir()) == ["plot.png"]


def test_notebook_executed_refuses_a_linked_copy_before_any_notebook_runs(tmp_path, capsys):
    pytest.importorskip("papermill")
    victim, out = tmp_path / "victim", tmp_path / "executed"
    victim.write_text("precious\n")
    out.mkdir()
    (out / "05_astar_refinement.ipynb").symlink_to(victim)
    err = one_line_2(cli_main, ["notebook", "executed", "05", "--out", str(out)], capsys)
    assert "05_astar_refinement.ipynb: a link" in err and victim.read_text() == "precious\n"
    assert "zz" in one_line_2(cli_main, ["notebook", "executed", "zz", "--out", str(out)], capsys)  # matches none


# --- 3. a run's own files are no output of another command ----------------------------------------------
@pytest.mark.parametrize("name", ["result.json", "policy.json", "steps.jsonl", "run.json"])
def test_official_refuses_the_run_folders_own_files_as_out(run, capsys, name):
    before = snapshot(run)
    err = one_line_2(cli_main, ["official", str(run), "--episodes", "2", "--out", str(run / name)], capsys)
    assert f"own {name}" in err and snapshot(run) == before


def test_failures_refuses_the_runs_result_as_out(run, capsys):
    before = snapshot(run)
    err = one_line_2(failures_main, [str(run / "result.json"), "--episodes", "2", "--out", str(run / "result.json")],
                     capsys)
    assert "own result.json" in err and snapshot(run) == before


# --- 4. a table or a recording appended to is never a link ------------------------------------------------
def test_a_results_table_linked_outside_the_sweep_is_refused(tmp_path, capsys):
    victim = tmp_path / "victim.csv"
    victim.write_text(",".join(COLUMNS) + "\n")  # a valid sweep table elsewhere
    out = tmp_path / "s"
    out.mkdir()
    (out / "results.csv").symlink_to(victim)
    err = one_line_2(sweep.main, [*SWEEP, "--out", str(out)], capsys)
    assert "results.csv" in err and "link" in err
    assert victim.read_text() == ",".join(COLUMNS) + "\n" and not (out / "cells").exists()


@pytest.fixture
def fake_vlm(monkeypatch):
    from test_vlm import KEY, Server

    server = Server()
    monkeypatch.setenv("OPENAI_API_KEY", KEY)
    monkeypatch.setenv("OPENAI_BASE_URL", server.base)
    monkeypatch.setenv("SPECREFINE_VLM_DEADLINE", "30")
    yield server
    server.close()


def test_a_vlm_recording_linked_outside_the_run_is_refused(fake_vlm, tmp_path, capsys):
    victim = tmp_path / "victim.jsonl"
    victim.write_text("")
    out = tmp_path / "out"
    out.mkdir()
    (out / "vlm_recording.jsonl").symlink_to(victim)
    argv = ["refine", "split_doorway", "--method", "ours", "--proposer", "litellm:openai/test-model", "-w", "1",
            "-d", "1", "--rollouts", "2", "--episodes", "2", "--quiet", "--out", str(out)]
    err = one_line_2(cli_main, argv, capsys)
    assert "vlm_recording.jsonl" in err and "link" in err
    assert victim.read_text() == "" and not fake_vlm.requests  # refused before the first call


def test_pinned_sweep_ships_its_table_whole_past_a_planted_link(tmp_path):
    victim, shipped, tree = tmp_path / "victim", tmp_path / "table.csv", tmp_path / "tree"
    victim.write_text("precious\n")
    (tmp_path / "table.csv.tmp").symlink_to(victim)  # where the copy is written before its rename
    env = {**os.environ, "CODE": "HEAD", "TREE": str(tree), "OUT": str(tmp_path / "sweep"), "SHIPPED": str(shipped),
           "PYTHON": sys.executable}
    try:
        done = subprocess.run(["bash", str(ROOT / "scripts" / "pinned_sweep.sh"), *SWEEP], env=env, cwd=ROOT,
                              capture_output=True, text=True, timeout=600)
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], capture_output=True)
    assert done.returncode == 0, done.stderr[-2000:]
    assert victim.read_text() == "precious\n" and not shipped.is_symlink()
    assert [r["status"] for r in csv.DictReader(shipped.open())] == ["ok"]


# --- 5. scripts/run_grid.sh runs no value as code ---------------------------------------------------------
@pytest.fixture
def grid_root(tmp_path) -> Path:
    """A checkout whose scripts/pinned_sweep.sh only records how it was called (one value a line)."""
    (tmp_path / "scripts").mkdir()
    shutil.copy(ROOT / "scripts" / "run_grid.sh", tmp_path / "scripts")
    (tmp_path / "specrefine").symlink_to(ROOT / "specrefine")
    (tmp_path / "scripts" / "pinned_sweep.sh").write_text(
        'printf "%s\\n" "CODE=$CODE" "OUT=$OUT" "SHIPPED=$SHIPPED" "$@" >> "$(dirname "$0")/calls.txt"\n')
    return tmp_path


def run_grid(root: Path, *args, **env) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", str(root / "scripts" / "run_grid.sh"), *args], capture_output=True, text=True,
                          env=os.environ | {"PYTHON": sys.executable} | env, cwd=root, timeout=120)


@pytest.mark.parametrize("out", ["o;touch${IFS}pwned;#", "with space/$(touch pwned)"])
def test_run_grid_passes_out_as_one_value_and_runs_none_of_it(grid_root, out):
    done = run_grid(grid_root, "repair", OUT=out, SHIPPED="a table.csv")
    assert done.returncode == 0, done.stderr
    assert not list(grid_root.rglob("pwned"))
    calls = (grid_root / "scripts" / "calls.txt").read_text().splitlines()
    assert calls.count(f"OUT={out}") == 3 and calls.count("SHIPPED=a table.csv") == 3  # the grid's three steps
    assert calls[3:8] == ["--agent", "point", "--workers", "1", "--methods"]


@pytest.mark.parametrize("args", [[], [""]])
def test_run_grid_without_a_name_exits_2_with_one_line(grid_root, args):
    done = run_grid(grid_root, *args)
    assert done.returncode == 2 and done.stderr.count("\n") == 1 and "usage" in done.stderr
    assert not (grid_root / "scripts" / "calls.txt").exists()


# --- 6. official takes the run folder's lock ------------------------------------------------------------
def test_official_is_refused_while_another_process_holds_the_run_folder(run):
    holder = subprocess.Popen([sys.executable, "-c", textwrap.dedent(f"""
        import json, sys, time
        from specrefine.core.runfolder import claim
        with claim({str(run)!r}, json.load(open({str(run / 'run.json')!r}))):
            print("held", flush=True)
            time.sleep(60)
        """)], stdout=subprocess.PIPE, text=True, env=os.environ | {"PYTHONPATH": str(ROOT)})
    try:
        assert holder.stdout.readline().strip() == "held"
        before = snapshot(run)
        proc = run_module("specrefine.cli", "official", run, "--episodes", "2")
        assert_one_line_2(proc, "in use by another run")
        assert snapshot(run) == before  # no official.json
    finally:
        holder.kill()
        holder.wait()
    proc = run_module("specrefine.cli", "official", run, "--episodes", "2")  # the holder gone: it runs
    assert proc.returncode == 0, proc.stderr
    assert json.loads((run / "official.json").read_text())["episodes"] == 2 and not (run / ".lock").exists()


def test_train_is_refused_while_another_holds_its_folder(tmp_path, capsys):
    from specrefine.core.runfolder import locked

    out = tmp_path / "train"
    out.mkdir()
    with locked(out):  # another trainer's (an OS lock: a second open of the file conflicts in one process too)
        err = one_line_2(cli_main, ["train", "--agent", "point", "--frames", "64", "--num-envs", "2",
                                    "--steps-per-env", "4", "--no-progress", "--out", str(out)], capsys)
    assert "in use by another run" in err and not any(out.iterdir())  # no log, checkpoint or policy


def test_a_sweep_is_refused_while_another_holds_its_folder(tmp_path, capsys):
    from specrefine.core.runfolder import locked

    out = tmp_path / "s"
    out.mkdir()
    with locked(out):  # another sweep's
        err = one_line_2(sweep.main, [*SWEEP, "--out", str(out)], capsys)
    assert "in use by another run" in err and not any(out.iterdir())  # no table, record or cell
    assert sweep.main([*SWEEP, "--out", str(out)]) == 0 and not (out / ".lock").exists()


def test_figures_are_refused_while_a_sweep_holds_their_folder(tmp_path, capsys):
    from specrefine.core.runfolder import locked

    out = tmp_path / "s"
    assert sweep.main([*SWEEP, "--out", str(out)]) == 0
    capsys.readouterr()
    before = snapshot(out)
    with locked(out):  # the sweep still running there: figures' default --out is the table's folder
        err = one_line_2(cli_main, ["figures", str(out / "results.csv")], capsys)
    assert "in use by another run" in err and snapshot(out) == before
    assert cli_main(["figures", str(out / "results.csv")]) == 0
    assert {"figure4.png", "summary.md"} <= {p.name for p in out.iterdir()} and not (out / ".lock").exists()


def test_calibrate_is_refused_while_another_appends_its_table(finished, tmp_path, capsys):
    from specrefine.core.runfolder import appending_alone

    table = tmp_path / "predictions.csv"
    table.write_text("cell,success_rate\nolder,0.5\n")
    with appending_alone(table) as fh:  # another calibrate resuming the same table
        err = one_line_2(cli_main, ["calibrate", str(finished), "--table", str(table)], capsys)
        assert "another command is appending" in err and table.read_text() == "cell,success_rate\nolder,0.5\n"
        fh.write("other,0.25\n")
    cli_main(["calibrate", str(finished), "--table", str(table)])
    cells = [r["cell"] for r in csv.DictReader(table.open())]
    assert cells == ["older", "other", finished.name]  # its row appended once, after the other's


def test_bench_refine_is_refused_while_another_appends_its_table(tmp_path, capsys):
    from specrefine.bench.__main__ import main as bench_main
    from specrefine.core.runfolder import appending_alone

    table = tmp_path / "bench.csv"
    with appending_alone(table):
        err = one_line_2(bench_main, ["refine", "--agent", "point", "--mazes", "u_maze", "--seeds", "0",
                                      "--episodes", "2", "--table", str(table)], capsys)
    assert "another command is appending" in err and table.read_text() == ""


@pytest.mark.parametrize("script", [["official_gap.py"], ["official_gap_ant.py"], ["official_info_success.py"],
                                    ["run_unseen.py"], ["rerun_table_rows.py", "data/results/ant/oracle_paper.csv",
                                                        "--rows", "1"]])
def test_a_maintainers_script_refuses_a_device_as_out_in_one_line(script):
    proc = subprocess.run([sys.executable, str(ROOT / "scripts" / script[0]), *script[1:], "--out", os.devnull],
                          cwd=ROOT, capture_output=True, text=True, env=os.environ | {"PYTHONPATH": str(ROOT)})
    err = assert_one_line_2(proc, os.devnull)
    assert err.startswith(f"{script[0]}: error: ") and stat.S_ISCHR(os.stat(os.devnull).st_mode)


def test_run_unseen_is_refused_while_another_holds_its_folder(tmp_path):
    from specrefine.core.runfolder import locked

    with locked(tmp_path):
        proc = subprocess.run([sys.executable, str(ROOT / "scripts" / "run_unseen.py"), "--out", str(tmp_path)],
                              capture_output=True, text=True, env=os.environ | {"PYTHONPATH": str(ROOT)})
    assert_one_line_2(proc, "in use by another run")
    assert not (tmp_path / "results.csv").exists()


# --- 7. a FIFO among the inputs is refused, never opened -------------------------------------------------
@pytest.mark.parametrize("name", ["result.json", "policy.json"])
def test_a_fifo_in_the_run_folder_is_one_line_not_a_hang(run, name):
    (run / name).unlink()
    os.mkfifo(run / name)
    proc = run_module("specrefine.cli", "official", run, "--episodes", "2", timeout=60)
    assert_one_line_2(proc, name)


def test_a_fifo_as_sweep_json_is_one_line_not_a_hang(tmp_path):
    (tmp_path / "s").mkdir()
    os.mkfifo(tmp_path / "s" / "sweep.json")
    proc = run_module("specrefine.runs.sweep", *SWEEP, "--out", tmp_path / "s", timeout=60)
    assert_one_line_2(proc, "sweep.json")


# --- 10. outputs checked before the first episode ----------------------------------------------------------
def test_official_out_that_is_a_folder_is_refused_before_any_episode(run, tmp_path, capsys):
    (tmp_path / "folder").mkdir()
    err = one_line_2(cli_main, ["official", str(run), "--episodes", "2", "--out", str(tmp_path / "folder")], capsys)
    assert "a folder" in err and (tmp_path / "folder").is_dir()


@pytest.mark.parametrize("where", ["out", "run"])
def test_official_into_a_read_only_folder_is_refused_before_any_episode(run, tmp_path, where):
    folder = tmp_path / "ro" if where == "out" else run
    folder.mkdir(exist_ok=True)
    undo = immutable(folder)
    try:
        extra = ["--out", folder / "official.json"] if where == "out" else []
        proc = run_module("specrefine.cli", "official", run, "--episodes", "2", *extra)
    finally:
        undo()
    assert_one_line_2(proc, "cannot write in its folder")  # one line: no episode's progress line before it
    assert not (folder / "official.json").exists()


# --- 11. a sweep's folder checked before any cell runs --------------------------------------------------------
@pytest.mark.parametrize("what", ["bad json", "cells 5", "foreign header", "read-only table"])
def test_a_sweep_folder_it_cannot_use_is_one_line_before_any_cell(tmp_path, capsys, what):
    out = tmp_path / "s"
    out.mkdir()
    if what == "bad json":
        (out / "sweep.json").write_text("{not json")
    elif what == "cells 5":
        (out / "sweep.json").write_text('{"cells": 5}')
    elif what == "foreign header":
        (out / "results.csv").write_text("a,b,c\n1,2,3\n")
    else:
        with (out / "results.csv").open("w", newline="") as fh:
            csv.writer(fh).writerow(COLUMNS)
    undo = immutable(out / "results.csv") if what == "read-only table" else (lambda: None)
    try:
        err = one_line_2(sweep.main, [*SWEEP, "--out", str(out)], capsys)
    finally:
        undo()
    assert ("sweep.json" if what in ("bad json", "cells 5") else "results.csv") in err
    assert not (out / "cells").exists()


# --- 12. a folder at result.json, a full disk ---------------------------------------------------------------
def test_a_folder_at_result_json_is_refused_before_the_rerun_works(run, capsys):
    (run / "result.json").unlink()
    (run / "result.json").mkdir()
    steps = (run / "steps.jsonl").read_bytes()
    err = one_line_2(cli_main, ["refine", *RUN_ARGS, "--out", str(run)], capsys)
    assert "result.json" in err and "a folder" in err
    assert (run / "steps.jsonl").read_bytes() == steps and (run / "result.json").is_dir()


def test_a_full_disk_is_one_line_naming_it(tmp_path, capsys, monkeypatch):
    def full(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", full)  # the first file written whole finds the disk full
    err = one_line_2(cli_main, ["refine", *TINY, "--out", str(tmp_path / "out")], capsys)
    assert "the disk is full (no space left on the file system at " in err


# --- 14. a cell id stays a file name -----------------------------------------------------------------------
def test_a_sweep_cell_with_a_very_long_spec_runs(tmp_path, capsys):
    maze = tmp_path / "room.maze"
    maze.write_text(ROOM)
    spec = "(" + " | ".join(["a"] * 80) + ") -> G"
    assert sweep.main([*SWEEP, "--mazes", str(maze), "--specs", spec, "--out", str(tmp_path / "s")]) == 0, \
        capsys.readouterr().err
    (row,) = sweep.read_table(tmp_path / "s" / "results.csv")
    assert row["status"] == "ok" and len(row["cell"]) <= 200 and row["spec"] == spec
    assert (tmp_path / "s" / "cells" / row["cell"] / "result.json").is_file()


# --- 18. a killed run's temporary files are removed by the next start -----------------------------------------
def test_temporary_files_a_killed_run_left_are_removed_at_the_next_start(run, capsys):
    shard = next(p for p in (run / "cache").iterdir() if p.is_dir())
    left = [run / ".steps.jsonl.999999.tmp", run / ".result.json.999999.tmp", shard / ".0123abcd.npz.999999.tmp"]
    for path in left:
        path.write_text("cut short")
    assert cli_main(["refine", *RUN_ARGS, "--out", str(run)]) == 0, capsys.readouterr().err
    assert not [p for p in left if p.exists()]
    assert not list(run.rglob("*.tmp"))


# --- 19. no bar redraws where stderr is no terminal ------------------------------------------------------------
def test_official_writes_plain_progress_lines_when_stderr_is_no_terminal(run):
    proc = run_module("specrefine.cli", "official", run, "--episodes", "4")
    assert proc.returncode == 0, proc.stderr
    assert "\r" not in proc.stderr
    lines = proc.stderr.splitlines()
    assert [line.rsplit(" (", 1)[0] for line in lines] == [f"official u_maze: {k}/4 episodes" for k in range(1, 5)]


def test_a_sweep_writes_plain_progress_lines_when_stderr_is_no_terminal(tmp_path):
    proc = run_module("specrefine.runs.sweep", *SWEEP, "--out", tmp_path / "s")
    assert proc.returncode == 0, proc.stderr
    assert "\r" not in proc.stderr
    assert [line.rsplit(" (", 1)[0] for line in proc.stderr.splitlines()] == ["sweep (local, try 1): 1/1 cells"]
