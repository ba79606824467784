"""Algorithms 1-3 on hand-made graphs with a stubbed evaluator (known probabilities)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from specrefine.core.graph import TaskGraph, check_refines
from specrefine.core.regions import Box, Disc
from specrefine.refine import RefinementSearch, SearchConfig, refine_chain, shortest_path
from specrefine.refine.search import SearchResult

WALLS = Box(100, 100, 101, 101)


@dataclass
class FakeResult:
    p: float
    n: int = 32

    @property
    def successes(self):
        return round(self.p * self.n)

    @property
    def end_states(self):
        return ("arrived", self.p)

    @property
    def ci(self):
        return (self.p, self.p)


class TableEvaluator:
    """p(start -> goal) from a function of the goal region (and optionally the start)."""

    n = 32

    def __init__(self, p_of):
        self.p_of = p_of
        self.calls = []

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None):
        self.calls.append((start, goal))
        return FakeResult(self.p_of(start, goal))


def box_at(x, y, h=0.5):
    return Box(x - h, y - h, x + h, y + h)


def diamond(p_sa, p_sb, p_ag, p_bg):
    """S -> A -> G and S -> B -> G."""
    g = TaskGraph("S")
    regions = {"S": box_at(0, 0), "A": box_at(1, 1), "B": box_at(1, -1), "G": box_at(2, 0)}
    for name, r in regions.items():
        g.add_vertex(name, r)
    for u, v in [("S", "A"), ("S", "B"), ("A", "G"), ("B", "G")]:
        g.add_edge(u, v, WALLS)
    g.finals = {"G"}
    return g


class DiamondEvaluator(TableEvaluator):
    def __init__(self, g, table):
        self.g = g
        self.table = table
        self.calls = []

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None):
        name = {self.g.region(v): v for v in self.g.vertices()}[goal]
        src = start[2] if isinstance(start, tuple) else "S"
        self.calls.append((src, name))
        p = self.table[(src, name)]
        return _Tagged(p, name=name)


@dataclass
class _Tagged(FakeResult):
    name: str = ""

    @property
    def end_states(self):
        return ("arrived", self.p, self.name)


@pytest.mark.parametrize("probs,expected", [
    ((0.9, 0.5, 0.5, 1.0), ["S", "B", "G"]),
    ((0.9, 0.5, 0.9, 0.6), ["S", "A", "G"]),
    ((0.0, 0.5, 1.0, 0.1), ["S", "B", "G"]),
])
def test_shortest_path_is_optimal_on_hand_made_graph(probs, expected):
    g = diamond(*probs)
    table = dict(zip([("S", "A"), ("S", "B"), ("A", "G"), ("B", "G")], probs))
    ev = DiamondEvaluator(g, table)
    result = shortest_path(g, ev)
    assert result.path == expected
    best = max(probs[0] * probs[2], probs[1] * probs[3])
    assert result.predicted_success == pytest.approx(best)
    assert result.refinements == 0


def test_evaluation_is_lazy():
    """Edges out of vertices that are never expanded are never evaluated."""
    g = diamond(1.0, 0.1, 1.0, 1.0)
    table = dict(zip([("S", "A"), ("S", "B"), ("A", "G"), ("B", "G")], (1.0, 0.1, 1.0, 1.0)))
    ev = DiamondEvaluator(g, table)
    shortest_path(g, ev)
    assert ("B", "G") not in ev.calls


def _chain_graph():
    g = TaskGraph("S")
    g.add_vertex("S", box_at(0, 0))
    g.add_vertex("G", box_at(10, 0))
    g.add_edge("S", "G", WALLS)
    g.finals = {"G"}
    return g


class SplitProposer:
    name, is_vlm, calls = "stub", False, 0

    def __init__(self, waypoints):
        self.waypoints = waypoints

    def propose_split(self, query, w, feedback=()):
        self.calls += 1
        return [list(self.waypoints)][:w]


def distance_evaluator():
    """p = exp(-(distance travelled)/4): short hops are easy, one long hop is hard."""

    def p_of(start, goal):
        src = np.array([0.0, 0.0]) if isinstance(start, Box) else np.array(start[1])
        return math.exp(-np.linalg.norm(goal.centre() - src) / 4)

    class Ev(TableEvaluator):
        def evaluate(self, start, goal, avoid, goal_point=None, seed=None):
            self.calls.append((start, goal))
            return _Arrive(self.p_of(start, goal), at=tuple(goal.centre()))

    return Ev(p_of)


@dataclass
class _Arrive(FakeResult):
    at: tuple = (0.0, 0.0)

    @property
    def end_states(self):
        return ("at", self.at)


def test_search_with_edge_split_keeps_validity_and_beats_dirl():
    g = _chain_graph()
    ev = distance_evaluator()
    ev.p_of = lambda start, goal: 0.05 if isinstance(start, Box) and goal.centre()[0] == 10 else 0.95
    proposer = SplitProposer([Disc(3, 0, 0.5), Disc(6, 0, 0.5)])
    search = RefinementSearch(g, ev, proposer=proposer, config=SearchConfig(w=1, d=1, vertex_refinement=False),
                              query_for=lambda graph, u, v, r: _Query(graph, u, v))
    result: SearchResult = search.run()
    assert result.refinements == 1
    assert len(result.path) == 4 and result.path[0] == "S" and result.path[-1] == "G"
    assert result.predicted_success == pytest.approx(0.95**3)
    assert check_refines(result.graph, g) == []
    assert shortest_path(g, ev).predicted_success == pytest.approx(0.05)
    kinds = [s["event"] for s in result.steps]
    assert "refine-accept" in kinds and kinds[-1] == "done"


@dataclass
class _Query:
    graph: TaskGraph
    u: str
    v: str

    @property
    def goal(self):
        return self.graph.region(self.v)

    @property
    def avoid(self):
        return self.graph.avoid(self.u, self.v)


def test_no_refinement_when_edge_is_already_easy():
    g = _chain_graph()
    ev = TableEvaluator(lambda s, goal: 0.99)
    proposer = SplitProposer([Disc(5, 0, 0.5)])
    result = RefinementSearch(g, ev, proposer=proposer, config=SearchConfig(w=1, d=1),
                              query_for=lambda graph, u, v, r: _Query(graph, u, v)).run()
    assert result.refinements == 0 and proposer.calls == 0  # pruned: cost(v) - cost(u) <= tau


def test_chain_dp_picks_best_subsets():
    """Synthetic chain: p depends on the chosen subsets; the DP must find the product's maximum."""
    rng = np.random.default_rng(0)
    inner = [Box(0, 0, 4, 4), Box(10, 0, 14, 4)]
    goal = Box(20, 0, 21, 1)

    def p_of(start, region):  # easier to enter small regions' far corners, harder from far away
        src = np.array([0.0, 0.0]) if isinstance(start, Box) else np.array(start[1])
        return float(np.exp(-abs(region.centre()[1] - src[1]) / 3 - region.area / 40))

    class Ev(TableEvaluator):
        def evaluate(self, start, goal_, avoid, goal_point=None, seed=None):
            self.calls.append((start, goal_))
            return _Arrive(self.p_of(start, goal_), at=tuple(goal_.centre()))

    ev = Ev(p_of)
    choice = refine_chain(ev, Box(-1, -1, 0, 0), inner, goal, [WALLS] * 3, k=5, rng=rng)
    # brute force over the same options (re-sampled with the same seed)
    from specrefine.refine.vertex import sample_subsets

    rng2 = np.random.default_rng(0)
    options = [[r] + sample_subsets(r, 5, rng2) for r in inner]
    best = 0.0
    for a in options[0]:
        for b in options[1]:
            pa = p_of(Box(-1, -1, 0, 0), a)
            pb = p_of(("at", tuple(a.centre())), b)
            pg = p_of(("at", tuple(b.centre())), goal)
            best = max(best, pa * pb * pg)
    assert choice.p == pytest.approx(best)
    assert choice.evaluations == 3 + 6 + 36 + 6  # unrefined chain, then (k+1) + (k+1)^2 (t-1) + (k+1)

    class Batched(Ev):  # an evaluator that can run many subtasks at once gets each DP layer in one call
        batches = []

        def evaluate_many(self, subtasks):
            self.batches.append(len(subtasks))
            return [self.evaluate(start, goal_, avoid, point) for start, goal_, avoid, point in subtasks]

    batched = Batched(p_of)
    same = refine_chain(batched, Box(-1, -1, 0, 0), inner, goal, [WALLS] * 3, k=5, rng=np.random.default_rng(0))
    assert same.p == choice.p and same.regions == choice.regions and same.evaluations == choice.evaluations
    assert batched.batches == [6, 36, 6]


def test_vertex_refinement_only_search_improves_a_path_with_a_bad_subgoal():
    g = _bad_subgoal_graph()
    result = RefinementSearch(g, _SmallIsBetter(), config=SearchConfig(edge_refinement=False, k=5, seed=1)).run()
    assert result.refinements >= 1
    assert result.predicted_success == pytest.approx(0.81)
    assert result.graph.region("a").area < 8
    assert check_refines(result.graph, g) == []


@pytest.mark.parametrize("p_split,accepted", [(0.52, True), (0.505, False)])
def test_tau_decides_between_refinement_and_progress(p_split, accepted):
    """S -> G has p = 0.5; a one-waypoint split has p_split = sqrt(p_split) * sqrt(p_split).

    The gain -log 0.5 + log p_split is 0.039 for 0.52 (> tau0 = 0.02: accept) and 0.0099 for 0.505 (decline).
    """
    g = _chain_graph()
    ev = TableEvaluator(lambda s, goal: 0.5 if goal.centre()[0] == 10 and isinstance(s, Box) else
                        math.sqrt(p_split))
    result = RefinementSearch(g, ev, proposer=SplitProposer([Disc(5, 0, 0.5)]),
                              config=SearchConfig(w=1, d=1, vertex_refinement=False),
                              query_for=lambda graph, u, v, r: _Query(graph, u, v)).run()
    assert (result.refinements == 1) == accepted
    step = next(s for s in result.steps if s["event"] in ("refine-accept", "refine-declined"))
    assert step["tau"] == pytest.approx(0.02)
    assert step["event"] == ("refine-accept" if accepted else "refine-declined")


def _bad_subgoal_graph():
    g = TaskGraph("S")
    g.add_vertex("S", box_at(0, 0))
    g.add_vertex("a", Box(3, -2, 7, 2))
    g.add_vertex("G", box_at(10, 0))
    g.add_edge("S", "a", WALLS)
    g.add_edge("a", "G", WALLS)
    g.finals = {"G"}
    return g


class _SmallIsBetter(TableEvaluator):
    """From a small region the next subtask is easy; from a big one it is hard."""

    def __init__(self):
        super().__init__(lambda start, goal: 0.9 if goal.centre()[0] != 10 else (0.9 if start[1][1] < 8 else 0.2))

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None):
        return _Arrive(self.p_of(start, goal), at=(0.0, goal.area))


def test_every_accepted_refinement_is_checked(monkeypatch):
    import specrefine.refine.search as search_module

    calls = []
    real = search_module.assert_refines
    monkeypatch.setattr(search_module, "assert_refines", lambda g, o: calls.append(1) or real(g, o))
    result = RefinementSearch(_bad_subgoal_graph(), _SmallIsBetter(),
                              config=SearchConfig(edge_refinement=False, seed=1)).run()
    assert result.refinements >= 1 and len(calls) == result.refinements


def test_an_invalid_refinement_is_a_bug_not_a_warning(monkeypatch):
    """A vertex 'subset' that leaves I(v) must stop the search (Theorem 4.1 would not hold)."""
    import specrefine.refine.vertex as vertex_module
    from specrefine.core.errors import InvalidRefinement

    monkeypatch.setattr(vertex_module, "sample_subsets", lambda region, k, rng, shrink=None: [Box(20, 20, 21, 21)] * k)
    with pytest.raises(InvalidRefinement, match="not a subset"):
        RefinementSearch(_bad_subgoal_graph(), _SmallIsBetter(), config=SearchConfig(edge_refinement=False)).run()
