"""Offline proposers (geometric stand-in and random ablation) on every benchmark maze, point and Ant scale."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from specrefine.core.errors import SpecrefineError
from specrefine.core.graph import check_refines
from specrefine.core.mazes import benchmark_mazes, load_maze
from specrefine.core.regions import Disc
from specrefine.core.spec import maze_task
from specrefine.proposers import (
    CandidateFeedback,
    EdgeQuery,
    GraphFeedback,
    GraphQuery,
    Proposer,
    make_proposer,
    segment_clear,
    split_messages,
)
from specrefine.proposers.schema import check_region

MAZES = sorted(benchmark_mazes())
W = 3


def edge_queries(maze, agent):
    """One query per edge of the maze's initial task graph (S -> a -> ... -> G), plus S -> G directly."""
    g = maze_task(maze)
    pairs = [(g.region(u), g.region(v)) for u, v in g.edges()]
    if len(pairs) > 1:
        pairs.append((maze.start, maze.goal))
    return [EdgeQuery(maze, agent, s, t, maze.walls, 0.25, 32, None, graph=g) for s, t in pairs]


def assert_valid(cand, maze):
    assert cand, "empty candidate"
    x0, y0, x1, y1 = maze.bounds()
    for r in cand:
        assert check_region(r, maze) is None, check_region(r, maze)
        cx, cy = r.centre()
        assert x0 < cx < x1 and y0 < cy < y1
        assert not maze.walls.contains(r.centre())
        assert isinstance(r, Disc) and 0.3 * maze.cell_size - 1e-9 <= r.r <= 0.5 * maze.cell_size + 1e-9


@pytest.mark.parametrize("agent", ["point", "ant"])
@pytest.mark.parametrize("name", MAZES)
def test_offline_proposers_valid_on_every_maze(name, agent):
    maze = load_maze(benchmark_mazes()[name]).for_agent(agent)
    geo, rnd = make_proposer("geometric", seed=3), make_proposer("random", seed=3)
    for q in edge_queries(maze, agent):
        for p in (geo, rnd):
            cands = p.propose_split(q, W)
            assert len(cands) == W
            keys = {tuple(tuple(np.round(r.centre(), 6)) + (round(r.r, 6),) for r in c) for c in cands}
            assert len(keys) == W, "w samples must differ"
            for c in cands:
                assert_valid(c, maze)
                assert not any(q.goal.contains(r.centre()) for r in c) or p is rnd
        # the plain shortest-path sample: every leg is a straight segment clear of the walls
        plain = make_proposer("geometric", seed=0).propose_split(q, 1)[0]
        pts = [q.start.centre()] + [r.centre() for r in plain] + [q.goal.centre()]
        for a, b in zip(pts, pts[1:]):
            assert segment_clear(maze, a, b, 0.2 * maze.cell_size), (name, a, b)
    assert geo.calls == rnd.calls == 0 and geo.cost_usd == 0.0


def test_names_never_claim_a_vlm():
    for spec, word in (("geometric", "offline stand-in, not a VLM"), ("random", "not a VLM")):
        p = make_proposer(spec)
        assert isinstance(p, Proposer) and not p.is_vlm and word in p.name
        assert p.describe()["is_vlm"] is False and p.describe()["proposer"] == spec
    for bad in ("geometric:x", "geometric:max_waypoints=0", "geometric:max_waypoints=4.5", "geometric:radius=2"):
        with pytest.raises(SpecrefineError, match="max_waypoints=N"):
            make_proposer(bad)


def _longest_leg_cells(maze, q, cand) -> float:
    pts = [q.start.centre()] + [r.centre() for r in cand] + [q.goal.centre()]
    return max(float(np.linalg.norm(np.subtract(a, b))) for a, b in zip(pts, pts[1:])) / maze.cell_size


def test_geometric_waypoint_cap(caplog):
    """U-chain 5 with the Ant needs 37 one-cell legs: the default cap of 32 doubles the legs, a higher cap
    keeps them."""
    maze = load_maze("u_chain_5").for_agent("ant")
    q = edge_queries(maze, "ant")[0]
    with caplog.at_level(logging.WARNING, logger="specrefine.proposers.geometric"):
        capped = make_proposer("geometric", seed=0).propose_split(q, 1)[0]
    assert "geometric:max_waypoints=N" in caplog.text  # the user is told why the legs grew and what to pass
    caplog.clear()
    p = make_proposer("geometric:max_waypoints=48", seed=0)
    assert p.describe()["proposer"] == "geometric:max_waypoints=48" and not p.is_vlm
    with caplog.at_level(logging.WARNING, logger="specrefine.proposers.geometric"):
        free = p.propose_split(q, 1)[0]
    assert "max_waypoints" not in caplog.text
    assert len(capped) <= 32 < len(free) <= 48
    assert _longest_leg_cells(maze, q, capped) > 1.5 and _longest_leg_cells(maze, q, free) < 1.5


@pytest.mark.parametrize("spec", ["geometric", "random"])
def test_seeded_determinism(spec):
    maze = load_maze("xx_maze_h")
    q = edge_queries(maze, "point")[0]
    a = [make_proposer(spec, seed=7).propose_split(q, W) for _ in range(2)]
    assert a[0] == a[1]
    b = make_proposer(spec, seed=8).propose_split(q, W)
    assert b != a[0]
    p = make_proposer(spec, seed=7)
    assert p.propose_split(q, W) == a[0] and p.propose_split(q, W) != a[0]  # the stream moves on


def test_geometric_routes_differ_where_the_maze_offers_two():
    maze = load_maze("or_maze")  # above or below the central block
    q = edge_queries(maze, "point")[0]
    sides = set()
    for seed in range(6):
        for c in make_proposer("geometric", seed=seed).propose_split(q, W):
            sides.add(bool(np.mean([r.cy for r in c]) > 0))
    assert sides == {True, False}


def test_geometric_adapts_to_feedback():
    maze = load_maze("u_maze")  # S bottom-left, G top-left, wall between: go right, up, back left
    q = EdgeQuery(maze, "point", maze.start, maze.goal, maze.walls, 0.0, 32, None)
    corner = Disc(1.0, -1.0, 0.4)  # bottom-right corner only: the leg corner -> G crosses the wall
    fb = [CandidateFeedback([corner], [1.0, 0.05]), CandidateFeedback([Disc(0.0, -1.0, 0.4)], [0.9, 0.0])]
    cands = make_proposer("geometric", seed=0).propose_split(q, W, fb)
    assert len(cands) == W
    for c in cands:
        assert_valid(c, maze)
        assert c[0] == corner and len(c) >= 2  # keeps the best candidate, adds waypoints on its failed leg
    pts = [q.start.centre()] + [r.centre() for r in cands[0]] + [q.goal.centre()]
    assert all(segment_clear(maze, a, b, 0.2) for a, b in zip(pts, pts[1:]))
    # nothing left to fix: jittered copies of the best
    fine = make_proposer("geometric", seed=0).propose_split(q, 2, [CandidateFeedback(cands[0], [1.0] * 3)])
    assert len(fine) == 2 and all(len(c) == len(cands[0]) for c in fine)


@pytest.mark.parametrize("spec", ["geometric", "random"])
def test_offline_graph_proposals_refine_the_original(spec):
    maze = load_maze("u_chain_3_subgoals")
    original = maze_task(maze)
    q = GraphQuery(maze, "point", original, 0.1, 32, None, edge_success={e: 0.5 for e in original.edges()})
    p = make_proposer(spec, seed=1)
    graphs = p.propose_graph(q, W)
    assert len(graphs) == W and len({g.to_json() for g in graphs}) == W
    for g in graphs:
        assert check_refines(g, original) == []
        assert len(g.vertices()) > len(original.vertices())
        assert set(original.vertices()) <= set(g.vertices()) and g.initial == "S" and g.finals == {"G"}
        for v in g.vertices():
            if g.g.nodes[v]["refines"] is None:
                assert check_region(g.region(v), maze) is None
    edge_success = {e: (0.1 if i == 0 else 1.0) for i, e in enumerate(graphs[0].edges())}
    worst = graphs[0].edges()[0]
    again = p.propose_graph(q, 2, [GraphFeedback(graphs[0], edge_success, 0.1)])
    for g in again:
        assert check_refines(g, original) == []
        assert len(g.vertices()) > len(graphs[0].vertices()) and not g.g.has_edge(*worst)


def test_split_prompt_without_pictures_still_builds():
    maze = load_maze("x_maze").for_agent("ant")
    q = edge_queries(maze, "ant")[0]
    msgs = split_messages(q, [CandidateFeedback([Disc(0.0, 0.0, 1.6)], [0.5, 0.5], None)])
    text = "\n".join(p["text"] for p in msgs[1]["content"] if p["type"] == "text")
    assert "cell size 4.0 m" in text and "Agent: ant" in text and "within 0.52 m" in text
    assert "no picture available" in text and not any(p["type"] == "image_url" for p in msgs[1]["content"])
