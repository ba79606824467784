"""specrefine.experiments.scaling: the scaling grid's two decision rules on synthetic tables."""
import csv

import pytest

from specrefine.experiments import scaling
from specrefine.runs.sweep import COLUMNS


def _row(maze, method, proposer, seed, rate, legs=10):
    return {"cell": f"{maze}-{method}-{proposer}-{seed}", "maze": maze, "agent": "ant", "method": method,
            "proposer": proposer, "seed": seed, "status": "ok", "success_rate": rate, "episodes": 200,
            "path_edges": legs, "evaluations": 10, "sim_steps": 100, "wall_seconds": 1.0, "policy": "/x/ant_stage5.pt",
            "success_ci_low": 0.0, "success_ci_high": 1.0, "graph_vertices": 5, "spec": ""}


def _rows(ours_rate, oneshot_rate=0.3, repair_rate=None, zero=None):
    rows = []
    for maze in scaling.MAZES:
        for seed in scaling.SEEDS:
            rate = ours_rate(maze) if callable(ours_rate) else ours_rate
            rows.append(_row(maze, "ours", scaling.ORACLE, seed, rate))
            rows.append(_row(maze, "ours", scaling.ERRING, seed, 0.0 if (maze, seed) == zero else rate))
            rows.append(_row(maze, "vlm-oneshot", scaling.ERRING, seed, oneshot_rate))
            if repair_rate is not None:
                rows.append(_row(maze, "ours-repair", scaling.ERRING, seed, repair_rate))
    return rows


def test_flat_at_the_level_holds_only_when_every_maze_is_above_it_and_the_change_is_flat():
    assert scaling.flat_claim(_rows(0.93))["verdict"] == "holds"
    below = scaling.flat_claim(_rows(lambda m: 0.85 if m == "u_chain_3" else 0.93))
    assert below["verdict"] == "not met" and below["below_level"] == ["u_chain_3"]
    falling = scaling.flat_claim(_rows(lambda m: 1.0 - 0.02 * scaling.rooms(m)))  # all >= 0.90, -0.08 over 4 rooms
    assert falling["change_verdict"] == "falls" and falling["verdict"] == "not met"
    assert falling["change_1_to_5"] == pytest.approx(-0.08)


def test_a_missing_cell_makes_the_verdict_partial():
    rows = [r for r in _rows(0.93) if not (r["maze"] == "u_chain_5" and r["seed"] == 2)]
    assert scaling.flat_claim(rows)["verdict"].startswith("partial")


def test_erring_rule_takes_the_better_method_per_maze_and_counts_zeros_where_the_one_shot_is_high():
    held = scaling.erring_claim(_rows(0.7, oneshot_rate=0.3, repair_rate=0.2))
    assert held["verdict"] == "holds" and held["ratio"] == pytest.approx(0.7 / 0.3)
    assert {c["method"] for c in held["chosen"].values()} == {"ours"}
    repaired = scaling.erring_claim(_rows(0.2, oneshot_rate=0.3, repair_rate=0.7))
    assert {c["method"] for c in repaired["chosen"].values()} == {"ours-repair"}
    zero = scaling.erring_claim(_rows(0.9, oneshot_rate=0.6, repair_rate=0.1, zero=("u_chain_2", 1)))
    assert zero["zeros"] == ["u_chain_2 seed 1"] and zero["verdict"] == "not met"  # ratio 1.5 too
    assert zero["ours_at_zero"] == [{"maze": "u_chain_2", "seed": 1, "ours_repair": 0.1}]
    assert "`ours` runs at 0: 1 of 27; `ours-repair` on the same cells: above 0 on 1 of 1 (u_chain_2 seed 1 0.100)." \
        in scaling.markdown(scaling.flat_claim(_rows(0.9)), zero)


def test_tables_without_the_erring_runs_say_so():
    rows = [r for r in _rows(0.93) if r["proposer"] == scaling.ORACLE]
    erring = scaling.erring_claim(rows)
    assert erring["verdict"] == "not run"
    text = scaling.markdown(scaling.flat_claim(rows), erring)
    assert text.rstrip().endswith("not run** (no ours or ours-repair x imperfect:moderate run in these tables).")


def test_the_erring_ratio_carries_a_bootstrap_interval_over_paired_cells():
    rows = _rows(0.6, oneshot_rate=0.2)
    flat = scaling.erring_claim(rows)
    assert flat["ratio_ci"] == pytest.approx([3.0, 3.0]) and flat["cells"] == 8 * len(scaling.SEEDS)
    rows = [dict(r, success_rate=0.0) if (r["method"], r["seed"]) == ("vlm-oneshot", 0) else r for r in rows]
    spread = scaling.erring_claim(rows)  # the one-shot at 0 on every seed-0 cell: the ratio rises, its interval widens
    low, high = spread["ratio_ci"]
    assert spread["ratio"] == pytest.approx(0.6 / (0.2 * 2 / 3)) and low < spread["ratio"] < high


def test_the_command_writes_claims_legs_and_figure(tmp_path):
    table = tmp_path / "t.csv"
    with table.open("w", newline="") as fh:
        w = csv.DictWriter(fh, COLUMNS, extrasaction="ignore")
        w.writeheader()
        w.writerows(_rows(0.93, repair_rate=0.5))
    assert scaling.main([str(table), "--out", str(tmp_path / "out")]) == 0
    claims = (tmp_path / "out" / "claims.md").read_text()
    assert "holds" in claims and "u_chain_5_subgoals" in claims
    assert "Ratio 3.10 [3.10, 3.10] (95 % bootstrap, 24 paired cells resampled)" in claims
    assert "runs at 0 where the one-shot is above 0.5: none." in claims
    assert (tmp_path / "out" / "figure5.png").stat().st_size > 0
    assert "| u_chain_3 |" in (tmp_path / "out" / "legs.md").read_text()
    seeds = (tmp_path / "out" / "erring_seeds.md").read_text()
    assert "| maze | ours, seed 2 | ours-repair, seed 2 | vlm-oneshot, seed 2 |" in seeds
    assert "| u_chain_3 | 0.930 (10) | 0.500 (10) | 0.300 (10) |" in seeds


def test_the_erring_seed_table_marks_a_cell_not_run_yet():
    rows = [r for r in _rows(0.93, repair_rate=0.5) if not (r["maze"] == "u_chain_4" and r["method"] == "ours-repair")]
    line = next(x for x in scaling.erring_seed_table(rows, 1).splitlines() if x.startswith("| u_chain_4 |"))
    assert line == "| u_chain_4 | 0.930 (10) | — | 0.300 (10) |"


def test_tables_of_two_goal_point_rules_are_refused(tmp_path):
    from specrefine.core.errors import SpecrefineError
    from specrefine.runs import sweep

    for name, rule in (("sampled.csv", "sampled"), ("centre.csv", "centre")):
        sweep._append(tmp_path / name, {k: 1 for k in sweep.COLUMNS} | {
            "cell": f"u_chain_1__ant__ours__x__s0__{rule}", "maze": "u_chain_1", "agent": "ant", "method": "ours",
            "proposer": scaling.ORACLE, "seed": 0, "status": "ok", "goal_points": rule})
    assert len(scaling.read_rows([tmp_path / "centre.csv"])) == 1
    with pytest.raises(SpecrefineError, match="mix goal-point rules"):
        scaling.read_rows([tmp_path / "sampled.csv", tmp_path / "centre.csv"])
