"""``ours-corrector-reaim`` (refine/correct.py ``reaim``): a weak leg of the found path is also offered its end
waypoints aimed at their regions' clearest points - the same regions, so the task is unchanged."""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_corrector import LUCKY, AnswerBook, LegTable, point_run, run, xs
from test_refine_search import _Arrive

from specrefine.core.graph import check_refines

SPLITS = {(0.0, 10.0): [3, 6]}  # asked about any later leg, the proposer has nothing to say
WALL_HUGGING = {(3.0, 6.0): 0.75}  # on fresh rollouts the leg to 6 loses a quarter while it aims at 6's centre


class AimTable(LegTable):
    """LegTable whose leg succeeds on every fresh rollout when it aims at a point of its own (the re-aimed one)."""

    def clearest(self, region):
        return np.array([region.centre()[0], 0.3])  # across the corridor from the centre

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None, n=None):
        result = super().evaluate(start, goal, avoid, goal_point, seed, n)
        return _Arrive(1.0, n=result.n, at=result.at) if goal_point is not None and seed is not None else result


def test_a_leg_hugging_a_wall_is_mended_by_aiming_its_end_clear_of_it():
    g, result = run(AimTable(LUCKY, WALL_HUGGING), AnswerBook(SPLITS), correct_rollouts=4, correct_reaim=True)
    assert xs(result) == [0.0, 3.0, 6.0, 10.0]  # the same regions, in the same order
    twin = result.path[2]
    assert twin not in ("S", "G") and result.graph.goal_point(twin) == pytest.approx([6.0, 0.3])
    assert result.graph.goal_point(result.path[1]) is None  # the other end stays where the proposer put it
    assert check_refines(result.graph, g) == []
    leg = next(s for s in result.steps if s["event"] == "correct-leg")
    assert leg["accepted"] == "reaim" and {t["kind"] for t in leg["tried"]} >= {"reaim"}
    assert next(s for s in result.steps if s["event"] == "correct-done")["p"] == pytest.approx(1.0)


def test_without_it_the_leg_stays_as_it_was_aimed():
    _, result = run(AimTable(LUCKY, WALL_HUGGING), AnswerBook(SPLITS), correct_rollouts=4)
    assert xs(result) == [0.0, 3.0, 6.0, 10.0]
    assert all(result.graph.goal_point(v) is None for v in result.path)
    assert next(s for s in result.steps if s["event"] == "correct-done")["p"] == pytest.approx(0.75)


def test_a_reaim_that_gains_nothing_is_not_taken():
    class NoBetter(AimTable):
        def evaluate(self, start, goal, avoid, goal_point=None, seed=None, n=None):
            return LegTable.evaluate(self, start, goal, avoid, goal_point, seed, n)

    _, result = run(NoBetter(LUCKY, WALL_HUGGING), AnswerBook(SPLITS), correct_rollouts=4, correct_reaim=True)
    assert all(result.graph.goal_point(v) is None for v in result.path)
    leg = next(s for s in result.steps if s["event"] == "correct-leg")
    assert leg["accepted"] is None and [t["kind"] for t in leg["tried"]].count("reaim") == 2  # both ends tried


def test_ours_corrector_reaim_runs_end_to_end_and_its_policy_aims_where_it_chose(tmp_path):
    result, steps = point_run(tmp_path, "ours-corrector-reaim")
    events = [step["event"] for step in steps]
    assert events[-1] == "done" and "correct-done" in events
    assert result["method"] == "ours-corrector-reaim" and result["refines_input"] is True
    saved = [leg["point"] for leg in json.loads((tmp_path / "run" / "policy.json").read_text())["legs"]]
    assert len(saved) == len(result["path"]) - 1 and all(p is not None for p in saved)  # centre or re-aimed
