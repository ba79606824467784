"""specrefine spend: a run's simulator steps phase by phase, read from its evaluation cache by each draw's seed."""

from __future__ import annotations

import csv
import json
import os

import numpy as np
import pytest

from specrefine.cli import main
from specrefine.experiments.spend import PACE_WINDOW_S, by_time, phase_offsets, recent_pace


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("spend") / "span"
    assert main(["refine", "u_chain_2", "--method", "ours-corrector-span", "--proposer", "imperfect:moderate",
                 "--seed", "1", "--rollouts", "8", "--episodes", "16", "--quiet", "--out", str(out)]) == 0
    return out


def test_every_phase_draws_at_its_own_offset():
    offsets = phase_offsets()
    assert offsets[0] == "search" and len(set(offsets.values())) == len(offsets) // 5  # five draws each: racing
    assert {"polish", "confirm", "tune-check", "pass 1", "pass 2", "pass 1 second draw"} <= set(offsets.values())


def test_draws_at_the_runs_own_seed_count_in_the_pass_running_when_they_were_written():
    entries = [("search", 1, 10), ("polish", 2, 10), ("pass 1", 5, 10), ("search", 6, 1), ("pass 1 second draw", 7, 1),
               ("pass 2", 9, 10), ("search", 9, 2), ("search", 12, 3), ("confirm", 13, 1), ("search", 4, 4)]
    own = "at the run's seed"
    moved = ["search", "polish", "pass 1", f"pass 1 {own}", "pass 1 second draw", "pass 2", f"pass 1 {own}",
             f"pass 2 {own}", "confirm", "search"]  # written in the tick pass 2 began: counted before it
    assert [phase for phase, _, _ in by_time(entries)] == moved


def test_the_phases_add_up_to_what_the_step_log_counted(run, tmp_path, capsys):
    table = tmp_path / "spend.csv"
    capsys.readouterr()
    assert main(["spend", str(run), "--out", str(table)]) == 0
    assert capsys.readouterr().out.startswith(f"{run.name}: ")
    rows = {row["phase"]: row for row in csv.DictReader(table.open())}
    assert {row["finished"] for row in rows.values()} == {"True"}
    steps = [json.loads(line) for line in (run / "steps.jsonl").read_text().splitlines()]
    begin, done = next(s for s in steps if s["event"] == "correct-begin"), steps[-1]
    assert "other" not in rows and {"search", "polish", "pass 1", "pass 2"} <= set(rows)
    count = lambda key, phases: sum(int(rows[p][key]) for p in phases if p in rows)  # noqa: E731
    passes = [p for p in rows if p.startswith("pass")]
    evaluations, steps = done["evaluations_so_far"], done["sim_steps_so_far"]
    assert count("evaluations", rows) == evaluations  # each cache entry simulated once, counted as it went
    assert count("evaluations", passes) == evaluations - begin["evaluations_so_far"]  # drawn after it began
    # an entry holds its episodes' rows; the counters also count the padding rows of batches shared by several tasks
    assert 0.9 * steps <= count("sim_steps", rows) <= steps
    assert 0.9 * (steps - begin["sim_steps_so_far"]) <= count("sim_steps", passes)
    assert sum(float(row["share_of_steps"]) for row in rows.values()) == pytest.approx(1.0, abs=1e-3)


def test_a_run_not_finished_is_read_as_far_as_its_cache_goes(run, tmp_path, capsys):
    import shutil

    going = tmp_path / "going"
    shutil.copytree(run, going)
    (going / "result.json").unlink()
    (going / "steps.jsonl").rename(going / ".steps.jsonl.1.tmp")
    for entry in sorted((going / "cache").rglob("*.npz"))[::2]:  # as a kill leaves it: part of the work done
        entry.unlink()
    table = tmp_path / "going.csv"
    capsys.readouterr()
    assert main(["spend", str(going), "--out", str(table)]) == 0
    assert "simulator steps so far (not finished): " in capsys.readouterr().out
    rows = list(csv.DictReader(table.open()))
    assert {row["finished"] for row in rows} == {"False"}
    entries = len(list((going / "cache").rglob("*.npz")))
    assert sum(int(row["evaluations"]) for row in rows) == entries
    os.mkfifo(going / "cache" / "fifo.npz")  # never opened: reading it would wait forever
    (going / "cache" / "link.npz").symlink_to(next((run / "cache").rglob("*.npz")))
    assert main(["spend", str(going), "--out", str(table)]) == 0
    assert sum(int(row["evaluations"]) for row in csv.DictReader(table.open())) == entries
    (going / "run.json").write_text('{"seed": "two"}')
    assert main(["spend", str(going)]) == 2
    assert "not a run's record" in capsys.readouterr().err


def test_a_run_still_going_is_paced_by_the_steps_its_cache_gained_lately(run, tmp_path, capsys):
    import shutil
    import time

    going = tmp_path / "paced"
    shutil.copytree(run, going)
    (going / "result.json").unlink()
    entries = sorted((going / "cache").rglob("*.npz"))
    hour_ago = time.time() - 3600
    for entry in entries:  # all written an hour ago but the last two, written now
        os.utime(entry, (hour_ago, hour_ago))
    recent = sum(int(np.load(e)["steps"]) for e in entries[-2:])
    for entry in entries[-2:]:
        entry.touch()
    assert recent_pace(going / "cache", time.time_ns()) == pytest.approx(recent / PACE_WINDOW_S)
    assert recent_pace(going / "cache", time.time_ns(), window_s=7200) == pytest.approx(
        sum(int(np.load(e)["steps"]) for e in entries) / 7200)
    capsys.readouterr()
    assert main(["spend", str(going), str(run)]) == 0
    lines = capsys.readouterr().out.splitlines()
    pace = f"  {recent / PACE_WINDOW_S / 1e3:.1f}k simulator steps/s over the last 30 min"
    assert [line.startswith(pace) for line in lines] == [False, True, False]  # the finished run has no pace


@pytest.mark.parametrize("make", ["missing", "empty"])
def test_a_folder_with_no_finished_run_is_one_line(tmp_path, capsys, make):
    folder = tmp_path / "runs"
    if make == "empty":
        folder.mkdir()
    assert main(["spend", str(folder)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and (str(folder) in err or "no run with an evaluation cache" in err)


@pytest.mark.parametrize("out", ["device", "link", "folder"])
def test_out_that_is_no_regular_file_is_refused_before_any_work(run, tmp_path, capsys, out):
    target = tmp_path / "target.csv"
    target.write_text("kept\n")
    path = {"device": "/dev/null", "link": tmp_path / "link.csv", "folder": tmp_path}[out]
    if out == "link":
        path.symlink_to(target)
    capsys.readouterr()
    assert main(["spend", str(run), "--out", str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and len(captured.err.strip().splitlines()) == 1 and "--out" in captured.err
    assert target.read_text() == "kept\n"
