"""Shortcut edges over a found path's waypoints (beyond the paper: ours-shortcut), on hand-made graphs."""

from __future__ import annotations

import numpy as np
from test_refine_search import FakeResult

from specrefine.core.graph import TaskGraph, check_refines
from specrefine.core.regions import Box, Disc
from specrefine.refine import RefinementSearch, SearchConfig
from specrefine.refine.shortcut import add_shortcuts, shortcuts

WALL = Box(3.5, 0.1, 4.5, 5.0)  # a wall just north of the line y = 0, around x = 4


def split_line(points, parent_avoid=WALL):
    """S -> x0 -> ... -> G: one split of the input edge S -> G through discs at ``points``."""
    original = TaskGraph("S")
    original.add_vertex("S", Disc(points[0][0], points[0][1], 0.5))
    original.add_vertex("G", Disc(points[-1][0], points[-1][1], 0.5))
    original.add_edge("S", "G", parent_avoid)
    original.finals = {"G"}
    refined = original.copy()
    names = refined.split_edge("S", "G", [Disc(x, y, 0.3) for x, y in points[1:-1]])
    return original, refined, ["S", *names, "G"]


def test_shortcuts_skip_only_straight_clear_waypoints_within_reach():
    # S (0,0) -> (2,0) -> (4,-2) -> (6,0) -> G (8,0): the wall stands above (4, 0.5..5)
    original, refined, path = split_line([(0, 0), (2, 0), (4, -2), (6, 0), (8, 0)])
    found = {(path[s.i], path[s.j]) for s in shortcuts(refined, path, reach=5.0, clearance=0.2)}
    assert ("S", path[2]) in found  # (0,0) -> (4,-2): clear, 4.5 m
    assert (path[1], path[3]) not in found  # (2,0) -> (6,0) passes 0.1 m under the wall: closer than 0.2
    assert ("S", "G") not in found  # 8 m: beyond the reach
    add_shortcuts(refined, path, shortcuts(refined, path, reach=5.0, clearance=0.2))
    assert check_refines(refined, original) == []  # a shortcut is a split of the same edge with fewer waypoints


def test_no_shortcut_over_an_original_vertex():
    g = TaskGraph("S")
    for name, x in (("S", 0), ("A", 2), ("G", 4)):
        g.add_vertex(name, Disc(x, 0, 0.5))
    g.add_edge("S", "A", WALL)
    g.add_edge("A", "G", WALL)
    g.finals = {"G"}
    assert shortcuts(g, ["S", "A", "G"], reach=10.0) == []  # A is a vertex of the task, not a waypoint


class _LegsEvaluator:
    """A leg out of S's box (the unsplit edge) fails; any other leg succeeds with 0.9: fewer legs is better."""

    n, clearance = 32, 0.1

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None):
        return FakeResult(0.9 if isinstance(start, tuple) or goal.centre()[0] < 7 else 0.0)


class _Proposer:
    name, is_vlm, calls = "stub", False, 0

    def propose_split(self, query, w, feedback=()):
        return [[Disc(x, y, 0.3) for x, y in ((2, 0), (4, -2), (6, -2))]]


class _PerfectEvaluator(_LegsEvaluator):
    """Every leg but the unsplit edge succeeds in every rollout: shortcuts tie with the legs they skip."""

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None):
        return FakeResult(1.0 if isinstance(start, tuple) or goal.centre()[0] < 7 else 0.0)


def _search(reach, evaluator=None):
    g = TaskGraph("S")
    g.add_vertex("S", Box(-0.5, -0.5, 0.5, 0.5))
    g.add_vertex("G", Disc(8, -2, 0.5))
    g.add_edge("S", "G", WALL)
    g.finals = {"G"}
    cfg = SearchConfig(w=1, d=1, vertex_refinement=False, shortcut_reach=reach)
    query = lambda graph, u, v, r: type("Q", (), {"goal": graph.region(v), "avoid": graph.avoid(u, v)})()
    return g, RefinementSearch(g, evaluator or _LegsEvaluator(), proposer=_Proposer(), config=cfg,
                               query_for=query).run()


def test_the_search_takes_a_shortcut_when_its_estimate_is_better():
    g, plain = _search(None)
    assert len(plain.path) == 5  # S, three waypoints, G: four legs
    g, short = _search(5.0)
    assert short.path[0] == "S" and short.path[-1] == "G" and len(short.path) < len(plain.path)
    assert np.isclose(short.predicted_success, 0.9 ** (len(short.path) - 1))
    assert check_refines(short.graph, g) == []
    assert any(s["event"] == "shortcut" for s in short.steps)


def test_a_shortcut_that_only_ties_with_the_legs_it_skips_is_not_taken():
    _, plain = _search(None, _PerfectEvaluator())
    _, tied = _search(5.0, _PerfectEvaluator())
    assert len(plain.path) == 5 and tied.path == plain.path  # all estimated 1.0: the found path stays
    assert any(s["event"] == "shortcut" for s in tied.steps)  # the shortcuts were added and estimated


def test_shortcut_edges_are_named_by_the_graph_and_drawn_dashed():
    from matplotlib.patches import FancyArrowPatch

    from specrefine.core.mazes import load_maze
    from specrefine.pictures.render import render_graph_diagram, render_task

    original, refined, path = split_line([(0, 0), (2, 0), (4, -2), (6, 0), (8, 0)])
    assert not any(refined.is_shortcut(u, v) for u, v in refined.edges())  # a plain split has none
    found = shortcuts(refined, path, reach=5.0, clearance=0.2)
    add_shortcuts(refined, path, found)
    dashed_edges = {(u, v) for u, v in refined.edges() if refined.is_shortcut(u, v)}
    assert dashed_edges == {(path[s.i], path[s.j]) for s in found}  # the split's own legs stay solid
    assert len(found) >= 1 and not original.is_shortcut("S", "G")

    def dashed(fig):
        arrows = [p for ax in fig.axes for p in ax.patches if isinstance(p, FancyArrowPatch)]
        return sum(a.get_linestyle() not in ("-", "solid") for a in arrows), len(arrows)

    maze = load_maze("u_maze")
    expected = (len(found), refined.g.number_of_edges())
    assert dashed(render_task(maze, refined, path=path)) == expected
    assert dashed(render_graph_diagram(refined, path=path)) == expected
    legend = [t.get_text() for t in render_task(maze, refined).legends[0].get_texts()]
    assert "shortcut edge" in legend
    assert "shortcut edge" not in [t.get_text() for t in render_task(maze, original).legends[0].get_texts()]
