"""The calibrated prediction: a Jeffreys posterior on held-out end-to-end episodes, its interval's coverage."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from specrefine.core.mazes import MAZE_DIR
from specrefine.runs.calibrate import coverage, product_posterior
from specrefine.runs.pipeline import refine_maze


def test_each_leg_is_charged_even_at_32_of_32():
    p, (lo, hi) = product_posterior([32], [32])
    assert p == pytest.approx(32.5 / 33) and lo < p < hi <= 1.0
    p15, (lo15, _) = product_posterior([32] * 15, [32] * 15)
    assert p15 == pytest.approx((32.5 / 33) ** 15) and p15 < 0.8 and lo15 < 0.7
    assert product_posterior([], []) == (0.0, (0.0, 0.0))
    _, (plo, phi) = product_posterior([32] * 4, [32] * 4, episodes=200)  # what 200 episodes would measure
    post_lo, post_hi = product_posterior([32] * 4, [32] * 4)[1]
    assert plo < post_lo and phi > post_hi  # wider: the measurement's own noise is added


def test_the_interval_covers_the_true_product():
    """Legs with known probabilities, 32 rollouts each: the 95 % interval holds the truth >= 90 % of the time."""
    rng = np.random.default_rng(0)
    hits, trials = 0, 300
    for i in range(trials):
        legs = int(rng.integers(1, 12))
        p = rng.uniform(0.85, 1.0, legs)
        s = rng.binomial(32, p)
        _, (lo, hi) = product_posterior(s, [32] * legs, seed=i, draws=4000)
        hits += lo <= np.prod(p) <= hi
    assert hits / trials >= 0.9


def test_the_predictive_interval_covers_the_measured_rate():
    """64 held-out episodes -> an interval for the rate over 200 fresh ones: it holds it >= 93 % of the time,
    also near 1 (where the former leg-by-leg product was pessimistic)."""
    rng = np.random.default_rng(1)
    for lo_p, hi_p in ((0.5, 1.0), (0.97, 1.0)):
        hits, trials = 0, 400
        for i in range(trials):
            p = rng.uniform(lo_p, hi_p)
            _, (lo, hi) = product_posterior([rng.binomial(64, p)], [64], seed=i, draws=4000, episodes=200)
            hits += lo <= rng.binomial(200, p) / 200 <= hi
        assert hits / trials >= 0.93, (lo_p, hi_p, hits)


def test_result_json_carries_the_calibrated_prediction(tmp_path):
    data = refine_maze("u_chain_1", agent="point", method="ours", proposer="geometric", seed=0, rollouts=8,
                       episodes=20, out=tmp_path).data
    on_disk = json.loads((tmp_path / "result.json").read_text())
    assert on_disk["predicted_ci"] == data["predicted_ci"]
    lo, hi = data["predicted_ci"]
    p_lo, p_hi = data["predicted_p_ci"]
    assert 0.0 <= lo <= hi <= 1.0 and p_lo <= data["predicted_success"] <= p_hi
    assert data["prediction_episodes"] == 64 and 0 <= data["prediction_successes"] <= 64
    assert data["search_estimate"] == pytest.approx(np.prod(data["edge_probabilities"]))
    assert data["prediction_sim_steps"] > 0
    assert coverage([{"success_rate": data["success_rate"], "predicted_ci_low": lo, "predicted_ci_high": hi},
                     {"success_rate": 0.5}]) == (int(lo <= data["success_rate"] <= hi), 1)


def test_a_finished_run_is_predicted_again_from_its_folder(tmp_path, capsys):
    from specrefine.runs.calibrate import main, predict_run

    run = tmp_path / "run"
    data = refine_maze("u_chain_1", agent="point", method="dirl", seed=1, rollouts=8, episodes=20, out=run).data
    again = predict_run(run)
    assert again["predicted_ci"] == data["predicted_ci"] and again["prediction_successes"] == \
        data["prediction_successes"]  # the same held-out episodes
    shipped = tmp_path / "u_chain_1_s1_result.json"  # as shipped: the result file alone
    shipped.write_bytes((run / "result.json").read_bytes())
    assert predict_run(shipped)["prediction_successes"] == data["prediction_successes"]
    table = tmp_path / "predictions.csv"
    assert main([str(run), str(shipped), str(tmp_path / "failed_cell"), "--table", str(table)]) == 0
    out = capsys.readouterr().out
    assert [line.split(",")[0] for line in table.read_text().splitlines()] == ["cell", "run", "u_chain_1_s1_result"]
    assert "/2 measured success rates inside" in out and "skipped 1 run(s) without a result.json" in out
    inside = sum(float(r["predicted_ci_low"]) <= float(r["success_rate"]) <= float(r["predicted_ci_high"])
                 for r in csv.DictReader(table.open()))
    assert main(["--coverage", str(table), str(table)]) == 0  # the same runs twice count once
    last = capsys.readouterr().out.splitlines()[-1]
    assert last.startswith(f"all, distinct runs: {inside}/2 measured") and "; 2 duplicate rows dropped" in last
    elsewhere = tmp_path / "mazes"  # a result naming a maze outside data/mazes/ by its stem
    elsewhere.mkdir()
    (elsewhere / "my_maze.maze").write_bytes((MAZE_DIR / "u_chain_1.maze").read_bytes())
    moved = tmp_path / "moved_result.json"
    moved.write_text(json.dumps({**json.loads(shipped.read_text()), "maze": "my_maze"}))
    assert main([str(moved), "--table", str(tmp_path / "moved.csv")]) == 2  # not found: one line, no traceback
    err = capsys.readouterr().err
    assert "moved_result.json: my_maze: no such maze" in err and len(err.strip().splitlines()) == 1
    assert main([str(moved), "--table", str(tmp_path / "moved.csv"), "--maze-dir", str(elsewhere)]) == 0
    assert predict_run(moved, elsewhere)["prediction_successes"] == data["prediction_successes"]
    with pytest.raises(SystemExit) as exit_:
        main(["--coverage", str(tmp_path / "nope.csv")])
    assert exit_.value.code == 2 and "no such table" in capsys.readouterr().err


def test_coverage_counts_each_run_once_and_reports_the_runs_above_zero(tmp_path, capsys):
    """A run shipped in two tables (an older one without the evaluation and policy columns) counts once; the runs
    measured above 0 are reported apart (a run at 0 predicted near 0 is covered trivially)."""
    from specrefine.runs.calibrate import main

    run = dict(maze="u_maze", agent="point", method="ours", proposer="geometric", rollouts_per_evaluation="32",
               episodes="200", predicted_ci_low="0.9", predicted_ci_high="1.0")
    older = [run | dict(seed="0", success_rate="0.95"), run | dict(seed="1", success_rate="0.0")]
    newer = [run | dict(seed="0", success_rate="0.95", evaluation="fixed", policy="shipped",
                        rollouts_per_evaluation="32.0"),
             run | dict(seed="0", success_rate="0.5", evaluation="adaptive", policy="shipped")]
    tables = []
    for name, rows in (("older.csv", older), ("newer.csv", newer)):
        tables.append(tmp_path / name)
        with tables[-1].open("w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=sorted({k for r in rows for k in r}))
            writer.writeheader()
            writer.writerows(rows)
    assert main(["--coverage", *map(str, tables)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].endswith("1/2 measured success rates inside predicted_ci (50.0%); above 0: 1/1 (100.0%)")
    assert lines[-1].startswith("all, distinct runs: 1/3 measured") and "above 0: 1/2 (50.0%)" in lines[-1]
    assert "1 duplicate rows dropped" in lines[-1] and "0 rows name their run by cell only" in lines[-1]
