"""The corrector's diagnosis (issue 39): losses, the correction and its proposer splits, from hand-made run folders."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from specrefine.experiments.corrector_diagnosis import study
from specrefine.experiments.taxonomy import read_runs


def write_run(folder, *, method, proposer, legs, outcomes, calls, steps=(), maze="u_chain_5", seed=0):
    folder.mkdir(parents=True)
    path = ["S"] + [f"x{i}" for i in range(len(legs) - 1)] + ["G"]
    episodes = sum(outcomes.values())
    result = {"maze": maze, "agent": "point", "method": method, "proposer": proposer, "seed": seed,
              "success_rate": outcomes["success"] / episodes, "episodes": episodes, "path": path,
              "leg_success": legs, "episode_outcomes": outcomes, "proposer_calls": calls}
    (folder / "result.json").write_text(json.dumps(result))
    (folder / "steps.jsonl").write_text("".join(json.dumps(s) + "\n" for s in steps))


def leg(p_leg, tried, accepted, window=0.9):
    return {"event": "correct-leg", "p_leg": p_leg, "p_window": window, "accepted": accepted,
            "tried": [{"kind": kind, "p_window": p} for kind, p in tried]}


CORRECTOR_STEPS = [
    {"event": "correct-check", "path": ["S", "x0", "G"], "p": 0.8},
    leg(127 / 128, [("split", 0.9 + 1 / 128), ("resplit", 0.85)], "split"),  # one failure, a gain of 1 rollout
    leg(120 / 128, [("bypass", 0.95), ("split", 0.93)], "bypass"),  # 8 failures
    leg(126 / 128, [("split", 0.8)], None),  # two failures, nothing gained
    {"event": "correct-done", "path": ["S", "x0", "x1", "G"], "p": 0.99},
    {"event": "done", "splits_generated": 10, "max_edge_splits": 30}]


@pytest.fixture
def folders(tmp_path):
    write_run(tmp_path / "corrector" / "cells" / "a", method="ours-corrector", proposer="imperfect:mild",
              legs=[1.0, 0.99, 0.97], outcomes={"success": 192, "avoid": 6, "timeout": 2}, calls=20,
              steps=CORRECTOR_STEPS)
    write_run(tmp_path / "corrector" / "cells" / "other_maze", method="ours-corrector", proposer="imperfect:mild",
              maze="u_maze", legs=[1.0], outcomes={"success": 200}, calls=6, steps=CORRECTOR_STEPS)
    write_run(tmp_path / "taxonomy" / "cells" / "a", method="ours", proposer="imperfect:mild", legs=[0.5],
              outcomes={"success": 100, "avoid": 100}, calls=4)
    write_run(tmp_path / "taxonomy" / "cells" / "b", method="ours", proposer="imperfect:mild", maze="u_maze",
              legs=[1.0], outcomes={"success": 200}, calls=1)
    write_run(tmp_path / "taxonomy" / "oracle" / "cells" / "a", method="ours", proposer="geometric",
              legs=[1.0, 0.99], outcomes={"success": 198, "timeout": 2}, calls=2)
    return tmp_path


def test_the_losses_the_correction_and_its_splits_are_counted_from_the_folders(folders):
    s = study(read_runs([folders / "corrector"]), read_runs([folders / "taxonomy"]),
              read_runs([folders / "taxonomy" / "oracle"]))
    mine, oracle = s["losses"]["ours-corrector"], s["losses"]["oracle"]
    assert mine["runs"] == 1 and mine["outcomes"] == {"success": 192, "avoid": 6, "timeout": 2}  # u_chain_5 only
    assert mine["legs_per_path"] == 3 and mine["loss_per_leg"] == pytest.approx(0.04 / 3)
    assert mine["legs_losing"] == 2 and oracle["legs_per_path"] == 2
    c = s["correction"]
    assert (c["legs_at_check"], c["legs_at_end"], c["legs_corrected"], c["accepted"]) == (2, 3, 3, 2)
    assert c["accepted_by_kind"] == {"split": 1, "bypass": 1} and c["accepted_by_one_rollout"] == 1
    assert c["fresh_p_before"] == pytest.approx(0.8) and c["fresh_p_after"] == pytest.approx(0.99)
    bins = {e["fresh_failures"]: (e["legs"], e["splits"]) for e in s["splits_by_failures"]}
    assert bins == {"1": (2, 4), "2": (2, 2), "3": (0, 0), ">= 4": (2, 2)}  # both corrector runs, every maze
    mild = next(e for e in s["cost"] if e["proposer"] == "imperfect:mild")
    assert (mild["pairs"], mild["proposer_calls"], mild["ours_proposer_calls"]) == (2, 26, 5)
    assert mild["ratio"] == pytest.approx(26 / 5)
    # gate 2 drops the 2 splits of the one-failure leg of 10 Algorithm 1 calls in each run; gate 3 also the 1 of
    # the two-failure leg
    assert mild["projected_ratio_gate_2"] == pytest.approx(26 * 0.8 / 5)
    assert mild["projected_ratio_gate_3"] == pytest.approx(26 * 0.7 / 5)
    u_chains = next(e for e in s["cost_u_chains"] if e["proposer"] == "imperfect:mild")
    assert (u_chains["pairs"], u_chains["proposer_calls"], u_chains["ours_proposer_calls"]) == (1, 20, 4)


def test_the_command_writes_its_tables_and_a_folder_without_runs_is_one_line(folders, tmp_path):
    cmd = [sys.executable, "-m", "specrefine.cli", "corrector-diagnosis"]
    ok = subprocess.run(cmd + [str(folders / "corrector"), "--reference", str(folders / "taxonomy"), "--out",
                               str(tmp_path / "out")], capture_output=True, text=True)
    assert ok.returncode == 0, ok.stderr
    assert "| ours-corrector | 1 | 0.960 | 200 | 6 | 2 |" in (tmp_path / "out" / "diagnosis.md").read_text()
    assert json.loads((tmp_path / "out" / "diagnosis.json").read_text())["runs"] == 2
    (tmp_path / "empty").mkdir()
    bad = subprocess.run(cmd + [str(tmp_path / "empty"), "--reference", str(folders / "taxonomy")],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1 and "Traceback" not in bad.stderr
