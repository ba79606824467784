"""The Gymnasium wrapper that judges a run's task (docs/official_env.md), through the doc's own loop."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import pytest

from specrefine.cli import main
from specrefine.runs.official import judged_env, run_official

DOC = Path(__file__).resolve().parent.parent / "docs" / "official_env.md"
FAST = ["--rollouts", "8", "--episodes", "8", "--quiet"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("judged")
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["refine", "split_doorway", "--method", "ours", "--proposer", "geometric", "--out",
                     str(root / "ours"), *FAST]) == 0
        assert main(["refine", "split_doorway", "--method", "dirl", "--out", str(root / "dirl"), *FAST]) == 0
    return root


def doc_loop() -> str:
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(), flags=re.S)
    loops = [b for b in blocks if "judged_env" in b]
    assert len(loops) == 1, "docs/official_env.md has one loop through judged_env"
    return loops[0]


@pytest.mark.parametrize("method", ["ours", "dirl"])
def test_the_docs_loop_counts_what_official_counts(runs, method, tmp_path):
    code = doc_loop()
    assert 'RUN, EPISODES = "runs/demo", 50' in code
    code = code.replace('RUN, EPISODES = "runs/demo", 50', f"RUN, EPISODES = {str(runs / method)!r}, 4")
    printed, scope = io.StringIO(), {}
    with contextlib.redirect_stdout(printed):
        exec(compile(code, str(DOC), "exec"), scope)
    official = run_official(runs / method, episodes=4, seed=0, out=tmp_path / "official.json")
    assert scope["successes"] == round(official["success_rate"] * 4)
    lines = printed.getvalue().splitlines()
    outcomes = [line.split()[1] for line in lines[:4]]
    assert {o: outcomes.count(o) for o in set(outcomes)} == official["outcomes"]
    assert lines[-1] == f"{scope['successes']}/4 episodes satisfied the original task"
    if method == "dirl":  # straight through the wall: every episode ends on its first contact, and fails
        assert outcomes == ["avoid"] * 4 and scope["successes"] == 0


def test_contact_ends_the_episode_and_the_envs_own_flag_stays_beside(runs):
    env = judged_env(runs / "dirl", seed=1)
    obs, info = env.reset(seed=1)
    assert info["outcome"] is None and info["task_success"] is False and "success" in info
    steps, terminated, truncated = 0, False, False
    while not (terminated or truncated):
        obs, _, terminated, truncated, info = env.step(env.policy.act(obs))
        steps += 1
    assert terminated and not truncated
    assert info["outcome"] == "avoid" and info["avoid_contact"] and not info["timeout"]
    assert info["task_success"] is False and isinstance(info["success"], bool)
    assert len(env.trajectory) == steps + 1
    env.close()


def test_the_envs_time_limit_truncates_and_the_steps_so_far_are_judged(runs):
    env = judged_env(runs / "ours", seed=0, max_episode_steps=7)
    obs, info = env.reset(seed=0)
    for _ in range(7):
        obs, _, terminated, truncated, info = env.step(env.policy.act(obs))
    assert (terminated, truncated) == (False, True)
    assert info["outcome"] == "truncated" and info["task_success"] is False and info["leg"] == 0
    env.close()


def test_a_bad_reset_rule_is_a_specrefine_error(runs):
    from specrefine.core.errors import SpecrefineError

    with pytest.raises(SpecrefineError, match="start 'mine'"):
        judged_env(runs / "ours", start="mine")
