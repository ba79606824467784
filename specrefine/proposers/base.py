"""What every proposer shares: the queries it answers, the feedback it gets, and the :class:`Proposer` interface.

``propose_split`` returns up to ``w`` candidate edge splits, each the ordered list of intermediate
waypoint regions x1..x_{k-1} (u -> x1 -> ... -> v); ``propose_graph`` returns up to ``w`` whole task
graphs (the one-shot VLM baseline of the paper's Sec. 5.1).  A new proposer subclasses
:class:`Proposer`, implements :meth:`~Proposer.split` and :meth:`~Proposer.graph` (the base class's
``propose_split`` / ``propose_graph`` count each query, then ask them) and is registered with
:func:`~specrefine.proposers.register_proposer`, whose ``make_proposer`` gives it its ``spec`` string.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..core.graph import TaskGraph
from ..core.regions import Region
from ..evaluation.evaluator import EvaluationFacts
from .schema import region_json


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
    facts: EvaluationFacts | None = None  # what the evaluator does (default: an Evaluator's default settings)
    snap: float = 0.0  # > 0: a reply's waypoint centred in a wall is moved this far clear of it (schema.snapped)


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
    facts: EvaluationFacts | None = None


@dataclass
class GraphFeedback:
    """An earlier candidate graph and how it did."""

    graph: TaskGraph
    edge_success: dict[tuple[str, str], float]
    success: float | None = None  # of the whole task under this graph
    image_png: bytes | None = None


class Proposer:
    """Base class. Its two contracts, kept here rather than by each subclass:

    * it counts its queries: ``propose_split`` / ``propose_graph`` add one to ``queries`` and ask :meth:`split` /
      :meth:`graph`, which a subclass implements (``proposer_calls``, in result.json, reads the count);
    * it carries the string that named it: ``spec`` (``make_proposer`` sets it to the ``--proposer`` string; the
      constructor takes it for proposers built by hand).

    ``calls``/``cost_usd`` count VLM API calls and dollars (0 for offline proposers)."""

    name: str = "?"
    spec: str = "?"  # a subclass may name its default string here (GeometricProposer: "geometric")
    is_vlm: bool = False
    #: whether its answers depend on the queries' pictures (offline proposers: no, so none are rendered)
    sees_images: bool = False

    def __init__(self, spec: str | None = None):
        if spec is not None:
            self.spec = spec  # the proposer string that names it (result.json's "proposer")
        self.queries = 0  # propose_* calls answered
        self.history: list[dict] = []  # per query: accepted candidates (with reasoning) and rejections

    @property
    def calls(self) -> int:
        return 0

    @property
    def cost_usd(self) -> float:
        return 0.0

    @property
    def proposer_calls(self) -> int:
        """Calls to whoever proposes (a VLM's completion calls, re-asks included; an offline proposer's queries)."""
        return self.queries

    def propose_split(self, q: EdgeQuery, w: int, feedback: Sequence[CandidateFeedback] = ()) -> list[list[Region]]:
        """Up to ``w`` candidate splits of ``q``'s edge (counted as one query)."""
        self.queries += 1
        return self.split(q, w, feedback)

    def propose_graph(self, q: GraphQuery, w: int, feedback: Sequence[GraphFeedback] = ()) -> list[TaskGraph]:
        """Up to ``w`` whole task graphs for ``q`` (counted as one query)."""
        self.queries += 1
        return self.graph(q, w, feedback)

    def split(self, q: EdgeQuery, w: int, feedback: Sequence[CandidateFeedback]) -> list[list[Region]]:
        """What a subclass answers to an edge query: each candidate the waypoint regions x1..x_{k-1}."""
        raise NotImplementedError(f"{type(self).__name__} does not propose edge splits")

    def graph(self, q: GraphQuery, w: int, feedback: Sequence[GraphFeedback]) -> list[TaskGraph]:
        """What a subclass answers to a whole-graph query (the one-shot baseline)."""
        raise NotImplementedError(f"{type(self).__name__} does not propose whole task graphs")

    def describe(self) -> dict:
        """What a result file should say about the proposer."""
        return {"proposer": self.spec, "name": self.name, "is_vlm": self.is_vlm, "queries": self.queries,
                "proposer_calls": self.proposer_calls, "vlm_calls": self.calls, "cost_usd": round(self.cost_usd, 6)}

    def __repr__(self):
        return f"<{type(self).__name__} {self.name}>"


def _jsonable(value):
    if isinstance(value, TaskGraph):
        return value.to_dict()
    return [region_json(r) for r in value]


def graph_score(fb: GraphFeedback) -> float:
    if fb.success is not None:
        return float(fb.success)
    return float(np.prod(list(fb.edge_success.values()))) if fb.edge_success else 0.0
