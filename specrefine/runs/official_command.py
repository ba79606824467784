"""``specrefine official``: a finished run's compositional policy in the official Gymnasium-Robotics environment."""

from __future__ import annotations

import sys
from pathlib import Path

from ..core.argtypes import bounded_int, out_path, silence_stdout
from .config import DEFAULTS

RESET_RULES = ("official", "package")  # as runs.official.RESET_RULES (not imported: it pulls in gymnasium)


def add_arguments(parser) -> None:
    parser.description = ("Run RUN_DIR's compositional policy (RUN_DIR/policy.json) in the official "
                          "Gymnasium-Robotics environment built from the run's maze, judge the ORIGINAL task with "
                          "this package's monitor, write RUN_DIR/official.json.")
    parser.add_argument("run_dir", metavar="RUN_DIR", type=Path, help="a finished 'specrefine refine' output folder")
    parser.add_argument("--episodes", type=bounded_int("episodes"), default=DEFAULTS.episodes, help="episodes")
    parser.add_argument("--seed", type=bounded_int("seed"), default=0, help="random seed of the episodes")
    parser.add_argument("--start", choices=RESET_RULES, default="official",
                        help="where an episode starts: the environment's reset (official) or this package's spawn "
                             "rule (uniform in S, clear of walls), to isolate a gap")
    parser.add_argument("--reset-noise", choices=RESET_RULES, default="official",
                        help="the environment's reset noise (official; none for AntMaze) or this package's (the "
                             "Ant's qpos +-0.1, qvel 0.1 N(0,1))")
    parser.add_argument("--out", type=out_path, default=None,
                        help="where to write the result (default: RUN_DIR/official.json)")


def run(args, parser) -> int:
    from ..core.errors import SpecrefineError
    from .official import partial_path, run_official, summary

    target = args.out or args.run_dir / "official.json"
    try:
        data = run_official(args.run_dir, episodes=args.episodes, seed=args.seed, start=args.start,
                            reset_noise=args.reset_noise, out=args.out)
    except SpecrefineError as exc:
        print(f"specrefine: error: {exc}", file=sys.stderr)  # the prefix scripts know
        return 2
    except KeyboardInterrupt:
        print(f"specrefine: interrupted; the finished episodes are in {partial_path(target)} "
              "(no official.json written)", file=sys.stderr)
        return 130
    try:
        print(summary(data) + f"\n  -> {target}", flush=True)
    except BrokenPipeError:
        silence_stdout()
    return 0
