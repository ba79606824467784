"""`specrefine refine` end to end on the shipped point policy: result.json keys, pictures, bad input."""

from __future__ import annotations

import json

import pytest

from specrefine.cli import main
from specrefine.core.graph import TaskGraph, check_refines
from specrefine.core.mazes import load_maze
from specrefine.core.spec import maze_task

REQUIRED = ["success_rate", "success_ci", "episodes", "predicted_success", "evaluations", "sim_steps", "vlm_calls",
            "wall_seconds", "graph"]
FAST = ["--rollouts", "8", "--episodes", "24"]


@pytest.mark.parametrize("method", ["dirl", "symbolic", "ours", "vlm-oneshot", "ours-corrector-mend"])
def test_refine_writes_every_result_key(tmp_path, method, capsys):
    out = tmp_path / method
    code = main(["refine", "u_maze", "--agent", "point", "--method", method, "--proposer", "geometric",
                 "--seed", "0", "--out", str(out), *FAST])
    assert code == 0, capsys.readouterr().err
    data = json.loads((out / "result.json").read_text())
    for key in REQUIRED:
        assert key in data, key
    lo, hi = data["success_ci"]
    assert 0 <= lo <= data["success_rate"] <= hi <= 1 and data["episodes"] == 24
    assert data["vlm_calls"] == 0 and data["proposer_is_vlm"] is False  # geometric is never a VLM
    refined = TaskGraph.from_dict(data["graph"])
    original = maze_task(load_maze("u_maze").for_agent("point"))
    if method != "vlm-oneshot":
        assert check_refines(refined, original) == [] and data["refines_input"] is True
    assert (out / "refined.png").stat().st_size > 1000 and (out / "graph.png").exists()
    assert (out / "roadmap.png").exists() == (method == "ours-corrector-mend")  # the correction's roadmap, if any
    assert (out / "steps.jsonl").exists()
    assert "success on the original task" in capsys.readouterr().out


def test_rerun_resumes_from_the_cache(tmp_path, capsys):
    args = ["refine", "u_maze", "--method", "ours", "--out", str(tmp_path), *FAST]
    assert main(args) == 0
    first = json.loads((tmp_path / "result.json").read_text())
    assert main(args) == 0
    second = json.loads((tmp_path / "result.json").read_text())
    assert first["evaluations"] > 0 and second["evaluations_simulated"] == 0  # all from the disk cache
    assert second["evaluations"] == first["evaluations"]
    assert second["success_rate"] == first["success_rate"] and second["graph"] == first["graph"]


def run_cli(args) -> int:
    try:
        return main(args)
    except SystemExit as exc:  # argparse errors
        return exc.code


@pytest.mark.parametrize("args,needle", [
    (["--proposer", "gpt"], "invalid proposer"),
    (["--proposer", "replay:/no/such/recording.jsonl"], "recording"),
    (["--method", "best"], "invalid choice"),
    (["--policy", "{tmp}/bad.pt"], "bad.pt"),
])
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, args, needle):
    (tmp_path / "bad.pt").write_bytes(b"not a checkpoint")
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    code = run_cli(["refine", "u_maze", "--method", "ours", "--out", str(tmp_path / "o"), *FAST, *args])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and needle in err, err
