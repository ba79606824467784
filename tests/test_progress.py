"""`specrefine refine` shows one live progress line on a terminal's stderr, and nothing otherwise."""

from __future__ import annotations

import sys

import pytest

from specrefine.cli import main

TINY = ["--rollouts", "8", "--episodes", "16"]


def refine(tmp_path, *extra):
    return main(["refine", "u_maze", "--method", "symbolic", "--out", str(tmp_path), *TINY, *extra])


def test_a_terminal_sees_the_phases_and_counters(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    monkeypatch.setenv("COLUMNS", "200")  # the line is cut to the terminal's width
    assert refine(tmp_path) == 0
    err = capsys.readouterr().err
    lines = [part.strip() for part in err.replace("\n", "\r").split("\r") if part.strip()]
    phases = [line.split()[1] for line in lines]
    assert {"search", "measurement", "calibration"} <= set(phases)
    assert phases.index("search") < phases.index("measurement") < phases.index("calibration")
    last = [line for line in lines if line.split()[1] == "calibration"][-1]
    for part in ("best path", "evaluations", "sim steps", "proposer calls"):
        assert part in last, last


@pytest.mark.parametrize("tty, extra", [(False, ()), (True, ("--quiet",))])
def test_nothing_extra_without_a_terminal_or_with_quiet(tmp_path, capsys, monkeypatch, tty, extra):
    monkeypatch.setattr(sys.stderr, "isatty", lambda: tty)
    assert refine(tmp_path, *extra) == 0
    out = capsys.readouterr()
    assert out.err == "" and "success on the original task" in out.out
