"""argparse ``type=`` functions for the command lines' numbers: a nonsense or absurd value is a one-line usage
error (exit 2) before anything runs, never a hang, a traceback or a silently meaningless result. Also the
command lines' quiet exit when their reader goes away (``... | head``).

The caps are far above what the paper uses (w = 3, d = 2, k = 5, 32 rollouts, 200 episodes): they only stop
values that would run for days (``-w 1000000``) or overflow a seed.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path


class DefaultsShown(argparse.HelpFormatter):
    """Help that ends each option's text in its default, ``(default: 32)``, unless the text already says it."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "default" in text.lower() or not action.option_strings or action.default in (None, argparse.SUPPRESS) \
                or action.nargs == 0:  # flags (store_true) and options that explain their own None
            return text
        return f"{text} (default: %(default)s)" if text else "(default: %(default)s)"


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line (no usage block), still exit code 2; the environment the commands
    depend on is checked with the arguments, before any work (``MPLBACKEND``, read when matplotlib is imported).
    Its help shows every option's default (:class:`DefaultsShown`)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", DefaultsShown)
        super().__init__(*args, **kwargs)

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")

    def parse_args(self, args=None, namespace=None):
        parsed = super().parse_args(args, namespace)
        problem = environment_problem()
        if problem:
            self.exit(2, f"{self.prog}: error: {problem}\n")
        return parsed


def environment_problem() -> str | None:
    """One line on what in the environment would make a command fail midway (None: nothing)."""
    backend = os.environ.get("MPLBACKEND")
    if backend is None:
        return None
    try:
        import matplotlib  # noqa: F401 - importing it validates MPLBACKEND
    except ValueError:
        return f"MPLBACKEND={backend!r} is not a matplotlib backend: unset it or name one (e.g. Agg)"
    return None


def exit_code_quiet_on_broken_pipe(main, *args) -> int:
    """``main(*args)``'s exit code; when stdout's reader has gone (``... | head``), the rest of the output is dropped
    without a traceback (exit 1, as in Python's docs on SIGPIPE). Files a command writes before it prints are kept."""
    try:
        return main(*args) or 0
    except BrokenPipeError:
        silence_stdout()
        return 1


def script_exit_code(main, *args) -> int:
    """A maintainer's script's exit code (``scripts/``): bad input it meets (a :class:`SpecrefineError`: an
    ``--out`` it cannot use, an unreadable record, a folder in use; a file it cannot open) is one line on stderr,
    exit 2, never a traceback; a closed stdout as :func:`exit_code_quiet_on_broken_pipe`."""
    from .errors import SpecrefineError

    try:
        return exit_code_quiet_on_broken_pipe(main, *args)
    except (SpecrefineError, OSError) as exc:
        text = f"{exc.filename}: {exc.strerror}" if isinstance(exc, OSError) and exc.filename else str(exc)
        print(f"{Path(sys.argv[0]).name}: error: {text}", file=sys.stderr)
        return 2


def silence_stdout() -> None:
    """Point stdout at /dev/null, so that the interpreter's last flush after a broken pipe does not raise."""
    os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


MAX_SEED = 2**31 - 1
#: option -> (smallest, largest) accepted value
LIMITS = {
    "w": (1, 20), "d": (1, 10), "k": (1, 100), "rollouts": (1, 4096), "episodes": (1, 100_000),
    "seed": (0, MAX_SEED), "workers": (1, 256), "batch": (1, 65_536), "rounds": (1, 1000), "horizon": (1, 100_000),
    "torch_threads": (1, 256), "nthread": (1, 256), "gym_steps": (1, 10_000_000), "batches": (1, 10_000),
    "chain": (1, 1000),
}


def bounded_int(name: str):
    """An argparse type: an integer within ``LIMITS[name]``, else a one-line message naming the range."""
    lo, hi = LIMITS[name]

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"{value} is out of range: use {lo} to {hi}")
        return value

    parse.__name__ = name  # argparse names the type in its messages
    return parse


def positive_float(text: str) -> float:
    """An argparse type: a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not 0 < value < float("inf"):
        raise argparse.ArgumentTypeError(f"{text} must be a finite number > 0")
    return value


def result_file(text: str) -> Path:
    """An argparse type for a finished run: its result.json, or its folder (then the result.json in it)."""
    path = out_path(text)
    return path / "result.json" if path.is_dir() else path


def out_path(text: str) -> Path:
    """An argparse type for an output path: not empty (``--out ''`` would write into the current directory)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path: name a folder (e.g. runs/mine)")
    return Path(text)
