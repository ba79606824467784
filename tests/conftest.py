"""Shared test setup: headless matplotlib for every test (and the notebooks they run); notebook tiers."""

import os

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")


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
