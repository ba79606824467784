"""The corrector (method ours-corrector, beyond the paper) on a stubbed straight corridor S (x = 0) -> G (x = 10).

Each leg's success is a function of where it starts and ends (x of the regions' centres), the same on every draw:
what the stub's proposer answers decides what each lever can do.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np
import pytest
from test_refine_search import WALLS, _Arrive, _chain_graph, _Query, box_at

from specrefine.core.errors import SpecrefineError
from specrefine.core.graph import TaskGraph, check_refines
from specrefine.core.regions import Box, Disc
from specrefine.refine import RefinementSearch, SearchConfig
from specrefine.refine.correct import (
    CHECK_SEED_OFFSET,
    PASS_SEED_STEP,
    Check,
    _span_ahead,
    split_start,
    weak_below,
    weakest_untried,
)
from specrefine.refine.roadmap import Roadmap
from specrefine.refine.search import live_start
from specrefine.runs.explore import describe
from specrefine.runs.methods import BACKTRACK, BRIDGE, DEEP, FINE, FLOOR, GUARD, MEND, SPAN, get_method


class LegTable:
    """p of a leg x0 -> x1 from a table (default 1.0), from ``fresh`` on the correction's fresh rollouts (a seed
    given) where it has the leg; counts the rollouts and seeds it was asked for."""

    n = 32

    def __init__(self, table, fresh=None, by_seed=None):
        self.table, self.fresh, self.calls = table, fresh or {}, []
        self.by_seed = by_seed or {}  # seed -> a fresh table of its own (a later pass's draw)

    sim_steps = 0

    @property
    def evaluations(self) -> int:  # the evaluator's counter, as the search's steps log it so far
        return len(self.calls)

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None, n=None):
        x0 = 0.0 if isinstance(start, Box) else start[1][0]
        x1 = float(goal.centre()[0])
        self.calls.append((x0, x1, n, seed))
        p = self.by_seed.get(seed, self.fresh).get((x0, x1)) if seed is not None else None
        return _Arrive(self.table.get((x0, x1), 1.0) if p is None else p, n=n or self.n, at=(x1, 0.0))


class AnswerBook:
    """Splits of the leg that ends at x (the query's goal): a list of waypoint x's per goal, or nothing."""

    name, is_vlm = "stub", False

    def __init__(self, book):
        self.book, self.queries = book, []

    def propose_split(self, query, w, feedback=()):
        x = float(query.goal.centre()[0])
        start = float(query.graph.region(query.u).centre()[0])
        self.queries.append((start, x))
        answer = self.book.get((start, x), self.book.get(x))
        return [[Disc(a, 0, 0.5) for a in answer]] if answer else []


def run(evaluator, proposer, **cfg):
    g = _chain_graph()
    config = SearchConfig(w=1, d=1, vertex_refinement=False, **cfg)
    result = RefinementSearch(g, evaluator, proposer=proposer, config=config,
                              query_for=lambda graph, u, v, r: _Query(graph, u, v)).run()
    return g, result


def point_run(tmp_path, method: str) -> tuple[dict, list[dict]]:
    """``method`` end to end on the point's U-chain 2 (imperfect:moderate, seed 1, centre goal points, a small run)
    -> (its result.json, its steps log)."""
    from specrefine.runs.pipeline import refine_maze

    out = tmp_path / "run"
    result = refine_maze("u_chain_2", method=method, proposer="imperfect:moderate", out=out, agent="point",
                         rollouts=8, episodes=20, seed=1, goal_points="centre").data
    return result, [json.loads(line) for line in (out / "steps.jsonl").read_text().splitlines()]


def xs(result):
    return [result.graph.region(v).centre()[0] for v in result.path]


# --- recursive repair ---------------------------------------------------------------------------------------
DEAD_TWICE = {(0.0, 10.0): 0.0, (3.0, 6.0): 0.0, (3.0, 4.5): 0.0}
SPLITS = {(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5], (3.0, 4.5): [3.75]}


def test_one_level_of_repair_gives_up_when_the_legs_split_has_a_dead_leg_of_its_own():
    g, result = run(LegTable(DEAD_TWICE), AnswerBook(SPLITS), repair=True)
    assert result.path == ["S", "G"] and result.predicted_success == 0.0


def test_repair_to_three_levels_repairs_the_dead_leg_of_the_legs_split():
    g, result = run(LegTable(DEAD_TWICE), AnswerBook(SPLITS), repair=True, repair_depth=3)
    assert xs(result) == [0.0, 3.0, 3.75, 4.5, 6.0, 10.0]
    assert result.predicted_success == pytest.approx(1.0)
    assert check_refines(result.graph, g) == []


# --- the correction of the found path -----------------------------------------------------------------------
LUCKY = {(0.0, 10.0): 0.0}  # the search's own estimates: every leg of S -> 3 -> 6 -> G at 1.0
FRESH = {(3.0, 6.0): 0.75}  # on fresh rollouts the middle leg loses a quarter (the search's 32 of 32 was lucky)


def test_a_leg_refuted_by_fresh_rollouts_is_split_when_its_split_gains_there():
    ev, book = LegTable(LUCKY, FRESH), AnswerBook({(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5]})
    g, result = run(ev, book, correct_rollouts=4)
    assert xs(result) == [0.0, 3.0, 4.5, 6.0, 10.0]
    assert check_refines(result.graph, g) == []
    fresh = [(n, seed) for *_, n, seed in ev.calls if seed is not None]
    assert fresh and set(fresh) == {(4 * 32, CHECK_SEED_OFFSET)}  # 4 x n rollouts, a seed apart
    leg = next(s for s in result.steps if s["event"] == "correct-leg")
    assert leg["p_leg"] == pytest.approx(0.75) and leg["accepted"] == "split"
    done = next(s for s in result.steps if s["event"] == "correct-done")
    assert done["p"] == pytest.approx(1.0)


def test_without_the_correction_the_lucky_estimate_is_trusted():
    _, result = run(LegTable(LUCKY, FRESH), AnswerBook({(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5]}))
    assert xs(result) == [0.0, 3.0, 6.0, 10.0] and result.predicted_success == pytest.approx(1.0)


def test_a_gain_below_one_rollout_is_not_taken():
    # on fresh rollouts the split of 3 -> 6 is better by less than 1/128 over the window: the path stays
    fresh = {(3.0, 6.0): 0.99, (3.0, 4.5): 0.995}
    _, result = run(LegTable(LUCKY, fresh), AnswerBook({(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5]}),
                    correct_rollouts=4)
    assert xs(result) == [0.0, 3.0, 6.0, 10.0]
    leg = next(s for s in result.steps if s["event"] == "correct-leg")
    assert leg["accepted"] is None and leg["tried"][0]["kind"] == "split"


def test_a_bad_waypoint_is_resplit_over():
    # the waypoint at 6 is bad both to reach and to leave; asked over it (3 -> 10) the proposer answers 5 and 7.5
    fresh = {(3.0, 6.0): 0.8, (6.0, 10.0): 0.8, (3.0, 10.0): 0.0, (4.5, 6.0): 0.8}
    book = AnswerBook({(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5], (3.0, 10.0): [5, 7.5]})
    g, result = run(LegTable(LUCKY, fresh), book, correct_rollouts=4, correct_reach=0.0)
    assert xs(result) == [0.0, 3.0, 5.0, 7.5, 10.0]
    assert check_refines(result.graph, g) == []
    assert (3.0, 10.0) in book.queries


def test_the_correction_spends_at_most_one_split_per_leg_of_the_found_path():
    fresh = {(0.0, 3.0): 0.5, (3.0, 6.0): 0.5, (6.0, 10.0): 0.5}
    book = AnswerBook({(0.0, 10.0): [3, 6]})  # asked about any leg, it has nothing to say
    _, result = run(LegTable(LUCKY, fresh), book, correct_rollouts=4)
    assert len(book.queries) == 1 + 3  # the search's split, then one per leg of the 3-leg path
    assert xs(result) == [0.0, 3.0, 6.0, 10.0]


def test_ours_corrector_runs_end_to_end_and_logs_its_correction(tmp_path):
    from specrefine.runs.pipeline import refine_maze

    out = tmp_path / "run"
    result = refine_maze("u_chain_2", method="ours-corrector", proposer="imperfect:moderate", out=out, agent="point",
                         rollouts=8, episodes=20, seed=1)
    steps = [json.loads(line) for line in (out / "steps.jsonl").read_text().splitlines()]
    events = [s["event"] for s in steps]
    assert events[-1] == "done" and "correct-check" in events and "correct-done" in events
    check = next(s for s in steps if s["event"] == "correct-check")
    assert len(check["probabilities"]) == len(check["path"]) - 1
    assert result.data["method"] == "ours-corrector" and result.data["proposer_calls"] >= 1
    assert result.data["refines_input"] is True
    calls = [s["proposer_calls"] for s in steps]  # each step: the proposer's calls so far
    assert calls == sorted(calls) and calls[-1] == result.data["proposer_calls"]
    assert 0 <= check["proposer_calls"] <= calls[-1]  # what the search spent before its correction


# --- the gate (method ours-corrector-gated): the proposer is asked about a leg only with enough fresh failures -----
ONE_FAILURE = {(3.0, 6.0): 127 / 128}  # the middle leg fails 1 of the 128 fresh rollouts
THREE_FAILURES = {(3.0, 6.0): 125 / 128}


def test_the_gate_asks_nothing_about_a_leg_with_fewer_fresh_failures_than_it_needs():
    book = AnswerBook({(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5]})
    _, result = run(LegTable(LUCKY, ONE_FAILURE), book, correct_rollouts=4, correct_min_failures=3)
    assert book.queries == [(0.0, 10.0)]  # the search's split only
    assert xs(result) == [0.0, 3.0, 6.0, 10.0]
    leg = next(s for s in result.steps if s["event"] == "correct-leg")
    assert leg["tried"] == [] and leg["accepted"] is None


def test_the_gate_still_offers_the_bypass_which_asks_nothing():
    # within reach, S -> 6 and 3 -> G never fail: the bypass over 3 (the first of the two) drops the weak leg
    book = AnswerBook({(0.0, 10.0): [3, 6]})
    _, result = run(LegTable(LUCKY, ONE_FAILURE), book, correct_rollouts=4, correct_min_failures=3,
                    correct_reach=10.0)
    assert book.queries == [(0.0, 10.0)]
    assert xs(result) == [0.0, 6.0, 10.0]
    leg = next(s for s in result.steps if s["event"] == "correct-leg")
    assert [t["kind"] for t in leg["tried"]] == ["bypass", "bypass"] and leg["accepted"] == "bypass"


def test_the_gate_splits_a_leg_with_enough_fresh_failures_as_the_corrector_does():
    for gate in (1, 3):
        book = AnswerBook({(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5]})
        _, result = run(LegTable(LUCKY, THREE_FAILURES), book, correct_rollouts=4, correct_min_failures=gate)
        assert (3.0, 6.0) in book.queries
        assert xs(result) == [0.0, 3.0, 4.5, 6.0, 10.0]


def test_without_the_gate_a_single_fresh_failure_is_split():
    book = AnswerBook({(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5]})
    _, result = run(LegTable(LUCKY, ONE_FAILURE), book, correct_rollouts=4)
    assert (3.0, 6.0) in book.queries and xs(result) == [0.0, 3.0, 4.5, 6.0, 10.0]


def test_a_leg_no_fresh_rollout_reaches_is_not_split():
    # fresh, the middle leg never succeeds, so nothing reaches the last one: the proposer is asked about the dead
    # leg (and over its end waypoint), never about the unreached leg, whose split would start from no state (that
    # crashed two ours-checked cells of the levers grid at code 722e118, in Algorithm 2's round)
    from specrefine.refine.correct import correct

    g = _chain_graph()
    path = ["S", *g.split_edge("S", "G", [Disc(3, 0, 0.5), Disc(6, 0, 0.5)]), "G"]
    asked = []

    def split_leg(graph, a, b, result, start):
        asked.append((graph.region(a).centre()[0], graph.region(b).centre()[0], start))
        return None

    _, kept, check = correct(g, path, LegTable({}, {(3.0, 6.0): 0.0}), rollouts=128, seed=CHECK_SEED_OFFSET,
                             split_leg=split_leg, may_split=lambda: True, reach=0.0, clearance=0.0,
                             log=lambda *a, **k: None)
    assert [(a, b) for a, b, _ in asked] == [(3.0, 6.0), (3.0, 10.0)]
    assert all(start is not None for *_, start in asked)
    assert kept == path and check.probabilities == [1.0, 0.0, 0.0]


# --- lean judging (method ours-corrector-lean): a leg must earn its place -----------------------------------------
def test_lean_judging_declines_three_sound_legs_for_one_that_failed_once():
    # raw, 128 of 128 on three legs beats 127 of 128 on one; by posterior means one more switch costs more than that
    for lean, expected in ((False, [0.0, 3.0, 4.0, 5.0, 6.0, 10.0]), (True, [0.0, 3.0, 6.0, 10.0])):
        book = AnswerBook({(0.0, 10.0): [3, 6], (3.0, 6.0): [4, 5]})
        _, result = run(LegTable(LUCKY, ONE_FAILURE), book, correct_rollouts=4, correct_lean=lean)
        assert (3.0, 6.0) in book.queries and xs(result) == expected


def test_lean_judging_still_takes_a_split_that_mends_a_refuted_leg():
    book = AnswerBook({(0.0, 10.0): [3, 6], (3.0, 6.0): [4, 5]})
    _, result = run(LegTable(LUCKY, FRESH), book, correct_rollouts=4, correct_lean=True)
    assert xs(result) == [0.0, 3.0, 4.0, 5.0, 6.0, 10.0]


def test_lean_offers_every_waypoint_its_bypass_and_takes_the_shorter_path():
    # every leg sound on fresh rollouts, so no leg is weak; lean still drops the waypoint at 3 (S -> 6 in reach)
    for lean, expected in ((False, [0.0, 3.0, 6.0, 10.0]), (True, [0.0, 6.0, 10.0])):
        g, result = run(LegTable(LUCKY), AnswerBook({(0.0, 10.0): [3, 6]}), correct_rollouts=4, correct_reach=10.0,
                        correct_lean=lean)
        assert xs(result) == expected
        assert check_refines(result.graph, g) == []
        pruned = [s for s in result.steps if s["event"] == "correct-prune"]
        assert bool(pruned) == lean
        if lean:
            assert pruned[0]["accepted"] == "bypass" and pruned[0]["tried"][0]["legs"] == 2


def test_lean_keeps_a_waypoint_whose_bypass_fails_more():
    fresh = {(0.0, 6.0): 0.9, (3.0, 10.0): 0.9}  # either bypass loses a tenth
    _, result = run(LegTable(LUCKY, fresh), AnswerBook({(0.0, 10.0): [3, 6]}), correct_rollouts=4,
                    correct_reach=10.0, correct_lean=True)
    assert xs(result) == [0.0, 3.0, 6.0, 10.0]
    assert [s["accepted"] for s in result.steps if s["event"] == "correct-prune"] == [None, None]


def test_posterior_mean_of_a_leg_nothing_reached_is_zero():
    from specrefine.core.results import unreached
    from specrefine.refine.correct import posterior_mean

    assert posterior_mean(unreached()) == 0.0
    assert posterior_mean(_Arrive(1.0, n=128)) == pytest.approx(129 / 130)


def test_ours_corrector_lean_runs_end_to_end_and_logs_its_pruning(tmp_path):
    from specrefine.runs.pipeline import refine_maze

    out = tmp_path / "run"
    result = refine_maze("u_chain_2", method="ours-corrector-lean", proposer="imperfect:mild", out=out,
                         agent="point", rollouts=8, episodes=20, seed=0)
    steps = [json.loads(line) for line in (out / "steps.jsonl").read_text().splitlines()]
    events = [s["event"] for s in steps]
    assert events[-1] == "done" and "correct-check" in events and "correct-done" in events
    done = next(s for s in steps if s["event"] == "correct-done")
    assert len(done["path"]) - 1 == result.data["path_edges"]
    assert result.data["method"] == "ours-corrector-lean" and result.data["refines_input"] is True


# --- passes (SearchConfig.correct_passes): the correction again on a draw that did not choose the path -------------
SECOND_DRAW = CHECK_SEED_OFFSET + PASS_SEED_STEP
PASS_BOOK = {(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5], (4.5, 6.0): [5.25]}


@pytest.mark.parametrize("confirm_pick", [False, True])  # True: ours-corrector-redraw, the Ant's (confirm + 2 passes)
def test_a_second_pass_splits_a_leg_that_was_lucky_on_the_draw_that_chose_it(confirm_pick):
    # the first pass splits 3 -> 6 (0.75) through 4.5, whose legs never fail on its draw; on the second draw
    # 4.5 -> 6 loses a fifth, and the second pass splits it through 5.25
    ev = LegTable(LUCKY, FRESH, by_seed={SECOND_DRAW: {(4.5, 6.0): 0.8}})
    g, result = run(ev, AnswerBook(PASS_BOOK), correct_rollouts=4, correct_passes=2, confirm_pick=confirm_pick)
    assert xs(result) == [0.0, 3.0, 4.5, 5.25, 6.0, 10.0]
    assert check_refines(result.graph, g) == []
    assert {seed for *_, seed in ev.calls if seed is not None} == {CHECK_SEED_OFFSET, SECOND_DRAW}
    legs = [s for s in result.steps if s["event"] == "correct-leg"]
    assert [(s["correct_pass"], s["accepted"]) for s in legs] == [(1, "split"), (2, "split")]


def test_one_pass_keeps_the_leg_its_own_draw_chose():
    ev = LegTable(LUCKY, FRESH, by_seed={SECOND_DRAW: {(4.5, 6.0): 0.8}})
    _, result = run(ev, AnswerBook(PASS_BOOK), correct_rollouts=4)
    assert xs(result) == [0.0, 3.0, 4.5, 6.0, 10.0]
    assert SECOND_DRAW not in {seed for *_, seed in ev.calls}


def test_correct_passes_must_be_positive():
    with pytest.raises(ValueError, match="correct_passes"):
        SearchConfig(correct_passes=0)


# --- cheapest first (SearchConfig.correct_first_win) and one round (correct_rounds): method ours-corrector-frugal ---
SPLIT_BOOK = {(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5], (3.0, 10.0): [5, 7.5]}


def test_a_winning_bypass_asks_the_proposer_nothing():
    for first_win, asked in ((False, True), (True, False)):
        book = AnswerBook(SPLIT_BOOK)
        _, result = run(LegTable(LUCKY, THREE_FAILURES), book, correct_rollouts=4, correct_min_failures=3,
                        correct_reach=10.0, correct_first_win=first_win)
        assert ((3.0, 6.0) in book.queries) is asked
        assert xs(result) == [0.0, 6.0, 10.0]  # the bypass over 3 wins either way
        leg = next(s for s in result.steps if s["event"] == "correct-leg")
        assert leg["accepted"] == "bypass"


def test_a_winning_split_is_taken_without_asking_over_the_next_waypoint():
    for first_win, asked in ((False, True), (True, False)):
        book = AnswerBook(SPLIT_BOOK)
        _, result = run(LegTable(LUCKY, FRESH), book, correct_rollouts=4, correct_first_win=first_win)
        assert ((3.0, 10.0) in book.queries) is asked
        assert xs(result) == [0.0, 3.0, 4.5, 6.0, 10.0]
        leg = next(s for s in result.steps if s["event"] == "correct-leg")
        assert leg["accepted"] == "split" and [t["kind"] for t in leg["tried"]][0] == "split"


def test_cheapest_first_still_asks_over_the_waypoint_when_the_split_does_not_win():
    fresh = {(3.0, 6.0): 0.8, (6.0, 10.0): 0.8, (3.0, 10.0): 0.0, (4.5, 6.0): 0.8}
    book = AnswerBook(SPLIT_BOOK)
    g, result = run(LegTable(LUCKY, fresh), book, correct_rollouts=4, correct_reach=0.0, correct_first_win=True)
    assert xs(result) == [0.0, 3.0, 5.0, 7.5, 10.0]
    assert check_refines(result.graph, g) == []
    leg = next(s for s in result.steps if s["event"] == "correct-leg")
    assert [t["kind"] for t in leg["tried"]] == ["split", "resplit"] and leg["accepted"] == "resplit"


def test_one_round_asks_the_proposer_once_per_correction_split():
    # the split 3 -> 4.5 -> 6 loses on the search's own rollouts, so Algorithm 1 would ask a second round
    table = {**LUCKY, (3.0, 4.5): 0.9}
    for rounds, asked in ((None, 2), (1, 1)):
        book = AnswerBook({(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5]})
        config = SearchConfig(w=1, d=2, vertex_refinement=False, correct_rollouts=4, correct_rounds=rounds)
        RefinementSearch(_chain_graph(), LegTable(table, FRESH), proposer=book, config=config,
                         query_for=lambda graph, u, v, r: _Query(graph, u, v)).run()
        assert book.queries.count((3.0, 6.0)) == asked
        assert book.queries.count((0.0, 10.0)) == 1  # the search's own split never failed: no second round


def test_correct_rounds_must_be_positive():
    with pytest.raises(ValueError, match="correct_rounds"):
        SearchConfig(correct_rounds=0)


# --- asked again after an empty reply (SearchConfig.empty_retries): method ours-corrector-retry -------------------
class LateBook(AnswerBook):
    """The AnswerBook, but its first ``empty`` replies (proposer calls) give no valid candidate."""

    def __init__(self, book, empty):
        super().__init__(book)
        self.empty = empty

    def propose_split(self, query, w, feedback=()):
        answer = super().propose_split(query, w, feedback)
        if len(self.queries) <= self.empty:
            return []
        return answer


def test_an_empty_reply_is_asked_again_and_its_split_taken():
    # d = 1: each Algorithm 1 call is one proposer call; the first two replies are empty
    for retries, found in ((0, [0.0, 10.0]), (1, [0.0, 10.0]), (2, [0.0, 3.0, 6.0, 10.0])):
        book = LateBook({(0.0, 10.0): [3, 6]}, empty=2)
        _, result = run(LegTable(LUCKY), book, empty_retries=retries)
        assert xs(result) == found and len(book.queries) == 1 + min(retries, 2)
        asked = [s.get("asked_again", 0) for s in result.steps if s["event"] == "split-generated"]
        assert asked == list(range(1 + min(retries, 2)))


def test_asking_again_stays_within_the_budget():
    book = LateBook({(0.0, 10.0): [3, 6]}, empty=5)
    _, result = run(LegTable(LUCKY), book, empty_retries=4, max_edge_splits=2)
    assert len(book.queries) == 2 and xs(result) == [0.0, 10.0]


def test_empty_retries_must_not_be_negative():
    with pytest.raises(ValueError, match="empty_retries"):
        SearchConfig(empty_retries=-1)


# --- a dead path corrected until alive (SearchConfig.correct_while_dead): method ours-corrector-persist -----------
class ReplyQueue(AnswerBook):
    """Replies to the query for S -> G in turn (each a list of waypoint x's; the last one repeated)."""

    def __init__(self, replies):
        super().__init__({})
        self.replies = replies

    def propose_split(self, query, w, feedback=()):
        self.queries.append(float(query.goal.centre()[0]))
        answer = self.replies[min(len(self.queries) - 1, len(self.replies) - 1)]
        return [[Disc(a, 0, 0.5) for a in answer]]


DEAD = {(0.0, 10.0): 0.0, (0.0, 2.0): 0.0, (0.0, 3.0): 0.0}  # S -> G, and into 2 or 3, never succeed


def test_a_dead_path_is_corrected_pass_after_pass_until_a_split_lives():
    # the search's split (2) and the correction's first (3) have a dead first leg; the third reply (5) lives
    book = ReplyQueue([[2], [3], [5]])
    g, result = run(LegTable(DEAD), book, correct_rollouts=4, correct_while_dead=True)
    assert xs(result) == [0.0, 5.0, 10.0] and result.predicted_success == pytest.approx(1.0)
    assert len(book.queries) == 3 and check_refines(result.graph, g) == []
    legs = [s for s in result.steps if s["event"] == "correct-leg"]
    assert [(s["correct_pass"], s["accepted"]) for s in legs] == [(1, None), (2, "split")]


def test_without_it_the_dead_path_ends_the_run_after_one_pass():
    book = ReplyQueue([[2], [3], [5]])
    _, result = run(LegTable(DEAD), book, correct_rollouts=4)
    assert xs(result) == [0.0, 10.0] and result.predicted_success == 0.0 and len(book.queries) == 2


def test_correcting_a_dead_path_stops_at_the_search_budget():
    book = ReplyQueue([[2], [3]])  # never a live split
    _, result = run(LegTable(DEAD), book, correct_rollouts=4, correct_while_dead=True, max_edge_splits=6)
    assert xs(result) == [0.0, 10.0] and len(book.queries) == 6
    assert result.edge_splits_generated == 6


def test_a_dead_path_may_go_past_the_search_budget_up_to_the_dead_budget():
    book = ReplyQueue([[2], [3], [3], [3], [3], [3], [3], [5]])  # the eighth reply lives
    _, result = run(LegTable(DEAD), book, correct_rollouts=4, correct_while_dead=True, max_edge_splits=6,
                    dead_budget=10)
    assert xs(result) == [0.0, 5.0, 10.0] and len(book.queries) == 8 and result.edge_splits_generated == 8
    extended = [s for s in result.steps if s["event"] == "budget-extended"]
    assert len(extended) == 1 and extended[0]["splits"] == [6, 10]
    assert result.steps[-1]["dead_budget"] == 10


def test_the_dead_budget_is_a_cap_too():
    book = ReplyQueue([[2], [3]])  # never a live split
    _, result = run(LegTable(DEAD), book, correct_rollouts=4, correct_while_dead=True, max_edge_splits=6,
                    dead_budget=9)
    assert xs(result) == [0.0, 10.0] and len(book.queries) == 9


def test_a_live_path_never_spends_the_dead_budget():
    fresh = {(3.0, 6.0): 0.75}  # weak, not dead: snap's one pass at snap's cost
    calls = []
    for budget in (None, 90):
        book = AnswerBook({(0.0, 10.0): [3, 6]})
        _, result = run(LegTable(LUCKY, fresh), book, correct_rollouts=4, correct_while_dead=True, dead_budget=budget)
        calls.append((len(book.queries), xs(result), [s["event"] for s in result.steps]))
    assert calls[0] == calls[1]


def test_dead_budget_must_be_positive():
    with pytest.raises(ValueError, match="dead_budget"):
        SearchConfig(dead_budget=0)


def test_a_live_path_gets_no_further_pass():
    fresh = {(3.0, 6.0): 0.75}  # weak, not dead: the correction's one pass, as without the setting
    calls = []
    for setting in (False, True):
        book = AnswerBook({(0.0, 10.0): [3, 6]})
        _, result = run(LegTable(LUCKY, fresh), book, correct_rollouts=4, correct_while_dead=setting)
        calls.append((len(book.queries), xs(result), [s["event"] for s in result.steps]))
    assert calls[0] == calls[1]


# --- a declined split taken where the found path is dead (SearchConfig.keep_declined): ours-corrector-keep -----------
TAIL_DEAD = {(0.0, 10.0): 0.0, (6.0, 10.0): 0.0}  # S -> G never succeeds; the split 3, 6 dies on its last leg


def test_a_dead_path_takes_the_declined_split_and_the_correction_repairs_its_dead_leg():
    for keep, found in ((False, [0.0, 10.0]), (True, [0.0, 3.0, 6.0, 8.0, 10.0])):
        book = AnswerBook({(0.0, 10.0): [3, 6], (6.0, 10.0): [8]})
        g, result = run(LegTable(TAIL_DEAD), book, correct_rollouts=4, keep_declined=keep)
        assert xs(result) == found and check_refines(result.graph, g) == []
        kept = [s for s in result.steps if s["event"] == "declined-kept"]
        assert len(kept) == keep and (not keep or (kept[0]["legs"], kept[0]["alive"]) == (3, 2))
    assert result.predicted_success == pytest.approx(1.0) and book.queries.count((6.0, 10.0)) == 1


def test_a_split_dead_from_its_first_leg_is_not_taken():
    book = AnswerBook({(0.0, 10.0): [3, 6]})
    _, result = run(LegTable({(0.0, 10.0): 0.0, (0.0, 3.0): 0.0}), book, correct_rollouts=4, keep_declined=True)
    assert xs(result) == [0.0, 10.0] and not any(s["event"] == "declined-kept" for s in result.steps)


def test_a_live_path_never_takes_a_declined_split():
    fresh = {(3.0, 6.0): 0.75}
    calls = []
    for keep in (False, True):
        book = AnswerBook({(0.0, 10.0): [3, 6]})
        _, result = run(LegTable(LUCKY, fresh), book, correct_rollouts=4, keep_declined=keep)
        calls.append((len(book.queries), xs(result), [s["event"] for s in result.steps]))
    assert calls[0] == calls[1]


class EdgeQueue(AnswerBook):
    """Per (start, goal) of the query, its replies in turn (the last one repeated)."""

    def propose_split(self, query, w, feedback=()):
        key = (float(query.graph.region(query.u).centre()[0]), float(query.goal.centre()[0]))
        self.queries.append(key)
        replies = self.book[key]
        return [[Disc(a, 0, 0.5) for a in replies[min(self.queries.count(key) - 1, len(replies) - 1)]]]


STUCK_TAIL = {(0.0, 10.0): 0.0, (6.0, 10.0): 0.0, (6.0, 8.0): 0.0}  # the kept split's last leg never lives
REPLIES = {(0.0, 10.0): [[3, 6], [5]], (6.0, 10.0): [[8]]}  # S -> G asked again: 5, which lives


def test_a_kept_split_still_dead_at_half_the_budget_falls_back_to_the_edge_it_replaced():
    book = EdgeQueue(REPLIES)
    g, result = run(LegTable(STUCK_TAIL), book, correct_rollouts=4, correct_while_dead=True, keep_declined=True,
                    keep_fallback=True, max_edge_splits=10)
    dropped = [s for s in result.steps if s["event"] == "declined-dropped"]
    assert len(dropped) == 1 and dropped[0]["path"] == ["S", "G"] and dropped[0]["splits"][0] <= 6
    assert xs(result) == [0.0, 5.0, 10.0] and check_refines(result.graph, g) == []


def test_without_the_fallback_the_kept_split_is_corrected_to_the_end():
    book = EdgeQueue(REPLIES)
    _, result = run(LegTable(STUCK_TAIL), book, correct_rollouts=4, correct_while_dead=True, keep_declined=True,
                    max_edge_splits=10)
    assert result.predicted_success == 0.0 and result.edge_splits_generated == 10
    assert "declined-dropped" not in [s["event"] for s in result.steps]


def test_live_start_counts_the_legs_before_the_first_dead_one():
    assert [live_start(p) for p in ([1.0, 0.5, 0.0, 1.0], [0.0], [0.9, 0.9], [])] == [2, 0, 2, 0]


# --- ground kept where the path is dead (SearchConfig.correct_advance): method ours-corrector-advance --------------
FAR_DEAD = {(0.0, 10.0): 0.0, (6.0, 9.0): 0.0, (6.0, 10.0): 0.0}  # the reply 3, 6, 9 dies after 6; so does 6 -> G
ONWARD = {(0.0, 10.0): [[3, 6, 9]], (6.0, 10.0): [[8]]}


def test_a_dead_path_keeps_the_live_legs_of_a_reply_and_asks_only_about_the_rest():
    book = EdgeQueue(ONWARD)
    g, result = run(LegTable(FAR_DEAD), book, correct_rollouts=4, correct_while_dead=True, correct_advance=True)
    assert xs(result) == [0.0, 3.0, 6.0, 8.0, 10.0] and check_refines(result.graph, g) == []
    assert result.predicted_success == pytest.approx(1.0) and book.queries.count((6.0, 10.0)) == 1
    legs = [s for s in result.steps if s["event"] == "correct-leg"]
    advanced = [s for s in legs if s["accepted"] == "advance"]
    assert len(advanced) == 1 and advanced[0]["edge"] == ["S", "G"]
    assert [t.get("nearer") for t in advanced[0]["tried"]] == [None, pytest.approx(6.0)]


def test_without_it_the_same_replies_leave_the_path_dead():
    book = EdgeQueue(ONWARD)
    _, result = run(LegTable(FAR_DEAD), book, correct_rollouts=4, correct_while_dead=True, max_edge_splits=8)
    assert xs(result) == [0.0, 10.0] and set(book.queries) == {(0.0, 10.0)}


def test_ground_that_is_not_nearer_the_legs_end_is_not_kept():
    book = EdgeQueue({(0.0, 10.0): [[-3, 5]]})  # 0 -> -3 lives, -3 -> 5 does not: -3 is farther from G than S
    _, result = run(LegTable({(0.0, 10.0): 0.0, (-3.0, 5.0): 0.0, (-3.0, 10.0): 0.0}), book, correct_rollouts=4,
                    correct_while_dead=True, correct_advance=True, max_edge_splits=6)
    assert xs(result) == [0.0, 10.0] and set(book.queries) == {(0.0, 10.0)}
    tried = [t for s in result.steps if s["event"] == "correct-leg" for t in s["tried"] if t["kind"] == "advance"]
    assert tried and all(t["nearer"] < 0 for t in tried)


def test_a_live_path_is_corrected_as_without_it():
    fresh = {(3.0, 6.0): 0.75}
    calls = []
    for setting in (False, True):
        book = AnswerBook({(0.0, 10.0): [3, 6]})
        _, result = run(LegTable(LUCKY, fresh), book, correct_rollouts=4, correct_while_dead=True,
                        correct_advance=setting)
        calls.append((len(book.queries), xs(result), [s["event"] for s in result.steps]))
    assert calls[0] == calls[1]


def test_while_the_path_is_dead_only_its_dead_legs_are_tried():
    check = Check(results=[_Arrive(0.5), _Arrive(0.0)], path=["S", "x0", "G"])
    assert weakest_untried(check, {("x0", "G")}, dead_only=True) is None
    assert weakest_untried(check, {("x0", "G")}) == 0 and weakest_untried(check, set(), dead_only=True) == 1


# --- replies pooled into a roadmap (SearchConfig.correct_roadmap): method ours-corrector-roadmap -------------------
#: no reply is right: S -> G is answered 3, 9 (3 -> 9 dead); 3 -> G is answered 6, 12 (6 -> 12 dead); 6 -> G is
#: answered 12 (dead). Pooled, 3, 6 and 9 are legs within reach 3.5 of each other, and 9 -> G lives.
NO_REPLY_RIGHT = {(0.0, 10.0): 0.0, (3.0, 9.0): 0.0, (3.0, 10.0): 0.0, (6.0, 12.0): 0.0, (6.0, 10.0): 0.0}
WRONG_REPLIES = {(0.0, 10.0): [[3, 9]], (3.0, 10.0): [[6, 12]], (6.0, 10.0): [[12]]}
POOLED = dict(correct_rollouts=4, correct_while_dead=True, correct_advance=True, correct_reach=3.5, max_edge_splits=8)


def test_a_dead_leg_is_finished_over_the_waypoints_of_replies_that_were_each_wrong():
    g, result = run(LegTable(NO_REPLY_RIGHT), EdgeQueue(WRONG_REPLIES), correct_roadmap=True, **POOLED)
    assert xs(result) == [0.0, 3.0, 6.0, 9.0, 10.0] and check_refines(result.graph, g) == []
    assert result.predicted_success == pytest.approx(1.0)
    accepted = [s["accepted"] for s in result.steps if s["event"] == "correct-leg" and s["accepted"]]
    assert accepted[-1] == "roadmap"
    found = [s for s in result.steps if s["event"] == "roadmap" and s["reaches_end"]]
    assert found and found[-1]["edge"][1] == "G" and found[-1]["waypoints"] == 1
    assert 0 < found[-1]["evaluations"] < found[-1]["evaluations_so_far"]  # its own search's, and the run's so far
    assert "a chain of 1, to the leg's end" in describe(found[-1])


def test_without_the_roadmap_the_same_replies_leave_the_path_dead():
    _, result = run(LegTable(NO_REPLY_RIGHT), EdgeQueue(WRONG_REPLIES), **POOLED)
    assert result.predicted_success == 0.0 and not any(s["event"] == "roadmap" for s in result.steps)


def test_a_live_path_never_consults_the_roadmap():
    runs = []
    for setting in (False, True):
        book = AnswerBook({(0.0, 10.0): [3, 6]})
        _, result = run(LegTable(LUCKY, {(3.0, 6.0): 0.75}), book, correct_rollouts=4, correct_while_dead=True,
                        correct_advance=True, correct_reach=3.5, correct_roadmap=setting)
        runs.append((book.queries, xs(result), [s["event"] for s in result.steps]))
    assert runs[0] == runs[1] and "roadmap" not in runs[1][2]


# --- a rescue (SearchConfig.rescue): method ours-corrector-redraw-rescue ---------------------------------------------
#: the base correction: two passes, no roadmap (redraw's shape); the rescue: the pooled replies' roadmap
BASE = dict(correct_rollouts=4, correct_passes=2, max_edge_splits=8)
RESCUE = dict(correct_while_dead=True, correct_advance=True, correct_reach=3.5, correct_roadmap=True)


def test_a_path_the_correction_leaves_dead_is_rescued_over_the_replies_pooled_before_the_rescue():
    g, result = run(LegTable(NO_REPLY_RIGHT), EdgeQueue(WRONG_REPLIES), **BASE, rescue=RESCUE)
    assert xs(result) == [0.0, 3.0, 6.0, 9.0, 10.0] and check_refines(result.graph, g) == []
    events = [s["event"] for s in result.steps]
    assert events.count("rescue") == 1 and events.index("rescue") < events.index("roadmap")
    rescue = result.steps[events.index("rescue")]
    assert rescue["path"] == ["S", "G"] and rescue["changes"] == sorted(RESCUE)
    assert "the path corrected once more, 4 settings changed" in describe(rescue)
    assert result.roadmap is not None and len(result.roadmap.points) >= 2  # the search's reply (3, 9) pooled too


def test_without_a_rescue_the_same_replies_leave_the_base_correction_dead():
    _, result = run(LegTable(NO_REPLY_RIGHT), EdgeQueue(WRONG_REPLIES), **BASE)
    assert result.predicted_success == 0.0 and result.roadmap is None
    assert not any(s["event"] in ("rescue", "roadmap") for s in result.steps)


def test_a_rescue_draws_apart_from_the_passes_before_it():
    table = LegTable(NO_REPLY_RIGHT)
    _, result = run(table, EdgeQueue(WRONG_REPLIES), **BASE, rescue=RESCUE)
    at = next(s["evaluations_so_far"] for s in result.steps if s["event"] == "rescue")
    before = {seed for *_, seed in table.calls[:at] if seed is not None}
    after = {seed for *_, seed in table.calls[at:] if seed is not None}
    assert len(before) == 2 and after and not before & after  # two passes' draws, then the rescue's own


def test_a_rescue_never_touches_a_path_the_correction_leaves_alive():
    runs = []
    for rescue in (None, RESCUE):
        book, table = AnswerBook({(0.0, 10.0): [3, 6]}), LegTable(LUCKY, {(3.0, 6.0): 0.75})
        _, result = run(table, book, **BASE, rescue=rescue)
        runs.append((book.queries, table.calls, xs(result), result.steps, result.roadmap))
    assert runs[0] == runs[1] and runs[1][-1] is None


def test_a_rescue_needs_the_correction_and_known_fields():
    with pytest.raises(ValueError, match="rescue needs correct_rollouts"):
        SearchConfig(rescue=RESCUE)
    with pytest.raises(SpecrefineError, match="no field 'roadmap_wide'"):
        SearchConfig(correct_rollouts=4, rescue=dict(roadmap_wide=True))
    with pytest.raises(ValueError, match="correct_roadmap needs correct_reach"):
        SearchConfig(correct_rollouts=4, rescue=dict(correct_roadmap=True))


def test_a_deaf_proposer_leaves_redraw_at_0_and_its_rescue_finds_the_way(tmp_path):
    """Every turn dropped, feedback never used: redraw (the Ant's default before its rescue) ends at 0; its rescue
    builds the way from the replies and its own probes (docs/corrector.md, "A rescue for the Ant's default")."""
    from specrefine.runs.pipeline import refine_maze

    deaf = dict(proposer="imperfect:p_drop_turn=1,rho=0", agent="point", rollouts=8, episodes=20, seed=0,
                goal_points="centre")
    redraw = refine_maze("u_chain_1", method="ours-corrector-redraw", out=tmp_path / "redraw", **deaf).data
    rescue = refine_maze("u_chain_1", method="ours-corrector-redraw-rescue", out=tmp_path / "rescue", **deaf).data
    assert redraw["success_rate"] == 0.0 and rescue["success_rate"] >= 0.9
    steps = [json.loads(line) for line in (tmp_path / "rescue" / "steps.jsonl").read_text().splitlines()]
    assert [s["event"] for s in steps].count("rescue") == 1 and (tmp_path / "rescue" / "roadmap.png").is_file()


def test_redraw_rescue_is_redraw_with_span_bridges_correction_as_its_rescue():
    from specrefine.runs.methods import REDRAW, SPAN_BRIDGE

    assert "rescue" not in REDRAW and SPAN_BRIDGE["roadmap_bridge"] and SPAN_BRIDGE["roadmap_span"] == 2
    assert get_method("ours-corrector-redraw-rescue").description.startswith("beyond the paper: ours-corrector-redraw")


def test_the_roadmap_needs_a_reach():
    with pytest.raises(ValueError, match="correct_roadmap needs correct_reach"):
        SearchConfig(correct_roadmap=True)


def test_the_roadmap_pools_one_waypoint_per_place_and_tries_a_dead_leg_once():
    roadmap = Roadmap(reach=3.5)
    roadmap.add([Disc(3, 0, 0.5), Disc(3.1, 0, 0.4)])
    roadmap.add([Disc(6, 0, 0.5)])
    assert [float(p.centre()[0]) for p in roadmap.points] == [3.0, 6.0]
    ev, s, g = LegTable({(3.0, 6.0): 0.0}), box_at(0, 0), box_at(10, 0)
    first, again = (roadmap.chain(ev, s, s, g, WALLS) for _ in range(2))
    assert [float(r.centre()[0]) for r in first.waypoints] == [3.0] and not first.reaches_goal
    assert (first.evaluations, again.evaluations) == (2, 1) and again.waypoints == first.waypoints


def test_the_roadmap_stops_at_its_evaluations():
    roadmap = Roadmap(reach=3.5, evaluations=1)
    roadmap.add([Disc(3, 0, 0.5), Disc(6, 0, 0.5), Disc(9, 0, 0.5)])
    ev, s = LegTable({}), box_at(0, 0)
    found = roadmap.chain(ev, s, s, box_at(10, 0), WALLS)
    assert found.evaluations == 1 and len(ev.calls) == 1 and not found.reaches_goal


@pytest.mark.parametrize("sound,first", [(0.0, 3.0), (0.5, 2.0)])
def test_a_sound_roadmap_builds_on_no_leg_that_mostly_fails(sound, first):
    roadmap = Roadmap(reach=3.5, sound=sound)
    roadmap.add([Disc(x, 0, 0.4) for x in (2, 3, 5, 6, 8)])
    ev, s = LegTable({(0.0, 3.0): 0.05}), box_at(0, 0)  # the leg nearest the goal succeeds on 5 % of its rollouts
    found = roadmap.chain(ev, s, s, box_at(10, 0), WALLS)
    assert found.reaches_goal and float(found.waypoints[0].centre()[0]) == first
    assert (Roadmap._key(np.zeros(2), np.array([3.0, 0.0])) in roadmap.dead) == (sound > 0)


def test_a_sound_roadmap_needs_a_fraction():
    with pytest.raises(ValueError, match="roadmap_sound must lie in"):
        SearchConfig(roadmap_sound=1.5)


@pytest.mark.parametrize("remember", [False, True])
def test_a_remembering_roadmap_goes_on_where_the_search_before_stopped(remember):
    roadmap = Roadmap(reach=3.5, evaluations=1, remember=remember)
    roadmap.add([Disc(x, 0, 0.4) for x in (3, 6, 9)])
    ev, s, g = LegTable({}), box_at(0, 0), box_at(10, 0)
    found = [roadmap.chain(ev, s, s, g, WALLS) for _ in range(4)]
    ends = [[float(r.centre()[0]) for r in f.waypoints] for f in found]
    if remember:  # one evaluation each: every search adds one leg to what the one before reached
        assert ends == [[3.0], [3.0, 6.0], [3.0, 6.0, 9.0], [3.0, 6.0, 9.0]] and found[-1].reaches_goal
        assert [f.remembered for f in found] == [0, 1, 2, 3] and len(ev.calls) == 4
    else:  # each search spends its one evaluation re-reaching the first waypoint
        assert ends == [[3.0]] * 4 and not any(f.reaches_goal for f in found)
        assert {f.remembered for f in found} == {0}


def test_a_remembering_roadmap_keeps_a_tree_per_origin():
    roadmap = Roadmap(reach=3.5, evaluations=1, remember=True)
    roadmap.add([Disc(x, 0, 0.4) for x in (3, 6, 9)])
    ev, g = LegTable({}), box_at(10, 0)
    roadmap.chain(ev, box_at(0, 0), box_at(0, 0), g, WALLS)
    other = roadmap.chain(ev, box_at(3, 0), box_at(3, 0), g, WALLS)  # another origin starts from nothing
    assert other.remembered == 0 and len(roadmap.trees) == 2


@pytest.mark.parametrize("explore", [0.0, 0.5])
def test_an_exploring_roadmap_finds_a_way_no_reply_named(explore):
    roadmap = Roadmap(reach=3.5, explore=explore)
    roadmap.add([Disc(3, 0, 0.5)])  # the one waypoint any reply named; its leg to the goal never succeeds
    ev, s, g = LegTable({(3.0, 6.0): 0.0}), box_at(0, 0), box_at(6, 0)
    found = roadmap.chain(ev, s, s, g, WALLS)
    assert found.reaches_goal == (explore > 0)
    if explore:  # eight waypoints around each node reached (the origin and x = 3), 1.75 m out
        assert found.explored == 16 and len(roadmap.points) == 17 and found.waypoints[0].centre()[0] == 3.0
        again = roadmap.chain(ev, s, s, g, WALLS)
        assert again.explored == 0 and again.reaches_goal  # a node is explored once; its waypoints stay pooled
    else:
        assert found.explored == 0 and [float(r.centre()[0]) for r in found.waypoints] == [3.0]


def test_a_probing_roadmap_probes_the_node_nearest_the_goal_and_tries_its_probes_from_it_only():
    roadmap = Roadmap(reach=3.5, probe=0.5)
    roadmap.add([Disc(3, 0, 0.5)])  # the one waypoint any reply named; its leg to the goal never succeeds
    ev, s, g = LegTable({(3.0, 6.0): 0.0}), box_at(0, 0), box_at(6, 0)
    found = roadmap.chain(ev, s, s, g, WALLS)
    assert found.reaches_goal and found.explored == 8 and len(roadmap.probes) == 8
    assert [float(r.centre()[0]) for r in found.waypoints] == [3.0, 4.75]  # the probe 1.75 m east of x = 3
    assert set(roadmap.probes.values()) == {Roadmap._key(np.array([3.0, 0.0]), np.array([3.0, 0.0]))}
    from_origin = [c for c in ev.calls if c[0] == 0.0]
    assert [c[1] for c in from_origin] == [3.0]  # no probe of x = 3 was tried from the origin


class ShortLegs:
    """A leg succeeds where it is at most 1 m long and ends within 0.2 m of a point of ``way``: a way on that no
    ring of probes 1.75 m out can land on."""

    def __init__(self, way):
        self.way, self.calls = [np.asarray(w, dtype=float) for w in way], []

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None, n=None):
        a, b = np.zeros(2) if isinstance(start, Box) else np.asarray(start[1]), np.asarray(goal.centre(), dtype=float)
        self.calls.append((tuple(a), tuple(b)))
        ok = np.linalg.norm(b - a) <= 1.0 and min(np.linalg.norm(b - w) for w in self.way) <= 0.2
        return _Arrive(1.0 if ok else 0.0, at=tuple(b))


@pytest.mark.parametrize("rings", [1, 2])
def test_a_second_ring_of_probes_at_half_the_radius_finds_a_turn_the_first_steps_over(rings):
    turn = 0.875 * np.array([np.cos(np.pi / 8), np.sin(np.pi / 8)])  # on the second ring, turned by pi / 8
    goal = turn + np.array([0.0, 0.9])
    roadmap = Roadmap(reach=3.5, probe=0.5, rings=rings)
    found = roadmap.chain(ShortLegs([turn, goal]), box_at(0, 0), box_at(0, 0), Disc(*goal, 0.3), WALLS)
    assert found.reaches_goal == (rings == 2)
    assert found.explored == 8 * rings  # the second ring only once the first is spent
    if rings == 2:
        assert np.allclose(found.waypoints[0].centre(), turn, atol=1e-9) and len(found.waypoints) == 1


def test_the_finer_rings_need_the_probes():
    with pytest.raises(ValueError, match="roadmap_rings > 1 needs roadmap_probe"):
        SearchConfig(roadmap_rings=2, correct_roadmap=True, correct_reach=3.0)
    with pytest.raises(ValueError, match="roadmap_rings must be at least 1"):
        SearchConfig(roadmap_rings=0)
    assert FINE == {"roadmap_rings": 2}  # the one thing ours-corrector-fine changes in backtrack


def test_exploring_needs_the_roadmap_and_a_fraction():
    with pytest.raises(ValueError, match="roadmap_explore needs correct_roadmap"):
        SearchConfig(roadmap_explore=0.5)
    with pytest.raises(ValueError, match="roadmap_explore must lie in"):
        SearchConfig(roadmap_explore=1.5, correct_roadmap=True, correct_reach=3.0)
    with pytest.raises(ValueError, match="roadmap_probe needs correct_roadmap"):
        SearchConfig(roadmap_probe=0.5)


def test_a_roadmap_search_spends_the_evaluations_its_config_gives_it():
    assert SearchConfig().roadmap_evaluations == Roadmap(reach=1.0).evaluations == 120
    with pytest.raises(ValueError, match="roadmap_evaluations must be at least 1"):
        SearchConfig(roadmap_evaluations=0)
    config = SearchConfig(correct_roadmap=True, correct_reach=3.0, roadmap_evaluations=360, edge_refinement=False)
    assert RefinementSearch(_chain_graph(), LegTable({}), config=config).roadmap.evaluations == 360
    assert DEEP == {"roadmap_evaluations": 360}  # the one thing ours-corrector-deep changes in probe
    assert get_method("ours-corrector-deep").name == "ours-corrector-deep"


def test_remembering_needs_the_roadmap():
    with pytest.raises(ValueError, match="roadmap_remember needs correct_roadmap"):
        SearchConfig(roadmap_remember=True)


# --- weak legs mended on the roadmap (SearchConfig.roadmap_weak): method ours-corrector-mend ---------------------
#: the search takes S -> 3 -> 6 -> G, where 3 -> 6 succeeds on half its rollouts. Its split (4.5) and its split over
#: 6 (5, 8: 5 -> 8 dead) both lose; pooled, 5 lies between 3 and 6, and 3 -> 5 -> 6 lives
WEAK_LEG = {(0.0, 10.0): 0.0, (3.0, 6.0): 0.5, (3.0, 4.5): 0.25, (4.5, 6.0): 0.25, (5.0, 8.0): 0.0}
WEAK_REPLIES = {(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5], (3.0, 10.0): [5, 8]}
MENDED = dict(correct_rollouts=4, correct_reach=3.5, correct_roadmap=True)


def weak_leg_run(table: dict, replies: dict, **cfg):
    """A run over ``table`` with ``replies`` and mend's settings (and ``cfg``) -> (the proposer's answer book, the
    input graph, the result, the kinds tried on the weak leg x0 -> x1, its correct-leg step)."""
    book = AnswerBook(replies)
    g, result = run(LegTable(table, table), book, **cfg, **MENDED)
    leg = next(s for s in result.steps if s["event"] == "correct-leg" and s["edge"] == ["x0", "x1"])
    return book, g, result, [t["kind"] for t in leg["tried"]], leg


@pytest.mark.parametrize("weak", [0.0, 0.9])
def test_a_weak_leg_the_proposer_cannot_mend_is_offered_the_roadmaps_chain_only_below_the_level(weak):
    book, g, result, kinds, leg = weak_leg_run(WEAK_LEG, WEAK_REPLIES, roadmap_weak=weak)
    assert kinds[:2] == ["split", "resplit"] and set(book.queries) == {(0.0, 10.0), (3.0, 6.0), (3.0, 10.0)}
    if weak:  # the pooled 5 mends the leg: no proposer call more
        assert kinds[-1] == "roadmap" and leg["accepted"] == "roadmap"
        assert xs(result) == [0.0, 3.0, 5.0, 6.0, 10.0] and check_refines(result.graph, g) == []
        assert result.predicted_success == pytest.approx(1.0)
    else:  # deep's correction: the roadmap is for dead legs of dead paths only
        assert "roadmap" not in kinds and leg["accepted"] is None
        assert xs(result) == [0.0, 3.0, 6.0, 10.0] and not any(s["event"] == "roadmap" for s in result.steps)


def test_the_roadmap_merges_a_waypoint_near_one_pooled_and_finds_the_same_nodes_in_reach():
    roadmap = Roadmap(reach=2.0)
    roadmap.add([Disc(0.0, 0, 0.3), Disc(0.2, 0, 0.3), Disc(1.0, 0, 0.3), Disc(0.25 + 1e-12, 0, 0.3)])
    assert [float(p.centre()[0]) for p in roadmap.points] == [0.0, 1.0, 0.25 + 1e-12]  # 0.2 merged, 0.25+ kept
    roadmap.add([Disc(3.0, 0, 0.3), Disc(2.0, 0, 0.3)])
    centres = np.asarray([p.centre() for p in roadmap.points] + [(4.0, 0.0)])
    to_goal = np.abs(centres[:, 0] - 4.0)
    every = [v for v in np.argsort(to_goal) if np.linalg.norm(centres[v] - centres[0]) <= roadmap.reach]
    assert roadmap._untried(centres[0], centres, to_goal, exclude=set()) == every == [4, 1, 2, 0]


def test_a_weak_legs_chain_builds_on_sound_legs_only_and_leaves_the_roadmaps_memory_alone():
    roadmap = Roadmap(reach=3.5, remember=True)
    roadmap.add([Disc(1.5, 0, 0.5)])
    ev, s, g = LegTable({(0.0, 3.0): 0.5}), box_at(0, 0), box_at(3, 0)  # the leg itself succeeds on half
    mended = roadmap.chain(ev, s, s, g, WALLS, sound=0.9)
    assert mended.reaches_goal and [float(r.centre()[0]) for r in mended.waypoints] == [1.5]
    assert not roadmap.dead and not roadmap.trees  # 0 -> 3 lives: not dead, and no tree kept for this floor
    plain = roadmap.chain(ev, s, s, g, WALLS)  # a dead leg's search: the leg itself reaches the goal
    assert plain.reaches_goal and plain.waypoints == [] and roadmap.trees


def test_mending_needs_the_roadmap_and_a_level_in_0_1():
    with pytest.raises(ValueError, match="roadmap_weak needs correct_roadmap"):
        SearchConfig(roadmap_weak=0.9)
    with pytest.raises(ValueError, match="roadmap_weak must lie in"):
        SearchConfig(roadmap_weak=1.5, correct_roadmap=True, correct_reach=3.0)
    assert MEND == {"roadmap_weak": 0.9} and get_method("ours-corrector-mend").name == "ours-corrector-mend"


# --- weak legs judged by the path (SearchConfig.roadmap_floor): the rescue of ours-corrector-redraw-rescue-floor -----
#: WEAK_LEG with all three legs live above mend's 0.9: 0.95 x 0.92 x 0.95 = 0.83 on the path, below a floor of 0.85,
#: whose share per leg is 0.85 ** (1 / 3) = 0.947: the leg at 0.92 is weak by the path's measure, not by mend's
ABOVE_MEND = WEAK_LEG | {(0.0, 3.0): 0.95, (3.0, 6.0): 0.92, (6.0, 10.0): 0.95}


@pytest.mark.parametrize("floor", [0.0, 0.85])
def test_a_leg_above_mends_level_is_mended_where_the_path_is_below_the_floor(floor):
    book, g, result, kinds, leg = weak_leg_run(ABOVE_MEND, WEAK_REPLIES, roadmap_weak=0.9, roadmap_floor=floor)
    assert leg["p_leg"] == pytest.approx(0.92, abs=0.01)
    if floor:  # the pooled 5 mends it, as mend would below 0.9; the legs at 0.95 lie above the share and are left
        assert kinds[-1] == "roadmap" and leg["accepted"] == "roadmap"
        assert xs(result) == [0.0, 3.0, 5.0, 6.0, 10.0] and check_refines(result.graph, g) == []
        others = [s for s in result.steps if s["event"] == "roadmap" and s["edge"] != ["x0", "x1"]]
        assert others == []
        assert leg["weak_below"] == pytest.approx(0.85 ** (1 / 3))  # the steps log shows the raised level
        assert "(weak below 0.947: the path is below its floor)" in describe(leg)
    else:
        assert "roadmap" not in kinds and leg["accepted"] is None and xs(result) == [0.0, 3.0, 6.0, 10.0]
        assert "weak_below" not in leg and "floor" not in describe(leg)


def test_the_floors_share_is_the_weak_level_only_while_the_path_is_below_it():
    legs = lambda *ps: Check(results=[_Arrive(p, n=128) for p in ps], path=[f"x{i}" for i in range(len(ps) + 1)])
    assert weak_below(legs(0.95, 0.92, 0.95), 0.9, 0.85) == pytest.approx(0.85 ** (1 / 3))
    assert weak_below(legs(0.95, 0.92, 0.95), 0.9) == 0.9  # no floor: mend's level
    assert weak_below(legs(0.99, 0.92, 0.99), 0.9, 0.85) == 0.9  # the path (0.90) is above the floor
    assert weak_below(legs(0.95, 0.0, 0.95), 0.9, 0.85) == 0.9  # a dead path: the dead legs' own rules
    assert weak_below(legs(0.8, 0.8, 0.8, 0.8), 0.9, 0.5) == 0.9  # the share (0.841) is below mend's level
    with pytest.raises(ValueError, match="roadmap_floor needs roadmap_weak"):
        SearchConfig(roadmap_floor=0.85, correct_roadmap=True, correct_reach=3.0)
    with pytest.raises(ValueError, match="roadmap_floor must lie in"):
        SearchConfig(roadmap_floor=1.5, roadmap_weak=0.9, correct_roadmap=True, correct_reach=3.0)
    method = get_method("ours-corrector-redraw-rescue-floor")
    assert FLOOR == {"roadmap_floor": 0.85} and method.name == "ours-corrector-redraw-rescue-floor"


# --- a weak leg bridged from the leg before (SearchConfig.roadmap_bridge): method ours-corrector-bridge ------------
#: as WEAK_LEG, but every leg out of 3 fails half its rollouts (the way into 3 spoils what follows): no chain from 3
#: is sound, while 2.5, pooled from the split over 6, leads from S to 6 on sound legs
ENTERED_BADLY = WEAK_LEG | {(3.0, 5.0): 0.5, (3.0, 2.5): 0.5}
BADLY_REPLIES = WEAK_REPLIES | {(3.0, 10.0): [2.5, 5, 8]}


@pytest.mark.parametrize("bridge", [False, True])
def test_a_weak_leg_no_chain_from_its_start_mends_is_bridged_from_the_leg_before(bridge):
    book, g, result, kinds, leg = weak_leg_run(ENTERED_BADLY, BADLY_REPLIES, roadmap_weak=0.9, roadmap_bridge=bridge)
    assert set(book.queries) == {(0.0, 10.0), (3.0, 6.0), (3.0, 10.0)}  # no proposer call more either way
    mended = [s for s in result.steps if s["event"] == "roadmap" and s["edge"] == ["x0", "x1"]]
    assert mended and not mended[0]["reaches_end"]  # mend's chain from 3 reaches no further on sound legs
    if bridge:
        assert kinds == ["split", "resplit", "bridge"] and leg["accepted"] == "bridge"
        assert xs(result) == [0.0, 2.5, 6.0, 10.0] and check_refines(result.graph, g) == []
        assert result.predicted_success == pytest.approx(1.0)
    else:
        assert kinds == ["split", "resplit"] and leg["accepted"] is None
        assert xs(result) == [0.0, 3.0, 6.0, 10.0]


def test_bridging_needs_mending():
    with pytest.raises(ValueError, match="roadmap_bridge needs roadmap_weak"):
        SearchConfig(roadmap_bridge=True, correct_roadmap=True, correct_reach=3.0)
    assert BRIDGE == {"roadmap_bridge": True} and get_method("ours-corrector-bridge").name == "ours-corrector-bridge"


# --- ground given back (SearchConfig.roadmap_backtrack): method ours-corrector-backtrack -----------------------------
#: S -> G is answered 4, 8: 8 lies nearest G but in a pocket (no leg out of 8 succeeds: to G, to 4, to 6, the reply
#: to 8 -> G). Pooled, 6 leads from 4 to G, which the chain from S finds and no chain from 8 can
POCKET = {(0.0, 10.0): 0.0, (8.0, 10.0): 0.0, (8.0, 6.0): 0.0, (8.0, 4.0): 0.0}
POCKET_REPLIES = {(0.0, 10.0): [[4, 8]], (8.0, 10.0): [[6]]}
BACKED = dict(correct_rollouts=4, correct_while_dead=True, correct_advance=True, correct_reach=4.5,
              correct_roadmap=True, max_edge_splits=8)


@pytest.mark.parametrize("backtrack", [False, True])
def test_a_dead_leg_in_a_pocket_is_rerouted_from_the_paths_start(backtrack):
    g, result = run(LegTable(POCKET), EdgeQueue(POCKET_REPLIES), roadmap_backtrack=backtrack, **BACKED)
    legs = [s for s in result.steps if s["event"] == "correct-leg"]
    assert legs[0]["accepted"] == "advance" and legs[0]["edge"] == ["S", "G"]  # ground won: S -> 4 -> 8
    if backtrack:
        assert any(s["accepted"] == "backtrack" for s in legs)
        assert xs(result) == [0.0, 4.0, 6.0, 10.0] and check_refines(result.graph, g) == []
        assert result.predicted_success == pytest.approx(1.0)
    else:  # every later search starts in the pocket
        assert xs(result) == [0.0, 4.0, 8.0, 10.0] and result.predicted_success == 0.0
        assert all(t["kind"] != "backtrack" for s in legs for t in s["tried"])


def test_bridge_and_backtrack_leave_a_run_alone_where_their_case_does_not_arise():
    """backtrack on a live path with a weak leg (mend's case), bridge and span on a dead path (backtrack's): the same
    steps."""
    cases = ((WEAK_LEG, WEAK_REPLIES, "roadmap_backtrack", dict(roadmap_weak=0.9, **MENDED)),
             (POCKET, POCKET_REPLIES, "roadmap_bridge", dict(roadmap_weak=0.9, **BACKED)),
             (POCKET, POCKET_REPLIES, "roadmap_span", dict(roadmap_weak=0.9, **BACKED)))
    for table, replies, setting, cfg in cases:
        runs = []
        for on in (False, True):
            book = (AnswerBook if replies is WEAK_REPLIES else EdgeQueue)(replies)
            _, result = run(LegTable(table, table), book, **{setting: on}, **cfg)
            runs.append((book.queries, xs(result), [(s["event"], s.get("accepted")) for s in result.steps]))
        assert runs[0] == runs[1]


def test_backtracking_needs_the_roadmap():
    with pytest.raises(ValueError, match="roadmap_backtrack needs correct_roadmap"):
        SearchConfig(roadmap_backtrack=True)
    assert BACKTRACK == {"roadmap_backtrack": True}
    assert get_method("ours-corrector-backtrack").name == "ours-corrector-backtrack"


def _subgoal_path() -> tuple[TaskGraph, list[str]]:
    """S -> a -> G with a a subgoal, each edge split through two waypoints: S w1 w2 a w3 w4 G."""
    g = TaskGraph("S")
    for name, x in (("S", 0), ("a", 5), ("G", 10)):
        g.add_vertex(name, box_at(x, 0))
    g.add_edge("S", "a", WALLS)
    g.add_edge("a", "G", WALLS)
    g.finals = {"G"}
    return g, ["S", *g.split_edge("S", "a", [box_at(2, 0), box_at(3, 0)]), "a",
               *g.split_edge("a", "G", [box_at(7, 0), box_at(8, 0)]), "G"]


def test_backtracking_and_bridging_never_skip_a_subgoal():
    """backtrack's chain starts where the dead leg's split starts, a subgoal, not the path's start (found on a
    random-proposer run of u_chain_2_subgoals whose refined graph then failed Theorem 4.1's check); bridge's starts a
    leg before only where the vertex between is one of that split's waypoints (legs 1, 2, 4, 5 here, not 3)."""
    g, path = _subgoal_path()
    assert [split_start(g, path, leg) for leg in range(6)] == [0, 0, 0, 3, 3, 3]
    assert [split_start(g, path, leg) < leg for leg in range(6)] == [False, True, True, False, True, True]


def test_a_chain_past_a_weak_legs_end_stays_on_its_split_and_in_the_judges_window():
    """span's chains end at most two vertices past the weak leg's end, never past a subgoal or the window's end."""
    g, path = _subgoal_path()
    assert [_span_ahead(g, path, leg, 2) for leg in range(6)] == [2, 1, 0, 2, 1, 0]
    assert _span_ahead(g, path, 0, 1) == 1 and _span_ahead(g, path, 0, 0) == 0


#: S -> 3 -> 6 -> 8 -> G, where 6 is a bad waypoint: every leg into it fails half its rollouts or more. The split of
#: 3 -> 6 (4.5) and the split over 6 (5, 7: 5 -> 7 dead) lose, and no chain of sound legs ends in 6; pooled, 5 leads
#: from 3 to 8 past it on sound legs
BAD_WAYPOINT = {(0.0, 10.0): 0.0, (3.0, 6.0): 0.5, (3.0, 4.5): 0.25, (4.5, 6.0): 0.25, (5.0, 6.0): 0.5, (5.0, 7.0): 0.0,
                (7.0, 6.0): 0.5, (8.0, 6.0): 0.5}
BAD_WAYPOINT_REPLIES = {(0.0, 10.0): [3, 6, 8], (3.0, 6.0): [4.5], (3.0, 8.0): [5, 7]}


@pytest.mark.parametrize("span", [0, 2])
def test_a_weak_leg_into_a_bad_waypoint_is_mended_past_it(span):
    book, g, result, kinds, leg = weak_leg_run(BAD_WAYPOINT, BAD_WAYPOINT_REPLIES, roadmap_weak=0.9, roadmap_span=span)
    assert set(book.queries) == {(0.0, 10.0), (3.0, 6.0), (3.0, 8.0)}  # no proposer call more either way
    if span:
        assert kinds == ["split", "resplit", "span", "span"] and leg["accepted"] == "span"  # to 8, to G
        assert xs(result) == [0.0, 3.0, 5.0, 8.0, 10.0] and check_refines(result.graph, g) == []
        assert result.predicted_success == pytest.approx(1.0)
    else:  # mend's chain from 3 reaches 6 on no sound leg
        assert kinds == ["split", "resplit"] and leg["accepted"] is None
        assert xs(result) == [0.0, 3.0, 6.0, 8.0, 10.0]


def test_spanning_needs_mending_and_a_count():
    with pytest.raises(ValueError, match="roadmap_span needs roadmap_weak"):
        SearchConfig(roadmap_span=2, correct_roadmap=True, correct_reach=3.0)
    with pytest.raises(ValueError, match="roadmap_span must be at least 0"):
        SearchConfig(roadmap_span=-1, roadmap_weak=0.9, correct_roadmap=True, correct_reach=3.0)
    assert SPAN == {"roadmap_span": 2} and get_method("ours-corrector-span").name == "ours-corrector-span"


# --- a window's win checked on the whole path (SearchConfig.correct_guard): method ours-corrector-guard ------------
class Drift(LegTable):
    """LegTable whose rollouts carry how they arrived: a leg into 3 from 1.5 arrives badly, the mark stays with the
    states leg after leg, and 8 -> G from a bad arrival succeeds on a fifth."""

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None, n=None):
        result = super().evaluate(start, goal, avoid, goal_point, seed, n)
        x0, bad = (0.0, 0.0) if isinstance(start, Box) else start[1]
        bad = 1.0 if bad or (x0, result.at[0]) == (1.5, 3.0) else 0.0
        if bad and (x0, result.at[0]) == (8.0, 10.0):
            result = _Arrive(0.2, n=result.n, at=result.at)
        return _Arrive(result.p, n=result.n, at=(result.at[0], bad))


#: the search takes S -> 3 -> 6 -> 8 -> G; fresh, S -> 3 succeeds on three quarters, and its split over 1.5 wins the
#: window S .. 8 (1.0 against 0.75) while the leg 8 -> G beyond it falls to 0.2: the path from 0.75 to 0.2
DOWNSTREAM = dict(table={(0.0, 10.0): 0.0}, fresh={(0.0, 3.0): 0.75})
DOWNSTREAM_REPLIES = {(0.0, 10.0): [3, 6, 8], (0.0, 3.0): [1.5]}


@pytest.mark.parametrize("guard", [False, True])
def test_a_window_win_that_lowers_the_whole_path_is_reverted_only_with_the_guard(guard):
    g, result = run(Drift(**DOWNSTREAM), AnswerBook(DOWNSTREAM_REPLIES), correct_rollouts=4, correct_guard=guard)
    leg = next(s for s in result.steps if s["event"] == "correct-leg" and s["edge"] == ["S", "x0"])
    split = next(t for t in leg["tried"] if t["kind"] == "split")
    assert split["p_window"] == pytest.approx(1.0) and leg["p_window"] == pytest.approx(0.75)
    done = next(s for s in result.steps if s["event"] == "correct-done")
    if guard:  # the path stays as it was, at 0.75 on the fresh check
        assert leg["accepted"] is None and split["reverted"] and split["p_path"] == pytest.approx(0.2)
        assert xs(result) == [0.0, 3.0, 6.0, 8.0, 10.0] and done["p"] == pytest.approx(0.75)
    else:  # deep's correction takes the window's win, and the path ends at 0.2
        assert leg["accepted"] == "split" and "reverted" not in split
        assert xs(result) == [0.0, 1.5, 3.0, 6.0, 8.0, 10.0] and done["p"] == pytest.approx(0.2)
    assert check_refines(result.graph, g) == []
    assert GUARD == {"correct_guard": True} and get_method("ours-corrector-guard").name == "ours-corrector-guard"


# --- snapped waypoints (SearchConfig.snap_waypoints): method ours-corrector-snap ----------------------------------
@dataclass
class SnapQuery(_Query):
    snap: float = 0.0


class SnapSeen(AnswerBook):
    def propose_split(self, query, w, feedback=()):
        self.snaps = getattr(self, "snaps", []) + [query.snap]
        return super().propose_split(query, w, feedback)


@pytest.mark.parametrize("setting,snap", [(False, 0.0), (True, 0.25)])
def test_the_search_asks_its_proposer_to_snap_by_the_agents_clearance_only_when_set(setting, snap):
    ev = LegTable(LUCKY)
    ev.clearance = 0.25
    book = SnapSeen({(0.0, 10.0): [3, 6]})
    config = SearchConfig(w=1, d=1, vertex_refinement=False, snap_waypoints=setting)
    RefinementSearch(_chain_graph(), ev, proposer=book, config=config,
                     query_for=lambda graph, u, v, r: SnapQuery(graph, u, v)).run()
    assert book.snaps == [snap]
