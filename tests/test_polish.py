"""Polishing the found path (method ours-polish, beyond the paper) on a stubbed chain S -> x -> G.

The leg into the waypoint x loses 5 % of its episodes unless x is narrowed (any strict subset of it: p = 1); on 32
rollouts the search may see none of that, on 128 the polish sees about six failures and tunes x.
"""

from __future__ import annotations

import numpy as np
from test_refine_search import WALLS, FakeResult, box_at

from specrefine.core.graph import TaskGraph, check_refines
from specrefine.core.regions import Disc
from specrefine.refine.polish import polish


class NarrowingEvaluator:
    n = 32

    def __init__(self, p_wide: float = 0.95):
        self.p_wide, self.asked = p_wide, []

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None, n=None):
        self.asked.append((n, seed))
        wide = isinstance(goal, Disc) and goal.r >= 1.0
        return FakeResult(self.p_wide if wide else 1.0, n=n or self.n)

    def evaluate_many(self, subtasks, seed=None, n=None):
        return [self.evaluate(s, g, a, p, seed=seed, n=n) for s, g, a, p in subtasks]


def chain() -> TaskGraph:
    g = TaskGraph("S")
    g.add_vertex("S", box_at(0, 0))
    g.add_vertex("x", Disc(5, 0, 1.0))
    g.add_vertex("G", box_at(10, 0))
    g.add_edge("S", "x", WALLS)
    g.add_edge("x", "G", WALLS)
    g.finals = {"G"}
    return g


def test_a_weak_waypoint_is_narrowed_on_the_larger_estimates_and_stays_a_refinement():
    g, ev = chain(), NarrowingEvaluator()
    original = g.copy()
    done = polish(g, ["S", "x", "G"], ev, rollouts=128, k=5, rng=np.random.default_rng(0), seed=99)
    assert [(d.vertex, d.changed) for d in done] == [("x", True)]
    assert done[0].p_before < done[0].p_after == 1.0
    assert g.region("x") != Disc(5, 0, 1.0) and g.region("x").r < 1.0
    assert not check_refines(g, original)  # a narrowed vertex: still a refinement of the input
    assert set(ev.asked) == {(128, 99)}  # every estimate on the polish's own rollouts and seed


def test_a_path_without_weak_legs_is_left_as_it_is():
    g, ev = chain(), NarrowingEvaluator(p_wide=1.0)
    assert polish(g, ["S", "x", "G"], ev, rollouts=128, k=5, rng=np.random.default_rng(0), seed=99) == []
    assert g.region("x") == Disc(5, 0, 1.0)


def test_one_failure_in_128_is_not_enough_to_tune():
    g, ev = chain(), NarrowingEvaluator(p_wide=1 - 1 / 128)
    assert polish(g, ["S", "x", "G"], ev, rollouts=128, k=5, rng=np.random.default_rng(0), seed=99) == []


def test_the_search_polishes_its_path_and_predicts_on_its_own_rollouts():
    from specrefine.refine import RefinementSearch, SearchConfig

    ev = NarrowingEvaluator()
    cfg = SearchConfig(edge_refinement=False, vertex_refinement=False, polish_rollouts=128)
    result = RefinementSearch(chain(), ev, config=cfg).run()
    assert result.path == ["S", "x", "G"]
    assert [s["changed"] for s in result.steps if s["event"] == "path-polished"] == [True]
    assert result.graph.region("x").r < 1.0 and result.predicted_success == 1.0
    assert (None, None) in ev.asked  # the prediction's estimates: the search's own rollouts (n = 32, its seed)
