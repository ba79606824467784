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
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .agents import get_agent
from .calibrate import predict
from .compositional import save_run_policy
from .errors import SpecrefineError
from .graph import check_refines
from .monitor import measure
from .refine.search import EVALUATIONS
from .runfolder import replacing, write_atomic
from .spec import maze_spec_text

MEASURE_SEED_OFFSET = 1_000_003  # final measurement never reuses the search's rollouts

#: every method: whether it asks a proposer, and what it is (the paper's Sec. 5.1, plus controls)
METHODS = {
    "ours": (True, "Alg. 3: Dijkstra-order search with proposer edge splits and vertex subsets"),
    "ours-novertex": (True, "control: ours without vertex refinement anywhere (neither the search's vertex subsets "
                            "nor Algorithm 2 inside an edge split)"),
    "ours-nosearchvertex": (True, "control: ours without the search's own vertex subsets (an edge split still "
                                  "tunes its later candidates with Algorithm 2)"),
    "ours-notune": (True, "control: ours with an edge split's later candidates evaluated as proposed (no "
                          "Algorithm 2 inside the split, Alg. 1 line 10)"),
    "ours-nofeedback": (True, "control: ours with an edge split's later round asked afresh, without the earlier "
                              "candidates' results"),
    "ours-d1": (True, "the paper's d = 1: no later round in an edge split (its samples, feedback and tuning)"),
    "ours-repair": (True, "beyond the paper: ours, and when no split candidate succeeds end to end, its failing "
                          "legs are split once more before it is judged (refine/repair.py)"),
    "ours-shortcut": (True, "beyond the paper: ours, then shortcut edges over the found path's waypoints (one "
                            "long leg where it beats several short ones; refine/shortcut.py)"),
    "vlm-oneshot": (True, "baseline: whole-graph refinement in one query + one feedback round, best of 2 x w"),
    "vlm-oneshot-matched": (True, "control: one-shot best-of-N, spending what ours spent (proposer calls, "
                                  "subtask evaluations) on the same task and seed"),
    "symbolic": (False, "baseline: the search with vertex subsets only"),
    "dirl": (False, "baseline: no refinement, Dijkstra on the input graph"),
}
#: what each variant of ``ours`` changes in its SearchConfig (every control removes one thing from ``ours``)
OURS_VARIANTS = {
    "ours": {},
    "ours-novertex": dict(vertex_refinement=False, split_tuning=False),
    "ours-nosearchvertex": dict(vertex_refinement=False),
    "ours-notune": dict(split_tuning=False),
    "ours-nofeedback": dict(split_feedback=False),
    "ours-d1": dict(d=1),
    "ours-repair": dict(repair=True),
    "ours-shortcut": dict(shortcut_reach="policy"),  # "policy": the agent's training goal range (below)
}
PROPOSER_METHODS = tuple(m for m, (asks, _) in METHODS.items() if asks)


@dataclass
class RunResult:
    data: dict
    out: Path

    def summary(self) -> str:
        d = self.data
        lo, hi = d["success_ci"]
        return (f"{d['maze']} [{d['spec']}] | {d['agent']} | method={d['method']} proposer={d['proposer']} "
                f"seed={d['seed']}\n"
                f"  success on the original task: {d['success_rate']:.3f} (95% CI {lo:.3f}-{hi:.3f}, "
                f"{d['episodes']} episodes); predicted {d['predicted_success']:.3f} (95% CI "
                f"{d['predicted_ci'][0]:.3f}-{d['predicted_ci'][1]:.3f}; the search's own {d['search_estimate']:.3f})\n"
                f"  graph: {d['graph_vertices']} vertices, {d['graph_edges']} edges, path of {d['path_edges']} "
                f"subtasks; refines input: {d['refines_input']}\n"
                f"  {d['evaluations']} subtask evaluations, {d['sim_steps']} sim steps, "
                f"{d['proposer_calls']} proposer calls ({'VLM' if d['proposer_is_vlm'] else 'offline, not a VLM'}), "
                f"{d['wall_seconds']:.1f} s\n  -> {self.out / 'result.json'}")


def refine_maze(maze_path, *, agent="point", method="ours", proposer="geometric", seed=0, out=Path("runs/latest"),
                rollouts=32, episodes=200, policy_path=None, w=3, d=2, k=5, evaluator=None,
                spec: str | None = None, evaluation: str | None = None) -> RunResult:
    """``spec``: the task as an expression over the maze's letters (``specrefine.spec.parse_spec``, e.g.
    ``"(a | b) -> c -> G"``); None = the maze's own task (its ``; spec:`` line, else its chain).

    ``evaluation``: "fixed" (every subtask estimate on ``rollouts`` rollouts, the paper's protocol) or
    "adaptive" (the chain DP by branch and bound with staged rollouts: :mod:`specrefine.refine.racing`);
    None: the agent's ``default_evaluation`` (fixed for the point mass, adaptive for the Ant).

    ``out`` holds this run only (:mod:`specrefine.runfolder`): its arguments go to ``out/run.json``, a
    rerun with other arguments into it is refused, and so is a folder another live run is using.
    """
    from .experiment import setup
    from .mazes import Maze, load_maze
    from .runfolder import claim, write_record
    from .spec import maze_task

    t0 = time.time()
    maze = maze_path if isinstance(maze_path, Maze) else load_maze(maze_path)
    maze_task(maze.for_agent(agent), spec)  # a bad agent or spec fails before the folder is touched
    evaluation = evaluation or get_agent(agent).default_evaluation
    args = {"maze": maze.name, "maze_grid": list(maze.grid), "maze_spec": maze.spec, "agent": agent,
            "method": method, "proposer": proposer if method in PROPOSER_METHODS else None, "seed": seed,
            "rollouts": rollouts, "episodes": episodes, "policy": str(policy_path or "shipped"), "w": w, "d": d,
            "k": k, "spec": spec}
    if evaluation != "fixed":  # run folders of the fixed protocol keep the records they always had
        args["evaluation"] = evaluation
    if evaluation not in EVALUATIONS:
        raise SpecrefineError(f"--evaluation must be one of {', '.join(EVALUATIONS)}, got {evaluation!r}")
    with claim(out, args) as out:
        exp = setup(maze, agent=agent, proposer=proposer if method in PROPOSER_METHODS else None, seed=seed,
                    rollouts=rollouts, policy=policy_path or "shipped", out=out, evaluator=evaluator,
                    record_path=out / "vlm_recording.jsonl", spec=spec)
        write_record(out, args)  # only once every argument proved usable: a refused run leaves no record
        return _refine(exp, method, proposer, seed, out, episodes, w, d, k, spec, t0, evaluation)


def _refine(exp, method, proposer, seed, out, episodes, w, d, k, spec, t0, evaluation="fixed") -> RunResult:
    agent = exp.agent
    maze, original, evaluator, prop = exp.maze, exp.graph, exp.evaluator, exp.proposer
    # the step log goes to a temporary file that replaces steps.jsonl only once the run is measured: a rerun into
    # a finished folder, killed at any moment, leaves the finished run's steps.jsonl beside its result.json
    with replacing(out / "steps.jsonl") as steps_log:

        def on_step(step):
            steps_log.write(json.dumps(step, default=_jsonable) + "\n")
            steps_log.flush()

        phases = {"search_seconds": time.time()}
        search = _search(method, original, evaluator, prop, maze, agent, seed, w, d, k, on_step, evaluation)
        phases["measure_seconds"] = time.time()
        measured = measure(evaluator, original, search.graph, search.path, episodes, seed + MEASURE_SEED_OFFSET)
        phases["calibrate_seconds"] = time.time()
        prediction = predict(evaluator, original, search.graph, search.path, seed, episodes)
    data = _result_dict(maze, agent, method, prop, proposer, seed, original, search, measured, evaluator, t0)
    data["search_estimate"] = data["predicted_success"]  # the search's own product (biased upward)
    data.update(prediction.to_dict())  # calibrated: held-out end-to-end episodes, Jeffreys posterior
    data["evaluation"] = evaluation
    data["policy"], data["policy_fingerprint"] = exp.policy_name, evaluator.policy_fingerprint  # which policy
    data["spec"] = maze_spec_text(maze, spec)  # the task's expression (the original graph is data["input_graph"])
    data.update(_durations(phases, time.time()))  # where the wall time went: search, measurement, calibration
    write_atomic(out / "result.json", json.dumps(data, indent=2, default=_jsonable))
    save_run_policy(out, maze, agent, search.graph, search.path, evaluator)  # out/policy.json: the policy as an object
    _pictures(maze, search, measured, out, data)
    return RunResult(data, out)


def _search(method, original, evaluator, proposer, maze, agent, seed, w, d, k, on_step, evaluation="fixed"):
    from .refine import RefinementSearch, SearchConfig, shortest_path

    if method == "dirl":
        return shortest_path(original, evaluator, seed=seed)
    if method == "symbolic":
        cfg = SearchConfig(k=k, edge_refinement=False, seed=seed, evaluation=evaluation)
        return RefinementSearch(original, evaluator, config=cfg, on_step=on_step).run()
    if method in OURS_VARIANTS:
        variant = dict(OURS_VARIANTS[method])
        if variant.get("shortcut_reach") == "policy":  # as far as the policy was trained to reach a goal
            variant["shortcut_reach"] = get_agent(agent).reach_task.goal_max
        cfg = SearchConfig(**{"w": w, "d": d, "k": k, "seed": seed, "evaluation": evaluation, **variant})
        images = getattr(proposer, "sees_images", True)  # offline proposers: no picture is drawn (seconds per run)
        query_for = edge_query_builder(maze, agent, evaluator.facts(), images=images)
        return RefinementSearch(original, evaluator, proposer=proposer, config=cfg, on_step=on_step,
                                query_for=query_for, picture=candidate_picture(maze) if images else None).run()
    if method.startswith("vlm-oneshot"):
        from .refine.oneshot import oneshot

        budget = budget_of_ours(original, evaluator, proposer.spec, maze, agent, seed, w, d, k, evaluation) \
            if method == "vlm-oneshot-matched" else None
        return oneshot(original, evaluator, proposer, maze=maze, agent=agent, w=w, rounds=d, seed=seed,
                       on_step=on_step, budget=budget)
    raise SpecrefineError(f"unknown method {method!r}")


def _durations(starts: dict, end: float) -> dict:
    """{phase: seconds} from {phase: its start time}, phases in order, the last ending at ``end``."""
    times = [*starts.values(), end]
    return {name: round(b - a, 3) for name, a, b in zip(starts, times, times[1:])}


def budget_of_ours(original, evaluator, proposer_spec, maze, agent, seed, w, d, k, evaluation="fixed"
                   ) -> tuple[int, int]:
    """(proposer calls, subtask evaluations) that ``ours`` spends on this task and seed (run here, on its own cache)."""
    from .proposers import make_proposer

    cache = evaluator.cache_dir.parent / "budget_cache" if evaluator.cache_dir is not None else None
    twin = evaluator.fresh_copy(cache_dir=cache)
    proposer = make_proposer(proposer_spec, seed=seed)
    _search("ours", original, twin, proposer, maze, agent, seed, w, d, k, on_step=None, evaluation=evaluation)
    return proposer.proposer_calls, twin.evaluations + twin.disk_hits


def edge_query_builder(maze, agent, facts=None, *, images: bool = True):
    """(graph, u, v, EdgeResult) -> EdgeQuery with the picture of the edge's evaluated rollouts.

    ``facts``: the evaluator's ``facts()``, what the prompt says about the evaluation (default: an
    evaluator with default settings on ``maze``). ``images=False``: no picture (``image_png`` None).
    """
    from .proposers import EdgeQuery
    from .render import render_task, to_png

    def picture(graph, u, v, result):
        if not images:
            return None
        fig = render_task(maze, _edge_graph(graph, u, v), trajectories=getattr(result, "trajectories", None),
                          success=getattr(result, "success", None), lengths=getattr(result, "lengths", None),
                          title=f"{u} -> {v}: {result.p:.0%} of {result.n} rollouts succeed")
        return to_png(fig)

    def build(graph, u, v, result):
        return EdgeQuery(maze=maze, agent=agent, start=graph.region(u), goal=graph.region(v),
                         avoid=graph.avoid(u, v), success=result.p, n=result.n,
                         image_png=picture(graph, u, v, result), graph=graph, facts=facts)

    return build


def _edge_graph(graph, u, v):
    from .graph import TaskGraph

    sub = TaskGraph(u)
    sub.add_vertex(u, graph.region(u), label=graph.label(u))
    sub.add_vertex(v, graph.region(v), label=graph.label(v))
    sub.add_edge(u, v, graph.avoid(u, v))
    sub.finals = {v}
    return sub


def candidate_picture(maze):
    """SplitCandidate -> PNG of its waypoints and the rollouts of each of its subtasks."""
    from .render import render_task, to_png

    def picture(candidate):
        legs = [r for r in candidate.results if getattr(r, "trajectories", None) is not None and r.n]
        if not legs:
            return None
        width = max(r.trajectories.shape[1] for r in legs)
        from .results import pad_trajectories

        traj = np.concatenate([pad_trajectories(r.trajectories, width) for r in legs])
        fig = render_task(maze, trajectories=traj, success=np.concatenate([r.success for r in legs]),
                          lengths=np.concatenate([r.lengths for r in legs]), waypoints=candidate.waypoints,
                          title="subtask success: " + ", ".join(f"{p:.2f}" for p in candidate.probabilities))
        return to_png(fig)

    return picture


def _result_dict(maze, agent, method, proposer, proposer_spec, seed, original, search, measured, evaluator, t0):
    from .results import wilson_ci

    n_ok, n = int(measured.success.sum()), len(measured.success)
    graph = search.graph
    path_edges = len(search.path) - 1 if search.path else 0
    return {
        "maze": maze.name, "agent": agent, "method": method, "proposer": proposer_spec,
        "proposer_is_vlm": bool(getattr(proposer, "is_vlm", False)), "seed": seed,
        "success_rate": measured.rate, "success_ci": list(wilson_ci(n_ok, n)), "episodes": n,
        "path_success_rate": float(measured.path_result.p) if measured.path_result else 0.0,
        # where the measured episodes of the path end (success, avoid, flipped, timeout) and each leg's rate
        "episode_outcomes": measured.path_result.counts() if measured.path_result else {},
        "leg_success": measured.path_result.leg_success if measured.path_result else [],
        "predicted_success": search.predicted_success, "edge_probabilities": search.edge_probabilities,
        # evaluations the result rests on: simulated now, or by an earlier run of the same --out (resume)
        "evaluations": evaluator.evaluations + getattr(evaluator, "disk_hits", 0),
        "evaluations_simulated": evaluator.evaluations, "cache_hits": getattr(evaluator, "cache_hits", 0),
        # environment steps the result rests on (as evaluations: cached work included), and those simulated now
        "sim_steps": int(evaluator.sim_steps + getattr(evaluator, "cached_steps", 0)),
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
    from .render import render_graph_diagram, render_task, save_png

    pr = measured.path_result
    lo, hi = data["success_ci"]
    title = (f"{maze.name} [{data['method']}, {data['proposer']}]: {data['success_rate']:.0%} "
             f"(95% CI {lo:.0%}-{hi:.0%}, {data['episodes']} episodes)")
    fig = render_task(maze, search.graph, trajectories=pr.trajectories if pr else None,
                      success=measured.success if pr else None, lengths=pr.lengths if pr else None,
                      path=search.path, title=title)
    save_png(fig, out / "refined.png")
    probs = {(a, b): p for (a, b), p in zip(zip(search.path, search.path[1:]), search.edge_probabilities)} \
        if search.path else None
    save_png(render_graph_diagram(search.graph, probs, path=search.path, title="refined task graph"),
             out / "graph.png")


def _jsonable(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
