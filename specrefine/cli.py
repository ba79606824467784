"""The ``specrefine`` command line.

    specrefine refine MAZE_FILE --agent {point,ant} --method {ours,vlm-oneshot,symbolic,dirl,...}
        --proposer {geometric,random,imperfect:PRESET,replay:PATH,litellm:MODEL} --seed N --out DIR [--spec EXPR]
    specrefine official RUN_DIR [--episodes N] [--seed S] [--start {official,package}]
        [--reset-noise {official,package}] [--out FILE]

The options of ``refine`` are the fields of :class:`specrefine.runs.config.RunConfig` (defaults, help, bounds).

Bad input exits 2 with one line on stderr; never a traceback.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .core.agents import AGENTS as _AGENT_REGISTRY
from .core.argtypes import OneLineParser, bounded_int, out_path, silence_stdout
from .core.errors import SpecrefineError
from .runs.config import DEFAULTS, RunConfig, add_run_options, proposer_arg
from .runs.official import RESET_RULES

AGENTS = tuple(_AGENT_REGISTRY)


_OneLineParser = OneLineParser  # the name other modules and tests know


def build_parser() -> argparse.ArgumentParser:
    parser = _OneLineParser(prog="specrefine", description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    r = sub.add_parser("refine", help="refine a maze task's specification and measure the resulting policy",
                       description="Refine the task graph of MAZE_FILE (S -> a -> ... -> G, avoiding walls), "
                                   "then measure the compositional policy end to end on the ORIGINAL task. The "
                                   "defaults are the paper's settings.")
    r.add_argument("maze", metavar="MAZE_FILE",
                   help="a .maze file, the name of one in data/mazes/, or gr:NAME: a Gymnasium-Robotics map "
                        "(gr:U_MAZE, gr:MEDIUM_MAZE, gr:LARGE_MAZE, gr:LARGE_MAZE_DIVERSE_G, ...)")
    add_run_options(r, types={"proposer": proposer_arg})
    r.add_argument("--out", type=out_path, default=Path("runs/latest"),
                   help="output directory for result.json, pictures, the step log and the evaluation cache")
    r.add_argument("--quiet", action="store_true",
                   help="no live progress line on stderr (shown only when stderr is a terminal anyway)")
    o = sub.add_parser("official", help="run a finished run's compositional policy in the official "
                                         "Gymnasium-Robotics environment (PointMaze-v3 / AntMaze-v5)",
                       description="Run RUN_DIR's compositional policy (RUN_DIR/policy.json) in the official "
                                   "Gymnasium-Robotics environment built from the run's maze, judge the ORIGINAL "
                                   "task with this package's monitor, write RUN_DIR/official.json.")
    o.add_argument("run_dir", metavar="RUN_DIR", type=Path, help="a finished 'specrefine refine' output folder")
    o.add_argument("--episodes", type=bounded_int("episodes"), default=DEFAULTS.episodes,
                   help=f"episodes (default: {DEFAULTS.episodes})")
    o.add_argument("--seed", type=bounded_int("seed"), default=0, help="random seed of the episodes (default: 0)")
    o.add_argument("--start", choices=RESET_RULES, default="official",
                   help="where an episode starts: the environment's reset (official, the default) or this "
                        "package's spawn rule (uniform in S, clear of walls), to isolate a gap")
    o.add_argument("--reset-noise", choices=RESET_RULES, default="official",
                   help="the environment's reset noise (official, the default; none for AntMaze) or this "
                        "package's (the Ant's qpos +-0.1, qvel 0.1 N(0,1))")
    o.add_argument("--out", type=out_path, default=None, help="where to write the result (default: "
                                                              "RUN_DIR/official.json)")
    from .runs import show

    show.add_arguments(sub.add_parser("show", help="a finished run at a glance: summary, path leg by leg, time, "
                                                   "pictures"))
    return parser


def _command(work, show, interrupted: str) -> int:
    """Run ``work()`` and print ``show(its result)``: bad input is one line and exit 2, Ctrl-C exit 130, and a
    closed pipe (``specrefine ... | head``) no traceback once the work is done and written."""
    try:
        result = work()
    except SpecrefineError as exc:
        print(f"specrefine: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"specrefine: interrupted; {interrupted}", file=sys.stderr)
        return 130
    try:
        print(show(result), flush=True)
    except BrokenPipeError:
        silence_stdout()
    return 0


def official(args) -> int:
    def work():
        from .runs.official import run_official

        return run_official(args.run_dir, episodes=args.episodes, seed=args.seed, start=args.start,
                            reset_noise=args.reset_noise, out=args.out)

    def show(data):
        from .runs.official import summary

        return summary(data) + f"\n  -> {args.out or args.run_dir / 'official.json'}"

    from .runs.official import partial_path

    kept = partial_path(args.out or args.run_dir / "official.json")
    return _command(work, show, f"the finished episodes are in {kept} (no official.json written)")


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    if args.command == "official":
        return official(args)
    if args.command == "show":
        from .runs.show import show

        return _command(lambda: show(args.run_dir), str, "nothing was written")

    def work():
        from .runs.pipeline import refine_maze  # heavy imports only after argument parsing

        return refine_maze(args.maze, RunConfig.from_namespace(args), out=args.out,
                           progress=False if args.quiet else None)

    return _command(work, lambda result: result.summary(), "evaluations so far are kept in the cache under --out")


if __name__ == "__main__":
    sys.exit(main())
