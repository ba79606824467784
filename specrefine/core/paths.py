"""Where the shipped files are: ``prompts/`` and ``data/`` of the checkout, or their copies in an installed wheel.

In a checkout (editable install, ``PYTHONPATH``) they are the top-level ``prompts/`` and ``data/``
beside ``specrefine/``; a built wheel carries the same files as ``specrefine/_shipped/{prompts,data}``
(see ``setup.py``).  The checkout wins when both exist.  :func:`code_commit` names the checkout's commit, so
that a result can say which code made it.
"""

from __future__ import annotations

import functools
import subprocess
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parents[1]  # specrefine/, above core/
_CHECKOUT = _PACKAGE.parent
_SHIPPED = _PACKAGE / "_shipped"


def _find(name: str) -> Path:
    here = _CHECKOUT / name
    return here if here.is_dir() or not (_SHIPPED / name).is_dir() else _SHIPPED / name


def prompt_dir() -> Path:
    return _find("prompts")


def data_dir() -> Path:
    return _find("data")


def shipped_name(text) -> bool:
    """Whether ``text`` names a shipped policy checkpoint by its stem (``ant_stage5``: data/policies/ant_stage5.pt)."""
    return isinstance(text, str) and text.isidentifier() and (data_dir() / "policies" / f"{text}.pt").is_file()


@functools.lru_cache(maxsize=1)
def code_commit() -> str:
    """The commit this package's code runs from (``git rev-parse --short=7 HEAD`` of its checkout or worktree), with
    ``-dirty`` when tracked files under ``specrefine/`` differ from it; ``unknown`` where the package is not the
    top of a git checkout (an installed wheel) or git is missing.  Asked once per process."""
    def git(*args) -> str:
        return subprocess.run(["git", "-C", str(_CHECKOUT), *args], capture_output=True, text=True, check=True,
                              timeout=30).stdout.strip()

    try:
        if Path(git("rev-parse", "--show-toplevel")).resolve() != _CHECKOUT:  # a wheel inside someone's repo
            return "unknown"
        commit = git("rev-parse", "--short=7", "HEAD")
        dirty = git("status", "--porcelain", "--untracked-files=no", "--", str(_PACKAGE))
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return f"{commit}-dirty" if dirty else commit


def regular_file(path, what: str = "file") -> Path:
    """``path`` if it is a regular file (a symlink to one too), checked BEFORE anything opens it: a FIFO would block
    the read forever, a device or a folder is no input file; otherwise a one-line
    :class:`~specrefine.core.errors.SpecrefineError`."""
    import os
    import stat

    from .errors import SpecrefineError

    path = Path(path)
    try:
        mode = os.stat(path).st_mode
    except OSError as exc:
        raise SpecrefineError(f"{path}: cannot read {what} ({exc.strerror or exc})") from None
    if not stat.S_ISREG(mode):
        kind = "a folder" if stat.S_ISDIR(mode) else "a FIFO" if stat.S_ISFIFO(mode) else "not a regular file"
        raise SpecrefineError(f"{path}: cannot read {what} ({kind}; give a regular file)")
    return path
