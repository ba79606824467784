"""``ours-corrector-sparing-frugal``: sparing whose correction asks as frugal does, cheapest alternative first and
each split in one proposer round (docs/corrector.md, "Sparing and frugal: the Ant")."""

from __future__ import annotations

from test_corrector import FRESH, LUCKY, SECOND_DRAW, AnswerBook, LegTable, _chain_graph, _Query, point_run, run, xs

from specrefine.refine.search import RefinementSearch, SearchConfig
from specrefine.runs.methods import FRUGAL, SPARING, SPARING_FRUGAL

# the search's split S -> 3 -> 6 -> G; the correction's replies: 3 -> 6 through 4.5, and over the next waypoint
BOOK = {(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5], (3.0, 10.0): [5, 7.5]}
SPARING_RUN = dict(correct_rollouts=4, correct_passes=2, confirm_pick=True, correct_min_failures=3)


def test_it_is_sparing_with_frugals_asking_and_nothing_else():
    assert {k: v for k, v in SPARING_FRUGAL.items() if SPARING.get(k) != v} == FRUGAL
    assert FRUGAL == {"correct_first_win": True, "correct_rounds": 1}


def test_a_winning_split_ends_the_asking_about_its_leg():
    # 3 -> 6 loses a quarter on the fresh draw; its split through 4.5 wins: sparing also asks over the next waypoint
    # (3 -> G), sparing-frugal takes the split without asking
    for frugal, over_next in ((False, True), (True, False)):
        book = AnswerBook(BOOK)
        extra = FRUGAL if frugal else {}
        _, result = run(LegTable(LUCKY, FRESH), book, **SPARING_RUN, **extra)
        assert ((3.0, 10.0) in book.queries) is over_next
        assert xs(result) == [0.0, 3.0, 4.5, 6.0, 10.0]
        legs = [s for s in result.steps if s["event"] == "correct-leg"]
        assert legs[0]["correct_pass"] == 1 and legs[0]["accepted"] == "split"


def test_its_correction_splits_take_one_proposer_round():
    # the correction's split 3 -> 4.5 -> 6 loses a tenth on its first leg, so with the search's two rounds Algorithm 1
    # asks about 3 -> 6 twice in a row; with frugal's one round the correction's next query is another leg's
    table = {**LUCKY, (3.0, 4.5): 0.9}
    for rounds, asked in ((None, [(3.0, 6.0), (3.0, 6.0)]), (1, [(3.0, 6.0), (3.0, 10.0)])):
        book = AnswerBook({(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5]})
        config = SearchConfig(w=1, d=2, vertex_refinement=False, **SPARING_RUN, correct_rounds=rounds)
        RefinementSearch(_chain_graph(), LegTable(table, FRESH), proposer=book, config=config,
                         query_for=lambda graph, u, v, r: _Query(graph, u, v)).run()
        assert book.queries[0] == (0.0, 10.0) and book.queries[1:3] == asked  # the search's one split, then the fix


def test_the_gate_still_holds_on_the_second_draw():
    # a leg at 2 of 128 on the second draw is offered its bypass only, as in sparing
    book = AnswerBook(BOOK)
    ev = LegTable(LUCKY, FRESH, by_seed={SECOND_DRAW: {(4.5, 6.0): 126 / 128}})
    _, result = run(ev, book, **SPARING_RUN, **FRUGAL)
    assert (4.5, 6.0) not in book.queries and xs(result) == [0.0, 3.0, 4.5, 6.0, 10.0]


def test_ours_corrector_sparing_frugal_runs_end_to_end_and_logs_two_passes(tmp_path):
    result, steps = point_run(tmp_path, "ours-corrector-sparing-frugal")
    assert steps[-1]["event"] == "done" and result["refines_input"] is True
    assert [s["correct_pass"] for s in steps if s["event"] == "correct-check"] == [1, 2]
    assert result["method"] == "ours-corrector-sparing-frugal"
