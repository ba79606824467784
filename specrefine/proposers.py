"""Who proposes refinements: a VLM through LiteLLM (or its recording), or an offline stand-in.

``make_proposer(spec)`` understands

* ``litellm:MODEL`` — any model LiteLLM speaks (keys from the environment only); every call is
  recorded to ``data/vlm/`` (or ``record_path``);
* ``replay:PATH`` — answers from such a recording, deterministically;
* ``geometric`` — an OFFLINE STAND-IN, not a VLM: waypoints at the turns of the shortest
  free-space path on the maze grid, jittered so that ``w`` samples differ, adapting to feedback by
  splitting the subtask that failed most.  It is always reported under its own name;
* ``random`` — random free-space waypoints (an ablation; also not a VLM).

All proposers share one interface (``docs/interfaces.md``): ``propose_split`` returns up to ``w``
candidate edge splits, each the ordered list of intermediate waypoint regions x1..x_{k-1}
(u -> x1 -> ... -> v); ``propose_graph`` returns up to ``w`` whole task graphs (the one-shot
VLM baseline of the paper's Sec. 5.1).  A bad VLM reply is logged, re-asked once and dropped;
it never ends a run.
"""

from __future__ import annotations

import heapq
import json
import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import SpecrefineError
from .graph import TaskGraph
from .regions import Disc, Region, is_subset
from .vlm import (
    LiteLLMClient,
    ProposalRejected,
    ReplayClient,
    VLMClient,
    build_content,
    parse_graph,
    parse_split,
    region_json,
    render_prompt,
)

log = logging.getLogger(__name__)

#: what the prompt says about each agent, and its body radius in metres (as in ``specrefine.sim``)
# (description, body radius in m, reach in m: the goal distance the pretrained policy was trained and checked on)
AGENT_INFO = {
    "point": ("a point mass (a small ball driven by a 2-D force, as in Gymnasium-Robotics PointMaze); it is fast "
              "and agile but can overshoot a target and slide along walls", 0.1, 3.0),
    "ant": ("the MuJoCo Ant, a four-legged walking robot (as in Gymnasium-Robotics AntMaze); it is slow to turn, "
            "can catch its legs on corners and can flip over", 0.5, 6.0),
}


def reach_cells(maze, agent: str) -> int:
    """How many cells one subtask should span at most: the policy's reach, at least one cell."""
    reach = AGENT_INFO.get(agent, (None, None, None))[2]
    return 6 if reach is None else max(1, int(reach // maze.cell_size))


# --------------------------------------------------------------------------------------------
# queries and feedback
# --------------------------------------------------------------------------------------------
@dataclass
class EdgeQuery:
    """One edge u -> v to split, with its evaluation (Algorithm 1's input)."""

    maze: object
    agent: str
    start: Region  # I(u)
    goal: Region  # I(v)
    avoid: Region  # O(e)
    success: float  # empirical success probability of the edge
    n: int  # rollouts behind it
    image_png: bytes | None  # the map with start/goal and the evaluated trajectories
    graph: TaskGraph | None = None  # the task graph the edge belongs to (context only)
    body_radius: float | None = None  # default: AGENT_INFO


@dataclass
class CandidateFeedback:
    """An earlier candidate split and how it did: one success probability per subtask (k = len(waypoints)+1)."""

    waypoints: list[Region]
    subtask_success: list[float]
    image_png: bytes | None = None

    @property
    def p(self) -> float:
        return float(np.prod(self.subtask_success)) if len(self.subtask_success) else 0.0


@dataclass
class GraphQuery:
    """A whole task graph to refine in one shot (the VLM baseline), with its evaluation."""

    maze: object
    agent: str
    graph: TaskGraph
    success: float  # success probability of the task under ``graph``
    n: int  # rollouts per subtask evaluation
    image_png: bytes | None
    edge_success: dict[tuple[str, str], float] = field(default_factory=dict)
    body_radius: float | None = None


@dataclass
class GraphFeedback:
    """An earlier candidate graph and how it did."""

    graph: TaskGraph
    edge_success: dict[tuple[str, str], float]
    success: float | None = None  # of the whole task under this graph
    image_png: bytes | None = None


# --------------------------------------------------------------------------------------------
# prompts
# --------------------------------------------------------------------------------------------
def _pct(p: float | None) -> str:
    return "not evaluated" if p is None or not np.isfinite(p) else f"{100 * float(p):.1f}%"


def _rj(region: Region) -> str:
    return json.dumps(region_json(region))


def environment_text(maze, agent: str, body_radius: float | None = None) -> str:
    """The environment description in every prompt: maze geometry and frame, agent, body size."""
    desc, default_r, reach = AGENT_INFO.get(agent, (f"the {agent} agent", None, None))
    r = body_radius if body_radius is not None else default_r
    lines = [maze.describe(), f"Agent: {agent}, {desc}."]
    if reach is not None:
        lines.append(f"Policy: a goal-conditioned policy pretrained on an open floor to reach goal points up to "
                     f"{reach:g} m away; it knows nothing about walls (they are the task graph's job).")
    if r is not None:
        lines.append(f"Body size: the agent's position is its centre; it counts as touching a wall when its centre "
                     f"comes within {r:g} m of one, so keep waypoints at least that far from walls.")
    if getattr(maze, "hazards", None) is not None:
        lines.append("Hazards: the '~' cells are free floor without walls, but touching one fails the task like "
                     "touching a wall; the walls and the hazards are the avoid set of every subtask, so route "
                     "waypoints around the hazards (keep them at least the body size away).")
    else:
        lines.append("The maze walls are the avoid set of every subtask.")
    return "\n".join(lines)


def _avoid_text(avoid: Region, maze) -> str:
    walls = maze.obstacles
    extra = [p for p in avoid.parts() if not is_subset(p, walls)]
    if not extra and is_subset(walls, avoid):
        return ("the maze walls (black) and hazards (purple in the pictures)" if maze.hazards is not None
                else "the maze walls (black in the pictures)")
    if not extra:
        return "parts of the maze walls: " + _rj(avoid)
    return "the maze walls and " + ", ".join(_rj(p) for p in extra)


def graph_text(graph: TaskGraph) -> str:
    """Vertices with regions and the edges, as shown to the VLM."""
    lines = ["vertices:"]
    for v in graph.vertices():
        tags = []
        if v == graph.initial:
            tags.append("initial")
        if v in graph.finals:
            tags.append("final")
        tag = f" [{', '.join(tags)}]" if tags else ""
        lines.append(f"  {v}{tag}: {_rj(graph.region(v))}")
    lines.append("edges: " + (", ".join(f"{u} -> {v}" for u, v in graph.edges()) or "(none)"))
    return "\n".join(lines)


def _edge_lines(graph: TaskGraph, edge_success: dict | None) -> str:
    edge_success = edge_success or {}
    return "\n".join(f"  {u} -> {v}: {_pct(edge_success.get((u, v)))}" for u, v in graph.edges()) or "  (no edges)"


def system_message() -> dict:
    return {"role": "system", "content": render_prompt("system", spec_api=render_prompt("spec_api"))}


def _edge_values(q: EdgeQuery) -> dict:
    context = ""
    if q.graph is not None:
        context = "\nThe edge belongs to this task graph (for context):\n" + graph_text(q.graph) + "\n"
    return dict(environment=environment_text(q.maze, q.agent, q.body_radius), start=_rj(q.start), goal=_rj(q.goal),
                avoid=_avoid_text(q.avoid, q.maze), success_pct=_pct(q.success),
                successes=int(round(q.success * q.n)), n=q.n, graph_context=context,
                schema=render_prompt("split_schema"))


def split_messages(q: EdgeQuery, feedback: Sequence[CandidateFeedback] = ()) -> list[dict]:
    """The chat messages of an edge-split query (first query, or follow-up with feedback)."""
    values = _edge_values(q)
    images = {"map": q.image_png}
    if not feedback:
        text = render_prompt("split_first", **values)
    else:
        blocks = []
        for j, fb in enumerate(feedback, start=1):
            legs = ["START"] + [f"x{i}" for i in range(1, len(fb.waypoints) + 1)] + ["GOAL"]
            lines = "\n".join(f"  {a} -> {b}: {_pct(p)}" for a, b, p in zip(legs, legs[1:], fb.subtask_success))
            blocks.append(render_prompt("split_candidate", index=j, round_note="",
                                        waypoints=json.dumps([region_json(w) for w in fb.waypoints]),
                                        subtask_lines=lines, overall_pct=_pct(fb.p)))
            images[f"candidate{j}"] = fb.image_png
        best = max(fb.p for fb in feedback)
        text = render_prompt("split_followup", **values, candidates="\n\n".join(blocks), best_pct=_pct(best))
    return [system_message(), {"role": "user", "content": build_content(text, images)}]


def graph_messages(q: GraphQuery, feedback: Sequence[GraphFeedback] = ()) -> list[dict]:
    """The chat messages of a one-shot whole-graph query (first, or follow-up with feedback)."""
    values = dict(environment=environment_text(q.maze, q.agent, q.body_radius), graph=graph_text(q.graph),
                  edge_lines=_edge_lines(q.graph, q.edge_success), success_pct=_pct(q.success), n=q.n,
                  example=render_prompt("graph_example"), schema=render_prompt("graph_schema"))
    images = {"map": q.image_png}
    if not feedback:
        text = render_prompt("graph_first", **values)
    else:
        blocks = []
        for j, fb in enumerate(feedback, start=1):
            blocks.append(render_prompt("graph_candidate", index=j, graph=graph_text(fb.graph),
                                        edge_lines=_edge_lines(fb.graph, fb.edge_success),
                                        overall_pct=_pct(_graph_score(fb))))
            images[f"candidate{j}"] = fb.image_png
        best = max(_graph_score(fb) for fb in feedback)
        text = render_prompt("graph_followup", **values, candidates="\n\n".join(blocks), best_pct=_pct(best))
    return [system_message(), {"role": "user", "content": build_content(text, images)}]


def _graph_score(fb: GraphFeedback) -> float:
    if fb.success is not None:
        return float(fb.success)
    return float(np.prod(list(fb.edge_success.values()))) if fb.edge_success else 0.0


# --------------------------------------------------------------------------------------------
# the interface
# --------------------------------------------------------------------------------------------
class Proposer:
    """Base class.  ``calls``/``cost_usd`` count VLM API calls and dollars (0 for offline proposers)."""

    name: str = "?"
    spec: str = "?"
    is_vlm: bool = False

    def __init__(self):
        self.queries = 0  # propose_* calls answered
        self.history: list[dict] = []  # per query: accepted candidates (with reasoning) and rejections

    @property
    def calls(self) -> int:
        return 0

    @property
    def cost_usd(self) -> float:
        return 0.0

    def propose_split(self, q: EdgeQuery, w: int, feedback: Sequence[CandidateFeedback] = ()) -> list[list[Region]]:
        raise NotImplementedError  # pragma: no cover

    def propose_graph(self, q: GraphQuery, w: int, feedback: Sequence[GraphFeedback] = ()) -> list[TaskGraph]:
        raise NotImplementedError  # pragma: no cover

    def describe(self) -> dict:
        """What a result file should say about the proposer."""
        return {"proposer": self.spec, "name": self.name, "is_vlm": self.is_vlm, "queries": self.queries,
                "vlm_calls": self.calls, "cost_usd": round(self.cost_usd, 6)}

    def __repr__(self):
        return f"<{type(self).__name__} {self.name}>"


class VLMProposer(Proposer):
    """Asks a vision-language model (through a :class:`~specrefine.vlm.VLMClient`)."""

    is_vlm = True

    def __init__(self, client: VLMClient, *, spec: str | None = None, reask: bool = True, max_waypoints: int = 32):
        super().__init__()
        self.client = client
        self.spec = spec or client.name
        self.name = client.name if not isinstance(client, ReplayClient) else f"{client.name} (recorded {client.model})"
        self.reask = reask
        self.max_waypoints = max_waypoints
        self.last_messages: list[dict] | None = None  # the latest request (see vlm.messages_to_text)

    @property
    def calls(self) -> int:
        return self.client.calls

    @property
    def cost_usd(self) -> float:
        return self.client.cost_usd

    def propose_split(self, q: EdgeQuery, w: int, feedback: Sequence[CandidateFeedback] = ()) -> list[list[Region]]:
        messages = split_messages(q, feedback)
        parse = lambda text: parse_split(text, q.maze, max_waypoints=self.max_waypoints)  # noqa: E731
        return self._ask(messages, w, parse, "edge split", round_=1 + bool(feedback))

    def propose_graph(self, q: GraphQuery, w: int, feedback: Sequence[GraphFeedback] = ()) -> list[TaskGraph]:
        messages = graph_messages(q, feedback)
        parse = lambda text: parse_graph(text, q.maze, q.graph)  # noqa: E731
        return self._ask(messages, w, parse, "task graph", round_=1 + bool(feedback))

    def _ask(self, messages, w, parse, kind, round_):
        self.queries += 1
        entry = {"kind": kind, "round": round_, "accepted": [], "rejected": [], "reasked": False}
        self.history.append(entry)
        self.last_messages = messages
        texts = self.client.complete(messages, n=w)
        out, bad = self._parse_all(texts, parse, entry, kind)
        if bad and self.reask:
            entry["reasked"] = True
            reasons = "\n".join(f"- answer {i}: {why}" for i, (_, why) in enumerate(bad, start=1))
            follow = messages + [
                {"role": "assistant", "content": bad[0][0] or "(empty reply)"},
                {"role": "user", "content": render_prompt("reask", count=f"{len(bad)} of {len(texts)}",
                                                          reasons=reasons, schema_name=kind)},
            ]
            more, _ = self._parse_all(self.client.complete(follow, n=len(bad)), parse, entry, kind)
            out += more
        return out[:w]

    def _parse_all(self, texts, parse, entry, kind):
        good, bad = [], []
        for text in texts:
            try:
                value, reasoning = parse(text)
            except ProposalRejected as exc:
                log.warning("%s: rejected %s candidate: %s", self.name, kind, exc)
                entry["rejected"].append(str(exc))
                bad.append((text, str(exc)))
                continue
            except Exception as exc:  # noqa: BLE001 - a reply must never end the run
                log.warning("%s: rejected %s candidate (unexpected: %s)", self.name, kind, exc)
                entry["rejected"].append(f"unexpected: {exc}")
                bad.append((text, f"could not be interpreted ({type(exc).__name__})"))
                continue
            good.append(value)
            entry["accepted"].append({"reasoning": reasoning, "value": _jsonable(value)})
        return good, bad


def _jsonable(value):
    if isinstance(value, TaskGraph):
        return value.to_dict()
    return [region_json(r) for r in value]


# --------------------------------------------------------------------------------------------
# maze-grid geometry for the offline proposers
# --------------------------------------------------------------------------------------------
_STEPS = [(-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1)]


def _nearest_free_cell(maze, xy) -> tuple[int, int]:
    r, c = (int(v) for v in maze.xy_to_cell(np.asarray(xy, dtype=float)))
    if maze.passable(r, c):
        return (r, c)
    cells = maze.passable_cells()
    centres = maze.cell_to_xy(np.array([a for a, _ in cells]), np.array([b for _, b in cells]))
    return cells[int(np.argmin(np.linalg.norm(centres - np.asarray(xy), axis=1)))]


def grid_path(maze, src: tuple[int, int], dst: tuple[int, int], rng: np.random.Generator | None = None,
              noise: float = 0.0) -> list[tuple[int, int]]:
    """Shortest 8-connected free-cell path (no corner cutting); ``noise`` > 0 randomises step costs."""
    dist = {src: 0.0}
    prev: dict = {}
    heap = [(0.0, src)]
    costs: dict = {}
    while heap:
        d, cell = heapq.heappop(heap)
        if cell == dst:
            break
        if d > dist.get(cell, math.inf):
            continue
        r, c = cell
        for dr, dc in _STEPS:
            nb = (r + dr, c + dc)
            if not maze.passable(*nb):
                continue
            if dr and dc and not (maze.passable(r + dr, c) and maze.passable(r, c + dc)):
                continue
            step = math.sqrt(2.0) if dr and dc else 1.0
            if noise > 0 and rng is not None:
                key = (cell, nb) if cell < nb else (nb, cell)
                if key not in costs:
                    costs[key] = 1.0 + noise * rng.random()
                step *= costs[key]
            nd = d + step
            if nd < dist.get(nb, math.inf):
                dist[nb], prev[nb] = nd, cell
                heapq.heappush(heap, (nd, nb))
    if dst not in dist:
        return []
    path = [dst]
    while path[-1] != src:
        path.append(prev[path[-1]])
    return path[::-1]


def clearance(maze, pts) -> np.ndarray:
    """Distance of each point from the nearest wall or hazard (negative inside one)."""
    return maze.obstacles.signed_distance(np.asarray(pts, dtype=float))


def segment_clear(maze, a, b, margin: float) -> bool:
    """True if the straight segment a-b stays at least ``margin`` metres away from every wall."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    k = max(2, int(np.ceil(np.linalg.norm(b - a) / (0.1 * maze.cell_size))) + 1)
    t = np.linspace(0.0, 1.0, k)[:, None]
    return bool(np.all(clearance(maze, a + t * (b - a)) >= margin))


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

    def __init__(self, seed: int = 0, radius: tuple[float, float] = (0.3, 0.5), max_waypoints: int = 32):
        super().__init__()
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
        return bool(x0 < xy[0] < x1 and y0 < xy[1] < y1 and clearance(maze, xy) >= margin_cells * maze.cell_size)

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

    def propose_split(self, q: EdgeQuery, w: int, feedback: Sequence[CandidateFeedback] = ()) -> list[list[Region]]:
        self.queries += 1
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

    def propose_graph(self, q: GraphQuery, w: int, feedback: Sequence[GraphFeedback] = ()) -> list[TaskGraph]:
        """The same per edge: each edge of the input graph (or the weakest edge of the best earlier graph)."""
        self.queries += 1
        out = []
        for j in range(w):
            if feedback:
                best = max(feedback, key=_graph_score)
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
                splice(g, u, v, wps)
            out.append(g)
        self.history.append({"kind": "task graph", "round": 1 + bool(feedback),
                             "accepted": [{"reasoning": self.name, "value": g.to_dict()} for g in out],
                             "rejected": [], "reasked": False})
        return out


def splice(graph: TaskGraph, u: str, v: str, waypoints: Sequence[Region]) -> list[str]:
    """Replace edge u -> v of ``graph`` (in place) by u -> x1 -> ... -> v; returns the new vertex names.

    New vertices are intermediates (``refines=None``); new edges keep the avoid set and the
    ``parent`` of the edge they replace, so the result refines the original (Theorem 4.1).
    """
    if not waypoints:
        return []
    avoid = graph.avoid(u, v)
    parent = graph.g.edges[u, v]["parent"]
    graph.g.remove_edge(u, v)
    names = [graph.add_vertex(None, w, refines=None) for w in waypoints]
    chain = [u, *names, v]
    for a, b in zip(chain, chain[1:]):
        graph.add_edge(a, b, avoid, parent=parent)
    return names


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

    def _route_points(self, maze, a_xy, b_xy, j, rng, margin_cells, max_leg) -> list[np.ndarray]:
        src, dst = _nearest_free_cell(maze, a_xy), _nearest_free_cell(maze, b_xy)
        path = grid_path(maze, src, dst, rng, noise=0.0 if j == 0 else 0.6)
        if not path:
            return []
        cells = np.array(path)
        pts = np.concatenate([np.asarray(a_xy, float)[None], maze.cell_to_xy(cells[:, 0], cells[:, 1]),
                              np.asarray(b_xy, float)[None]])
        keep = pull_string(maze, pts, margin_cells * maze.cell_size)
        # halve legs that are long along the path
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
        pts = self._route_points(maze, a, b, j, rng, margin, max_leg)
        while len(pts) > self.max_waypoints and max_leg < 4 * reach + 8:  # too many: longer legs, turns kept
            max_leg += 1
            pts = self._route_points(maze, a, b, j, rng, margin, max_leg)
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


# --------------------------------------------------------------------------------------------
# factory
# --------------------------------------------------------------------------------------------
def make_proposer(spec: str, *, seed: int = 0, record_path: str | Path | None = None, **client_kw) -> Proposer:
    """``geometric`` | ``random`` | ``replay:PATH`` | ``litellm:MODEL`` (extra keywords go to LiteLLMClient)."""
    kind, _, rest = str(spec).partition(":")
    if kind == "geometric" and not rest:
        proposer: Proposer = GeometricProposer(seed=seed)
    elif kind == "random" and not rest:
        proposer = RandomProposer(seed=seed)
    elif kind == "replay" and rest:
        proposer = VLMProposer(ReplayClient(rest), spec=spec)
    elif kind == "litellm" and rest:
        proposer = VLMProposer(LiteLLMClient(rest, record_path=record_path, **client_kw), spec=spec)
    else:
        raise SpecrefineError(f"invalid proposer {spec!r}: use geometric, random, replay:PATH or litellm:MODEL")
    log.info("proposer: %s", proposer.name)
    return proposer
