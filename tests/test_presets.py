"""The best measured settings by default, the paper's rules one switch away (--preset paper), every departure listed
in docs/choices.md, and one carrier of a run's settings (a sweep cell is a maze and a RunConfig)."""

from __future__ import annotations

import json
import re
from dataclasses import replace
from pathlib import Path

import pytest

from specrefine.cli import build_parser, main
from specrefine.core.agents import AGENTS
from specrefine.core.paper import PAPER
from specrefine.refine.search import SearchConfig
from specrefine.runs import sweep
from specrefine.runs.config import RunConfig

ROOT = Path(__file__).resolve().parent.parent
TINY = ["--rollouts", "8", "--episodes", "10", "-w", "1", "-d", "1", "-k", "1"]


def resolved(*argv: str) -> RunConfig:
    """The configuration `specrefine refine ARGV` runs with."""
    return RunConfig.from_namespace(build_parser("refine").parse_args(["refine", "u_maze", *argv])).resolved()


def test_the_defaults_are_the_best_measured_and_paper_restores_the_papers_rules():
    best, paper = resolved("--agent", "ant"), resolved("--agent", "ant", "--preset", "paper")
    assert (best.evaluation, best.goal_points, best.policy) == ("adaptive", "centre", "ant_stage5")
    assert (paper.evaluation, paper.goal_points, paper.policy) == ("fixed", "sampled", "ant_stage5")
    assert (best.method, paper.method) == ("ours-corrector-redraw-rescue", "ours")  # the paper's algorithm under paper
    assert (best.w, best.d, best.k, best.rollouts) == (paper.w, paper.d, paper.k, paper.rollouts) == (3, 2, 5, 32)
    point, point_paper = resolved(), resolved("--preset", "paper")
    # the point mass: the same settings but the goal points (centre since grid corrector-centre) and the method (the
    # corrector since grid corrector-deep-oracle, mend since corrector-mend-oracle, span since corrector-span-oracle,
    # span-bridge since corrector-span-bridge-oracle)
    assert replace(point_paper, preset="best", goal_points="centre", method="ours-corrector-span-bridge") == point
    assert (point.evaluation, point.goal_points, point.policy) == ("fixed", "centre", "shipped")
    assert (point.method, point_paper.method) == ("ours-corrector-span-bridge", "ours")
    assert resolved("--agent", "ant", "--method", "ours").method == "ours"  # an explicit method wins
    assert (point_paper.evaluation, point_paper.goal_points, point_paper.policy) == ("fixed", "sampled", "shipped")
    explicit = resolved("--agent", "ant", "--preset", "paper", "--goal-points", "centre", "--policy", "shipped")
    assert (explicit.goal_points, explicit.policy, explicit.evaluation) == ("centre", "shipped", "fixed")
    with pytest.raises(SystemExit):
        build_parser("refine").parse_args(["refine", "u_maze", "--preset", "fast"])


def test_a_run_records_its_preset_and_official_prints_it(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["refine", "split_doorway", *TINY, "--out", str(out)]) == 0
    assert "preset=best" in capsys.readouterr().out
    data = json.loads((out / "result.json").read_text())
    assert data["preset"] == "best" and data["config"]["goal_points"] == "centre"
    assert data["config"]["evaluation"] == "fixed" and data["config"]["policy"] == "shipped"
    assert data["config"]["method"] == "ours-corrector-span-bridge"
    # the point mass's presets differ in the goal points and the method: run.json records what runs, so the paper's
    # preset is another run (refused), and with centre points and the corrector the same one (the folder takes it)
    assert main(["refine", "split_doorway", *TINY, "--preset", "paper", "--out", str(out)]) == 2
    assert "holds another run" in capsys.readouterr().err
    assert main(["refine", "split_doorway", *TINY, "--preset", "paper", "--goal-points", "centre", "--method",
                 "ours-corrector-span-bridge", "--out", str(out)]) == 0
    assert json.loads((out / "result.json").read_text())["preset"] == "paper"
    capsys.readouterr()
    assert main(["official", str(out), "--episodes", "2"]) == 0
    assert ("the run's preset: paper with method=ours-corrector-span-bridge, goal_points=centre (the best preset's "
            "settings)") in capsys.readouterr().out
    assert json.loads((out / "official.json").read_text())["preset"] == "paper"


def test_a_run_given_the_other_presets_settings_is_named_by_both():
    """The pinned grids give the paper's rules one by one under the default preset: the summary says so."""
    from specrefine.runs.config import preset_text

    paper_by_flags = replace(RunConfig(agent="ant", preset="paper").resolved(), preset="best").to_dict()
    assert preset_text({"config": paper_by_flags}) == ("best with method=ours, evaluation=fixed, goal_points=sampled, "
                                           "split_pick=estimate (the paper preset's settings)")
    assert preset_text({"config": RunConfig(agent="ant").resolved().to_dict()}) == "best"
    assert preset_text({"config": RunConfig(agent="point", method="dirl").resolved().to_dict()}) == \
        "best with method=dirl"
    assert preset_text({"preset": "paper"}) == "paper"  # a result from before its config was recorded


def test_an_ant_folder_from_before_the_new_defaults_refuses_them(tmp_path, capsys):
    """An Ant run made with the old defaults (adaptive, sampled points, ant.pt) is another run than today's (the
    method named, so that the error's first differences are the settings)."""
    out = tmp_path / "old"
    out.mkdir()
    old = {"maze": "u_chain_1", "agent": "ant", "method": "ours", "proposer": "geometric", "seed": 0, "rollouts": 8,
           "episodes": 10, "policy": "shipped", "w": 1, "d": 1, "k": 1, "spec": None, "evaluation": "adaptive"}
    (out / "run.json").write_text(json.dumps(old))  # refused before any Ant is built: the record is checked first
    assert main(["refine", "u_chain_1", "--agent", "ant", "--method", "ours", *TINY, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "holds another run" in err and "goal_points" in err and "policy" in err
    assert json.loads((out / "run.json").read_text()) == old


def test_a_sweep_cell_is_a_maze_and_a_run_config():
    parsed = sweep.parser().parse_args(["--mazes", "u_maze", "--methods", "ours", "dirl", "--proposers", "geometric",
                                        "--agent", "ant", "--seeds", "0", "-k", "5", "7"])
    cells = sweep.cells_of(parsed)
    assert all(isinstance(c.config, RunConfig) and c.config == c.config.resolved() for c in cells)
    ours = [c for c in cells if c.method == "ours"]
    assert [c.id for c in ours] == ["u_maze__ant__ours__geometric__s0__adaptive__centre__split_pick-confirmed",
                                    "u_maze__ant__ours__geometric__s0__adaptive__k7__centre__split_pick-confirmed"]
    assert {(c.config.goal_points, c.config.policy, c.k) for c in ours} == {("centre", "ant_stage5", 5),
                                                                             ("centre", "ant_stage5", 7)}
    (dirl,) = [c for c in cells if c.method == "dirl"]
    assert dirl.proposer == "none" and dirl.row()["proposer"] == "none" and dirl.row()["cell"] == dirl.id
    paper = sweep.cells_of(sweep.parser().parse_args(["--mazes", "u_maze", "--methods", "dirl", "--seeds", "0",
                                                      "--agent", "ant", "--preset", "paper"]))
    assert [c.id for c in paper] == ["u_maze__ant__dirl__none__s0"]


def test_search_settings_come_from_the_run_config_in_one_place():
    config = RunConfig(agent="ant", w=4, d=1, k=9, seed=3).resolved()
    search = SearchConfig.from_run(config, repair=True)
    assert (search.w, search.d, search.k, search.seed, search.evaluation, search.repair) == (4, 1, 9, 3, "adaptive",
                                                                                             True)


def test_docs_choices_lists_every_departure_the_code_makes():
    text = (ROOT / "docs" / "choices.md").read_text()
    table = text.split("\n## Presets\n", 1)[1]
    rows = [[c.strip() for c in line.split("|")[1:-1]] for line in table.splitlines()
            if line.startswith("| ") and not line.startswith("| ---")][1:]  # the header row aside
    listed = {(agent, re.search(r"`(--[a-z-]+)`", setting).group(1)): (best, paper)
              for agent, setting, best, paper, _ in rows if re.search(r"`--[a-z-]+`", setting)}  # not "any other"
    flags = {"evaluation": "--evaluation", "goal_points": "--goal-points", "policy": "--policy",
             "split_pick": "--split-pick"}
    for name in AGENTS:
        best, paper = RunConfig(agent=name).resolved(), RunConfig(agent=name, preset="paper").resolved()
        for field, flag in flags.items():
            if getattr(best, field) != getattr(paper, field) or getattr(best, field) not in (
                    getattr(PAPER, field, None), "shipped"):  # a departure from the paper, or a non-default policy
                assert (name, flag) in listed, (name, flag)
                shown_best, shown_paper = listed[name, flag]
                assert f"`{getattr(best, field)}`" in shown_best and f"`{getattr(paper, field)}`" in shown_paper
    assert any(agent == "point" and "the paper's rules" in best for agent, _, best, _, _ in rows)


def test_every_run_setting_reaches_a_sweep_cell():
    """Each RunConfig field is a sweep option (or axis), so a new setting needs no sweep code to reach its cells."""
    from dataclasses import fields

    dests = {action.dest for action in sweep.parser()._actions}
    axes = {"method": "methods", "proposer": "proposers", "seed": "seeds", "spec": "specs"}
    assert [f.name for f in fields(RunConfig) if axes.get(f.name, f.name) not in dests] == []
    assert sweep.OTHER_SETTINGS == ("split_pick", "switching")  # named in the id when not the paper's
    parsed = sweep.parser().parse_args(["--mazes", "u_maze", "--methods", "ours", "--proposers", "geometric",
                                        "--agent", "ant", "--seeds", "0", "--switching", "slow-turn"])
    [cell] = sweep.cells_of(parsed)
    assert cell.config.switching == "slow-turn"
    assert cell.id.endswith("__centre__split_pick-confirmed__switching-slow-turn")


def test_the_split_pick_is_a_preset_setting_that_reaches_the_search_and_is_named_where_not_the_papers():
    for name in AGENTS:
        paper = RunConfig(agent=name, preset="paper").resolved()
        assert paper.split_pick == PAPER.split_pick == "estimate" and not SearchConfig.from_run(paper).confirm_pick
        assert "split_pick" not in paper.record()  # older folders' run.json stay valid
    confirmed = RunConfig(agent="point", split_pick="confirmed").resolved()
    assert SearchConfig.from_run(confirmed).confirm_pick and confirmed.record()["split_pick"] == "confirmed"
    assert SearchConfig.from_run(RunConfig().resolved(), confirm_pick=True).confirm_pick  # a method's own wins
    parsed = sweep.parser().parse_args(["--mazes", "u_maze", "--methods", "ours", "--proposers", "geometric",
                                        "--seeds", "0", "--split-pick", "confirmed", "--preset", "paper"])
    [cell] = sweep.cells_of(parsed)
    assert cell.id.endswith("__s0__split_pick-confirmed")
    [paper_cell] = sweep.cells_of(sweep.parser().parse_args(["--mazes", "u_maze", "--methods", "ours", "--proposers",
                                                             "geometric", "--seeds", "0", "--preset", "paper"]))
    assert paper_cell.id == "u_maze__point__ours__geometric__s0"  # the id every older table holds
    [dirl] = sweep.cells_of(sweep.parser().parse_args(["--mazes", "u_maze", "--methods", "dirl", "--seeds", "0",
                                                       "--split-pick", "confirmed", "--preset", "paper"]))
    assert dirl.id == "u_maze__point__dirl__none__s0"  # it splits no edge: nothing to name
    assert "split_pick" not in RunConfig(method="dirl", split_pick="confirmed").resolved().record()


def test_a_confirmed_split_pick_runs_ours_as_the_method_ours_confirm_does(tmp_path):
    from specrefine.runs.pipeline import refine_maze

    # sampled goal points (the paper's): with centre points no later round's pick is confirmed on this cell
    common = dict(agent="point", proposer="imperfect:moderate", seed=3, rollouts=8, episodes=16, preset="paper")
    by_setting = refine_maze("u_chain_2", method="ours", split_pick="confirmed", out=tmp_path / "setting", **common)
    by_method = refine_maze("u_chain_2", method="ours-confirm", out=tmp_path / "method", **common)
    for key in ("path", "success_rate", "evaluations", "proposer_calls", "refinements"):
        assert by_setting.data[key] == by_method.data[key], key
    assert by_setting.data["split_pick"] == "confirmed" and by_method.data["split_pick"] == "estimate"
    steps = (tmp_path / "setting" / "steps.jsonl").read_text()
    assert '"confirm": {' in steps  # a later round's pick was confirmed here: the setting reached the split


def test_readme_names_each_agents_default_method_and_the_papers():
    """README's Command line says which method a run uses by default: the agents' registry, not a copy that ages."""
    text = " ".join((ROOT / "README.md").read_text().split())
    point, ant = AGENTS["point"].default_method, AGENTS["ant"].default_method
    assert f"By default a run uses the corrector (`{point}` for the point mass, `{ant}` for the Ant)" in text
    assert f"With `--preset paper` it runs the paper's `{PAPER.method}`" in text
