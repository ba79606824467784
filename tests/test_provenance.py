"""Every sweep row records the code it ran on (``commit``) and the goal policy (``policy_fingerprint``), also when
appended to a table from before those columns; a hash that looks like a number stays text."""
from __future__ import annotations

import csv
import re
import subprocess

from specrefine.core import paths
from specrefine.runs import sweep


def test_code_commit_is_the_checkouts_head_and_unknown_outside_one(tmp_path, monkeypatch):
    head = subprocess.run(["git", "-C", str(paths._CHECKOUT), "rev-parse", "--short=7", "HEAD"], capture_output=True,
                          text=True, check=True).stdout.strip()
    assert re.fullmatch(rf"{head}(-dirty)?", paths.code_commit())
    monkeypatch.setattr(paths, "_CHECKOUT", tmp_path)  # a copy of the package outside any checkout
    paths.code_commit.cache_clear()
    try:
        assert paths.code_commit() == "unknown"
    finally:
        paths.code_commit.cache_clear()


def test_an_older_table_gets_the_provenance_columns_and_keeps_its_rows(tmp_path):
    table = tmp_path / "results.csv"
    old = [c for c in sweep.COLUMNS if c not in sweep.PROVENANCE]
    with table.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, old)
        writer.writeheader()
        writer.writerow({c: "" for c in old} | {"cell": "a", "status": "ok", "success_rate": 0.5})
    sweep._append(table, {"cell": "b", "status": "ok", "commit": "1461726", "policy_fingerprint": "123e45678901"})
    with table.open(newline="") as fh:
        header, *rows = list(csv.reader(fh))
    assert header == old + list(sweep.PROVENANCE) and all(len(r) == len(header) for r in rows)
    first, second = sweep.read_table(table)
    assert (first["cell"], first["success_rate"], first["commit"]) == ("a", 0.5, "")  # unknown: from before
    assert (second["commit"], second["policy_fingerprint"]) == ("1461726", "123e45678901")  # text, not numbers


def test_a_failed_cell_names_its_code_too(tmp_path):
    (cell,) = sweep.grid(["no_such_maze"], ["dirl"], ["none"], [0])
    row = sweep.run_cell(cell, str(tmp_path))
    assert row["status"] == "error" and row["commit"] == paths.code_commit() != ""
