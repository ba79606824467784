"""Where the shipped files are: ``prompts/`` and ``data/`` of the checkout, or their copies in an installed wheel.

In a checkout (editable install, ``PYTHONPATH``) they are the top-level ``prompts/`` and ``data/``
beside ``specrefine/``; a built wheel carries the same files as ``specrefine/_shipped/{prompts,data}``
(see ``setup.py``).  The checkout wins when both exist.
"""

from __future__ import annotations

from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent
_CHECKOUT = _PACKAGE.parent
_SHIPPED = _PACKAGE / "_shipped"


def _find(name: str) -> Path:
    here = _CHECKOUT / name
    return here if here.is_dir() or not (_SHIPPED / name).is_dir() else _SHIPPED / name


def prompt_dir() -> Path:
    return _find("prompts")


def data_dir() -> Path:
    return _find("data")
