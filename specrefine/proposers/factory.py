"""``make_proposer(spec)``: the one place that turns a ``--proposer`` string into a proposer.

* ``litellm:MODEL`` — any model LiteLLM speaks (keys from the environment only); every call is
  recorded to ``data/vlm/`` (or ``record_path``);
* ``replay:PATH`` — answers from such a recording, deterministically;
* ``geometric`` — an OFFLINE STAND-IN, not a VLM (shortest free-space path waypoints);
  ``geometric:max_waypoints=N`` raises its cap of 32 waypoints per split (when a route needs more, it
  lengthens its legs instead, beyond the agent's reach);
* ``random`` — random free-space waypoints (an ablation; also not a VLM);
* ``imperfect:PRESET`` / ``imperfect:key=value,...`` — a VLM-like error model, offline (NOT a VLM).

A new proposer is one more branch here.
"""

from __future__ import annotations

import logging
from pathlib import Path

from ..errors import SpecrefineError
from ..vlm import LiteLLMClient, ReplayClient
from .base import Proposer
from .geometric import GeometricProposer, RandomProposer
from .imperfect import ImperfectProposer, parse_imperfect
from .vlm import VLMProposer

log = logging.getLogger(__name__)


def parse_proposer(spec: str) -> tuple[str, object]:
    """``(kind, option)`` of a ``--proposer`` string, or a one-line :class:`SpecrefineError`: the one parser the
    command lines validate with (before anything runs) and :func:`make_proposer` builds from.  Options: the
    waypoint cap (geometric), the error model (imperfect), the path (replay) or the model (litellm)."""
    kind, _, rest = str(spec).partition(":")
    if kind == "geometric":
        return kind, _max_waypoints(rest)
    if kind == "random" and not rest:
        return kind, None
    if kind == "imperfect" and rest:
        return kind, parse_imperfect(rest)
    if kind in ("replay", "litellm") and rest:
        return kind, rest
    raise SpecrefineError(f"invalid proposer {spec!r}: use geometric, geometric:max_waypoints=N, random, "
                          "imperfect:PRESET, replay:PATH or litellm:MODEL")


def make_proposer(spec: str, *, seed: int = 0, record_path: str | Path | None = None, **client_kw) -> Proposer:
    """``geometric`` | ``random`` | ``replay:PATH`` | ``litellm:MODEL`` (extra keywords go to LiteLLMClient)."""
    kind, option = parse_proposer(spec)
    if kind == "geometric":
        proposer: Proposer = GeometricProposer(seed=seed, max_waypoints=option)
        proposer.spec = spec
    elif kind == "random":
        proposer = RandomProposer(seed=seed)
    elif kind == "replay":
        proposer = VLMProposer(ReplayClient(option), spec=spec)
    elif kind == "imperfect":
        proposer = ImperfectProposer(option, spec=spec, seed=seed)
    else:
        proposer = VLMProposer(LiteLLMClient(option, record_path=record_path, **client_kw), spec=spec)
    log.info("proposer: %s", proposer.name)
    return proposer


def _max_waypoints(options: str) -> int:
    """``''`` -> 32; ``'max_waypoints=N'`` -> N (a positive integer); anything else is a one-line error."""
    if not options:
        return 32
    key, eq, value = (t.strip() for t in options.partition("="))
    if key != "max_waypoints" or not eq or not value.isdigit() or int(value) < 1:
        raise SpecrefineError(f"invalid proposer 'geometric:{options}': the one option is max_waypoints=N "
                              "(a positive integer)")
    return int(value)
