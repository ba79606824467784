"""``specrefine refine``: one run on one maze (the options are :class:`~specrefine.runs.config.RunConfig`'s fields)."""

from __future__ import annotations

import sys
from pathlib import Path

from ..core.argtypes import out_path, silence_stdout
from .config import add_run_options, proposer_arg

DESCRIPTION = ("Refine the task graph of MAZE_FILE (S -> a -> ... -> G, avoiding walls), then measure the "
               "compositional policy end to end on the ORIGINAL task. The defaults are the best measured settings "
               "(--preset best); --preset paper restores every rule of the paper they depart from "
               "(docs/choices.md, 'Presets').")


def add_arguments(parser) -> None:
    parser.description = DESCRIPTION
    parser.add_argument("maze", metavar="MAZE_FILE",
                        help="a .maze file, the name of one in data/mazes/, gr:NAME (a Gymnasium-Robotics map: "
                             "gr:U_MAZE, gr:MEDIUM_MAZE, gr:LARGE_MAZE, gr:LARGE_MAZE_DIVERSE_G, ...) or "
                             "random:RxC:SEED (a generated corridor maze of R x C rooms)")
    add_run_options(parser, types={"proposer": proposer_arg})
    parser.add_argument("--out", type=out_path, default=Path("runs/latest"),
                        help="output directory for result.json, pictures, the step log and the evaluation cache")
    parser.add_argument("--quiet", action="store_true",
                        help="no live progress line on stderr (shown only when stderr is a terminal anyway)")


def run(args, parser) -> int:
    from ..core.errors import SpecrefineError
    from .config import RunConfig
    from .pipeline import refine_maze  # heavy imports only after argument parsing

    try:
        result = refine_maze(args.maze, RunConfig.from_namespace(args), out=args.out,
                             progress=False if args.quiet else None)
    except SpecrefineError as exc:
        print(f"specrefine: error: {exc}", file=sys.stderr)  # the prefix scripts know
        return 2
    except KeyboardInterrupt:
        print("specrefine: interrupted; evaluations so far are kept in the cache under --out", file=sys.stderr)
        return 130
    try:
        print(result.summary(), flush=True)
    except BrokenPipeError:  # `specrefine refine ... | head`: the run is done and written
        silence_stdout()
    return 0
