"""The answer schema of a proposal (pydantic) and its validation against a maze.

:func:`parse_split` reads an edge split (an ordered list of waypoint regions) and
:func:`parse_graph` a whole task graph (the one-shot baseline).  A bad reply raises
:class:`~specrefine.core.errors.ProposalRejected` with a one-line reason.
"""

from __future__ import annotations

import json
import logging
import re
from typing import Annotated, Any, Literal

import networkx as nx
import numpy as np
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, ValidationError, model_validator

from ..core.errors import ProposalRejected
from ..core.graph import TaskGraph, infer_parents
from ..core.regions import Box, Disc, Region, union

log = logging.getLogger(__name__)

_TYPE_ALIASES = {"circle": "disc", "disk": "disc", "ball": "disc", "rectangle": "box", "rect": "box",
                 "square": "box", "aabb": "box"}


def _normalise_region(d: Any) -> Any:
    if not isinstance(d, dict):
        return d
    d = dict(d)
    if "centre" in d and "center" not in d:
        d["center"] = d.pop("centre")
    if "r" in d and "radius" not in d:
        d["radius"] = d.pop("r")
    if "cx" in d and "cy" in d and "center" not in d:
        d["center"] = [d.pop("cx"), d.pop("cy")]
    if all(k in d for k in ("xmin", "ymin", "xmax", "ymax")) and "min" not in d:
        d["min"] = [d.pop("xmin"), d.pop("ymin")]
        d["max"] = [d.pop("xmax"), d.pop("ymax")]
    kind = d.get("type")
    if isinstance(kind, str):
        kind = kind.strip().lower()
        d["type"] = _TYPE_ALIASES.get(kind, kind)
    elif kind is None:
        d["type"] = "disc" if "radius" in d else "box" if "min" in d else None
    return d


class _Strict(BaseModel):
    model_config = ConfigDict(extra="ignore", allow_inf_nan=False)


class DiscSpec(_Strict):
    type: Literal["disc"]
    center: tuple[float, float]
    radius: float = Field(gt=0)

    def to_region(self) -> Region:
        return Disc(self.center[0], self.center[1], self.radius)


class BoxSpec(_Strict):
    type: Literal["box"]
    min: tuple[float, float]
    max: tuple[float, float]

    @model_validator(mode="after")
    def _ordered(self):
        if not (self.max[0] > self.min[0] and self.max[1] > self.min[1]):
            raise ValueError("box needs max > min in both x and y")
        return self

    def to_region(self) -> Region:
        return Box(self.min[0], self.min[1], self.max[0], self.max[1])


RegionSpec = Annotated[DiscSpec | BoxSpec, Field(discriminator="type"), BeforeValidator(_normalise_region)]


class SplitProposal(_Strict):
    """One edge-split candidate: waypoint regions x1..x_{k-1}, visited in order between u and v."""

    reasoning: str = ""
    waypoints: list[RegionSpec] = Field(min_length=1)


class VertexSpec(_Strict):
    name: str = Field(min_length=1)
    region: RegionSpec | None = None
    refines: str | None = None


class EdgeSpec(_Strict):
    u: str
    v: str

    @model_validator(mode="before")
    @classmethod
    def _aliases(cls, d):
        if isinstance(d, dict):
            d = dict(d)
            for a, b in (("from", "u"), ("to", "v"), ("source", "u"), ("target", "v")):
                if a in d and b not in d:
                    d[b] = d.pop(a)
        elif isinstance(d, (list, tuple)) and len(d) == 2:
            d = {"u": d[0], "v": d[1]}
        return d


class GraphProposal(_Strict):
    """A whole task graph (the one-shot VLM baseline)."""

    reasoning: str = ""
    vertices: list[VertexSpec] = Field(min_length=1)
    edges: list[EdgeSpec] = Field(min_length=1)
    initial: str
    finals: list[str] = Field(min_length=1)


def region_json(region: Region, digits: int = 3) -> dict:
    """A region in the answer schema's JSON form (unions as ``{"type": "union", "members": [...]}``)."""
    r = lambda v: round(float(v), digits)  # noqa: E731
    if isinstance(region, Disc):
        return {"type": "disc", "center": [r(region.cx), r(region.cy)], "radius": r(region.r)}
    if isinstance(region, Box):
        return {"type": "box", "min": [r(region.xmin), r(region.ymin)], "max": [r(region.xmax), r(region.ymax)]}
    return {"type": "union", "members": [region_json(m, digits) for m in region.parts()]}


def parse_json(text: str | None) -> Any:
    """The JSON object in a reply: bare, in a ```json fence, or the outermost {...}; else ProposalRejected."""
    if not text or not text.strip():
        raise ProposalRejected("empty reply")
    candidates = [text.strip()]
    fence = re.search(r"```(?:json|JSON)?\s*(.*?)```", text, re.DOTALL)
    if fence:
        candidates.append(fence.group(1).strip())
    lo, hi = text.find("{"), text.rfind("}")
    if 0 <= lo < hi:
        candidates.append(text[lo:hi + 1])
    err = None
    for c in candidates:
        try:
            return json.loads(c)
        except json.JSONDecodeError as exc:
            err = exc
    raise ProposalRejected(f"reply is not valid JSON ({err.msg} at line {err.lineno} column {err.colno})")


def _schema_reason(exc: ValidationError) -> str:
    errs = exc.errors()
    parts = []
    for e in errs[:2]:
        loc = ".".join(str(x) for x in e.get("loc", ())) or "reply"
        parts.append(f"{loc}: {e.get('msg', 'invalid')}")
    more = f" (+{len(errs) - 2} more)" if len(errs) > 2 else ""
    return "reply does not follow the schema: " + "; ".join(parts) + more


def check_region(region: Region, maze, what: str = "waypoint") -> str | None:
    """Why ``region`` is unusable as a waypoint in ``maze`` (None if it is fine)."""
    c = np.asarray(region.centre(), dtype=float)
    x0, y0, x1, y1 = maze.bounds()
    size = max(maze.width, maze.height)
    tiny = 0.01 * maze.cell_size
    if not np.all(np.isfinite(c)):
        return f"{what} has a non-finite centre"
    if not (x0 <= c[0] <= x1 and y0 <= c[1] <= y1):
        return (f"{what} centre ({c[0]:.3g}, {c[1]:.3g}) lies outside the maze "
                f"(x in [{x0:g}, {x1:g}], y in [{y0:g}, {y1:g}])")
    if bool(maze.obstacles.contains(c)):
        row, col = (int(v) for v in maze.xy_to_cell(c))
        kind = "wall" if bool(maze.walls.contains(c)) else "hazard"
        return f"{what} centre ({c[0]:.3g}, {c[1]:.3g}) lies inside a {kind} (cell row {row}, col {col})"
    if isinstance(region, Disc):
        if region.r > size:
            return f"{what} radius {region.r:.3g} is larger than the maze ({size:g})"
        if region.r < tiny:
            return f"{what} radius {region.r:.3g} is below 1% of a cell ({tiny:g})"
    elif isinstance(region, Box):
        w, h = region.xmax - region.xmin, region.ymax - region.ymin
        if max(w, h) > size:
            return f"{what} box side {max(w, h):.3g} is larger than the maze ({size:g})"
        if min(w, h) < tiny:
            return f"{what} box side {min(w, h):.3g} is below 1% of a cell ({tiny:g})"
    return None


def snapped(region: Region, maze, clearance: float) -> Region | None:
    """``region`` moved so that its centre is the nearest point at least ``clearance`` from the maze's walls and
    hazards within one cell of where it was (on a grid of 1/20 cell); None if there is no such point."""
    c = np.asarray(region.centre(), dtype=float)
    step = maze.cell_size / 20
    offsets = np.arange(-20, 21) * step
    grid = c + np.stack(np.meshgrid(offsets, offsets), axis=-1).reshape(-1, 2)
    x0, y0, x1, y1 = maze.bounds()
    inside = (grid[:, 0] >= x0) & (grid[:, 0] <= x1) & (grid[:, 1] >= y0) & (grid[:, 1] <= y1)
    clear = grid[inside][maze.obstacles.signed_distance(grid[inside]) >= clearance]
    if not len(clear):
        return None
    dx, dy = clear[np.argmin(np.sum((clear - c) ** 2, axis=1))] - c
    if isinstance(region, Disc):
        return Disc(region.cx + dx, region.cy + dy, region.r)
    return Box(region.xmin + dx, region.ymin + dy, region.xmax + dx, region.ymax + dy)


def parse_split(text: str | None, maze, *, max_waypoints: int = 32, snap: float = 0.0
                ) -> tuple[list[Region], str]:
    """Validate one edge-split reply: ``(waypoint regions, reasoning)`` or ProposalRejected. ``snap`` > 0 (beyond the
    paper): a waypoint whose centre lies in a wall or hazard is moved to the nearest point that far from them within
    one cell (:func:`snapped`), and the reply is rejected only if there is none."""
    data = parse_json(text)
    if isinstance(data, list):  # a bare list of waypoints
        data = {"waypoints": data}
    try:
        prop = SplitProposal.model_validate(data)
    except ValidationError as exc:
        raise ProposalRejected(_schema_reason(exc)) from None
    if len(prop.waypoints) > max_waypoints:
        raise ProposalRejected(f"{len(prop.waypoints)} waypoints is more than the limit of {max_waypoints}")
    regions = []
    for i, spec in enumerate(prop.waypoints, start=1):
        region = spec.to_region()
        why = check_region(region, maze, f"waypoint {i}")
        if why and snap > 0 and " lies inside a " in why and (moved := snapped(region, maze, snap)) is not None:
            x, y = moved.centre()
            log.warning("%s: moved to (%.3g, %.3g), %.3g m clear of walls (snap)", why, x, y, snap)
            region, why = moved, check_region(moved, maze, f"waypoint {i}")
        if why:
            raise ProposalRejected(why)
        regions.append(region)
    return regions, prop.reasoning


def parse_graph(text: str | None, maze, original, *, max_vertices: int = 40):
    """Validate a one-shot whole-graph reply against ``maze`` and the ``original`` TaskGraph.

    Returns ``(TaskGraph, reasoning)``.  Vertices that keep an original vertex (``refines`` = its
    name, or the same name with ``refines`` null) keep that name and, if ``region`` is null, its
    set; all others are intermediates (``refines=None``).  Edges get the avoid set of the original
    edge they lie on (or the union of the original avoid sets) and, where a chain of
    intermediates joins original vertices ``u -> v`` that the original links, ``parent=(u, v)``.
    No refinement guarantee is implied (the paper's baseline has none).
    """
    data = parse_json(text)
    try:
        prop = GraphProposal.model_validate(data)
    except ValidationError as exc:
        raise ProposalRejected(_schema_reason(exc)) from None
    if len(prop.vertices) > max_vertices:
        raise ProposalRejected(f"{len(prop.vertices)} vertices is more than the limit of {max_vertices}")
    names = [v.name for v in prop.vertices]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise ProposalRejected(f"vertex name(s) used twice: {', '.join(sorted(dup))}")
    tg, rename = _proposed_vertices(prop, maze, original)
    initial, finals = _ends(prop, tg, rename, original)
    pairs = _proposed_edges(prop, rename)
    tg.initial = initial
    all_avoid = union(list({json.dumps(original.avoid(u, v).to_dict(), sort_keys=True): original.avoid(u, v)
                            for u, v in original.edges()}.values()))
    for a, b in pairs:
        tg.add_edge(a, b, all_avoid)
    infer_parents(tg, original)  # the original edge each chain of new waypoints implements
    for a, b in tg.edges():
        if original.has_edge(*tg.parent(a, b)):
            tg.set_avoid(a, b, original.avoid(*tg.parent(a, b)))
    if not finals & (tg.descendants(initial) | {initial}):
        raise ProposalRejected("no final vertex is reachable from the initial vertex")
    tg.finals = finals
    return tg, prop.reasoning


def _proposed_vertices(prop: GraphProposal, maze, original) -> tuple[TaskGraph, dict[str, str]]:
    """The proposal's vertices as a graph without edges, and the name each proposed name became."""
    tg = TaskGraph(original.initial)
    rename: dict[str, str] = {}
    kept: set[str] = set()
    for i, vs in enumerate(prop.vertices):
        orig = vs.refines if vs.refines is not None else (vs.name if vs.name in original else None)
        if orig is not None and orig not in original:
            raise ProposalRejected(f"vertex {vs.name!r} refines {orig!r}, which is not a vertex of the original graph")
        if vs.region is None and orig is None:
            raise ProposalRejected(f"new vertex {vs.name!r} needs a region")
        region = original.region(orig) if vs.region is None else vs.region.to_region()
        if vs.region is not None:
            why = check_region(region, maze, f"vertex {vs.name!r}")
            if why:
                raise ProposalRejected(why)
        if orig is not None and orig not in kept:
            name = orig
            kept.add(orig)
        elif vs.name not in original and vs.name not in tg and vs.name not in rename.values():
            name = vs.name
        else:
            name = f"x{i}" if f"x{i}" not in original and f"x{i}" not in tg else tg.fresh_name()
        rename[vs.name] = name
        point = original.goal_point(orig) if orig is not None and vs.region is None else None
        tg.add_vertex(name, region, refines=orig, label=vs.name, point=point)
    return tg, rename


def _ends(prop: GraphProposal, tg: TaskGraph, rename: dict[str, str], original) -> tuple[str, set[str]]:
    for who, what in ((prop.initial, "initial"), *((f, "final") for f in prop.finals)):
        if who not in rename:
            raise ProposalRejected(f"{what} vertex {who!r} is not among the vertices")
    initial = rename[prop.initial]
    if tg.refines(initial) != original.initial:
        raise ProposalRejected(f"the initial vertex must keep the original start {original.initial!r}")
    finals = {rename[f] for f in prop.finals}
    for f in finals:
        if tg.refines(f) not in original.finals:
            goals = ", ".join(sorted(original.finals))
            raise ProposalRejected(f"final vertex {f!r} must keep an original final vertex ({goals})")
    return initial, finals


def _proposed_edges(prop: GraphProposal, rename: dict[str, str]) -> list[tuple[str, str]]:
    pairs = []
    for es in prop.edges:
        for end in (es.u, es.v):
            if end not in rename:
                raise ProposalRejected(f"edge {es.u}->{es.v} uses unknown vertex {end!r}")
        a, b = rename[es.u], rename[es.v]
        if a == b:
            raise ProposalRejected(f"edge {es.u}->{es.v} is a self-loop")
        if (a, b) not in pairs:
            pairs.append((a, b))
    if not nx.is_directed_acyclic_graph(nx.DiGraph(pairs)):
        raise ProposalRejected("the edges contain a cycle (a task graph must be acyclic)")
    return pairs
