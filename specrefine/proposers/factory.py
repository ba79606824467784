"""``make_proposer(spec)``: the one place that turns a ``--proposer`` string into a proposer.

* ``litellm:MODEL`` — any model LiteLLM speaks (keys from the environment only); every call is
  recorded to ``data/vlm/`` (or ``record_path``);
* ``replay:PATH`` — answers from such a recording, deterministically;
* ``geometric`` — an OFFLINE STAND-IN, not a VLM (shortest free-space path waypoints);
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


def make_proposer(spec: str, *, seed: int = 0, record_path: str | Path | None = None, **client_kw) -> Proposer:
    """``geometric`` | ``random`` | ``replay:PATH`` | ``litellm:MODEL`` (extra keywords go to LiteLLMClient)."""
    kind, _, rest = str(spec).partition(":")
    if kind == "geometric" and not rest:
        proposer: Proposer = GeometricProposer(seed=seed)
    elif kind == "random" and not rest:
        proposer = RandomProposer(seed=seed)
    elif kind == "replay" and rest:
        proposer = VLMProposer(ReplayClient(rest), spec=spec)
    elif kind == "imperfect" and rest:
        proposer = ImperfectProposer(parse_imperfect(rest), spec=spec, seed=seed)
    elif kind == "litellm" and rest:
        proposer = VLMProposer(LiteLLMClient(rest, record_path=record_path, **client_kw), spec=spec)
    else:
        raise SpecrefineError(f"invalid proposer {spec!r}: use geometric, random, imperfect:PRESET, replay:PATH "
                              "or litellm:MODEL")
    log.info("proposer: %s", proposer.name)
    return proposer
