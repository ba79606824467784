"""specrefine.experiments.oracle_check: issue 42's oracle rule and a lever against its baseline, cell for cell."""
import csv

import pytest
from test_scaling import _row

from specrefine.experiments import oracle_check, scaling
from specrefine.runs.sweep import COLUMNS


def _grid(method, rate):
    return [_row(maze, method, scaling.ORACLE, seed, rate(maze, seed) if callable(rate) else rate)
            for maze in scaling.MAZES for seed in scaling.SEEDS]


def _write(path, rows):
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, COLUMNS, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    return str(path)


def test_the_rule_takes_its_level_and_tolerance():
    rows = _grid("ours", lambda m, s: 0.995 - 0.01 * scaling.rooms(m))  # 0.945-0.985: -0.04 over 4 rooms
    strict = scaling.flat_claim(rows, level=0.97, tolerance=0.03)
    assert strict["verdict"] == "not met" and strict["change_verdict"] == "falls"
    assert strict["below_level"] == sorted(m for m in scaling.MAZES if scaling.rooms(m) >= 3)
    loose = scaling.flat_claim(rows, level=0.90, tolerance=0.05)
    assert loose["verdict"] == "holds" and loose["change_1_to_5"] == pytest.approx(-0.04)
    assert scaling.flat_claim(_grid("ours-tunecheck", 0.99), method="ours-tunecheck", level=0.97,
                              tolerance=0.03)["verdict"] == "holds"


def test_a_lever_is_adopted_only_above_its_baseline_with_no_maze_far_below():
    base = _grid("ours", 0.90)
    better = oracle_check.against(_grid("ours-tunecheck", 0.93), base, "ours-tunecheck", "ours", 0.03)
    assert better["verdict"] == "adopted" and better["total"]["cells"] == 27
    assert better["total"]["difference"] == pytest.approx(0.03)
    lo, hi = better["total"]["ci"]
    assert lo < 0.03 < hi
    one_worse = _grid("ours-tunecheck", lambda m, s: 0.85 if m == "u_chain_2" else 0.95)
    verdict = oracle_check.against(one_worse, base, "ours-tunecheck", "ours", 0.03)
    assert verdict["total"]["difference"] > 0 and verdict["verdict"] == "not adopted"
    assert verdict["per_maze"]["u_chain_2"]["difference"] == pytest.approx(-0.05)
    partial = oracle_check.against(_grid("ours-tunecheck", 0.93)[:5], base, "ours-tunecheck", "ours", 0.03)
    assert partial["verdict"] == "partial (adopted so far, 5 of 27 cells)"


def test_the_command_writes_the_rule_and_the_comparison(tmp_path):
    lever = _write(tmp_path / "lever.csv", _grid("ours-tunecheck", 0.98))
    base = _write(tmp_path / "base.csv", _grid("ours", 0.96))
    out = tmp_path / "check.md"
    assert oracle_check.main([lever, "--method", "ours-tunecheck", "--baseline", base, "--out", str(out)]) == 0
    text = out.read_text()
    assert "at least 0.97 on every maze, flat (+-0.03) from 1 to 5 rooms: holds." in text
    assert "| u_chain_3 | 3 | 0.980 [0.965, 0.989] (600) | 0.960 [0.941, 0.973] (600) | +0.020" in text
    assert "**Against ours on the same 27 cells: adopted**" in text and "NOT a VLM" in text
    assert ("Summary: 27 of 27 cells; below the level on 0 of 9 mazes run; change from 1 to 5 rooms +0.000 "
            "[+0.000, +0.000]; against ours on the same 27 cells +0.020 [") in text
    with pytest.raises(SystemExit):
        oracle_check.main([str(tmp_path / "absent.csv"), "--out", str(out)])


@pytest.mark.parametrize("out", ["/dev/null", "folder", "link"])
def test_an_out_that_is_no_regular_file_is_refused_before_any_work(tmp_path, capsys, out):
    (tmp_path / "folder").mkdir()
    (tmp_path / "target.md").write_text("kept\n")
    (tmp_path / "link").symlink_to(tmp_path / "target.md")
    table = _write(tmp_path / "t.csv", _grid("ours", 0.98))
    with pytest.raises(SystemExit) as exit_:
        oracle_check.main([table, "--out", out if out.startswith("/") else str(tmp_path / out)])
    assert exit_.value.code == 2 and len(capsys.readouterr().err.strip().splitlines()) == 1
    assert (tmp_path / "target.md").read_text() == "kept\n"


def test_a_described_comparison_has_no_rule(tmp_path):
    lever = _write(tmp_path / "now.csv", _grid("ours", 0.90))
    base = _write(tmp_path / "before.csv", _grid("ours", 0.95)[:21])
    out = tmp_path / "check.md"
    assert oracle_check.main([lever, "--baseline", base, "--describe", "--baseline-label", "ours before the fix",
                              "--out", str(out)]) == 0
    text = out.read_text()
    assert "**Against ours before the fix on the same 21 cells (described, no rule).** Pooled 0.900" in text
    assert "adopted" not in text and "against ours before the fix on the same 21 cells -0.050 [" in text
    assert "| ours before the fix (baseline) |" in text


def test_a_partial_grids_change_says_which_u_chains_it_extrapolates_over(tmp_path):
    rows = [r for r in _grid("ours", lambda m, s: 0.99 - 0.02 * scaling.rooms(m)) if scaling.rooms(r["maze"]) <= 2]
    out = tmp_path / "check.md"
    assert oracle_check.main([_write(tmp_path / "t.csv", rows), "--level", "0.90", "--out", str(out)]) == 0
    text = out.read_text()
    assert "(extrapolated: no run yet of U-chain 3, U-chain 4, U-chain 5)." in text  # the summary's change
    assert "from 1 to 5 rooms: partial (" in text and "; extrapolated: no run yet of U-chain 3" in text
    assert "extrapolated" not in oracle_check.change_text(scaling.flat_claim(_grid("ours", 0.95)), verdict=True)


def test_costs_give_each_mazes_spending_as_a_multiple_of_the_baselines(tmp_path):
    def spending(rows, calls, evaluations, steps):
        return [r | {"proposer_calls": calls, "evaluations": evaluations, "sim_steps": steps} for r in rows]

    lever = _write(tmp_path / "paper.csv", spending(_grid("ours", 0.90), 3, 40, 500))
    base = _write(tmp_path / "nearest.csv", spending(_grid("ours", 0.92), 4, 10, 100))
    out = tmp_path / "check.md"
    assert oracle_check.main([lever, "--baseline", base, "--describe", "--costs", "--level", "0.90", "--out",
                              str(out)]) == 0
    text = out.read_text()
    assert "| difference | calls / evaluations / simulator steps (x baseline) |" in text
    assert "| u_chain_5 | 3 | 0.900 [0.873, 0.922] (600) | 0.920 [0.896, 0.939] (600) | -0.020 [" in text
    assert text.count("| 0.75x / 4.00x / 5.00x |") == len(scaling.MAZES)
    assert "It spent 0.75x / 4.00x / 5.00x the baseline's calls / evaluations / simulator steps.\n" in text
    plain = tmp_path / "plain.md"
    assert oracle_check.main([lever, "--baseline", base, "--describe", "--level", "0.90", "--out", str(plain)]) == 0
    assert "x baseline" not in plain.read_text() and "It spent" not in plain.read_text()


def test_costs_without_a_baseline_is_one_line(tmp_path, capsys):
    table = _write(tmp_path / "t.csv", _grid("ours", 0.98))
    with pytest.raises(SystemExit) as exit_:
        oracle_check.main([table, "--costs", "--out", str(tmp_path / "check.md")])
    assert exit_.value.code == 2 and "--baseline" in capsys.readouterr().err
    assert not (tmp_path / "check.md").exists()


def test_costs_on_a_table_without_them_is_one_line(tmp_path, capsys):
    lever = _write(tmp_path / "lever.csv", _grid("ours", 0.90))  # no proposer_calls recorded
    base = _write(tmp_path / "base.csv", _grid("ours", 0.92))
    with pytest.raises(SystemExit) as exit_:
        oracle_check.main([lever, "--baseline", base, "--costs", "--out", str(tmp_path / "check.md")])
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and len(err.strip().splitlines()) == 1 and "no proposer_calls" in err
    assert not (tmp_path / "check.md").exists()
