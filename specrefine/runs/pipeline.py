"""One refinement run, end to end: maze -> task graph -> refine -> measure -> result.json.

``refine_maze`` is what ``specrefine refine`` runs.  The output policy is measured on
FRESH rollouts from the initial distribution (a seed disjoint from the search's), and
success is judged by the monitor of the ORIGINAL task graph, not the refined one.
The step log is appended as the search goes and evaluations are cached under ``out``,
so an interrupted run keeps what it computed and a rerun resumes from the cache.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..core.errors import SpecrefineError
from ..core.graph import check_refines
from ..core.paths import code_commit
from ..core.runfolder import replacing, write_atomic
from ..core.spec import maze_spec_text
from ..evaluation.compositional import save_run_policy
from ..evaluation.monitor import measure
from ..refine.search import EVALUATIONS, evaluator_counts
from .calibrate import predict
from .config import RunConfig, preset_text
from .methods import METHODS, PROPOSER_METHODS, get_method, run_search  # noqa: F401 (names other modules know)
from .progress import RunProgress
from .queries import candidate_picture, edge_query_builder  # noqa: F401 (notebooks 03 and 04 import them here)

MEASURE_SEED_OFFSET = 1_000_003  # final measurement never reuses the search's rollouts


@dataclass
class RunResult:
    data: dict
    out: Path

    def summary(self) -> str:
        """What the run found, the input task beside the refined one ("input 0.000 -> refined 1.000")."""
        d = self.data
        lo, hi = d["success_ci"]
        return (f"{d['maze']} [{d['spec']}] | {d['agent']} | method={d['method']} proposer={d['proposer']} "
                f"seed={d['seed']} preset={preset_text(d)}\n"
                f"  success on the original task: {_before(d, 'success_rate')}{d['success_rate']:.3f} "
                f"(95% CI {lo:.3f}-{hi:.3f}, {d['episodes']} episodes)\n"
                f"  estimated: {_before(d, 'estimate')}{d['search_estimate']:.3f} (the search's own); "
                f"predicted {d['predicted_success']:.3f} (95% CI {d['predicted_ci'][0]:.3f}-{d['predicted_ci'][1]:.3f},"
                f" held-out episodes)\n"
                f"  graph: {d['graph_vertices']} vertices, {d['graph_edges']} edges, path of {d['path_edges']} "
                f"subtasks; {_refinement_text(d)}\n"
                f"  {d['evaluations']} subtask evaluations, {d['sim_steps']} sim steps, "
                f"{d['proposer_calls']} proposer calls ({'VLM' if d['proposer_is_vlm'] else 'offline, not a VLM'}), "
                f"{d['wall_seconds']:.1f} s\n  -> {self.out / 'result.json'}")


def _before(d: dict, key: str, form: str = ".3f") -> str:
    """"input X -> refined " for a run that recorded its input task and refined it (else nothing)."""
    before = None if _unrefined(d) else d.get("input_task")  # absent in runs written before it was recorded
    return "" if before is None else f"input {before[key]:{form}} -> refined "


def _unrefined(d: dict) -> bool:
    return d.get("refinements", 0) == 0 and d.get("graph") == d.get("input_graph")


def _refinement_text(d: dict) -> str:
    """Whether the output graph is a refinement of the input, or the input itself (a method that refines nothing)."""
    if _unrefined(d):
        return f"the input graph itself ({d['method']} refined nothing)"
    if d["refines_input"]:
        return f"a refinement of the input (checked; refinements accepted: {d.get('refinements', 0)})"
    return "NOT a refinement of the input (checked: the method's graph breaks Theorem 4.1)"


def refine_maze(maze_path, config: RunConfig | None = None, *, out=Path("runs/latest"), evaluator=None,
                progress: bool | None = None, policy_path=None, **fields) -> RunResult:
    """Run ``config`` (default: the paper's :class:`~specrefine.runs.config.RunConfig`) on the maze ``maze_path``.

    Keywords named like RunConfig's fields change them (``refine_maze("u_maze", method="dirl", rollouts=8)``);
    ``policy_path`` is the ``policy`` field under its older name.  ``spec``: the task as an expression over the
    maze's letters (``specrefine.core.spec.parse_spec``, e.g. ``"(a | b) -> c -> G"``); None = the maze's own task (its
    ``; spec:`` line, else its chain).  ``evaluation``: "fixed" (every subtask estimate on ``rollouts`` rollouts,
    the paper's protocol) or "adaptive" (the chain DP by branch and bound with staged rollouts:
    :mod:`specrefine.refine.racing`); None, like ``goal_points`` and ``policy``: what ``preset`` decides (``best``:
    the agent's best measured settings; ``paper``: the paper's rules).  ``evaluator``: use this one instead of
    building one.  ``progress``: the live line on stderr (:mod:`specrefine.runs.progress`); None shows it when
    stderr is a terminal or in a notebook.

    ``out`` holds this run only (:mod:`specrefine.core.runfolder`): its arguments go to ``out/run.json``, a
    rerun with other arguments into it is refused, and so is a folder another live run is using.
    """
    from ..core.mazes import Maze, load_maze
    from ..core.runfolder import claim, write_record
    from ..core.spec import maze_task
    from .experiment import setup

    t0 = time.time()
    if policy_path is not None:
        fields["policy"] = str(policy_path)
    config = replace(config or RunConfig(), **fields)
    maze = maze_path if isinstance(maze_path, Maze) else load_maze(maze_path)
    maze_task(maze.for_agent(config.agent), config.spec)  # a bad agent or spec fails before the folder is touched
    config = config.resolved()
    proposer = config.proposer if get_method(config.method).asks_proposer else None
    args = {"maze": maze.name, "maze_grid": list(maze.grid), "maze_spec": maze.spec, **config.record()}
    if config.evaluation not in EVALUATIONS:
        raise SpecrefineError(f"--evaluation must be one of {', '.join(EVALUATIONS)}, got {config.evaluation!r}")
    with claim(out, args) as out:
        exp = setup(maze, agent=config.agent, proposer=proposer, seed=config.seed, rollouts=config.rollouts,
                    policy=config.policy, out=out, evaluator=evaluator, record_path=out / "vlm_recording.jsonl",
                    spec=config.spec, goal_points=config.goal_points, switching=config.switching)
        write_record(out, args)  # only once every argument proved usable: a refused run leaves no record
        with RunProgress(exp.evaluator, exp.proposer, enabled=progress) as shown:
            return _refine(exp, config, out, t0, shown)


def _refine(exp, config: RunConfig, out: Path, t0: float, shown: RunProgress) -> RunResult:
    maze, original, evaluator = exp.maze, exp.graph, exp.evaluator
    seed, episodes = config.seed, config.episodes
    # the step log goes to a temporary file that replaces steps.jsonl only once the run is measured: a rerun into
    # a finished folder, killed at any moment, leaves the finished run's steps.jsonl beside its result.json
    with replacing(out / "steps.jsonl") as steps_log:

        def on_step(step):
            steps_log.write(json.dumps(step, default=_jsonable) + "\n")
            steps_log.flush()
            shown.step(step)

        phases = {"search_seconds": time.time()}
        search = run_search(config, original, evaluator, exp.proposer, maze, on_step)
        phases["measure_seconds"] = time.time()
        shown.phase(f"measurement of {episodes} episodes")
        measured = measure(evaluator, original, search.graph, search.path, episodes, seed + MEASURE_SEED_OFFSET)
        phases["calibrate_seconds"] = time.time()
        shown.phase("calibration on held-out episodes")
        prediction = predict(evaluator, original, search.graph, search.path, seed, episodes)
    data = _result_dict(exp, config, search, measured, t0)  # the counters and wall_seconds: the refinement's cost
    data["search_estimate"] = data["predicted_success"]  # the search's own product (biased upward)
    data.update(prediction.to_dict())  # calibrated: held-out end-to-end episodes, Jeffreys posterior
    data["evaluation"], data["goal_points"] = config.evaluation, config.goal_points
    data["switching"] = config.switching  # when each leg's goal point is fed (sim.switching)
    data["split_pick"] = config.split_pick  # which of an edge split's candidates the search takes
    data["policy"], data["policy_fingerprint"] = exp.policy_name, evaluator.policy_fingerprint  # which policy
    data["commit"] = code_commit()  # which code: the checkout's commit, "-dirty" if specrefine/ was edited
    data["spec"] = maze_spec_text(maze, config.spec)  # the task as an expression (the original: data["input_graph"])
    data["config"] = config.to_dict()  # everything this run was asked to do (what its preset decides resolved)
    data["preset"] = config.preset  # best (the best measured settings) or paper (the paper's rules)
    phases["input_seconds"] = time.time()
    shown.phase(f"input task as it is: {episodes} episodes")
    data["input_task"] = _input_task(exp, config, search, measured)
    data.update(_durations(phases, time.time()))  # where the wall time went: search, measurement, calibration, input
    write_atomic(out / "result.json", json.dumps(data, indent=2, default=_jsonable))
    save_run_policy(out, maze, config.agent, search.graph, search.path, evaluator)  # out/policy.json: as an object
    _pictures(maze, search, measured, out, data)
    return RunResult(data, out)


def _input_task(exp, config: RunConfig, search, measured) -> dict:
    """The input task as it is, for the before-and-after: DiRL's shortest path on the input graph, its estimate
    (the search's rollouts, mostly cached) and its success measured on the refined path's episode seeds.  Run after
    the refinement's counters are taken: its evaluations and seconds (``input_seconds``) are apart from them."""
    from ..core.results import wilson_ci
    from ..refine import shortest_path

    original, evaluator = exp.graph, exp.evaluator
    if search.refinements == 0 and search.graph == original:  # the method's own path is the input's (dirl)
        found, run = search, measured
    else:
        found = shortest_path(original, evaluator, seed=config.seed)
        run = measure(evaluator, original, original, found.path, config.episodes, config.seed + MEASURE_SEED_OFFSET)
    k, n = int(run.success.sum()), len(run.success)
    return {"path": found.path, "estimate": found.predicted_success, "success_rate": run.rate,
            "success_ci": list(wilson_ci(k, n)), "episodes": n,
            "episode_outcomes": run.path_result.counts() if run.path_result else {}}


def _durations(starts: dict, end: float) -> dict:
    """{phase: seconds} from {phase: its start time}, phases in order, the last ending at ``end``."""
    times = [*starts.values(), end]
    return {name: round(b - a, 3) for name, a, b in zip(starts, times, times[1:])}


def _result_dict(exp, config: RunConfig, search, measured, t0) -> dict:
    from ..core.results import wilson_ci

    maze, original, evaluator, proposer = exp.maze, exp.graph, exp.evaluator, exp.proposer
    n_ok, n = int(measured.success.sum()), len(measured.success)
    graph = search.graph
    path_edges = len(search.path) - 1 if search.path else 0
    counts = evaluator_counts(evaluator)
    return {
        "maze": maze.name, "agent": config.agent, "method": config.method, "proposer": config.proposer,
        "proposer_is_vlm": bool(getattr(proposer, "is_vlm", False)), "seed": config.seed,
        "success_rate": measured.rate, "success_ci": list(wilson_ci(n_ok, n)), "episodes": n,
        "path_success_rate": float(measured.path_result.p) if measured.path_result else 0.0,
        # where the measured episodes of the path end (success, avoid, flipped, timeout) and each leg's rate
        "episode_outcomes": measured.path_result.counts() if measured.path_result else {},
        "leg_success": measured.path_result.leg_success if measured.path_result else [],
        "predicted_success": search.predicted_success, "edge_probabilities": search.edge_probabilities,
        # evaluations the result rests on: simulated now, or by an earlier run of the same --out (resume)
        "evaluations": counts["evaluations"],
        "evaluations_simulated": evaluator.evaluations, "cache_hits": getattr(evaluator, "cache_hits", 0),
        # environment steps the result rests on (as evaluations: cached work included), and those simulated now
        "sim_steps": counts["sim_steps"],
        "sim_steps_simulated": int(evaluator.sim_steps), "vlm_calls": int(getattr(proposer, "calls", 0) or 0),
        "proposer_calls": int(getattr(proposer, "proposer_calls", 0) or 0),
        "vlm_cost_usd": float(getattr(proposer, "cost_usd", 0.0) or 0.0), "wall_seconds": time.time() - t0,
        "vlm_bad_replies": int(getattr(proposer, "bad_replies", 0) or 0),
        "rollouts_per_evaluation": evaluator.n, "refinements": search.refinements,
        "refines_input": not check_refines(graph, original), "path": search.path,
        "graph_vertices": graph.n_vertices, "graph_edges": graph.n_edges,
        "path_edges": path_edges, "graph": graph.to_dict(), "input_graph": original.to_dict(),
    }


def _pictures(maze, search, measured, out, data) -> None:
    from ..pictures.render import render_graph_diagram, render_roadmap, render_task, save_png

    pr = measured.path_result
    lo, hi = data["success_ci"]
    title = (f"{maze.name} [{data['method']}, {data['proposer']}]\nmeasured: {_before(data, 'success_rate', '.0%')}"
             f"{data['success_rate']:.0%} (95% CI {lo:.0%}-{hi:.0%}, {data['episodes']} episodes)\n"
             f"estimated: {_before(data, 'estimate', '.0%')}{data['search_estimate']:.0%}")
    fig = render_task(maze, search.graph, trajectories=pr.trajectories if pr else None,
                      success=measured.success if pr else None, lengths=pr.lengths if pr else None,
                      path=search.path, title=title)
    save_png(fig, out / "refined.png")
    probs = {(a, b): p for (a, b), p in zip(zip(search.path, search.path[1:]), search.edge_probabilities)} \
        if search.path else None
    save_png(render_graph_diagram(search.graph, probs, path=search.path, title="refined task graph"),
             out / "graph.png")
    roadmap = getattr(search, "roadmap", None)
    if roadmap is not None and roadmap.points:
        save_png(render_roadmap(maze, roadmap, search.graph, search.path,
                                title=f"{maze.name} [{data['method']}]\nthe correction's roadmap"), out / "roadmap.png")


def _jsonable(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
