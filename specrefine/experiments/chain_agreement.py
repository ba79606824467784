"""Does a chained estimate of a path agree with whole episodes of it? One row per finished run (issue 39).

    specrefine chain-agreement runs/ant_corrector_redraw/cells/CELL --legs 8 --n 1000 --out DIR

The search and the correction judge a path by a chained estimate: each leg simulated on its own from the end states
of the previous leg's successful rollouts, the path's success the product of the legs'. The run's success is
measured on whole episodes, every leg in one go. With the same policy, physics and goal points the two estimate the
same probability; this command checks it on a run's found path (its ``policy.json``: legs, goal points, goal policy,
horizon, switching rule), from the start region of its ``result.json``, on ``--n`` fresh rollouts each way (apart
seeds). A gap between a run's last check and its measured success that this check does not show is the selection's
(the check chose the path on its own rollouts), not the estimator's.

Each row: the legs compared (``--legs``: the path's first K, else all), each leg's successes in the chain, the
chain's product, the episodes' successes and where each lost episode stopped, and the difference chain - episodes
with a Newcombe 95 % interval that counts the chain's product as that share of ``--n`` (an approximation: with a
deterministic policy and physics a chain of n rollouts is close to n episodes, each leg's start states spread over
the previous leg's successes, ``evaluator.spread_draw``). Writes ``agreement.csv`` and ``agreement.md``; without
``--out`` prints the table. Simulates about twice the path's legs times ``--n`` rollouts per run.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..core.errors import SpecrefineError
from ..core.records import read_result
from ..core.results import newcombe_ci, wilson_ci
from ..core.runfolder import ensure_dir, locked, write_atomic
from ..core.tables import csv_text

COLUMNS = ("run", "maze", "agent", "method", "proposer", "seed", "legs", "n", "chain_successes", "chain_p",
           "episode_successes", "episode_p", "episode_ci_low", "episode_ci_high", "episode_lost_at", "difference",
           "difference_ci_low", "difference_ci_high", "verdict")
SEED = 20_261_202  # the chain's rollouts; the episodes' are SEED + 1: apart from every seed a run draws


def run_path(run_dir: Path, legs: int | None):
    """(result.json's data, the run's CompositionalPolicy, its start region, the legs compared) of a finished run."""
    from ..core.graph import TaskGraph
    from ..evaluation.compositional import CompositionalPolicy

    result = read_result(run_dir / "result.json")
    policy = CompositionalPolicy.load(run_dir)
    try:
        graph, path = TaskGraph.from_dict(result["graph"]), list(result["path"])
        start = graph.region(path[0])
    except (KeyError, TypeError, ValueError, AttributeError, IndexError) as exc:
        raise SpecrefineError(f"{run_dir}: result.json has no usable graph and path ({type(exc).__name__}: "
                              f"{exc})") from None
    if path[1:] != [leg.vertex for leg in policy.legs]:
        raise SpecrefineError(f"{run_dir}: policy.json's legs are not result.json's path: not one run's records")
    k = len(policy.legs) if legs is None else legs
    if not 1 <= k <= len(policy.legs):
        raise SpecrefineError(f"--legs {k}: the run's path has {len(policy.legs)} legs (give 1 to "
                              f"{len(policy.legs)})")
    return result, policy, start, policy.legs[:k]


def agreement(run_dir: Path, *, legs: int | None = None, n: int = 1000, seed: int = SEED) -> dict:
    """The row of one run (module doc): its path's first ``legs`` legs, chained and as whole episodes."""
    from ..core.paper import PAPER
    from ..evaluation.evaluator import Evaluator
    from ..refine.common import Leg, estimate_legs
    from ..runs.progress import counted

    result, policy, start, chosen = run_path(run_dir, legs)
    evaluator = Evaluator(policy.maze, policy.agent, policy.goal_policy, n=n, horizon=policy.horizon,
                          goal_points=result.get("goal_points", PAPER.goal_points), switching=policy.switching)
    chained = [Leg(leg.goal, leg.avoid, leg.point) for leg in chosen]
    chain = estimate_legs(evaluator, start, counted(chained, len(chained), f"{run_dir.name[:32]}: chained legs",
                                                    unit="leg"), seed=seed, n=n)
    episodes = evaluator.run_compositional(start, [(leg.goal, leg.avoid, leg.point) for leg in chosen], n=n,
                                           seed=seed + 1)
    chain_p = math.prod(r.p for r in chain.results)
    k_chain, k_eps = round(chain_p * n), int(episodes.successes)
    low, high = newcombe_ci(k_chain, n, k_eps, n)
    episode_ci = wilson_ci(k_eps, n)
    lost = np.bincount(episodes.legs_done[~episodes.success], minlength=len(chosen))[:len(chosen)]
    return {"run": run_dir.name, "maze": result.get("maze", ""), "agent": policy.agent,
            "method": result.get("method", ""), "proposer": result.get("proposer", ""), "seed": result.get("seed", ""),
            "legs": len(chosen), "n": n, "chain_successes": " ".join(str(r.successes) for r in chain.results),
            "chain_p": chain_p, "episode_successes": k_eps, "episode_p": k_eps / n,
            "episode_ci_low": episode_ci[0], "episode_ci_high": episode_ci[1],
            "episode_lost_at": " ".join(str(int(v)) for v in lost), "difference": chain_p - k_eps / n,
            "difference_ci_low": low, "difference_ci_high": high,
            "verdict": "chain above" if low > 0 else "chain below" if high < 0 else "agree"}


def markdown(rows: list[dict]) -> str:
    lines = ["Every proposer here is offline, NOT a VLM. Descriptive (no rule); `specrefine chain-agreement` "
             "(specrefine/experiments/chain_agreement.py) from the run folders: each run's found path (its first "
             "`legs` legs), chained leg by leg and as whole episodes, on `n` fresh rollouts each.", "",
             "| maze | method | proposer | seed | legs | n | chained | episodes (95 %) | chained - episodes (95 %) "
             "| verdict | episodes lost at leg |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['maze']} | {r['method']} | {r['proposer']} | {r['seed']} | {r['legs']} | {r['n']} | "
              f"{r['chain_p']:.3f} | {r['episode_p']:.3f} [{r['episode_ci_low']:.3f}, {r['episode_ci_high']:.3f}] | "
              f"{r['difference']:+.3f} [{r['difference_ci_low']:+.3f}, {r['difference_ci_high']:+.3f}] | "
              f"{r['verdict']} | {r['episode_lost_at']} |" for r in rows]
    lines += ["", "Chained successes per leg (of n, each leg from the previous one's successes):", ""]
    lines += [f"- {r['maze']} seed {r['seed']}: {r['chain_successes']}" for r in rows]
    return "\n".join(lines) + "\n"


def add_arguments(p) -> None:
    from ..core.argtypes import bounded_int, out_path

    p.description = __doc__.split("\n\n")[0]
    p.add_argument("runs", nargs="+", type=Path, help="finished run folders (each with result.json and policy.json)")
    p.add_argument("--legs", type=bounded_int("chain"), default=None,
                   help="compare the path's first LEGS legs (default: all of them)")
    p.add_argument("--n", type=bounded_int("rollouts"), default=1000, help="rollouts each way per run (default: 1000)")
    p.add_argument("--seed", type=bounded_int("seed"), default=SEED,
                   help=f"the chain's seed; the episodes' is one more (default: {SEED})")
    p.add_argument("--out", type=out_path, default=None,
                   help="folder for agreement.csv and agreement.md (default: the table printed only)")


def write_tables(out: Path, rows: list[dict]) -> None:
    with locked(ensure_dir(out)):
        write_atomic(out / "agreement.csv", csv_text(rows, COLUMNS))
        write_atomic(out / "agreement.md", markdown(rows))


def run(args, p) -> int:
    for run_dir in args.runs:  # every run's records checked before minutes of simulation
        run_path(run_dir, args.legs)
    rows = []
    for run_dir in args.runs:
        rows.append(agreement(run_dir, legs=args.legs, n=args.n, seed=args.seed))
        if args.out is not None:  # written after each run: an interrupted comparison keeps the runs it finished
            write_tables(args.out, rows)
    if args.out is None:
        print(markdown(rows), end="")
        return 0
    print(f"{len(rows)} run{'' if len(rows) == 1 else 's'} compared -> {args.out}/agreement.{{csv,md}}")
    return 0


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("chain-agreement", argv, prog="python -m specrefine.experiments.chain_agreement")


if __name__ == "__main__":
    raise SystemExit(main())
