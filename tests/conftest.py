"""Shared test setup: headless matplotlib for every test (and the notebooks they run)."""

import os

os.environ.setdefault("MPLBACKEND", "Agg")
