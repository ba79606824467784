"""specrefine.experiments.cost: a run's time split from its result.json, written whole or not at all."""
import json

from specrefine.experiments import cost


def _result(seed, **over):
    result = {"maze": "u_chain_5", "agent": "ant", "seed": seed, "success_rate": 0.9, "episodes": 200,
              "path_edges": 38, "evaluations": 100, "sim_steps": 5000, "wall_seconds": 50.5, "search_seconds": 40.0,
              "measure_seconds": 8.0, "calibrate_seconds": 2.0, "graph": {}, "path": []}
    return result | over


def test_the_report_keeps_the_given_notes_first_and_each_runs_split(tmp_path, capsys):
    paths = []
    for seed in (0, 1):
        paths.append(tmp_path / f"s{seed}.json")
        paths[-1].write_text(json.dumps(_result(seed)))
    out = tmp_path / "cost.json"
    assert cost.main([*map(str, paths), "--about", "what=two runs", "--about", "machine=a=b", "--out", str(out)]) == 0
    report = json.loads(out.read_text())
    assert list(report) == ["what", "machine", "runs"] and report["machine"] == "a=b"
    assert [r["seed"] for r in report["runs"]] == [0, 1]
    assert report["runs"][0] == {k: _result(0)[k] for k in cost.FIELDS}
    assert "seed 1: 50 s (search 40, measurement 8, calibration 2)" in capsys.readouterr().out


def test_a_result_without_the_split_or_a_bad_note_writes_nothing(tmp_path, capsys):
    old = _result(0)
    del old["search_seconds"]
    path, out = tmp_path / "old.json", tmp_path / "cost.json"
    path.write_text(json.dumps(old))
    assert cost.main([str(path), "--out", str(out)]) == 2
    assert "no search_seconds" in capsys.readouterr().err and not out.exists()
    path.write_text(json.dumps(_result(0)))
    assert cost.main([str(path), "--about", "no equals sign", "--out", str(out)]) == 2
    assert "KEY=TEXT" in capsys.readouterr().err and not out.exists()
