"""The ``specrefine`` command line: one entry point, a subcommand per job (``python -m specrefine`` is the same).

    specrefine [--plugin MODULE] COMMAND [options]        specrefine COMMAND --help: its options and defaults

Commands: :data:`COMMANDS` (refine, official, sweep, grids, train, calibrate, failures, taxonomy, the corrector's
reports, figures, bench, notebook, show; the machinery is :mod:`specrefine.core.commands`). Bad input exits 2 with one
line on stderr, never a traceback.
"""

from __future__ import annotations

import sys

from .core.argtypes import OneLineParser
from .core.commands import COMMANDS, Command, build_parser, main, run_command

_OneLineParser = OneLineParser  # the name other modules and tests know

__all__ = ["COMMANDS", "Command", "build_parser", "main", "run_command"]

if __name__ == "__main__":
    sys.exit(main())
