"""The imperfect proposer: each error mode injects the error it documents, measured on its replies."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from specrefine.core.errors import SpecrefineError
from specrefine.core.mazes import load_maze, parse_maze
from specrefine.core.spec import maze_task
from specrefine.proposers import CandidateFeedback, EdgeQuery, GraphQuery, make_proposer, parse_split
from specrefine.proposers.imperfect import (
    PRESETS,
    ErrorModelClient,
    ImperfectConfig,
    ImperfectProposer,
    convex_corners,
    parse_imperfect,
)

N = 200  # replies per measurement


def maze(name="u_chain_3"):
    return load_maze(name).for_agent("point")


def edge_query(m):
    return EdgeQuery(maze=m, agent="point", start=m.start, goal=m.goal, avoid=m.walls, success=0.0, n=32,
                     image_png=None)


def replies(config, m=None, n=N, seed=0, feedback=()):
    """Raw reply texts of the error model for the maze's S -> G edge, and the client (its injection log)."""
    m = m or maze()
    client = ErrorModelClient(config, seed=seed)
    client.context = ("split", edge_query(m), list(feedback))
    return client.complete([], n=n), client


def centres(text) -> np.ndarray:
    return np.array([w["center"] for w in json.loads(text)["waypoints"]], dtype=float)


def truth(m=None):
    """The uncorrupted route (every turn kept, legs uncapped)."""
    texts, _ = replies(ImperfectConfig(p_uncapped=1.0), m, n=1)
    return centres(texts[0])


def binomial_ok(k, n, p):
    """k successes of n consistent with probability p (4 standard deviations)."""
    return abs(k - n * p) <= 4 * math.sqrt(n * p * (1 - p)) + 1


def test_presets_parse_and_bad_specs_are_one_line_errors():
    assert parse_imperfect("moderate") == PRESETS["moderate"]
    assert parse_imperfect("moderate, alpha=0.1").alpha == 0.1
    assert parse_imperfect("position_sigma=0.2,rho=0.5") == ImperfectConfig(position_sigma=0.2, rho=0.5)
    for bad, why in [("sloppy", "unknown preset"), ("mild,foo=1", "unknown parameter 'foo'"),
                     ("mild,rho=2", "probability"), ("mild,position_sigma=-1", ">= 0"), ("mild,alpha", "key=value"),
                     ("mild,alpha=x", "not a number"), ("mild,alpha=nan", ">= 0")]:
        with pytest.raises(SpecrefineError, match=why):
            parse_imperfect(bad)
    out = subprocess.run([sys.executable, "-m", "specrefine.cli", "refine", "u_chain_3", "--proposer",
                          "imperfect:mild,foo=1"], capture_output=True, text=True)
    assert out.returncode == 2 and len(out.stderr.strip().splitlines()) == 1 and "foo" in out.stderr


def test_it_is_never_reported_as_a_vlm():
    proposer = make_proposer("imperfect:moderate", seed=3)
    assert isinstance(proposer, ImperfectProposer) and not proposer.is_vlm and proposer.calls == 0
    assert "not a VLM" in proposer.name
    proposer.propose_split(edge_query(maze()), w=3)
    d = proposer.describe()
    assert d["is_vlm"] is False and d["vlm_calls"] == 0 and d["proposer_calls"] >= 1
    assert d["error_model"]["position_sigma"] == PRESETS["moderate"].position_sigma


def test_a_perfect_error_model_is_the_geometric_route():
    texts, _ = replies(ImperfectConfig(), n=5)
    pts = [centres(t) for t in texts]
    assert all(np.array_equal(p, pts[0]) for p in pts)  # nothing random left
    m = maze()
    assert all(not m.walls.contains(p) for p in pts[0])
    assert len(truth()) >= 4  # u_chain_3 turns at every U


def test_position_error_has_the_stated_spread_and_is_not_snapped():
    t = truth()
    sigma = 0.3
    texts, _ = replies(ImperfectConfig(position_sigma=sigma, p_uncapped=1.0))
    offsets = np.concatenate([centres(x) - t for x in texts])
    assert np.std(offsets) == pytest.approx(sigma, rel=0.1)  # cell size 1 m
    m = maze()
    inside = np.mean([m.walls.contains(p) for x in texts for p in centres(x)])
    assert inside > 0.05  # not snapped to free space: some land in walls


def test_coordinates_are_rounded_to_the_coarse_grid():
    texts, _ = replies(ImperfectConfig(position_sigma=0.3, coord_grid=0.5), n=50)
    values = np.concatenate([centres(x).ravel() for x in texts])
    assert np.allclose(values * 2, np.round(values * 2))


def test_radius_is_log_normal_around_the_nominal_size():
    texts, _ = replies(ImperfectConfig(radius=0.4, radius_log_sigma=0.35))
    radii = np.array([w["radius"] for x in texts for w in json.loads(x)["waypoints"]])
    logs = np.log(radii / 0.4)
    assert abs(logs.mean()) < 0.05 and np.std(logs) == pytest.approx(0.35, rel=0.12)


def test_corner_pull_moves_waypoints_onto_convex_corners():
    m = maze()
    corners = convex_corners(m)
    texts, _ = replies(ImperfectConfig(corner_pull=1.0), n=3)
    d = [np.linalg.norm(corners - p, axis=1).min() for x in texts for p in centres(x)]
    assert max(d) < 1e-6
    half, _ = replies(ImperfectConfig(corner_pull=0.5), n=1)
    assert all(0.1 < np.linalg.norm(corners - p, axis=1).min() for p in centres(half[0]))


def test_turns_are_dropped_with_the_stated_probability():
    n_turns = len(truth())
    texts, client = replies(ImperfectConfig(p_drop_turn=0.3, p_uncapped=1.0))
    dropped = sum(r["dropped"] for r in client.injected)
    assert sum(r["turns"] for r in client.injected) == n_turns * N
    assert binomial_ok(dropped, n_turns * N, 0.3)
    kept = sum(len(centres(x)) for x in texts)
    assert kept >= n_turns * N - dropped  # a reply with every turn dropped still names its midpoint


def test_legs_are_capped_at_the_reach_unless_the_reply_forgets():
    m = parse_maze("###########\n#S.......G#\n###########", "corridor")  # 8 m straight
    reach = 3.0  # the point policy's reach (m)

    def longest_leg(text):
        pts = np.vstack([m.start.centre(), centres(text), m.goal.centre()])
        return np.linalg.norm(np.diff(pts, axis=0), axis=1).max()

    capped, _ = replies(ImperfectConfig(p_uncapped=0.0), m, n=20)
    free, client = replies(ImperfectConfig(p_uncapped=0.5), m)
    assert max(longest_leg(x) for x in capped) <= reach + 1e-6
    assert binomial_ok(sum(bool(r.get("uncapped")) for r in client.injected), N, 0.5)
    assert max(longest_leg(x) for x in free) > reach


def _crosses_wall(m, text) -> bool:
    pts = np.vstack([m.start.centre(), centres(text), m.goal.centre()])
    for a, b in zip(pts, pts[1:]):
        t = np.linspace(0, 1, 50)[:, None]
        if m.walls.contains(a + t * (b - a)).any():
            return True
    return False


def test_false_openings_plan_through_a_wall():
    m = maze()
    honest, _ = replies(ImperfectConfig(), m, n=1)
    fooled, client = replies(ImperfectConfig(p_false_opening=0.4), m)
    assert not _crosses_wall(m, honest[0])
    opened = [bool(r.get("false_opening")) for r in client.injected]
    assert binomial_ok(sum(opened), N, 0.4)
    crossing = [_crosses_wall(m, x) for x in fooled]
    assert all(crossing[i] for i in range(N) if opened[i])  # every opened plan cuts through a wall
    assert not any(crossing[i] for i in range(N) if not opened[i])


TWO_DOORS = """###############
#S....#.......#
#.....#.......#
#.............#
#.....#.#####.#
#.....#.#...#.#
#.....#.#.G.#.#
#.....#.#...#.#
#.....#.##.##.#
#.............#
###############"""  # the upper door (row 3) is nearer the straight line S-G, the lower one (row 9) is shorter


def test_wrong_branch_takes_the_doorway_nearest_the_straight_line():
    m = parse_maze(TWO_DOORS, "two_doors")
    upper_y = m.cell_to_xy(3, 6)[1]

    def doorway(text):  # the lower route never comes near the upper door's row
        return "upper" if np.abs(centres(text)[:, 1] - upper_y).min() < 0.5 else "lower"

    right, _ = replies(ImperfectConfig(p_uncapped=1.0), m, n=1)
    wrong, client = replies(ImperfectConfig(p_uncapped=1.0, p_wrong_branch=0.3), m)
    assert doorway(right[0]) == "lower"
    greedy = [bool(r.get("wrong_branch")) for r in client.injected]
    assert binomial_ok(sum(greedy), N, 0.3)
    assert [doorway(x) == "upper" for x in wrong] == greedy


def test_mirrored_replies_flip_y_and_nothing_else():
    straight, _ = replies(ImperfectConfig(position_sigma=0.2), n=20, seed=4)
    mirrored, client = replies(ImperfectConfig(position_sigma=0.2, p_mirror_y=1.0), n=20, seed=4)
    for a, b in zip(straight, mirrored):
        assert np.allclose(centres(b), centres(a) * [1, -1])
    assert all(r["mirrored_y"] for r in client.injected)


def test_unparseable_replies_at_the_stated_rate_are_rejected_like_real_ones():
    m = maze()
    texts, client = replies(ImperfectConfig(p_unparseable=0.2), m)
    bad = 0
    for text in texts:
        try:
            parse_split(text, m)
        except Exception:  # noqa: BLE001 - counting rejections
            bad += 1
    assert bad == sum(bool(r.get("unparseable")) for r in client.injected)
    assert binomial_ok(bad, N, 0.2)


def test_waypoints_in_walls_go_through_the_real_validation_and_re_ask():
    proposer = make_proposer("imperfect:position_sigma=0.6,p_uncapped=1", seed=1)
    for _ in range(10):
        proposer.propose_split(edge_query(maze()), w=3)
    rejected = [r for h in proposer.history for r in h["rejected"]]
    assert any("inside a wall" in r for r in rejected)
    assert any(h["reasked"] for h in proposer.history)
    assert proposer.proposer_calls == 10 + sum(h["reasked"] for h in proposer.history)


def test_feedback_repairs_the_weakest_leg_with_probability_rho():
    m = maze()
    earlier = [list(map(_disc, truth()[:2]))]  # two waypoints: three legs, the last one weakest
    fb = [CandidateFeedback(waypoints=earlier[0], subtask_success=[0.9, 0.8, 0.1])]
    texts, client = replies(ImperfectConfig(rho=0.7), m, feedback=fb)
    repairs = [r["repair"] for r in client.injected]
    assert binomial_ok(repairs.count("weakest"), N, 0.7)
    assert binomial_ok(repairs.count("wrong-leg"), N, 0.15) and binomial_ok(repairs.count("repeat"), N, 0.15)
    for text, how in zip(texts, repairs):
        pts = centres(text)
        if how == "weakest":  # the first two waypoints kept, new ones on the last leg
            assert np.allclose(pts[:2], truth()[:2]) and len(pts) > 2
        if how == "repeat":
            assert len(pts) == 2


def _disc(p):
    from specrefine.core.regions import Disc

    return Disc(float(p[0]), float(p[1]), 0.4)


def test_whole_graph_replies_ignore_subgoals_with_the_stated_probability():
    m = load_maze("u_chain_2_subgoals").for_agent("point")
    proposer = make_proposer("imperfect:p_ignore_subgoals=0.3", seed=2)
    graph = maze_task(m)
    q = GraphQuery(maze=m, agent="point", graph=graph, success=0.0, n=32, image_png=None)
    graphs = [g for _ in range(100) for g in proposer.propose_graph(q, w=1)]
    assert len(graphs) == 100  # a perfect model's graphs all parse
    ignored = [not any(g.g.nodes[v]["refines"] == "a" for v in g.vertices()) for g in graphs]
    assert binomial_ok(sum(ignored), 100, 0.3)
    logged = [bool(r.get("ignored_subgoals")) for r in proposer.client.injected]
    assert ignored == logged


def test_alpha_grows_the_position_error_with_the_turns_a_query_spans():
    t = truth()
    base, _ = replies(ImperfectConfig(position_sigma=0.2, p_uncapped=1.0), n=100)
    grown, client = replies(ImperfectConfig(position_sigma=0.2, p_uncapped=1.0, alpha=0.25), n=100)
    turns = client.injected[0]["span_turns"]
    spread = lambda texts: np.std(np.concatenate([centres(x) - t for x in texts]))  # noqa: E731
    assert spread(grown) / spread(base) == pytest.approx(1 + 0.25 * (turns - 1), rel=0.15)


def test_same_seed_same_replies_and_its_own_random_stream():
    a, _ = replies(PRESETS["moderate"], n=10, seed=5)
    b, _ = replies(PRESETS["moderate"], n=10, seed=5)
    c, _ = replies(PRESETS["moderate"], n=10, seed=6)
    assert a == b and a != c


MISREAD = dict(position_sigma=0.2)  # a base whose replies differ from one another


def test_misreadings_leave_every_other_draw_as_it_was():
    base, _ = replies(ImperfectConfig(**MISREAD), seed=7)
    texts, client = replies(ImperfectConfig(**MISREAD, p_swap_xy=0.2, p_shuffle=0.2, p_truncate=0.2, p_stale=0.2),
                            seed=7)
    untouched = [not any(k in r for k in ("swapped_xy", "shuffled", "truncated", "stale")) for r in client.injected]
    assert 0 < sum(untouched) < N
    assert all(a == b for a, b, u in zip(base, texts, untouched) if u)
    assert all(a != b for a, b, u in zip(base, texts, untouched) if not u)


def test_swapped_replies_exchange_x_and_y_at_the_stated_rate():
    base, _ = replies(ImperfectConfig(**MISREAD), seed=8)
    texts, client = replies(ImperfectConfig(**MISREAD, p_swap_xy=0.3), seed=8)
    swapped = [bool(r.get("swapped_xy")) for r in client.injected]
    assert binomial_ok(sum(swapped), N, 0.3)
    for a, b, s in zip(base, texts, swapped):
        assert np.allclose(centres(b), centres(a)[:, ::-1] if s else centres(a))


def test_bias_moves_every_waypoint_by_one_vector_per_run():
    m = maze()
    moves = {}
    for seed in (1, 2):
        base, _ = replies(ImperfectConfig(**MISREAD), m, n=20, seed=seed)
        texts, _ = replies(ImperfectConfig(**MISREAD, bias=0.5), m, n=20, seed=seed)
        shift = np.concatenate([centres(b) - centres(a) for a, b in zip(base, texts)])
        assert np.allclose(shift, shift[0], atol=0.02)  # coordinates are written to two decimals before the shift
        assert np.linalg.norm(shift[0]) == pytest.approx(0.5 * m.cell_size, abs=0.02)
        moves[seed] = shift[0]
    assert not np.allclose(moves[1], moves[2])  # the direction is drawn per run


def test_shuffled_and_truncated_replies_keep_their_waypoints_or_their_first_half():
    base, _ = replies(ImperfectConfig(**MISREAD), seed=9)
    texts, client = replies(ImperfectConfig(**MISREAD, p_shuffle=0.3, p_truncate=0.3), seed=9)
    log = client.injected
    assert binomial_ok(sum("shuffled" in r for r in log), N, 0.3)
    assert binomial_ok(sum("truncated" in r for r in log), N, 0.3)
    for a, b, r in zip(base, texts, log):
        before, after = centres(a), centres(b)
        if "truncated" in r:
            assert len(after) == len(before) // 2 and r["truncated"] == len(before) - len(after)
        else:
            assert len(after) == len(before)
        if "shuffled" not in r:
            assert np.allclose(after, before[: len(after)])
        elif "truncated" not in r:
            assert sorted(map(tuple, after)) == sorted(map(tuple, before))


def test_stale_replies_repeat_the_previous_edge_answer():
    texts, client = replies(ImperfectConfig(**MISREAD, p_stale=0.3), seed=10)
    stale = [bool(r.get("stale")) for r in client.injected]
    assert not stale[0] and binomial_ok(sum(stale), N - 1, 0.3)
    for i in range(1, N):
        assert np.array_equal(centres(texts[i]), centres(texts[i - 1])) == stale[i]
