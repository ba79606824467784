"""Offline planners that stand in for a VLM (never reported as one): geometric and random waypoints.

* :class:`GeometricProposer` — waypoints at the turns of the shortest free-space path on the maze
  grid, jittered so that ``w`` samples differ, adapting to feedback by splitting the subtask that
  failed most.
* :class:`RandomProposer` — random free-space waypoints (the ablation).
"""

from __future__ import annotations

import functools
import heapq
import json
import logging
import math
from collections.abc import Sequence

import numpy as np

from ..core.agents import get_agent
from ..core.graph import TaskGraph
from ..core.regions import CompiledRegion, Disc, Region
from .base import CandidateFeedback, EdgeQuery, GraphFeedback, GraphQuery, Proposer, _jsonable, graph_score
from .schema import region_json

log = logging.getLogger(__name__)


def reach_cells(maze, agent: str) -> int:
    """How many cells one subtask should span at most: the policy's reach, at least one cell."""
    return max(1, int(get_agent(agent).policy_reach // maze.cell_size))


_STEPS = [(dr, dc, math.sqrt(2.0) if dr and dc else 1.0)
          for dr, dc in [(-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1)]]


@functools.lru_cache(maxsize=8)
def _passable_flags(maze) -> bytes:
    """Cell (r, c) as the number ``(r + 1) * (cols + 2) + c + 1``; ``flags[number]`` is 1 where a route may enter
    it.  A frame of 0 surrounds the grid, and numbers order as (r, c) tuples do (ties break as they always did)."""
    frame = bytes(maze.cols + 2)
    return frame + b"".join(bytes([0, *(maze.passable(r, c) for c in range(maze.cols)), 0])
                            for r in range(maze.rows)) + frame


@functools.lru_cache(maxsize=8)
def _obstacles(maze) -> CompiledRegion:
    return CompiledRegion(maze.obstacles)


def _nearest_free_cell(maze, xy) -> tuple[int, int]:
    r, c = (int(v) for v in maze.xy_to_cell(np.asarray(xy, dtype=float)))
    if maze.passable(r, c):
        return (r, c)
    cells = maze.passable_cells()
    centres = maze.cell_to_xy(np.array([a for a, _ in cells]), np.array([b for _, b in cells]))
    return cells[int(np.argmin(np.linalg.norm(centres - np.asarray(xy), axis=1)))]


def grid_path(maze, src: tuple[int, int], dst: tuple[int, int], rng: np.random.Generator | None = None,
              noise: float = 0.0, cell_cost=None) -> list[tuple[int, int]]:
    """Shortest 8-connected free-cell path (no corner cutting); ``noise`` > 0 randomises step costs.

    ``cell_cost(cell)`` (optional) multiplies the cost of every step into ``cell``.
    """
    width = maze.cols + 2
    ok = _passable_flags(maze)
    steps = [(dr * width + dc, dr * width, dc, step) for dr, dc, step in _STEPS]
    start, end = (src[0] + 1) * width + src[1] + 1, (dst[0] + 1) * width + dst[1] + 1
    dist, prev = [math.inf] * len(ok), [-1] * len(ok)
    dist[start] = 0.0
    heap = [(0.0, start)]
    costs: dict = {}
    while heap:
        d, cell = heapq.heappop(heap)
        if cell == end:
            break
        if d > dist[cell]:
            continue
        for move, down, side, step in steps:
            nb = cell + move
            if not ok[nb] or (down and side and not (ok[cell + down] and ok[cell + side])):
                continue
            if noise > 0 and rng is not None:
                key = (cell, nb) if cell < nb else (nb, cell)
                if key not in costs:
                    costs[key] = 1.0 + noise * rng.random()
                step *= costs[key]
            if cell_cost is not None:
                step *= cell_cost((nb // width - 1, nb % width - 1))
            nd = d + step
            if nd < dist[nb]:
                dist[nb], prev[nb] = nd, cell
                heapq.heappush(heap, (nd, nb))
    if dist[end] == math.inf:
        return []
    path = [end]
    while path[-1] != start:
        path.append(prev[path[-1]])
    return [(n // width - 1, n % width - 1) for n in reversed(path)]


def clear_of_obstacles(maze, pts, margin: float) -> np.ndarray:
    """Whether each point lies at least ``margin`` metres from every wall and hazard.

    Exact (the signed distance of ``maze.obstacles``), but only the boxes near each point are looked at,
    on one bucket grid per maze: a big maze has hundreds of wall boxes.
    """
    return ~_obstacles(maze).below(pts, margin, grid_thr=0.5 * maze.cell_size)


def segment_clear(maze, a, b, margin: float) -> bool:
    """True if the straight segment a-b stays at least ``margin`` metres away from every wall."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    k = max(2, int(np.ceil(np.linalg.norm(b - a) / (0.1 * maze.cell_size))) + 1)
    t = np.linspace(0.0, 1.0, k)[:, None]
    return bool(np.all(clear_of_obstacles(maze, a + t * (b - a), margin)))


def pull_string(maze, pts: np.ndarray, margin: float) -> list[int]:
    """Indices of the intermediate points kept when a polyline is shortened by line of sight."""
    keep, i, last = [], 0, len(pts) - 1
    while i < last:
        j = i + 1
        while j < last and segment_clear(maze, pts[i], pts[j + 1], margin):
            j += 1
        if j < last:
            keep.append(j)
        i = j
    return keep


class _GridProposer(Proposer):
    """Shared parts of the offline proposers."""

    is_vlm = False

    def __init__(self, seed: int = 0, radius: tuple[float, float] = (0.3, 0.5), max_waypoints: int = 32,
                 spec: str | None = None):
        super().__init__(spec)
        self.seed = seed
        self.rng = np.random.default_rng(seed)
        self.radius = radius
        self.max_waypoints = max_waypoints

    # -- helpers --------------------------------------------------------------------------------
    def _disc(self, maze, xy, rng, fixed: float | None = None) -> Disc:
        lo, hi = self.radius
        r = fixed if fixed is not None else rng.uniform(lo, hi)
        return Disc(float(xy[0]), float(xy[1]), float(r * maze.cell_size))

    def _usable(self, maze, xy, margin_cells: float = 0.05) -> bool:
        x0, y0, x1, y1 = maze.bounds()
        return bool(x0 < xy[0] < x1 and y0 < xy[1] < y1
                    and clear_of_obstacles(maze, xy, margin_cells * maze.cell_size).all())

    def _dedupe(self, candidates: list[list[Region]]) -> list[list[Region]]:
        seen, out = set(), []
        for cand in candidates:
            sig = tuple(tuple(np.round(region_json(r)["center"] + [region_json(r)["radius"]], 3))
                        if isinstance(r, Disc) else json.dumps(region_json(r)) for r in cand)
            if sig not in seen:
                seen.add(sig)
                out.append(cand)
        return out

    def _split_for(self, maze, start: Region, goal: Region, j: int, rng,
                   agent: str = "") -> list[Region]:  # pragma: no cover
        raise NotImplementedError

    def split(self, q: EdgeQuery, w: int, feedback: Sequence[CandidateFeedback] = ()) -> list[list[Region]]:
        out = []
        for j in range(w):
            cand = None
            if feedback:
                cand = self._adapt(q, list(feedback), j, self.rng)
            for _ in range(6):  # distinct samples
                cand = cand or self._split_for(q.maze, q.start, q.goal, j, self.rng, q.agent)
                if self._dedupe(out + [cand]) == out + [cand]:
                    break
                cand = None
            if cand:
                out.append(cand)
        self.history.append({"kind": "edge split", "round": 1 + bool(feedback), "accepted":
                             [{"reasoning": f"{self.name}", "value": _jsonable(c)} for c in out],
                             "rejected": [], "reasked": False})
        return out

    def _adapt(self, q, feedback, j, rng) -> list[Region] | None:  # default: ignore feedback
        return None

    def graph(self, q: GraphQuery, w: int, feedback: Sequence[GraphFeedback] = ()) -> list[TaskGraph]:
        """The same per edge: each edge of the input graph (or the weakest edge of the best earlier graph)."""
        out = []
        for j in range(w):
            if feedback:
                best = max(feedback, key=graph_score)
                g = best.graph.copy()
                edges = g.edges()
                if not edges:
                    continue
                worst = min(edges, key=lambda e: best.edge_success.get(e, 1.0))
                targets = [worst]
            else:
                g = q.graph.copy()
                targets = g.edges()
            for u, v in targets:
                wps = self._split_for(q.maze, g.region(u), g.region(v), j, self.rng, q.agent)
                g.split_edge(u, v, wps)
            out.append(g)
        self.history.append({"kind": "task graph", "round": 1 + bool(feedback),
                             "accepted": [{"reasoning": self.name, "value": g.to_dict()} for g in out],
                             "rejected": [], "reasked": False})
        return out


def splice(graph: TaskGraph, u: str, v: str, waypoints: Sequence[Region]) -> list[str]:
    """Former name of :meth:`TaskGraph.split_edge` (notebook 03 still calls it)."""
    return graph.split_edge(u, v, waypoints)


class GeometricProposer(_GridProposer):
    """OFFLINE STAND-IN (not a VLM): waypoints at the turns of the shortest free-space path.

    Sample 0 is the plain shortest path (turns kept by line of sight with a 0.35-cell clearance,
    legs longer than 6 cells halved, discs of 0.4 cell); later samples perturb the step costs
    (other routes through other doorways), the clearance, the leg length, positions (jitter) and
    radii (0.3-0.5 cell).  With feedback, it keeps the best earlier candidate and adds waypoints
    on its weakest subtask (sample 0: that leg's turns, 1: its path midpoint, 2+: the next weakest
    leg, jittered).
    """

    spec = "geometric"
    name = "geometric (offline stand-in, not a VLM)"

    def _route_points(self, maze, a_xy, b_xy, j, rng, margin_cells, max_leg, cell_cost=None) -> list[np.ndarray]:
        return self._turns(self._route(maze, a_xy, b_xy, j, rng, margin_cells, cell_cost), max_leg)

    @staticmethod
    def _route(maze, a_xy, b_xy, j, rng, margin_cells, cell_cost=None) -> tuple[np.ndarray, list[int]] | None:
        """The shortest path's points (a, cell centres, b) and the turns string pulling keeps; None if no path."""
        src, dst = _nearest_free_cell(maze, a_xy), _nearest_free_cell(maze, b_xy)
        path = grid_path(maze, src, dst, rng, noise=0.0 if j == 0 else 0.6, cell_cost=cell_cost)
        if not path:
            return None
        cells = np.array(path)
        pts = np.concatenate([np.asarray(a_xy, float)[None], maze.cell_to_xy(cells[:, 0], cells[:, 1]),
                              np.asarray(b_xy, float)[None]])
        return pts, pull_string(maze, pts, margin_cells * maze.cell_size)

    @staticmethod
    def _turns(route, max_leg) -> list[np.ndarray]:
        """A route's waypoints: its turns, with legs longer than ``max_leg`` path cells cut into pieces."""
        if route is None:
            return []
        pts, keep = route
        idx = [0, *keep, len(pts) - 1]
        full = []
        for a, b in zip(idx, idx[1:]):
            span = b - a
            pieces = max(1, int(np.ceil(span / max_leg)))
            full += [a + round(span * s / pieces) for s in range(pieces)]
        inner = [i for i in sorted(set(full[1:])) if 0 < i < len(pts) - 1]
        if not inner and len(pts) > 3:  # start and goal see each other: one waypoint halfway along the path
            inner = [len(pts) // 2]
        return [pts[i] for i in inner]

    def _split_for(self, maze, start: Region, goal: Region, j: int, rng, agent: str = "") -> list[Region]:
        a, b = np.asarray(start.centre(), float), np.asarray(goal.centre(), float)
        reach = reach_cells(maze, agent)
        if j == 0:
            margin, max_leg, jitter, fixed_r = 0.35, reach, 0.0, 0.4
        else:
            margin, max_leg, jitter, fixed_r = rng.uniform(0.2, 0.45), int(rng.integers(1, 2 * reach + 2)), 0.12, None
        route = self._route(maze, a, b, j, rng, margin)
        pts = self._turns(route, max_leg)
        while len(pts) > self.max_waypoints and max_leg < 4 * reach + 8:  # too many: longer legs, turns kept
            max_leg += 1
            if j:  # a noisy route is drawn afresh each time, as it always was (seeded runs stay reproducible)
                route = self._route(maze, a, b, j, rng, margin)
            pts = self._turns(route, max_leg)
        if j == 0 and max_leg > reach:
            log.warning("geometric: this route needs more than %d waypoints at the agent's reach of %d cell(s), so "
                        "its legs span up to %d cells, past that reach (more waypoints: geometric:max_waypoints=N)",
                        self.max_waypoints, reach, max_leg)
        pts = [p for p in pts if not (bool(start.contains(p)) or bool(goal.contains(p)))]
        if j and len(pts) > 1:  # drop redundant waypoints (neighbours still see each other) now and then
            kept = []
            for i, p in enumerate(pts):
                prev = kept[-1] if kept else a
                nxt = pts[i + 1] if i + 1 < len(pts) else b
                if rng.random() < 0.4 and segment_clear(maze, prev, nxt, 0.15 * maze.cell_size):
                    continue
                kept.append(p)
            pts = kept or pts[:1]
        if not pts:
            pts = [self._midpoint(maze, a, b)]
        out = []
        for p in pts[: self.max_waypoints]:
            if jitter:
                q = p + np.clip(rng.normal(0.0, jitter * maze.cell_size, 2), -0.25 * maze.cell_size,
                                0.25 * maze.cell_size)
                if self._usable(maze, q, 0.3):
                    p = q
            out.append(self._disc(maze, p, rng, fixed_r))
        return out

    def _midpoint(self, maze, a, b) -> np.ndarray:
        m = (np.asarray(a) + np.asarray(b)) / 2
        if self._usable(maze, m, 0.2):
            return m
        r, c = _nearest_free_cell(maze, m)
        return maze.cell_to_xy(r, c)

    def _adapt(self, q: EdgeQuery, feedback: list[CandidateFeedback], j: int, rng) -> list[Region] | None:
        usable = [f for f in feedback if len(f.subtask_success) == len(f.waypoints) + 1]
        if not usable:
            return None
        best = max(usable, key=lambda f: f.p)
        wps = list(best.waypoints)
        succ = np.asarray(best.subtask_success, float)
        failing = [int(i) for i in np.argsort(succ, kind="stable") if succ[i] < 0.95]
        maze = q.maze
        if not failing or len(wps) >= self.max_waypoints:  # nothing to fix: a jittered copy
            return [self._disc(maze, self._jitter(maze, w.centre(), rng), rng) if isinstance(w, Disc) else w
                    for w in wps] or None
        leg = failing[(j // 2) % len(failing)]
        ends = [np.asarray(q.start.centre(), float)] + [np.asarray(w.centre(), float) for w in wps] + \
               [np.asarray(q.goal.centre(), float)]
        a, b = ends[leg], ends[leg + 1]
        if j % 2 == 0:
            new = self._route_points(maze, a, b, 0, rng, 0.35, reach_cells(maze, q.agent))
        else:
            cells = grid_path(maze, _nearest_free_cell(maze, a), _nearest_free_cell(maze, b))
            new = [maze.cell_to_xy(*cells[len(cells) // 2])] if len(cells) >= 3 else []
        existing = [np.asarray(w.centre(), float) for w in wps]
        new = [p for p in new if min((np.linalg.norm(p - e) for e in existing + [a, b]), default=1e9)
               > 0.25 * maze.cell_size]
        if not new:
            new = [self._midpoint(maze, a, b)]
        if j >= 2:
            new = [self._jitter(maze, p, rng) for p in new]
        room = self.max_waypoints - len(wps)
        regions = [self._disc(maze, p, rng, 0.4 if j == 0 else None) for p in new[:room]]
        return wps[:leg] + regions + wps[leg:]

    def _jitter(self, maze, p, rng) -> np.ndarray:
        p = np.asarray(p, float)
        q = p + np.clip(rng.normal(0.0, 0.12 * maze.cell_size, 2), -0.25 * maze.cell_size, 0.25 * maze.cell_size)
        return q if self._usable(maze, q, 0.3) else p


class RandomProposer(_GridProposer):
    """Ablation (not a VLM): 1-4 waypoints uniform over free space, in random order; ignores feedback."""

    spec = "random"
    name = "random (offline ablation, not a VLM)"

    def _split_for(self, maze, start: Region, goal: Region, j: int, rng, agent: str = "") -> list[Region]:
        k = int(rng.integers(1, 5))
        out = []
        while len(out) < k:
            p = maze.free.sample(1, rng)[0]
            if self._usable(maze, p, 0.05):
                out.append(self._disc(maze, p, rng))
        return out
