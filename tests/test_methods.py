"""The controls beside ours and the one-shot baseline: each does what its name says, through refine_maze."""

from __future__ import annotations

import json

from specrefine.pipeline import METHODS, PROPOSER_METHODS, refine_maze

SMALL = dict(agent="point", rollouts=8, episodes=20, seed=0)


def run(tmp_path, method, proposer="imperfect:mild", maze="u_chain_2"):
    result = refine_maze(maze, method=method, proposer=proposer, out=tmp_path / method, **SMALL)
    steps = [json.loads(line) for line in (tmp_path / method / "steps.jsonl").read_text().splitlines()]
    return result.data, steps


def test_every_method_is_listed_once_with_what_it_is():
    assert set(METHODS) == {"ours", "ours-novertex", "ours-d1", "vlm-oneshot", "vlm-oneshot-matched", "symbolic",
                            "dirl"}
    assert set(PROPOSER_METHODS) == {"ours", "ours-novertex", "ours-d1", "vlm-oneshot", "vlm-oneshot-matched"}


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
