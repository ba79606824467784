"""Plugins: user code that registers methods and proposers, loaded before any command line is built.

A plugin is a module whose import calls :func:`specrefine.runs.methods.register_method` and/or
:func:`specrefine.proposers.register_proposer` (see ``examples/greedy_plugin.py``). ``specrefine`` loads, before it
builds a parser (so that ``--method`` and ``--proposer`` accept the plugin's names):

* every entry point of the groups ``specrefine.methods`` and ``specrefine.proposers`` of the installed packages
  (``[project.entry-points."specrefine.methods"] greedy = "mypackage.plugin"``); an entry point naming a function
  (``"mypackage.plugin:register"``) has it called with no arguments;
* each ``--plugin MODULE`` (a dotted module name, found from the working directory as ``python -m`` would, or the
  path of a ``.py`` file), in the order given.

A sweep passes the same plugins to its cells (:func:`loaded`), so a Ray worker loads them too. A plugin that cannot
be imported, or whose registration is refused, is one line and exit 2.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import sys
from importlib.metadata import entry_points
from pathlib import Path

from .errors import SpecrefineError

GROUPS = ("specrefine.methods", "specrefine.proposers")
_done: list[str] = []  # what was loaded, in order: entry points as GROUP:NAME, modules as given


def plugin_args(argv: list[str]) -> list[str]:
    """The values of every ``--plugin MODULE`` / ``--plugin=MODULE`` in ``argv`` (up to a ``--``)."""
    found = []
    for i, arg in enumerate(argv):
        if arg == "--":
            break
        if arg == "--plugin" and i + 1 < len(argv):
            found.append(argv[i + 1])
        elif arg.startswith("--plugin="):
            found.append(arg.split("=", 1)[1])
    return found


def load_plugins(modules=()) -> None:
    """Load the installed entry points (once) and each module in ``modules`` (each once)."""
    if "entry points" not in _done:
        for group in GROUPS:
            for point in entry_points(group=group):
                _load_entry_point(group, point)
        _done.append("entry points")
    for module in modules:
        if module not in _done:
            _import(module)
            _done.append(module)


def loaded() -> list[str]:
    """The ``--plugin`` modules loaded in this process, in order (for a sweep's workers)."""
    return [name for name in _done if name != "entry points"]


def _load_entry_point(group: str, point) -> None:
    where = f"plugin {point.name!r} ({group} = {point.value})"
    try:
        target = point.load()
        if callable(target):
            target()
    except SpecrefineError as exc:
        raise SpecrefineError(f"{where}: {exc}") from None
    except Exception as exc:  # noqa: BLE001 - a broken plugin is one line, never a traceback
        raise SpecrefineError(f"{where} failed to load: {type(exc).__name__}: {exc}") from None


def _import(module: str) -> None:
    try:
        if module.endswith(".py") or os.sep in module:
            path = Path(module)
            if not path.is_file():
                raise SpecrefineError(f"--plugin {module}: no such file")
            spec = importlib.util.spec_from_file_location(f"specrefine_plugin_{path.stem}", path)
            loaded_module = importlib.util.module_from_spec(spec)
            sys.modules[spec.name] = loaded_module
            spec.loader.exec_module(loaded_module)
        else:
            if "" not in sys.path and os.getcwd() not in sys.path:  # as `python -m` finds modules
                sys.path.insert(0, os.getcwd())
            importlib.import_module(module)
    except SpecrefineError as exc:
        raise SpecrefineError(str(exc) if str(exc).startswith("--plugin") else f"--plugin {module}: {exc}") from None
    except Exception as exc:  # noqa: BLE001 - a broken plugin is one line, never a traceback
        raise SpecrefineError(f"--plugin {module}: cannot load it: {type(exc).__name__}: {exc}") from None
