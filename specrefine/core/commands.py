"""The machinery of the ``specrefine`` command line (:mod:`specrefine.cli`): commands, plugins, errors.

    specrefine [--plugin MODULE] COMMAND [options]        specrefine COMMAND --help: its options and defaults

It lives in the core, below every command, so that each command's older ``python -m specrefine.<module>`` path can
run through it (:func:`run_command`) without importing a layer above its own; commands are imported by name.

:data:`COMMANDS` names each command's module, which has ``add_arguments(parser)`` and ``run(args, parser) -> int``:
a new command is one entry there. Only the chosen command's module is imported (``train`` imports PyTorch, the
others need not), and plugins (:mod:`specrefine.core.plugins`: entry points and ``--plugin MODULE``) are loaded before
any parser is built, so ``--method`` and ``--proposer`` accept the names they register.

Bad input exits 2 with one line on stderr; never a traceback. Ctrl-C exits 130.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from dataclasses import dataclass

from .argtypes import OneLineParser, silence_stdout
from .errors import SpecrefineError
from .plugins import load_plugins, plugin_args


@dataclass(frozen=True)
class Command:
    module: str  # has add_arguments(parser) and run(args, parser) -> int
    help: str  # one line for `specrefine --help`


COMMANDS: dict[str, Command] = {
    "refine": Command("specrefine.runs.refine_command", "refine a maze task's specification and measure the policy"),
    "official": Command("specrefine.runs.official_command",
                        "run a finished run's policy in the official Gymnasium-Robotics environment"),
    "sweep": Command("specrefine.runs.sweep", "a grid of runs (mazes x methods x proposers x seeds) into one table"),
    "grids": Command("specrefine.experiments.grids", "the experiment grids fixed before they ran: list, show, status"),
    "train": Command("specrefine.sim.train", "train or evaluate a goal-conditioned policy (PPO, TorchRL)"),
    "calibrate": Command("specrefine.runs.calibrate", "a run's prediction made again, and its coverage over runs"),
    "failures": Command("specrefine.experiments.failures", "where a finished run's path loses its episodes"),
    "taxonomy": Command("specrefine.experiments.taxonomy", "why runs ended below the oracle: one cause per run"),
    "corrector-claims": Command("specrefine.experiments.corrector_claims",
                                "the corrector grids' rules decided from their shipped tables"),
    "corrector-diagnosis": Command("specrefine.experiments.corrector_diagnosis",
                                   "where ours-corrector still loses and where its proposer calls go"),
    "correction-ledger": Command("specrefine.experiments.correction_ledger",
                                 "what each run's correction decided, and its last check against the measured success"),
    "spend": Command("specrefine.experiments.spend",
                     "where runs' simulator steps went, phase by phase, read from their evaluation caches"),
    "chain-agreement": Command("specrefine.experiments.chain_agreement",
                               "a run's path estimated leg by leg (chained) and as whole episodes, side by side"),
    "figures": Command("specrefine.experiments.figures", "the paper's Figures 4-6 from a sweep table"),
    "bench": Command("specrefine.bench.__main__", "throughput benchmarks: evaluator, gymenv, train, refine"),
    "notebook": Command("specrefine.runs.notebook", "executed copies of the numbered notebooks"),
    "show": Command("specrefine.runs.show", "a finished run at a glance: summary, path leg by leg, time, pictures"),
}


def _module(name: str):
    return importlib.import_module(COMMANDS[name].module)


def _plugin_option(parser, help_text: str, default) -> None:
    parser.add_argument("--plugin", action="append", metavar="MODULE", default=default, help=help_text)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The command line; ``command``: the one whose options are built ("": none; None: all, importing every module)."""
    parser = OneLineParser(prog="specrefine", description="Refine reach-avoid task specifications for RL agents, "
                                                          "and measure the policies they give: one command per job.")
    version = importlib.import_module("specrefine").__version__  # by name: the package is the layer above
    parser.add_argument("--version", action="version", version=f"specrefine {version}")
    _plugin_option(parser, "a module (dotted name, or a .py file) that registers methods or proposers, loaded "
                           "before anything else; repeatable (default: none; installed entry points of the groups "
                           "specrefine.methods and specrefine.proposers are always loaded)", [])
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    parser.commands = {}  # name -> its parser
    for name, cmd in COMMANDS.items():
        p = parser.commands[name] = sub.add_parser(name, help=cmd.help, description=cmd.help)
        if command is None or command == name:
            _plugin_option(p, "as before the command (default: none)", argparse.SUPPRESS)
            _module(name).add_arguments(p)
    return parser


def command_parser(name: str, prog: str) -> argparse.ArgumentParser:
    """The parser of one command on its own (its older ``python -m`` path)."""
    parser = OneLineParser(prog=prog, description=COMMANDS[name].help)
    _plugin_option(parser, "a module that registers methods or proposers (default: none)", [])
    _module(name).add_arguments(parser)
    return parser


def main(argv=None) -> int:
    argv = [str(a) for a in (sys.argv[1:] if argv is None else argv)]
    if not _load(argv, "specrefine"):
        return 2
    name = _command_in(argv)
    parser = build_parser(name)
    args = parser.parse_args(argv)
    return _run(args.command, args, parser.commands[args.command])


def run_command(name: str, argv=None, *, prog: str) -> int:
    """Command ``name`` as its older ``python -m specrefine.<module>`` path runs it (the same options and code)."""
    argv = [str(a) for a in (sys.argv[1:] if argv is None else argv)]
    if not _load(argv, prog):
        return 2
    parser = command_parser(name, prog)
    return _run(name, parser.parse_args(argv), parser)


def _load(argv: list[str], prog: str) -> bool:
    try:
        load_plugins(plugin_args(argv))
    except SpecrefineError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return False
    return True


def _command_in(argv: list[str]) -> str:
    """The command named in ``argv`` ("" if none is: argparse then says what is wrong)."""
    skip = False
    for arg in argv:
        if skip:
            skip = False
        elif arg == "--plugin":
            skip = True
        elif not arg.startswith("-"):
            return arg if arg in COMMANDS else ""
    return ""


def _run(name: str, args, parser) -> int:
    """Run a parsed command: a SpecrefineError or OSError it lets through is one line and exit 2, Ctrl-C exit 130,
    and a closed pipe (``... | head``) no traceback."""
    try:
        return _module(name).run(args, parser) or 0
    except SpecrefineError as exc:
        print(f"{parser.prog}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{parser.prog}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        silence_stdout()
        return 1
    except OSError as exc:  # after BrokenPipeError, its subclass: a file the command could not read or write
        print(f"{parser.prog}: error: {exc}", file=sys.stderr)
        return 2

