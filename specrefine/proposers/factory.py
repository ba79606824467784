"""``make_proposer(spec)``: the one place that turns a ``--proposer`` string into a proposer, through one registry.

A proposer string is ``KIND`` or ``KIND:OPTIONS``; :data:`PROPOSERS` maps each kind to its entry:

* ``litellm:MODEL`` — any model LiteLLM speaks (keys from the environment only); every call is
  recorded to ``data/vlm/`` (or ``record_path``);
* ``replay:PATH`` — answers from such a recording, deterministically;
* ``geometric`` — an OFFLINE STAND-IN, not a VLM (shortest free-space path waypoints);
  ``geometric:max_waypoints=N`` raises its cap of 32 waypoints per split (when a route needs more, it
  lengthens its legs instead, beyond the agent's reach);
* ``random`` — random free-space waypoints (an ablation; also not a VLM);
* ``imperfect:PRESET`` / ``imperfect:key=value,...`` — a VLM-like error model, offline (NOT a VLM).

A new proposer is its module and one :func:`register_proposer` call: ``parse`` checks the options (the text
after ``KIND:``) without side effects and returns what ``build`` needs; ``build(options, spec=..., seed=...,
record_path=..., **client_kw)`` returns the :class:`Proposer`.  :func:`parse_proposer` checks a whole string.
What every proposer promises (it counts its queries, it carries the string that named it) is kept by the
:class:`Proposer` base class and by :func:`make_proposer`, not by each builder. A registration is checked when it
is made: a safe name, a built-in not replaced unless ``replace=True``, functions for ``build`` and ``parse``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..core.errors import SpecrefineError
from ..core.names import check_callable, check_registration
from ..vlm import LiteLLMClient, ReplayClient
from .base import Proposer
from .geometric import GeometricProposer, RandomProposer
from .imperfect import ImperfectProposer, parse_imperfect
from .vlm import VLMProposer

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ProposerKind:
    name: str  # the KIND before the colon
    build: Callable[..., Proposer]  # (options, *, spec, seed, record_path, **client_kw) -> Proposer
    parse: Callable[[str], object]  # options text -> options (SpecrefineError if bad; no side effects)
    usage: str  # how it is written, for help and messages (e.g. "replay:PATH")
    description: str  # what it is, for --help


PROPOSERS: dict[str, ProposerKind] = {}
BUILT_IN: frozenset[str] = frozenset()  # set below, once the package's own proposers are registered


def register_proposer(name: str, build: Callable[..., Proposer], parse: Callable[[str], object], *,
                      usage: str | None = None, description: str = "", replace: bool = False) -> ProposerKind:
    """Make ``NAME`` / ``NAME:OPTIONS`` a proposer string everywhere (``make_proposer``, the sweep, notebooks). A
    built-in kind is replaced only with ``replace=True``; a bad name, build or parse is a one-line SpecrefineError."""
    check_registration("proposer", name, PROPOSERS, BUILT_IN, replace)
    check_callable("proposer", name, "build", build)
    check_callable("proposer", name, "parse", parse)
    kind = ProposerKind(name, build, parse, usage or name, str(description))
    PROPOSERS[name] = kind
    return kind


def usage_text() -> str:
    """'a, b, c or d': every registered proposer as it is written."""
    usages = [p.usage.replace(" or ", ", ") for p in PROPOSERS.values()]
    return ", ".join(usages[:-1]) + f" or {usages[-1]}" if len(usages) > 1 else "".join(usages)


def parse_proposer(spec: str) -> tuple[ProposerKind, object]:
    """``(kind, options)`` of a proposer string; SpecrefineError (one line) if it names no registered proposer or its
    options are bad."""
    name, _, rest = str(spec).partition(":")
    kind = PROPOSERS.get(name)
    if kind is None:
        raise SpecrefineError(f"invalid proposer {spec!r}: use {usage_text()}")
    return kind, kind.parse(rest)


def make_proposer(spec: str, *, seed: int = 0, record_path: str | Path | None = None, **client_kw) -> Proposer:
    """The proposer a ``--proposer`` string names (extra keywords go to LiteLLMClient); its ``spec`` is that string."""
    kind, options = parse_proposer(spec)
    proposer = kind.build(options, spec=spec, seed=seed, record_path=record_path, **client_kw)
    if not isinstance(proposer, Proposer):
        raise SpecrefineError(f"proposer {kind.name!r}: its build returned {type(proposer).__name__}, not a Proposer")
    proposer.spec = spec  # what result.json and a sweep's rows name it by
    log.info("proposer: %s", proposer.name)
    return proposer


def _no_options(name: str):
    def parse(options: str) -> None:
        if options:
            raise SpecrefineError(f"invalid proposer {name + ':' + options!r}: use {usage_text()}")

    return parse


def _needs(name: str, what: str):
    def parse(options: str) -> str:
        if not options:
            raise SpecrefineError(f"invalid proposer {name!r}: use {usage_text()} ({name} needs its {what})")
        return options

    return parse


def _max_waypoints(options: str) -> int:
    """``''`` -> 32; ``'max_waypoints=N'`` -> N (a positive integer); anything else is a one-line error."""
    if not options:
        return 32
    key, eq, value = (t.strip() for t in options.partition("="))
    if key != "max_waypoints" or not eq or not value.isdigit() or int(value) < 1:
        raise SpecrefineError(f"invalid proposer 'geometric:{options}': the one option is max_waypoints=N "
                              "(a positive integer)")
    return int(value)


def _geometric(max_waypoints, *, spec, seed, **_):
    proposer = GeometricProposer(seed=seed, max_waypoints=max_waypoints)
    proposer.spec = spec
    return proposer


def _random(_, *, seed, **__):
    return RandomProposer(seed=seed)


def _imperfect(config, *, spec, seed, **_):
    return ImperfectProposer(config, spec=spec, seed=seed)


def _replay(path, *, spec, **_):
    return VLMProposer(ReplayClient(path), spec=spec)


def _litellm(model, *, spec, record_path, seed=0, **client_kw):
    return VLMProposer(LiteLLMClient(model, record_path=record_path, **client_kw), spec=spec)


register_proposer("geometric", _geometric, _max_waypoints, usage="geometric or geometric:max_waypoints=N",
                  description="offline shortest-path waypoints, NOT a VLM; at most N waypoints per split, 32 "
                              "unless given")
register_proposer("random", _random, _no_options("random"), description="random free-space waypoints, ablation")
register_proposer("imperfect", _imperfect, parse_imperfect, usage="imperfect:PRESET",
                  description="or imperfect:key=value,...: a VLM-like error model, offline, NOT a VLM; presets "
                              "mild, moderate, severe")
register_proposer("replay", _replay, _needs("replay", "recording's path"), usage="replay:PATH",
                  description="recorded VLM replies")
register_proposer("litellm", _litellm, _needs("litellm", "model"), usage="litellm:MODEL",
                  description="any LiteLLM model, e.g. litellm:gpt-4o, litellm:gemini/gemini-2.0-flash; keys from "
                              "the environment")

BUILT_IN = frozenset(PROPOSERS)  # registered by the package itself: replaced only with replace=True
