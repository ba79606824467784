"""One run configuration: RunConfig's defaults are the CLI's, and result.json records what a run ran with."""

from __future__ import annotations

import json
from dataclasses import asdict, fields

import pytest

from specrefine.cli import build_parser, main
from specrefine.core.agents import AGENTS
from specrefine.runs.config import DEFAULTS, RunConfig
from specrefine.runs.pipeline import refine_maze


def test_the_paper_settings_are_the_defaults_of_the_cli():
    args = build_parser().parse_args(["refine", "u_maze"])
    assert RunConfig.from_namespace(args) == DEFAULTS == RunConfig()
    assert (DEFAULTS.rollouts, DEFAULTS.episodes, DEFAULTS.w, DEFAULTS.d, DEFAULTS.k) == (32, 200, 3, 2, 5)
    assert all(f.metadata["help"] for f in fields(RunConfig))  # every field documented


def test_every_field_is_an_option(capsys):
    args = build_parser().parse_args(["refine", "u_maze", "--agent", "point", "--method", "symbolic", "--proposer",
                                      "random", "--spec", "a -> G", "--seed", "4", "--rollouts", "8", "--episodes",
                                      "9", "--policy", "scripted", "-w", "4", "-d", "1", "-k", "6", "--evaluation",
                                      "adaptive", "--goal-points", "centre", "--switching", "slow-turn",
                                      "--split-pick", "confirmed", "--preset", "paper"])
    assert asdict(RunConfig.from_namespace(args)) == dict(
        agent="point", method="symbolic", proposer="random", spec="a -> G", seed=4, rollouts=8, episodes=9,
        policy="scripted", w=4, d=1, k=6, evaluation="adaptive", goal_points="centre", switching="slow-turn",
        split_pick="confirmed", preset="paper")


def test_help_prints_every_options_text_as_written_and_its_preset_defaults_from_the_agents(capsys):
    """A help text's '%' is a per cent sign, not argparse's formatting (a method's 'losing about 1 % and' once printed
    argparse's own parameters there), and the preset's defaults come from the agents' registry."""
    with pytest.raises(SystemExit):
        main(["refine", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "finds legs losing about 1 % and their alternatives" in out and "'container'" not in out
    assert "(default: the preset's: best: fixed for point, adaptive for ant; paper: fixed)" in out
    assert "(default: the preset's: best: centre; paper: sampled)" in out  # one value where every agent has it
    refine = build_parser()._subparsers._group_actions[0].choices["refine"]
    method = next(a for a in refine._actions if a.dest == "method").help
    assert method.endswith(f"(default: the preset's: best: {AGENTS['point'].default_method} for point, "
                           f"{AGENTS['ant'].default_method} for ant; paper: ours)")


def test_usage_names_the_method_and_a_wrong_one_lists_every_choice(capsys):
    """The usage line says METHOD (the list of methods is the option's help), and a wrong name still lists them."""
    with pytest.raises(SystemExit):
        main(["refine", "--help"])
    usage = capsys.readouterr().out.split("\n\n")[0]
    assert "[--method METHOD]" in usage and "ours-corrector" not in usage
    with pytest.raises(SystemExit):
        main(["refine", "u_maze", "--method", "nope"])
    err = capsys.readouterr().err
    assert "invalid choice: 'nope'" in err and all(f"'{name}'" in err for name in ("ours", "vlm-oneshot", "dirl"))


def test_result_json_records_the_config_and_the_keywords_build_the_same_one(tmp_path, capsys):
    assert main(["refine", "u_maze", "--method", "dirl", "--rollouts", "8", "--episodes", "16", "-k", "7",
                 "--out", str(tmp_path / "cli")]) == 0
    recorded = json.loads((tmp_path / "cli" / "result.json").read_text())["config"]
    assert recorded == {**asdict(DEFAULTS), "method": "dirl", "rollouts": 8, "episodes": 16, "k": 7,
                        "evaluation": "fixed", "goal_points": "centre", "policy": "shipped",
                        "split_pick": "estimate"}  # the preset's, resolved
    data = refine_maze("u_maze", method="dirl", rollouts=8, episodes=16, k=7, out=tmp_path / "kw").data
    assert data["config"] == recorded
    with pytest.raises(TypeError):
        refine_maze("u_maze", rolouts=8, out=tmp_path / "typo")
