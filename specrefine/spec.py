"""A SpectRL-style specification language that compiles to a task graph.

Four combinators, as small as SpectRL's ``ev``/``seq``/``choose``/``alw``:

>>> from specrefine.regions import Box
>>> s = seq(reach(Box(0, 0, 1, 1), "a"), choose(reach(Box(2, 0, 3, 1), "b"), reach(Box(0, 2, 1, 3), "c")))
>>> graph = compile_spec(Box(-1, -1, 0, 0), avoiding(s, Box(5, 5, 6, 6)))

``reach(R)`` eventually reach R; ``seq(a, b, ...)`` do a, then b; ``choose(a, b, ...)`` do
any one of them; ``avoiding(s, R)`` do s while never entering R.
"""

from __future__ import annotations

from dataclasses import dataclass

from .errors import SpecError
from .graph import TaskGraph
from .regions import Region, union


class Spec:
    pass


@dataclass(frozen=True)
class Reach(Spec):
    region: Region
    name: str | None = None


@dataclass(frozen=True)
class Seq(Spec):
    parts: tuple[Spec, ...]


@dataclass(frozen=True)
class Choice(Spec):
    options: tuple[Spec, ...]


@dataclass(frozen=True)
class Avoiding(Spec):
    spec: Spec
    region: Region


def reach(region: Region, name: str | None = None) -> Spec:
    if not isinstance(region, Region):
        raise SpecError(f"reach() needs a Region, got {type(region).__name__}")
    return Reach(region, name)


def seq(*parts: Spec) -> Spec:
    _check_specs("seq", parts)
    return parts[0] if len(parts) == 1 else Seq(tuple(parts))


def choose(*options: Spec) -> Spec:
    _check_specs("choose", options)
    return options[0] if len(options) == 1 else Choice(tuple(options))


def avoiding(spec: Spec, region: Region) -> Spec:
    _check_specs("avoiding", (spec,))
    if not isinstance(region, Region):
        raise SpecError(f"avoiding() needs a Region, got {type(region).__name__}")
    return Avoiding(spec, region)


def _check_specs(name, items):
    if not items:
        raise SpecError(f"{name}() needs at least one specification")
    for s in items:
        if not isinstance(s, Spec):
            raise SpecError(f"{name}() takes specifications, got {type(s).__name__}")


def compile_spec(start: Region, spec: Spec, avoid: Region | None = None, initial: str = "v0") -> TaskGraph:
    """Compile ``spec``, started from ``start``, to a task graph (one vertex per ``reach``)."""
    if not isinstance(start, Region):
        raise SpecError(f"compile_spec() needs a start Region, got {type(start).__name__}")
    if avoid is not None and not isinstance(avoid, Region):
        raise SpecError(f"compile_spec() needs avoid to be a Region or None, got {type(avoid).__name__}")
    tg = TaskGraph(initial)
    tg.add_vertex(initial, start, label="start")
    tg.finals = set(_compile(tg, spec, [initial], [avoid] if avoid is not None else []))
    return tg


def _compile(tg: TaskGraph, spec: Spec, entries: list[str], avoids: list[Region]) -> list[str]:
    if isinstance(spec, Reach):
        if not avoids:
            raise SpecError("every reach must avoid something: wrap the spec in avoiding(..., walls)")
        name = spec.name if spec.name and spec.name not in tg else tg.fresh_name()
        v = tg.add_vertex(name, spec.region, label=spec.name or name)
        for u in entries:
            tg.add_edge(u, v, union(avoids))
        return [v]
    if isinstance(spec, Seq):
        for part in spec.parts:
            entries = _compile(tg, part, entries, avoids)
        return entries
    if isinstance(spec, Choice):
        return [v for option in spec.options for v in _compile(tg, option, entries, avoids)]
    if isinstance(spec, Avoiding):
        return _compile(tg, spec.spec, entries, avoids + [spec.region])
    raise SpecError(f"not a specification: {spec!r}")


def maze_spec(maze) -> Spec:
    """The maze's task: reach subgoals a, b, ... in order, then G, avoiding walls."""
    steps = [reach(region, letter) for letter, region in maze.subgoals.items()]
    return avoiding(seq(*steps, reach(maze.goal, "G")), maze.walls)


def maze_task(maze) -> TaskGraph:
    """The initial task graph of a maze: S -> a -> b -> ... -> G."""
    return compile_spec(maze.start, maze_spec(maze), initial="S")
