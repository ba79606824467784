"""The correction ledger (issue 39): one row per corrected run, from hand-made run folders."""

from __future__ import annotations

import csv
import io
import json
import subprocess
import sys

import pytest

from specrefine.core.tables import csv_text
from specrefine.experiments.correction_ledger import BEFORE_CALLS, COLUMNS, ledger, length_trend
from specrefine.experiments.taxonomy import read_runs


def write_run(folder, *, steps, success=180, maze="u_chain_4", seed=0, method="ours-corrector-redraw", calls=19):
    folder.mkdir(parents=True)
    result = {"maze": maze, "agent": "ant", "method": method, "proposer": "imperfect:moderate", "seed": seed,
              "success_rate": success / 200, "episodes": 200, "path": ["S", "a", "G"], "proposer_calls": calls}
    (folder / "result.json").write_text(json.dumps(result))
    (folder / "steps.jsonl").write_text("".join(json.dumps(s) + "\n" for s in steps))


def leg(accepted, *tried):
    return {"event": "correct-leg", "p_leg": 0.9, "p_window": 0.8, "accepted": accepted, "tried": list(tried)}


TWO_PASSES = [
    {"event": "correct-check", "path": ["S", "G"], "p": 0.5, "correct_pass": 1, "proposer_calls": 7},
    leg("split", {"kind": "split", "p_window": 0.9}, {"kind": "bypass", "p_window": 0.7}),
    leg(None, {"kind": "split", "p_window": 0.95, "p_window_second": 0.8, "p_current_second": 0.85}),  # refuted
    {"event": "correct-done", "path": ["S", "a", "b", "G"], "p": 0.97, "correct_pass": 1},
    {"event": "correct-check", "path": ["S", "a", "b", "G"], "p": 0.93, "correct_pass": 2, "proposer_calls": 15},
    leg("bypass", {"kind": "bypass", "p_window": 0.99, "p_window_second": 0.98, "p_current_second": 0.9}),
    {"event": "correct-done", "path": ["S", "a", "G"], "p": 0.99, "correct_pass": 2},
    {"event": "done"}]


@pytest.fixture
def sweep(tmp_path):
    write_run(tmp_path / "sweep" / "cells" / "redrawn", steps=TWO_PASSES)
    write_run(tmp_path / "sweep" / "cells" / "uncorrected", steps=[{"event": "done"}], method="ours", seed=1)
    write_run(tmp_path / "sweep" / "cells" / "unfinished", steps=TWO_PASSES[:3], seed=2)
    return tmp_path / "sweep"


def test_a_run_s_passes_taken_alternatives_refutations_and_last_check_are_read(sweep):
    (row,) = ledger(read_runs([sweep]))  # the uncorrected and the unfinished runs have no row
    assert (row["passes"], row["legs_at_check"], row["legs_at_end"], row["legs_tried"]) == (2, 1, 2, 3)
    assert (row["taken"], row["taken_by_kind"], row["refuted"]) == (2, "bypass:1 split:1", 1)
    assert row["check_p"] == 0.5 and row["pass_end_p"] == "0.9700;0.9900" and row["last_p"] == 0.99
    assert row["last_p_minus_success"] == pytest.approx(0.09)
    assert row["last_p_above_interval"] is True  # 0.99 is above the Wilson interval of 180 of 200
    assert (row["proposer_calls"], row["search_calls"], row["pass_calls"]) == (19, 7, "8;4")
    table = list(csv.DictReader(io.StringIO(csv_text([row], COLUMNS))))
    assert table[0]["taken_by_kind"] == "bypass:1 split:1" and float(table[0]["last_p"]) == pytest.approx(0.99)


def test_the_command_writes_its_tables_and_a_folder_without_corrections_is_one_line(sweep, tmp_path):
    cmd = [sys.executable, "-m", "specrefine.cli", "correction-ledger"]
    ok = subprocess.run(cmd + [str(sweep), "--out", str(tmp_path / "out")], capture_output=True, text=True)
    assert ok.returncode == 0, ok.stderr
    md = (tmp_path / "out" / "ledger.md").read_text()
    assert "| ours-corrector-redraw | imperfect:moderate | 1 | 0.500 | 0.990 | 0.900 | +0.090 | 1 of 1 |" in md
    assert "(imperfect:moderate): 19.0 a run over 1 run: search 7.0, pass 1 8.0, pass 2 4.0" in md
    assert md.rstrip().endswith("| 0.9700, 0.9900 | 0.900 | 7 + 8 + 4 |")
    assert len((tmp_path / "out" / "ledger.csv").read_text().splitlines()) == 2
    assert (tmp_path / "out" / "ledger.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    bad = subprocess.run(cmd + [str(sweep / "cells" / "uncorrected")], capture_output=True, text=True)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1 and "Traceback" not in bad.stderr


def test_keep_carries_the_rows_of_runs_whose_folders_are_gone(sweep, tmp_path):
    """A new machine has lost earlier runs' folders: --keep keeps their ledger rows, byte for byte, and a cell given
    again gets its row from its folder; without --keep the ledger is what the folders given hold."""
    import shutil

    cmd = [sys.executable, "-m", "specrefine.cli", "correction-ledger"]
    out = tmp_path / "out"
    assert subprocess.run(cmd + [str(sweep), "--out", str(out)], capture_output=True, text=True).returncode == 0
    first = (out / "ledger.csv").read_text().splitlines()
    later = tmp_path / "later"
    write_run(later / "cells" / "u_chain_5", steps=TWO_PASSES, maze="u_chain_5", success=170)
    kept = subprocess.run(cmd + [str(later), "--out", str(out), "--keep"], capture_output=True, text=True)
    assert kept.returncode == 0 and "2 runs with a correction (1 kept from the ledger)" in kept.stdout, kept.stderr
    lines = (out / "ledger.csv").read_text().splitlines()
    assert len(lines) == 3 and first[1] in lines and any(line.startswith("u_chain_5,u_chain_5,") for line in lines)
    assert "| ours-corrector-redraw | imperfect:moderate | 2 |" in (out / "ledger.md").read_text()
    shutil.rmtree(sweep / "cells" / "redrawn")  # the same cell again, measured differently: its folder's row wins
    write_run(sweep / "cells" / "redrawn", steps=TWO_PASSES, success=150)
    assert subprocess.run(cmd + [str(sweep), "--out", str(out), "--keep"], capture_output=True,
                          text=True).returncode == 0
    rows = list(csv.DictReader(io.StringIO((out / "ledger.csv").read_text())))
    assert sorted((r["cell"], float(r["success_rate"])) for r in rows) == [("redrawn", 0.75), ("u_chain_5", 0.85)]
    assert subprocess.run(cmd + [str(later), "--out", str(out)], capture_output=True, text=True).returncode == 0
    assert len((out / "ledger.csv").read_text().splitlines()) == 2  # without --keep: the folders given only


def test_a_run_or_a_ledger_from_before_the_call_counts_keeps_its_calls_unknown(sweep, tmp_path):
    """A step log without the checks' proposer calls gives no calls; a ledger written before the calls were read is
    still kept by --keep, its calls unknown, and the summary counts only the runs whose calls are known."""
    cmd = [sys.executable, "-m", "specrefine.cli", "correction-ledger"]
    old_steps = [{k: v for k, v in s.items() if k != "proposer_calls"} for s in TWO_PASSES]
    write_run(tmp_path / "old" / "cells" / "u_chain_5", steps=old_steps, maze="u_chain_5")
    (row,) = ledger(read_runs([tmp_path / "old"]))
    assert (row["proposer_calls"], row["search_calls"], row["pass_calls"]) == ("", "", "")
    out = tmp_path / "out"
    out.mkdir()
    before = [{k: v for k, v in row.items() if k in BEFORE_CALLS}]
    (out / "ledger.csv").write_text(csv_text(before, BEFORE_CALLS))
    kept = subprocess.run(cmd + [str(sweep), "--out", str(out), "--keep"], capture_output=True, text=True)
    assert kept.returncode == 0 and "(1 kept from the ledger)" in kept.stdout, kept.stderr
    md = (out / "ledger.md").read_text()
    assert "19.0 a run over 1 run: search 7.0, pass 1 8.0, pass 2 4.0" in md and "| 0.900 |  |" in md


def test_keep_refuses_a_file_that_is_not_its_ledger_and_needs_out(sweep, tmp_path):
    cmd = [sys.executable, "-m", "specrefine.cli", "correction-ledger", str(sweep)]
    out = tmp_path / "out"
    out.mkdir()
    (out / "ledger.csv").write_text("cell,maze\nx,y\n")
    for argv in (["--out", str(out), "--keep"], ["--keep"]):
        done = subprocess.run(cmd + argv, capture_output=True, text=True)
        assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, done.stderr
        assert "Traceback" not in done.stderr
    assert (out / "ledger.csv").read_text() == "cell,maze\nx,y\n" and not (out / "ledger.md").exists()


def test_the_length_trend_is_the_least_squares_slope_of_the_gap_on_the_legs():
    rows = [{"legs_at_end": n, "last_p_minus_success": 0.01 + 0.002 * n} for n in (10, 30, 60)]
    assert length_trend(rows) == "+0.020 per 10 legs (Pearson r +1.00) over 3 runs of 10-60 legs"
    assert length_trend(rows[:2]) == "2 runs, too few or too alike for a trend"
