"""A run's records, ``result.json`` and ``policy.json``, read and checked by one schema before anything uses them.

Every reader (``specrefine official``, ``failures``, ``calibrate``, the cost and leg reports, the AntMaze table,
``CompositionalPolicy.load``) goes through :func:`read_result` / :func:`read_policy`, so a damaged or tampered record
is one line naming the field and what is wrong with it (:class:`~specrefine.core.errors.RecordError`; a
``PolicyError`` for policy.json), before any episode runs or any file is written: never a traceback midway, never a
meaningless number.

The schema is the fields' types and ranges (``RESULT_FIELDS``, ``POLICY_FIELDS``).  ``result.json`` must name its
maze and agent; its other fields are checked where present (older runs lack newer fields; a reader that needs one
says so).  ``policy.json`` is checked whole: its grid as a ``.maze`` file is (rectangular, S and G, known cells, at
most ``MAX_SIDE`` a side), its legs' regions and points finite, its horizon a whole number of decisions.  Fields the
schema does not name are left alone.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable

from .agents import AGENTS
from .errors import RecordError, SpecrefineError
from .paths import regular_file

#: a problem with a value as a phrase ("must be ..."), None when the value is fine
Check = Callable[[object], str | None]
MAX_HORIZON = 100_000  # decisions per leg: the agents use 100 (point) and 300 (Ant)


def read_json(path, what: str, error: type[SpecrefineError] = RecordError):
    """The JSON in ``path`` (a regular file: a FIFO, a folder or a device is refused unopened); anything unreadable,
    nesting too deep included, is one ``error`` line."""
    try:
        return json.loads(regular_file(path, what).read_text(encoding="utf-8"))
    except SpecrefineError as exc:
        raise error(str(exc)) from None
    except RecursionError:
        raise error(f"{path}: unreadable {what} (JSON nested too deeply)") from None
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise error(f"{path}: unreadable {what} ({type(exc).__name__})") from None


def read_result(path) -> dict:
    """A run's result.json, checked (module docstring)."""
    return check_result(read_json(path, "result.json"), path)


def read_policy(path, error: type[SpecrefineError] = RecordError) -> dict:
    """A run's policy.json, checked (module docstring); the caller checks ``format`` and ``version`` first where it
    wants its own message for a file of another kind."""
    return check_policy(read_json(path, "policy.json", error), path, error)


def check_result(data, where) -> dict:
    """``data`` if it is a run's result.json by the schema, else one RecordError line naming the field."""
    if not isinstance(data, dict):
        raise RecordError(f"{where}: not a run's result.json (a JSON {type(data).__name__})")
    missing = [key for key in ("maze", "agent") if key not in data]
    if missing:
        raise RecordError(f"{where}: not a run's result.json (no {' or '.join(missing)} named)")
    _check_fields(data, RESULT_FIELDS, where, RecordError)
    path, graph = data.get("path"), data.get("graph")
    if path and graph:
        _check_path(path, _graph(graph), where)
    return data


def check_policy(data, where, error: type[SpecrefineError] = RecordError) -> dict:
    """``data`` if it is a compositional policy by the schema, else one ``error`` line naming the field."""
    if not isinstance(data, dict):
        raise error(f"{where}: not a compositional policy (a JSON {type(data).__name__})")
    missing = [key for key in POLICY_REQUIRED if key not in data]
    if missing:
        raise error(f"{where}: not a compositional policy (no {', '.join(missing)})")
    _check_fields(data, POLICY_FIELDS, where, error)
    cell = AGENTS[data["agent"]].cell_size
    if data["cell_size"] != cell:
        raise error(f"{where}: cell_size {data['cell_size']!r} is not the {data['agent']}'s {cell:g} m")
    return data


def _check_fields(data: dict, fields: dict[str, Check], where, error) -> None:
    for key, check in fields.items():
        if key in data:
            try:
                problem = check(data[key])
            except RecursionError:
                problem = "is nested too deeply"
            if problem:
                raise error(f"{where}: {key} {problem}")


def _check_path(path: list, graph, where) -> None:
    unknown = [v for v in path if v not in graph]
    if unknown:
        raise RecordError(f"{where}: path names {unknown[0]!r:.40}, no vertex of the graph")
    for u, v in zip(path, path[1:], strict=False):
        if (u, v) not in graph.edges():
            raise RecordError(f"{where}: path {u!r} -> {v!r} is no edge of the graph")


# --- the checks -----------------------------------------------------------------------------------------------
def _shown(value) -> str:
    """A value as an error line shows it: short."""
    if isinstance(value, list | dict):
        return f"{'a list' if isinstance(value, list) else 'an object'} of {len(value)}"
    return json.dumps(value[:40] if isinstance(value, str) else value)


def number(lo: float = -math.inf, hi: float = math.inf, *, whole: bool = False) -> Check:
    """A finite number (``whole``: an integer) in [lo, hi]."""
    kind = "a whole number" if whole else "a finite number"
    span = f" in [{lo:g}, {hi:g}]" if math.isfinite(hi) else f" >= {lo:g}" if math.isfinite(lo) else ""

    def check(value):
        ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value) \
            and (isinstance(value, int) or not whole) and lo <= value <= hi
        return None if ok else f"must be {kind}{span}, got {_shown(value)}"
    return check


def text(value):
    return None if isinstance(value, str) else f"must be a string, got {_shown(value)}"


def optional(check: Check) -> Check:
    return lambda value: None if value is None else check(value)


def flag(value):
    return None if isinstance(value, bool) else f"must be true or false, got {_shown(value)}"


def list_of(check: Check) -> Check:
    def each(value):
        if not isinstance(value, list):
            return f"must be a list, got {_shown(value)}"
        return next((f"[{i}] {problem}" for i, item in enumerate(value) if (problem := check(item))), None)
    return each


def interval(value):
    """[low, high], both probabilities, low <= high."""
    problem = list_of(probability)(value)
    if problem or len(value) != 2 or value[0] > value[1]:
        return problem or f"must be [low, high] with 0 <= low <= high <= 1, got {json.dumps(value)[:40]}"
    return None


def counts(value):
    """{name: count}"""
    if not isinstance(value, dict):
        return f"must be an object of counts, got {_shown(value)}"
    return next((f"[{k!r}] {problem}" for k, v in value.items() if (problem := count(v))), None)


def agent(value):
    return None if value in AGENTS else f"must name an agent ({', '.join(AGENTS)}), got {_shown(value)}"


def mapping(value):
    return None if isinstance(value, dict) else f"must be an object, got {_shown(value)}"


def task_graph(value):
    """A task graph as ``TaskGraph.to_dict`` writes it, or {} (none recorded: what readers take it for)."""
    if value == {}:
        return None
    try:
        _graph(value)
    except SpecrefineError as exc:
        return f"is not a task graph: {exc}"
    return None


def _graph(value):
    from .graph import TaskGraph

    return TaskGraph.from_dict(value)


def maze_grid(value):
    """Rows of a ``.maze`` grid, checked as the file would be."""
    from .mazes import parse_maze

    problem = list_of(text)(value)
    if problem or not value:
        return problem or "must list the grid's rows"
    if any("\n" in row or "\r" in row for row in value):
        return "has a row with a line break in it"
    try:
        maze = parse_maze("\n".join(value), "maze_grid")
    except SpecrefineError as exc:
        return f"is not a maze grid: {exc}"
    return None if list(maze.grid) == value else "holds a comment, a blank or a padded row: rows of cells only"


def region(value):
    from .regions import from_dict

    try:
        from_dict(value)
    except SpecrefineError as exc:
        return f"is not a region: {exc}"
    return None


def point(value):
    problem = list_of(number())(value)
    return problem or (None if len(value) == 2 else f"must be [x, y], got {len(value)} numbers")


def leg(value):
    if not isinstance(value, dict):
        return f"must be an object (vertex, goal, avoid, point), got {_shown(value)}"
    for key, check in (("vertex", text), ("goal", region), ("avoid", region), ("point", optional(point))):
        if key not in value:
            return f"has no {key}"
        if problem := check(value[key]):
            return f"{key} {problem}"
    return None


def goal_policy(value):
    """The goal policy by reference: a checkpoint ("shipped" or a path) or the scripted controller's gains."""
    if not isinstance(value, dict):
        return f"must be an object, got {_shown(value)}"
    if "scripted" in value:
        gains = value["scripted"]
        if not isinstance(gains, dict) or set(gains) != {"gain", "vmax", "kv"}:
            return "scripted must give gain, vmax and kv"
        for key, gain in gains.items():
            if problem := nonnegative(gain):
                return f"scripted {key} {problem}"
    elif problem := text(value.get("checkpoint")):
        return f"checkpoint {problem}"
    if problem := text(value.get("fingerprint")):
        return f"fingerprint {problem}"
    return None


def legs(value):
    return list_of(leg)(value) or (None if value else "must list at least one leg")


count = number(0, whole=True)
probability = number(0, 1)
nonnegative = number(0)

RESULT_FIELDS: dict[str, Check] = {
    "maze": text, "agent": agent, "method": text, "proposer": optional(text), "seed": count, "episodes": count,
    "success_rate": probability, "success_ci": interval, "path_success_rate": probability,
    "predicted_success": probability, "search_estimate": probability, "predicted_ci": interval,
    "predicted_p_ci": interval, "edge_probabilities": list_of(probability),
    "leg_success": list_of(optional(probability)),  # null: a leg no episode started
    "episode_outcomes": counts, "rollouts_per_evaluation": number(1, whole=True), "path": list_of(text),
    "graph": task_graph, "input_graph": task_graph, "config": mapping, "refines_input": flag,
    "proposer_is_vlm": flag, "policy": optional(text), "policy_fingerprint": optional(text), "spec": optional(text),
    **dict.fromkeys(("evaluations", "evaluations_simulated", "cache_hits", "sim_steps", "sim_steps_simulated",
                     "vlm_calls", "proposer_calls", "vlm_bad_replies", "refinements", "graph_vertices", "graph_edges",
                     "path_edges", "prediction_successes", "prediction_episodes", "prediction_sim_steps"), count),
    **dict.fromkeys(("wall_seconds", "vlm_cost_usd", "search_seconds", "measure_seconds", "calibrate_seconds"),
                    nonnegative),
}
POLICY_REQUIRED = ("agent", "maze", "maze_grid", "cell_size", "horizon", "legs", "goal_policy")
POLICY_FIELDS: dict[str, Check] = {
    "agent": agent, "maze": text, "maze_grid": maze_grid, "cell_size": nonnegative,
    "horizon": number(1, MAX_HORIZON, whole=True), "legs": legs, "goal_policy": goal_policy, "path": list_of(text),
    "clearance": nonnegative, "control_period": nonnegative,
}
