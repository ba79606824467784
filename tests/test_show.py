"""A run a person can judge at a glance: the input task beside the refined one, and `specrefine show RUN`."""

from __future__ import annotations

import json
import re

import pytest

from specrefine.cli import main

TINY = ["--rollouts", "8", "--episodes", "16", "--quiet"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("show")
    assert main(["refine", "split_doorway", "--method", "ours", "--proposer", "geometric", "--out",
                 str(root / "ours"), *TINY]) == 0
    assert main(["refine", "split_doorway", "--method", "dirl", "--out", str(root / "dirl"), *TINY]) == 0
    return root


def test_the_summary_puts_the_input_task_before_the_refined_one(runs, capsys):
    data = json.loads((runs / "ours" / "result.json").read_text())
    before = data["input_task"]
    assert before["path"] == ["S", "G"] and before["episodes"] == 16
    assert before["success_rate"] == 0.0 and before["estimate"] == 0.0  # straight through the doorway's wall
    assert data["success_rate"] > before["success_rate"]
    capsys.readouterr()
    assert main(["show", str(runs / "ours")]) == 0
    out = capsys.readouterr().out
    assert f"success on the original task: input 0.000 -> refined {data['success_rate']:.3f}" in out
    assert f"estimated: input 0.000 -> refined {data['search_estimate']:.3f}" in out
    assert "a refinement of the input (checked" in out


def test_dirl_is_not_called_a_refinement(runs, capsys):
    data = json.loads((runs / "dirl" / "result.json").read_text())
    assert data["input_task"]["success_rate"] == data["success_rate"]  # its path is the input's: measured once
    capsys.readouterr()
    assert main(["show", str(runs / "dirl")]) == 0
    out = capsys.readouterr().out
    assert "the input graph itself (dirl refined nothing)" in out
    assert "refines input" not in out and "-> refined" not in out


def test_show_gives_the_path_leg_by_leg_the_time_and_the_pictures(runs, capsys):
    run = runs / "ours"
    data = json.loads((run / "result.json").read_text())
    capsys.readouterr()
    assert main(["show", str(run)]) == 0
    out = capsys.readouterr().out
    legs = [line for line in out.splitlines() if re.match(r"\s+\d+\. ", line)]
    path = data["path"]
    assert len(legs) == len(path) - 1
    for line, u, v, p in zip(legs, path, path[1:], data["edge_probabilities"]):
        assert f"{u} -> {v}" in line and f"estimate {p:.3f}" in line
    assert "the input task's path: S -> G" in out
    time_line = next(line for line in out.splitlines() if line.startswith("time: "))
    for phase in ("search", "measurement", "calibration", "setup", "input task"):
        assert phase in time_line
    assert str(run / "refined.png") in out and str(run / "graph.png") in out
    assert "official environment: not run" in out


@pytest.mark.parametrize("content", [None, "{x", "[]", '{"maze": "u_maze", "agent": "point"}', "fifo", "folder"])
def test_show_refuses_what_is_not_a_run_in_one_line(tmp_path, capsys, content):
    import os

    if content == "fifo":  # refused unopened: reading it would wait forever
        os.mkfifo(tmp_path / "result.json")
    elif content == "folder":
        (tmp_path / "result.json").mkdir()
    elif content is not None:
        (tmp_path / "result.json").write_text(content)
    assert main(["show", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "result.json" in err


def test_show_gives_what_the_run_asked_and_where_the_correction_spent_it(runs, tmp_path, capsys):
    ours = json.loads((runs / "ours" / "result.json").read_text())
    capsys.readouterr()
    assert main(["show", str(runs / "ours")]) == 0
    out = capsys.readouterr().out
    assert f"cost: {ours['proposer_calls']} proposer calls, {ours['evaluations']} evaluations\n" in out  # no correction
    assert f"\nspent: search {ours['evaluations']:,} evaluations (" in out  # the search, then the measurement
    assert "correction" not in out.split("spent:")[1].splitlines()[0]
    run = tmp_path / "corrector"
    assert main(["refine", "u_chain_2", "--method", "ours-corrector", "--proposer", "imperfect:moderate", "--seed", "1",
                 "--out", str(run), *TINY]) == 0
    data = json.loads((run / "result.json").read_text())
    steps = [json.loads(line) for line in (run / "steps.jsonl").read_text().splitlines()]
    before = next(s["proposer_calls"] for s in steps if s["event"] == "correct-check")
    capsys.readouterr()
    assert main(["show", str(run)]) == 0
    out = capsys.readouterr().out
    assert f"(proposer calls: {before} in the search, {data['proposer_calls'] - before} in the correction)" in out
    begin = next(i for i, s in enumerate(steps) if s["event"] == "correct-begin")
    assert steps[begin + 1]["event"] == "correct-check"
    spent = re.search(r"spent: search ([\d,]+) evaluations \(.*\), correction ([\d,]+) evaluations", out)
    searched, corrected = (int(n.replace(",", "")) for n in spent.groups())
    assert searched == steps[begin]["evaluations_so_far"] > 0
    assert corrected >= len(steps[begin + 1]["path"]) - 1  # its first check estimates every leg on fresh rollouts
    assert searched + corrected == data["evaluations"] == steps[-1]["evaluations_so_far"]


def test_show_splits_a_rescued_runs_correction_from_its_rescue(tmp_path, capsys):
    run = tmp_path / "rescue"
    assert main(["refine", "u_chain_1", "--method", "ours-corrector-redraw-rescue", "--proposer",
                 "imperfect:p_drop_turn=1,rho=0", "--seed", "0", "--out", str(run), *TINY]) == 0
    data = json.loads((run / "result.json").read_text())
    steps = [json.loads(line) for line in (run / "steps.jsonl").read_text().splitlines()]
    begun, rescue = (next(s for s in steps if s["event"] == event) for event in ("correct-begin", "rescue"))
    capsys.readouterr()
    assert main(["show", str(run)]) == 0
    out = capsys.readouterr().out
    calls = (begun["proposer_calls"], rescue["proposer_calls"] - begun["proposer_calls"],
             data["proposer_calls"] - rescue["proposer_calls"])
    assert "(proposer calls: {} in the search, {} in the correction, {} in its rescue)".format(*calls) in out
    spent = re.search(r"spent: search ([\d,]+) evaluations \(.*\), correction ([\d,]+) evaluations \(.*\), "
                      r"rescue ([\d,]+) evaluations", out)
    assert sum(int(n.replace(",", "")) for n in spent.groups()) == data["evaluations"]
    assert int(spent.group(3).replace(",", "")) > 0


def unfinished(runs, tmp_path, pid: int, half_line: bool = True):
    """The 'ours' run as a killed or running one would leave it: no result.json, its step log under the temporary
    name the run writes it to (the last line half-written)."""
    import shutil

    run = tmp_path / "unfinished"
    shutil.copytree(runs / "ours", run)
    (run / "result.json").unlink()
    log = run / f".steps.jsonl.{pid}.tmp"
    (run / "steps.jsonl").rename(log)
    if half_line:
        with log.open("a") as fh:
            fh.write('{"step": 999, "event": "exp')
    return run, [json.loads(line) for line in (runs / "ours" / "steps.jsonl").read_text().splitlines()]


def test_show_tells_an_interrupted_run_by_its_step_log_so_far(runs, tmp_path, capsys):
    run, steps = unfinished(runs, tmp_path, pid=4242)
    capsys.readouterr()
    assert main(["show", str(run)]) == 0
    out = capsys.readouterr().out
    assert out.startswith("split_doorway · point · ours · geometric · seed 0: not finished")
    assert "state: interrupted (no live process holds the folder): the same command resumes it" in out
    assert f"so far: {len(steps)} search steps (" in out  # the half-written line is not a step
    expands = sum(s["event"] == "expand" for s in steps)
    assert f"expand {expands}" in out and f"{steps[-1]['proposer_calls']} proposer calls" in out
    assert "search done" in out and "correction:" not in out  # ours has no correction


def test_show_tells_a_running_run_and_its_correction_so_far(runs, tmp_path, capsys):
    import os

    from specrefine.core.runfolder import _start_time

    run, _ = unfinished(runs, tmp_path, pid=os.getpid(), half_line=False)
    (run / ".lock").write_text(f"{os.getpid()} {_start_time(os.getpid())}\n")
    log = run / f".steps.jsonl.{os.getpid()}.tmp"
    with log.open("a") as fh:
        for step in ({"step": 50, "event": "correct-check", "path": ["S", "x0", "x1", "G"], "p": 0.5},
                     {"step": 51, "event": "correct-leg", "accepted": "split", "proposer_calls": 7},
                     {"step": 52, "event": "correct-leg", "accepted": None, "proposer_calls": 8},
                     {"step": 53, "event": "correct-done", "path": ["S", "x0", "x2", "x1", "G"], "p": 0.9}):
            fh.write(json.dumps(step) + "\n")
    capsys.readouterr()
    assert main(["show", str(run)]) == 0
    out = capsys.readouterr().out
    assert f"state: running (pid {os.getpid()})" in out and ", 8 proposer calls" in out
    assert "correction: the found path's fresh check 0.500 over 3 legs; 2 legs tried, 1 alternative taken (split 1)" \
        in out
    assert "last step: correct-done (#53), " in out  # not "search done": another pass may follow
    with log.open("a") as fh:  # a second pass on a fresh draw (correct_passes=2) begins
        fh.write(json.dumps({"step": 54, "event": "correct-check", "path": ["S", "x0", "x2", "x1", "G"], "p": 0.8,
                             "correct_pass": 2}) + "\n")
    assert main(["show", str(run)]) == 0
    assert "fresh check 0.500 over 3 legs; pass 2's fresh check 0.800 over 4 legs; 2 legs tried" in \
        capsys.readouterr().out


def test_show_reads_no_linked_step_log_and_a_folder_no_run_started_in_is_refused(runs, tmp_path, capsys):
    target = tmp_path / "elsewhere.jsonl"
    target.write_text('{"step": 0, "event": "expand"}\n')
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / ".steps.jsonl.7.tmp").symlink_to(target)
    assert main(["show", str(empty)]) == 2
    assert "result.json" in capsys.readouterr().err


def test_show_gives_a_sweep_cell_by_cell_done_running_stopped_and_failed(tmp_path, capsys):
    import csv
    import os

    from specrefine.core.runfolder import _start_time
    from specrefine.runs.sweep import grid, read_table, run_sweep

    cells = grid(["u_maze"], ["dirl"], ["geometric"], [0, 1, 2, 3], agent="point", rollouts=8, episodes=16)
    table = run_sweep(cells, tmp_path, workers=1)
    rows = read_table(table)
    done, running, stopped, failed = rows
    with table.open() as fh:
        raw = list(csv.DictReader(fh))
    raw[3].update(status="failed", error="RuntimeError: boom")
    with table.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(raw[0]))
        writer.writeheader()
        writer.writerows([raw[0], raw[3]])
    for row, live in ((running, True), (stopped, False)):
        folder = tmp_path / "cells" / row["cell"]
        (folder / "result.json").unlink()
        (folder / "steps.jsonl").rename(folder / f".steps.jsonl.{os.getpid()}.tmp")
        if live:
            (folder / ".lock").write_text(f"{os.getpid()} {_start_time(os.getpid())}\n")
    capsys.readouterr()
    assert main(["show", str(tmp_path)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"sweep {tmp_path}: 4 cells begun (1 done, 1 running, 1 stopped, 1 failed)"
    state = {line.split()[1]: line.split()[0] for line in out[1:]}
    assert state == {done["cell"]: "done", running["cell"]: "running", stopped["cell"]: "stopped",
                     failed["cell"]: "failed"}
    first = next(line for line in out if done["cell"] in line)
    assert f"{done['success_rate']:.3f} [{done['success_ci_low']:.3f}, " in first and "RuntimeError: boom" in out[-1]


def test_show_tells_a_run_measured_but_not_yet_written(runs, tmp_path, capsys):
    """Once measured, the step log has its own name while the run measures the input task and draws its pictures."""
    import shutil

    run = tmp_path / "measured"
    shutil.copytree(runs / "ours", run)
    (run / "result.json").unlink()
    capsys.readouterr()
    assert main(["show", str(run)]) == 0
    out = capsys.readouterr().out
    assert "state: interrupted" in out and "search, measurement and calibration done, " in out
