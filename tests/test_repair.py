"""The look-ahead repair (method ours-repair, beyond the paper) on a stubbed straight corridor S -> G.

The proposer splits S -> G at x = 3 and x = 6, but the hop 3 -> 6 crosses a "wall" (p = 0); asked about that
leg alone, it proposes x = 4.5. The paper's search keeps no split here; the repair splices the leg's split in.
"""

from __future__ import annotations

import pytest
from test_refine_search import TableEvaluator, _Arrive, _chain_graph, _Query

from specrefine.core.graph import check_refines
from specrefine.core.regions import Box, Disc
from specrefine.refine import RefinementSearch, SearchConfig


class CorridorEvaluator(TableEvaluator):
    n = 32

    def __init__(self):
        self.calls = []

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None):
        x0 = 0.0 if isinstance(start, Box) else start[1][0]
        x1 = goal.centre()[0]
        self.calls.append((x0, x1))
        p = 0.0 if (x0, x1) in {(0.0, 10.0), (3.0, 6.0)} else 0.95
        return _Arrive(p, at=tuple(goal.centre()))


class LegProposer:
    name, is_vlm = "stub", False

    def __init__(self):
        self.queries = []

    def propose_split(self, query, w, feedback=()):
        x = float(query.goal.centre()[0])
        self.queries.append(x)
        return [[Disc(3, 0, 0.5), Disc(6, 0, 0.5)]] if x == 10 else [[Disc(4.5, 0, 0.5)]]


def search(repair: bool, max_edge_splits: int = 30):
    g = _chain_graph()
    proposer = LegProposer()
    cfg = SearchConfig(w=1, d=1, vertex_refinement=False, repair=repair, max_edge_splits=max_edge_splits)
    result = RefinementSearch(g, CorridorEvaluator(), proposer=proposer, config=cfg,
                              query_for=lambda graph, u, v, r: _Query(graph, u, v)).run()
    return g, result, proposer


def test_without_repair_the_split_with_a_dead_leg_is_never_kept():
    _, result, proposer = search(repair=False)
    assert result.refinements == 0 and result.path == ["S", "G"] and result.predicted_success == 0.0
    assert proposer.queries == [10.0]


def test_repair_splits_the_dead_leg_and_the_split_is_kept():
    g, result, proposer = search(repair=True)
    assert proposer.queries[:2] == [10.0, 6.0]  # the whole edge, then the leg 3 -> 6 from where leg 1 ends
    assert result.refinements == 1 and len(result.path) == 5
    assert [result.graph.region(v).centre()[0] for v in result.path] == [0.0, 3.0, 4.5, 6.0, 10.0]
    assert result.predicted_success == pytest.approx(0.95**4)
    assert check_refines(result.graph, g) == []
    step = next(s for s in result.steps if s["event"] == "split-repaired")
    assert step["p_before"][:2] == [0.95, 0.0] and step["legs_repaired"] == 1
    assert step["p_after"] == pytest.approx([0.95] * 4)


def test_repair_spends_from_the_searchs_budget_of_edge_splits():
    _, result, proposer = search(repair=True, max_edge_splits=1)
    assert proposer.queries == [10.0] and result.refinements == 0
