"""Shortcut edges over the waypoints of a found path (beyond the paper: method ``ours-shortcut``).

An edge split replaces u -> v by u -> x_1 -> ... -> x_k -> v, and a proposer (the offline ones especially) may
place its waypoints closer together than the policy needs: each leg loses some episodes at its switch, so a path
with fewer, longer legs can succeed more often. After the search, every pair of vertices of the found path that
lie on one split (the vertices between them are all its waypoints, the edges between them share one parent edge
and one avoid set) and whose straight segment keeps clear of that avoid set within the policy's reach gets a
shortcut edge x_i -> x_j with the same parent and avoid set. The shortcut is an edge split of the same parent
edge with fewer waypoints, so the refined graph still implies the input graph (Theorem 4.1, checked like every
refinement). The path is then chosen again by a shortest path over these vertices with every edge evaluated from
where its start is reached, so the estimates themselves decide where one long leg beats two short ones.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.graph import TaskGraph

SEGMENT_SAMPLES = 64  # points checked along a shortcut's straight segment


@dataclass(frozen=True)
class Shortcut:
    i: int  # index in the path of the shortcut's start
    j: int  # index of its end (j >= i + 2)


def shortcuts(graph: TaskGraph, path: list[str], reach: float, clearance: float = 0.0) -> list[Shortcut]:
    """Every shortcut of ``path`` that skips only one split's waypoints and whose segment is clear and in reach."""
    out = []
    for i in range(len(path) - 2):
        parent, avoid = graph.parent(path[i], path[i + 1]), graph.avoid(path[i], path[i + 1])
        for j in range(i + 2, len(path)):
            skipped = path[j - 1]
            same_split = graph.refines(skipped) is None and graph.parent(skipped, path[j]) == parent \
                and graph.avoid(skipped, path[j]) == avoid
            if not same_split:
                break
            if graph.has_edge(path[i], path[j]):
                continue
            a, b = _anchor(graph, path[i]), _anchor(graph, path[j])
            if np.linalg.norm(b - a) <= reach and _clear(avoid, a, b, clearance):
                out.append(Shortcut(i, j))
    return out


def add_shortcuts(graph: TaskGraph, path: list[str], found: list[Shortcut]) -> None:
    """Add each shortcut to ``graph`` as an edge with the parent and avoid set of the leg it starts with."""
    for s in found:
        a, b = path[s.i], path[s.i + 1]
        graph.add_edge(a, path[s.j], graph.avoid(a, b), parent=graph.parent(a, b))


def _anchor(graph: TaskGraph, v: str) -> np.ndarray:
    point = graph.goal_point(v)
    return np.asarray(point, dtype=float) if point is not None else np.asarray(graph.region(v).centre(), dtype=float)


def _clear(avoid, a: np.ndarray, b: np.ndarray, clearance: float) -> bool:
    t = np.linspace(0.0, 1.0, SEGMENT_SAMPLES)[:, None]
    return bool(np.all(avoid.signed_distance(a + t * (b - a)) > clearance))
