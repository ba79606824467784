"""The grid registry: each shipped table holds cells of its grid only (all of them for the finished grids), with the
grid's rollouts, episodes, evaluation and policy; the sweep arguments parse back to the same cells; the CLI and
scripts/run_grid.sh (dry run) print what the old per-grid scripts ran."""

from __future__ import annotations

import csv
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from specrefine.experiments import grids
from specrefine.runs import sweep

ROOT = Path(__file__).resolve().parents[1]
#: the grids whose every cell has a row (decided from the tables: these ran to the end)
COMPLETE = {"paper-sweep", "point-comparison", "controls", "repair", "repair-tuned", "ant-comparison", "ant-polish",
            "ant-centre", "ant-scaling-centre", "ant-shortcut-centre", "ant-rotated-centre", "ant-polish-erring",
            "ant-shortcut-centre-ties", "antmaze", "antmaze-centre"}
SHIPPED = [(g, t) for g in grids.GRIDS.values() for t in g.tables if (ROOT / t).exists()]


def _rows(table: str) -> list[dict]:
    with (ROOT / table).open(newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.mark.parametrize("g, table", SHIPPED, ids=[f"{g.name}:{t}" for g, t in SHIPPED])
def test_a_shipped_table_holds_cells_of_its_grid_with_its_parameters(g, table):
    expected = {c.id: c for c in grids.cells(g, table=table)}
    rows = _rows(table)
    assert {r["cell"] for r in rows} <= set(expected), "rows of cells outside the grid"
    if g.name in COMPLETE:
        assert {r["cell"] for r in rows} == set(expected)
    for row in rows:
        cell = expected[row["cell"]]
        assert (int(row["rollouts_per_evaluation"]), int(row["episodes"])) == (cell.rollouts, cell.episodes)
        assert row.get("evaluation") in (None, cell.evaluation)
        if row.get("policy") == "shipped" or cell.policy == "shipped":
            assert row.get("policy") in (None, "shipped") and cell.policy == "shipped"
        elif row.get("policy"):  # a path from the machine that ran it: the same file of the same tree
            relative = Path(cell.policy).relative_to(ROOT).as_posix()
            assert row["policy"].endswith("/" + relative)
            assert "/runs/" not in row["policy"][:-len(relative)], "a pinned tree's copy where the checkout's ran"


def test_every_table_belongs_to_one_grid():
    tables = [t for g in grids.GRIDS.values() for t in g.tables]
    assert len(tables) == len(set(tables))


def _git(*args) -> subprocess.CompletedProcess:
    return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True)


PINNED = [g for g in grids.GRIDS.values() if g.code]


@pytest.mark.skipif(not (ROOT / ".git").exists(), reason="not a git checkout")
@pytest.mark.parametrize("g", PINNED, ids=[g.name for g in PINNED])
def test_the_pinned_code_takes_the_grids_arguments(g):
    """The commit's own sweep knows every option and method the grid passes it, and what scripts/pinned_sweep.sh
    reads from it to ship the table."""
    assert _git("cat-file", "-t", g.code).stdout.strip() == "commit"
    moved = _git("cat-file", "-e", f"{g.code}:specrefine/runs/sweep.py").returncode == 0  # the sub-package layout
    module = "specrefine/runs/sweep.py" if moved else "specrefine/sweep.py"
    source = _git("show", f"{g.code}:{module}").stdout
    if moved:  # the RunConfig fields that add_run_options turns into the sweep's options
        source += _git("show", f"{g.code}:specrefine/runs/config.py").stdout
    options = {a for i in range(len(g.parts)) for args in grids.sweep_args(g, i) for a in args if a.startswith("--")}
    # an option is spelled out ("--policy") or, for the RunConfig fields add_run_options turns into options, named
    # ("episodes", "goal_points")
    assert all(f'"{option}"' in source or f'"{option[2:].replace("-", "_")}"' in source for option in options), options
    assert "def is_done" in source and "_typed" in source
    for method in g.methods:
        assert _git("grep", "-q", f'"{method}"', g.code, "--", "specrefine").returncode == 0, method


@pytest.mark.parametrize("name", list(grids.GRIDS))
def test_sweep_args_parse_back_to_the_grids_cells(name, tmp_path, monkeypatch):
    g = grids.GRIDS[name]
    root = tmp_path.resolve()
    tree = root / "runs" / f"code_{g.code}"
    tree.mkdir(parents=True)
    monkeypatch.chdir(tree)  # where scripts/pinned_sweep.sh runs the sweep: a relative --policy is that tree's
    for i in range(len(g.parts)):
        steps = grids.sweep_args(g, i, root=root)
        assert steps and all("--out" not in args for args in steps)
        # every grid is pinned to code from before the best-measured defaults: its sweep's defaults were the
        # paper's goal points, split pick and the shipped policy, which today's sweep is told explicitly
        then = (["--goal-points", "sampled"] if g.goal_points is None else []) + \
            (["--split-pick", "estimate"] if g.split_pick is None else [])
        parsed = [c for args in steps for c in sweep.cells_of(sweep.parser().parse_args(
            args + then + ([] if "--policy" in args else ["--policy", "shipped"])))]
        assert list(dict.fromkeys(parsed)) == grids.part_cells(g, i, root=root)


@pytest.mark.parametrize("name, mazes, seeds", [("ant-corrector-redraw", ("u_chain_5",), (0,)),
                                                ("ant-corrector-redraw", ("u_chain_3", "u_chain_2_subgoals"), (2, 1)),
                                                ("repair", None, (1,)), ("paper-sweep", ("u_maze",), None)])
def test_a_subset_runs_the_grids_own_cells_in_its_order(name, mazes, seeds, tmp_path, monkeypatch):
    g = grids.GRIDS[name]
    root = tmp_path.resolve()
    tree = root / "runs" / f"code_{g.code}"
    tree.mkdir(parents=True)
    monkeypatch.chdir(tree)
    subset = grids.Subset(mazes, seeds)
    then = (["--goal-points", "sampled"] if g.goal_points is None else []) + \
        (["--split-pick", "estimate"] if g.split_pick is None else [])
    for i in range(len(g.parts)):
        parsed = [c for args in grids.sweep_args(g, i, root=root, subset=subset) for c in sweep.cells_of(
            sweep.parser().parse_args(args + then + ([] if "--policy" in args else ["--policy", "shipped"])))]
        expected = [c for c in grids.part_cells(g, i, root=root)
                    if (mazes is None or c.maze in mazes) and (seeds is None or c.seed in seeds)]
        assert parsed == expected and expected  # the same ids, in the grid's order (not the subset's)


def test_a_subset_outside_the_grid_is_refused_in_one_line(capsys):
    for argv in (["args", "ant-corrector-redraw", "--part", "0", "--mazes", "u_chain_9"],
                 ["plan", "ant-corrector-redraw", "--seeds", "0", "7"], ["plan", "repair", "--mazes", "u_chian_2"]):
        with pytest.raises(SystemExit) as exit_:
            grids.main(argv)
        err = capsys.readouterr().err
        assert exit_.value.code == 2 and err.count("\n") == 1 and "has no" in err, err
    assert grids.main(["plan", "ant-corrector-redraw", "--mazes", "u_chain_5", "--seeds", "1"]) == 0
    assert [line.split("\t")[:3] for line in capsys.readouterr().out.splitlines()] == [["code", "96e357e"],
                                                                                      ["step", "0", "0"]]


def test_args_cli_prints_one_step_and_refuses_an_unknown_grid(capsys):
    command = [sys.executable, "-m", "specrefine.experiments.grids", "args", "repair", "--part", "0", "--step", "1"]
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, env=os.environ | {"PYTHONPATH": str(ROOT)})
    assert done.returncode == 0
    assert done.stdout == ("--agent point --workers 1 --methods ours ours-repair vlm-oneshot "
                           "--proposers imperfect:severe --seeds 0 1 2 3\n")
    for argv in (["args", "nonsense", "--part", "0"], ["show", "nonsense"], ["args", "repair", "--part", "1"],
                 ["args", "repair", "--part", "0", "--step", "3"]):
        with pytest.raises(SystemExit) as exit_:
            grids.main(argv)
        assert exit_.value.code == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "error:" in err


def _dry_run(name: str, **env) -> list[str]:
    done = subprocess.run(["bash", str(ROOT / "scripts" / "run_grid.sh"), name], capture_output=True, text=True,
                          env=os.environ | {"DRY_RUN": "1", "PYTHON": sys.executable} | env)
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


def test_run_grid_dry_run_prints_the_old_scripts_commands():
    # the deleted scripts/repair_grid.sh and scripts/ant_scaling_grid.sh as they ran (CODE given, WORKERS unset)
    repair = [f"CODE=410997e OUT=runs/repair SHIPPED=data/results/repair/results.csv bash scripts/pinned_sweep.sh "
              f"--agent point --workers 1 --methods ours ours-repair vlm-oneshot --proposers imperfect:{preset} "
              f"--seeds 0 1 2 3" for preset in ("moderate", "severe", "mild")]
    assert _dry_run("repair") == repair
    common = ("--agent ant --evaluation adaptive --policy data/policies/ant_stage5.pt --workers 2 --mazes u_chain_1 "
              "u_chain_2 u_chain_2_subgoals u_chain_3 u_chain_3_subgoals u_chain_4 u_chain_4_subgoals u_chain_5 "
              "u_chain_5_subgoals")

    def step(part, args):
        return (f"CODE=fc93db3 OUT=runs/ant_scaling/{part} SHIPPED=data/results/ant/scaling/{part}.csv "
                f"bash scripts/pinned_sweep.sh {common} {args}")

    geo48 = "geometric:max_waypoints=48"
    assert _dry_run("ant-scaling") == (
        [step("ours_geometric", f"--methods ours --proposers {geo48} --seeds {s}") for s in range(3)]
        + [step("oneshot", f"--methods vlm-oneshot --proposers {geo48} imperfect:moderate --seeds 0 1 2")]
        + [step("imperfect", f"--methods ours ours-repair --proposers imperfect:moderate --seeds {s}")
           for s in range(3)]
        + [step("repair_geometric", f"--methods ours-repair --proposers {geo48} --seeds 0 1 2")])


def test_run_grid_takes_code_out_and_workers_from_the_environment_and_refuses_bad_names():
    lines = _dry_run("ant-comparison", CODE="abc1234", OUT="/tmp/elsewhere", WORKERS="1")
    assert len(lines) == 4 and all(line.startswith("CODE=abc1234 OUT=/tmp/elsewhere ") for line in lines)
    assert all(f"--policy {ROOT}/data/policies/ant_stage4.pt --workers 1 " in line for line in lines)
    for name, env in (("nonsense", {}), ("ant-scaling", {"SHIPPED": "one.csv"})):
        done = subprocess.run(["bash", str(ROOT / "scripts" / "run_grid.sh"), name], capture_output=True, text=True,
                              env=os.environ | {"DRY_RUN": "1", "PYTHON": sys.executable} | env)
        assert done.returncode == 2 and done.stdout == "" and done.stderr.count("\n") == 1


def test_run_grid_runs_the_subset_named_by_mazes_and_seeds():
    redraw = ("CODE=96e357e OUT=runs/ant_corrector_redraw SHIPPED=data/results/corrector/ant_redraw.csv bash "
              "scripts/pinned_sweep.sh --agent ant --evaluation adaptive --goal-points centre --split-pick confirmed "
              "--policy data/policies/ant_stage5.pt --workers 1 --mazes {} --methods ours-corrector-redraw "
              "--proposers imperfect:moderate --seeds {}")
    assert _dry_run("ant-corrector-redraw", MAZES="u_chain_5", SEEDS="0", WORKERS="1") == [
        redraw.format("u_chain_5", 0)]
    assert _dry_run("ant-corrector-redraw", MAZES=" u_chain_3  u_chain_2 ", SEEDS="2 1", WORKERS="1") == [
        redraw.format("u_chain_2 u_chain_3", s) for s in (1, 2)]
    done = subprocess.run(["bash", str(ROOT / "scripts" / "run_grid.sh"), "ant-corrector-redraw"], capture_output=True,
                          text=True, env=os.environ | {"DRY_RUN": "1", "PYTHON": sys.executable, "MAZES": "u_chain_*"})
    assert done.returncode == 2 and done.stdout == "" and "has no mazes u_chain_*" in done.stderr


def test_status_counts_done_rows_names_the_rest_and_the_started_ones(tmp_path, capsys, monkeypatch):
    for name in sorted(COMPLETE):  # every cell of a finished grid is done
        assert all(st.done == st.total and not st.missing for st in grids.status(grids.get(name)))
    g = grids.get("ant-scaling")  # a table cut short: its done rows are counted, the rest named in run order
    (tmp_path / "data/results/ant/scaling").mkdir(parents=True)
    first = [c.id for c in grids.part_cells(g, 0)]
    table = tmp_path / g.part_table(0)
    shipped = {r["cell"]: r for r in _rows(g.part_table(0))}
    rows = [shipped[c] for c in first[:3]] + [shipped[first[3]] | {"status": "error", "error": "killed"}]
    with table.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    report = grids.status(g, root=tmp_path)
    assert report[0][1:3] == (3, len(first)) and report[0].missing == first[3:] and report[0].started == {}
    assert all(st.done == 0 for st in report[1:])
    grids.main(["status", "ant-scaling"])
    out = capsys.readouterr().out.splitlines()
    assert len(out) == len(g.parts) and out[0].startswith("part 0: ours x geometric:max_waypoints=48: ")
    # a cell cut midway (its folder, two evaluations cached) is named with them; a done cell's folder is not
    sweep = tmp_path / "sweep"
    cells = Path(g.part_out(0, str(sweep))) / "cells"  # a part's sub-folder of the sweep folder
    for cell, n in ((first[3], 2), (first[4], 0), (first[0], 5)):
        (cells / cell / "cache" / "ab").mkdir(parents=True)
        for k in range(n):
            (cells / cell / "cache" / "ab" / f"ab{k}.npz").write_bytes(b"x")
    report = grids.status(g, root=tmp_path, out=str(sweep))
    assert report[0].started == {first[3]: 2, first[4]: 0} and report[0].done == 3
    monkeypatch.setattr(grids, "ROOT", tmp_path)  # the command reads the table cut short above
    grids.main(["status", "ant-scaling", "--out", str(sweep)])
    out = capsys.readouterr().out.splitlines()
    assert out[0].endswith(f"done, 2 started ({g.part_table(0)})")
    assert out[1:3] == [f"  {first[3]}  (started: 2 evaluations cached)",
                        f"  {first[4]}  (started: 0 evaluations cached)"]
    # a cell held by a live run (this process, its lock naming it) is running now; a cell the sweep finished (a done
    # row in the sweep folder's own table) is named as such until its row is copied into the shipped table; a lock
    # left by a dead process is not a running cell
    from specrefine.core.runfolder import locked

    (cells / first[5] / "cache").mkdir(parents=True)
    (cells / first[5] / ".lock").write_text("999999999 1\n")  # no such process
    with (Path(g.part_out(0, str(sweep))) / "results.csv").open("w", newline="") as fh:
        writer = csv.DictWriter(fh, list(shipped[first[4]]))
        writer.writeheader()
        writer.writerow(shipped[first[4]])
    with locked(cells / first[3]):
        report = grids.status(g, root=tmp_path, out=str(sweep))
        grids.main(["status", "ant-scaling", "--out", str(sweep)])
    assert report[0].running == {first[3]} and report[0].finished == {first[4]}
    table = Path(g.part_out(0, str(sweep))) / "results.csv"
    kept = table.read_text()
    table.write_text("")  # a sweep table with no header yet: no cell finished, as the sweep itself reads it
    assert grids.status(g, root=tmp_path, out=str(sweep))[0].finished == frozenset()
    table.write_text(kept)
    out = capsys.readouterr().out.splitlines()
    # its pace: the steps its cache gained in the last 30 min, none here (the entries are not readable ones)
    assert out[1:4] == [f"  {first[3]}  (started: 2 evaluations cached; running now, 0.0k simulator steps/s over "
                        "the last 30 min)",
                        f"  {first[4]}  (done in the sweep folder's table, not yet in the shipped one)",
                        f"  {first[5]}  (started: 0 evaluations cached)"]


def test_seed_cache_copies_entries_whole_and_keeps_existing_ones(tmp_path):
    src = tmp_path / "from" / "u_chain_3__ant__ours__geometric__s0__adaptive" / "cache" / "ab"
    src.mkdir(parents=True)
    (src / "ab01.npz").write_bytes(b"source one")
    (src / "ab02.npz").write_bytes(b"source two")
    other = tmp_path / "from" / "u_chain_4__ant__ours__geometric__s0__adaptive" / "cache" / "cd"
    other.mkdir(parents=True)
    (other / "cd01.npz").write_bytes(b"other maze")
    dest = tmp_path / "to"
    kept = dest / "u_chain_3__ant__ours-repair__geometric__s0__adaptive" / "cache" / "ab"
    kept.mkdir(parents=True)
    (kept / "ab02.npz").write_bytes(b"already here")
    env = {**os.environ, "FROM": "ours", "TO": "ours-repair", "DEST": str(dest), "MAZES": "u_chain_3"}
    done = subprocess.run(["bash", str(ROOT / "scripts" / "seed_cache.sh"), str(tmp_path / "from")],
                          capture_output=True, text=True, env=env, timeout=60)
    assert done.returncode == 0, done.stderr
    assert "seeded 1 cell caches" in done.stdout
    assert (kept / "ab01.npz").read_bytes() == b"source one"
    assert (kept / "ab02.npz").read_bytes() == b"already here"
    assert sorted(p.name for p in dest.rglob("*") if p.is_file()) == ["ab01.npz", "ab02.npz"]  # no .part left


def test_the_paper_preset_grid_runs_what_preset_paper_resolves_to_for_the_ant(tmp_path):
    """Issue 42's `--preset paper` grid passes its settings explicitly (pinned code); they must be the preset's."""
    from specrefine.runs.config import RunConfig

    paper = RunConfig(agent="ant", proposer=grids.GEOMETRIC_48, preset="paper").resolved()
    cells = grids.cells(grids.GRIDS["ant-oracle-paper"], root=tmp_path)
    assert len(cells) == 27 and {c.maze for c in cells} == set(grids.SCALING_MAZES)
    for c in cells:
        assert Path(c.config.policy).name == f"{paper.policy}.pt"
        # every setting equal; the preset itself is not recorded (run.json records what it decided)
        assert replace(c.config, policy=paper.policy, seed=paper.seed, preset="paper") == paper, c.id


def test_status_reads_a_relative_out_from_the_working_directory(tmp_path, capsys, monkeypatch):
    # a sweep folder named relative to where the user stands (not to the package's checkout) is the one read
    g = grids.get("ant-corrector-span")
    monkeypatch.setattr(grids, "ROOT", tmp_path / "checkout")  # a checkout with no table yet: every cell to run
    missing = grids.status(g)[0].missing
    cell = tmp_path / "mine" / "cells" / missing[0] / "cache" / "ab"
    cell.mkdir(parents=True)
    (cell / "ab0.npz").write_bytes(b"x")
    monkeypatch.chdir(tmp_path)
    grids.main(["status", "ant-corrector-span", "--out", "mine"])
    out = capsys.readouterr().out.splitlines()
    assert out[0].endswith("1 started (data/results/corrector/ant_span.csv)")
    assert out[1] == f"  {missing[0]}  (started: 1 evaluations cached)"
    assert grids.main(["status", "ant-corrector-span", "--out", str(tmp_path / "mine")]) == 0  # the same folder
    assert capsys.readouterr().out.splitlines() == out
