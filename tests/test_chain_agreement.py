"""A run's path estimated leg by leg (chained) and as whole episodes (issue 39): the command's row, files, errors."""

from __future__ import annotations

import csv
import json
import math
import shutil
import subprocess
import sys

import pytest

from specrefine.experiments.chain_agreement import agreement


def test_the_row_holds_both_estimates_of_the_same_legs(finished_run):
    path = json.loads((finished_run / "result.json").read_text())["path"]
    row = agreement(finished_run, n=48)
    assert row["legs"] == len(path) - 1 >= 2 and row["n"] == 48
    chained = [int(s) for s in row["chain_successes"].split()]
    assert len(chained) == row["legs"] and all(0 <= s <= 48 for s in chained)
    assert row["chain_p"] == pytest.approx(math.prod(s / 48 for s in chained))
    lost = [int(v) for v in row["episode_lost_at"].split()]
    assert len(lost) == row["legs"] and sum(lost) == 48 - row["episode_successes"]
    assert row["episode_ci_low"] - 1e-9 <= row["episode_p"] <= row["episode_ci_high"] + 1e-9
    assert row["difference"] == pytest.approx(row["chain_p"] - row["episode_p"])
    low, high = row["difference_ci_low"], row["difference_ci_high"]
    assert low - 1e-9 <= row["difference"] <= high + 1e-9
    assert row["verdict"] == ("chain above" if low > 0 else "chain below" if high < 0 else "agree")
    first = agreement(finished_run, legs=1, n=48)
    assert first["legs"] == 1 and len(first["episode_lost_at"].split()) == 1
    assert first["chain_successes"] == row["chain_successes"].split()[0]  # the same seed draws the same first leg


def test_the_command_writes_its_tables_and_bad_runs_are_one_line(finished_run, tmp_path):
    cmd = [sys.executable, "-m", "specrefine.cli", "chain-agreement"]
    ok = subprocess.run(cmd + [str(finished_run), "--n", "16", "--out", str(tmp_path / "out")],
                        capture_output=True, text=True)
    assert ok.returncode == 0, ok.stderr
    (row,) = csv.DictReader((tmp_path / "out" / "agreement.csv").open())
    assert row["maze"] == "u_maze" and row["n"] == "16" and row["verdict"] in ("agree", "chain above", "chain below")
    assert "| u_maze | ours | geometric | 0 |" in (tmp_path / "out" / "agreement.md").read_text()

    def one_line(*args) -> str:
        bad = subprocess.run(cmd + [*map(str, args), "--n", "8"], capture_output=True, text=True)
        assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1, bad.stderr
        assert "Traceback" not in bad.stderr
        return bad.stderr

    assert "the run's path has" in one_line(finished_run, "--legs", "999")
    no_policy = tmp_path / "no_policy"
    shutil.copytree(finished_run, no_policy)
    (no_policy / "policy.json").unlink()
    assert "no compositional policy" in one_line(no_policy)
    other = tmp_path / "other"
    shutil.copytree(finished_run, other)
    policy = json.loads((other / "policy.json").read_text())
    (other / "policy.json").write_text(json.dumps(policy | {"legs": policy["legs"][:-1]}))
    assert "not one run's records" in one_line(other)
    late = tmp_path / "late"
    assert "no compositional policy" in one_line(finished_run, no_policy, "--out", late)  # checked before simulating
    assert not (late / "agreement.csv").exists()
