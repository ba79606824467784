"""Issue 29 (reliability, round 3): no code from a checkpoint, no half-written file, one lock, and every command's
bad input in one line (exit 2) before any long work."""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
TINY = ["--rollouts", "2", "--episodes", "2"]


def run_module(module: str, *args, cwd=None, env=None, timeout=120) -> subprocess.CompletedProcess:
    """``python -m MODULE ARGS`` with this checkout on the path (stdout, stderr as text)."""
    full_env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
                **(env or {})}
    return subprocess.run([sys.executable, "-m", module, *map(str, args)], capture_output=True, text=True,
                          cwd=cwd or ROOT, env=full_env, timeout=timeout)


def assert_one_line_2(proc: subprocess.CompletedProcess, needle: str = "") -> str:
    err = proc.stderr.strip()
    assert proc.returncode == 2, (proc.returncode, err[-2000:])
    assert len(err.splitlines()) == 1 and "Traceback" not in err and needle in err, err[-2000:]
    return err


# --- security: a checkpoint never runs code -------------------------------------------------------------
class _MakesAFile:
    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):  # what an attacker's checkpoint does on unpickling: here, create a file
        return (open, (self.path, "w"))


TRAIN_TINY = ["--agent", "point", "--frames", "64", "--num-envs", "2", "--steps-per-env", "4", "--no-progress"]


@pytest.mark.parametrize("how", ["--init", "--resume"])
def test_a_malicious_checkpoint_runs_no_code_and_is_one_line(tmp_path, how):
    marker = tmp_path / "pwned"
    evil = tmp_path / "out" / "checkpoint.pt"
    evil.parent.mkdir()
    evil.write_bytes(pickle.dumps({"loss": _MakesAFile(marker)}))
    extra = ["--init", evil] if how == "--init" else ["--resume"]
    proc = run_module("specrefine.train", *TRAIN_TINY, "--out", tmp_path / "out", *extra)
    assert not marker.exists()  # the pickle's code never ran
    assert_one_line_2(proc, f"{how} {evil}")


def test_resume_from_a_foreign_checkpoint_is_one_line(tmp_path):
    import torch

    torch.save({"weights": torch.zeros(3)}, tmp_path / "checkpoint.pt")  # safe to load, but not ours
    proc = run_module("specrefine.train", *TRAIN_TINY, "--out", tmp_path, "--resume")
    assert "KeyError" not in assert_one_line_2(proc, "not a trainer checkpoint")
