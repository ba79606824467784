"""Lever G: ``goal_points="centre"`` aims every leg whose goal vertex has no fixed point at its region's centre, in
the search, the measurement, the calibration and the saved compositional policy alike; ``sampled`` is the paper's."""

import json

import numpy as np
import pytest

from specrefine.cli import main as cli_main
from specrefine.core.errors import SpecrefineError
from specrefine.core.graph import TaskGraph
from specrefine.core.mazes import load_maze
from specrefine.core.spec import maze_task
from specrefine.evaluation.evaluator import Evaluator
from specrefine.proposers import EdgeQuery, split_messages
from specrefine.runs import sweep
from specrefine.runs.config import RunConfig
from specrefine.runs.experiment import setup
from specrefine.runs.pipeline import refine_maze
from specrefine.sim.policy import PointController
from specrefine.vlm import messages_to_text

TINY = dict(rollouts=8, episodes=16)


def _evaluators(maze_name="split_doorway"):
    maze = load_maze(maze_name).for_agent("point")
    return maze, {rule: Evaluator(maze, "point", PointController(), n=16, seed=3, goal_points=rule)
                  for rule in ("sampled", "centre")}


def test_centre_is_the_sampled_rule_given_the_centre_as_a_fixed_point():
    maze, ev = _evaluators()
    graph = maze_task(maze)
    u, v = graph.edges()[0]
    start, goal, avoid = graph.region(u), graph.region(v), graph.avoid(u, v)
    centre = ev["centre"].evaluate(start, goal, avoid)
    fixed = ev["sampled"].evaluate(start, goal, avoid, goal_point=goal.centre())
    assert centre.successes == fixed.successes and centre.n == fixed.n == 16
    assert np.array_equal(centre.success, fixed.success) and np.array_equal(centre.lengths, fixed.lengths)
    assert ev["centre"].aim(goal) == pytest.approx(goal.centre()) and ev["sampled"].aim(goal) is None
    given = np.array([0.1, 0.2])
    assert ev["centre"].aim(goal, given) is given  # a vertex's own point wins under either rule


def test_the_rules_are_cached_apart_and_a_bad_rule_is_one_line():
    maze, ev = _evaluators()
    graph = maze_task(maze)
    u, v = graph.edges()[0]
    legs_s = [(graph.region(v), graph.avoid(u, v), ev["sampled"].aim(graph.region(v)))]
    legs_c = [(graph.region(v), graph.avoid(u, v), ev["centre"].aim(graph.region(v)))]
    key_s, _ = ev["sampled"]._key("edge", graph.region(u), legs_s, 16, 3, "fp")
    key_c, _ = ev["centre"]._key("edge", graph.region(u), legs_c, 16, 3, "fp")
    assert key_s != key_c
    with pytest.raises(SpecrefineError, match="goal points 'corner'"):
        Evaluator(maze, "point", PointController(), goal_points="corner")


def test_the_prompt_states_the_rule_the_evaluator_runs():
    maze, ev = _evaluators()
    graph = maze_task(maze)
    u, v = graph.edges()[0]
    texts = {}
    for rule, evaluator in ev.items():
        query = EdgeQuery(maze=maze, agent="point", start=graph.region(u), goal=graph.region(v),
                          avoid=graph.avoid(u, v), success=0.25, n=8, image_png=None, graph=graph,
                          facts=evaluator.facts())
        texts[rule] = messages_to_text(split_messages(query))
    assert "centre of the next region, in every rollout" in texts["centre"]
    assert "drawn uniformly" not in texts["centre"] and "drawn uniformly" in texts["sampled"]


def test_a_centre_run_records_the_rule_and_its_policy_aims_at_the_centres(tmp_path):
    out = tmp_path / "run"
    result = refine_maze("u_chain_1", RunConfig(agent="point", method="ours", goal_points="centre", **TINY),
                         out=out).data
    assert result["config"]["goal_points"] == "centre"
    assert json.loads((out / "run.json").read_text())["goal_points"] == "centre"
    graph = TaskGraph.from_dict(result["graph"])
    saved = json.loads((out / "policy.json").read_text())
    points = [leg["point"] for leg in saved["legs"]]
    expected = [graph.goal_point(v) if graph.goal_point(v) is not None else graph.region(v).centre()
                for v in result["path"][1:]]
    assert len(points) == len(expected) and all(np.allclose(p, e) for p, e in zip(points, expected))
    # the paper's rule into the same folder is another run: refused, the folder left alone
    with pytest.raises(SpecrefineError):
        refine_maze("u_chain_1", RunConfig(agent="point", method="ours", preset="paper", **TINY), out=out)
    assert json.loads((out / "result.json").read_text())["config"]["goal_points"] == "centre"


def test_a_sampled_run_keeps_the_records_it_always_had(tmp_path):
    out = tmp_path / "run"
    refine_maze("u_maze", RunConfig(agent="point", method="dirl", preset="paper", **TINY), out=out)
    assert "goal_points" not in json.loads((out / "run.json").read_text())


def test_the_cli_takes_the_rule(tmp_path, capsys):
    out = tmp_path / "cli"
    assert cli_main(["refine", "u_maze", "--method", "dirl", "--goal-points", "centre", "--rollouts", "8",
                     "--episodes", "16", "--out", str(out), "--quiet"]) == 0
    assert json.loads((out / "result.json").read_text())["config"]["goal_points"] == "centre"
    with pytest.raises(SystemExit) as exc:
        cli_main(["refine", "u_maze", "--goal-points", "corner"])
    assert exc.value.code == 2 and "--goal-points" in capsys.readouterr().err


def test_a_given_evaluator_with_the_other_rule_is_refused():
    maze, ev = _evaluators("u_maze")
    with pytest.raises(SpecrefineError, match="aims at sampled goal points, the run asks for centre"):
        setup(maze, evaluator=ev["sampled"], goal_points="centre")


def test_sweep_cells_name_the_rule_and_old_tables_refuse_it(tmp_path):
    (cell,) = sweep.grid(["u_maze"], ["dirl"], ["none"], [0], goal_points="centre")
    (paper,) = sweep.grid(["u_maze"], ["dirl"], ["none"], [0], preset="paper")
    assert cell.id == paper.id + "__centre" and cell.config.goal_points == "centre"
    table = tmp_path / "old.csv"
    table.write_text(",".join(c for c in sweep.COLUMNS if c != "goal_points") + "\n")
    with pytest.raises(ValueError, match="goal_points"):
        sweep._append(table, {"cell": cell.id, "goal_points": "centre", "status": "ok"})
    sweep._append(table, {"cell": paper.id, "goal_points": "sampled", "status": "ok"})  # the paper's rule fits
    assert sweep.main(["--mazes", "u_maze", "--methods", "dirl", "--seeds", "0", "--rollouts", "8", "--episodes",
                       "16", "--workers", "1", "--goal-points", "centre", "--out", str(tmp_path / "s")]) == 0
    (row,) = sweep.read_table(tmp_path / "s" / "results.csv")
    assert row["cell"] == cell.id and row["goal_points"] == "centre"


def _figure_rows(rule):
    return [{"maze": f"u_chain_{n}", "method": "ours", "proposer": "geometric", "seed": s, "status": "ok",
             "success_rate": 0.9, "graph_vertices": 5, "goal_points": rule} for n in (1, 2) for s in (0, 1)]


@pytest.mark.parametrize("rules, labels", [
    (["centre"], ["ours, centre goal points (no subgoals)", "ours, centre goal points (with subgoals)"]),
    (["", "centre"], ["ours (no subgoals)", "ours (with subgoals)", "ours, centre goal points (no subgoals)",
                      "ours, centre goal points (with subgoals)"]),  # "": a table from before the option
])
def test_figures_draw_runs_that_aimed_at_centres_under_their_method(rules, labels):
    from specrefine.experiments.figures import figure4, figure5

    rows = [r for rule in rules for r in _figure_rows(rule)]
    ax = figure5(rows, methods=["ours"]).axes[0]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == labels
    bars = figure4(rows, tasks=["u_chain_1", "u_chain_2"], methods=["ours"]).axes[0].patches
    assert len(bars) == 2 * len(rules) and all(b.get_height() == pytest.approx(0.9) for b in bars)


def test_figure5_keeps_equal_series_apart():
    from specrefine.experiments.figures import figure5

    rows = [dict(r, method=m) for m in ("ours", "ours-repair") for r in _figure_rows("centre")]
    bars = figure5(rows, methods=["ours", "ours-repair"]).axes[0].containers  # one errorbar per series
    xs = [tuple(bar.lines[0].get_xdata()) for bar in bars]
    assert len(xs) == 4 and len(set(xs)) == 4  # same successes, four series, each visible
    assert all(abs(x - round(x)) < 0.1 for line in xs for x in line)  # still read as whole rooms
