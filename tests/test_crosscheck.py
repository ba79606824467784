"""``ours-corrector-crosscheck`` (refine/correct.py ``crosscheck``): an alternative that wins on the correction's
draw replaces the path only if it also beats it on a second draw of its own."""

from __future__ import annotations

import pytest
from test_corrector import FAR_DEAD, LUCKY, ONWARD, AnswerBook, EdgeQueue, LegTable, point_run, run, xs

from specrefine.core.graph import check_refines
from specrefine.refine.correct import CHECK_SEED_OFFSET, CROSS_SEED_OFFSET
from specrefine.runs.methods import get_method

SECOND = CHECK_SEED_OFFSET + CROSS_SEED_OFFSET
SPLITS = {(0.0, 10.0): [3, 6], (3.0, 6.0): [4.5]}
FIRST_DRAW = {(3.0, 6.0): 0.75}  # on the check's draw the leg 3 -> 6 loses a quarter and its split never fails


def test_a_win_the_second_draw_refutes_is_not_taken():
    # on the second draw the split's second leg loses half: its win on the first draw was the draw's
    ev = LegTable(LUCKY, FIRST_DRAW, by_seed={SECOND: {(3.0, 6.0): 0.75, (4.5, 6.0): 0.5}})
    _, result = run(ev, AnswerBook(SPLITS), correct_rollouts=4, correct_crosscheck=True)
    assert xs(result) == [0.0, 3.0, 6.0, 10.0]
    leg = next(s for s in result.steps if s["event"] == "correct-leg")
    assert leg["accepted"] is None
    split = next(t for t in leg["tried"] if t["kind"] == "split")
    assert split["p_window"] == pytest.approx(1.0)  # it won on the first draw ...
    assert split["p_window_second"] == pytest.approx(0.5) and split["p_current_second"] == pytest.approx(0.75)
    assert {seed for *_, seed in ev.calls if seed is not None} == {CHECK_SEED_OFFSET, SECOND}


def test_a_win_the_second_draw_confirms_is_taken_and_both_checks_follow_the_new_path():
    ev = LegTable(LUCKY, FIRST_DRAW, by_seed={SECOND: {(3.0, 6.0): 0.8, (4.5, 6.0): 0.9}})
    g, result = run(ev, AnswerBook(SPLITS), correct_rollouts=4, correct_crosscheck=True)
    assert xs(result) == [0.0, 3.0, 4.5, 6.0, 10.0]
    assert check_refines(result.graph, g) == []
    check, done = (next(s for s in result.steps if s["event"] == event) for event in ("correct-check", "correct-done"))
    assert check["p_second"] == pytest.approx(0.8) and done["p_second"] == pytest.approx(0.9)
    assert done["p"] == pytest.approx(1.0)


def test_without_it_the_first_draws_win_is_taken():
    ev = LegTable(LUCKY, FIRST_DRAW, by_seed={SECOND: {(3.0, 6.0): 0.75, (4.5, 6.0): 0.5}})
    _, result = run(ev, AnswerBook(SPLITS), correct_rollouts=4)
    assert xs(result) == [0.0, 3.0, 4.5, 6.0, 10.0]
    assert SECOND not in {seed for *_, seed in ev.calls}
    assert "p_second" not in next(s for s in result.steps if s["event"] == "correct-done")


def test_ours_corrector_crosscheck_runs_end_to_end_and_logs_both_draws(tmp_path):
    result, steps = point_run(tmp_path, "ours-corrector-crosscheck")
    assert steps[-1]["event"] == "done" and result["refines_input"] is True
    done = next(s for s in steps if s["event"] == "correct-done")
    assert 0.0 <= done["p_second"] <= 1.0
    assert get_method("ours-corrector-crosscheck").name == result["method"] == "ours-corrector-crosscheck"


def test_ground_won_on_a_dead_path_is_not_crosschecked():
    # a dead window scores 0 on both draws whatever replaces it: advance's "nearer" rule judges it, as without
    book = EdgeQueue(ONWARD)
    g, result = run(LegTable(FAR_DEAD), book, correct_rollouts=4, correct_while_dead=True, correct_advance=True,
                    correct_crosscheck=True)
    assert xs(result) == [0.0, 3.0, 6.0, 8.0, 10.0] and check_refines(result.graph, g) == []
    advanced = [s for s in result.steps if s["event"] == "correct-leg" and s["accepted"] == "advance"]
    assert len(advanced) == 1 and all("p_window_second" not in t for t in advanced[0]["tried"])
