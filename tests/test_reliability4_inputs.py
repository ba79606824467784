"""Issue 40 (reliability, round 4), part B: every file a command reads is checked before any work (one schema for a
run's policy.json and result.json, capped maze sizes, finite observations), and sim_steps is one number however a
run got there."""

from __future__ import annotations

import json
import os
import random
import subprocess
import sys
from pathlib import Path

import pytest

from specrefine.cli import main as cli_main
from specrefine.core.errors import MazeError
from specrefine.core.mazes import Maze, load_maze

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


# --- item 13: maze sizes are capped where they are parsed ---------------------------------------------------------
def _cli(*args, timeout=60) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-m", "specrefine.cli", *map(str, args)], capture_output=True, text=True,
                          cwd=ROOT, env=env, timeout=timeout)


def _one_line_2(proc: subprocess.CompletedProcess, needle: str = "") -> str:
    err = proc.stderr.strip()
    assert proc.returncode == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, (proc.returncode, err)
    assert needle in err, err
    return err


def test_a_huge_random_maze_or_maze_file_is_refused_in_one_line_before_any_work(tmp_path):
    _one_line_2(_cli("refine", "random:3000x3000:0", "--out", tmp_path / "r"), "at most 49x49 rooms")
    big = tmp_path / "big.maze"
    big.write_text("\n".join(["S" + "." * 100, *["." * 101] * 99, "." * 100 + "G"]))
    _one_line_2(_cli("refine", big, "--out", tmp_path / "f"), "larger than 100 x 100")
    assert not (tmp_path / "r").exists() and not (tmp_path / "f").exists()


def test_a_huge_gymnasium_map_is_refused_and_the_largest_allowed_parses():
    with pytest.raises(MazeError, match="larger than 100 x 100"):
        Maze.from_gymnasium([["r"] * 300] * 300)
    with pytest.raises(MazeError, match="at most 49x49 rooms"):
        load_maze("random:50x2:0")
    edge = Maze.from_gymnasium([[1] + [0] * 98 + [1]] * 100)
    assert (edge.rows, edge.cols) == (100, 100) and edge.cells("S") == [(0, 1)]
    assert (load_maze("random:49x49:0").rows, load_maze("random:49x49:0").cols) == (99, 99)
