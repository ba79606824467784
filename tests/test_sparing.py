"""``ours-corrector-sparing``: redraw whose two correction passes ask the proposer only about a leg with at least 3
fresh failures (SearchConfig.correct_min_failures on both passes; docs/corrector.md, "A gate for the Ant's
corrector")."""

from __future__ import annotations

from test_corrector import FRESH, LUCKY, SECOND_DRAW, AnswerBook, LegTable, point_run, run, xs

from specrefine.runs.methods import REDRAW, SPARING

BOOK = {(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5], (4.5, 6.0): [5.25]}
SPARING_RUN = dict(correct_rollouts=4, correct_passes=2, confirm_pick=True)


def test_it_is_redraw_with_one_change():
    assert {k: v for k, v in SPARING.items() if REDRAW.get(k) != v} == {"correct_min_failures": 3}


def test_the_second_pass_asks_nothing_about_a_leg_with_two_failures_on_its_draw():
    # pass 1 splits 3 -> 6 (a quarter lost) through 4.5; on the second draw 4.5 -> 6 fails 2 of 128: redraw asks
    # the proposer about it and takes 5.25, sparing asks nothing and keeps the path
    for gate, asked in ((1, True), (3, False)):
        book = AnswerBook(BOOK)
        ev = LegTable(LUCKY, FRESH, by_seed={SECOND_DRAW: {(4.5, 6.0): 126 / 128}})
        _, result = run(ev, book, correct_min_failures=gate, **SPARING_RUN)
        assert ((4.5, 6.0) in book.queries) is asked
        assert (3.0, 6.0) in book.queries  # the first pass's weak leg (32 of 128 failures) is asked about either way
        assert xs(result) == ([0.0, 3.0, 4.5, 5.25, 6.0, 10.0] if asked else [0.0, 3.0, 4.5, 6.0, 10.0])


def test_the_second_pass_still_splits_a_leg_with_three_failures():
    book = AnswerBook(BOOK)
    ev = LegTable(LUCKY, FRESH, by_seed={SECOND_DRAW: {(4.5, 6.0): 125 / 128}})
    _, result = run(ev, book, correct_min_failures=3, **SPARING_RUN)
    assert (4.5, 6.0) in book.queries and xs(result) == [0.0, 3.0, 4.5, 5.25, 6.0, 10.0]
    legs = [s for s in result.steps if s["event"] == "correct-leg"]
    assert [(s["correct_pass"], s["accepted"]) for s in legs] == [(1, "split"), (2, "split")]


def test_ours_corrector_sparing_runs_end_to_end_and_logs_two_passes(tmp_path):
    result, steps = point_run(tmp_path, "ours-corrector-sparing")
    assert steps[-1]["event"] == "done" and result["refines_input"] is True
    assert [s["correct_pass"] for s in steps if s["event"] == "correct-check"] == [1, 2]
    assert result["method"] == "ours-corrector-sparing"
