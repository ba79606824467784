"""Shared test setup: headless matplotlib for every test (and the notebooks they run); notebook tiers; a finished
point run to read."""

import os
from pathlib import Path

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory) -> Path:
    """A finished point run (u_maze, ours, geometric), one per test module, read-only to the tests: they tamper
    with copies."""
    from specrefine.cli import main as cli_main

    out = tmp_path_factory.mktemp("finished") / "run"
    assert cli_main(["refine", "u_maze", "--method", "ours", "--proposer", "geometric", "--rollouts", "8",
                     "--episodes", "8", "--quiet", "--out", str(out)]) == 0
    return out


def pytest_addoption(parser):
    parser.addoption("--update-notebook-expected", action="store_true", default=False,
                     help="write the figures the notebooks record into tests/notebook_expected/<tier>.json "
                          "instead of comparing (a decision, not a fix: see tests/test_notebooks.py)")


def pytest_collection_modifyitems(config, items):
    """The full-parameter notebook runs (minutes each) run only when selected: -m notebooks_full."""
    if "notebooks_full" in (config.getoption("-m") or ""):
        return
    skip = pytest.mark.skip(reason="full-parameter notebook run: select with -m notebooks_full (make notebooks-full)")
    for item in items:
        if "notebooks_full" in item.keywords:
            item.add_marker(skip)
