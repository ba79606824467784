"""A built wheel runs ``specrefine refine`` from any directory: prompts, mazes and policies travel with it."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SOURCES = ["pyproject.toml", "setup.py", "README.md", "specrefine", "prompts", "data/mazes", "data/policies",
           "data/vlm/README.md"]


def _copy_sources(dst: Path) -> None:
    """The files a build reads, copied so that the build leaves nothing in the checkout."""
    for name in SOURCES:
        src = ROOT / name
        target = dst / name
        target.parent.mkdir(parents=True, exist_ok=True)
        if src.is_dir():
            skip = ("__pycache__", "*.pyc") + (("pictures",) if name == "data/mazes" else ())  # not the sub-package
            shutil.copytree(src, target, ignore=shutil.ignore_patterns(*skip))
        else:
            shutil.copy2(src, target)


@pytest.mark.slow
def test_wheel_runs_refine_outside_the_checkout(tmp_path):
    src, dist, site, work = (tmp_path / d for d in ("src", "dist", "site", "elsewhere"))
    _copy_sources(src)
    pip = [sys.executable, "-m", "pip", "--disable-pip-version-check", "-q"]
    subprocess.run(pip + ["wheel", "--no-deps", "--no-build-isolation", "-w", str(dist), str(src)], check=True,
                   cwd=tmp_path, timeout=300)
    wheel = next(dist.glob("specrefine-*.whl"))
    subprocess.run(pip + ["install", "--no-deps", "--no-compile", "--target", str(site), str(wheel)], check=True,
                   timeout=300)
    work.mkdir()
    # only the installed copy on the path: the checkout (and the editable install, whose finder comes last) lose
    env = {**os.environ, "PYTHONPATH": str(site)}
    probe = ("import specrefine, specrefine.core.paths as p; from specrefine.proposers import system_message; "
             "assert 'Specification language' in system_message()['content']; "
             "print(specrefine.__file__); print(p.prompt_dir()); print(p.data_dir())")
    where = subprocess.run([sys.executable, "-c", probe], cwd=work, env=env, capture_output=True, text=True,
                           check=True).stdout.split()
    assert len(where) == 3 and all(Path(p).is_relative_to(site) for p in where), where
    assert (site / "specrefine" / "py.typed").is_file()  # type hints ship (PEP 561)
    run = subprocess.run([str(site / "bin" / "specrefine"), "refine", "split_doorway", "--agent", "point",
                          "--proposer", "geometric", "--rollouts", "4", "--episodes", "4", "-w", "1", "-d", "1",
                          "-k", "1", "--out", str(work / "run")], cwd=work, env=env, capture_output=True,
                         text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    result = json.loads((work / "run" / "result.json").read_text())
    assert result["maze"] == "split_doorway" and result["episodes"] == 4 and result["evaluations"] > 0
