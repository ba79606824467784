"""One refinement run's configuration: :class:`RunConfig`, the one carrier of a run's settings.

The defaults are the best measured settings (``preset="best"``: per agent, ``core.agents.Agent.default_*``);
``preset="paper"`` restores every rule of the paper they depart from (docs/choices.md, "Presets"). The settings a
preset decides (``evaluation``, ``goal_points``, ``policy``, ``split_pick``) default to None, filled in by
:meth:`RunConfig.resolved`.
A sweep cell is a maze and a RunConfig, ``run.json`` is :meth:`RunConfig.record`, and every method's search
settings are ``SearchConfig.from_run(config, **changes)``: a new run setting is a field here and the code that
uses it.

Every field is documented, and the documentation is the command line: :func:`add_run_options` turns the fields
into ``specrefine refine``'s options (flags, defaults, help, bounds), as ``train.Config`` does for training,
and ``python -m specrefine.runs.sweep`` takes its ``-w/-d/-k`` grid axes from the same fields.  ``result.json``
records the configuration a run ran with under ``"config"``.

    from specrefine.runs.config import RunConfig
    from specrefine.runs.pipeline import refine_maze
    refine_maze("u_maze", RunConfig(method="symbolic", k=10), out="runs/k10")

Library defaults elsewhere (``setup``'s rollouts, ``SearchConfig``'s w, d and k, a sweep cell's rollouts and
episodes, ...) read :data:`DEFAULTS`.  At import time this module reads only :mod:`specrefine.core.argtypes` (the
registries behind the choices and help are read when a parser is built), so any layer may import it.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path

from ..core.argtypes import bounded_int
from ..core.paper import PAPER


def option(default, help, *, flags: tuple[str, ...] = (), type: Callable | None = None,
           choices: Callable[[], Iterable[str]] | None = None, shown: str | Callable[[], str] | None = None,
           metavar: str | None = None):
    """A documented field: ``help`` (a string, or a function returning one when the parser is built), the command
    line's ``flags`` (default ``--field-name``), its argparse ``type``, ``choices`` (a function: read when the parser
    is built, so a registry's later entries are in it) and how the default is ``shown`` in the help (a string, or a
    function returning one when the parser is built)."""
    meta = dict(help=help, flags=flags, type=type, choices=choices, shown=shown, metavar=metavar)
    return field(default=default, metadata=meta)


def _per_agent(attr: str) -> str:
    """Each agent's ``Agent.ATTR`` (the best measured setting), as help shows a default: one value where every agent
    has it, else 'X for point, Y for ant'."""
    from ..core.agents import AGENTS

    values = {name: getattr(agent, attr) for name, agent in AGENTS.items()}
    if len(set(values.values())) == 1:
        return next(iter(values.values()))
    return ", ".join(f"{value} for {name}" for name, value in values.items())


def _preset_default(attr: str) -> Callable[[], str]:
    """How help shows a setting the preset decides: the agents' ``default_ATTR`` under best, the paper's under paper."""
    return lambda: f"the preset's: best: {_per_agent(f'default_{attr}')}; paper: {getattr(PAPER, attr)}"


def _agents() -> list[str]:
    from ..core.agents import AGENTS

    return list(AGENTS)


def _methods() -> list[str]:
    from .methods import METHODS

    return list(METHODS)


def _methods_help() -> str:
    from .methods import METHODS

    return "; ".join(f"{name}: {m.description}" for name, m in METHODS.items())


def _proposers_help() -> str:
    from ..proposers.factory import PROPOSERS

    return "who proposes edge splits: " + ", ".join(f"{p.usage} ({p.description})" for p in PROPOSERS.values())


def _evaluations() -> list[str]:
    from ..refine.search import EVALUATIONS

    return list(EVALUATIONS)


def _goal_points() -> tuple[str, ...]:
    from ..evaluation.evaluator import GOAL_POINTS

    return GOAL_POINTS


def _split_picks() -> tuple[str, ...]:
    from ..refine.search import SPLIT_PICKS

    return SPLIT_PICKS


def _switching() -> tuple[str, ...]:
    from ..sim.switching import SWITCHING

    return SWITCHING


def policy_arg(text: str) -> str:
    """'shipped', 'scripted' and a shipped checkpoint's name as they are; a path as ``str(Path(text))`` (the form
    run.json records)."""
    return text if text in ("shipped", "scripted") else str(Path(text))


@dataclass(frozen=True)
class RunConfig:
    """Every argument of one refinement run (the maze and the output folder aside); the defaults are the best
    measured settings, and ``preset="paper"`` the paper's rules."""

    agent: str = option("point", "point: fast point mass, 1 m cells; ant: MuJoCo Ant, 4 m cells", choices=_agents)
    method: str | None = option(None, _methods_help, choices=_methods, metavar="METHOD",
                                shown=_preset_default("method"))
    proposer: str = option("geometric", _proposers_help)
    spec: str | None = option(None, "the task as an expression over the maze's letters: a..z its subgoal regions, G "
                                    "the goal, S implicit; '->' sequence, '|' choice (binds tighter), parentheses; "
                                    "must end in G; e.g. '(a | b) -> c -> G'", metavar="EXPR",
                              shown="the maze's '; spec:' line, else its chain a -> b -> ... -> G")
    seed: int = option(0, "random seed for rollouts and proposers", type=bounded_int("seed"))
    rollouts: int = option(PAPER.rollouts, "rollouts per subtask evaluation", type=bounded_int("rollouts"))
    episodes: int = option(PAPER.episodes, "fresh end-to-end episodes to measure the final policy on the original task",
                           type=bounded_int("episodes"))
    policy: str | None = option(None, "policy checkpoint: a path, 'shipped' (data/policies/AGENT.pt), the name of "
                                      "another shipped one (e.g. ant_stage5: data/policies/ant_stage5.pt) or "
                                      "'scripted' (the point mass's straight-line controller)", type=policy_arg,
                                shown=lambda: f"the agent's adopted policy: {_per_agent('default_policy')}, "
                                                      "under either preset")
    w: int = option(PAPER.w, "candidate edge splits per VLM query (at most 20)", flags=("-w",),
                    type=bounded_int("w"))
    d: int = option(PAPER.d, "VLM query rounds per edge split (at most 10)", flags=("-d",), type=bounded_int("d"))
    k: int = option(PAPER.k, "subsets sampled per vertex refinement (at most 100)", flags=("-k",),
                    type=bounded_int("k"))
    evaluation: str | None = option(None, "fixed: every subtask estimate on --rollouts rollouts (the paper); "
                                          "adaptive: the vertex refinement's candidates in stages, stopping those "
                                          "that cannot be chosen (same full budget for what is chosen; far fewer "
                                          "simulator steps)", choices=_evaluations,
                                    shown=_preset_default("evaluation"))
    goal_points: str | None = option(None,
                                     "where a subtask's policy aims when its goal vertex has no fixed point, in the "
                                     "search, the measurement and the calibration alike: sampled (a point drawn in "
                                     "the goal region per rollout, the paper's rule), centre (the goal region's "
                                     "centre in every rollout; beyond the paper) or clear (the region's point "
                                     "farthest from walls, the nearest such to its centre; beyond the paper)",
                                     choices=_goal_points,
                                     shown=_preset_default("goal_points"))
    switching: str = option("at-region", "when a leg's policy is fed the next goal point, in the search, the "
                                         "measurement, the calibration and the saved policy alike: at-region (on "
                                         "entering the goal region, the paper's rule) or slow-turn (a leg that starts "
                                         "with the torso moving fast and turned away from its goal first brakes; "
                                         "beyond the paper, docs/ant_experiments.md section 6)", choices=_switching)
    split_pick: str | None = option(None, "which of an edge split's candidates the search takes: estimate (the best "
                                          "product of its estimates, whatever round it came from: the paper's "
                                          "Algorithm 1) or confirmed (a later round's pick kept only if it beats the "
                                          "first round's best on the same fresh rollouts; beyond the paper, "
                                          "docs/ant_experiments.md 'lever 5')", choices=_split_picks,
                                    shown=_preset_default("split_pick"))
    preset: str = option("best", "what the settings left unset default to: best (the best measured settings, per "
                                 "agent) or paper (every rule of the paper they depart from: docs/choices.md, "
                                 "'Presets')", choices=lambda: PRESETS)

    def resolved(self) -> RunConfig:
        """This configuration with what its preset decides filled in (``method``, ``evaluation``, ``goal_points``,
        ``policy``, ``split_pick``):
        the agent's ``default_*`` under ``best``, the paper's rules under ``paper`` (the policy is the agent's
        adopted one under either: the paper does not fix how its policy is trained)."""
        from ..core.agents import get_agent
        from ..core.errors import SpecrefineError

        if self.preset not in PRESETS:
            raise SpecrefineError(f"preset {self.preset!r}: use one of {', '.join(PRESETS)}")
        agent = get_agent(self.agent)
        best = self.preset == "best"
        return replace(self, method=self.method or (agent.default_method if best else PAPER.method),
                       evaluation=self.evaluation or (agent.default_evaluation if best else PAPER.evaluation),
                       goal_points=self.goal_points or (agent.default_goal_points if best else PAPER.goal_points),
                       policy=self.policy or agent.default_policy,
                       split_pick=self.split_pick or (agent.default_split_pick if best else PAPER.split_pick))

    def to_dict(self) -> dict:
        return asdict(self)

    def record(self) -> dict:
        """What ``run.json`` records of this (resolved) configuration: a rerun into the folder with another record is
        refused. Derived from the fields, with five rules that keep older folders' records valid: no proposer (nor
        split pick) for a method that asks none, ``evaluation`` only when not fixed, ``goal_points`` only when not
        sampled, ``switching`` only when not at-region, ``split_pick`` only when not the paper's; the preset is not
        recorded (what it decided is)."""
        from .methods import get_method

        data = {k: v for k, v in self.to_dict().items() if k != "preset"}
        if not get_method(self.method).asks_proposer:  # nor does it split an edge
            data["proposer"] = None
            data["split_pick"] = None
        if data["evaluation"] == PAPER.evaluation:
            del data["evaluation"]
        if data["goal_points"] == PAPER.goal_points:
            del data["goal_points"]
        if data["switching"] == "at-region":
            del data["switching"]
        if data["split_pick"] in (None, PAPER.split_pick):  # None: an unresolved configuration
            del data["split_pick"]
        return data

    @classmethod
    def from_namespace(cls, args: argparse.Namespace) -> RunConfig:
        """The configuration of parsed options (those :func:`add_run_options` added)."""
        return cls(**{f.name: getattr(args, f.name) for f in fields(cls) if hasattr(args, f.name)})


PRESETS = ("best", "paper")
DEFAULTS = RunConfig()  # the defaults (w, d, k, rollouts, episodes: the paper's): read them here, not written again
#: the settings a preset decides where they are left unset (the policy is the agent's adopted one under either)
PRESET_DECIDED = ("method", "evaluation", "goal_points", "split_pick")


def preset_text(result: dict) -> str:
    """A run's preset as its summary names it, from its result.json's resolved ``config``: the preset alone where
    every setting it decides is its own; else the settings given in its place, and the other preset where they are
    that one's (a run given each of the paper's rules under ``best`` is the paper's: "best with method=ours, ...
    (the paper preset's settings)"). A result from before its config was recorded: its ``preset`` as it is."""
    config = result.get("config") or {}
    preset, agent = config.get("preset", result.get("preset")), config.get("agent")
    if preset not in PRESETS or agent is None:
        return str(preset or "?")

    def decided(name: str) -> dict:
        resolved = RunConfig(agent=agent, preset=name).resolved()
        return {k: getattr(resolved, k) for k in PRESET_DECIDED}

    given = {k: config.get(k) for k, v in decided(preset).items() if config.get(k) != v}
    if not given:
        return preset
    same = [p for p in PRESETS if p != preset and all(config.get(k) == v for k, v in decided(p).items())]
    return (f"{preset} with {', '.join(f'{k}={v}' for k, v in given.items())}"
            + (f" (the {same[0]} preset's settings)" if same else ""))


def add_run_options(parser, names: Iterable[str] | None = None, *, types: dict[str, Callable] | None = None,
                    many: Iterable[str] = (), suffix: str = "") -> None:
    """One option per :class:`RunConfig` field (or per field in ``names``), with its flags, default, help and bounds.

    ``types``: argparse types that replace a field's own (the CLI checks proposer strings itself); ``many``: fields
    that take several values (``nargs="+"``, default a one-element list: a sweep's grid axes); ``suffix``: appended
    to every help text.
    """
    types, many = types or {}, set(many)
    chosen = {f.name: f for f in fields(RunConfig)}
    for name in names if names is not None else chosen:
        f = chosen[name]
        meta = f.metadata
        text = meta["help"]() if callable(meta["help"]) else meta["help"]
        shown = meta["shown"] if meta["shown"] is not None else f.default
        shown = shown() if callable(shown) else shown
        help_text = f"{text}{suffix} (default: {shown})".replace("%", "%%")  # a per cent sign, not argparse's format
        kwargs = dict(default=[f.default] if name in many else f.default, help=help_text)
        if name in many:
            kwargs["nargs"] = "+"
        argtype = types.get(name, meta["type"])
        if argtype is not None:
            kwargs["type"] = argtype
        if meta["choices"] is not None:
            kwargs["choices"] = list(meta["choices"]())
        if meta["metavar"] is not None:
            kwargs["metavar"] = meta["metavar"]
        parser.add_argument(*(meta["flags"] or ("--" + name.replace("_", "-"),)), dest=name, **kwargs)


# --- argument checks that need the registries (argtypes holds those that need nothing) -----------------
def proposer_arg(text: str) -> str:
    """An argparse type: any proposer the library accepts (its one parser, ``proposers.factory.parse_proposer``)."""
    from ..core.errors import SpecrefineError
    from ..proposers.factory import parse_proposer

    try:
        parse_proposer(text)
    except SpecrefineError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def maze_problem(mazes) -> str | None:
    """The first maze argument (a name, a file, or ``MAZE=SPEC``) that does not load, as one line (None: all do)."""
    from ..core.errors import SpecrefineError
    from ..core.mazes import load_maze
    from ..core.spec import maze_task

    for arg in mazes:
        maze, _, spec = str(arg).partition("=")
        try:
            maze_task(load_maze(maze), spec.strip() or None)
        except SpecrefineError as exc:
            return str(exc)
    return None
