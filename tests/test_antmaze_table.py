"""specrefine.experiments.antmaze: the AntMaze table pools each map and method over seeds in both simulators."""

from __future__ import annotations

import csv
import json

import pytest

from specrefine.experiments import antmaze


def _run(root, name, method, proposer, seed, sim, official=None, maze="gr:U_MAZE"):
    run = root / "cells" / name
    run.mkdir(parents=True)
    (run / "result.json").write_text(json.dumps({"maze": maze, "agent": "ant", "method": method,
                                                 "proposer": proposer, "seed": seed, "success_rate": sim,
                                                 "episodes": 200, "path": [], "graph": {}}))
    if official is not None:
        (run / "official.json").write_text(json.dumps({"success_rate": official, "episodes": 100,
                                                       "env_id": "AntMaze_UMaze-v5"}))


def test_the_table_pools_seeds_in_both_simulators_and_names_no_proposer_for_dirl(tmp_path):
    _run(tmp_path, "a", "ours", "geometric", 0, 0.9, 0.8)
    _run(tmp_path, "b", "ours", "geometric", 1, 0.8, 0.7)
    _run(tmp_path, "c", "dirl", "geometric", 0, 0.0)  # no official run yet
    (tmp_path / "cells" / "d").mkdir()  # a cell still running: no result.json
    rows = antmaze.run_rows(tmp_path)
    assert [(r["method"], r["proposer"], r["seed"]) for r in rows] == [("ours", "geometric", 0),
                                                                        ("ours", "geometric", 1), ("dirl", "none", 0)]
    table = antmaze.table(rows).splitlines()
    assert table[2] == ("| gr:U_MAZE | ours | geometric | 0,1 | 0.850 [0.812, 0.882] (400) | "
                        "0.750 [0.686, 0.805] (200) | -0.100 [-0.172, -0.033] |")  # 340/400, 150/200; Newcombe
    assert table[3].endswith("| — | — |") and "| dirl | none | 0 (official: none yet) |" in table[3]
    assert antmaze.main([str(tmp_path), "--out", str(tmp_path / "out")]) == 0
    with (tmp_path / "out" / "official.csv").open() as fh:
        assert [r["official_successes"] for r in csv.DictReader(fh)] == ["80", "70", ""]
    assert (tmp_path / "out" / "figure.png").stat().st_size > 0


def test_maps_come_small_to_large_whatever_their_folder_names(tmp_path):
    for name, maze in (("gr-LARGE_MAZE__s0", "gr:LARGE_MAZE"), ("gr-MEDIUM_MAZE__s0", "gr:MEDIUM_MAZE"),
                       ("gr-U_MAZE__s0", "gr:U_MAZE"), ("my_maze__s0", "my_maze")):
        _run(tmp_path, name, "ours", "geometric", 0, 0.5, maze=maze)
    assert [k[0] for k in antmaze.groups(antmaze.run_rows(tmp_path))] == ["gr:U_MAZE", "gr:MEDIUM_MAZE",
                                                                          "gr:LARGE_MAZE", "my_maze"]


def test_a_malformed_result_is_one_line_and_exit_2(tmp_path, capsys):
    (tmp_path / "cells" / "x").mkdir(parents=True)
    (tmp_path / "cells" / "x" / "result.json").write_text("[1]")
    with pytest.raises(SystemExit) as exit_:
        antmaze.main([str(tmp_path), "--out", str(tmp_path / "out")])
    assert exit_.value.code == 2 and len(capsys.readouterr().err.strip().splitlines()) == 1


def test_runs_aiming_at_centres_are_their_own_rows_from_their_own_folder(tmp_path):
    _run(tmp_path / "paper", "a", "ours", "geometric", 0, 0.8, 0.8)
    _run(tmp_path / "centre", "a", "ours", "geometric", 0, 0.9, 0.85)
    result = tmp_path / "centre" / "cells" / "a" / "result.json"
    result.write_text(json.dumps({**json.loads(result.read_text()), "goal_points": "centre"}))
    rows = antmaze.run_rows([tmp_path / "paper", tmp_path / "centre"])
    assert [k[1] for k in antmaze.groups(rows)] == ["ours", "ours (centre)"]
    assert antmaze.main([str(tmp_path / "paper"), str(tmp_path / "centre"), "--out", str(tmp_path / "out")]) == 0
    assert "| ours (centre) | geometric | 0 | 0.900" in (tmp_path / "out" / "table.md").read_text()


def test_the_difference_pools_only_the_runs_measured_in_both_simulators(tmp_path):
    _run(tmp_path, "a", "ours", "geometric", 0, 0.9, 0.9)
    _run(tmp_path, "b", "ours", "geometric", 1, 0.1)  # no official run yet: left out of the difference
    line = antmaze.table(antmaze.run_rows(tmp_path)).splitlines()[2]
    assert "| 0,1 (official: 0) | 0.500 [0.451, 0.549] (400) |" in line  # this simulator: both runs
    assert line.endswith("| +0.000 [-0.082, +0.067] |")  # 90/100 official vs 180/200 here


def test_the_headline_quotes_one_method_per_map_in_both_simulators(tmp_path):
    _run(tmp_path, "a", "ours", "geometric", 0, 0.9, 0.8)
    _run(tmp_path, "b", "ours", "geometric", 0, 0.5, maze="gr:LARGE_MAZE")  # no official run yet
    _run(tmp_path, "c", "dirl", "none", 0, 0.0, 0.0)
    rows = antmaze.run_rows(tmp_path)
    assert antmaze.headline(rows, "ours", "geometric") == "U_MAZE 0.900 / 0.800, LARGE_MAZE 0.500 / —"


def test_official_episodes_on_each_runs_own_seed_with_seed_run(tmp_path, monkeypatch, capsys):
    seeds = []

    def fake_official(run, episodes, seed):
        seeds.append((run.name, episodes, seed))
        (run / "official.json").write_text(json.dumps({"success_rate": 0.5, "episodes": episodes,
                                                       "env_id": "AntMaze_UMaze-v5"}))

    monkeypatch.setattr(antmaze, "run_official", fake_official)
    _run(tmp_path, "a", "ours", "geometric", 1, 0.9)
    _run(tmp_path, "b", "ours", "geometric", 2, 0.9)
    assert antmaze.main([str(tmp_path), "--official", "10", "--seed", "run", "--out", str(tmp_path / "out")]) == 0
    assert seeds == [("a", 10, 1), ("b", 10, 2)]
    _run(tmp_path / "fixed", "c", "ours", "geometric", 2, 0.9)
    assert antmaze.main([str(tmp_path / "fixed"), "--official", "10", "--out", str(tmp_path / "out2")]) == 0
    assert seeds[-1] == ("c", 10, 0)  # the default: one seed for every run, as the shipped tables ran
    with pytest.raises(SystemExit) as exit_:
        antmaze.main([str(tmp_path), "--seed", "first", "--out", str(tmp_path / "out3")])
    assert exit_.value.code == 2 and "an integer or 'run'" in capsys.readouterr().err


def test_an_out_it_cannot_use_is_refused_before_any_official_episode(tmp_path, monkeypatch, capsys):
    from specrefine.core.runfolder import locked

    monkeypatch.setattr(antmaze, "run_official", lambda *a: pytest.fail("an official episode ran"))
    _run(tmp_path, "a", "ours", "geometric", 0, 0.9)
    (tmp_path / "file").write_text("x")
    with pytest.raises(SystemExit) as exit_:
        antmaze.main([str(tmp_path), "--official", "10", "--out", str(tmp_path / "file")])
    assert exit_.value.code == 2 and "not a directory" in capsys.readouterr().err
    out = tmp_path / "out"
    out.mkdir()
    with locked(out), pytest.raises(SystemExit) as exit_:  # another command writing the same table
        antmaze.main([str(tmp_path), "--out", str(out)])
    assert exit_.value.code == 2 and "in use" in capsys.readouterr().err and not any(out.iterdir())
