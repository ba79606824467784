"""The specification monitor: which trajectories satisfy a task graph (success on the ORIGINAL task).

``measure`` runs a path's compositional policy and judges every episode by this monitor, as a run's
final measurement (and its held-out prediction) does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.regions import CompiledRegion


def satisfies(graph, trajectories, lengths=None, clearance: float = 0.0) -> np.ndarray:
    """Which trajectories satisfy the task graph's specification.

    A trajectory s_0..s_{T-1} satisfies the graph if there are a path v0 = initial -> v1 -> ... -> vk
    (vk final) and times 0 = t0 <= t1 <= ... <= tk < T with s_{ti} in I(vi) and, for every i >= 1, no
    state s_t with t_{i-1} <= t <= t_i inside O(v_{i-1} -> v_i) (signed distance < ``clearance``;
    pass ``Evaluator.clearance``, the distance at which the evaluator counts the body as touching).
    Choices in the DAG are resolved nondeterministically: the monitor tracks the set of edges a
    trajectory may currently be traversing (an NFA over edges), vectorised over trajectories.
    """
    traj = np.asarray(trajectories, dtype=float)
    if traj.ndim == 2:
        traj = traj[None]
    n, T = traj.shape[:2]
    lengths = np.full(n, T) if lengths is None else np.asarray(lengths, dtype=np.int64)
    valid = np.arange(T)[None, :] < lengths[:, None]  # (n, T)
    flat = traj.reshape(-1, 2)
    order = graph.topological_order()

    def chunked(fn, *args):  # bounded memory for long trajectories x many boxes
        return np.concatenate([fn(flat[i:i + 32768], *args) for i in range(0, len(flat), 32768)]).reshape(n, T)

    compiled: dict = {}
    comp = lambda region: compiled.setdefault(region, CompiledRegion(region))  # noqa: E731
    in_v = {v: chunked(comp(graph.region(v)).contains) for v in order}
    bad = {}
    for u, v in graph.edges():
        bad[(u, v)] = chunked(comp(graph.avoid(u, v)).below, clearance)
    active = {e: np.zeros(n, dtype=bool) for e in bad}
    accepted = np.zeros(n, dtype=bool)
    finals = set(graph.finals)
    for t in range(T):
        ok_t = valid[:, t]
        reached = {}
        for v in order:
            r = (in_v[v][:, t] & ok_t) if (t == 0 and v == graph.initial) else np.zeros(n, dtype=bool)
            for u in graph.predecessors(v):
                r |= active[(u, v)] & in_v[v][:, t]
            reached[v] = r
            if v in finals:
                accepted |= r
            for w in graph.successors(v):
                e = (v, w)
                active[e] = (active[e] | r) & ~bad[e][:, t] & ok_t
        # edges into v were updated before v was visited (topological order), so reaching v at time t
        # uses edges that survived time t -- the avoid check includes the reaching state itself
        if not any(a.any() for a in active.values()):
            break
    return accepted


@dataclass
class Measurement:
    success: np.ndarray  # per episode: satisfied the original task
    path_result: object | None  # the CompositionalResult (None: no path)

    @property
    def rate(self) -> float:
        return float(self.success.mean()) if len(self.success) else 0.0


def measure(evaluator, original, graph, path, episodes: int, seed) -> Measurement:
    """``episodes`` episodes of the compositional policy along ``path`` of ``graph``, judged on ``original``.

    Always from the ORIGINAL initial distribution, even if a baseline changed the initial vertex.
    """
    from .evaluator import path_legs

    if not path or len(path) < 2:
        return Measurement(np.zeros(0, dtype=bool), None)
    run = evaluator.run_compositional(original.region(original.initial), path_legs(graph, path), n=episodes,
                                      seed=seed)
    return Measurement(satisfies(original, run.trajectories, run.lengths, clearance=evaluator.clearance), run)
