"""The ``specrefine`` command line.

    specrefine refine MAZE_FILE --agent {point,ant} --method {ours,vlm-oneshot,symbolic,dirl,...}
        --proposer {geometric,random,imperfect:PRESET,replay:PATH,litellm:MODEL} --seed N --out DIR [--spec EXPR]

The options of ``refine`` are the fields of :class:`specrefine.runconfig.RunConfig` (defaults, help, bounds).

Bad input exits 2 with one line on stderr; never a traceback.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .agents import AGENTS as _AGENT_REGISTRY
from .argtypes import OneLineParser, silence_stdout
from .errors import SpecrefineError
from .runconfig import RunConfig, add_run_options

AGENTS = tuple(_AGENT_REGISTRY)


def proposer_arg(text: str) -> str:
    kind, _, rest = text.partition(":")
    if kind in ("geometric", "random") and not rest:
        return text
    if kind in ("replay", "litellm") and rest:
        return text
    if kind == "imperfect" and rest:
        from .proposers.imperfect import parse_imperfect

        try:
            parse_imperfect(rest)
        except SpecrefineError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
        return text
    raise argparse.ArgumentTypeError(
        f"invalid proposer {text!r}: use geometric, random, imperfect:PRESET, replay:PATH or litellm:MODEL")


_OneLineParser = OneLineParser  # the name other modules and tests know


def build_parser() -> argparse.ArgumentParser:
    parser = _OneLineParser(prog="specrefine", description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    r = sub.add_parser("refine", help="refine a maze task's specification and measure the resulting policy",
                       description="Refine the task graph of MAZE_FILE (S -> a -> ... -> G, avoiding walls), "
                                   "then measure the compositional policy end to end on the ORIGINAL task. The "
                                   "defaults are the paper's settings.")
    r.add_argument("maze", metavar="MAZE_FILE", help="a .maze file (or the name of one in data/mazes/)")
    add_run_options(r, types={"proposer": proposer_arg})
    r.add_argument("--out", type=Path, default=Path("runs/latest"),
                   help="output directory for result.json, pictures, the step log and the evaluation cache")
    r.add_argument("--quiet", action="store_true",
                   help="no live progress line on stderr (shown only when stderr is a terminal anyway)")
    return parser


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        from .pipeline import refine_maze  # heavy imports only after argument parsing

        result = refine_maze(args.maze, RunConfig.from_namespace(args), out=args.out,
                             progress=False if args.quiet else None)
    except SpecrefineError as exc:
        print(f"specrefine: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("specrefine: interrupted; evaluations so far are kept in the cache under --out", file=sys.stderr)
        return 130
    try:
        print(result.summary(), flush=True)
    except BrokenPipeError:  # `specrefine refine ... | head`: the run is done and written; no traceback at exit
        silence_stdout()
    return 0


if __name__ == "__main__":
    sys.exit(main())
