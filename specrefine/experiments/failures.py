"""Where a refined path loses its episodes: per leg, how many fail and how, with and without the inner walls.

A long chain of subtasks fails when any leg fails, so an end-to-end rate below the goal says little by
itself.  This re-runs a finished run's selected path (its ``result.json``) on fresh episodes and counts,
for every leg, the episodes that ended there (flipped, touched the avoid set, ran out of time), with the
turn the agent makes where the leg starts.  Run again on the same maze with every inner wall removed
(same coordinates, outer wall kept), the comparison separates failures the walls cause (a leg caught
on a corner) from failures of the policy on open floor (a flip in a sharp turn)::

    python -m specrefine.experiments.failures runs/X/result.json --episodes 300 --seed 77 --out failures.json

``--estimates SEED ...`` instead estimates every leg of the path again as the search does (the run's rollouts per
subtask, each leg started from the end states of the previous leg's successes), once per seed, beside the search's
own estimates and the measured per-leg success: how far the estimates the search chose the path on are from fresh
ones (a path picked as the best of many noisy estimates looks better to the search than it is)::

    python -m specrefine.experiments.failures runs/X/result.json --estimates 101 202 303 --out estimates.json
"""

from __future__ import annotations

import json
import sys
from collections import Counter
from contextlib import nullcontext
from dataclasses import replace

import numpy as np

from ..core.errors import SpecrefineError
from ..core.paper import PAPER
from ..core.results import OUTCOMES


def open_floor(maze):
    """The maze with every wall cell off the border made free (same grid, same coordinates)."""
    last_r, last_c = maze.rows - 1, maze.cols - 1
    grid = tuple("".join("." if ch == "#" and 0 < r < last_r and 0 < c < last_c else ch for c, ch in enumerate(row))
                 for r, row in enumerate(maze.grid))
    return replace(maze, name=f"{maze.name}_open", grid=grid)


def turn_angles(points) -> list[float | None]:
    """Degrees the path turns where each leg starts (None for the first leg)."""
    p = np.asarray(points, dtype=float)
    out: list[float | None] = [None]
    for k in range(1, len(p) - 1):
        a, b = p[k] - p[k - 1], p[k + 1] - p[k]
        out.append(float(np.degrees(np.arctan2(abs(a[0] * b[1] - a[1] * b[0]), a @ b))))
    return out


def path_aims(graph, path: list[str]) -> list:
    """Where each vertex of ``path`` is aimed at when its set's centre stands for it: its fixed point, else the
    centre (the start vertex's centre is where its legs come from on average)."""
    return [graph.goal_point(v) if graph.goal_point(v) is not None else graph.region(v).centre() for v in path]


def leg_table(run, n_legs: int) -> list[dict]:
    """Per leg: episodes that started it and how the ones that ended on it ended (CompositionalResult)."""
    rows = []
    for k in range(n_legs):
        started = int((run.legs_done >= k).sum())
        ended = Counter(OUTCOMES[o] for o in run.outcome[(run.legs_done == k) & ~run.success].tolist())
        rows.append({"leg": k, "started": started, **{o: ended.get(o, 0) for o in ("flipped", "avoid", "timeout")}})
    return rows


def path_failures(result: dict, episodes: int, seed: int, policy=None, goal_points: str | None = None,
                  switching: str | None = None, walls_only: bool = False) -> dict:
    """Re-run ``result``'s selected path twice (as built, and with the inner walls removed): per-leg failures.

    ``goal_points``: "sampled" (the paper's rule: each episode aims at a point drawn from the goal vertex's set) or
    "centre" (each leg aims at the centre of its goal vertex's set) or "clear" (``Evaluator.clearest``; both beyond
    the paper); None: as the run measured
    it (its configuration's ``goal_points``).  ``switching``: the switching rule (``sim.switching``); None: the
    run's own.  ``walls_only``: the run with the walls alone (no ``no_inner_walls`` entry)."""
    from ..evaluation.evaluator import Evaluator

    exp, graph, path, legs = _path_setup(result, seed, policy, goal_points, switching)
    agent, goal_points, switching = result["agent"], exp.evaluator.goal_points, exp.evaluator.switching
    start = graph.region(path[0])
    centres = path_aims(graph, path)
    turns = turn_angles(centres)
    lengths = [float(np.linalg.norm(np.subtract(centres[k + 1], centres[k]))) for k in range(len(legs))]
    out = {"maze": exp.maze.name, "agent": agent, "seed": seed, "episodes": episodes, "policy": exp.policy_name,
           "goal_points": goal_points, "switching": switching,
           "legs": [{"leg": k, "from": path[k], "to": path[k + 1], "turn_deg": turns[k], "length_m": lengths[k]}
                    for k in range(len(legs))]}
    bare = open_floor(exp.maze)
    variants = {"walls": (exp.evaluator, legs),
                "no_inner_walls": (Evaluator(bare, agent, exp.policy, n=exp.evaluator.n, seed=seed,
                                             goal_points=goal_points, switching=switching),
                                   [(goal, bare.walls, point) for goal, _avoid, point in legs])}
    if walls_only:
        del variants["no_inner_walls"]
    for name, (evaluator, variant_legs) in variants.items():
        run = evaluator.run_compositional(start, variant_legs, n=episodes, seed=seed)
        counts = Counter(OUTCOMES[o] for o in run.outcome.tolist())
        out[name] = {"success": run.successes, "rate": run.p, "ci": list(run.ci), "outcomes": dict(counts),
                     "per_leg": leg_table(run, len(legs))}
    return out


def _path_setup(result: dict, seed: int, policy, goal_points: str | None, switching: str | None = None):
    """(experiment, graph, path, legs) of ``result``'s selected path, run as it was measured unless told."""
    from ..core.graph import TaskGraph
    from ..core.tables import goal_points_of
    from ..evaluation.evaluator import path_legs
    from ..runs.experiment import setup

    if not isinstance(result, dict) or not result.get("path") or "graph" not in result:
        raise SpecrefineError("the result has no selected path to re-run (no 'path' or 'graph')")
    if goal_points is None:
        goal_points = goal_points_of(result.get("config") or {})
    if switching is None:
        switching = (result.get("config") or {}).get("switching") or "at-region"
    if policy is None:  # the run's own (a run from before the config was recorded: the shipped one)
        policy = (result.get("config") or {}).get("policy") or "shipped"
    rollouts = int((result.get("config") or {}).get("rollouts") or result.get("rollouts_per_evaluation")
                   or PAPER.rollouts)
    exp = setup(result["maze"], agent=result["agent"], seed=seed, policy=policy, goal_points=goal_points,
                rollouts=rollouts, switching=switching)
    try:
        graph = TaskGraph.from_dict(result["graph"])
        path, legs = result["path"], path_legs(graph, result["path"])
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise SpecrefineError(f"the result's graph or path is malformed ({type(exc).__name__}: {exc})") from None
    return exp, graph, path, legs


def leg_estimates(result: dict, seeds, policy=None, goal_points: str | None = None) -> dict:
    """Every leg of ``result``'s path estimated again along the chain, once per seed (see the module docstring)."""
    from ..refine.common import Leg, estimate_legs
    from ..refine.polish import Rollouts

    exp, graph, path, legs = _path_setup(result, seeds[0], policy, goal_points)
    chain = [Leg(goal, avoid, point) for goal, avoid, point in legs]
    fresh = [[r.p for r in estimate_legs(Rollouts(exp.evaluator, exp.evaluator.n, seed), graph.region(path[0]),
                                         chain).results] for seed in seeds]
    return {"maze": exp.maze.name, "agent": result["agent"], "policy": exp.policy_name,
            "goal_points": exp.evaluator.goal_points, "rollouts": exp.evaluator.n, "seeds": list(seeds),
            "search": result.get("edge_probabilities"), "measured": result.get("leg_success"), "fresh": fresh}


def estimates_summary(report: dict) -> str:
    lines = [f"{report['maze']} ({report['agent']}): each leg's estimate on {report['rollouts']} rollouts along the "
             f"chain; search = the run's own, measured = among the run's episodes that started the leg",
             "  leg  search  measured  " + "  ".join(f"seed {s}" for s in report["seeds"])]
    def cell(values, k: int, width: int) -> str:
        return f"{values[k]:>{width}.2f}" if values and k < len(values) else " " * (width - 1) + "-"

    widths = [len(f"seed {s}") for s in report["seeds"]]
    for k in range(len(report["fresh"][0])):
        lines.append(f"  {k:3d}  {cell(report['search'], k, 6)}  {cell(report['measured'], k, 8)}  " +
                     "  ".join(cell(run, k, w) for run, w in zip(report["fresh"], widths)))
    return "\n".join(lines)


def summary(report: dict) -> str:
    lines = [f"{report['maze']} ({report['agent']}, {report['episodes']} episodes, seed {report['seed']}):"]
    variants = [name for name in ("walls", "no_inner_walls") if name in report]
    for name in variants:
        r = report[name]
        lo, hi = r["ci"]
        lines.append(f"  {name:15s} success {r['rate']:.3f} [{lo:.3f}, {hi:.3f}]  outcomes {r['outcomes']}")
    lines.append("  leg  turn  length  failures " + ("with walls / without" if len(variants) == 2 else "with walls")
                 + " (flipped+avoid+timeout)")
    for k, leg in enumerate(report["legs"]):
        cells = []
        for name in variants:
            a = report[name]["per_leg"][k]
            cells.append(f"{a['flipped'] + a['avoid'] + a['timeout']:3d} ({a['flipped']}+{a['avoid']}+{a['timeout']})")
        turn = "   -" if leg["turn_deg"] is None else f"{leg['turn_deg']:4.0f}"
        lines.append(f"  {leg['leg']:3d}  {turn}  {leg['length_m']:5.1f}   {' / '.join(cells)}")
    return "\n".join(lines)


def add_arguments(p) -> None:
    from ..core.argtypes import bounded_int, out_path, result_file
    from ..evaluation.evaluator import GOAL_POINTS
    from ..sim.switching import SWITCHING

    p.description = __doc__.split("\n\n")[0]
    p.add_argument("result", type=result_file,
                   help="a run's folder or its result.json (the maze is rebuilt from the folder's run.json)")
    p.add_argument("--episodes", type=bounded_int("episodes"), default=300)
    p.add_argument("--seed", type=bounded_int("seed"), default=77,
                   help="seed of the fresh episodes (not the run's own)")
    p.add_argument("--policy", default=None, help="'shipped' (data/policies/AGENT.pt), a shipped one's name or a "
                                                  "policy checkpoint (default: the run's own)")
    p.add_argument("--goal-points", choices=GOAL_POINTS, default=None,
                   help="sampled: each episode aims at a point drawn from the goal vertex's set (the paper's rule); "
                        "centre: at the set's centre; clear: at its point nearest the centre among those as clear of "
                        "walls as it allows, up to half a cell (both beyond the paper) "
                        "(default: as the run measured it)")
    p.add_argument("--switching", choices=SWITCHING, default=None,
                   help="at-region: the next goal point as soon as a goal region is entered (the paper's rule); "
                        "slow-turn: a leg that starts fast and turned away from its goal brakes first (beyond the "
                        "paper) (default: as the run measured it)")
    p.add_argument("--walls-only", action="store_true",
                   help="re-run the path with its walls only, not again with the inner walls removed")
    p.add_argument("--estimates", type=bounded_int("seed"), nargs="+", default=None, metavar="SEED",
                   help="instead of re-running episodes: estimate every leg again along the chain, once per seed "
                        "(default: none: re-run episodes)")
    p.add_argument("--out", type=out_path, default=None, help="write the report here as JSON (default: printed only)")


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("failures", argv, prog="python -m specrefine.experiments.failures")


def run(args, p) -> int:
    from ..core.runfolder import read_result, recorded_maze, writable_parent, write_atomic, writing_into

    try:
        out = None if args.out is None else writable_parent(args.out)  # before the re-run, not after it
        result = read_result(args.result)
        with nullcontext() if out is None else writing_into(out):  # into a run folder: under its lock
            maze = recorded_maze(args.result, result["maze"])
            if args.estimates:
                report = leg_estimates({**result, "maze": maze}, args.estimates, args.policy, args.goal_points)
            else:
                report = path_failures({**result, "maze": maze}, args.episodes, args.seed, args.policy,
                                       args.goal_points, args.switching, args.walls_only)
            if args.out is not None:
                write_atomic(args.out, json.dumps(report, indent=1) + "\n")
    except SpecrefineError as e:
        print(f"{p.prog}: error: {e}", file=sys.stderr)
        return 2
    print(estimates_summary(report) if args.estimates else summary(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
