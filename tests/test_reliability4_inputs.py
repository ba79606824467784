"""Issue 40 (reliability, round 4), part B: every file a command reads is checked before any work (one schema for a
run's policy.json and result.json, capped maze sizes, finite observations), and sim_steps is one number however a
run got there."""

from __future__ import annotations

import json
import random
from pathlib import Path

from specrefine.cli import main as cli_main

ROOT = Path(__file__).resolve().parent.parent


# --- item 17: sim_steps after a rerun or a resume ------------------------------------------------------------
CHAIN = ["refine", "u_chain_3", "--agent", "point", "--method", "ours", "--proposer", "imperfect:moderate", "--seed",
         "0", "--rollouts", "8", "--episodes", "20", "--quiet"]


def test_sim_steps_are_the_same_after_a_rerun_and_after_a_resume_from_part_of_the_cache(tmp_path):
    out = tmp_path / "run"
    record = lambda: json.loads((out / "result.json").read_text())  # noqa: E731
    assert cli_main([*CHAIN, "--out", str(out)]) == 0
    first = record()
    assert cli_main([*CHAIN, "--out", str(out)]) == 0  # a rerun into the finished folder: every evaluation cached
    rerun = record()
    cache = sorted((out / "cache").rglob("*.npz"))
    for entry in random.Random(40).sample(cache, len(cache) // 2):  # as a kill leaves it: part of the work kept
        entry.unlink()
    (out / "result.json").unlink()
    assert cli_main([*CHAIN, "--out", str(out)]) == 0
    resumed = record()
    assert first["sim_steps"] == first["sim_steps_simulated"]
    assert rerun["sim_steps"] == resumed["sim_steps"] == first["sim_steps"]
    assert rerun["sim_steps_simulated"] < resumed["sim_steps_simulated"] < first["sim_steps_simulated"]
    assert rerun["path"] == resumed["path"] == first["path"]
    assert rerun["evaluations"] == resumed["evaluations"] == first["evaluations"]
