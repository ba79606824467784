"""specrefine.experiments.levers: a lever against its baseline on the same cells, Newcombe's interval."""
import csv

import pytest

from specrefine.core.results import newcombe_ci
from specrefine.experiments import levers
from specrefine.runs.sweep import COLUMNS


def test_newcombe_interval_matches_his_worked_example():
    lo, hi = newcombe_ci(56, 70, 48, 80)  # Newcombe (1998), Table II example (method 10): 0.0524 to 0.3339
    assert lo == pytest.approx(0.0524, abs=5e-4) and hi == pytest.approx(0.3339, abs=5e-4)
    lo, hi = newcombe_ci(10, 10, 0, 10)
    assert 0 < lo < hi <= 1


def _write(path, method, rates):
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, COLUMNS)
        w.writeheader()
        for (maze, seed), rate in rates.items():
            w.writerow({"cell": f"{maze}__ant__{method}__s{seed}", "maze": maze, "agent": "ant", "method": method,
                        "proposer": "geometric", "seed": seed, "status": "ok", "success_rate": rate,
                        "success_ci_low": 0.0, "success_ci_high": 1.0, "episodes": 200, "evaluations": 1,
                        "graph_vertices": 2})


@pytest.mark.parametrize("lever_rate, verdict", [(0.95, "helps"), (0.80, "no difference shown"), (0.60, "hurts")])
def test_a_lever_is_judged_on_the_cells_both_sides_ran(tmp_path, lever_rate, verdict):
    cells = [(m, s) for m in ("u_chain_3", "u_chain_5") for s in (0, 1, 2)]
    _write(tmp_path / "lever.csv", "ours-polish", {c: lever_rate for c in cells})
    _write(tmp_path / "base.csv", "ours", {c: 0.80 for c in cells})
    check = levers.lever_check(levers._by_cell(tmp_path / "lever.csv", "ours-polish", None),
                               levers._by_cell(tmp_path / "base.csv", "ours", None), cells)
    assert check["verdict"] == verdict and check["complete"] and check["lever"] == (round(lever_rate * 1200), 1200)
    _write(tmp_path / "lever.csv", "ours-polish", {c: lever_rate for c in cells[:4]})  # two cells still to run
    out = tmp_path / "check.md"
    assert levers.main([str(tmp_path / "lever.csv"), "--method", "ours-polish", "--baseline",
                        str(tmp_path / "base.csv"), "--baseline-method", "ours", "--mazes", "u_chain_3", "u_chain_5",
                        "--seeds", "0", "1", "2", "--out", str(out)]) == 0
    assert out.read_text().startswith(f"**ours-polish against ours, 4 of 6 cells: partial ({verdict} so far).**")


def test_a_missing_table_is_one_line_exit_2(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_:
        levers.main([str(tmp_path / "none.csv"), "--method", "x", "--baseline", str(tmp_path / "none.csv"),
                     "--baseline-method", "y", "--mazes", "u_chain_3", "--seeds", "0"])
    assert exit_.value.code == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_a_lever_aiming_at_centres_is_named_so(tmp_path):
    _write(tmp_path / "t.csv", "ours", {("u_chain_3", 0): 0.9})
    rows = levers._by_cell(tmp_path / "t.csv", "ours", None)
    assert levers.label("ours", rows) == "ours"  # a table from before the column: the paper's rule
    rows = {k: {**r, "goal_points": "centre"} for k, r in rows.items()}
    assert levers.label("ours", rows) == "ours (centre goal points)"
    rows = {k: {**r, "cell": r["cell"] + "__switching-slow-turn"} for k, r in rows.items()}
    assert levers.label("ours", rows) == "ours (centre goal points; slow-turn switching)"


def test_a_layout_is_paired_with_another_maze_of_the_baseline_seed_by_seed(tmp_path, capsys):
    _write(tmp_path / "lever.csv", "ours", {("u_chain_3_rotated-1a2b", s): 0.95 for s in (0, 1)})
    _write(tmp_path / "base.csv", "ours", {("u_chain_3", 0): 0.90, ("u_chain_3", 1): 0.96, ("u_chain_5", 0): 0.5})
    common = [str(tmp_path / "lever.csv"), "--method", "ours", "--baseline", str(tmp_path / "base.csv"),
              "--baseline-method", "ours", "--mazes", "u_chain_3_rotated-1a2b", "--seeds", "0", "1"]
    assert levers.main([*common, "--baseline-mazes", "u_chain_3"]) == 0
    text = capsys.readouterr().out
    assert "ours against ours on u_chain_3, 2 of 2 cells" in text
    assert "| u_chain_3_rotated-1a2b | 0 | 0.950 | 0.900 |" in text
    assert levers.shown("/x/held_out/u_chain_3_rotated.maze") == "u_chain_3_rotated"
    with pytest.raises(SystemExit) as exit_:
        levers.main([*common, "--baseline-mazes", "u_chain_3", "u_chain_5"])
    assert exit_.value.code == 2 and "names 2 mazes for the 1" in capsys.readouterr().err


def test_each_side_is_named_by_its_policy_only_when_they_differ(tmp_path):
    _write(tmp_path / "t.csv", "ours", {("u_chain_3", 0): 0.9})
    rows = levers._by_cell(tmp_path / "t.csv", "ours", None)
    eight = {k: {**r, "policy": "/x/code_abc/data/policies/ant_stage8.pt"} for k, r in rows.items()}
    five = {k: {**r, "policy": "data/policies/ant_stage5.pt"} for k, r in rows.items()}
    assert levers.policies(eight) == ["ant_stage8"] and levers.policies(rows) == []
    assert levers.label("ours", eight, policy=True) == "ours (policy ant_stage8)"
    assert levers.label("ours", five) == "ours"  # the same policy on both sides: not named
