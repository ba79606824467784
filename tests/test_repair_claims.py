"""specrefine.experiments.repair_claims on synthetic tables: the paired verdicts, the paper's claims with ours-repair,
partial presets and the descriptive counts."""

from __future__ import annotations

import json

import pytest
from test_comparison import row, write_csv

from specrefine.core.mazes import benchmark_mazes
from specrefine.experiments import repair_claims as rc
from specrefine.experiments.comparison import MULTI_ROOM_MAZES

MODERATE = "imperfect:moderate"


def grid_rows(success, proposer=MODERATE, seeds=rc.SEEDS):
    """One row per (maze, method, seed); success(maze, method, seed) -> rate; evaluations 10 (ours-repair 15)."""
    return [row(maze, m, success(maze, m, seed), seed, proposer) | {
        "evaluations": 15 if m == "ours-repair" else 10, "proposer_calls": 6 if m == "ours-repair" else 3}
        for maze in sorted(benchmark_mazes()) for m in rc.METHODS for seed in seeds]


def entries_of(rows, proposer=MODERATE):
    from specrefine.experiments import comparison as cmp

    cells, failed = cmp.table_cells(rows, "point")
    return {e["claim"]: e for e in [rc.paired_claim(cells, failed, proposer, MULTI_ROOM_MAZES, "multi-room"),
                                    rc.paired_claim(cells, failed, proposer, sorted(benchmark_mazes()), "every maze"),
                                    *rc.paper_claims(cells, failed, proposer)]}


def repair_lifts_multi_room(maze, method, seed):
    base = {"ours": 0.4, "ours-repair": 0.4, "vlm-oneshot": 0.2}[method]
    return base + (0.3 if method == "ours-repair" and maze in MULTI_ROOM_MAZES else 0.0)


def test_a_lift_on_every_multi_room_cell_helps_and_is_diluted_over_every_maze():
    e = entries_of(grid_rows(repair_lifts_multi_room))
    multi, every = e["ours-repair - ours, multi-room"], e["ours-repair - ours, every maze"]
    assert multi["verdict"] == "helps" and multi["estimate"] == pytest.approx(0.3)
    assert (multi["ci_low"], multi["ci_high"]) == pytest.approx((0.3, 0.3))
    assert every["estimate"] == pytest.approx(0.3 * len(MULTI_ROOM_MAZES) / len(benchmark_mazes()))
    assert multi["complete"] and multi["n_cells"] == len(MULTI_ROOM_MAZES) * len(rc.SEEDS)
    ratio = e["ours-repair >= 2x one-shot on multi-room tasks"]
    assert ratio["estimate"] == pytest.approx(0.7 / 0.2) and ratio["verdict"] == "holds"


def test_noise_around_zero_is_undecided_and_a_loss_hurts():
    noisy = entries_of(grid_rows(lambda maze, m, seed: 0.5 + (0.1 if m == "ours-repair" and seed % 2 else
                                                              -0.1 if m == "ours-repair" else 0.0)))
    assert noisy["ours-repair - ours, every maze"]["verdict"] == "undecided"
    worse = entries_of(grid_rows(lambda maze, m, seed: 0.3 if m == "ours-repair" else 0.5))
    assert worse["ours-repair - ours, multi-room"]["verdict"] == "hurts"


def test_rooms_claim_reads_ours_repair_not_ours():
    def falls_for_ours_only(maze, m, seed):
        rooms = int(maze.split("_")[2]) if maze.startswith("u_chain_") and not maze.endswith("subgoals") else 1
        return 0.9 if m == "ours-repair" else 1.0 - 0.2 * rooms

    e = entries_of(grid_rows(falls_for_ours_only))
    assert e["ours-repair success over 1-5 rooms"]["verdict"] == "flat"
    assert e["ours success over 1-5 rooms"]["verdict"] == "falls"


def test_missing_cells_are_partial_and_named():
    rows = [r for r in grid_rows(repair_lifts_multi_room) if not (r["maze"] == "u_chain_3" and r["seed"] == 2
                                                                   and r["method"] == "ours-repair")]
    multi = entries_of(rows)["ours-repair - ours, multi-room"]
    assert not multi["complete"] and multi["missing"] == ["u_chain_3 s2: ours-repair (no row)"]


def test_cli_writes_claims_counts_zeros_and_cost_ratios(tmp_path):
    rows = grid_rows(lambda maze, m, seed: 0.0 if m == "ours" and maze == "u_chain_2" else 0.5)
    write_csv(tmp_path / "t.csv", rows)  # one preset only: the other two are all missing
    assert rc.main([str(tmp_path / "t.csv"), "--out", str(tmp_path / "out")]) == 0
    data = json.loads((tmp_path / "out" / "claims.json").read_text())
    (moderate,) = [c for c in data["costs"] if c["proposer"] == MODERATE]
    assert moderate["zero_runs"] == {"ours": 4, "ours-repair": 0, "vlm-oneshot": 0}
    assert moderate["evaluations_ratio"] == pytest.approx(1.5) and moderate["proposer_calls_ratio"] == 2.0
    severe = [c for c in data["claims"] if c["proposer"] == "imperfect:severe"]
    assert severe and not any(c["complete"] for c in severe)
    assert "u_chain_2 | 0.000 [0.000, 0.000] (n=4) | 0.500" in (tmp_path / "out" / "mazes.md").read_text()
    assert all((tmp_path / "out" / f"{name}.png").stat().st_size > 0 for name in ("figure4", "figure5"))
    summary = (tmp_path / "out" / "summary.md").read_text().splitlines()
    assert len(summary) == 2 + len(rc.PRESETS) and summary[2].startswith("| moderate | +0.062 [")
    assert summary[2].endswith("| 4/68, 0/68, 0/68 | 1.50x, 2.00x |") and "(*partial*)" in summary[3]


def test_cli_refuses_a_missing_table(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        rc.main([str(tmp_path / "nope.csv"), "--out", str(tmp_path / "out")])
    assert exc.value.code == 2 and "no table" in capsys.readouterr().err


def test_tuned_study_pairs_the_tuned_repair_with_the_repair_per_preset(tmp_path):
    rows = [row(maze, m, 0.0 if (m, maze, seed) == ("ours-repair", "u_chain_3", 0) else
                (0.8 if m == "ours-repair-tuned" and maze in MULTI_ROOM_MAZES else 0.6), seed, preset)
            | {"evaluations": 12 if m == "ours-repair-tuned" else 10, "proposer_calls": 3}
            for preset in rc.TUNED.proposers for maze in sorted(benchmark_mazes()) for m in rc.TUNED_PAIR
            for seed in rc.TUNED.seeds]
    entries, cost_rows, text = rc.tuned_study(rows)
    first = entries[0]
    assert first["claim"] == "ours-repair-tuned - ours-repair, multi-room" and first["verdict"] == "helps"
    assert first["complete"] and first["n_cells"] == len(MULTI_ROOM_MAZES) * len(rc.TUNED.seeds)
    assert cost_rows[0]["zero_runs"] == {"ours-repair-tuned": 0, "ours-repair": 1}
    assert cost_rows[0]["evaluations_ratio"] == pytest.approx(1.2)
    assert "ours-repair-tuned / ours-repair: evaluations" in text
    table = tmp_path / "t.csv"
    write_csv(table, rows)
    assert rc.main([str(table), "--tuned", "--out", str(tmp_path / "o")]) == 0
    assert json.loads((tmp_path / "o" / "tuned_claims.json").read_text())["claims"][0]["verdict"] == "helps"


def test_cli_refuses_a_folder_another_command_is_writing(tmp_path, capsys):
    from specrefine.core.runfolder import locked

    write_csv(tmp_path / "t.csv", grid_rows(lambda maze, m, seed: 0.5))
    out = tmp_path / "out"
    out.mkdir()
    with locked(out), pytest.raises(SystemExit) as exc:
        rc.main([str(tmp_path / "t.csv"), "--out", str(out)])
    assert exc.value.code == 2 and "in use" in capsys.readouterr().err
    assert list(out.iterdir()) == []
    assert rc.main([str(tmp_path / "t.csv"), "--out", str(out)]) == 0  # free again: written, and no lock left
    assert (out / "claims.md").is_file() and not (out / ".lock").exists()
