"""Property tests: the search returns a maximum-product path (Dijkstra order, Algorithm 3).

A stub evaluator knows every edge's success probability: it is a pure function of where the
subtask starts (the centre of the previous goal) and the goal region, so any path of any graph,
the refined one included, can be scored by brute force and compared with what the search returns.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import networkx as nx
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_refine_search import _Query

from specrefine.core.graph import TaskGraph, check_refines
from specrefine.core.regions import Box, Disc
from specrefine.refine import RefinementSearch, SearchConfig, shortest_path

WALLS = Box(1000, 1000, 1001, 1001)
N_ROLLOUTS = 32


@dataclass
class _Result:
    p: float
    at: tuple

    @property
    def successes(self):
        return round(self.p * N_ROLLOUTS)

    @property
    def end_states(self):
        return ("at", self.at)

    @property
    def ci(self):
        return (self.p, self.p)


class KnownEvaluator:
    """p(start -> goal) = table[(start centre, goal centre)], else a smooth function of the distance."""

    n = N_ROLLOUTS

    def __init__(self, table=None):
        self.table = table or {}

    def p(self, src: tuple, goal_centre: tuple) -> float:
        key = (src, goal_centre)
        if key in self.table:
            return self.table[key]
        return max(0.02, math.exp(-math.dist(src, goal_centre) / 6))

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None):
        src = tuple(start.centre()) if isinstance(start, Box) else start[1]
        at = tuple(goal.centre())
        return _Result(self.p(src, at), at)


def _centre(g: TaskGraph, v: str) -> tuple:
    return tuple(g.region(v).centre())


def brute_force_best(g: TaskGraph, ev: KnownEvaluator) -> float:
    best = 0.0
    for final in g.finals:
        for path in nx.all_simple_paths(g.g, g.initial, final):
            best = max(best, math.prod(ev.p(_centre(g, a), _centre(g, b)) for a, b in zip(path, path[1:])))
    return best


def path_product(g: TaskGraph, path: list[str], ev: KnownEvaluator) -> float:
    return math.prod(ev.p(_centre(g, a), _centre(g, b)) for a, b in zip(path, path[1:]))


@st.composite
def random_dags(draw):
    """Vertices 0..n-1 in topological order at random positions; S = 0, G = n-1, edges i -> j (i < j)."""
    n = draw(st.integers(3, 8))
    xs = draw(st.lists(st.integers(-6, 6), min_size=n, max_size=n))
    ys = draw(st.lists(st.integers(-6, 6), min_size=n, max_size=n))
    names = ["S"] + [f"v{i}" for i in range(1, n - 1)] + ["G"]
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n)]
    present = draw(st.lists(st.booleans(), min_size=len(pairs), max_size=len(pairs)))
    chosen = [pair for pair, keep in zip(pairs, present) if keep]
    probs = draw(st.lists(st.floats(0.05, 1.0), min_size=len(chosen), max_size=len(chosen)))
    g = TaskGraph("S")
    for i, name in enumerate(names):
        g.add_vertex(name, Box(10 * i + xs[i], ys[i], 10 * i + xs[i] + 1, ys[i] + 1))
    table = {}
    for (i, j), p in zip(chosen, probs):
        g.add_edge(names[i], names[j], WALLS)
        table[(_centre(g, names[i]), _centre(g, names[j]))] = p
    g.finals = {"G"}
    if not nx.has_path(g.g, "S", "G"):
        g.add_edge("S", "G", WALLS)
    return g, KnownEvaluator(table)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_dags())
def test_search_without_refinement_returns_the_maximum_product_path(case):
    g, ev = case
    result = shortest_path(g, ev)
    assert result.path is not None and result.path[0] == "S" and result.path[-1] == "G"
    best = brute_force_best(g, ev)
    assert path_product(g, result.path, ev) == pytest.approx(best, rel=1e-12)
    assert result.predicted_success == pytest.approx(best, rel=1e-12)


def test_merge_before_the_goal_is_searched_optimally():
    """S -> {A, B} -> C -> G: C is closed (through A) before B is expanded; B must not reopen it."""
    g = TaskGraph("S")
    for i, name in enumerate("SABCG"):
        g.add_vertex(name, Box(10 * i, 0, 10 * i + 1, 1))
    for u, v in ["SA", "SB", "AC", "BC", "CG"]:
        g.add_edge(u, v, WALLS)
    g.finals = {"G"}
    p = {"SA": 0.9, "SB": 0.5, "AC": 0.9, "BC": 0.95, "CG": 0.5}
    ev = KnownEvaluator({(_centre(g, e[0]), _centre(g, e[1])): q for e, q in p.items()})
    result = shortest_path(g, ev)
    assert result.path == ["S", "A", "C", "G"]
    assert result.predicted_success == pytest.approx(0.9 * 0.9 * 0.5)  # not S-B-C-G's 0.2375


class MidpointProposer:
    """Proposes evenly spaced small discs on the straight line of the queried edge."""

    name, is_vlm = "stub", False

    def __init__(self):
        self.calls = 0

    def propose_split(self, query, w, feedback=()):
        self.calls += 1
        a, b = query.graph.region(query.u).centre(), query.graph.region(query.v).centre()
        proposals = []
        for parts in range(1, w + 1):
            proposals.append([Disc(*(a + (b - a) * t / (parts + 1)), 0.5) for t in range(1, parts + 1)])
        return proposals


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_dags(), st.booleans(), st.integers(0, 3))
def test_search_with_refinements_is_optimal_on_the_final_graph(case, vertex_refinement, seed):
    g, ev = case
    config = SearchConfig(w=2, d=1, k=2, vertex_refinement=vertex_refinement, seed=seed, max_edge_splits=4)
    result = RefinementSearch(g, ev, proposer=MidpointProposer(), config=config,
                              query_for=lambda graph, u, v, r: _Query(graph, u, v)).run()
    assert check_refines(result.graph, g) == []
    best = brute_force_best(result.graph, ev)
    assert path_product(result.graph, result.path, ev) == pytest.approx(best, rel=1e-9)
    assert result.predicted_success == pytest.approx(best, rel=1e-9)
    assert result.predicted_success >= brute_force_best(g, ev) * (1 - 1e-9)  # refinement never loses
