"""README's result tables are their files' numbers: each row recomputed from the shipped table it names.

A hand-typed or stale figure (a rounding of a rounding, a count from before a table grew) fails here naming the
row. Only tables whose files are complete are checked; the growing Ant comparison is reported, not pinned.
"""
from __future__ import annotations

import importlib.util
import json
import math
import re
from pathlib import Path

from specrefine.sweep import read_table, summarise

ROOT = Path(__file__).parents[1]
README = (ROOT / "README.md").read_text()

_spec = importlib.util.spec_from_file_location("per_maze_report", ROOT / "scripts" / "per_maze_report.py")
per_maze_report = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(per_maze_report)


def _table_after(header_start: str) -> list[list[str]]:
    """The cells of each body row of the README table whose header line starts with ``header_start``."""
    lines = README[README.index(header_start):].splitlines()
    body = []
    for line in lines[2:]:
        if not line.startswith("|"):
            break
        body.append([c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]])
    assert body, f"no rows under {header_start!r}"
    return body


def test_point_table_is_results_csv():
    rows = read_table(ROOT / "data/results/results.csv")
    seed0 = {(r["maze"], r["method"], r["proposer"]): r for r in rows if r["seed"] == 0}
    summary = {(s["maze"], s["method"], s["proposer"]): s for s in summarise(rows)}  # summary.md's numbers
    columns = [("ours", "geometric"), ("vlm-oneshot", "geometric"), ("dirl", "none"), ("symbolic", "none"),
               ("ours", "random")]
    table = _table_after("| maze | ours, seed 0 [95 % CI] |")
    assert len(table) == 17
    for cells in table:
        maze = cells[0].split()[0]
        r = seed0[maze, "ours", "geometric"]
        want = [f"{r['success_rate']:.3f} [{r['success_ci_low']:.3f}, {r['success_ci_high']:.3f}]"]
        for m, p in columns:
            s = summary[maze, m, p]
            assert s["seeds"] == [0, 1, 2, 3], (maze, m, p)
            want.append(f"{s['success_mean']:.3f} ± {s['success_std']:.3f}")
        assert cells[1:] == want, maze


def test_ant_uchain_table_is_per_maze_report():
    rows = [r for r in read_table(ROOT / "data/results/ant/comparison.csv")
            if r["method"] == "ours" and r["proposer"] == "geometric"]
    table = _table_after("| maze | success, pooled [95 % CI] (seeds 0, 1, 2) |")
    assert [c[0] for c in table] == [f"u_chain_{n}" for n in range(1, 6)] + [
        f"u_chain_{n}_subgoals" for n in range(2, 6)]
    for cells in table:
        runs = sorted((r for r in rows if r["maze"] == cells[0]), key=lambda r: r["seed"])
        assert [r["seed"] for r in runs] == [0, 1, 2], cells[0]
        report = [c.strip() for c in per_maze_report.pooled_line(cells[0], runs).split("|")[1:-1]]
        del report[1]  # "3 of 3": runs done
        report[2] = report[2].replace(" inside)", ")")
        assert cells == report, cells[0]


def test_offline_claims_table_is_claims_json():
    claims = json.loads((ROOT / "data/results/imperfect/claims.json").read_text())["claims"]
    by = {(c["proposer"], c["method"]): c for c in claims}
    fmt = lambda c: f"{c['estimate']:.2f} [{c['ci_low']:.2f}, {c['ci_high']:.2f}]"  # noqa: E731
    table = _table_after("| preset | ours / one-shot, multi-room |")
    presets = {"mild": "imperfect:mild", "moderate": "imperfect:moderate", "severe": "imperfect:severe",
               "moderate, alpha = 0.1": "imperfect:moderate,alpha=0.1"}
    assert [c[0] for c in table] == list(presets)
    for cells in table:
        p = presets[cells[0]]
        ratio, ours, oneshot = by[p, "ours / vlm-oneshot"], by[p, "ours"], by[p, "vlm-oneshot"]
        if all(isinstance(x, float) and math.isfinite(x) for x in (ratio["ci_low"], ratio["ci_high"])):
            assert cells[1] == fmt(ratio) and cells[2] == ratio["verdict"], p
        assert cells[3] == fmt(ours) and cells[4] == ours["verdict"], p
        assert cells[5] == f"{fmt(oneshot)}, {oneshot['verdict']}", p



def test_adaptive_table_is_the_bench_markdown():
    from specrefine.bench.refinement import _read, markdown

    table = markdown(_read(ROOT / "data/results/ant/adaptive_bench.csv")).splitlines()
    assert len(table) == 2 + 9  # header, rule, 3 mazes x 3 seeds
    missing = [line for line in table if line not in README.splitlines()]
    assert not missing, missing


def test_ant_comparison_seed_tables_are_complete_seeds_of_the_table():
    """Each seed of the growing Ant comparison that README shows is complete in the table and shown as it is, with
    the lines that contrast ours and the one-shot under it."""
    from specrefine.comparison import ANT_GRID, seed_contrast, seed_table

    rows = read_table(ROOT / "data/results/ant/comparison.csv")
    seeds = re.findall(r"<!-- ant comparison seed (\d+) -->", README)
    assert seeds, "README shows no seed of the Ant comparison"
    for seed in seeds:
        table, shown, expected = seed_table(rows, ANT_GRID, int(seed))
        assert shown == expected, f"seed {seed}: {shown} of {expected} cells in the table"
        contrast = "\n".join(seed_contrast(rows, ANT_GRID, int(seed)))
        assert f"<!-- ant comparison seed {seed} -->\n{table}\n\n{contrast}\n" in README, f"seed {seed}"


def test_ant_comparison_claims_are_claims_md_of_the_complete_grid():
    """README's Ant claims are the table of the shipped claims.md, drawn from every run of the fixed grid."""
    from specrefine.comparison import ANT_GRID, expected_cells, grid_cells, table_cells

    rows = read_table(ROOT / "data/results/ant/comparison.csv")
    assert grid_cells(ANT_GRID) <= set(table_cells(rows, "ant")[0]), "the Ant grid is not complete"
    assert expected_cells(ANT_GRID) == 306
    claims = json.loads((ROOT / "data/results/ant/comparison/claims.json").read_text())["claims"]
    assert claims and all(c["complete"] for c in claims)
    table = "\n".join(line for line in (ROOT / "data/results/ant/comparison/claims.md").read_text().splitlines()
                      if line.startswith("|"))
    assert f"<!-- ant comparison claims -->\n{table}\n" in README


def test_repair_summary_is_the_repair_grid():
    """README's look-ahead repair table is specrefine.repair_claims' summary of the shipped, complete grid."""
    from specrefine.repair_claims import study

    rows = read_table(ROOT / "data/results/repair/results.csv")
    summary = study(rows).summary()
    assert "(*partial*)" not in summary
    assert f"<!-- repair summary -->\n{summary}\n" in README
    assert (ROOT / "data/results/repair/summary.md").read_text() == summary + "\n"
