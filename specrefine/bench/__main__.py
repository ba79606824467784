"""``python -m specrefine.bench {evaluator,gymenv,train,refine} ...``: one benchmark, one JSON line on stdout."""

from __future__ import annotations

import json
import sys
import warnings
from pathlib import Path

from ..core.agents import AGENTS
from ..core.argtypes import bounded_int, out_path, positive_float
from ..core.errors import SpecrefineError
from ..runs.config import DEFAULTS, maze_problem, proposer_arg
from ..runs.methods import METHODS
from . import __doc__ as package_doc


def add_arguments(ap) -> None:
    ap.description = package_doc.splitlines()[0]
    sub = ap.add_subparsers(dest="what", required=True, metavar="{evaluator,gymenv,train,refine}")

    def bench(name, what):
        return sub.add_parser(name, help=what, description=what)

    e = bench("evaluator", "env steps/s of the subtask evaluator vs raw mujoco.rollout")
    e.add_argument("--agent", choices=list(AGENTS), default="point", help="the agent")
    e.add_argument("--batch", type=bounded_int("batch"), default=32, help="rollouts per batch")
    e.add_argument("--seconds", type=positive_float, default=6.0, help="time spent in the evaluator measurement")
    e.add_argument("--horizon", type=bounded_int("horizon"), default=None,
                   help="control steps per rollout (default: the agent's)")
    e.add_argument("--torch-threads", type=bounded_int("torch_threads"), default=1, help="PyTorch threads")
    e.add_argument("--nthread", type=bounded_int("nthread"), default=None,
                   help="mujoco.rollout threads (default: up to 2)")
    e.add_argument("--scenario", default="open",
                   help="'open' (open room, full-length rollouts) or a maze name (S -> G, early exits)")
    e.add_argument("--rounds", type=bounded_int("rounds"), default=3, help="measurement rounds")
    g = bench("gymenv", "the evaluator and TorchRL GymEnv around Gymnasium-Robotics, in one run")
    g.add_argument("--agent", choices=("point", "ant"), default="ant", help="the agent")
    g.add_argument("--batch", type=bounded_int("batch"), default=32, help="rollouts per batch")
    g.add_argument("--seconds", type=positive_float, default=9.0, help="time spent in the evaluator measurement")
    g.add_argument("--gym-steps", type=bounded_int("gym_steps"), default=2000, help="GymEnv steps measured")
    t = bench("train", "PPO training frames/s vs raw mujoco.rollout, and vs the reference TorchRL config")
    t.add_argument("--agent", choices=list(AGENTS), default="ant", help="the agent")
    t.add_argument("--batches", type=bounded_int("batches"), default=4, help="measured batches per configuration")
    t.add_argument("--no-reference", action="store_true",
                   help="skip the reference TorchRL config (minibatch 64) (default: run it too)")
    r = bench("refine", "a refinement run's cost: fixed vs adaptive evaluation, side by side")
    r.add_argument("--agent", choices=list(AGENTS), default="ant", help="the agent")
    r.add_argument("--mazes", nargs="+", default=["split_doorway", "u_maze", "u_chain_2"], help="mazes")
    r.add_argument("--seeds", nargs="+", type=bounded_int("seed"), default=[0, 1, 2], help="seeds")
    r.add_argument("--method", choices=list(METHODS), default="ours", help="the method")
    r.add_argument("--proposer", type=proposer_arg, default="geometric", help="the proposer")
    r.add_argument("--episodes", type=bounded_int("episodes"), default=DEFAULTS.episodes, help="episodes per run")
    r.add_argument("--table", type=out_path, default=None,
                   help="CSV the rows are appended to (and resumed from) (default: none)")


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("bench", argv, prog="python -m specrefine.bench")


def run(args, ap) -> int:
    if args.what == "refine":  # before seconds of Ant setup
        problem = maze_problem(args.mazes)
        if problem is None and args.table is not None and Path(args.table).is_dir():
            problem = f"--table {args.table}: is a folder: name a CSV file"
        if problem:
            ap.exit(2, f"{ap.prog}: error: {problem}\n")
    warnings.filterwarnings("ignore")
    from . import bench_evaluator, bench_gymenv, bench_refinement, bench_train

    try:
        if args.what == "evaluator":
            out = bench_evaluator(args.agent, args.batch, args.seconds, args.horizon, args.torch_threads, args.nthread,
                                  args.scenario, args.rounds)
        elif args.what == "gymenv":
            ev = bench_evaluator(args.agent, args.batch, args.seconds)
            gym = bench_gymenv(args.agent, args.gym_steps)
            out = {"evaluator": ev, "gymenv": gym}
            if "env_steps_per_s" in gym:
                out["evaluator_over_gymenv"] = round(ev["env_steps_per_s"] / gym["env_steps_per_s"], 2)
            out["evaluator_over_raw_rollout"] = ev["ratio_vs_raw_rollout"]
        elif args.what == "refine":
            out = bench_refinement(args.mazes, args.seeds, args.agent, args.method, args.proposer, args.table,
                                   args.episodes)
        else:
            out = bench_train(args.agent, args.batches, not args.no_reference)
    except SpecrefineError as exc:
        ap.exit(2, f"{ap.prog}: error: {exc}\n")
    print(json.dumps(out), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
