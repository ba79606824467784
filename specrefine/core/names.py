"""Names a user registers (methods, proposer kinds): checked once, the same way for every registry.

A name goes into command lines, cell ids and folder names, so it is a letter followed by letters, digits, ``_`` or
``-`` (at most 40 characters). A registry's built-in entries are not replaced unless the caller says ``replace=True``.
"""

from __future__ import annotations

import re
from collections.abc import Container

from .errors import SpecrefineError

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_-]{0,39}")


def check_registration(kind: str, name, taken: Container[str], built_in: Container[str], replace: bool) -> str:
    """``name`` if it may be registered as a ``kind``; else a one-line :class:`SpecrefineError` saying why."""
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise SpecrefineError(f"{kind} name {name!r}: use a letter, then letters, digits, '_' or '-' "
                              "(at most 40 characters), e.g. 'ours-greedy'")
    if name in built_in and name in taken and not replace:
        raise SpecrefineError(f"{kind} {name!r} is built in: choose another name (or pass replace=True to replace "
                              "it everywhere)")
    return name


def check_callable(kind: str, name: str, what: str, value) -> None:
    """A one-line :class:`SpecrefineError` unless ``value`` is callable."""
    if not callable(value):
        raise SpecrefineError(f"{kind} {name!r}: {what} must be a function, got {type(value).__name__} {value!r}")
