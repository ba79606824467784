"""scripts/per_maze_report.py: the closing notes' per-maze lines pool episodes, not rates."""
import importlib.util
from pathlib import Path

from specrefine.core.results import wilson_ci
from specrefine.runs.sweep import _NUMBERS

_spec = importlib.util.spec_from_file_location("per_maze_report",
                                               Path(__file__).parents[1] / "scripts" / "per_maze_report.py")
report = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(report)


def _row(seed, rate, episodes, lo=0.5, hi=0.9, status="ok"):
    return {key: 1 for key in _NUMBERS} | {"maze": "m", "seed": seed, "status": status, "error": "",
            "success_rate": rate, "episodes": episodes,
            "success_ci_low": 0.0, "success_ci_high": 1.0, "predicted_success": 0.7, "predicted_ci_low": lo,
            "predicted_ci_high": hi, "evaluations": 10 * (seed + 1), "sim_steps": 1_000_000, "wall_seconds": 60.0}


def test_pooled_line_pools_episodes_and_counts_inside():
    rows = [_row(0, 0.8, 200), _row(1, 0.5, 100, lo=0.6), _row(2, 0.0, 0, status="error")]
    line = report.pooled_line("m", rows)
    lo, hi = wilson_ci(210, 300)
    assert f"2 of 3 | 210/300 = 0.700 [{lo:.3f}, {hi:.3f}] (0.800, 0.500)" in line
    assert "(1 of 2 inside)" in line and "| 15 | 1.00M | 60 |" in line
    assert report.pooled_line("m", [rows[2]]).startswith("| m | 0 of 1 |")


def test_without_method_one_section_per_method_and_proposer(tmp_path, monkeypatch, capsys):
    import csv

    rows = [_row(0, 0.8, 200) | {"method": "ours", "proposer": "geometric"},
            _row(0, 0.0, 200) | {"method": "dirl", "proposer": "none"},
            _row(1, 0.9, 200) | {"method": "ours", "proposer": "geometric"}]
    table = tmp_path / "t.csv"
    with open(table, "w", newline="") as fh:
        w = csv.DictWriter(fh, list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    monkeypatch.setattr("sys.argv", ["per_maze_report.py", str(table), "--pooled"])
    report.main()
    out = capsys.readouterr().out
    assert out.index("dirl / none: 1 runs") < out.index("ours / geometric: 2 runs")
    assert "| m | 2 of 2 | 340/400 = 0.850" in out and "| m | 1 of 1 | 0/200 = 0.000" in out


def test_a_closed_stdout_ends_quietly(tmp_path):
    """`per_maze_report.py TABLE | head`: exit 1 without a traceback once the reader has gone."""
    import csv
    import os
    import subprocess
    import sys

    table = tmp_path / "t.csv"
    with open(table, "w", newline="") as fh:
        w = csv.DictWriter(fh, list(_row(0, 0.8, 200)) + ["method", "proposer"])
        w.writeheader()
        w.writerow(_row(0, 0.8, 200) | {"method": "ours", "proposer": "geometric"})
    read_end, write_end = os.pipe()
    os.close(read_end)
    proc = subprocess.run([sys.executable, str(Path(__file__).parents[1] / "scripts" / "per_maze_report.py"),
                           str(table)], stdout=write_end, stderr=subprocess.PIPE, text=True)
    os.close(write_end)
    assert (proc.returncode, proc.stderr) == (1, "")
