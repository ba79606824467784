"""``imperfect``: a VLM-like proposer with seeded, documented error modes. It is NOT a VLM.

It plans the route the ``geometric`` stand-in would (the turns of the shortest free-space path),
corrupts it the way vision-language models get spatial plans wrong, and writes the answer as the
JSON text a VLM would send. That text goes through the same parsing, validation, re-ask and
validity checks as a real reply (it is answered by a :class:`~specrefine.vlm.VLMClient` inside a
:class:`~specrefine.proposers.vlm.VLMProposer`), so a waypoint inside a wall is rejected exactly as a
real one would be. Its random stream is its own (seeded from ``--seed``), separate from the
evaluator's.

Error modes (``ImperfectConfig``; lengths in maze cells, probabilities per reply or per turn):

* position error: each waypoint moved by a Gaussian offset (``position_sigma``), not snapped to
  free space; coordinates rounded to a coarse grid (``coord_grid``);
* region size error: radius log-normal around ``radius`` (``radius_log_sigma``); a pull toward the
  nearest convex wall corner (``corner_pull``: hugging corners);
* missing turns: each turn dropped (``p_drop_turn``); legs not capped at the policy's reach
  (``p_uncapped``);
* false openings: the route planned on a map with one wall cell falsely opened (``p_false_opening``,
  the thin wall cell nearest the straight line between the ends); wrong branch (``p_wrong_branch``):
  the route planned greedily, each step costing more the farther it is from the straight line, so
  it takes the opening nearest the line even where another is shorter;
* a whole reply with the y axis mirrored (``p_mirror_y``); unparseable replies (``p_unparseable``);
* feedback use: a follow-up repairs the weakest leg with probability ``rho``, otherwise (half and
  half) it repairs another leg, or repeats an earlier answer with jitter;
* whole-graph queries only: the input graph's subgoals ignored (``p_ignore_subgoals``).

Misreadings, added after every corrector lever had been designed (2026-12-07), as error kinds none of them had met
(every preset leaves them at 0; they draw from a random stream of their own, so a configuration without them replies
exactly as before they existed):

* a whole reply with x and y swapped (``p_swap_xy``: a picture's rows and columns confused);
* every waypoint of every reply moved ``bias`` cells in one direction, drawn once per run (a misregistered origin:
  asking again does not average it away);
* edge queries only: the waypoints listed out of order (``p_shuffle``), the list cut to its first half while the
  JSON stays valid (``p_truncate``), or the previous edge's answer given again (``p_stale``: the context confused).

The same model answers edge queries and whole-graph queries (a whole-graph reply is the corrupted
route of every edge of the input graph). ``alpha`` grows the position error, the turn-drop and the
false-opening probabilities with the number of turns T the query spans: x (1 + alpha (T - 1)).
``alpha = 0`` leaves the paper's hypothesis (errors grow with the span of a query) out of the model;
``alpha > 0`` builds it in.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from ..core.errors import SpecrefineError
from ..core.regions import Box, Disc
from ..vlm import VLMClient
from .geometric import GeometricProposer, reach_cells
from .schema import region_json
from .vlm import VLMProposer


@dataclass(frozen=True)
class ImperfectConfig:
    position_sigma: float = 0.0  # cells: std of the Gaussian offset of each waypoint
    coord_grid: float = 0.0  # cells: coordinates rounded to multiples of this (0: two decimals)
    radius: float = 0.4  # cells: nominal waypoint radius
    radius_log_sigma: float = 0.0  # std of log(radius)
    corner_pull: float = 0.0  # 0..1: fraction of the way toward the nearest convex wall corner
    p_drop_turn: float = 0.0  # each turn of the route left out
    p_uncapped: float = 0.0  # a reply that does not cap legs at the policy's reach
    p_false_opening: float = 0.0  # a reply planned with one wall cell falsely open
    p_wrong_branch: float = 0.0  # a reply that takes the opening nearest the straight line
    p_mirror_y: float = 0.0  # a reply with y mirrored (image rows read as y)
    p_unparseable: float = 0.0  # a reply that is not valid JSON
    rho: float = 1.0  # a follow-up repairs the weakest leg
    p_ignore_subgoals: float = 0.0  # a whole-graph reply that plans start -> goal, ignoring subgoals
    alpha: float = 0.0  # error growth per extra turn the query spans
    p_swap_xy: float = 0.0  # a reply with x and y swapped
    bias: float = 0.0  # cells: every waypoint moved this far, in one direction drawn once per run
    p_shuffle: float = 0.0  # an edge reply with its waypoints out of order
    p_truncate: float = 0.0  # an edge reply cut to the first half of its waypoints
    p_stale: float = 0.0  # an edge reply that repeats the previous edge reply's waypoints

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
                raise SpecrefineError(f"imperfect: {f.name} must be a finite number >= 0, got {value!r}")
            if (f.name.startswith("p_") or f.name in ("rho", "corner_pull")) and value > 1:
                raise SpecrefineError(f"imperfect: {f.name} is a probability (0..1), got {value!r}")
        if self.radius <= 0:
            raise SpecrefineError("imperfect: radius must be > 0")


#: the presets (reasons in docs/proposers.md; fixed before any comparison was run)
PRESETS = {
    "mild": ImperfectConfig(position_sigma=0.15, coord_grid=0.0, radius_log_sigma=0.2, corner_pull=0.1,
                            p_drop_turn=0.1, p_uncapped=0.2, p_false_opening=0.05, p_wrong_branch=0.1,
                            p_mirror_y=0.0, p_unparseable=0.02, rho=0.8, p_ignore_subgoals=0.05),
    "moderate": ImperfectConfig(position_sigma=0.3, coord_grid=0.1, radius_log_sigma=0.35, corner_pull=0.25,
                                p_drop_turn=0.25, p_uncapped=0.5, p_false_opening=0.15, p_wrong_branch=0.25,
                                p_mirror_y=0.05, p_unparseable=0.05, rho=0.6, p_ignore_subgoals=0.15),
    "severe": ImperfectConfig(position_sigma=0.5, coord_grid=0.25, radius_log_sigma=0.5, corner_pull=0.4,
                              p_drop_turn=0.4, p_uncapped=0.8, p_false_opening=0.3, p_wrong_branch=0.4,
                              p_mirror_y=0.1, p_unparseable=0.1, rho=0.4, p_ignore_subgoals=0.3),
}
#: the growth of error with the turns a query spans, for the "alpha on" arm of the comparison
ALPHA_ON = 0.1


def parse_imperfect(text: str) -> ImperfectConfig:
    """``PRESET``, ``key=value,...`` or ``PRESET,key=value,...`` -> config (SpecrefineError on a bad one)."""
    config, known = ImperfectConfig(), {f.name for f in fields(ImperfectConfig)}
    items = [t.strip() for t in str(text).split(",") if t.strip()]
    if not items:
        raise SpecrefineError(f"imperfect: give a preset ({', '.join(PRESETS)}) or key=value pairs")
    if "=" not in items[0]:
        if items[0] not in PRESETS:
            raise SpecrefineError(f"imperfect: unknown preset {items[0]!r} (use {', '.join(PRESETS)})")
        config, items = PRESETS[items[0]], items[1:]
    changes = {}
    for item in items:
        key, eq, value = (s.strip() for s in item.partition("="))
        if not eq:
            raise SpecrefineError(f"imperfect: {item!r} is not key=value")
        if key not in known:
            raise SpecrefineError(f"imperfect: unknown parameter {key!r} (known: {', '.join(sorted(known))})")
        try:
            changes[key] = float(value)
        except ValueError:
            raise SpecrefineError(f"imperfect: {key}={value!r} is not a number") from None
    return replace(config, **changes)


class ErrorModelClient(VLMClient):
    """Answers a proposer's messages with corrupted plans, as JSON text (``context`` names the query)."""

    model = "imperfect"

    def __init__(self, config: ImperfectConfig, seed: int = 0):
        super().__init__()
        self.cfg = config
        self.rng = np.random.default_rng([int(seed), 0x1A9E])  # not the evaluator's stream
        self.name = "imperfect"
        self.context: tuple | None = None  # (kind, query, feedback), set before each query
        self.injected: list[dict] = []  # per reply: which errors were injected (for tests and analysis)
        self._planner = GeometricProposer(seed=seed)
        self._corners: dict = {}
        self._misread_rng = np.random.default_rng([int(seed), 0x5EAD])  # the misreadings' own stream
        self._bias_angle = float(self._misread_rng.uniform(0.0, 2 * math.pi))
        self._last_waypoints: list | None = None  # the previous edge reply's, for p_stale

    def complete(self, messages, n: int = 1) -> list[str]:
        kind, q, feedback = self.context
        self.calls += 1
        self.attempts += 1
        reply = self._split_reply if kind == "split" else self._graph_reply
        return [reply(q, feedback) for _ in range(n)]

    # --- replies ---------------------------------------------------------------------------------
    def _split_reply(self, q, feedback) -> str:
        a, b = _centre(q.start), _centre(q.goal)
        log = {"kind": "split", "span_turns": self._turns(q.maze, a, b)}
        mult = self._mult(log["span_turns"])
        if feedback:
            regions = self._follow_up([list(f.waypoints) for f in feedback],
                                      [list(f.subtask_success) for f in feedback], [a, b], q, mult, log)
        else:
            regions = self._route(q.maze, a, b, q.agent, mult, log)
        waypoints = [self._region_json(q.maze, r) for r in regions]
        return self._finish({"reasoning": _reasoning(log), "waypoints": waypoints}, q.maze, log)

    def _graph_reply(self, q, feedback) -> str:
        g, maze = q.graph, q.maze
        log = {"kind": "graph", "span_turns": sum(self._turns(maze, _centre(g.region(u)), _centre(g.region(v)))
                                                  for u, v in g.edges())}
        mult = self._mult(log["span_turns"])
        base, route = g, lambda u, v: self._route(maze, _centre(base.region(u)), _centre(base.region(v)), q.agent,
                                                  mult, log)
        if feedback:
            base, chains = self._graph_follow_up(feedback, maze, log)
            chains = {e: route(*e) if chains[e] is None else chains[e] for e in chains}
        elif self.rng.random() < self.cfg.p_ignore_subgoals:
            log["ignored_subgoals"] = True
            chains = {(g.initial, sorted(g.finals)[0]): None}
            chains = {e: route(*e) for e in chains}
        else:
            chains = {e: route(*e) for e in g.edges()}
        answer = _graph_json(g, base, chains, lambda r: self._region_json(maze, r), _reasoning(log))
        return self._finish(answer, maze, log)

    def _finish(self, answer: dict, maze, log: dict) -> str:
        answer = self._misread(answer, maze, log)
        if self.rng.random() < self.cfg.p_mirror_y:
            log["mirrored_y"] = True
            answer = _mirror_y(answer)
        text = json.dumps(answer)
        if self.rng.random() < self.cfg.p_unparseable:
            log["unparseable"] = True
            text = _garble(text, self.rng)
        self.injected.append(log)
        return text

    def _misread(self, answer: dict, maze, log: dict) -> dict:
        """The misreadings (module docstring), each drawn only where its probability is set."""
        cfg, rng = self.cfg, self._misread_rng
        if "waypoints" in answer:
            answer = {**answer, "waypoints": self._misordered(list(answer["waypoints"]), log)}
        if cfg.p_swap_xy and rng.random() < cfg.p_swap_xy:
            log["swapped_xy"] = True
            answer = _moved(answer, lambda x, y: (y, x))
        if cfg.bias:
            dx, dy = cfg.bias * maze.cell_size * np.array([math.cos(self._bias_angle), math.sin(self._bias_angle)])
            answer = _moved(answer, lambda x, y: (round(x + dx, 3), round(y + dy, 3)))
        return answer

    def _misordered(self, waypoints: list, log: dict) -> list:
        cfg, rng = self.cfg, self._misread_rng
        if cfg.p_stale and rng.random() < cfg.p_stale and self._last_waypoints:
            log["stale"] = True
            waypoints = list(self._last_waypoints)
        if cfg.p_shuffle and rng.random() < cfg.p_shuffle and len(waypoints) > 1:
            log["shuffled"] = True
            waypoints = [waypoints[i] for i in rng.permutation(len(waypoints))]
        if cfg.p_truncate and rng.random() < cfg.p_truncate and len(waypoints) > 1:
            log["truncated"] = len(waypoints) - len(waypoints) // 2
            waypoints = waypoints[: len(waypoints) // 2]
        self._last_waypoints = waypoints
        return waypoints

    # --- follow-ups ------------------------------------------------------------------------------
    def _follow_up(self, answers, successes, ends, q, mult, log) -> list:
        """Edge split round 2: repair the weakest leg of the best answer (rho), another leg, or repeat."""
        scores = [float(np.prod(s)) if len(s) == len(w) + 1 else 0.0 for w, s in zip(answers, successes)]
        best = int(np.argmax(scores))
        waypoints, legs = answers[best], successes[best]
        if len(legs) != len(waypoints) + 1:
            legs = [0.0] * (len(waypoints) + 1)
        leg = self._leg_to_repair(legs, log)
        if leg is None:
            return self._jittered(answers[int(self.rng.integers(len(answers)))], q.maze)
        points = [ends[0], *(_centre(w) for w in waypoints), ends[1]]
        new = self._route(q.maze, points[leg], points[leg + 1], q.agent, mult, log)
        return waypoints[:leg] + new + waypoints[leg:]

    def _leg_to_repair(self, legs, log) -> int | None:
        weakest = int(np.argmin(legs))
        u = self.rng.random()
        if u < self.cfg.rho:
            log["repair"] = "weakest"
            return weakest
        others = [i for i in range(len(legs)) if i != weakest]
        if others and u < self.cfg.rho + (1 - self.cfg.rho) / 2:
            log["repair"] = "wrong-leg"
            return int(self.rng.choice(others))
        log["repair"] = "repeat"
        return None

    def _graph_follow_up(self, feedback, maze, log) -> tuple:
        """One-shot round 2: the best earlier graph with its weakest edge (rho) or another edge re-planned
        (``None`` = re-plan), or that graph repeated with its waypoints jittered."""
        best = max(feedback, key=lambda f: f.success if f.success is not None else 0.0)
        edges = best.graph.edges()
        leg = self._leg_to_repair([best.edge_success.get(e, 1.0) for e in edges], log) if edges else None
        if leg is not None:
            return best.graph, {e: (None if i == leg else []) for i, e in enumerate(edges)}
        moved = best.graph.copy()
        for v in moved.vertices():
            if moved.g.nodes[v]["refines"] is None:
                moved.g.nodes[v]["region"] = self._jittered([moved.region(v)], maze)[0]
        return moved, {e: [] for e in edges}

    def _jittered(self, regions, maze) -> list:
        sigma = max(self.cfg.position_sigma, 0.1) * maze.cell_size
        return [_shifted(r, self.rng.normal(0.0, sigma, 2)) for r in regions]

    # --- the corrupted route ---------------------------------------------------------------------
    def _route(self, maze, a, b, agent, mult, log) -> list:
        cfg, rng = self.cfg, self.rng
        plan_maze, cost = maze, None
        if rng.random() < min(1.0, cfg.p_false_opening * mult):
            plan_maze = _falsely_opened(maze, a, b)
            log["false_opening"] = plan_maze is not maze
        if rng.random() < cfg.p_wrong_branch:
            log["wrong_branch"] = True
            cost = _near_line_cost(maze, a, b)
        turns = self._planner._route_points(plan_maze, a, b, 0, rng, 0.35, 10**6, cell_cost=cost)
        keep = rng.random(len(turns)) >= min(1.0, cfg.p_drop_turn * mult)
        log["turns"] = log.get("turns", 0) + len(turns)
        log["dropped"] = log.get("dropped", 0) + int((~keep).sum())
        points = [p for p, k in zip(turns, keep) if k]
        if rng.random() >= cfg.p_uncapped:
            points = _capped(points, a, b, reach_cells(maze, agent) * maze.cell_size)
        else:
            log["uncapped"] = log.get("uncapped", 0) + 1
        if not points:  # a VLM asked for a split gives at least one waypoint: halfway
            points = [(np.asarray(a) + np.asarray(b)) / 2]
        return [self._corrupt_point(maze, p, mult) for p in points]

    def _corrupt_point(self, maze, p, mult) -> tuple:
        cfg, cell = self.cfg, maze.cell_size
        p = np.asarray(p, dtype=float)
        if cfg.corner_pull > 0:
            corner = self._nearest_corner(maze, p)
            if corner is not None:
                p = p + cfg.corner_pull * (corner - p)
        p = p + self.rng.normal(0.0, cfg.position_sigma * mult * cell, 2)
        r = cfg.radius * cell * math.exp(self.rng.normal(0.0, cfg.radius_log_sigma))
        return (p, r)

    def _nearest_corner(self, maze, p):
        if maze not in self._corners:
            self._corners[maze] = convex_corners(maze)
        corners = self._corners[maze]
        if not len(corners):
            return None
        return corners[int(np.argmin(np.linalg.norm(corners - p, axis=1)))]

    def _region_json(self, maze, region) -> dict:
        if isinstance(region, tuple):  # a corrupted point and radius, written as a VLM would
            (x, y), r = region
            return {"type": "disc", "center": [self._round(maze, x), self._round(maze, y)], "radius": round(r, 2)}
        return region_json(region)

    def _round(self, maze, v: float) -> float:
        step = self.cfg.coord_grid * maze.cell_size
        return round(round(v / step) * step, 3) if step > 0 else round(float(v), 2)

    # --- how much a query spans ------------------------------------------------------------------
    def _turns(self, maze, a, b) -> int:
        return len(self._planner._route_points(maze, a, b, 0, None, 0.35, 10**6))

    def _mult(self, turns: int) -> float:
        return 1.0 + self.cfg.alpha * max(0, turns - 1)


class ImperfectProposer(VLMProposer):
    """``imperfect:PRESET`` or ``imperfect:key=value,...``: a VLM-like error model, offline. NOT a VLM."""

    is_vlm = False
    sees_images = False  # it answers from the query's geometry (``client.context``), never from a picture

    def __init__(self, config: ImperfectConfig, *, spec: str = "imperfect", seed: int = 0):
        super().__init__(ErrorModelClient(config, seed), spec=spec)
        self.config = config
        self.name = f"{spec} (VLM-like error model, offline, not a VLM)"

    @property
    def calls(self) -> int:  # no VLM was called
        return 0

    def split(self, q, w, feedback=()):
        self.client.context = ("split", q, list(feedback))
        return super().split(q, w, feedback)

    def graph(self, q, w, feedback=()):
        self.client.context = ("graph", q, list(feedback))
        return super().graph(q, w, feedback)

    def describe(self) -> dict:
        return {**super().describe(), "error_model": asdict(self.config)}


# --- geometry helpers ------------------------------------------------------------------------------
def _centre(region) -> np.ndarray:
    return np.asarray(region.centre(), dtype=float)


def convex_corners(maze) -> np.ndarray:
    """Grid vertices where exactly one of the four cells around is wall: the corners one turns around."""
    out = []
    for r in range(1, maze.rows):
        for c in range(1, maze.cols):
            around = [(r - 1, c - 1), (r - 1, c), (r, c - 1), (r, c)]
            if sum(not maze.is_free(*x) for x in around) == 1:
                centre = maze.cell_to_xy(r, c)
                out.append(centre + np.array([-0.5, 0.5]) * maze.cell_size)
    return np.array(out).reshape(-1, 2)


def _near_line_cost(maze, a, b):
    """Step cost that grows with the distance from the straight line a-b: the greedy branch."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    length2 = float(d @ d) or 1.0

    def cost(cell):
        p = maze.cell_to_xy(*cell)
        t = np.clip((p - a) @ d / length2, 0.0, 1.0)
        return 1.0 + 4.0 * float(np.linalg.norm(p - (a + t * d))) / maze.cell_size

    return cost


def _falsely_opened(maze, a, b):
    """The maze with the thin wall cell nearest the straight line a-b opened (or the maze, if none)."""
    from ..core.mazes import Maze

    thin = [(r, c) for r in range(1, maze.rows - 1) for c in range(1, maze.cols - 1)
            if maze.grid[r][c] == "#" and ((maze.is_free(r - 1, c) and maze.is_free(r + 1, c))
                                           or (maze.is_free(r, c - 1) and maze.is_free(r, c + 1)))]
    if not thin:
        return maze
    cost = _near_line_cost(maze, a, b)
    r, c = min(thin, key=cost)
    grid = list(maze.grid)
    grid[r] = grid[r][:c] + "." + grid[r][c + 1:]
    return Maze(maze.name, tuple(grid), maze.cell_size)


def _capped(points, a, b, reach: float) -> list:
    """Insert evenly spaced points on every straight leg longer than ``reach`` metres."""
    ends = [np.asarray(a, float), *(np.asarray(p, float) for p in points), np.asarray(b, float)]
    out = []
    for i, (p, q) in enumerate(zip(ends, ends[1:])):
        pieces = max(1, math.ceil(float(np.linalg.norm(q - p)) / reach - 1e-9))
        out += [p + (q - p) * s / pieces for s in range(1, pieces)]
        if i < len(points):
            out.append(q)
    return out


def _graph_json(original, base, chains: dict, region_json_of, reasoning: str) -> dict:
    """A whole-graph reply: each ``(u, v)`` of ``chains`` (vertices of ``base``) becomes u -> waypoints -> v.

    Vertices of ``base`` that no chain touches are left out (a reply that ignores subgoals drops
    them); a vertex that keeps an original vertex's set is written with ``"region": null``.
    """
    names = {v for e in chains for v in e}
    vertices, edges = [], []
    for v in base.vertices():
        if v not in names:
            continue
        refines = base.g.nodes[v]["refines"]
        same = refines is not None and refines in original.g and base.region(v) == original.region(refines)
        vertices.append({"name": v, "refines": refines, "region": None if same else region_json_of(base.region(v))})
    fresh = (f"w{i}" for i in range(1, 10**6))
    for (u, v), waypoints in chains.items():
        chain = [u]
        for w in waypoints:
            name = next(fresh)
            while name in base.g:
                name = next(fresh)
            vertices.append({"name": name, "refines": None, "region": region_json_of(w)})
            chain.append(name)
        edges += [{"u": x, "v": y} for x, y in zip(chain, [*chain[1:], v])]
    finals = sorted(f for f in base.finals if f in names)
    return {"reasoning": reasoning, "vertices": vertices, "edges": edges, "initial": base.initial, "finals": finals}


def _shifted(region, offset):
    """``region`` moved by ``offset`` (a follow-up that repeats an earlier answer with jitter)."""
    dx, dy = (float(v) for v in offset)
    if isinstance(region, Disc):
        return Disc(region.cx + dx, region.cy + dy, region.r)
    if isinstance(region, Box):
        return Box(region.xmin + dx, region.ymin + dy, region.xmax + dx, region.ymax + dy)
    return region


def _mirror_y(answer: dict) -> dict:
    return _moved(answer, lambda x, y: (x, -y))


def _moved(answer: dict, f) -> dict:
    """``answer`` with every region's coordinates mapped by ``f`` ((x, y) -> (x, y)); a box stays axis-aligned."""
    def move(region):
        if not isinstance(region, dict):
            return region
        out = dict(region)
        if "center" in out:
            out["center"] = list(f(*out["center"]))
        if "min" in out and "max" in out:
            a, b = f(*out["min"]), f(*out["max"])
            out["min"], out["max"] = [min(a[0], b[0]), min(a[1], b[1])], [max(a[0], b[0]), max(a[1], b[1])]
        return out

    answer = dict(answer)
    if "waypoints" in answer:
        answer["waypoints"] = [move(w) for w in answer["waypoints"]]
    if "vertices" in answer:
        answer["vertices"] = [{**v, "region": move(v["region"])} for v in answer["vertices"]]
    return answer


def _garble(text: str, rng) -> str:
    """An unparseable reply: cut off mid-answer, or prose without the JSON."""
    if rng.random() < 0.5:
        return text[: int(rng.integers(1, max(2, len(text) // 2)))]
    return "I would route the agent along the corridor and place a waypoint at each corner of the walls."


def _reasoning(log: dict) -> str:
    parts = [f"imperfect error model (offline, not a VLM): {log.get('turns', 0)} turns planned, "
             f"{log.get('dropped', 0)} dropped"]
    for key in ("false_opening", "wrong_branch", "uncapped", "ignored_subgoals", "repair"):
        if log.get(key):
            parts.append(f"{key}={log[key]}")
    return "; ".join(parts)
