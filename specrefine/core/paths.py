"""Where the shipped files are: ``prompts/`` and ``data/`` of the checkout, or their copies in an installed wheel.

In a checkout (editable install, ``PYTHONPATH``) they are the top-level ``prompts/`` and ``data/``
beside ``specrefine/``; a built wheel carries the same files as ``specrefine/_shipped/{prompts,data}``
(see ``setup.py``).  The checkout wins when both exist.
"""

from __future__ import annotations

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
