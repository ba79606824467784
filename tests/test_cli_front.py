"""One front door: every command is a `specrefine` subcommand with its defaults in --help, the old module paths still
run, a base install refines without the extras, and docs/cli.md names what --help names."""

from __future__ import annotations

import argparse
import errno
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from specrefine import __version__, cli
from specrefine.proposers.factory import PROPOSERS
from specrefine.runs.methods import METHODS

ROOT = Path(__file__).resolve().parent.parent
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
EXTRAS = ("litellm", "ray", "papermill", "jupyterlab", "ipywidgets", "ipykernel", "nbformat", "playwright")
TINY = ["--rollouts", "8", "--episodes", "10", "-w", "1", "-d", "1", "-k", "1"]


def _python(*args, cwd=ROOT, timeout=300):
    return subprocess.run([sys.executable, *args], cwd=cwd, env=ENV, capture_output=True, text=True, timeout=timeout)


def _options(parser: argparse.ArgumentParser, prefix: str = ""):
    """(command path, action) of every option of ``parser`` and of its nested subcommands."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _options(sub, f"{prefix} {name}".strip())
        elif action.option_strings:
            yield prefix, action


def test_version_and_the_same_cli_under_python_m(capsys):
    with pytest.raises(SystemExit) as done:
        cli.main(["--version"])
    assert done.value.code == 0 and capsys.readouterr().out.strip() == f"specrefine {__version__}"
    listed = _python("-m", "specrefine", "--help")
    assert listed.returncode == 0
    assert all(re.search(rf"^\s+{name}\s", listed.stdout, re.M) for name in cli.COMMANDS), listed.stdout
    assert set(cli.COMMANDS) >= {"refine", "official", "sweep", "grids", "train", "calibrate", "failures", "figures",
                                 "bench", "notebook"}


def test_every_option_of_every_command_shows_its_default():
    parser = cli.build_parser()
    formatter = parser.formatter_class(prog="x")
    missing = [f"{where}: {action.option_strings[0]}" for where, action in _options(parser)
               if action.nargs != 0 and not isinstance(action, (argparse._HelpAction, argparse._VersionAction))
               and "default" not in formatter._get_help_string(action).lower()
               and not action.required]
    assert not missing, missing
    assert "(default: runs/latest)" in " ".join(parser.commands["refine"].format_help().split())


@pytest.mark.parametrize("command", list(cli.COMMANDS))
def test_each_command_has_help(command, capsys):
    with pytest.raises(SystemExit) as done:
        cli.main([command, "--help"])
    assert done.value.code == 0 and f"usage: specrefine {command}" in capsys.readouterr().out


REQUIRED = {  # the least each command's parser takes (nothing is read: the command's run is replaced)
    "refine": ["u_maze"], "official": ["x"], "grids": ["list"], "train": ["--agent", "point"], "calibrate": ["x"],
    "failures": ["x"], "taxonomy": ["x", "--oracle", "x"], "corrector-diagnosis": ["x", "--reference", "x"],
    "correction-ledger": ["x"], "spend": ["x"], "chain-agreement": ["x"], "figures": ["x"], "bench": ["evaluator"],
    "notebook": ["executed"], "show": ["x"]}


@pytest.mark.parametrize("command", list(cli.COMMANDS))
def test_a_file_error_midway_is_one_line_on_every_command(command, monkeypatch, capsys):
    """An OSError no command foresaw (a full disk while writing) is one line and exit 2, not a traceback; a closed
    pipe (BrokenPipeError, its subclass) stays quiet."""
    from specrefine.core import commands

    module = commands._module(command)

    def full_disk(args, parser):
        raise OSError(errno.ENOSPC, "No space left on device", "out/table.csv")

    monkeypatch.setattr(module, "run", full_disk)
    argv = [command, *REQUIRED.get(command, [])]
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.splitlines() == [f"specrefine {command}: error: [Errno {errno.ENOSPC}] No space left on device: "
                                "'out/table.csv'"], err

    def closed_pipe(args, parser):
        raise BrokenPipeError(errno.EPIPE, "Broken pipe")

    monkeypatch.setattr(module, "run", closed_pipe)
    monkeypatch.setattr(commands, "silence_stdout", lambda: None)
    assert cli.main(argv) == 1 and "error" not in capsys.readouterr().err


def test_old_module_paths_take_the_same_options():
    for module, args in (("specrefine.runs.sweep", ["--help"]), ("specrefine.experiments.grids", ["list"]),
                         ("specrefine.cli", ["refine", "--help"])):
        done = _python("-m", module, *args)
        assert done.returncode == 0 and done.stdout, (module, done.stderr)
    assert "--all" in _python("-m", "specrefine.runs.sweep", "--help").stdout


def test_a_sweep_without_mazes_refuses_and_names_all(tmp_path, capsys):
    assert cli.main(["sweep", "--methods", "dirl", "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--all" in err and "--mazes" in err
    assert not (tmp_path / "s").exists()
    assert cli.main(["sweep", "--all", "--mazes", "u_maze", "--out", str(tmp_path / "s")]) == 2


def test_an_unknown_maze_name_suggests_the_nearest(tmp_path, capsys):
    assert cli.main(["refine", "u_chian_2", "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "nearest: u_chain_2" in err, err


def test_a_base_install_refines_and_a_missing_extra_is_one_line(tmp_path):
    """Without any extra importable, an offline run works; a litellm: proposer names the 'vlm' extra."""
    block = f"import sys; sys.modules.update(dict.fromkeys({EXTRAS!r})); from specrefine.cli import main; "
    run = _python("-c", block + "sys.exit(main(sys.argv[1:]))", "refine", "split_doorway", *TINY,
                  "--out", str(tmp_path / "base"))
    assert run.returncode == 0, run.stderr[-2000:]
    vlm = _python("-c", block + "sys.exit(main(sys.argv[1:]))", "refine", "split_doorway", *TINY,
                  "--proposer", "litellm:gpt-4o", "--out", str(tmp_path / "vlm"))
    lines = vlm.stderr.strip().splitlines()
    assert vlm.returncode == 2 and len(lines) == 1 and "pip install 'specrefine[vlm]'" in lines[0], vlm.stderr
    for extra, argv in (("ray", ["sweep", "--mazes", "u_maze", "--methods", "dirl", "--seeds", "0", "--backend",
                                 "ray", "--out", str(tmp_path / "sweep")]),
                        ("notebooks", ["notebook", "executed", "05", "--out", str(tmp_path / "nb")])):
        done = _python("-c", block + "sys.exit(main(sys.argv[1:]))", *argv)
        lines = done.stderr.strip().splitlines()
        assert done.returncode == 2 and len(lines) == 1 and f"'specrefine[{extra}]'" in lines[0], done.stderr


def test_py_typed_ships_with_the_package():
    assert (ROOT / "specrefine" / "py.typed").is_file()
    assert '"py.typed"' in (ROOT / "pyproject.toml").read_text()


def _doc_sections(text: str) -> dict[str, str]:
    """docs/cli.md cut at its '## specrefine COMMAND' headings."""
    parts = re.split(r"^## `specrefine ([\w-]+)`", text, flags=re.M)
    return dict(zip(parts[1::2], parts[2::2]))


def test_docs_cli_names_every_option_method_and_proposer_of_the_help():
    text = (ROOT / "docs" / "cli.md").read_text()
    sections = _doc_sections(text)
    parser = cli.build_parser()
    assert set(sections) == set(cli.COMMANDS), sorted(sections)
    absent = [f"{where}: {flag}" for where, action in _options(parser) if where
              for flag in action.option_strings[:1] if flag not in ("-h", "--plugin")
              and not re.search(rf"`[^`]*{re.escape(flag)}\b", sections[where.split()[0]])]
    assert not absent, absent
    assert all(f"`{name}`" in text for name in METHODS), [m for m in METHODS if f"`{m}`" not in text]
    assert all(kind.usage.split(" or ")[0].split(":")[0] in text for kind in PROPOSERS.values())
    assert "random:RxC:SEED" in text and "--plugin" in text and "--preset paper" in text
