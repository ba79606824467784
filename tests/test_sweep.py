"""Sweeps: stable table schema, resume after a killed run, the Ray backend on a local head."""

from __future__ import annotations

import csv
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from specrefine.runs.sweep import COLUMNS, cell_log, grid, read_table, run_sweep, summarise
from specrefine.sim.policy import load_policy

TINY = dict(agent="point", rollouts=8, episodes=16)


def tiny_cells(seeds=(0, 1)):
    return grid(["u_maze"], ["dirl"], ["geometric"], seeds, **TINY)


def test_grid_gives_proposer_free_methods_one_cell_per_seed():
    cells = grid(["u_maze", "x_maze"], ["dirl", "symbolic", "ours", "vlm-oneshot"], ["geometric", "random"], [0, 1])
    assert len(cells) == 2 * (2 + 2 * 2) * 2
    assert {c.proposer for c in cells if c.method in ("dirl", "symbolic")} == {"none"}
    assert len({c.id for c in cells}) == len(cells)


def test_table_schema_is_stable(tmp_path):
    table = run_sweep(tiny_cells(seeds=(0,)), tmp_path, workers=1)
    with table.open() as fh:
        header = next(csv.reader(fh))
    assert header == COLUMNS
    (row,) = read_table(table)
    assert row["status"] == "ok", row["error"]
    assert 0.0 <= row["success_ci_low"] <= row["success_rate"] <= row["success_ci_high"] <= 1.0
    assert row["episodes"] == 16 and row["proposer"] == "none" and row["proposer_is_vlm"] is False
    result = json.loads((tmp_path / "cells" / row["cell"] / "result.json").read_text())
    assert row["policy_fingerprint"] == result["policy_fingerprint"] == load_policy("point").fingerprint
    assert (tmp_path / "cells" / row["cell"] / "result.json").exists()
    assert (tmp_path / "cells" / row["cell"] / "log.txt").exists()


def test_policy_fingerprint_is_read_as_text_and_older_tables_lack_it(tmp_path):
    newer, older = tmp_path / "newer.csv", tmp_path / "older.csv"
    newer.write_text("cell,seed,policy_fingerprint\r\nc,0,123e45678901\r\n")  # hex digits that parse as a float
    older.write_text("cell,seed\r\nc,0\r\n")
    assert read_table(newer)[0]["policy_fingerprint"] == "123e45678901"
    assert read_table(older)[0].get("policy_fingerprint") is None


def test_a_cells_warnings_and_log_records_go_to_its_log_file(tmp_path, capfd, caplog):
    import logging
    import warnings

    path = tmp_path / "cell" / "log.txt"
    with cell_log(path):
        logging.getLogger("specrefine.proposers.vlm").warning("rejected edge split candidate: inside a wall")
        warnings.warn("region has almost no room", UserWarning, stacklevel=1)
    text = path.read_text()
    assert "WARNING specrefine.proposers.vlm: rejected edge split candidate" in text
    assert "UserWarning: region has almost no room" in text
    assert capfd.readouterr().err == "" and caplog.text == ""  # neither printed nor passed to the root logger
    logging.getLogger("specrefine.proposers.vlm").warning("after the cell")  # the block's end restores both
    assert "after the cell" in caplog.text and "after the cell" not in path.read_text()


def test_failed_cell_is_recorded_and_retried(tmp_path, capsys):
    bad = grid(["no_such_maze"], ["dirl"], ["geometric"], [0], **TINY)
    table = run_sweep(bad, tmp_path, workers=1, retries=1)
    rows = read_table(table)
    assert "try 2" in capsys.readouterr().err  # retried once
    assert [r["status"] for r in rows] == ["error"]  # and one row per cell in the end
    assert "no_such_maze" in rows[0]["error"]


def test_sweep_resumes_after_kill_without_redoing_finished_cells(tmp_path):
    cmd = [sys.executable, "-m", "specrefine.runs.sweep", "--mazes", "u_maze", "--methods", "dirl",
           "--seeds", "0", "1", "2", "3",
           "--rollouts", "8", "--episodes", "16", "--workers", "1", "--out", str(tmp_path)]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    table = tmp_path / "results.csv"
    deadline = time.time() + 120
    while time.time() < deadline and len(read_table(table)) < 1:
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    first = read_table(table)
    assert 1 <= len(first) < 4, "the sweep should have been killed midway"
    done_before = {r["cell"] for r in first}
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=300)
    rows = read_table(table)
    assert sorted(r["seed"] for r in rows) == [0, 1, 2, 3]  # every cell exactly once
    assert {r["cell"] for r in rows[: len(first)]} == done_before  # finished rows kept, not redone


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _start_ray_head(ray_bin: str, env: dict, tries: int = 2) -> tuple[int, str]:
    """A local Ray head -> (port, temp dir). Tried again on a fresh port once: on a loaded 2-core machine `ray start`
    itself can fail (exit 1) before its services come up, which says nothing about the sweep's Ray backend."""
    for attempt in range(tries):
        port = _free_port()
        temp_dir = tempfile.mkdtemp(prefix="ray", dir="/tmp")  # short: Ray's unix socket paths have a length limit
        start = [ray_bin, "start", "--head", "--node-ip-address=127.0.0.1", f"--port={port}", "--num-cpus=2",
                 "--include-dashboard=false", "--disable-usage-stats", f"--temp-dir={temp_dir}"]
        try:
            subprocess.run(start, check=True, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                           timeout=180)
            return port, temp_dir
        except subprocess.CalledProcessError:
            subprocess.run([ray_bin, "stop", "--force"], env=env, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL, timeout=120)
            shutil.rmtree(temp_dir, ignore_errors=True)
            if attempt == tries - 1:
                raise


@pytest.mark.slow
def test_ray_backend_runs_two_cells_on_a_local_head(tmp_path):
    ray_bin = shutil.which("ray", path=str(Path(sys.executable).parent))
    if ray_bin is None:
        pytest.skip("ray is not installed")
    env = {**os.environ, "RAY_USAGE_STATS_ENABLED": "0"}
    port, temp_dir = _start_ray_head(ray_bin, env)
    try:
        table = run_sweep(tiny_cells(), tmp_path / "out", backend="ray", address=f"127.0.0.1:{port}")
        rows = read_table(table)
        assert sorted(r["seed"] for r in rows) == [0, 1]
        assert all(r["status"] == "ok" for r in rows), [r["error"] for r in rows]
        stats = summarise(rows)
        assert stats[0]["runs"] == 2 and stats[0]["seeds"] == [0, 1]
    finally:
        import ray

        ray.shutdown()
        subprocess.run([ray_bin, "stop", "--force"], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       timeout=120)
        shutil.rmtree(temp_dir, ignore_errors=True)


def test_a_sweep_runs_every_cell_with_the_policy_it_is_given(tmp_path, capsys):
    import json

    from specrefine.runs.sweep import main
    from specrefine.sim.policy import POLICY_DIR, load_policy

    policy = tmp_path / "my_point.pt"
    shutil.copy(POLICY_DIR / "point.pt", policy)
    args = ["--mazes", "u_maze", "--methods", "dirl", "--seeds", "0", "--rollouts", "8", "--episodes", "16",
            "--workers", "1", "--out", str(tmp_path / "out")]
    assert main([*args, "--policy", str(policy)]) == 0
    (row,) = read_table(tmp_path / "out" / "results.csv")
    assert row["status"] == "ok" and row["policy"] == str(policy.resolve())
    result = json.loads((tmp_path / "out" / "cells" / row["cell"] / "result.json").read_text())
    assert result["policy_fingerprint"] == load_policy(policy).fingerprint and "my_point.pt" in result["policy"]
    capsys.readouterr()
    assert main([*args]) == 2  # the same cells with the shipped policy: refused, nothing mixed
    assert "--policy" in capsys.readouterr().err
    assert main([*args[:-1], str(tmp_path / "other"), "--policy", str(tmp_path / "missing.pt")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "missing.pt: policy file not found" in err
    assert not (tmp_path / "other" / "results.csv").exists()


def _git(root, *args) -> str:
    return subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True).stdout.strip()


@pytest.mark.parametrize("layout", ["HEAD", "flat"])
def test_pinned_sweep_runs_the_commits_code_and_ships_done_rows(tmp_path, layout):
    """scripts/pinned_sweep.sh: the sweep runs from a worktree at CODE (not the checkout) and its rows reach SHIPPED,
    also for a commit from before the sub-package layout (its flat ``specrefine.sweep``: grids pinned to old code)."""
    root = Path(__file__).parents[1]
    if not (root / ".git").exists():
        pytest.skip("not a git checkout")
    code = "HEAD"
    if layout == "flat":  # the parent of the commit that moved sweep.py into runs/
        moved = _git(root, "log", "-1", "--format=%H", "--diff-filter=D", "--", "specrefine/sweep.py")
        code = _git(root, "rev-parse", "--verify", "-q", f"{moved}^") if moved else ""
        if not code:
            pytest.skip("no commit with the flat layout in this clone")
    tree, shipped = tmp_path / "tree", tmp_path / "shipped" / "t.csv"
    env = {**os.environ, "CODE": code, "OUT": str(tmp_path / "out"), "SHIPPED": str(shipped), "TREE": str(tree),
           "PYTHON": sys.executable}
    try:
        proc = subprocess.run(["bash", str(root / "scripts" / "pinned_sweep.sh"), "--mazes", "u_maze", "--methods",
                               "dirl", "--seeds", "0", "--rollouts", "8", "--episodes", "16", "--workers", "1"],
                              env=env, capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr[-2000:]
        assert f"in {tree}" in proc.stdout
        assert (tree / "specrefine" / "runs" / "sweep.py").exists() == (layout == "HEAD")
        (row,) = read_table(shipped)
        assert row["status"] == "ok" and row["maze"] == "u_maze"
        assert _git(tree, "rev-parse", "HEAD") == _git(root, "rev-parse", f"{code}^{{commit}}")
    finally:
        subprocess.run(["git", "-C", str(root), "worktree", "remove", "--force", str(tree)], capture_output=True)


def test_w_d_k_are_grid_axes_and_the_paper_values_keep_their_ids(tmp_path):
    from specrefine.runs.sweep import Cell, _append, pending

    cells = grid(["u_maze"], ["ours", "symbolic", "dirl"], ["geometric"], [0], w=[3, 5], k=[5, 10], preset="paper")
    ids = sorted(c.id for c in cells)
    assert ids == sorted(["u_maze__point__ours__geometric__s0", "u_maze__point__ours__geometric__s0__w5",
                          "u_maze__point__ours__geometric__s0__k10", "u_maze__point__ours__geometric__s0__w5__k10",
                          "u_maze__point__symbolic__none__s0", "u_maze__point__symbolic__none__s0__k10",
                          "u_maze__point__dirl__none__s0"])  # symbolic reads k only, dirl none
    assert {(c.w, c.k) for c in cells if c.method == "ours"} == {(3, 5), (5, 5), (3, 10), (5, 10)}
    assert Cell.of("u_maze", "point", "ours", "geometric", 0, k=10).config.k == 10
    # a table from before the w, d, k columns: its rows read as the paper's values, its cells stay done
    old = [c for c in COLUMNS if c not in ("w", "d", "k")]
    table = tmp_path / "results.csv"
    with table.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=old)
        writer.writeheader()
        writer.writerow({c: "" for c in old} | {"cell": "u_maze__point__dirl__none__s0", "status": "ok",
                                                 "success_rate": 1.0, "success_ci_low": 0.9, "success_ci_high": 1.0,
                                                 "episodes": 16, "evaluations": 2, "graph_vertices": 3})
    (row,) = read_table(table)
    assert (row["w"], row["d"], row["k"]) == (3, 2, 5)
    assert [c.id for c in pending(cells, table)] == [c.id for c in cells if c.method != "dirl"]
    with pytest.raises(ValueError, match="no 'w', 'd', 'k' columns"):
        _append(table, {"cell": "x", "w": 5, "d": 2, "k": 5})


def test_every_table_column_comes_from_a_runs_result_or_its_cell(tmp_path):
    """sweep.COLUMNS is the table's chosen subset of result.json: a column no run writes would stay empty."""
    import json

    from specrefine.runs.pipeline import refine_maze
    from specrefine.runs.sweep import COLUMNS, result_row

    refine_maze("u_maze", agent="point", method="ours", proposer="geometric", seed=0, rollouts=8, episodes=20,
                out=tmp_path / "run")
    data = json.loads((tmp_path / "run" / "result.json").read_text())
    row = result_row(data, {"cell": "u_maze__point__ours__geometric__s0", "w": 3, "d": 2, "k": 5})
    assert [c for c in COLUMNS if c not in row] == []
