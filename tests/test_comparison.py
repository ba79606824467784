"""specrefine.experiments.comparison on small synthetic tables: the claims' verdicts, missing cells, figures and the
CLI."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from specrefine.experiments import comparison as cmp
from specrefine.runs.sweep import COLUMNS, read_table

MODERATE = "imperfect:moderate"


def row(maze, method, success, seed, proposer=MODERATE, status="ok"):
    return {"cell": f"{maze}__point__{method}__{proposer}__s{seed}", "maze": maze, "agent": "point",
            "method": method, "proposer": proposer, "proposer_is_vlm": False, "seed": seed, "status": status,
            "error": "" if status == "ok" else "boom", "success_rate": success, "success_ci_low": 0.0,
            "success_ci_high": 1.0, "episodes": 200, "evaluations": 10, "graph_vertices": 3, "spec": ""}


def ratio_rows(oneshot_of, ratio, seeds=cmp.SEEDS, proposer=MODERATE):
    """ours = ratio x vlm-oneshot in every multi-room cell; vlm-oneshot's success from oneshot_of(maze, seed)."""
    rows = []
    for i, maze in enumerate(cmp.MULTI_ROOM_MAZES):
        for seed in seeds:
            base = oneshot_of(i, seed)
            rows += [row(maze, "vlm-oneshot", base, seed, proposer), row(maze, "ours", ratio * base, seed, proposer)]
    return rows


def rooms_rows(method, success_of, seeds=cmp.SEEDS, proposer=MODERATE):
    return [row(maze, method, success_of(n, seed), seed, proposer)
            for n, maze in cmp.U_CHAIN_ROOMS.items() for seed in seeds]


def entry(entries, method, proposer=MODERATE):
    """The rooms entry of ``method``, or the ratio entry for method 'ratio'."""
    kind = "ratio" if method == "ratio" else "rooms"
    return next(e for e in entries if (e["proposer"], e["kind"]) == (proposer, kind)
                and (kind == "ratio" or e["method"] == method))


def test_exact_two_and_a_half_times_holds():
    rows = ratio_rows(lambda i, seed: 0.1 + 0.03 * i + 0.01 * seed, 2.5)
    e = entry(cmp.claims(rows), "ratio")
    assert e["estimate"] == pytest.approx(2.5)
    assert e["ci_low"] == pytest.approx(2.5) and e["ci_high"] == pytest.approx(2.5)
    assert e["verdict"] == "holds"
    assert e["complete"] and e["n_cells"] == e["n_expected"] == 8 * 4 and e["seeds"] == [0, 1, 2, 3]


def test_ratio_below_two_does_not_hold():
    rows = ratio_rows(lambda i, seed: 0.2 + 0.02 * seed, 1.2)
    assert entry(cmp.claims(rows), "ratio")["verdict"] == "does not hold"


def test_ratio_interval_straddling_two_is_undecided():
    # half the cells at 1.2x, half at 3x: the mean ratio is near 2 and the resampled cells move it both ways
    rows = []
    for i, maze in enumerate(cmp.MULTI_ROOM_MAZES):
        for seed in cmp.SEEDS:
            factor = 3.0 if (i + seed) % 2 else 1.2
            rows += [row(maze, "vlm-oneshot", 0.3, seed), row(maze, "ours", factor * 0.3, seed)]
    e = entry(cmp.claims(rows), "ratio")
    assert e["ci_low"] < 2 < e["ci_high"]
    assert e["verdict"] == "undecided"


def test_a_one_shot_above_half_leaves_no_room_for_2x_and_the_rule_text_says_so():
    # the one-shot at 0.75 on every cell: even ours at 1.000 everywhere gives 1/0.75 = 1.333, below 2
    e = entry(cmp.claims(ratio_rows(lambda i, seed: 0.75, 1 / 0.75)), "ratio")
    assert e["estimate"] == pytest.approx(4 / 3) and e["ceiling"] == pytest.approx(4 / 3)
    assert cmp.ratio_rule_text(e).endswith("; at most 1.333 is possible here (the one-shot's mean 0.750, every cell "
                                           "at 1.000 would give that)")
    low = entry(cmp.claims(ratio_rows(lambda i, seed: 0.25, 3.0)), "ratio")  # room for 2x: the interval alone
    assert low["ceiling"] == pytest.approx(4.0) and cmp.ratio_rule_text(low) == cmp._interval_text(low)
    rows = [row(maze, m, 0.5 if m == "ours" else 0.0, seed, MODERATE)
            for maze in cmp.MULTI_ROOM_MAZES for seed in cmp.SEEDS for m in ("ours", "vlm-oneshot")]
    zero = entry(cmp.claims(rows), "ratio")  # a one-shot at 0: no ceiling
    assert zero["ceiling"] == math.inf and cmp.ratio_rule_text(zero) == cmp._interval_text(zero)


def test_bootstrap_is_reproducible():
    rng = np.random.default_rng(5)
    rows = ratio_rows(lambda i, seed: rng.uniform(0.1, 0.4), 2.0)
    for r in rows:
        r["success_rate"] = min(1.0, r["success_rate"] + rng.normal(0, 0.05))
    first, second = (entry(cmp.claims(rows), "ratio") for _ in range(2))
    assert (first["ci_low"], first["ci_high"]) == (second["ci_low"], second["ci_high"])


def test_one_shot_never_succeeding_gives_an_infinite_ratio():
    rows = ratio_rows(lambda i, seed: 0.0, 1.0) + [row("u_chain_2", "ours", 0.5, 0)]  # the later row counts
    e = entry(cmp.claims(rows), "ratio")
    # ours is 0.5 in one cell only, one-shot 0 everywhere: resamples without that cell are 0/0
    assert e["estimate"] == np.inf
    assert np.isnan(e["ci_low"]) and e["verdict"] == "undecided" and "0/0" in e["note"]


def test_missing_and_failed_cells_are_reported():
    rows = ratio_rows(lambda i, seed: 0.3, 2.5)
    rows = [r for r in rows if not (r["maze"] == "u_chain_3" and r["seed"] == 2 and r["method"] == "vlm-oneshot")]
    rows = [r if not (r["maze"] == "u_chain_4" and r["seed"] == 1 and r["method"] == "ours")
            else {**r, "status": "error", "success_rate": ""} for r in rows]
    e = entry(cmp.claims(rows), "ratio")
    assert e["missing"] == ["u_chain_3 s2: vlm-oneshot (no row)", "u_chain_4 s1: ours (failed)"]
    assert (e["n_cells"], e["n_expected"], e["complete"]) == (30, 32, False)
    assert e["verdict"] == "holds"  # on the cells present, and said to be partial
    assert "(*partial*)" in cmp.markdown([e]) and "30/32" in cmp.markdown([e])


def test_a_preset_without_rows_is_all_missing():
    e = entry(cmp.claims(ratio_rows(lambda i, seed: 0.3, 2.5)), "ratio", "imperfect:severe")
    assert e["n_cells"] == 0 and len(e["missing"]) == 32 and e["verdict"] == "undecided" and e["seeds"] == []


def test_flat_series_is_flat():
    rows = rooms_rows("ours", lambda n, seed: 0.9 + 0.01 * (seed - 1.5))
    e = entry(cmp.claims(rows), "ours")
    assert e["estimate"] == pytest.approx(0.0, abs=1e-12)
    assert e["verdict"] == "flat" and e["paper"] == "flat" and e["n_cells"] == 20


def test_falling_series_falls_and_small_drift_is_not_flat_by_decree():
    rows = rooms_rows("vlm-oneshot", lambda n, seed: 0.9 - 0.1 * (n - 1) + 0.01 * seed)
    rows += rooms_rows("ours", lambda n, seed: 0.9 - 0.012 * (n - 1) + 0.05 * (seed % 2))
    entries = cmp.claims(rows)
    falls = entry(entries, "vlm-oneshot")
    assert falls["estimate"] == pytest.approx(-0.4) and falls["verdict"] == "falls" and falls["paper"] == "falls"
    drift = entry(entries, "ours")  # a drop of 0.048 with seed noise: its interval leaves +-0.05
    assert drift["estimate"] == pytest.approx(-0.048)
    assert drift["verdict"] == "undecided"


def test_rooms_missing_a_whole_room_says_so():
    rows = [r for r in rooms_rows("ours", lambda n, seed: 0.8) if r["maze"] != "u_chain_4"]
    e = entry(cmp.claims(rows), "ours")
    assert e["n_cells"] == 16 and "[4]" in e["note"] and not e["complete"]


def test_verdict_boundaries():
    assert cmp.threshold_verdict((2.0, 2.3), 2.0) == "holds"
    assert cmp.threshold_verdict((1.5, 1.99), 2.0) == "does not hold"
    assert cmp.rooms_verdict((-0.05, 0.05)) == "flat"
    assert cmp.rooms_verdict((0.06, 0.2)) == "rises"
    assert cmp.rooms_verdict((-0.2, 0.0)) == "undecided"


def test_mean_ci_uses_student_t():
    mean, lo, hi = cmp.mean_ci([0.5, 0.6, 0.7, 0.8])
    assert mean == pytest.approx(0.65)
    assert hi - mean == pytest.approx(3.182 * np.std([0.5, 0.6, 0.7, 0.8], ddof=1) / 2)
    assert cmp.mean_ci([0.4]) == (0.4, 0.4, 0.4)


def test_every_figure_panel_says_offline(tmp_path):
    rows = []
    for proposer in cmp.PRESETS[:2]:
        for method in cmp.COMPARISON_METHODS:
            rows += rooms_rows(method, lambda n, seed: 0.5, seeds=(0, 1), proposer=proposer)
    figures = cmp.comparison_figures(rows)
    assert set(figures) == {"figure4", "figure5", "error_levels"}
    for name in ("figure5", "error_levels"):
        titles = [ax.get_title() for ax in figures[name].axes]
        assert titles and all("offline error model, not a VLM" in t for t in titles), (name, titles)
    assert len(figures["error_levels"].axes) == 5


def write_csv(path, rows):
    with path.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, COLUMNS, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)


def test_cli_writes_figures_and_claims(tmp_path, capsys):
    rows = ratio_rows(lambda i, seed: 0.3, 2.5) + rooms_rows("ours", lambda n, seed: 0.9)
    table = tmp_path / "results.csv"
    write_csv(table, rows)
    assert len(read_table(table)) == len(rows)
    out = tmp_path / "out"
    assert cmp.main([str(table), "--out", str(out)]) == 0
    for name in ("figure4.png", "figure5.png", "error_levels.png", "claims.md", "claims.json"):
        assert (out / name).stat().st_size > 0, name
    data = json.loads((out / "claims.json").read_text())
    assert len(data["claims"]) == len(cmp.PRESETS) * (1 + len(cmp.COMPARISON_METHODS))
    assert data["about"]["flat_tolerance"] == cmp.FLAT_TOLERANCE
    assert "PARTIAL" in capsys.readouterr().out


def test_cli_refuses_a_missing_table(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        cmp.main([str(tmp_path / "nope.csv"), "--out", str(tmp_path / "out")])
    assert exc.value.code == 2 and "no table" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_table_note_tolerates_a_missing_file(tmp_path):
    assert "no comparison table" in cmp.table_note(tmp_path / "nope.csv", [])


@pytest.mark.filterwarnings("error")
def test_figure5_legend_when_the_last_preset_has_no_u_chain_runs_yet():
    rows = rooms_rows("ours", lambda n, seed: 0.5, proposer="imperfect:mild")
    rows.append(row("split_doorway", "ours", 0.5, 0, proposer=MODERATE))
    fig = cmp.comparison_figures(rows)["figure5"]
    legend = fig.axes[-1].get_legend()
    assert legend is not None and [t.get_text() for t in legend.get_texts()][0] == "ours (no subgoals)"


def test_calibration_figure_counts_runs_inside_the_predicted_interval():
    from specrefine.experiments.figures import calibration_figure

    rows = [{"success_rate": 0.9, "predicted_success": 0.88, "predicted_ci_low": 0.8, "predicted_ci_high": 0.95},
            {"success_rate": 0.5, "predicted_success": 0.9, "predicted_ci_low": 0.8, "predicted_ci_high": 0.97},
            {"success_rate": 0.7, "predicted_success": "", "predicted_ci_low": "", "predicted_ci_high": ""}]
    fig = calibration_figure({"runs": rows})
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels == ["runs: 1/2 covered"]


def ant_row(maze, method, success, seed, proposer):
    return {**row(maze, method, success, seed, proposer), "agent": "ant",
            "cell": f"{maze}__ant__{method}__{proposer}__s{seed}"}


def test_ant_grid_counts_methods_without_a_proposer_once_per_seed():
    from specrefine.core.mazes import benchmark_mazes

    # dirl and symbolic once per seed, vlm-oneshot and ours once per proposer: 6 runs per maze and seed
    assert cmp.expected_cells(cmp.ANT_GRID) == len(benchmark_mazes()) * 6 * 3
    rows = [ant_row("u_maze", "dirl", 0.0, 0, "none"), ant_row("u_maze", "ours", 0.9, 0, "geometric"),
            row("u_maze", "ours", 0.9, 1, "geometric")]  # a point row: another agent, not counted
    note = cmp.table_note(__file__, rows, cmp.ANT_GRID)
    assert f"PARTIAL, 2 of {cmp.expected_cells(cmp.ANT_GRID)} runs" in note


def test_ant_grid_claims_test_ours_and_oneshot_per_proposer_on_ant_rows_only():
    rows = []
    for proposer in cmp.ANT_GRID.proposers:
        for maze in cmp.MULTI_ROOM_MAZES:
            for seed in cmp.ANT_GRID.seeds:
                rows += [ant_row(maze, "vlm-oneshot", 0.2, seed, proposer), ant_row(maze, "ours", 0.8, seed, proposer)]
    rows += [row(maze, "vlm-oneshot", 0.8, 0, "geometric") for maze in cmp.MULTI_ROOM_MAZES]  # point: ignored
    entries = cmp.claims(rows, cmp.ANT_GRID)
    assert [(e["proposer"], e["kind"], e["method"]) for e in entries] == [
        (p, kind, m) for p in cmp.ANT_GRID.proposers
        for kind, m in (("ratio", "ours / vlm-oneshot"), ("rooms", "ours"), ("rooms", "vlm-oneshot"))]
    ratio = entries[0]
    assert ratio["estimate"] == pytest.approx(4.0) and ratio["verdict"] == "holds" and ratio["complete"]
    assert ratio["n_expected"] == len(cmp.MULTI_ROOM_MAZES) * 3


def test_ant_cli_draws_figures_4_and_5_without_error_levels(tmp_path):
    rows = [ant_row(maze, method, 0.5, seed, "none" if method in ("dirl", "symbolic") else proposer)
            for proposer in cmp.ANT_GRID.proposers for maze in ("u_chain_1", "u_chain_2", "u_maze")
            for method in cmp.ANT_GRID.methods for seed in (0, 1)]
    table = tmp_path / "results.csv"
    write_csv(table, rows)
    out = tmp_path / "out"
    assert cmp.main([str(table), "--out", str(out), "--grid", "ant"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["claims.json", "claims.md", "figure4.png", "figure5.png",
                                                     "seed0.md", "seed1.md", "seed2.md"]
    assert json.loads((out / "claims.json").read_text())["about"]["agent"] == "ant"
    assert (out / "seed2.md").read_text().startswith(f"Seed 2: 0 of {cmp.expected_cells(cmp.ANT_GRID) // 3} cells")


def test_seed_table_one_line_per_maze_methods_without_a_proposer_once():
    from specrefine.core.mazes import benchmark_mazes

    rows = [ant_row("u_maze", "dirl", 0.0, 1, "none"), ant_row("u_maze", "ours", 0.9, 1, "imperfect:moderate"),
            ant_row("u_maze", "ours", 0.8, 0, "geometric"),  # another seed
            ant_row("x_maze", "ours", 0.7, 1, "geometric") | {"status": "error"},  # failed: no result
            row("x_maze", "ours", 0.6, 1, "geometric")]  # the point mass: another agent
    rows[1] |= {"success_ci_low": 0.85, "success_ci_high": 0.94}
    table, shown, expected = cmp.seed_table(rows, cmp.ANT_GRID, 1)
    lines = table.splitlines()
    assert lines[0] == ("| maze | dirl | symbolic | vlm-oneshot, geometric | ours, geometric | "
                        "vlm-oneshot, imperfect:moderate | ours, imperfect:moderate |")
    assert len(lines) == 2 + len(benchmark_mazes()) and (shown, expected) == (2, 6 * len(benchmark_mazes()))
    assert "| u_maze | 0.000 [0.000, 1.000] | — | — | — | — | 0.900 [0.850, 0.940] |" in lines
    assert "| x_maze | — | — | — | — | — | — |" in lines


def test_seed_contrast_sorts_mazes_by_disjoint_intervals_and_counts_the_absent():
    from specrefine.core.mazes import benchmark_mazes

    def run(maze, method, success, low, high, proposer="geometric", seed=2):
        return ant_row(maze, method, success, seed, proposer) | {"success_ci_low": low, "success_ci_high": high}

    rows = [run("u_maze", "ours", 0.9, 0.85, 0.94), run("u_maze", "vlm-oneshot", 0.5, 0.43, 0.57),  # above
            run("x_maze", "ours", 0.0, 0.0, 0.02), run("x_maze", "vlm-oneshot", 0.3, 0.24, 0.37),  # below, at 0
            run("or_maze", "ours", 0.5, 0.43, 0.57), run("or_maze", "vlm-oneshot", 0.55, 0.48, 0.62),  # overlap
            run("two_doors", "ours", 0.9, 0.85, 0.94),  # no one-shot run: absent
            run("u_maze", "ours", 0.0, 0.0, 0.02, seed=1),  # another seed
            run("x_maze", "ours", 0.9, 0.85, 0.94) | {"status": "error"}]  # failed: not a result
    geometric, moderate = cmp.seed_contrast(rows, cmp.ANT_GRID, 2)
    absent = len(benchmark_mazes()) - 3
    assert geometric == ("- `geometric`: `ours` above `vlm-oneshot` (disjoint 95 % CIs) on 1 maze (u_maze), below on "
                         "1 maze (x_maze), overlapping on 1; `ours` at 0.000 on 1 maze (x_maze); "
                         f"{absent} mazes without both runs.")
    assert moderate.startswith("- `imperfect:moderate`: `ours` above `vlm-oneshot` (disjoint 95 % CIs) on 0 mazes,")
    assert moderate.endswith(f"; {len(benchmark_mazes())} mazes without both runs.")


def test_cli_keeps_its_files_when_stdout_is_closed(tmp_path):
    """`python -m specrefine.experiments.comparison ... | head`: the reader gone, the figures and claims are still
    written."""
    import os
    import subprocess
    import sys

    table, out = tmp_path / "results.csv", tmp_path / "out"
    write_csv(table, ratio_rows(lambda i, seed: 0.3, 2.5))
    read_end, write_end = os.pipe()
    os.close(read_end)  # every write to stdout now fails with a broken pipe
    proc = subprocess.run([sys.executable, "-m", "specrefine.experiments.comparison", str(table), "--out", str(out)],
                          stdout=write_end, stderr=subprocess.PIPE, text=True)
    os.close(write_end)
    assert (proc.returncode, proc.stderr) == (1, "")
    assert all((out / name).stat().st_size > 0 for name in ("figure4.png", "claims.md", "claims.json"))


def test_mean_ratio_is_the_ratio_of_means_over_paired_rows():
    import math

    from specrefine.experiments.comparison import mean_ratio

    pairs = [({"calls": "30"}, {"calls": "10"}), ({"calls": "10"}, {"calls": "30"})]
    assert mean_ratio(pairs, "calls") == 1.0  # not the mean of the per-pair ratios (5/3)
    assert mean_ratio(pairs[:1], "calls") == 3.0
    assert math.isnan(mean_ratio([], "calls"))
