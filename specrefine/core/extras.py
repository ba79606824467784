"""The optional parts of the package (``pip install 'specrefine[EXTRA]'``): a missing one is one line naming it.

A base install refines with the offline proposers; the extras add ``vlm`` (LiteLLM: ``litellm:MODEL`` proposers),
``ray`` (the sweep's ``--backend ray``), ``notebooks`` (JupyterLab, papermill, ipywidgets: ``specrefine notebook``
and the notebooks' widgets) and ``dev`` (the test suite and linters).
"""

from __future__ import annotations

import importlib

from .errors import SpecrefineError


def require(module: str, extra: str, what: str):
    """``module``, imported; if it is not installed, a :class:`SpecrefineError` naming the extra that installs it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise SpecrefineError(f"{what} needs {module.split('.')[0]}, which is not installed: "
                              f"pip install 'specrefine[{extra}]'") from None
