"""The controls beside ours and the one-shot baseline: each does what its name says, through refine_maze."""

from __future__ import annotations

import json

import pytest

from specrefine.experiment import setup
from specrefine.pipeline import METHODS, PROPOSER_METHODS, _search, refine_maze
from specrefine.proposers.geometric import GeometricProposer

SMALL = dict(agent="point", rollouts=8, episodes=20, seed=0)


def run(tmp_path, method, proposer="imperfect:mild", maze="u_chain_2"):
    result = refine_maze(maze, method=method, proposer=proposer, out=tmp_path / method, **SMALL)
    steps = [json.loads(line) for line in (tmp_path / method / "steps.jsonl").read_text().splitlines()]
    return result.data, steps


def test_every_method_is_listed_once_with_what_it_is():
    asking = {"ours", "ours-novertex", "ours-d1", "ours-repair", "vlm-oneshot", "vlm-oneshot-matched"}
    assert set(METHODS) == asking | {"symbolic", "dirl"} and set(PROPOSER_METHODS) == asking


def test_controls_of_ours(tmp_path):
    full, full_steps = run(tmp_path, "ours")
    novertex, nv_steps = run(tmp_path, "ours-novertex")
    d1, d1_steps = run(tmp_path, "ours-d1")
    assert not any(s["event"] == "vertex-generated" for s in nv_steps)
    rounds = {c["round"] for s in d1_steps if s["event"] == "split-generated" for c in s["candidates"]}
    assert rounds == {0}  # rounds count from 0: no follow-up
    assert {c["round"] for s in full_steps if s["event"] == "split-generated" for c in s["candidates"]} >= {0, 1}
    for data in (full, novertex, d1):
        assert data["proposer_calls"] >= 1 and data["vlm_calls"] == 0 and data["proposer_is_vlm"] is False


def test_repair_keeps_a_split_that_ours_never_keeps(tmp_path):
    """u_chain_2 with moderate errors: ours keeps no split (success 0); ours-repair splits the failing legs."""
    plain, _ = run(tmp_path, "ours", "imperfect:moderate")
    repaired, steps = run(tmp_path, "ours-repair", "imperfect:moderate")
    assert plain["refinements"] == 0 and plain["success_rate"] == 0.0
    assert any(s["event"] == "split-repaired" and s["legs_repaired"] >= 1 for s in steps)
    assert repaired["refinements"] >= 1 and repaired["refines_input"] is True and repaired["success_rate"] > 0.0


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
        _search(method, exp.graph, exp.evaluator.fresh_copy(), proposer, exp.maze, "point", 0, 3, 2, 5, None)
    assert blind.pictures and all(p is None for p in blind.pictures)
    assert seeing.pictures[0][:8] == b"\x89PNG\r\n\x1a\n"  # the query's map
    assert [p is None for p in blind.pictures] == [True] * len(seeing.pictures)  # the same queries were asked
