"""Issue 42's sentence on README's front page and the slow-turn checks' table re-derive from their files
(data/results/ant/switching_checks, scripts/switching_table.py)."""

import contextlib
import csv
import importlib.util
import io
import json
import re
import shlex
import shutil
from pathlib import Path

from specrefine.core.results import difference_text
from specrefine.experiments.legs import kind_table

ROOT = Path(__file__).resolve().parents[1]
CHECKS = ROOT / "data" / "results" / "ant" / "switching_checks"


def script(name: str):
    """scripts/NAME.py as a module (the scripts folder is not a package)."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


switching_table = script("switching_table")


def pages() -> str:
    """README, then docs/ant_experiments.md, where README's lever-by-lever account of issue 42 moved on 2026-12-06."""
    return (ROOT / "README.md").read_text() + "\n" + (ROOT / "docs" / "ant_experiments.md").read_text()


def front(name: str) -> str:
    found = re.search(rf"<!-- front {name} -->(.*?)<!-- /front {name} -->", pages(), flags=re.S)
    assert found, f"neither README nor docs/ant_experiments.md has a '{name}' marker"
    return " ".join(found.group(1).split())


def pooled(points: str, rule: str) -> tuple[int, int]:
    reports = switching_table.held_out(CHECKS, points, rule).values()
    return sum(r["walls"]["success"] for r in reports), sum(r["episodes"] for r in reports)


def test_checks_table_regenerates(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)  # the sampled at-region side falls back to stage 5's own files, relative paths
    for f in CHECKS.glob("*.json"):
        shutil.copy(f, tmp_path / f.name)
    text = switching_table.main(tmp_path)
    assert text.replace(str(tmp_path), str(CHECKS.relative_to(ROOT))) == (CHECKS / "checks.md").read_text()


def test_front_sentence_recomputes(monkeypatch):
    monkeypatch.chdir(ROOT)
    slow, at = pooled("centre", "slow-turn"), pooled("centre", "at-region")
    assert slow[1] == at[1] == 900
    expected = f"{slow[0]} of {slow[1]} against {at[0]} of {at[1]}, {difference_text(*slow, *at)}"
    assert front("slow-turn") == expected
    sampled = {rule: pooled("sampled", rule) for rule in switching_table.RULES}
    assert front("slow-turn sampled") == (f"{sampled['slow-turn'][0]} against {sampled['at-region'][0]} "
                                          f"of {sampled['at-region'][1]}")


def test_stage7_held_out_recomputes():
    folder = ROOT / "data" / "results" / "ant" / "stage7_checks"
    counts = {}
    for tag in ("stage7", "stage5"):
        reports = [json.loads(p.read_text()) for p in sorted(folder.glob(f"u_chain_2_s?_{tag}.json"))]
        assert len(reports) == 3, f"{tag}: {len(reports)} held-out reports"
        counts[tag] = (sum(r["walls"]["success"] for r in reports), sum(r["episodes"] for r in reports))
    assert front("stage7") == f"{counts['stage7'][0]} against {counts['stage5'][0]} of {counts['stage5'][1]}"


def turning_loss(points: str, rule: str) -> str:
    table = kind_table(list(switching_table.held_out(CHECKS, points, rule).values()))
    row = next(line for line in table.splitlines() if line.startswith("| turning |"))
    return f"{100 * float(row.split('|')[-2].split()[0]):.2f} %"


def test_front_turning_legs_recompute(monkeypatch):
    monkeypatch.chdir(ROOT)
    assert front("slow-turn turning") == (f"{turning_loss('centre', 'slow-turn')} against "
                                          f"{turning_loss('centre', 'at-region')}")


def test_front_train_ratio_recomputes():
    lines = (ROOT / "data" / "results" / "bench" / "train_ant.jsonl").read_text().splitlines()
    runs = [json.loads(line) for line in lines if line.strip()]
    ratios = sorted(r["ratio_vs_raw_rollout"] for r in runs)
    assert front("train ratio") == f"{ratios[0]:.2f}-{ratios[-1]:.2f}"


def pooled_u_chains(table: Path) -> str:
    """Success pooled over the six cells of check 5 (U-chain 3 and 5, seeds 0-2)."""
    with table.open(newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if r["maze"] in ("u_chain_3", "u_chain_5") and r["method"] == "ours"
                and r["status"] == "ok" and int(r["seed"]) in (0, 1, 2)]
    assert len(rows) == 6, f"{table}: {len(rows)} U-chain 3 and 5 runs"
    won = sum(float(r["success_rate"]) * int(r["episodes"]) for r in rows)
    return f"{won / sum(int(r['episodes']) for r in rows):.3f}"


def test_front_slow_turn_u_chains_recompute():
    slow = pooled_u_chains(CHECKS / "uchain_slow_turn.csv")
    at = pooled_u_chains(ROOT / "data" / "results" / "ant" / "centre.csv")
    assert front("slow-turn uchains") == f"{slow} against {at}"
    assert f"Pooled {slow} [" in (CHECKS / "uchain_check.md").read_text()


STAGE8 = ROOT / "data" / "results" / "ant" / "stage8_checks"


def held_out_count(tag: str, points: str) -> tuple[int, int]:
    """Successes and episodes over the three held-out U-chain 2 paths (check 3: centre, check 5: sampled)."""
    infix = "_centre" if points == "centre" else ""
    reports = [json.loads(p.read_text()) for p in sorted(STAGE8.glob(f"u_chain_2_s?{infix}_{tag}.json"))]
    assert len(reports) == 3, f"{tag} {points}: {len(reports)} held-out reports"
    return sum(r["walls"]["success"] for r in reports), sum(r["episodes"] for r in reports)


def test_front_stage8_recomputes():
    eight, five = held_out_count("stage8", "centre"), held_out_count("stage5", "centre")
    expected = f"{eight[0]} of {eight[1]} against {five[0]} of {five[1]}, {difference_text(*eight, *five)}"
    assert front("stage8") == expected
    sampled = {tag: held_out_count(tag, "sampled") for tag in ("stage8", "stage5")}
    assert front("stage8 sampled") == (f"{sampled['stage8'][0]} against {sampled['stage5'][0]} of "
                                       f"{sampled['stage5'][1]}")
    chains = {tag: json.loads((STAGE8 / f"turn_chain8_{tag}.json").read_text()) for tag in ("stage8", "stage5")}
    won = {tag: round(c["success_rate"] * c["episodes"]) for tag, c in chains.items()}
    flips = {tag: int(sum(c["flipped"])) for tag, c in chains.items()}
    assert front("stage8 turning") == (f"{won['stage8']} against {won['stage5']} of {chains['stage5']['episodes']}, "
                                       f"flips {flips['stage8']} against {flips['stage5']}")


def test_front_stage8_u_chains_recompute():
    eight = pooled_u_chains(STAGE8 / "uchain_stage8.csv")
    five = pooled_u_chains(ROOT / "data" / "results" / "ant" / "centre.csv")
    check = (STAGE8 / "uchain_check.md").read_text()
    assert f"Pooled {eight} [" in check and f"against {five} [" in check
    difference = re.search(r"difference ([+-][0-9.]+ \[[+-][0-9.]+, [+-][0-9.]+\])", check).group(1)
    assert front("stage8 uchains") == f"{eight} against {five} over the six cells, {difference}"


ORACLE_CHECKS = {"oracle spread": ("oracle_spread.csv", ["--baseline", "data/results/ant/scaling/ours_centre.csv",
                                                        "--describe", "--baseline-label", "ours before the fix"]),
                 "oracle tunecheck": ("oracle_tunecheck.csv", ["--method", "ours-tunecheck", "--baseline",
                                                              "data/results/ant/oracle_spread.csv"]),
                 "oracle confirm": ("oracle_confirm.csv", ["--method", "ours-confirm", "--baseline",
                                                          "data/results/ant/oracle_spread.csv"]),
                 "oracle corrector scaling": ("oracle_corrector_scaling.csv",
                                              ["--method", "ours-corrector-redraw", "--baseline",
                                               "data/results/ant/oracle_confirm.csv", "--baseline-method",
                                               "ours-confirm"]),
                 "oracle wide scaling": ("oracle_wide_scaling.csv",
                                         ["--method", "ours-corrector-wide", "--baseline",
                                          "data/results/ant/oracle_corrector_scaling.csv", "--baseline-method",
                                          "ours-corrector-redraw"])}


def test_the_oracle_checks_regenerate_and_readme_quotes_their_summaries(tmp_path, monkeypatch):
    """data/results/ant/oracle_*_check.md from their tables (experiments.oracle_check), and README's sentence."""
    from specrefine.experiments import oracle_check

    monkeypatch.chdir(ROOT)
    for name, (table, args) in ORACLE_CHECKS.items():
        shipped = ROOT / "data" / "results" / "ant" / table.replace(".csv", "_check.md")
        out = tmp_path / shipped.name
        assert oracle_check.main([f"data/results/ant/{table}", *args, "--out", str(out)]) == 0
        assert out.read_text() == shipped.read_text()
        summary = next(line for line in shipped.read_text().splitlines() if line.startswith("Summary: "))
        assert front(name) == summary.removeprefix("Summary: ").rstrip(".")


def test_readme_names_the_cells_whose_outcome_the_tuning_check_changed():
    def rates(table):
        with (ROOT / "data" / "results" / "ant" / table).open(newline="") as fh:
            return {(r["maze"], int(r["seed"])): float(r["success_rate"]) for r in csv.DictReader(fh)
                    if r["status"] == "ok"}

    lever, base = rates("oracle_tunecheck.csv"), rates("oracle_spread.csv")
    common = sorted(set(lever) & set(base))
    changed = [c for c in common if lever[c] != base[c]]
    cells = ", ".join(f"{m} seed {s}: {lever[(m, s)]:.3f} against {base[(m, s)]:.3f}" for m, s in changed)
    assert front("tunecheck changed") == f"{len(changed)} of the {len(common)} cells run, {cells}"


STAGE9 = ROOT / "data" / "results" / "ant" / "stage9_checks"


def chain_outcome(path: Path) -> tuple[int, int, int]:
    """Episodes that reached every goal, episodes, and timeouts of one chain check's file."""
    c = json.loads(path.read_text())
    return round(c["success_rate"] * c["episodes"]), c["episodes"], int(sum(c["timed_out"]))


def test_front_stage9_recomputes():
    for marker, stem in (("stage9 chain", "chain8"), ("stage9 turning", "turn_chain8")):
        nine, five = chain_outcome(STAGE9 / f"{stem}_stage9.json"), chain_outcome(STAGE9 / f"{stem}_stage5.json")
        assert front(marker) == f"{nine[0]} against {five[0]} of {five[1]}, timeouts {nine[2]} against {five[2]}"
    device = STAGE9 / "device_stage5"
    held = {where: sum(json.loads(p.read_text())["walls"]["success"] for p in sorted(folder.glob(
        "u_chain_2_s?_centre_stage5.json"))) for where, folder in (("device", device), ("here", STAGE9))}
    turning = {where: chain_outcome(folder / "turn_chain8_stage5.json") for where, folder in (("device", device),
                                                                                              ("here", STAGE9))}
    assert front("stage9 device") == (f"{held['device']} against {held['here']} of 900 on the held-out paths, "
                                      f"{turning['device'][0]} against {turning['here'][0]} of "
                                      f"{turning['here'][1]} on the turning goals")


def test_stage9_checks_table_regenerates():
    summary = script("ant_stage8_summary")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        summary.main(STAGE9, "stage9", "stage5")
    assert out.getvalue() == (STAGE9 / "checks.md").read_text()


def test_stage10_rule_read_on_stage8s_files_fails_only_its_aim(tmp_path):
    """Stage 10's rule (lever 9) applied to a policy judged before, stage 8: above 811 with sampled points fails
    (792), the other four hold; with no files, every check is listed as not yet run."""
    summary = script("ant_stage10_summary")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        summary.main(ROOT / "data" / "results" / "ant" / "stage8_checks", "stage8", "stage5")
        summary.main(tmp_path, "stage10", "stage5")
    verdicts = re.findall(r"^\| (\d)\. .*: (holds|fails)\b", out.getvalue(), flags=re.M)
    assert dict(verdicts) == {"1": "holds", "2": "holds", "3": "fails", "4": "holds", "5": "holds"}
    assert "put forward by the rule: no" in out.getvalue()
    assert out.getvalue().rstrip().endswith("checks not yet run: [1, 2, 3, 4, 5]")


def test_stage10_checks_regenerate_into_its_table_and_readme():
    """stage10_checks/checks.md from its JSON files, the same table in docs/ant_experiments.md, and README's aim
    check (the held-out paths with sampled goal points) from the same files."""
    folder = ROOT / "data" / "results" / "ant" / "stage10_checks"
    summary = script("ant_stage10_summary")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        summary.main(folder, "stage10", "stage5")
    assert out.getvalue() == (folder / "checks.md").read_text()
    table = out.getvalue().split("\n\n")[0]
    assert f"<!-- stage 10 checks -->\n{table}\n" in (ROOT / "docs" / "ant_experiments.md").read_text()
    k = {tag: script("ant_stage7_summary").held_out(folder, tag)[1:] for tag in ("stage10", "stage5")}
    assert front("stage10") == (f"{k['stage10'][0]} of {k['stage10'][1]} against {k['stage5'][0]} of {k['stage5'][1]}, "
                                f"{difference_text(*k['stage10'], *k['stage5'])}")


SCALE = ROOT / "data" / "results" / "ant" / "switching_scale"
switching_scale_table = script("switching_scale_table")


def test_switching_scale_table_regenerates(tmp_path):
    for f in SCALE.glob("*.json"):
        shutil.copy(f, tmp_path / f.name)
    assert switching_scale_table.main(tmp_path) == (SCALE / "checks.md").read_text()


def test_front_switching_scale_recomputes():
    pairs = switching_scale_table.paired_reports(SCALE)
    assert len(pairs) == 30  # 3 paths x 10 episode seeds, both rules
    by_rule = {rule: [r[rule] for r in pairs.values()] for rule in switching_scale_table.RULES}
    slow, at = (switching_scale_table.pooled(by_rule[rule]) for rule in ("slow-turn", "at-region"))
    expected = f"{slow[0]} of {slow[1]} against {at[0]} of {at[1]}, {difference_text(*slow, *at)}"
    assert front("slow-turn scale") == expected

    def turning(rule):
        row = next(line for line in kind_table(by_rule[rule]).splitlines() if line.startswith("| turning |"))
        return f"{100 * float(row.split('|')[-2].split()[0]):.2f} %"

    assert front("slow-turn scale turning") == f"{turning('slow-turn')} against {turning('at-region')}"


def test_switching_scale_table_pairs_only_what_both_rules_finished(tmp_path):
    for f in SCALE.glob("u_chain_2_s0_centre_*_seed100[12].json"):
        shutil.copy(f, tmp_path / f.name)
    (tmp_path / "u_chain_2_s0_centre_slow-turn_seed1002.json").unlink()  # its at-region partner is left alone
    pairs = switching_scale_table.paired_reports(tmp_path)
    assert list(pairs) == [(0, 1001)]
    assert "1 (path, episode seed) pairs" in switching_scale_table.table(tmp_path)


ANT = ROOT / "data" / "results" / "ant"
LEVER_CELLS = [(m, s) for m in ("u_chain_3", "u_chain_5") for s in (0, 1, 2)]  # levers 7 and 8 (U-chain 3 and 5)


def lever_check_quoted(tmp_path, capsys, table, method, baseline, baseline_method, outcome_start):
    """The rule's command on the shipped tables regenerates the shipped check -> (its verdict, its difference, the
    docs outcome paragraph that starts with ``outcome_start``, whitespace collapsed)."""
    from specrefine.experiments import levers

    out = tmp_path / "check.md"
    assert levers.main([str(ANT / table), "--method", method, "--baseline", str(ANT / baseline), "--baseline-method",
                        baseline_method, "--mazes", "u_chain_3", "u_chain_5", "--seeds", "0", "1", "2", "--out",
                        str(out)]) == 0
    capsys.readouterr()
    text = out.read_text()
    assert text == (ANT / table.replace(".csv", "_check.md")).read_text()
    verdict, difference = re.search(r"6 of 6 cells: ([\w ]+)\.\*\*.*difference (\S+ \[\S+ \S+\])", text).groups()
    docs = (ROOT / "docs" / "ant_experiments.md").read_text()
    return verdict, difference, " ".join(docs.split(outcome_start)[1].split("\n\n")[0].split())


def lever_line(table, method, baseline, baseline_method) -> tuple[str, dict, dict]:
    """What README's line for a lever says (pooled success of both sides, the difference, the verdict) -> (that text,
    the lever's rows by cell, the baseline's)."""
    from specrefine.experiments import levers

    lever, base = levers._by_cell(ANT / table, method, None), levers._by_cell(ANT / baseline, baseline_method, None)
    check = levers.lever_check(lever, base, LEVER_CELLS)
    (k1, n1), (k2, n2) = check["lever"], check["baseline"]
    return (f"{k1 / n1:.3f} against {k2 / n2:.3f} over {check['cells']} cells, "
            f"{difference_text(k1, n1, k2, n2)}: {check['verdict']}"), lever, base


def leg_kinds(profiles, after: bool = False) -> dict[str, list[str]]:
    """experiments.legs.turn_table's rows: kind -> its count, episodes started, lost, rate."""
    from specrefine.experiments.legs import turn_table

    rows = [line.strip("|").split("|") for line in turn_table(profiles, after=after).splitlines()[2:]]
    return {cells[0].strip(): [c.strip() for c in cells[1:]] for cells in rows}


def kinds_line(lever: dict, before: dict, against: str = "") -> str:
    """The docs' per-kind line of a lever's legs against ``before``'s (leg_kinds of each)."""
    return (f"turning legs {lost_of('turning', lever).replace(', ', ' started episodes lost, ', 1)} per leg, "
            f"against {against}{lost_of('turning', before)}; straight legs {lost_of('straight', lever)}, against "
            f"{lost_of('straight', before)}")


def docs_marker(name: str) -> str:
    """The text between docs/ant_experiments.md's ``<!-- name -->`` markers, on one line."""
    found = re.search(rf"<!-- {name} -->(.*?)<!-- /{name} -->", (ROOT / "docs" / "ant_experiments.md").read_text(),
                      flags=re.S)
    assert found, name
    return " ".join(found.group(1).split())


def lost_of(kind: str, side: dict) -> str:
    count, started, lost, rate = side[kind]
    return f"{lost} of {started}, {rate}"


def test_lever_7_check_regenerates_and_its_outcome_quotes_it(tmp_path, capsys):
    """docs/ant_experiments.md's lever 7 outcome: the rule's command on the shipped tables, its verdict and interval."""
    verdict, difference, outcome = lever_check_quoted(tmp_path, capsys, "oracle_corrector.csv",
                                                      "ours-corrector-redraw", "oracle_confirm.csv", "ours-confirm",
                                                      "**Outcome (complete 2026-12-04 21:40")
    assert verdict == "helps" and "the correction helps the oracle" in outcome
    assert f"**{difference}**" in outcome


def test_front_oracle_corrector_recomputes_from_its_table():
    """README's lever 7 line: pooled success of both sides, the difference and the verdict, and the per-maze means."""
    expected, lever, _ = lever_line("oracle_corrector.csv", "ours-corrector-redraw", "oracle_confirm.csv",
                                    "ours-confirm")
    assert front("oracle corrector") == expected
    per_maze = [sum(float(lever[(m, s)]["success_rate"]) for s in (0, 1, 2)) / 3 for m in ("u_chain_3", "u_chain_5")]
    readme = " ".join(pages().split())
    assert f"({per_maze[0]:.3f} and {per_maze[1]:.3f}), at" in readme


def test_lever_7_legs_recompute_from_the_shipped_profiles():
    """docs/ant_experiments.md's per-kind losses of lever 7's paths and of ours's on the same cells, from the JSONs."""
    lever = leg_kinds(json.loads((ANT / "oracle_corrector_legs.json").read_text()))
    ours = leg_kinds([p for p in json.loads((ANT / "scaling_centre" / "leg_profiles.json").read_text())
                      if (p["maze"], p["seed"]) in set(LEVER_CELLS)])
    assert docs_marker("lever 7 legs") == kinds_line(lever, ours)
    docs = (ROOT / "docs" / "ant_experiments.md").read_text()
    assert lever["turning"][0] == ours["turning"][0] == "84"  # "Both have 84 turning legs"
    assert (lever["straight"][0], ours["straight"][0]) == ("139", "91")
    assert "(139 against 91)" in docs and "Both have 84 turning legs" in docs


def test_lever_8_check_regenerates_and_its_outcome_quotes_it(tmp_path, capsys):
    """docs/ant_experiments.md's lever 8 outcome: the rule's command on the shipped tables, its verdict and interval."""
    verdict, difference, outcome = lever_check_quoted(tmp_path, capsys, "oracle_wide.csv", "ours-corrector-wide",
                                                      "oracle_corrector.csv", "ours-corrector-redraw",
                                                      "**Outcome (complete 2026-12-05 01:55")
    assert verdict == "no difference shown" and "no difference shown.**" in outcome
    assert f"**{difference}**" in outcome


def test_front_oracle_wide_recomputes_from_its_table():
    """README's lever 8 line: pooled success of both sides, the difference and the verdict; U-chain 5 pooled; cost."""
    expected, lever, base = lever_line("oracle_wide.csv", "ours-corrector-wide", "oracle_corrector.csv",
                                       "ours-corrector-redraw")
    assert front("oracle wide") == expected

    def u5(rows):
        return sum(float(rows[("u_chain_5", s)]["success_rate"]) for s in (0, 1, 2)) / 3

    def ratio(column):
        return sum(int(lever[c][column]) for c in LEVER_CELLS) / sum(int(base[c][column]) for c in LEVER_CELLS)

    readme = " ".join(pages().split())
    assert (f"U-chain 5 pooled {u5(lever):.3f} against {u5(base):.3f}, at {ratio('proposer_calls'):.2f}x lever 7's "
            f"proposer calls and {ratio('sim_steps'):.2f}x its simulator steps") in readme


def test_lever_8_legs_recompute_from_the_shipped_profiles():
    """docs/ant_experiments.md's per-kind losses of lever 8's paths against lever 7's, from the shipped JSONs."""
    lever, before = (leg_kinds(json.loads((ANT / name).read_text()))
                     for name in ("oracle_wide_legs.json", "oracle_corrector_legs.json"))
    assert docs_marker("lever 8 legs") == kinds_line(lever, before, against="lever 7's ")


def test_lever_8_scaling_legs_recompute_from_the_shipped_profiles():
    """docs/ant_experiments.md's per-kind losses over the 27 cells of lever 8's and lever 7's scaling grids, and the
    lost episodes by outcome, from the shipped JSONs."""
    profiles = {name: json.loads((ANT / f"{name}_legs.json").read_text())
                for name in ("oracle_wide_scaling", "oracle_corrector_scaling")}
    lever, before = (leg_kinds(p) for p in profiles.values())
    assert docs_marker("lever 8 scaling legs") == kinds_line(lever, before, against="lever 7's ")
    docs = (ROOT / "docs" / "ant_experiments.md").read_text()
    assert all(len({(p["maze"], p["seed"]) for p in side}) == 27 for side in profiles.values())
    lost = {name: {k: sum(p["episode_outcomes"].get(k, 0) for p in side) for k in ("flipped", "avoid", "timeout")}
            for name, side in profiles.items()}
    wide, redraw = lost["oracle_wide_scaling"], lost["oracle_corrector_scaling"]
    assert (f"The {sum(wide.values())} episodes lost on lever 8's paths: {wide['flipped']} flipped, {wide['avoid']} "
            f"touched a wall, none timed out (lever 7's {sum(redraw.values())}: {redraw['flipped']}, "
            f"{redraw['avoid']} and {redraw['timeout']})") in " ".join(docs.split())
    assert wide["timeout"] == 0


def test_front_oracle_wide_legs_quote_the_scaling_profiles():
    """README's per-leg rates of lever 8 over its 27 cells (turning, then straight) and lever 7's beside them."""
    lever, before = (leg_kinds(json.loads((ANT / f"{name}_legs.json").read_text()))
                     for name in ("oracle_wide_scaling", "oracle_corrector_scaling"))
    assert front("oracle wide legs") == f"{lever['turning'][3]} and {lever['straight'][3]}"
    readme = " ".join(pages().split())
    rate = {kind: before[kind][3].split()[0] for kind in ("turning", "straight")}
    assert f"(lever 7: {rate['turning']} and {rate['straight']}), above issue 42's 0.0005 and 0.0003" in readme


def test_lever_8_scaling_switches_recompute_from_the_shipped_profiles():
    """docs/ant_experiments.md's losses by the kind of the leg before, on lever 8's 27 cells (turn_table after=True)."""
    kinds = leg_kinds(json.loads((ANT / "oracle_wide_scaling_legs.json").read_text()), after=True)
    rate = {kind: row[3] for kind, row in kinds.items()}
    assert docs_marker("lever 8 scaling switches") == (
        f"the second leg, the first goal switch, {rate['straight after first leg']}; a straight leg after a straight "
        f"one {rate['straight after straight']}, after a turn {rate['straight after turning']}; a turn after a "
        f"straight leg {rate['turning after straight']}")


def test_readme_states_issue_42s_targets_as_the_checks_count_them():
    """README's summary of issue 42: the mazes below 0.97 for redraw and for lever 8 (their oracle checks), and the
    sampled grid's mazes below 0.90 (README's own marker)."""
    def below(table):
        summary = next(line for line in (ROOT / "data" / "results" / "ant" / table).read_text().splitlines()
                       if line.startswith("Summary: "))
        return re.search(r"below the level on (\d+) of 9 mazes run: ([^;]*);", summary).groups()

    readme = " ".join((ROOT / "README.md").read_text().split())
    words = {2: "two", 4: "four"}
    redraw, wide = below("oracle_corrector_scaling_check.md"), below("oracle_wide_scaling_check.md")
    assert f"misses it on {words[int(redraw[0])]} of the nine mazes" in readme
    assert wide == ("2", "u_chain_4, u_chain_5_subgoals") and "on two, U-chain 4 and U-chain 5 with subgoals" in readme
    sampled = re.search(r"(\d+) of the 9 mazes below 0.90", front("sampled grid")).group(1)
    assert f"is below 0.90 on {sampled} of its 9 mazes" in readme


def test_the_paper_preset_grid_beside_the_nearest_grid_regenerates(tmp_path, monkeypatch):
    """data/results/ant/oracle_paper_vs_scaling.md by the command data/results/README.md names, and the docs' section
    quotes its pooled difference and costs."""
    from specrefine.experiments import oracle_check

    monkeypatch.chdir(ROOT)
    readme = " ".join((ROOT / "data" / "results" / "README.md").read_text().split())
    command = re.search(r"the same command with `(--baseline .*? --out data/results/ant/oracle_paper_vs_scaling\.md)`",
                        readme).group(1)
    out = tmp_path / "vs.md"
    args = shlex.split(command.removesuffix("data/results/ant/oracle_paper_vs_scaling.md") + str(out))
    assert oracle_check.main(["data/results/ant/oracle_paper.csv", "--method", "ours", "--level", "0.90",
                              "--tolerance", "0.05", *args]) == 0
    shipped = (ROOT / "data" / "results" / "ant" / "oracle_paper_vs_scaling.md").read_text()
    assert out.read_text() == shipped
    pooled = re.search(r"difference ([+-]\d\.\d{3} \[[^]]+\]) \(Newcombe 95 %\)\. It spent ([\d.]+x) / ([\d.]+x) / "
                       r"([\d.]+x) the baseline's", shipped).groups()
    section = " ".join((ROOT / "docs" / "ant_experiments.md").read_text().split())
    section = section[section.index("## The paper's rule as `--preset paper`"):]
    for number in pooled:
        assert number in section, number


def test_the_paper_preset_legs_recompute_from_the_shipped_profiles():
    """docs/ant_experiments.md's per-kind losses of the paper-preset grid's 27 paths against the centre rule's on the
    same cells, the lost episodes by outcome and the search's estimates, from the shipped JSONs."""
    paper = json.loads((ANT / "oracle_paper_legs.json").read_text())
    centre = json.loads((ANT / "scaling_centre" / "leg_profiles.json").read_text())
    assert {(p["maze"], p["seed"]) for p in paper} == {(p["maze"], p["seed"]) for p in centre} and len(paper) == 27
    assert docs_marker("paper preset legs") == kinds_line(leg_kinds(paper), leg_kinds(centre), "the centre rule's ")
    lost = {k: sum(p["episode_outcomes"].get(k, 0) for p in paper) for k in ("flipped", "avoid", "timeout")}
    estimates = [e for p in paper for e in p["search_estimate"]]
    others = sorted(e for e in estimates if e < 1)
    docs = " ".join((ROOT / "docs" / "ant_experiments.md").read_text().split())
    assert (f"Of the {sum(lost.values()):,} episodes lost, {lost['flipped']} flipped, {lost['avoid']} touched a wall "
            f"and {lost['timeout']} timed out") in docs
    count = ["no", "one", "two", "three", "four", "five"][len(others)]
    assert (f"{len(estimates) - len(others)} of the paths' {len(estimates)} legs have a search estimate of 1.000 (the "
            f"other {count} {others[0]:.3f}-{others[-1]:.3f})") in docs
    legs = [len(p["leg_failure"]) for p in paper]
    assert f"a path's {min(legs)}-{max(legs)} legs" in docs
    kinds = {name: leg_kinds(side) for name, side in (("paper", paper), ("centre", centre))}
    rate = {(name, kind): float(row[kind][3].split()[0]) for name, row in kinds.items() for kind in row}
    for kind in ("straight", "turning"):  # "four to five times more per straight or turning leg"
        assert 4 <= round(rate["paper", kind] / rate["centre", kind], 1) <= 5, kind
    assert f"the first leg {rate['paper', 'first leg']:.4f} against {rate['centre', 'first leg']:.4f}" in docs


def test_readme_states_the_paper_preset_grid_as_its_check_counts_it(tmp_path, monkeypatch):
    """README's `--preset paper` item: the cells run, the mazes below 0.90 and each maze's pooled success, as
    data/results/ant/oracle_paper_check.md gives them; that check regenerates from its table by the command that
    data/results/README.md names."""
    from specrefine.experiments import oracle_check

    monkeypatch.chdir(ROOT)
    out = tmp_path / "check.md"
    assert oracle_check.main(["data/results/ant/oracle_paper.csv", "--method", "ours", "--level", "0.90",
                              "--tolerance", "0.05", "--out", str(out)]) == 0
    check = (ROOT / "data" / "results" / "ant" / "oracle_paper_check.md").read_text()
    assert out.read_text() == check
    cells, below, run = re.search(r"Summary: (\d+) of 27 cells; below the level on (\d+) of (\d+) mazes run",
                                  check).groups()
    readme = " ".join((ROOT / "README.md").read_text().split())
    item = readme[readme.index("**The paper's rule, at least 0.90"):]
    item = item[:item.index(" - **")]
    status = "so far, " if int(cells) < 27 else ""
    assert f"{cells} of 27 cells {status}below 0.90 on {below} of the {run} mazes run" in item, item
    for rate in re.findall(r"^\| u_chain_\w+ \| \d \| (\d\.\d{3}) ", check, re.M):
        assert rate in item, rate
    complete_below = [m for m, rate in re.findall(r"^\| (u_chain_\w+) \| 3 \| (\d\.\d{3}) ", check, re.M)
                      if float(rate) < 0.90]
    assert ("**the rule cannot be met**" in item) == bool(complete_below), complete_below
    change = re.search(r"Summary: .*change from 1 to 5 rooms ([+-]\d\.\d{3}) \[([+-]\d\.\d{3}), ([+-]\d\.\d{3})\]"
                       r"( \(extrapolated)?", check)
    if not change.group(4):  # every room count has a run: README gives the change as the check computes it
        assert f"{change.group(1)} [{change.group(2)}, {change.group(3)}]" in item, change.group(0)
