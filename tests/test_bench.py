"""The benchmark entry point: ``python -m specrefine.bench evaluator`` prints one JSON line (a short run)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def test_evaluator_benchmark_prints_one_json_line():
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    run = subprocess.run([sys.executable, "-m", "specrefine.bench", "evaluator", "--agent", "point", "--seconds",
                          "0.2", "--rounds", "1", "--horizon", "20"], cwd=ROOT, env=env, capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    lines = run.stdout.strip().splitlines()
    assert len(lines) == 1
    out = json.loads(lines[0])
    assert out["bench"] == "evaluator" and out["agent"] == "point" and out["batch"] == 32
    assert out["env_steps_per_s"] > 0 and out["env_steps"] > 0 and out["horizon"] == 20
    assert out["raw_same_work_steps_per_s"] > 0 and out["ratio_vs_same_work"] > 0


def test_the_same_work_ceiling_replays_exactly_what_the_evaluator_simulated():
    import numpy as np

    from specrefine.bench.evaluator import _policy, _recorded_steps, _replay, open_room
    from specrefine.evaluation.evaluator import Evaluator

    maze = open_room("point")
    ev = Evaluator(maze, "point", _policy("point")[0], n=16, horizon=12, seed=0)
    ev.evaluate(maze.start, maze.goal, maze.walls, seed=1)  # builds the sim the recording wraps
    before = ev.sim_steps
    calls = _recorded_steps(ev, maze, seed=2)
    assert sum(n for n, *_ in calls) == ev.sim_steps - before  # every simulated row-step, padding included
    assert [s.physics_observer for s in ev.built_sims] == [None]  # the recording leaves the sim as it was
    first, second = calls[0][1], calls[1][1]
    assert not np.array_equal(first, second)  # the states move on, so the replay redoes real steps
    wall, cpu = _replay(ev.sim(16).model, calls, nthread=1)
    assert wall > 0 and cpu > 0


@pytest.mark.parametrize("what", ["evaluator", "gymenv", "train", "refine"])
def test_every_benchmark_is_a_subcommand(what, capsys):
    from specrefine.bench.__main__ import main

    with pytest.raises(SystemExit) as e:
        main([what, "--help"])
    assert e.value.code == 0 and "--agent" in capsys.readouterr().out


def test_refine_benchmark_runs_both_evaluations_and_resumes(tmp_path, capsys):
    from specrefine.bench.__main__ import main

    table = tmp_path / "bench.csv"
    args = ["refine", "--agent", "point", "--mazes", "u_chain_1", "--seeds", "1", "--episodes", "20", "--table",
            str(table)]
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    rows = table.read_text().splitlines()
    assert len(rows) == 3 and rows[1].split(",")[5] == "adaptive"  # odd seed: adaptive first
    assert out["pairs"] == 1 and out["overall"]["sim_steps"]["fixed"] > 0
    assert set(out["per_maze"]) == {"u_chain_1"} and len(out["overall"]["success_adaptive"]) == 1
    from specrefine.bench.refinement import _read, markdown

    lines = markdown(_read(table)).splitlines()
    assert len(lines) == 3 and lines[2].startswith("| u_chain_1 | 1 | ") and lines[2].count("x)") == 2
    assert main(args) == 0  # resumed: nothing rerun, the same summary
    assert len(table.read_text().splitlines()) == 3
    assert json.loads(capsys.readouterr().out.strip().splitlines()[-1]) == out


def test_training_benchmark_reports_the_raw_rollout_ceiling_of_the_same_batch_shape():
    from specrefine.bench.training import bench_train

    out = bench_train("point", batches=1, reference=False)
    ours = out["ours"]
    assert (ours["num_envs"], ours["steps_per_env"], out["raw_nthread"]) == (64, 32, ours["sim_threads"])
    assert len(ours["fps_per_batch"]) == 1 and out["raw_rollout_steps_per_s"] > 0
    assert out["ratio_vs_raw_rollout"] == round(ours["fps_median"] / out["raw_rollout_steps_per_s"], 3)
    assert out["ratio_vs_raw_per_step"] == round(ours["fps_median"] / out["raw_per_step_steps_per_s"], 3)
    assert "reference_minibatch64" not in out
