"""The failure taxonomy (issue 39): one cause per run below the oracle, from hand-made run folders."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import pytest

from specrefine.core.mazes import random_name
from specrefine.experiments import taxonomy as tx
from specrefine.experiments.taxonomy import CAUSES, classify, read_runs


def write_run(folder, *, success, estimates, measured, steps, method="ours", maze="u_chain_3"):
    folder.mkdir(parents=True)
    path = ["S"] + [f"x{i}" for i in range(len(estimates) - 1)] + ["G"]
    result = {"maze": maze, "agent": "point", "method": method, "proposer": "imperfect:mild", "seed": 0,
              "success_rate": success, "episodes": 200, "path": path, "edge_probabilities": estimates,
              "leg_success": measured, "proposer_calls": 3}
    (folder / "result.json").write_text(json.dumps(result))
    (folder / "steps.jsonl").write_text("".join(json.dumps(s) + "\n" for s in steps))


def done(splits=3, budget=30):
    return {"event": "done", "splits_generated": splits, "max_edge_splits": budget}


@pytest.fixture
def sweep(tmp_path):
    cells = tmp_path / "sweep" / "cells"
    dead_split = {"event": "split-generated", "edge": ["S", "G"], "candidates": [{"p": 0.0}]}
    write_run(cells / "declined", success=0.0, estimates=[0.0], measured=[0.0], steps=[dead_split, done()])
    write_run(cells / "gave_up", success=0.0, estimates=[0.0], measured=[0.0], method="ours-repair",
              steps=[dead_split, {"event": "split-repaired", "edge": ["S", "G"], "p_after": None}, done()])
    write_run(cells / "budget", success=0.0, estimates=[0.0], measured=[0.0], steps=[dead_split, done(30, 30)])
    write_run(cells / "nothing", success=0.0, estimates=[0.0], measured=[0.0],
              steps=[{"event": "split-generated", "edge": ["S", "G"], "candidates": []}, done()])
    write_run(cells / "lucky", success=0.80, estimates=[1.0, 1.0], measured=[1.0, 0.80], steps=[done()])
    write_run(cells / "weak", success=0.80, estimates=[0.9, 0.9], measured=[0.9, 0.89], steps=[done()])
    write_run(cells / "unstarted", success=0.0, estimates=[1.0, 1.0, 1.0], measured=[1.0, 0.0, None],
              steps=[done()])  # no episode started the last leg: its measured success is null
    write_run(cells / "fine", success=0.99, estimates=[1.0], measured=[0.99], steps=[done()])
    (cells / "unfinished").mkdir()
    (tmp_path / "oracle.csv").write_text("maze,method,proposer,status,success_rate\n"
                                         "u_chain_3,ours,geometric,ok,0.99\nu_chain_3,ours,geometric,ok,1.0\n")
    return tmp_path


def test_each_run_below_the_oracle_gets_its_first_cause(sweep):
    runs = read_runs([sweep / "sweep"])
    assert len(runs) == 8  # the unfinished folder is not a run
    rows = {r["cell"]: r for r in classify(runs, {"u_chain_3": 0.995})}
    assert "fine" not in rows  # within 0.05 of the oracle
    assert {cell: r["cause"] for cell, r in rows.items()} == {
        "declined": "split-declined-dead-legs", "gave_up": "repair-gave-up", "budget": "budget-spent",
        "nothing": "no-split-offered", "lucky": "estimate-refuted", "weak": "weak-legs-accepted",
        "unstarted": "estimate-refuted"}
    assert rows["budget"]["flags"] == "budget-spent split-declined-dead-legs"
    assert rows["lucky"]["refuted_legs"] == 1 and rows["weak"]["refuted_legs"] == 0
    assert set(r["cause"] for r in rows.values()) == set(CAUSES)


def test_the_command_writes_the_table_and_the_summary(sweep):
    out = sweep / "out"
    proc = subprocess.run([sys.executable, "-m", "specrefine.experiments.taxonomy", str(sweep / "sweep"),
                           "--oracle", str(sweep / "oracle.csv"), "--out", str(out)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    rows = list(csv.DictReader((out / "taxonomy.csv").open()))
    assert len(rows) == 7 and {r["cause"] for r in rows} == set(CAUSES)
    md = (out / "taxonomy.md").read_text()
    assert "| ours | imperfect:mild | 7 | 6 | 1 | 0 | 1 | 1 | 2 | 1 |" in md


def test_a_missing_oracle_is_one_line(sweep, tmp_path):
    proc = subprocess.run([sys.executable, "-m", "specrefine.experiments.taxonomy", str(sweep / "sweep"),
                           "--oracle", str(tmp_path / "nope.csv")], capture_output=True, text=True)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1


def test_a_folder_another_command_is_writing_is_refused_in_one_line(sweep):
    from specrefine.core.runfolder import locked

    out = sweep / "busy"
    out.mkdir()
    with locked(out):  # another holder of the folder's lock (a sweep, or a second analysis command)
        proc = subprocess.run([sys.executable, "-m", "specrefine.experiments.taxonomy", str(sweep / "sweep"),
                               "--oracle", str(sweep / "oracle.csv"), "--out", str(out)], capture_output=True,
                              text=True)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1 and "in use" in proc.stderr
    assert sorted(p.name for p in out.iterdir()) == []


def test_the_oracle_of_a_generated_layout_is_found_under_the_name_its_runs_record(tmp_path):
    table = tmp_path / "oracle.csv"
    table.write_text("maze,method,proposer,status,success_rate\nrandom:5x7:44,ours,geometric,ok,1.0\n"
                     "random:5x7:44,ours,geometric,ok,0.99\nu_chain_2,ours,geometric,ok,0.9\n")
    assert tx.oracle_means(table) == pytest.approx({"random_5x7_s44": 0.995, "u_chain_2": 0.9})
    assert random_name(" Random:5X7:44 ") == "random_5x7_s44" and random_name("unseen/zigzag") == "unseen/zigzag"
