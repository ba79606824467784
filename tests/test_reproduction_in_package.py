"""docs/interfaces.md's decision (issue 43 section 7): the paper's reproduction stays in the package, as commands,
and the library never loads it."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
REPRODUCTION = ("specrefine.experiments", "specrefine.bench", "specrefine.runs.notebook", "papermill")


def test_the_library_loads_none_of_the_reproduction():
    code = ("import sys, specrefine\n"
            "from specrefine.runs.pipeline import refine_maze\n"
            "from specrefine.runs.official import judged_env\n"
            "from specrefine.evaluation.gym_wrapper import TaskJudge\n"
            f"print(sorted(m for m in sys.modules if m.startswith({REPRODUCTION!r})))")
    done = subprocess.run([sys.executable, "-c", code], env=ENV, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip() == "[]"


def test_the_benchmark_contract_and_the_commands_run_from_the_installed_modules():
    for argv in (["-m", "specrefine.bench", "evaluator", "--help"], ["-m", "specrefine", "grids", "list"]):
        done = subprocess.run([sys.executable, *argv], env=ENV, capture_output=True, text=True, timeout=300,
                              cwd=ROOT.parent)  # found as the package's modules, not by the working directory
        assert done.returncode == 0, (argv, done.stderr[-2000:])
        assert done.stdout.strip()
