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


@pytest.mark.parametrize("what", ["evaluator", "gymenv", "train"])
def test_every_benchmark_is_a_subcommand(what, capsys):
    from specrefine.bench.__main__ import main

    with pytest.raises(SystemExit) as e:
        main([what, "--help"])
    assert e.value.code == 0 and "--agent" in capsys.readouterr().out
