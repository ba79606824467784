"""Adaptive evaluation (specrefine.refine.racing): the chain DP's choice on full-budget estimates, fewer rollouts."""

from __future__ import annotations

import json

import numpy as np
import pytest

from specrefine.cli import main as cli_main
from specrefine.core.regions import Box
from specrefine.core.results import EdgeResult, StartStates, merge_edge_results, wilson_ci
from specrefine.refine import refine_chain
from specrefine.refine.racing import Racing, stage_seed
from specrefine.refine.search import SearchConfig

WALLS = Box(100, 100, 101, 101)


def edge_result(successes: int, n: int, T: int = 3, steps: int = 0) -> EdgeResult:
    success = np.arange(n) < successes
    traj = np.zeros((n, T, 2), np.float32)
    traj[:, :, 0] = np.arange(T)
    return EdgeResult(successes / n, wilson_ci(successes, n), n, successes, success, traj, np.full(n, T),
                      StartStates(np.ones((successes, 3)), np.ones((successes, 2))), steps or n * T,
                      outcome=np.where(success, 0, 1).astype(np.int8))


class ExactEvaluator:
    """Every subtask succeeds in round(p * n) of n rollouts, p a function of the goal region's centre x."""

    def __init__(self, p_of_x, n: int = 32):
        self.p_of_x, self.n, self.seed = p_of_x, n, 0
        self.rollouts = 0

    def evaluate_many(self, subtasks, seed=None, n=None):
        n = int(n or self.n)
        self.rollouts += n * len(subtasks)
        return [edge_result(round(self.p_of_x(goal.centre()[0]) * n), n) for _, goal, _, _ in subtasks]

    def evaluate(self, start, goal, avoid, goal_point=None, seed=None, n=None):
        return self.evaluate_many([(start, goal, avoid, goal_point)], seed=seed, n=n)[0]


def test_merge_concatenates_rollouts_and_pads_trajectories():
    a, b = edge_result(3, 8, T=3), edge_result(20, 24, T=5)
    m = merge_edge_results(a, b)
    assert (m.n, m.successes) == (32, 23) and m.p == pytest.approx(23 / 32)
    assert m.ci == wilson_ci(23, 32)
    assert m.trajectories.shape == (32, 5, 2) and len(m.end_states) == 23 and m.steps == a.steps + b.steps
    assert np.array_equal(m.trajectories[0, 3:], np.repeat(a.trajectories[0, -1:], 2, axis=0))  # padded with last
    assert np.array_equal(m.success, np.concatenate([a.success, b.success]))


def test_stages_and_seeds():
    assert Racing.for_budget(32).stages == (8, 24) and Racing.for_budget(32).budget == 32
    assert Racing.for_budget(4).budget == 4
    assert len({stage_seed(0, 0), stage_seed(0, 1), 0, 1_000_003, 2_000_029}) == 5
    with pytest.raises(ValueError):
        Racing((8, 0))
    with pytest.raises(ValueError):
        Racing((8, 24), indifference=1.0)
    assert Racing((8, 24)).may_beat(1.0, 31 / 32) and not Racing((8, 24)).may_beat(1.0, 1.0)
    assert not Racing((8, 24), indifference=1 / 32).may_beat(1.0, 31 / 32)  # one rollout's worth: indifferent


def test_hopeless_candidate_gets_only_its_first_stage():
    ev = ExactEvaluator(lambda x: 0.0 if x > 5 else 1.0)
    tasks = [(None, Box(0, 0, 1, 1), WALLS, None), (None, Box(9, 0, 10, 1), WALLS, None)]
    out = Racing((8, 24)).evaluate(ev, tasks, floors=[0.5, 0.5], scale=[1.0, 1.0])
    assert out[0].n == 32 and out[0].p == 1.0
    assert out[1] is None  # 0/8: even the upper end of its interval cannot beat 0.5
    assert ev.rollouts == 8 + 8 + 24


def _bumps(seed, plateau: float):
    bumps = np.random.default_rng(seed).uniform(0.3, 1.0, size=4)

    def p_of_x(x):  # a smooth landscape over x, lifted by `plateau` (clipped at 1: subtasks that never fail)
        return float(np.clip(max(b * np.exp(-((x - c) ** 2)) for b, c in zip(bumps, (1, 3, 5, 7))) + plateau, 0, 1))

    return p_of_x


def _fixed_and_adaptive(p_of_x, seed, racing=None):
    racing = racing or Racing((8, 24))
    inner = [Box(0, 0, 2.5, 1), Box(2.5, 0, 5, 1), Box(5, 0, 7.5, 1)]
    goal = Box(7.5, 0, 9, 1)
    runs = {}
    for name, how in (("fixed", None), ("adaptive", racing)):
        ev = ExactEvaluator(p_of_x)
        choice = refine_chain(ev, Box(-1, 0, 0, 1), inner, goal, [WALLS] * 4, 5, np.random.default_rng(seed),
                              racing=how)
        runs[name] = (choice, ev.rollouts)
    return runs["fixed"], runs["adaptive"]


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("plateau", [0.15, 0.6])
def test_adaptive_chain_dp_chooses_what_the_fixed_dp_chooses(seed, plateau):
    """With exact estimates the adaptive DP finds the fixed DP's optimum (a tie may pick another option), never
    on more rollouts; with a margin of 1/32 it ends within (1 - 1/32) per layer of it."""
    p_of_x = _eighths(_bumps(seed, plateau))
    (fixed, fixed_rollouts), (adaptive, adaptive_rollouts) = _fixed_and_adaptive(p_of_x, seed)
    (_, _), (margin, _) = _fixed_and_adaptive(p_of_x, seed, Racing((8, 24), indifference=1 / 32))
    assert adaptive.p == pytest.approx(fixed.p, rel=1e-12)
    assert fixed.p * (1 - 1 / 32) ** 4 - 1e-12 <= margin.p <= fixed.p + 1e-12
    assert all(r.n == 32 for r in adaptive.results)  # what is chosen rests on the full budget
    assert adaptive_rollouts <= fixed_rollouts


def test_adaptive_saves_where_most_extensions_never_fail():
    """As on the point mass: one prefix that never fails settles a target for all the others."""
    runs = [_fixed_and_adaptive(_point_like, seed) for seed in range(6)]
    assert all(a.p == pytest.approx(f.p, rel=1e-12) for (f, _), (a, _) in runs)
    assert sum(a for (_, _), (_, a) in runs) < 0.8 * sum(f for (_, f), (_, _) in runs)


def _eighths(p_of_x):
    """Probabilities on multiples of 1/8: 8 + 24 rollouts give exactly the 32-rollout estimate."""
    return lambda x: round(p_of_x(x) * 8) / 8


def _point_like(x):
    """Every subtask succeeds except those ending near x = 3.75 (the middle of the second waypoint)."""
    return 0.5 if abs(x - 3.75) < 0.4 else 1.0


def test_search_config_names_the_evaluations():
    assert SearchConfig(evaluation="adaptive").evaluation == "adaptive"
    with pytest.raises(ValueError, match="fixed, adaptive"):
        SearchConfig(evaluation="lazy")


def test_cli_adaptive_run_records_its_evaluation(tmp_path, capsys):
    out = tmp_path / "run"
    rc = cli_main(["refine", "u_chain_1", "--evaluation", "adaptive", "--rollouts", "16", "--episodes", "40",
                   "--out", str(out)])
    assert rc == 0
    data = json.loads((out / "result.json").read_text())
    assert data["evaluation"] == "adaptive" and data["refines_input"]
    assert json.loads((out / "run.json").read_text())["evaluation"] == "adaptive"
    rc = cli_main(["refine", "u_chain_1", "--evaluation", "fixed", "--rollouts", "16", "--episodes", "40",
                   "--out", str(out)])
    assert rc == 2 and "evaluation" in capsys.readouterr().err  # another run's folder is refused


def test_default_evaluation_is_the_agents():
    """Unasked, the Ant evaluates adaptively (its held-out benchmark) and the point mass as the paper does."""
    from specrefine.runs.sweep import grid

    ant, point = (grid(["u_maze"], ["ours"], ["geometric"], [0], agent=a)[0] for a in ("ant", "point"))
    assert (ant.evaluation, point.evaluation) == ("adaptive", "fixed")
    assert "__adaptive__centre" in ant.id and not point.id.endswith("fixed")  # centre: the Ant's best
    assert grid(["u_maze"], ["ours"], ["geometric"], [0], agent="ant", evaluation="fixed")[0].evaluation == "fixed"


def test_ant_run_without_evaluation_records_adaptive(tmp_path):
    from specrefine.runs.pipeline import refine_maze

    run = refine_maze("u_chain_1", agent="ant", method="dirl", rollouts=4, episodes=4, out=tmp_path / "ant")
    assert run.data["evaluation"] == "adaptive"
    assert json.loads((tmp_path / "ant" / "run.json").read_text())["evaluation"] == "adaptive"


@pytest.mark.parametrize("method", ["dirl", "vlm-oneshot"])
def test_methods_without_the_vertex_dp_do_not_depend_on_the_evaluation(method, tmp_path):
    from specrefine.runs.pipeline import refine_maze

    runs = [refine_maze("u_chain_1", method=method, seed=2, rollouts=8, episodes=20, out=tmp_path / ev,
                        evaluation=ev).data for ev in ("fixed", "adaptive")]
    for key in ("success_rate", "evaluations", "sim_steps", "path", "predicted_ci"):
        assert runs[0][key] == runs[1][key], key


class _ThreeRoutes:
    """Three routes of three waypoints each, the same every round (a proposer that does not learn)."""

    def propose_split(self, query, w, feedback=()):
        return [[Box(x0 + 2.5 * j, 0, x0 + 2.5 * j + 2, 1) for j in range(3)] for x0 in (0.0, 0.2, 0.4)]


class _Query:
    goal, avoid = Box(7.5, 0, 9, 1), WALLS


@pytest.mark.parametrize("seed", range(4))
def test_adaptive_edge_split_picks_the_fixed_candidate_on_fewer_rollouts(seed):
    from specrefine.refine.edge_split import edge_split

    p_of_x = _eighths(_bumps(seed, 0.3))
    out = {}
    for name, racing in (("fixed", None), ("adaptive", Racing((8, 24)))):
        ev = ExactEvaluator(p_of_x)
        split = edge_split(ev, _ThreeRoutes(), _Query(), start=Box(-1, 0, 0, 1), w=3, d=2, k=5,
                           rng=np.random.default_rng(seed), racing=racing)
        out[name] = (split.best.p, ev.rollouts)
    assert out["adaptive"][0] == pytest.approx(out["fixed"][0], rel=1e-12)
    assert out["adaptive"][1] < out["fixed"][1]
