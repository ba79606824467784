"""Where a point-mass run's episodes are lost at the paper's sampled goal points, and the same found paths aimed at
their regions' centres (docs/corrector.md, "Aimed at the centre"; exploration that informed grid corrector-centre).

    python -m specrefine.experiments.aim_check runs/corrector_polish --proposer imperfect:moderate \\
        --mazes u_chain_4 u_chain_4_subgoals u_chain_5 u_chain_5_subgoals --out data/results/corrector/diagnosis/aim.md

From each run folder (its ``result.json``): how its measured episodes ended, and each leg's measured loss by the
radius of the disc it enters. Then each found path is run again on ``--episodes`` fresh episodes twice, once aiming
as the run did (a point drawn in the goal region per rollout) and once at every region's centre; of the first, how
far outside its leg's goal region a timed-out episode ended. Offline proposers only: NOT a VLM.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..core.argtypes import OneLineParser, exit_code_quiet_on_broken_pipe
from ..core.errors import SpecrefineError
from ..core.graph import TaskGraph
from ..core.results import TIMEOUT
from ..core.runfolder import output_file, write_atomic, writing_into
from .taxonomy import read_runs

RADII = (0.2, 0.3, 0.45)  # m: the disc-radius bins of the per-leg loss (below each, then the rest)
SEED = 4242  # the re-measurement's episode seed


def runs(sweep: Path, proposer: str, mazes: list[str]) -> list[dict]:
    """The ``result.json`` of every finished point-mass run of the sweep folder (its ``cells/``) with that proposer
    and one of ``mazes``, in order (``taxonomy.read_runs``: each checked as it is read)."""
    out = [run.result for run in read_runs([sweep]) if run.result.get("agent") == "point"
           and run.result.get("proposer") == proposer and run.result.get("maze") in mazes]
    if not out:
        raise SpecrefineError(f"{sweep}: no point-mass run folder with proposer {proposer} on {', '.join(mazes)}")
    return out


def leg_losses(data: dict) -> list[tuple[float | None, float]]:
    """(radius of the disc a leg enters, or None for another region; the leg's measured loss) for each leg."""
    graph = TaskGraph.from_dict(data["graph"])
    out = []
    for v, p in zip(data["path"][1:], data["leg_success"]):
        if p is not None:
            out.append((getattr(graph.region(v), "r", None), 1.0 - p))
    return out


def radius_bins(losses) -> list[dict]:
    edges = (0.0, *RADII, np.inf)
    rows = []
    for lo, hi in zip(edges, edges[1:]):
        here = [loss for r, loss in losses if r is not None and lo <= r < hi]
        rows.append({"radius": f"{lo:g}-{hi:g} m" if np.isfinite(hi) else f">= {lo:g} m", "legs": len(here),
                     "loss": float(np.mean(here)) if here else float("nan")})
    return rows


def remeasure(data: dict, policy, episodes: int) -> dict:
    """The found path on ``episodes`` fresh episodes aimed both ways; the timed-out episodes' gaps to their region."""
    from ..core.mazes import load_maze
    from ..evaluation.evaluator import Evaluator

    graph, path = TaskGraph.from_dict(data["graph"]), data["path"]
    maze = load_maze(data["maze"])
    out = {}
    for rule in ("sampled", "centre"):
        res = Evaluator(maze, "point", policy, goal_points=rule).run_graph_path(graph, path, n=episodes, seed=SEED)
        out[rule] = {"successes": res.successes, "counts": res.counts()}
        if rule == "sampled":
            late = np.flatnonzero(res.outcome == TIMEOUT)
            ends = [res.trajectories[e, res.lengths[e] - 1] for e in late]
            out["gaps"] = [float(graph.region(path[res.legs_done[e] + 1]).signed_distance(end[None])[0])
                           for e, end in zip(late, ends)]
    return out


def stop_offset(policy, n: int = 64) -> list[float]:
    """How far from the point it aims at the point mass comes to rest: the shipped policy on an open floor, each of
    ``n`` rollouts aiming at one fixed point for a whole horizon (its goal region is out of reach), per point."""
    from ..core.mazes import Maze
    from ..core.regions import Disc
    from ..evaluation.evaluator import Evaluator

    room = [[1] * 9, [1, "r", *[0] * 6, 1], *([1, *[0] * 7, 1] for _ in range(5)), [*[1] * 7, "g", 1], [1] * 9]
    maze = Maze.from_gymnasium(room, name="open_floor")
    ev = Evaluator(maze, "point", policy)
    out = []
    for point in ((1.0, 0.0), (1.5, 0.5), (2.0, -1.0), (0.3, 0.3)):
        res = ev.run_compositional(Disc(0.0, 0.0, 0.3), [(Disc(50.0, 50.0, 0.01), maze.obstacles, point)], n=n,
                                   seed=SEED)
        ends = res.trajectories[np.arange(n), res.lengths - 1]
        out.append(float(np.median(np.linalg.norm(ends - np.asarray(point), axis=1))))
    return out


def check(data_runs: list[dict], episodes: int) -> dict:
    from ..sim.policy import load_policy

    policy = load_policy("point")
    lost = {k: 0 for k in ("avoid", "flipped", "timeout")}
    for d in data_runs:
        for k in lost:
            lost[k] += d["episode_outcomes"].get(k, 0)
    per_run = []
    for d in data_runs:
        again = remeasure(d, policy, episodes)
        per_run.append({"maze": d["maze"], "seed": d["seed"], "legs": len(d["path"]) - 1,
                        "success": d["success_rate"], "episodes": d["episodes"], **again})
    gaps = [g for r in per_run for g in r["gaps"]]
    return {"runs": len(data_runs), "lost": lost, "bins": radius_bins([x for d in data_runs for x in leg_losses(d)]),
            "per_run": per_run, "gaps": gaps, "episodes": episodes,
            "stop_offset": stop_offset(policy)}


def markdown(c: dict, proposer: str) -> str:
    lost = c["lost"]
    gaps = np.array(c["gaps"])
    lines = [f"Point mass, `{proposer}` (offline, NOT a VLM), {c['runs']} runs; the paper's sampled goal points.", "",
             f"**Lost episodes** (each run's 200): {sum(lost.values())}, of which {lost['timeout']} timed out, "
             f"{lost['avoid']} touched a wall, {lost['flipped']} flipped.", "",
             "**Measured loss per leg by the radius of the disc it enters** (mean over legs):", "",
             "| disc radius | legs | loss per leg |", "|---|---|---|"]
    lines += [f"| {b['radius']} | {b['legs']} | {b['loss'] * 100:.2f} % |" for b in c["bins"]]
    if len(gaps):
        cm = {"median": np.median(gaps) * 100, "p90": np.quantile(gaps, 0.9) * 100, "max": gaps.max() * 100}
        lines += ["", f"**Timed-out episodes of the re-measurement** ({len(gaps)}): they ended outside their leg's "
                  f"goal region by a median of {cm['median'] * 10:.1f} mm (90 % within {cm['p90'] * 10:.1f} mm; "
                  f"largest {cm['max'] * 10:.1f} mm)."]
    lines += ["", "**Where the policy comes to rest** (open floor, one fixed point per rollout for a whole horizon, 64 "
              "rollouts per point, medians): " + ", ".join(f"{d * 1000:.1f} mm" for d in c["stop_offset"])
              + " from the point it aims at. A point drawn in the goal region closer to its edge than that, on the "
              "side the agent stops, leaves it outside the region for good: the leg times out."]
    lines += ["", f"**The same found paths on {c['episodes']} fresh episodes each** (seed {SEED}), aimed as they were "
              "chosen (sampled) and at every region's centre:", "",
              "| maze | seed | legs | measured (run) | sampled | ended (sampled) | centre | ended (centre) |",
              "|---|---|---|---|---|---|---|---|"]
    for r in c["per_run"]:
        n = c["episodes"]
        lines.append(f"| {r['maze']} | {r['seed']} | {r['legs']} | {r['success']:.3f} | "
                     f"{r['sampled']['successes'] / n:.3f} | {_counts(r['sampled']['counts'])} | "
                     f"{r['centre']['successes'] / n:.3f} | {_counts(r['centre']['counts'])} |")
    return "\n".join(lines) + "\n"


def _counts(counts: dict) -> str:
    return ", ".join(f"{k} {v}" for k, v in counts.items())


def main(argv=None) -> int:
    p = OneLineParser(prog="python -m specrefine.experiments.aim_check", description=__doc__.split("\n")[0])
    p.add_argument("sweep", type=Path, help="a sweep folder (its cells/, one run folder per cell)")
    p.add_argument("--proposer", default="imperfect:moderate")
    p.add_argument("--mazes", nargs="+", default=["u_chain_4", "u_chain_4_subgoals", "u_chain_5", "u_chain_5_subgoals"])
    p.add_argument("--episodes", type=int, default=1000)
    p.add_argument("--out", type=Path, required=True)
    args = p.parse_args(argv)
    if args.episodes < 1:
        p.error("--episodes must be >= 1")
    try:
        with writing_into(args.out) as out:  # both files checked before any work
            data = output_file(out.with_suffix(".json"))
            result = check(runs(args.sweep, args.proposer, args.mazes), args.episodes)
            write_atomic(out, markdown(result, args.proposer))
            write_atomic(data, json.dumps(result, indent=1, default=float) + "\n")
    except (SpecrefineError, OSError) as exc:
        p.exit(2, f"{p.prog}: error: {exc}\n")
    print(f"-> {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
