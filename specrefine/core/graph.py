"""The task graph: a DAG of reach-avoid subtasks on networkx.

Vertices carry ``region`` = I(v) and an optional representative ``point``; edges carry
``avoid`` = O(e).  Provenance makes refinement checkable (Theorem 4.1): a vertex's
``refines`` names the vertex of the original graph whose set it narrows (None for an
intermediate waypoint introduced by an edge split), and an edge's ``parent`` names the
original edge it helps to implement.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from itertools import count

import networkx as nx
import numpy as np

from .errors import GraphError, InvalidRefinement
from .regions import Region, from_dict, is_subset


class TaskGraph:
    def __init__(self, initial: str = "v0"):
        self.g = nx.DiGraph()
        self.initial = initial
        self.finals: set[str] = set()
        self._ids = count()

    # --- construction ------------------------------------------------------------
    def add_vertex(self, name: str | None, region: Region, *, point=None, refines="self", label=None) -> str:
        name = name if name is not None else self.fresh_name()
        refines = name if refines == "self" else refines
        pt = None if point is None else tuple(float(v) for v in point)
        self.g.add_node(name, region=region, point=pt, refines=refines, label=label or name)
        return name

    def add_edge(self, u: str, v: str, avoid: Region, *, parent=None) -> None:
        for x in (u, v):
            if x not in self.g:
                raise KeyError(f"unknown vertex {x!r}")
        self.g.add_edge(u, v, avoid=avoid, parent=tuple(parent) if parent else (u, v))
        if not nx.is_directed_acyclic_graph(self.g):
            self.g.remove_edge(u, v)
            raise GraphError(f"edge {u}->{v} would create a cycle")

    def fresh_name(self) -> str:
        while True:
            name = f"x{next(self._ids)}"
            if name not in self.g:
                return name

    # --- queries -----------------------------------------------------------------
    def region(self, v: str) -> Region:
        return self.g.nodes[v]["region"]

    def goal_point(self, v: str):
        pt = self.g.nodes[v]["point"]
        return None if pt is None else np.asarray(pt)

    def avoid(self, u: str, v: str) -> Region:
        return self.g.edges[u, v]["avoid"]

    def vertices(self) -> list[str]:
        return list(self.g.nodes)

    def edges(self) -> list[tuple[str, str]]:
        return list(self.g.edges)

    def successors(self, v: str) -> list[str]:
        return list(self.g.successors(v))

    def predecessors(self, v: str) -> list[str]:
        return list(self.g.predecessors(v))

    def has_vertex(self, v: str) -> bool:
        return v in self.g

    __contains__ = has_vertex

    def has_edge(self, u: str, v: str) -> bool:
        return self.g.has_edge(u, v)

    def in_degree(self, v: str) -> int:
        return self.g.in_degree(v)

    def out_degree(self, v: str) -> int:
        return self.g.out_degree(v)

    def is_chain_vertex(self, v: str) -> bool:
        """An inner vertex of a chain (neither initial nor final, one edge in, one out): narrowing it changes the
        subtasks of one path only."""
        return v != self.initial and v not in self.finals and self.in_degree(v) == 1 and self.out_degree(v) == 1

    def is_shortcut(self, u: str, v: str) -> bool:
        """u -> v skips waypoints of one split: another path u -> w -> ... -> v leaves u through a waypoint w of the
        same parent edge (refine/shortcut.py adds such edges; a split or a repair removes the edge it replaces)."""
        parent = self.parent(u, v)
        return any(w != v and self.refines(w) is None and self.parent(u, w) == parent and nx.has_path(self.g, w, v)
                   for w in self.g.successors(u))

    def label(self, v: str) -> str:
        return self.g.nodes[v]["label"]

    def refines(self, v: str) -> str | None:
        """The original vertex whose set I(v) narrows (None: an intermediate waypoint)."""
        return self.g.nodes[v]["refines"]

    def parent(self, u: str, v: str) -> tuple[str, str]:
        """The original edge that u -> v helps to implement."""
        return self.g.edges[u, v]["parent"]

    def topological_order(self) -> list[str]:
        return list(nx.topological_sort(self.g))

    def topological_layers(self) -> list[list[str]]:
        """Vertices by depth: sources first, each vertex one layer after its deepest predecessor."""
        return [list(layer) for layer in nx.topological_generations(self.g)]

    def descendants(self, v: str) -> set[str]:
        return nx.descendants(self.g, v)

    @property
    def n_vertices(self) -> int:
        return self.g.number_of_nodes()

    @property
    def n_edges(self) -> int:
        return self.g.number_of_edges()

    # --- surgery (in place; the result still refines what it refined: Theorem 4.1) ------------
    def split_edge(self, u: str, v: str, waypoints) -> list[str]:
        """Replace edge u -> v by u -> x1 -> ... -> v; returns the new vertex names (none for no waypoints).

        New vertices are intermediates (``refines=None``); new edges keep the avoid set and the
        ``parent`` of the edge they replace.
        """
        if not waypoints:
            return []
        avoid, parent = self.avoid(u, v), self.parent(u, v)
        self.g.remove_edge(u, v)
        names = [self.add_vertex(None, w, refines=None) for w in waypoints]
        chain = [u, *names, v]
        for a, b in zip(chain, chain[1:]):
            self.add_edge(a, b, avoid, parent=parent)
        return names

    def set_avoid(self, u: str, v: str, avoid: Region) -> None:
        self.g.edges[u, v]["avoid"] = avoid

    def narrow_vertex(self, v: str, region: Region) -> None:
        """Replace I(v) by ``region`` (a subset of it: vertex refinement); its goal point is dropped."""
        node = self.g.nodes[v]
        node["region"], node["point"] = region, None

    def copy(self) -> TaskGraph:
        return TaskGraph.from_json(self.to_json())

    def __repr__(self):
        return f"TaskGraph({self.g.number_of_nodes()} vertices, {self.g.number_of_edges()} edges)"

    # --- serialisation -----------------------------------------------------------
    def to_dict(self) -> dict:
        return {
            "initial": self.initial,
            "finals": sorted(self.finals),
            "vertices": [
                {"name": v, "region": d["region"].to_dict(), "point": d["point"], "refines": d["refines"],
                 "label": d["label"]}
                for v, d in self.g.nodes(data=True)
            ],
            "edges": [
                {"u": u, "v": v, "avoid": d["avoid"].to_dict(), "parent": list(d["parent"])}
                for u, v, d in self.g.edges(data=True)
            ],
        }

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), **kw)

    @classmethod
    def from_dict(cls, d: dict) -> TaskGraph:
        """The graph ``to_dict`` wrote; anything else (a wrong type, a non-finite point, an edge, the initial vertex
        or a final naming no vertex, a cycle) is one GraphError (or RegionError) line."""
        try:
            return cls._from_dict(d)
        except (KeyError, TypeError, AttributeError) as exc:
            raise GraphError(f"malformed task graph ({type(exc).__name__}: {str(exc)[:60]})") from None

    @classmethod
    def _from_dict(cls, d: dict) -> TaskGraph:
        tg = cls(_name(d["initial"], "initial vertex"))
        for vd in _listed(d["vertices"], "vertices"):
            name = _name(vd["name"], "vertex name")
            if name in tg:
                raise GraphError(f"vertex {name!r} is listed twice")
            refines, label = vd.get("refines", name), vd.get("label")
            tg.add_vertex(name, from_dict(vd["region"]), point=_point(vd.get("point"), name),
                          refines=None if refines is None else _name(refines, "refines"),
                          label=None if label is None else _name(label, "label"))
        for ed in _listed(d["edges"], "edges"):
            u, v = _name(ed["u"], "edge end"), _name(ed["v"], "edge end")
            parent = ed.get("parent")
            if parent is not None and (not isinstance(parent, list) or len(parent) != 2):
                raise GraphError(f"edge {u}->{v}: its parent must be a pair of vertex names")
            if u not in tg or v not in tg:
                raise GraphError(f"edge {u}->{v} names a vertex the graph does not have")
            tg.add_edge(u, v, from_dict(ed["avoid"]), parent=None if parent is None else
                        [_name(x, "parent") for x in parent])
        tg.finals = {_name(f, "final vertex") for f in _listed(d["finals"], "finals")}
        unknown = sorted(({tg.initial} | tg.finals) - set(tg.vertices()))
        if unknown:
            names = ", ".join(map(repr, unknown))[:60]
            raise GraphError(f"{names}: named as the initial or a final vertex, but no vertex of the graph")
        if not tg.finals:
            raise GraphError("a task graph needs at least one final vertex")
        return tg

    @classmethod
    def from_json(cls, text: str) -> TaskGraph:
        return cls.from_dict(json.loads(text))

    def __eq__(self, other):
        return isinstance(other, TaskGraph) and self.to_dict() == other.to_dict()


def _name(value, what: str) -> str:
    if not isinstance(value, str):
        raise GraphError(f"{what} must be a string, got {type(value).__name__} {value!r:.40}")
    return value


def _listed(value, what: str) -> list:
    if not isinstance(value, list):
        raise GraphError(f"a task graph's {what} must be a list, got {type(value).__name__}")
    return value


def _point(value, vertex: str):
    if value is None:
        return None
    if not isinstance(value, list | tuple) or len(value) != 2 or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and np.isfinite(v) for v in value):
        raise GraphError(f"vertex {vertex!r}: its point must be two finite numbers, got {value!r:.60}")
    return value


def path_graph(regions: list[Region], avoid: Region, names: list[str] | None = None) -> TaskGraph:
    """The chain v0 -> v1 -> ... -> vn with the same avoid set on every edge."""
    names = names or [f"v{i}" for i in range(len(regions))]
    tg = TaskGraph(names[0])
    for name, region in zip(names, regions, strict=True):
        tg.add_vertex(name, region)
    for u, v in zip(names, names[1:], strict=False):
        tg.add_edge(u, v, avoid)
    tg.finals = {names[-1]}
    return tg


@dataclass(frozen=True)
class Violation:
    condition: str
    where: str

    def __str__(self):
        return f"{self.where}: {self.condition}"


def check_refines(refined: TaskGraph, original: TaskGraph) -> list[Violation]:
    """Theorem 4.1 conditions for vertex-subset and edge-split refinements.

    Returns the violated conditions (empty list = ``refined`` implies ``original``).
    """
    out: list[Violation] = []
    rg, og = refined.g, original.g

    def origin(v):
        return rg.nodes[v]["refines"]

    for v, d in rg.nodes(data=True):
        o = d["refines"]
        if o is None:
            continue
        if o not in og:
            out.append(Violation(f"refines unknown original vertex {o!r}", f"vertex {v}"))
        elif not is_subset(d["region"], og.nodes[o]["region"]):
            out.append(Violation(f"I'({v}) is not a subset of I({o}) (vertex subset)", f"vertex {v}"))
    if refined.initial not in rg or origin(refined.initial) != original.initial:
        out.append(Violation(f"initial vertex must refine the original initial {original.initial!r}",
                             f"vertex {refined.initial}"))
    for f in refined.finals:
        if f not in rg or origin(f) not in original.finals:
            out.append(Violation("final vertex must refine an original final vertex", f"vertex {f}"))
    for a, b, d in rg.edges(data=True):
        u, v = d["parent"]
        where = f"edge {a}->{b}"
        if not og.has_edge(u, v):
            out.append(Violation(f"parent edge {u}->{v} is not in the original graph", where))
            continue
        if not is_subset(og.edges[u, v]["avoid"], d["avoid"]):
            out.append(Violation(f"O({a}->{b}) does not contain the avoid set of its parent {u}->{v} (edge split)",
                                 where))
        if not (origin(a) == u or (origin(a) is None and all(rg.edges[p, a]["parent"] == (u, v)
                                                             for p in rg.predecessors(a)) and rg.in_degree(a))):
            out.append(Violation(f"start {a} neither refines {u} nor continues a split of {u}->{v}", where))
        if not (origin(b) == v or (origin(b) is None and all(rg.edges[b, s]["parent"] == (u, v)
                                                             for s in rg.successors(b)) and rg.out_degree(b))):
            out.append(Violation(f"end {b} neither refines {v} nor leads on in a split of {u}->{v}", where))
    return out


def assert_refines(refined: TaskGraph, original: TaskGraph) -> None:
    problems = check_refines(refined, original)
    if problems:
        raise InvalidRefinement(f"refined graph does not imply the original: {problems[0]}"
                                + (f" (+{len(problems) - 1} more)" if len(problems) > 1 else ""))


def infer_parents(proposal: TaskGraph, original: TaskGraph) -> TaskGraph:
    """Give a whole-graph proposal (e.g. the one-shot VLM baseline's) edge provenance.

    Vertices must already say which original vertex they refine (``refines``; None for new
    waypoints).  Each edge a -> b gets as parent the original edge u -> v, where u is the first
    refining vertex found walking back from a and v the first walking on from b through
    unbranched new waypoints.  ``check_refines`` then judges whether the proposal implies the input.
    """
    g = proposal.g

    def walk(x, step, degree):
        seen = set()
        while g.nodes[x]["refines"] is None and degree(x) == 1 and x not in seen:
            seen.add(x)
            x = next(iter(step(x)))
        return g.nodes[x]["refines"]

    for a, b in g.edges:
        u = walk(a, g.predecessors, g.in_degree)
        v = walk(b, g.successors, g.out_degree)
        if u is not None and v is not None:
            g.edges[a, b]["parent"] = (u, v)
    return proposal
