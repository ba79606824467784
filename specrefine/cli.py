"""The ``specrefine`` command line.

    specrefine refine MAZE_FILE --agent {point,ant} --method {ours,vlm-oneshot,symbolic,dirl}
        --proposer {geometric,random,imperfect:PRESET,replay:PATH,litellm:MODEL} --seed N --out DIR [--spec EXPR]
    specrefine official RUN_DIR [--episodes N] [--seed S]

Bad input exits 2 with one line on stderr; never a traceback.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .agents import AGENTS as _AGENT_REGISTRY
from .argtypes import OneLineParser, bounded_int, out_path, proposer_arg, silence_stdout
from .errors import SpecrefineError
from .pipeline import METHODS

AGENTS = tuple(_AGENT_REGISTRY)


_OneLineParser = OneLineParser  # the name other modules and tests know


def build_parser() -> argparse.ArgumentParser:
    parser = _OneLineParser(prog="specrefine", description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    r = sub.add_parser("refine", help="refine a maze task's specification and measure the resulting policy",
                       description="Refine the task graph of MAZE_FILE (S -> a -> ... -> G, avoiding walls), "
                                   "then measure the compositional policy end to end on the ORIGINAL task.")
    r.add_argument("maze", metavar="MAZE_FILE",
                   help="a .maze file, the name of one in data/mazes/, or gr:NAME: a Gymnasium-Robotics map "
                        "(gr:U_MAZE, gr:MEDIUM_MAZE, gr:LARGE_MAZE, gr:LARGE_MAZE_DIVERSE_G, ...)")
    r.add_argument("--agent", choices=AGENTS, default="point",
                   help="point: fast point mass, 1 m cells; ant: MuJoCo Ant, 4 m cells (default: point)")
    r.add_argument("--method", choices=list(METHODS), default="ours",
                   help="; ".join(f"{m}: {what}" for m, (_, what) in METHODS.items()) + " (default: ours)")
    r.add_argument("--proposer", type=proposer_arg, default="geometric",
                   help="who proposes edge splits: geometric (offline shortest-path waypoints, NOT a VLM), "
                        "random (random free-space waypoints, ablation), imperfect:PRESET or imperfect:key=value,... "
                        "(VLM-like error model, offline, NOT a VLM; presets mild, moderate, severe), "
                        "replay:PATH (recorded VLM replies), "
                        "litellm:MODEL (any LiteLLM model, e.g. litellm:gpt-4o, litellm:gemini/gemini-2.0-flash; "
                        "keys from the environment) (default: geometric)")
    r.add_argument("--spec", metavar="EXPR", default=None,
                   help="the task as an expression over the maze's letters: a..z its subgoal regions, G the goal, "
                        "S implicit; '->' sequence, '|' choice (binds tighter), parentheses; must end in G; e.g. "
                        "'(a | b) -> c -> G' (default: the maze's '; spec:' line, else its chain a -> b -> ... -> G)")
    r.add_argument("--seed", type=bounded_int("seed"), default=0,
                   help="random seed for rollouts and proposers (default: 0)")
    r.add_argument("--out", type=out_path, default=Path("runs/latest"),
                   help="output directory for result.json, pictures, the step log and the evaluation cache")
    r.add_argument("--rollouts", type=bounded_int("rollouts"), default=32,
                   help="rollouts per subtask evaluation (paper: 32)")
    r.add_argument("--episodes", type=bounded_int("episodes"), default=200,
                   help="fresh end-to-end episodes to measure the final policy on the original task")
    r.add_argument("--policy", type=Path, default=None,
                   help="policy checkpoint (default: the shipped data/policies/AGENT.pt)")
    r.add_argument("-w", type=bounded_int("w"), default=3,
                   help="candidate edge splits per VLM query (paper: 3; at most 20)")
    r.add_argument("-d", type=bounded_int("d"), default=2,
                   help="VLM query rounds per edge split (paper: 2; at most 10)")
    r.add_argument("-k", type=bounded_int("k"), default=5,
                   help="subsets sampled per vertex refinement (paper: 5; at most 100)")
    r.add_argument("--evaluation", choices=["fixed", "adaptive"], default=None,
                   help="fixed: every subtask estimate on --rollouts rollouts (the paper); adaptive: the vertex "
                        "refinement's candidates in stages, stopping those that cannot be chosen (same full "
                        "budget for what is chosen; far fewer simulator steps) (default: fixed for point, "
                        "adaptive for ant)")
    o = sub.add_parser("official", help="run a finished run's compositional policy in the official "
                                         "Gymnasium-Robotics environment (PointMaze-v3 / AntMaze-v5)",
                       description="Run RUN_DIR's compositional policy (RUN_DIR/policy.json) in the official "
                                   "Gymnasium-Robotics environment built from the run's maze, judge the ORIGINAL "
                                   "task with this package's monitor, write RUN_DIR/official.json.")
    o.add_argument("run_dir", metavar="RUN_DIR", type=Path, help="a finished 'specrefine refine' output folder")
    o.add_argument("--episodes", type=bounded_int("episodes"), default=200, help="episodes (default: 200)")
    o.add_argument("--seed", type=bounded_int("seed"), default=0, help="random seed of the episodes (default: 0)")
    return parser


def official(args) -> int:
    try:
        from .official import run_official, summary

        data = run_official(args.run_dir, episodes=args.episodes, seed=args.seed)
    except SpecrefineError as exc:
        print(f"specrefine: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("specrefine: interrupted; nothing written", file=sys.stderr)
        return 130
    try:
        print(summary(data) + f"\n  -> {args.run_dir / 'official.json'}", flush=True)
    except BrokenPipeError:
        silence_stdout()
    return 0


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    if args.command == "official":
        return official(args)
    try:
        from .pipeline import refine_maze  # heavy imports only after argument parsing

        result = refine_maze(args.maze, agent=args.agent, method=args.method, proposer=args.proposer,
                             seed=args.seed, out=args.out, rollouts=args.rollouts, episodes=args.episodes,
                             policy_path=args.policy, w=args.w, d=args.d, k=args.k, spec=args.spec,
                             evaluation=args.evaluation)
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
