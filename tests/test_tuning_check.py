"""A split's tuned chain checked against its proposal on fresh rollouts (method ours-tunecheck)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_refine_search import SplitProposer, TableEvaluator, _Arrive, _chain_graph, _Query

from specrefine.core.regions import Box, Disc
from specrefine.refine.edge_split import edge_split
from specrefine.runs.pipeline import refine_maze

PROPOSED = Disc(5, 0, 1.0)
FRESH = 99


def _evaluator(search: tuple[float, float], fresh: tuple[float, float], region=PROPOSED):
    """p of a leg into ``region`` / into any other waypoint: ``search`` on the search's rollouts, ``fresh`` on seed
    FRESH (the leg after a waypoint is sure)."""

    class Ev(TableEvaluator):
        def evaluate(self, start, goal, avoid, goal_point=None, seed=None):
            self.calls.append((start, goal, seed))
            if goal.centre()[0] == 10:
                return _Arrive(1.0, at=(10.0, 0.0))
            ours, other = fresh if seed == FRESH else search
            return _Arrive(ours if goal == region else other, at=tuple(goal.centre()))

    return Ev(None)


def _split(ev, check: bool):
    g = _chain_graph()
    return edge_split(ev, SplitProposer([PROPOSED]), _Query(g, "S", "G"), start=Box(-0.5, -0.5, 0.5, 0.5), w=1, d=2,
                      k=3, rng=np.random.default_rng(0), tune_check_seed=FRESH if check else None)


@pytest.mark.parametrize("fresh, kept", [((0.95, 0.80), "proposed"), ((0.80, 0.95), "tuned"),
                                         ((0.90, 0.90), "proposed")])
def test_a_tuned_chain_is_kept_only_if_it_beats_its_proposal_on_fresh_rollouts(fresh, kept):
    ev = _evaluator(search=(0.90, 1.0), fresh=fresh)  # on the search's own draw every subset looks sure
    paper = _split(ev, check=False).candidates[1]
    assert paper.tuned and paper.waypoints != [PROPOSED] and paper.p == pytest.approx(1.0)
    assert paper.check is None

    checked = _split(ev, check=True).candidates[1]
    assert checked.check == pytest.approx(fresh)
    assert checked.tuned is (kept == "tuned")
    assert (checked.waypoints == [PROPOSED]) is (kept == "proposed")
    assert checked.p == pytest.approx(max(fresh) if kept == "tuned" else fresh[0])  # the winner's fresh estimate


def test_the_check_costs_two_fresh_chains_and_is_skipped_when_nothing_was_tuned():
    ev = _evaluator(search=(0.90, 1.0), fresh=(0.95, 0.80))
    unchecked, checked = _split(ev, check=False), _split(ev, check=True)
    assert checked.evaluations == unchecked.evaluations + 2 * 2  # two chains of two legs
    calm = _evaluator(search=(0.90, 0.50), fresh=(0.95, 0.80))  # no subset beats the proposal: nothing to check
    plain = _split(calm, check=True)
    assert plain.candidates[1].check is None and not any(seed == FRESH for *_, seed in calm.calls)


def test_ours_tunecheck_logs_each_check_and_differs_from_ours_only_there(tmp_path):
    """u_chain_2, imperfect:mild, seed 1, 16 rollouts, sampled goal points (later rounds are tuned there): each tuned
    candidate of ours-tunecheck carries its check in steps.jsonl; the search is ours' up to its first checked
    split."""
    steps = {}
    for method in ("ours", "ours-tunecheck"):
        refine_maze("u_chain_2", agent="point", method=method, proposer="imperfect:mild", seed=1, rollouts=16,
                    episodes=20, preset="paper", out=tmp_path / method)
        steps[method] = [json.loads(line) for line in (tmp_path / method / "steps.jsonl").read_text().splitlines()]
    splits = {m: [s for s in steps[m] if s["event"] == "split-generated"] for m in steps}
    checked = [c for s in splits["ours-tunecheck"] for c in s["candidates"] if "check" in c]
    assert checked and not any("check" in c for s in splits["ours"] for c in s["candidates"])
    for c in checked:
        assert c["tuned"] is (c["check"]["tuned"] > c["check"]["proposed"])
        assert c["p"] == pytest.approx(max(c["check"].values()) if c["tuned"] else c["check"]["proposed"])
    first = next(i for i, s in enumerate(splits["ours-tunecheck"]) if any("check" in c for c in s["candidates"]))
    assert splits["ours-tunecheck"][:first] == splits["ours"][:first]
    assert [c["waypoints"] for c in splits["ours-tunecheck"][first]["candidates"] if c["round"] == 0] == \
        [c["waypoints"] for c in splits["ours"][first]["candidates"] if c["round"] == 0]


class _Rounds:
    """A proposer whose first round offers FIRST and later rounds LATER (one candidate each)."""

    name, is_vlm, calls = "stub", False, 0

    def propose_split(self, query, w, feedback=()):
        self.calls += 1
        return [[LATER] if feedback else [FIRST]]


FIRST, LATER = Disc(5, 0, 1.0), Disc(5, 1, 1.0)


def _confirm_split(search: tuple[float, float], fresh: tuple[float, float], confirm: bool = True):
    """p of the leg into FIRST / into LATER: ``search`` on the search's rollouts, ``fresh`` on seed FRESH."""
    g = _chain_graph()
    return edge_split(_evaluator(search, fresh, region=FIRST), _Rounds(), _Query(g, "S", "G"),
                      start=Box(-0.5, -0.5, 0.5, 0.5), w=1, d=2, k=3, rng=np.random.default_rng(0), tune=False,
                      confirm_seed=FRESH if confirm else None)


@pytest.mark.parametrize("fresh, kept", [((0.95, 0.80), FIRST), ((0.80, 0.95), LATER), ((0.90, 0.90), FIRST)])
def test_a_later_rounds_pick_is_kept_only_if_it_beats_the_first_rounds_best_on_fresh_rollouts(fresh, kept):
    paper = _confirm_split(search=(0.90, 1.0), fresh=fresh, confirm=False)
    assert paper.best.waypoints == [LATER] and paper.confirm is None  # the lucky draw wins in the paper's rule
    out = _confirm_split(search=(0.90, 1.0), fresh=fresh)
    assert out.best.waypoints == [kept] and out.confirm == pytest.approx(fresh)
    assert out.best.p == pytest.approx(max(fresh) if kept is LATER else fresh[0])  # the winner's fresh estimate
    assert out.evaluations == paper.evaluations + 2 * 2
    assert [c.waypoints for c in out.candidates] == [[FIRST], [LATER]]  # the candidates themselves are as drawn


def test_nothing_is_confirmed_when_the_first_round_wins_or_never_succeeded():
    assert _confirm_split(search=(0.95, 0.90), fresh=(0.5, 1.0)).confirm is None  # the first round's best is the pick
    dead = _confirm_split(search=(0.0, 0.90), fresh=(0.5, 1.0))
    assert dead.confirm is None and dead.best.waypoints == [LATER]


def test_ours_confirm_logs_each_confirmation(tmp_path):
    """u_chain_2, imperfect:mild, seed 1, 16 rollouts, sampled goal points: a confirmed split logs both fresh
    products and the pick."""
    refine_maze("u_chain_2", agent="point", method="ours-confirm", proposer="imperfect:mild", seed=1, rollouts=16,
                episodes=20, preset="paper", out=tmp_path)
    steps = [json.loads(line) for line in (tmp_path / "steps.jsonl").read_text().splitlines()]
    confirmed = [s["confirm"] for s in steps if s["event"] == "split-generated" and "confirm" in s]
    assert confirmed
    for c in confirmed:
        assert c["kept"] == ("later" if c["later"] > c["first_round"] else "first round")
