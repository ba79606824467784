"""Issue 13: no silently wrong result, no hang, one line for every bad input, a run folder that cannot lie."""

from __future__ import annotations

import pytest

from specrefine import bench, sweep
from specrefine.cli import main as cli_main

TINY = ["--rollouts", "2", "--episodes", "2"]


def exit_code(main, args) -> int:
    try:
        return main(args)
    except SystemExit as exc:  # argparse errors
        return exc.code


def assert_one_line_exit_2(main, args, capsys, needle=""):
    code = exit_code(main, args)
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1 and needle in err and "Traceback" not in err, err


# --- nonsense numbers: one line, exit 2, before anything runs ------------------------------------------
@pytest.mark.parametrize("args", [
    ["-w", "0"], ["-d", "0"], ["-w", "-1"], ["-d", "-2"], ["-k", "-1"], ["-k", "0"], ["--rollouts", "0"],
    ["--rollouts", "-3"], ["--episodes", "0"], ["--episodes", "-1"], ["--seed", "-1"], ["-w", "1000000"],
    ["--seed", str(2**40)], ["--rollouts", "lots"],
])
def test_refine_rejects_nonsense_numbers(tmp_path, capsys, args):
    out = tmp_path / "o"
    assert_one_line_exit_2(cli_main, ["refine", "u_maze", "--out", str(out), *TINY, *args], capsys,
                           "out of range" if args[1].lstrip("-").isdigit() else "not a whole number")
    assert not out.exists()  # refused before anything was written


@pytest.mark.parametrize("args", [
    ["--rollouts", "0"], ["--episodes", "-1"], ["--seeds", "0", "-1"], ["--workers", "0"], ["--rollouts", "99999"],
])
def test_sweep_rejects_nonsense_numbers(tmp_path, capsys, args):
    out = tmp_path / "s"
    assert_one_line_exit_2(sweep.main, ["--mazes", "u_maze", "--methods", "dirl", "--out", str(out), *args], capsys,
                           "out of range")
    assert not out.exists()


@pytest.mark.parametrize("args", [["--batch", "0"], ["--batch", "-4"], ["--rounds", "0"], ["--seconds", "0"]])
def test_bench_rejects_nonsense_numbers(capsys, args):
    assert_one_line_exit_2(bench.main, ["evaluator", *args], capsys, "error")
