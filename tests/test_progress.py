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


def test_the_line_says_the_split_budget_and_what_is_simulated(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    monkeypatch.setenv("COLUMNS", "300")
    assert main(["refine", "split_doorway", "--method", "ours", "--proposer", "geometric", "--out", str(tmp_path),
                 *TINY]) == 0
    lines = [part.strip() for part in capsys.readouterr().err.replace("\n", "\r").split("\r") if part.strip()]
    after_split = [line for line in lines if "splits 1/30" in line]
    assert after_split, lines[-3:]
    assert any("measurement of 16 episodes" in line for line in lines)
    assert any("input task as it is: 16 episodes" in line for line in lines)


def test_a_notebook_keeps_the_runs_last_line_not_its_first(tmp_path):
    """The saved output of a run in a notebook is how it ended (the executed copies once kept '00:00 search | 0
    evaluations', the first state of a widget)."""
    import os
    from pathlib import Path

    import nbformat
    from nbclient import NotebookClient

    from specrefine.runs.notebook import kernel_env

    repo = Path(__file__).resolve().parent.parent
    env = kernel_env(tmp_path / "jupyter")
    env["PYTHONPATH"] = os.pathsep.join([str(repo), *filter(None, [env.get("PYTHONPATH")])])
    code = ("from specrefine.runs.pipeline import refine_maze\n"
            f"run = refine_maze('u_maze', method='symbolic', rollouts=8, episodes=8, out={str(tmp_path / 'run')!r})")
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(code)])
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "python3", "language": "python"}
    saved = dict(os.environ)
    os.environ.update(env)  # the kernel is started with this process's environment
    try:
        NotebookClient(nb, timeout=300, kernel_name="python3").execute()
    finally:
        os.environ.clear()
        os.environ.update(saved)
    texts = ["".join(o["data"]["text/plain"]) for o in nb.cells[0].outputs if "data" in o]
    assert len(texts) == 1, nb.cells[0].outputs
    assert " done | " in texts[0] and "0 evaluations" not in texts[0], texts[0]
