"""README's result tables and claims are their tables' numbers: each recomputed here from the shipped CSV it names
(not read from claims.json / claims.md / legs.md, which could be stale), with the package's own functions or, for the
Ant's stage-5 grids, through a path of its own: the plain ``csv`` module and the formula the text states.

A hand-typed or stale figure (a rounding of a rounding, a count from before a table grew) fails here naming the
row; floats are compared as README prints them, verdicts exactly.
"""
from __future__ import annotations

import csv
import importlib.util
import json
import math
import re
from pathlib import Path

import pytest

from specrefine.runs.sweep import read_table, summarise

ROOT = Path(__file__).parents[1]
README = (ROOT / "docs" / "results.md").read_text()  # the results page (README, the front page, links to it)
FRONT = (ROOT / "README.md").read_text()

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


def test_geometric_one_shot_matches_ours_on_every_maze_but_two_doors():
    rows = read_table(ROOT / "data/results/results.csv")
    means = {(s["maze"], s["method"]): s["success_mean"] for s in summarise(rows) if s["proposer"] == "geometric"}
    gaps = {maze: abs(means[maze, "ours"] - means[maze, "vlm-oneshot"]) for maze, m in means if m == "ours"}
    assert max(g for maze, g in gaps.items() if maze != "two_doors") <= 0.004 < gaps["two_doors"]
    text = " ".join(README.split())
    assert "every maze but two_doors (4-seed means within 0.004 of each other on the other 16" in text
    assert f"{means['two_doors', 'vlm-oneshot']:.3f} against {means['two_doors', 'ours']:.3f}" in text


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


def _offline():
    """The offline comparison's claims, contrasts and multi-room means, recomputed from its table (not claims.json)."""
    from specrefine.experiments import comparison as cmp
    from specrefine.runs.sweep import mean_std

    rows = read_table(ROOT / "data/results/imperfect/results.csv")
    cells, _ = cmp.table_cells(rows)
    means = {(p, m): mean_std([cells[maze, m, p, s] for maze in cmp.MULTI_ROOM_MAZES for s in cmp.SEEDS])[0]
             for p in cmp.PRESETS for m in cmp.COMPARISON_METHODS}
    by = {(c["proposer"], c["method"]): c for c in cmp.claims(rows)}
    contrasts = {(c["proposer"], c["claim"]): c for c in cmp.contrasts(rows)}
    return by, contrasts, means


def test_offline_claims_table_is_recomputed_from_its_table():
    by, _, means = _offline()
    fmt = lambda c: f"{c['estimate']:.2f} [{c['ci_low']:.2f}, {c['ci_high']:.2f}]"  # noqa: E731
    table = _table_after("| preset | ours / one-shot, multi-room |")
    presets = {"mild": "imperfect:mild", "moderate": "imperfect:moderate", "severe": "imperfect:severe",
               "moderate, alpha = 0.1": "imperfect:moderate,alpha=0.1"}
    assert [c[0] for c in table] == list(presets)
    for cells in table:
        p = presets[cells[0]]
        ratio, ours, oneshot = by[p, "ours / vlm-oneshot"], by[p, "ours"], by[p, "vlm-oneshot"]
        assert all(c["complete"] for c in (ratio, ours, oneshot)), p
        if math.isfinite(ratio["estimate"]) and not math.isnan(ratio["ci_low"]):
            assert cells[1] == fmt(ratio), p
        elif math.isinf(ratio["estimate"]):  # the one-shot at 0 on every cell
            assert cells[1] == "∞ (one-shot 0.000 on every multi-room cell)", p
            assert means[p, "vlm-oneshot"] == 0
        else:  # an interval undefined: both methods at 0 in some resamples (0/0)
            undefined = re.search(r"in (\d+) of (\d+) resamples", ratio["note"]).groups()
            assert cells[1] == f"{ratio['estimate']:.0f} (both methods at 0 in {int(undefined[0])} of " \
                               f"{int(undefined[1]):,} resamples, 0/0: no interval)", p
        assert cells[2] == ratio["verdict"], p
        assert cells[3] == fmt(ours) and cells[4] == ours["verdict"], p
        assert cells[5] == f"{fmt(oneshot)}, {oneshot['verdict']}", p


def test_offline_means_and_contrasts_are_recomputed_from_its_table():
    from specrefine.experiments.comparison import COMPARISON_METHODS

    by, contrasts, means = _offline()
    for preset, label in (("mild", "mild"), ("moderate", "moderate"), ("severe", "severe"),
                          ("moderate,alpha=0.1", "moderate with alpha 0.1")):
        line = " / ".join(f"{means['imperfect:' + preset, m]:.3f}" for m in COMPARISON_METHODS)
        assert f"{label} {line}" in " ".join(README.split()), preset
    matched = {p: contrasts["imperfect:" + p, "vlm-oneshot-matched - vlm-oneshot"] for p in ("mild", "moderate")}
    text = " ".join(README.split())
    m = matched["mild"]
    matched_mean, oneshot_mean = means["imperfect:mild", "vlm-oneshot-matched"], means["imperfect:mild", "vlm-oneshot"]
    assert (f"{matched_mean:.3f} against {oneshot_mean:.3f}, paired difference "
            f"{m['estimate']:+.3f} [{m['ci_low']:+.3f}, {m['ci_high']:+.3f}]") in text
    assert m["verdict"] == "higher" and matched["moderate"]["verdict"] == "lower"
    m = matched["moderate"]
    assert f"below it at moderate, {m['estimate']:.3f} [{m['ci_low']:.3f}, {m['ci_high']:.3f}]" in text
    for p in ("severe", "moderate,alpha=0.1"):  # "level at severe and alpha 0.1"
        assert contrasts["imperfect:" + p, "vlm-oneshot-matched - vlm-oneshot"]["verdict"] == "undecided", p
    mild, severe = by["imperfect:mild", "ours / vlm-oneshot"], by["imperfect:severe", "ours / vlm-oneshot"]
    assert f"at mild ({mild['estimate']:.2f}x, interval above 1 but not clear of 2" in text
    assert mild["ci_low"] > 1 and mild["verdict"] == "undecided"
    assert (f"at severe both are near 0 ({means['imperfect:severe', 'ours']:.3f} against "
            f"{means['imperfect:severe', 'vlm-oneshot']:.4f}; each is above 0 in one of the 32 cells) and the verdict "
            f"is {severe['verdict']}") in text


def test_calibration_headline_is_the_coverage_command():
    from specrefine.runs.calibrate import coverage_report

    command = re.search(r"python -m specrefine.runs.calibrate --coverage\s+([^`]+)`\) the measured success", README)
    tables = [t for pattern in command.group(1).split() for t in sorted(ROOT.glob(pattern))]
    last = coverage_report(tables).splitlines()[-1]
    pattern = r"all, distinct runs: (\d+/\d+) .*?\(([\d.]+)%\); above 0: (\d+/\d+) \(([\d.]+)%\); (\d+) duplicate"
    runs, share, above, above_share, dropped = re.match(pattern, last).groups()
    text = " ".join(README.split())
    assert f"in **{runs.replace('/', ' of ')} distinct runs ({share} %)**" in text
    assert f"**{above.replace('/', ' of the ')} measured above 0 ({above_share} %)**" in text
    assert f"drops those {dropped} rows" in text


def test_adaptive_table_is_the_bench_markdown():
    from specrefine.bench.refinement import _read, markdown

    table = markdown(_read(ROOT / "data/results/ant/adaptive_bench.csv")).splitlines()
    assert len(table) == 2 + 9  # header, rule, 3 mazes x 3 seeds
    missing = [line for line in table if line not in README.splitlines()]
    assert not missing, missing


def test_ant_comparison_seed_tables_are_complete_seeds_of_the_table():
    """Each seed of the growing Ant comparison that README shows is complete in the table and shown as it is, with
    the lines that contrast ours and the one-shot under it."""
    from specrefine.experiments.comparison import ANT_GRID, seed_contrast, seed_table

    rows = read_table(ROOT / "data/results/ant/comparison.csv")
    seeds = re.findall(r"<!-- ant comparison seed (\d+) -->", README)
    assert seeds, "README shows no seed of the Ant comparison"
    for seed in seeds:
        table, shown, expected = seed_table(rows, ANT_GRID, int(seed))
        assert shown == expected, f"seed {seed}: {shown} of {expected} cells in the table"
        contrast = "\n".join(seed_contrast(rows, ANT_GRID, int(seed)))
        assert f"<!-- ant comparison seed {seed} -->\n{table}\n\n{contrast}\n" in README, f"seed {seed}"


def test_ant_comparison_claims_are_recomputed_from_the_complete_grid():
    """README's Ant claims are specrefine.experiments.comparison's claims of the table, every run of the fixed grid,
    and the shipped claims.md says the same."""
    from specrefine.experiments.comparison import ANT_GRID, claims, expected_cells, grid_cells, markdown, table_cells

    rows = read_table(ROOT / "data/results/ant/comparison.csv")
    assert grid_cells(ANT_GRID) <= set(table_cells(rows, "ant")[0]), "the Ant grid is not complete"
    assert expected_cells(ANT_GRID) == 306
    entries = claims(rows, ANT_GRID)
    assert entries and all(c["complete"] for c in entries)
    table = "\n".join(line for line in markdown(entries).splitlines() if line.startswith("|"))
    assert f"<!-- ant comparison claims -->\n{table}\n" in README
    assert table in (ROOT / "data/results/ant/comparison/claims.md").read_text()


def test_repair_summary_is_the_repair_grid():
    """README's look-ahead repair table is specrefine.experiments.repair_claims' summary of the shipped, complete
    grid."""
    from specrefine.experiments.repair_claims import study

    rows = read_table(ROOT / "data/results/repair/results.csv")
    summary = study(rows).summary()
    assert "(*partial*)" not in summary
    assert f"<!-- repair summary -->\n{summary}\n" in README
    assert (ROOT / "data/results/repair/summary.md").read_text() == summary + "\n"


def test_front_page_point_line_is_results_csv():
    rows = [r for r in read_table(ROOT / "data/results/results.csv") if r["proposer"] in ("geometric", "none")]
    ours = {r["maze"]: r["success_rate"] for r in rows if r["method"] == "ours" and r["seed"] == 0}
    dirl = {r["maze"]: r["success_rate"] for r in rows if r["method"] == "dirl" and r["seed"] == 0}
    good = [m for m, p in ours.items() if p >= 0.99 and dirl[m] == 0.0]
    rest = sorted(set(ours) - set(good))
    text = " ".join(FRONT.split())
    assert f"`ours` reaches at least 0.99 on {len(good)} of the {len(ours)} mazes" in text
    assert rest == ["two_doors"] and f"0.955 (`dirl` {dirl['two_doors']:.3f})" in text
    assert ours["two_doors"] == 0.955


def test_front_page_shows_the_ant_claims_as_computed():
    claims = (ROOT / "data/results/ant/comparison/claims.md").read_text()
    block = FRONT[FRONT.index("<!-- ant comparison claims -->"):].split("\n\n")[0]
    assert block.splitlines()[1:] and all(line in claims for line in block.splitlines()[1:])
    assert block in README  # the same table as the results page, whose test recomputes it from the CSV


#: the control contrasts the results page quotes: (preset, control, verdict of ours - control)
ATTRIBUTION = [("mild", "ours-d1", "higher"), ("moderate", "ours-d1", "higher"),
               ("moderate,alpha=0.1", "ours-d1", "higher"),
               ("mild", "ours-nofeedback", "undecided"), ("moderate", "ours-nofeedback", "undecided"),
               ("moderate,alpha=0.1", "ours-nofeedback", "lower"),
               ("mild", "ours-novertex", "higher"), ("moderate", "ours-novertex", "higher"),
               ("moderate,alpha=0.1", "ours-novertex", "higher"),
               ("mild", "ours-notune", "higher"), ("moderate", "ours-notune", "undecided"),
               ("mild", "ours-nosearchvertex", "undecided"), ("moderate", "ours-nosearchvertex", "lower")]


def test_control_attribution_is_the_tables_contrasts():
    _, contrasts, _ = _offline()
    text = " ".join(README.split())
    for preset, control, verdict in ATTRIBUTION:
        c = contrasts["imperfect:" + preset, f"ours - {control}"]
        assert f"{c['estimate']:+.3f} [{c['ci_low']:+.3f}, {c['ci_high']:+.3f}]" in text, (preset, control)
        assert c["verdict"] == verdict, (preset, control)
    assert all(c["verdict"] == "undecided" for (p, name), c in contrasts.items() if p == "imperfect:severe")


def test_front_page_offline_line_is_the_claims():
    by, contrasts, _ = _offline()
    verdict = {p: by["imperfect:" + p, "ours / vlm-oneshot"]["verdict"] for p in ("mild", "moderate", "severe")}
    assert verdict == {"mild": "undecided", "moderate": "holds", "severe": "undecided"}
    assert all(by[p, "ours"]["verdict"] == "falls" for p, m in by if m == "ours")  # falls at every error level
    said = {("mild", "ours-d1"): "higher", ("moderate", "ours-d1"): "higher", ("mild", "ours-notune"): "higher",
            ("mild", "ours-nofeedback"): "undecided", ("moderate", "ours-nofeedback"): "undecided",
            ("mild", "ours-nosearchvertex"): "undecided"}  # later round and tuning help; feedback, search vertices not
    assert {k: contrasts["imperfect:" + k[0], f"ours - {k[1]}"]["verdict"] for k in said} == said
    assert "at least 2x the one-shot on the multi-room tasks at moderate errors" in " ".join(FRONT.split())


def test_repair_tuned_tables_are_the_tuned_grid():
    """The results page's repair-tuned tables are repair_claims --tuned on the shipped, complete grid."""
    from specrefine.experiments.repair_claims import tuned_study

    entries, _, text = tuned_study(read_table(ROOT / "data/results/repair/tuned.csv"))
    assert all(e["complete"] for e in entries)
    assert "<!-- repair tuned -->\n" + text.split("\n\n", 1)[1] + "\n" in README
    assert (ROOT / "data/results/repair/tuned_claims.md").read_text() == text + "\n"


def test_scaling_seed_tables_are_the_tables():
    """docs/ant_experiments.md's seed-0 table of the scaling grid is experiments.scaling.seed_table of its tables, and
    its sentence's shares of wall time are seed 0's."""
    from specrefine.experiments import scaling

    doc = (ROOT / "docs" / "ant_experiments.md").read_text()
    rows = scaling.read_rows(_grid_tables("ant-scaling"))
    baseline = scaling.read_rows([ROOT / "data/results/ant/comparison.csv"])
    assert "<!-- scaling seed 0 -->\n" + scaling.seed_table(baseline, rows, 0) + "\n" in doc
    multi = [r for r in rows if (r["seed"], r["method"], r["proposer"]) == (0, "ours", scaling.ORACLE)
             and r["maze"] != "u_chain_1"]
    assert len(multi) == 8
    shares = {k: [100 * r[k] / r["wall_seconds"] for r in multi] for k in scaling.PHASES}
    s, m, c = (f"{round(min(v))}-{round(max(v))} %" for v in shares.values())
    assert f"takes {s} of the wall time" in doc and f"measurement\n{m}" in doc and f"episodes {c}" in doc


def _grid_tables(name: str) -> list[Path]:
    """The shipped tables of a grid (those written so far)."""
    from specrefine.experiments import grids

    return [ROOT / t for t in grids.get(name).tables if (ROOT / t).exists()]


def _between(text: str, marker: str) -> str:
    return " ".join(text[text.index(f"<!-- {marker} -->") + len(f"<!-- {marker} -->"):
                         text.index(f"<!-- /{marker} -->")].split())


def test_front_page_centre_lever_is_its_shipped_check():
    check = (ROOT / "data/results/ant/centre_check.md").read_text()
    lever, base, diff = re.search(r"Pooled ([0-9.]+) .*? against ([0-9.]+) .*?: difference (\S+ \[\S+ \S+\])",
                                  check).groups()
    assert _between(FRONT, "front centre") == f"{base} to {lever}, difference {diff}"


def test_front_page_rotated_check_is_its_shipped_check():
    check = (ROOT / "data/results/ant/rotated_centre_check.md").read_text()
    lever, base, diff = re.search(r"Pooled ([0-9.]+) .*? against ([0-9.]+) .*?: difference (\S+ \[\S+ \S+\])",
                                  check).groups()
    assert _between(FRONT, "front rotated") == f"{lever} against {base}, difference {diff}"


# The Ant's stage-5 grids, recomputed with the csv module alone and the formulas the text states: success pooled
# over seeds 0-2 (successes = rate x episodes), the change from 1 to 5 rooms as the least-squares slope of the
# seed means on U-chain 1-5 times 4, its interval the 2.5 and 97.5 % points of the bootstrap that resamples the
# seeds within each room (enumerated exactly here; the package draws 10,000 resamples, hence the tolerance).
ORACLE = "geometric:max_waypoints=48"
ERRING = "imperfect:moderate"
CENTRE = ["data/results/ant/centre.csv", "data/results/ant/scaling/ours_centre.csv",
          "data/results/ant/scaling/oneshot_centre.csv", "data/results/ant/scaling/imperfect_centre.csv",
          "data/results/ant/scaling/repair_geometric_centre.csv"]
SAMPLED = ["data/results/ant/scaling/ours_geometric.csv", "data/results/ant/scaling/oneshot.csv"]
PLAIN = [f"u_chain_{n}" for n in range(1, 6)]
SCALING = [m for n in range(1, 6) for m in (f"u_chain_{n}", f"u_chain_{n}_subgoals") if m != "u_chain_1_subgoals"]
SUBGOALS = [f"u_chain_{n}_subgoals" for n in range(2, 6)]
MULTI_ROOM = [m for n in range(2, 6) for m in (f"u_chain_{n}", f"u_chain_{n}_subgoals")]


def _csv_runs(tables) -> dict:
    """{(maze, method, proposer): {seed: row}} of the ok rows, by the csv module alone; one row per run."""
    import csv

    runs: dict = {}
    for table in tables:
        with (ROOT / table).open(newline="") as fh:
            for row in csv.DictReader(fh):
                if row["status"] == "ok":
                    seeds = runs.setdefault((row["maze"], row["method"], row["proposer"]), {})
                    assert int(row["seed"]) not in seeds, (table, row["cell"])
                    seeds[int(row["seed"])] = row
    return runs


def _rates(runs, method, proposer, mazes) -> list[float]:
    """Success pooled over seeds 0-2 per maze."""
    out = []
    for maze in mazes:
        seeds = runs[maze, method, proposer]
        assert sorted(seeds) == [0, 1, 2], (maze, method, proposer)
        ok = sum(round(float(r["success_rate"]) * int(r["episodes"])) for r in seeds.values())
        out.append(ok / sum(int(r["episodes"]) for r in seeds.values()))
    return out


def _change(room_values: list[list[float]]) -> float:
    """4 x the least-squares slope of the room means over 1-5 rooms (x centred: -2..2, sum of x^2 = 10)."""
    return 4 * sum(x * sum(v) / len(v) for x, v in zip(range(-2, 3), room_values)) / 10


def _change_interval(room_values: list[list[float]]) -> tuple[float, float]:
    """The exact percentile bootstrap of _change with the seeds resampled within each room."""
    import itertools
    from collections import Counter

    dist = {0.0: 1.0}
    for x, values in zip(range(-2, 3), room_values):
        draws = Counter(sum(d) / len(d) for d in itertools.product(values, repeat=len(values)))
        total = len(values) ** len(values)
        step: dict = {}
        for a, pa in dist.items():
            for mean, count in draws.items():
                key = round(a + 0.4 * x * mean, 12)
                step[key] = step.get(key, 0.0) + pa * count / total
        dist = step
    cum, lo, hi = 0.0, None, None
    for value, prob in sorted(dist.items()):
        cum += prob
        lo = value if lo is None and cum >= 0.025 - 1e-12 else lo
        hi = value if hi is None and cum >= 0.975 - 1e-12 else hi
    return lo, hi


def _room_values(runs, method, proposer) -> list[list[float]]:
    return [[float(r["success_rate"]) for r in runs[maze, method, proposer].values()] for maze in PLAIN]


def _change_text(runs, method, proposer, printed: str) -> str:
    """The change as README prints it, its interval checked against the exact bootstrap."""
    values = _room_values(runs, method, proposer)
    lo, hi = (float(x) for x in re.search(r"\[(\S+), (\S+)\]", printed).groups())
    exact = _change_interval(values)
    assert abs(lo - exact[0]) <= 0.002 and abs(hi - exact[1]) <= 0.002, (printed, exact)
    return f"{_change(values):+.3f} [{lo:+.3f}, {hi:+.3f}]"


def _three(values) -> str:
    return ", ".join(f"{v:.3f}" for v in values)


def test_front_page_centre_grid_is_its_csvs():
    runs = _csv_runs(CENTRE)
    text = _between(FRONT, "front centre grid")
    printed = re.search(r"rooms (\S+ \[\S+ \S+\])$", text).group(1)
    assert text == (f"{_three(_rates(runs, 'ours', ORACLE, PLAIN))} for 1-5 rooms (with subgoals "
                    f"{_three(_rates(runs, 'ours', ORACLE, SUBGOALS))}); change from 1 to 5 rooms "
                    f"{_change_text(runs, 'ours', ORACLE, printed)}")
    assert min(_rates(runs, "ours", ORACLE, PLAIN + SUBGOALS)) >= 0.90  # "at least 0.90 at every length holds"
    assert "**At least 0.90 at every length holds; flat within ±0.05 does not.**" in " ".join(FRONT.split())
    assert _change_interval(_room_values(runs, "ours", ORACLE))[0] < -0.05


def test_front_page_one_shot_with_the_oracle_is_its_csv():
    """The near-flat curve is the one-shot's too: README names its numbers and the runs where they are equal."""
    runs = _csv_runs(CENTRE)
    text = _between(FRONT, "front centre oneshot")
    printed = re.search(r"change (\S+ \[\S+ \S+\])", text).group(1)
    same = sum(runs[maze, "ours", ORACLE][s]["success_rate"] == runs[maze, "vlm-oneshot", ORACLE][s]["success_rate"]
               for maze in PLAIN + SUBGOALS for s in (0, 1, 2))
    assert text == (f"{_three(_rates(runs, 'vlm-oneshot', ORACLE, PLAIN))} for 1-5 rooms; change "
                    f"{_change_text(runs, 'vlm-oneshot', ORACLE, printed)}; the same success as `ours` in {same} of "
                    f"the {3 * len(PLAIN + SUBGOALS)} runs")
    assert "**`ours --goal-points centre`** with the same oracle" in " ".join(FRONT.split())


def test_front_page_sampled_goal_points_are_their_csv():
    """The paper's rule (sampled goal points), stage 5, cap 48: README names it beside the centre variant."""
    runs = _csv_runs(SAMPLED)
    text = _between(FRONT, "front sampled grid")
    printed = re.search(r"rooms (\S+ \[\S+ \S+\]);", text).group(1)
    below = sum(r < 0.90 for r in _rates(runs, "ours", ORACLE, PLAIN + SUBGOALS))
    assert text == (f"{_three(_rates(runs, 'ours', ORACLE, PLAIN))} for 1-5 rooms; change from 1 to 5 rooms "
                    f"{_change_text(runs, 'ours', ORACLE, printed)}; {below} of the 9 mazes below 0.90")
    with (ROOT / "data/results/ant/scaling/ours_geometric.csv").open() as fh:
        assert "goal_points" not in fh.readline()  # from before the option: every row aimed at sampled points


def test_front_page_leg_losses_and_legs_per_room_are_the_centre_grids():
    import json

    from specrefine.experiments.legs import turn_table

    profiles = json.loads((ROOT / "data/results/ant/scaling_centre/leg_profiles.json").read_text())
    rate = {line.split(" | ")[0].strip("| "): float(line.split(" | ")[-1].split()[0])
            for line in turn_table(profiles).splitlines()[2:]}
    assert " ".join(_between(FRONT, "front turns").split()) == (
        f"{100 * rate['straight']:.2f} % of the episodes that start it when it runs straight and "
        f"{100 * rate['turning']:.2f} % when it turns, against {100 * rate['first leg']:.2f} % for a path's first leg")
    runs = _csv_runs(CENTRE)
    # the profiles are of the shipped runs: each one's legs and successes are its row's
    assert len(profiles) == 27
    for p in profiles:
        row = runs[p["maze"], "ours", ORACLE][p["seed"]]
        assert len(p["leg_failure"]) == int(float(row["path_edges"])), (p["maze"], p["seed"])
        assert p["episode_outcomes"].get("success", 0) == round(float(row["success_rate"]) * p["episodes"])
    per_room = [sum(float(r["path_edges"]) for r in runs[maze, "ours", ORACLE].values()) / 3
                / int(maze.split("_")[2]) for maze in PLAIN + SUBGOALS]
    assert _between(FRONT, "front legs") == f"{min(per_room):.1f}-{max(per_room):.1f} legs per room"


def _erring_cells(runs, method) -> list[tuple[str, int, float]]:
    return [(maze, s, float(runs[maze, method, ERRING][s]["success_rate"])) for maze in MULTI_ROOM for s in (0, 1, 2)]


def test_front_page_erring_line_is_the_centre_grids_csvs():
    """The better of ours / ours-repair per maze (higher mean over seeds, a tie keeps ours) over the one-shot's mean
    on the multi-room runs; ours alone beside it; the runs of ours at 0 and what the repair made of them."""
    from specrefine.experiments.comparison import bootstrap_ratio

    runs = _csv_runs(CENTRE)
    shot = [v for _, _, v in _erring_cells(runs, "vlm-oneshot")]
    ours, repair = _erring_cells(runs, "ours"), _erring_cells(runs, "ours-repair")
    chosen = []
    for maze in MULTI_ROOM:
        mine, fixed = ([v for m, _, v in cells if m == maze] for cells in (ours, repair))
        chosen += fixed if sum(fixed) > sum(mine) else mine
    zeros = [(m, s) for m in ["u_chain_1", *MULTI_ROOM] for s in (0, 1, 2)
             if float(runs[m, "ours", ERRING][s]["success_rate"]) == 0]
    lifted = sum(float(runs[m, "ours-repair", ERRING][s]["success_rate"]) > 0 for m, s in zeros)

    def ratio(values):
        _, (lo, hi), _ = bootstrap_ratio(np.array(values), np.array(shot))  # the comparison's bootstrap
        return sum(values) / sum(shot), lo, hi

    import numpy as np

    best, lo, hi = ratio(chosen)
    assert _between(FRONT, "front erring") == (
        f"{best:.1f}x the one-shot [{lo:.1f}, {hi:.1f}] on the multi-room mazes ({len(shot)} paired runs; the rule: "
        f"{'holds' if best >= 2 else 'not met'}); `ours` ends at 0 in {len(zeros)} of 27 runs and `ours-repair` "
        f"lifts {lifted} of them above 0")
    alone, lo, hi = ratio([v for _, _, v in ours])
    assert _between(FRONT, "front erring ours") == f"{alone:.1f}x [{lo:.1f}, {hi:.1f}]"


def test_front_page_ant_sentences_the_tables_carry():
    """The stage-4 legs per room and per-leg failure, the rotated check's wording, the cost's goal-point rule, the
    one-shot's better two_doors, the attribution at moderate, row 286's rerun and where the one-shot table ran."""
    import csv
    import json

    with (ROOT / "data/results/ant/comparison.csv").open(newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if (r["method"], r["proposer"]) == ("ours", "geometric")]
    legs, fail = {}, {}
    for maze in PLAIN + SUBGOALS:
        runs = [r for r in rows if r["maze"] == maze]
        n_legs = sum(float(r["path_edges"]) for r in runs) / len(runs)
        ok = sum(round(float(r["success_rate"]) * int(r["episodes"])) for r in runs)
        legs[maze] = n_legs / int(maze.split("_")[2])
        fail[maze] = 1 - (ok / sum(int(r["episodes"]) for r in runs)) ** (1 / n_legs)
    rest = [m for m in PLAIN[1:] + SUBGOALS if m != "u_chain_5"]  # from two rooms on; U-chain 5 has doubled legs
    assert " ".join(_between(FRONT, "front stage4 legs").split()) == (
        f"{min(legs[m] for m in rest):.1f}-{max(legs[m] for m in rest):.1f} legs per room from two rooms on, each "
        f"losing {100 * min(fail[m] for m in rest):.1f}-{100 * max(fail[m] for m in rest):.1f} % of the episodes "
        f"(1 - success^(1/legs)); U-chain 5 without subgoals {legs['u_chain_5']:.1f} legs per room losing "
        f"{100 * fail['u_chain_5']:.1f} % each")
    text = " ".join(FRONT.split())
    assert "no dependence on the direction of travel shown" in text
    lo, hi = (float(x) for x in re.search(r"difference \S+ \[(\S+), (\S+)\]",
                                          (ROOT / "data/results/ant/rotated_centre_check.md").read_text()).groups())
    assert lo < 0 < hi  # a null result: no dependence shown, not none found
    cost = json.loads((ROOT / "data/results/ant/scaling/cost_u_chain_5.json").read_text())
    assert "--goal-points" not in cost["command"] and "d6a96ee" in cost["code"]
    assert "A U-chain 5 run with the paper's sampled goal points (code d6a96ee" in text
    point = {(s["maze"], s["method"]): s["success_mean"]
             for s in summarise(read_table(ROOT / "data/results/results.csv")) if s["proposer"] == "geometric"}
    assert (f"better on two_doors ({point['two_doors', 'vlm-oneshot']:.3f} against {point['two_doors', 'ours']:.3f})"
            in text)
    _, contrasts, _ = _offline()
    mild, moderate = (contrasts[f"imperfect:{p}", "ours - ours-notune"] for p in ("mild", "moderate"))
    assert (mild["verdict"], moderate["verdict"]) == ("higher", "undecided")
    fmt = lambda c: f"{c['estimate']:+.3f} [{c['ci_low']:+.3f}, {c['ci_high']:+.3f}]"  # noqa: E731
    assert _between(FRONT, "front notune") == (f"{fmt(mild)} at mild; at moderate, the one preset where the 2x claim "
                                               f"holds, {fmt(moderate)}, undecided")
    with (ROOT / "data/results/ant/comparison/row286_rerun.csv").open(newline="") as fh:
        (rerun,) = csv.DictReader(fh)
    with (ROOT / "data/results/ant/comparison.csv").open(newline="") as fh:
        shipped = list(csv.DictReader(fh))[285]
    assert rerun["cell"] == shipped["cell"] == "u_maze__ant__ours__geometric__s2__adaptive"
    assert shipped["policy_fingerprint"] == ""
    assert _between(FRONT, "front row286") == (
        f"{float(rerun['success_rate']):.3f} with {rerun['evaluations']} evaluations and {rerun['refinements']} "
        f"refinements, against the shipped {float(shipped['success_rate']):.3f} with {shipped['evaluations']} and "
        f"{shipped['refinements']}")
    with (ROOT / "data/results/ant/scaling/oneshot.csv").open(newline="") as fh:
        assert len(list(csv.DictReader(fh))) == 54
    doc = " ".join((ROOT / "docs/ant_experiments.md").read_text().split())
    assert "53 of part 2's 54 cells" in doc and "16 x86-64 cores" in doc
    assert "except 53 of the 54 runs of `data/results/ant/scaling/oneshot.csv`" in text


def test_front_page_evaluator_ratio_is_the_shipped_benchmark():
    import json

    runs = [json.loads(line) for line in (ROOT / "data/results/bench/evaluator_ant.jsonl").read_text().splitlines()]
    wall = sorted(r["ratio_vs_raw_rollout"] for r in runs)
    assert _between(FRONT, "front evaluator") == f"{wall[0]:.2f}-{wall[-1]:.2f}"
    same_cpu = sorted(r["cpu_ratio_vs_same_work"] for r in runs)
    assert f"{same_cpu[0]:.2f}-{same_cpu[-1]:.2f} by CPU time against its own physics" in " ".join(FRONT.split())


def test_front_page_cost_is_the_shipped_runs():
    import json

    cost = json.loads((ROOT / "data/results/ant/scaling/cost_u_chain_5.json").read_text())
    assert _between(FRONT, "front cost") == " and ".join(f"{r['wall_seconds']:.0f} s" for r in cost["runs"])


SCALING_OURS = "data/results/ant/scaling/ours_geometric.csv"


@pytest.mark.parametrize("table, method, baseline, check, marker", [
    ("data/results/ant/polish.csv", "ours-polish", SCALING_OURS, "data/results/ant/polish_check.md", "polish check"),
    ("data/results/ant/centre.csv", "ours", SCALING_OURS, "data/results/ant/centre_check.md", "centre check"),
    ("data/results/ant/shortcut_centre.csv", "ours-shortcut", "data/results/ant/centre.csv",
     "data/results/ant/shortcut_centre_check.md", "shortcut centre check"),
    ("data/results/ant/shortcut_centre_ties.csv", "ours-shortcut", "data/results/ant/centre.csv",
     "data/results/ant/shortcut_centre_ties_check.md", "shortcut ties check"),
])
def test_a_lever_check_is_the_levers_rule_on_the_shipped_tables(table, method, baseline, check, marker):
    from specrefine.experiments import levers

    def side(table, method):
        return levers._by_cell(ROOT / table, method, "geometric:max_waypoints=48")

    cells = [(m, s) for m in ("u_chain_3", "u_chain_5") for s in (0, 1, 2)]
    lever, base = side(table, method), side(baseline, "ours")
    text = levers.markdown(levers.lever_check(lever, base, cells), levers.label(method, lever),
                           levers.label("ours", base))
    assert (ROOT / check).read_text() == text
    assert f"<!-- {marker} -->\n" + text in (ROOT / "docs" / "ant_experiments.md").read_text()


def test_the_rotated_check_is_the_levers_rule_on_the_shipped_tables(tmp_path, capsys):
    import csv

    from specrefine.experiments import levers

    table = ROOT / "data/results/ant/rotated_centre.csv"
    with table.open(newline="") as fh:
        (maze,) = {row["maze"] for row in csv.DictReader(fh)}
    assert maze == "held_out/u_chain_3_rotated"
    out = tmp_path / "check.md"
    assert levers.main([str(table), "--method", "ours", "--baseline", str(ROOT / "data/results/ant/centre.csv"),
                        "--baseline-method", "ours", "--proposer", "geometric:max_waypoints=48", "--mazes", maze,
                        "--baseline-mazes", "u_chain_3", "--seeds", "0", "1", "2", "--out", str(out)]) == 0
    text = out.read_text()
    assert (ROOT / "data/results/ant/rotated_centre_check.md").read_text() == text
    assert "<!-- rotated check -->\n" + text in (ROOT / "docs" / "ant_experiments.md").read_text()


def test_the_polish_erring_check_is_the_levers_rule_on_the_shipped_tables(tmp_path):
    from specrefine.experiments import levers

    out = tmp_path / "check.md"
    assert levers.main([str(ROOT / "data/results/ant/polish_erring.csv"), "--method", "ours-polish", "--baseline",
                        str(ROOT / "data/results/ant/scaling/imperfect_centre.csv"), "--baseline-method", "ours",
                        "--proposer", "imperfect:moderate", "--mazes", "u_chain_3", "u_chain_4", "--seeds", "0", "1",
                        "2", "--out", str(out)]) == 0
    text = out.read_text()
    assert (ROOT / "data/results/ant/polish_erring_check.md").read_text() == text
    assert "<!-- polish erring check -->\n" + text in (ROOT / "docs" / "ant_experiments.md").read_text()


def test_fresh_estimates_table_is_the_shipped_reports():
    import json
    import math

    lines = ["| run (seed 0) | legs | search's product of leg estimates | fresh products, seeds 101, 202, 303 | "
             "measured product of leg successes |", "|---|---|---|---|---|"]
    for path in sorted((ROOT / "data/results/ant/scaling_centre/estimates").glob("*.json")):
        r = json.loads(path.read_text())
        assert r["seeds"] == [101, 202, 303] and r["rollouts"] == 32
        lines.append(f"| {path.stem} | {len(r['search'])} | {math.prod(r['search']):.3f} | "
                     f"{', '.join(f'{math.prod(run):.3f}' for run in r['fresh'])} | {math.prod(r['measured']):.3f} |")
    assert len(lines) == 5
    assert "<!-- fresh estimates -->\n" + "\n".join(lines) + "\n" in (ROOT / "docs/ant_experiments.md").read_text()


def test_erring_seed_tables_and_verdict_are_the_shipped_tables():
    from specrefine.experiments import scaling

    tables = [ROOT / "data/results/ant/centre.csv", *sorted((ROOT / "data/results/ant/scaling").glob("*_centre.csv"))]
    rows = scaling.read_rows(tables)
    doc = (ROOT / "docs/ant_experiments.md").read_text()
    for seed in scaling.SEEDS:
        table = scaling.erring_seed_table(rows, seed)
        assert "—" not in table  # part 3 is complete
        assert f"<!-- erring seed {seed} -->\n" + table + "\n" in doc
    erring = scaling.erring_claim(rows)
    lo, hi = erring["ratio_ci"]
    assert erring["verdict"] == "holds" and "the erring-proposer claim holds" in doc
    assert (f"reaches {erring['ratio']:.1f} times the one-shot's mean success on the multi-room mazes (95 % bootstrap "
            f"interval [{lo:.1f}, {hi:.1f}] over the {erring['cells']} paired runs") in " ".join(doc.split())


def test_leg_profiles_table_is_the_shipped_profiles():
    import json

    from specrefine.experiments.legs import profile_table

    doc = (ROOT / "docs" / "ant_experiments.md").read_text()
    profiles = json.loads((ROOT / "data/results/ant/scaling/leg_profiles.json").read_text())
    assert "<!-- leg profiles -->\n" + profile_table(profiles) + "\n" in doc


def test_centre_leg_profiles_and_turns_are_the_shipped_profiles():
    import json

    from specrefine.experiments.legs import profile_table, turn_table

    doc = (ROOT / "docs" / "ant_experiments.md").read_text()
    profiles = json.loads((ROOT / "data/results/ant/scaling_centre/leg_profiles.json").read_text())
    assert "<!-- centre turns -->\n" + turn_table(profiles) + "\n" in doc
    assert "<!-- centre leg profiles -->\n" + profile_table(profiles) + "\n" in doc
    lost = {k: sum(p["episode_outcomes"].get(k, 0) for p in profiles) for k in ("flipped", "avoid", "timeout")}
    episodes = sum(p["episodes"] for p in profiles)
    assert (f"lose {sum(lost.values())} of {episodes:,} episodes: {lost['flipped']} flips, {lost['avoid']} wall "
            f"contacts, {lost['timeout']} timeouts") in " ".join(doc.split())


def test_antmaze_table_is_its_official_csv():
    import csv

    from specrefine.experiments.antmaze import table

    with (ROOT / "data/results/ant/antmaze/official.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    doc = (ROOT / "docs" / "official_env.md").read_text()
    assert "<!-- antmaze table -->\n" + table(rows) + "\n" in doc
    assert (ROOT / "data/results/ant/antmaze/table.md").read_text() == table(rows) + "\n"


def test_the_goal_point_reruns_in_the_docs_are_the_shipped_reruns():
    import json

    folder = ROOT / "data/results/ant/scaling/goal_points"
    text = " ".join((ROOT / "docs" / "ant_experiments.md").read_text().split())
    for maze in ("u_chain_3", "u_chain_5"):
        for gp in ("sampled", "centre"):
            walls = json.loads((folder / f"{maze}_s0_{gp}.json").read_text())["walls"]
            assert f"{walls['success']} of 200 = {walls['rate']:.3f}" in text, (maze, gp)


def test_the_point_mass_gap_table_is_its_record():
    import json

    spec = importlib.util.spec_from_file_location("official_gap", ROOT / "scripts" / "official_gap.py")
    official_gap = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(official_gap)
    record = json.loads((ROOT / "data/official/point_gap.json").read_text())
    assert [r["maze"] for r in record["rows"]] == official_gap.MAZES
    doc = (ROOT / "docs" / "official_env.md").read_text()
    assert "<!-- point gap table -->\n" + official_gap.gap_table(record) + "\n" in doc
    flat = " ".join(doc.split())
    for row in record["rows"]:  # the counts the text quotes
        here, there = (row[side]["outcomes"].get("avoid", 0) for side in ("this_simulator", "official"))
        if row["maze"] in ("u_maze", "gr:MEDIUM_MAZE"):
            assert f"{there} against {here} on `{row['maze']}`" in flat


def test_the_antmaze_results_quoted_are_its_official_csv():
    import csv

    from specrefine.core.results import newcombe_ci
    from specrefine.experiments.antmaze import groups, headline

    with (ROOT / "data/results/ant/antmaze/official.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    for marker, method, proposer in (("front antmaze centre", "ours (centre)", "geometric"),
                                     ("front antmaze ours", "ours", "imperfect:moderate"),
                                     ("front antmaze oneshot", "vlm-oneshot", "imperfect:moderate")):
        assert _between(FRONT, marker) == headline(rows, method, proposer), marker

    def rate(runs, side):
        return sum(int(r[f"{side}_successes"]) for r in runs) / sum(int(r[f"{side}_episodes"]) for r in runs)

    by = groups(rows)
    agree = sum(lo <= 0 <= hi for lo, hi in (
        newcombe_ci(*(sum(int(r[f"{side}_{x}"]) for r in runs) for side in ("official", "sim")
                      for x in ("successes", "episodes"))) for runs in by.values()))
    assert f"agree within their intervals on {agree} of the {len(by)} rows" in " ".join(FRONT.split())
    doc = " ".join((ROOT / "docs" / "official_env.md").read_text().split())
    assert f"**The two simulators agree on {agree} of the {len(by)} rows**" in doc
    centre = {m: by[(m, "ours (centre)", "geometric")] for m in ("gr:U_MAZE", "gr:MEDIUM_MAZE", "gr:LARGE_MAZE")}
    assert (f"({rate(centre['gr:U_MAZE'], 'sim'):.3f} and {rate(centre['gr:MEDIUM_MAZE'], 'sim'):.3f} here, "
            f"{rate(centre['gr:U_MAZE'], 'official'):.3f} and {rate(centre['gr:MEDIUM_MAZE'], 'official'):.3f} "
            "official") in doc


def test_the_antmaze_default_grid_is_its_official_csv_in_readme_and_docs():
    import csv

    from specrefine.experiments.antmaze import headline, table

    with (ROOT / "data/results/ant/antmaze_default/official.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 9  # three maps x seeds 0-2
    assert _between(FRONT, "front antmaze default") == headline(rows, "ours (centre)", "geometric")
    doc = (ROOT / "docs" / "official_env.md").read_text()
    assert "<!-- antmaze default table -->\n" + table(rows) + "\n<!-- /antmaze default table -->" in doc
    assert (ROOT / "data/results/ant/antmaze_default/table.md").read_text() == table(rows) + "\n"
    with (ROOT / "data/results/ant/antmaze_default.csv").open() as fh:  # the sweep's table: the same runs
        sweep = {(r["maze"], int(r["seed"])): round(float(r["success_rate"]) * int(r["episodes"]))
                 for r in csv.DictReader(fh) if r["status"] == "ok"}
    assert sweep == {(r["maze"], int(r["seed"])): int(r["sim_successes"]) for r in rows}
    import json

    from specrefine.core.results import rate_text

    own = []  # each run's own episode seed: seed 0's from the table, seeds 1 and 2 from run_seeds/
    for maze in ("U_MAZE", "MEDIUM_MAZE", "LARGE_MAZE"):
        won = sum(int(r["official_successes"]) for r in rows if r["maze"] == f"gr:{maze}" and r["seed"] == "0")
        for seed in (1, 2):
            d = json.loads((ROOT / f"data/results/ant/antmaze_default/run_seeds/{maze}_seed{seed}.json").read_text())
            assert d["seed"] == seed and d["maze"] == f"gr:{maze}" and d["episodes"] == 200
            won += round(d["success_rate"] * d["episodes"])
        own.append(f"{maze} {rate_text(won, 600)}")
    assert _between(doc, "antmaze default run seeds") == ", ".join(own)


def test_the_ant_gap_table_is_its_record():
    import json

    spec = importlib.util.spec_from_file_location("official_gap_ant", ROOT / "scripts" / "official_gap_ant.py")
    official_gap_ant = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(official_gap_ant)
    record = json.loads((ROOT / "data/official/ant_gap.json").read_text())
    doc = (ROOT / "docs" / "official_env.md").read_text()
    assert "<!-- ant gap table -->\n" + official_gap_ant.gap_table(record) + "\n" in doc
    imperfect = [e for name, e in record["runs"].items() if "imperfect" in name]
    keys = ("this_simulator", "start=official,reset_noise=official", "start=package,reset_noise=official")
    totals = {key: [sum(e[key]["outcomes"].get(k, 0) for e in imperfect) for k in ("avoid", "flipped")] for key in keys}
    (sim_a, sim_f), (off_a, off_f), (pkg_a, pkg_f) = totals.values()
    assert (f"({pkg_a} wall contacts and {pkg_f} flips over the three runs, against {off_a} and {off_f} with "
            f"AntMaze's start; this simulator {sim_a} and {sim_f})") in " ".join(doc.split())


def test_the_ant_gap_records_outcomes_agree_with_their_success_rates():
    """One truth per entry: its outcomes add up to its episodes, and its successes are the episodes labelled
    success plus those counted apart (a trajectory that met the task while the policy's run ended otherwise)."""
    import json

    spec = importlib.util.spec_from_file_location("official_gap_ant", ROOT / "scripts" / "official_gap_ant.py")
    official_gap_ant = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(official_gap_ant)
    record = json.loads((ROOT / "data/official/ant_gap.json").read_text())
    assert official_gap_ant.UNLABELLED in record["note"]
    apart = []
    for name, entry in record["runs"].items():
        for key, side in entry.items():
            assert sum(side["outcomes"].values()) == side["episodes"], (name, key)
            assert side == official_gap_ant.side(side), (name, key)  # what the script writes today
            successes = round(side["success_rate"] * side["episodes"])
            assert successes == side["outcomes"].get("success", 0) + side.get(official_gap_ant.UNLABELLED, 0)
            apart += [side[official_gap_ant.UNLABELLED]] if official_gap_ant.UNLABELLED in side else []
    assert apart == [1, 1] and "1 in each of 2 of the 24 entries" in record["note"]
    assert sum(len(entry) for entry in record["runs"].values()) == 24


def test_the_choices_numbers_are_their_tables():
    """docs/choices.md's numbers for the goal-point rule, adaptive evaluation and the oracle's cap."""
    import csv

    def rows(table, **match):
        with (ROOT / table).open(newline="") as fh:
            return [r for r in csv.DictReader(fh) if all(r[k] == v for k, v in match.items())]

    def pooled(runs, episodes=None):
        return (sum(round(float(r["success_rate"]) * (episodes or int(r["episodes"]))) for r in runs),
                sum(episodes or int(r["episodes"]) for r in runs))

    doc = " ".join((ROOT / "docs/choices.md").read_text().split())
    check = (ROOT / "data/results/ant/centre_check.md").read_text()
    lever, base, diff = re.search(r"Pooled ([0-9.]+) .*? against ([0-9.]+) .*?: difference (\S+ \[\S+ \S+\])",
                                  check).groups()
    assert f"{base} sampled against {lever} centre, difference {diff}" in doc
    cap48 = pooled(rows("data/results/ant/uchain5_cap48.csv"))
    cap32 = pooled(rows("data/results/ant/comparison.csv", maze="u_chain_5", method="ours", proposer="geometric"))
    assert f"{cap48[0]}/{cap48[1]} = {cap48[0] / cap48[1]:.3f} against {cap32[0]}/{cap32[1]} = " \
           f"{cap32[0] / cap32[1]:.3f} with 32" in doc
    held = {ev: rows("data/results/ant/adaptive_bench.csv", evaluation=ev) for ev in ("fixed", "adaptive")}
    held = {ev: [r for r in runs if r["seed"] in ("1", "2")] for ev, runs in held.items()}  # seed 0 informed it
    ratio = {k: sum(float(r[k]) for r in held["fixed"]) / sum(float(r[k]) for r in held["adaptive"])
             for k in ("sim_steps", "wall_seconds")}
    (ka, na), (kf, nf) = (pooled(held[ev], episodes=200) for ev in ("adaptive", "fixed"))
    assert (f"{ratio['sim_steps']:.2f}x fewer simulator steps and {ratio['wall_seconds']:.2f}x less wall time on the "
            f"held-out Ant runs at equal success ({ka}/{na} adaptive against {kf}/{nf} fixed") in doc
    front = json.loads((ROOT / "data/results/corrector/claims.json").read_text())["front"]  # corrector-claims'
    assert f"points {front['centre-paired']}; the oracle {front['centre-oracle']} (paired)" in doc


def test_the_stage5_section_is_its_csvs():
    """docs/results.md's stage-5 table and the numbers under it, from the CSVs as the front page's."""
    centre, sampled = _csv_runs(CENTRE), _csv_runs(SAMPLED)
    columns = [(sampled, "ours"), (sampled, "vlm-oneshot"), (centre, "ours"), (centre, "vlm-oneshot")]
    rates = [_rates(runs, method, ORACLE, SCALING) for runs, method in columns]
    lines = ["| maze | ours, sampled | vlm-oneshot, sampled | ours, centre | vlm-oneshot, centre |",
             "|---|---|---|---|---|"]
    lines += [f"| {maze} | " + " | ".join(f"{r[i]:.3f}" for r in rates) + " |" for i, maze in enumerate(SCALING)]
    lines.append("| change 1→5 rooms | " + " | ".join(f"{_change(_room_values(runs, method, ORACLE)):+.3f}"
                                                    for runs, method in columns) + " |")
    assert "<!-- stage 5 table -->\n" + "\n".join(lines) + "\n" in README
    text = " ".join(README.split())
    assert [m for m, r in zip(SCALING, rates[0]) if r >= 0.90] == ["u_chain_1", "u_chain_2"]
    assert "With sampled goal points `ours` reaches 0.90 only on U-chain 1 and 2" in text
    for marker in ("front sampled grid", "front centre grid"):  # the same intervals as the front page's
        change = re.search(r"change from 1 to 5 rooms (\S+ \[\S+ \S+\])", _between(FRONT, marker)).group(1)
        assert change in text, marker
    assert _between(FRONT, "front centre oneshot").endswith("the same success as `ours` in 23 of the 27 runs")
    assert "the same success in 23 of the 27 runs" in text
    erring, alone = _between(FRONT, "front erring"), _between(FRONT, "front erring ours")
    best = re.match(r"(\S+)x the one-shot (\[\S+ \S+\])", erring).groups()
    assert f"reaches {best[0]}x the one-shot's mean success on the multi-room mazes {best[1]}; `ours` alone {alone}" \
           in text
    zeros, lifted = re.search(r"at 0 in (\d+) of 27 runs and `ours-repair` lifts (\d+)", erring).groups()
    assert f"`ours` ends at 0 in {zeros} of its 27 runs, {lifted} of which `ours-repair` lifts above 0" in text
    rotated = _between(FRONT, "front rotated").replace(", difference", " on the original, difference")
    assert rotated in text
    centre_check = _between(FRONT, "front centre").split(", difference")[0]
    assert f"helps, {centre_check})" in text


def test_the_offline_comparison_counts_its_rows_by_code():
    import csv
    from collections import Counter

    with (ROOT / "data/results/imperfect/results.csv").open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    first = Counter(r["method"] for r in rows[:1360])
    later = Counter(r["method"] for r in rows[1360:])
    assert set(first) == {"ours", "ours-nosearchvertex", "ours-d1", "vlm-oneshot", "vlm-oneshot-matched"}
    assert set(later) == {"ours-novertex", "ours-notune", "ours-nofeedback"} and set(first.values()) == {272}
    assert len(first) == 5
    assert all(r["status"] == "ok" for r in rows)
    assert " ".join(_between(README, "imperfect rows").split()) == (
        f"{len(rows)} runs in `results.csv`, none failed: {sum(first.values())} of five methods run with "
        f"commit 1461726 and {sum(later.values())} of the three redefined controls run with commit 309875a")
    readme = " ".join((ROOT / "data/results/README.md").read_text().split())
    assert (f"**rows 1-{sum(first.values())}** (272 each of `ours`, `ours-nosearchvertex`, `ours-d1`, `vlm-oneshot`, "
            f"`vlm-oneshot-matched`) ran with commit **1461726**") in readme
    assert f"**rows {sum(first.values()) + 1}-{len(rows)}** (272 each of the redefined" in readme


def test_the_corrector_s_ant_room_is_the_oracle_confirm_check():
    """README's range for the oracle on U-chain 4-5 at the Ant corrector's settings is ant-oracle-confirm's check."""
    check = (ROOT / "data/results/ant/oracle_confirm_check.md").read_text()
    rates = [float(m) for m in re.findall(r"^\| u_chain_[45](?:_subgoals)? \| 3 \| ([0-9.]+) ", check, re.M)]
    assert len(rates) == 4
    readme = " ".join((ROOT / "README.md").read_text().split())
    assert f"U-chain 4 and 5 with and without subgoals reach {min(rates):.3f}-{max(rates):.3f} per maze" in readme


def test_the_ants_adopted_corrector_sentence_is_its_tables():
    """README's sentence on the Ant's adopted corrector: its lowest maze, its cells below the control, its cost and
    its ledger, recomputed from ant_redraw.csv, ant_confirm.csv and the redraw ledger.csv."""
    from specrefine.experiments import corrector_claims as cc

    ant = cc.ant_study(ROOT)
    read = next(c for c in ant["candidates"] if c["method"] == ant["method"])
    assert read["adopted"] and ant["method"] == "ours-corrector-redraw"
    lo, hi = read["paired"]["ci"]
    low = min(ant["per_maze"], key=lambda e: e["success"])
    below = sum(redraw < confirm for _, redraw, confirm in read["paired"]["rows"])
    one = [next(e for e in table if e["maze"] == "u_chain_1") for table in (ant["per_maze"], ant["confirm"])]
    with (ROOT / "data/results/corrector/ledger/redraw/ledger.csv").open(newline="") as fh:
        ledger = list(csv.DictReader(fh))
    assert all(row["last_p_above_interval"] == "True" for row in ledger)
    readme = " ".join(FRONT.split())
    assert (f"over the 27 paired cells: {read['paired']['difference']:+.3f} [{lo:+.3f}, {hi:+.3f}])") in readme
    assert low["maze"] == "u_chain_5_subgoals" and low["success"] >= cc.ANT_FLOOR
    assert (f"(the lowest, U-chain 5 with subgoals, {low['success']:.3f} [{low['ci_low']:.3f}, {low['ci_high']:.3f}])"
            in readme)
    assert (f"it is below confirm on {below} of the {read['paired']['cells']} cells (U-chain 1 pooled "
            f"{one[0]['success']:.3f} against {one[1]['success']:.3f}); it spends "
            f"{read['cost_vs_confirm']['proposer_calls_ratio']:.2f}x confirm's proposer calls and "
            f"{read['cost_vs_ours']['proposer_calls_ratio']:.2f}x `ours`'s") in readme
    assert f"on each of the {len(ledger)} runs its ledger holds" in readme
