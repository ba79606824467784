"""The controls beside ours and the one-shot baseline: each does what its name says, through refine_maze."""

from __future__ import annotations

import json
import math

import pytest

from specrefine.proposers.geometric import GeometricProposer
from specrefine.runs.config import RunConfig
from specrefine.runs.experiment import setup
from specrefine.runs.methods import run_search
from specrefine.runs.pipeline import METHODS, PROPOSER_METHODS, refine_maze

SMALL = dict(agent="point", rollouts=8, episodes=20, seed=0)


def run(tmp_path, method, proposer="imperfect:mild", maze="u_chain_2", **settings):
    result = refine_maze(maze, method=method, proposer=proposer, out=tmp_path / method, **SMALL, **settings)
    steps = [json.loads(line) for line in (tmp_path / method / "steps.jsonl").read_text().splitlines()]
    return result.data, steps


def test_the_built_in_methods_are_registered_with_what_they_are():
    """The built-ins are there (a plugin may add more: the registry is not exactly them)."""
    asking = {"ours", "ours-novertex", "ours-nosearchvertex", "ours-notune", "ours-nofeedback", "ours-d1",
              "ours-repair", "ours-repair-tuned", "ours-corrector", "ours-corrector-gated", "ours-corrector-lean",
              "ours-corrector-precise", "ours-corrector-trim", "ours-corrector-recheck", "ours-corrector-frugal",
              "ours-corrector-retry", "ours-corrector-thrift", "ours-corrector-polish", "ours-corrector-persist",
              "ours-corrector-snap", "ours-corrector-confirm",
              "ours-deeprepair",
              "ours-feasible", "ours-checked",
              "ours-polish", "ours-shortcut", "ours-tunecheck", "ours-confirm", "vlm-oneshot",
              "vlm-oneshot-matched"}
    assert set(METHODS) >= asking | {"symbolic", "dirl"} and set(PROPOSER_METHODS) >= asking
    assert not {"symbolic", "dirl"} & set(PROPOSER_METHODS)
    assert all(METHODS[name].description for name in asking | {"symbolic", "dirl"})


def test_controls_of_ours(tmp_path):
    # sampled goal points (the paper's): with centre points ours asks no follow-up round here
    full, full_steps = run(tmp_path, "ours", preset="paper")
    novertex, nv_steps = run(tmp_path, "ours-novertex", preset="paper")
    d1, d1_steps = run(tmp_path, "ours-d1", preset="paper")
    assert not any(s["event"] == "vertex-generated" for s in nv_steps)
    rounds = {c["round"] for s in d1_steps if s["event"] == "split-generated" for c in s["candidates"]}
    assert rounds == {0}  # rounds count from 0: no follow-up
    assert {c["round"] for s in full_steps if s["event"] == "split-generated" for c in s["candidates"]} >= {0, 1}
    for data in (full, novertex, d1):
        assert data["proposer_calls"] >= 1 and data["vlm_calls"] == 0 and data["proposer_is_vlm"] is False


def _search_steps(tmp_path, method):
    """The issue's reproduction: u_chain_2, imperfect:mild, seed 1, 16 rollouts (later rounds tuned there), at the
    paper's sampled goal points."""
    refine_maze("u_chain_2", agent="point", method=method, proposer="imperfect:mild", seed=1, rollouts=16,
                episodes=20, preset="paper", out=tmp_path / method)
    steps = [json.loads(line) for line in (tmp_path / method / "steps.jsonl").read_text().splitlines()]
    candidates = [c for s in steps if s["event"] == "split-generated" for c in s["candidates"]]
    return {"vertex": sum(s["event"] == "vertex-generated" for s in steps),
            "tuned": sum(c["tuned"] for c in candidates), "later": sum(c["round"] > 0 for c in candidates)}


def test_each_control_removes_exactly_what_it_names(tmp_path):
    seen = {m: _search_steps(tmp_path, m) for m in ("ours", "ours-novertex", "ours-nosearchvertex", "ours-notune")}
    assert seen["ours"]["vertex"] > 0 and seen["ours"]["tuned"] > 0  # ours does both here
    assert seen["ours-novertex"]["vertex"] == seen["ours-novertex"]["tuned"] == 0  # no vertex refinement anywhere
    assert seen["ours-nosearchvertex"]["vertex"] == 0 and seen["ours-nosearchvertex"]["tuned"] > 0
    assert seen["ours-notune"]["tuned"] == 0 and seen["ours-notune"]["later"] > 0 and seen["ours-notune"]["vertex"] > 0


class _Feedback:
    """A proposer (imperfect:mild, seed 1) recording how many earlier candidates each edge-split query shows it."""

    def __init__(self):
        from specrefine.proposers import make_proposer

        self.inner, self.shown = make_proposer("imperfect:mild", seed=1), []

    def __getattr__(self, name):
        return getattr(self.inner, name)

    def propose_split(self, q, w, feedback=()):
        self.shown.append(len(feedback))
        return self.inner.propose_split(q, w, feedback)


@pytest.mark.parametrize("method, feedback_seen", [("ours", True), ("ours-nofeedback", False)])
def test_the_no_feedback_control_asks_its_later_round_afresh(method, feedback_seen):
    exp = setup("u_chain_2", agent="point", rollouts=16, seed=1)
    proposer = _Feedback()
    run_search(RunConfig(method=method, seed=1, rollouts=16), exp.graph, exp.evaluator.fresh_copy(), proposer, exp.maze)
    assert len(proposer.shown) >= 2  # a later round was asked
    assert any(n > 0 for n in proposer.shown) is feedback_seen


def test_repair_keeps_a_split_that_ours_never_keeps(tmp_path):
    """u_chain_2 with moderate errors: ours keeps no split (success 0); ours-repair splits the failing legs."""
    plain, _ = run(tmp_path, "ours", "imperfect:moderate")
    repaired, steps = run(tmp_path, "ours-repair", "imperfect:moderate")
    assert plain["refinements"] == 0 and plain["success_rate"] == 0.0
    assert any(s["event"] == "split-repaired" and s["legs_repaired"] >= 1 for s in steps)
    assert repaired["refinements"] >= 1 and repaired["refines_input"] is True and repaired["success_rate"] > 0.0


def test_repair_tuned_tunes_the_repaired_chain_and_nothing_else(tmp_path):
    """The same cell: ours-repair-tuned repairs as ours-repair does, then Algorithm 2 tunes the repaired chain (its
    product never falls: the chain as repaired is the DP's fallback, estimated from the same cache)."""
    _, plain = run(tmp_path, "ours-repair", "imperfect:moderate")
    tuned_data, tuned = run(tmp_path, "ours-repair-tuned", "imperfect:moderate")
    first = [s for s in plain if s["event"] == "split-repaired"][0]
    assert [s for s in tuned if s["event"] == "split-repaired"][0] == first  # the repair itself is unchanged
    tunings = [s for s in tuned if s["event"] == "split-repair-tuned"]
    assert tunings and not any(s["event"] == "split-repair-tuned" for s in plain)
    for s in tunings:
        assert len(s["p_after"]) == len(s["p_before"]) == len(s["waypoints"]) + 1
        assert math.prod(s["p_after"]) >= math.prod(s["p_before"]) - 1e-12
    assert tuned_data["refines_input"] is True


def test_matched_one_shot_spends_what_ours_spent(tmp_path):
    ours, _ = run(tmp_path, "ours", proposer="geometric")
    matched, steps = run(tmp_path, "vlm-oneshot-matched", proposer="geometric")
    plain, plain_steps = run(tmp_path, "vlm-oneshot", proposer="geometric")
    calls, evaluations = ours["proposer_calls"], ours["evaluations"]
    # it stops as soon as either budget is spent; each query (one proposer call) adds its w graphs' evaluations
    assert matched["proposer_calls"] >= calls or matched["evaluations"] >= evaluations
    assert matched["proposer_calls"] <= calls
    assert plain["proposer_calls"] == 2  # the paper's baseline: one query + one feedback round
    assert sum(s["event"] == "candidate" for s in steps) == 3 * matched["proposer_calls"]  # w = 3 per call
    assert all(s["round"] == 1 for s in steps if s["event"] == "candidate")  # best-of-N: no feedback rounds


class _Seeing(GeometricProposer):
    """The geometric proposer, recording the pictures each query hands it."""

    def __init__(self, sees_images: bool):
        super().__init__(seed=0)
        self.sees_images, self.pictures = sees_images, []

    def propose_split(self, q, w, feedback=()):
        self.pictures += [q.image_png] + [f.image_png for f in feedback]
        return super().propose_split(q, w, feedback)

    def propose_graph(self, q, w, feedback=()):
        self.pictures += [q.image_png] + [f.image_png for f in feedback]
        return super().propose_graph(q, w, feedback)


@pytest.mark.parametrize("method", ["ours", "vlm-oneshot"])
def test_pictures_are_drawn_only_for_a_proposer_that_looks_at_them(method):
    exp = setup("u_chain_2", agent="point", rollouts=8, seed=0)
    blind, seeing = _Seeing(False), _Seeing(True)
    for proposer in (blind, seeing):
        run_search(RunConfig(method=method, rollouts=8), exp.graph, exp.evaluator.fresh_copy(), proposer, exp.maze)
    assert blind.pictures and all(p is None for p in blind.pictures)
    assert seeing.pictures[0][:8] == b"\x89PNG\r\n\x1a\n"  # the query's map
    assert [p is None for p in blind.pictures] == [True] * len(seeing.pictures)  # the same queries were asked


def test_a_run_records_where_its_wall_time_went(tmp_path):
    data, _ = run(tmp_path, "ours", proposer="geometric", maze="u_maze")
    phases = [data[k] for k in ("search_seconds", "measure_seconds", "calibrate_seconds")]
    assert all(p >= 0 for p in phases) and sum(phases) <= data["wall_seconds"] + 1e-6
