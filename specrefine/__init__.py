"""specrefine: VLM-proposed, symbolically tuned refinement of reach-avoid task specifications."""

from .runs.experiment import Experiment, setup

__version__ = "0.1.0"


def record(name, value, *, tol=None, rel=None):
    """Record a notebook's key figure for the regression tests: see ``specrefine.runs.notebook.record``."""
    from .runs.notebook import record as _record  # imported on use: `python -m specrefine.runs.notebook` stays clean

    return _record(name, value, tol=tol, rel=rel)


__all__ = ["Experiment", "setup", "record", "__version__"]
