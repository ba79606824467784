"""``ours-corrector-wide`` (SearchConfig.correct_wide): after the correction's passes, one more on a wide draw that
asks the proposer only about legs with several failures there."""

from __future__ import annotations

import pytest
from test_corrector import LUCKY, AnswerBook, LegTable, point_run, run, xs

from specrefine.core.graph import check_refines
from specrefine.refine import SearchConfig
from specrefine.refine.correct import CHECK_SEED_OFFSET, PASS_SEED_STEP

WIDE_DRAW = CHECK_SEED_OFFSET + PASS_SEED_STEP  # one pass before it: the wide pass is the second draw
BOOK = {(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5]}
WIDE = dict(correct_rollouts=4, correct_wide=16, correct_wide_min_failures=3)


def asked_about(book, leg):
    return leg in book.queries


def test_a_leg_failing_several_times_on_the_wide_draw_is_split():
    # 128 fresh rollouts see 3 -> 6 at 1.0; 512 see it lose 1 % (5 failures): the proposer is asked and its split wins
    book = AnswerBook(BOOK)
    ev = LegTable(LUCKY, by_seed={WIDE_DRAW: {(3.0, 6.0): 0.99}})
    g, result = run(ev, book, **WIDE)
    assert asked_about(book, (3.0, 6.0))
    assert xs(result) == [0.0, 3.0, 4.5, 6.0, 10.0] and check_refines(result.graph, g) == []
    wide = [s for s in result.steps if s.get("wide_rollouts")]
    assert {s["wide_rollouts"] for s in wide} == {512} and {s["correct_pass"] for s in wide} == {2}
    assert [s["accepted"] for s in wide if s["event"] == "correct-leg"] == ["split"]
    assert {n for *_, n, seed in ev.calls if seed == WIDE_DRAW} == {512}


def test_a_leg_failing_once_on_the_wide_draw_is_not_asked_about():
    book = AnswerBook(BOOK)
    ev = LegTable(LUCKY, by_seed={WIDE_DRAW: {(3.0, 6.0): 511 / 512}})
    _, result = run(ev, book, **WIDE)
    assert not asked_about(book, (3.0, 6.0))
    assert xs(result) == [0.0, 3.0, 6.0, 10.0]
    leg = next(s for s in result.steps if s["event"] == "correct-leg" and s.get("wide_rollouts"))
    assert leg["accepted"] is None and all(t["kind"] != "split" for t in leg["tried"])


def test_without_it_no_wide_draw_is_made():
    ev = LegTable(LUCKY, by_seed={WIDE_DRAW: {(3.0, 6.0): 0.99}})
    _, result = run(ev, AnswerBook(BOOK), correct_rollouts=4)
    assert xs(result) == [0.0, 3.0, 6.0, 10.0]
    assert WIDE_DRAW not in {seed for *_, seed in ev.calls} and max(n or 0 for *_, n, _ in ev.calls) == 128


@pytest.mark.parametrize("bad", [dict(correct_wide=0, correct_rollouts=4), dict(correct_wide=16),
                                 dict(correct_wide=16, correct_rollouts=4, correct_wide_min_failures=0)])
def test_bad_settings_are_refused(bad):
    with pytest.raises(ValueError, match="correct_wide"):
        SearchConfig(**bad)


def test_ours_corrector_wide_runs_end_to_end_and_logs_its_wide_pass(tmp_path):
    result, steps = point_run(tmp_path, "ours-corrector-wide")
    assert steps[-1]["event"] == "done" and result["refines_input"] is True
    checks = [s for s in steps if s["event"] == "correct-check"]
    assert [s["correct_pass"] for s in checks] == [1, 2, 3] and checks[-1]["wide_rollouts"] == 16 * 8
    assert result["method"] == "ours-corrector-wide"
