"""A SpectRL-style specification language that compiles to a task graph.

Four combinators, as small as SpectRL's ``ev``/``seq``/``choose``/``alw``:

>>> from specrefine.core.regions import Box
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


# --- spec expressions over a maze's letters ------------------------------------------------------
class SpecSyntaxError(SpecError):
    """A bad spec expression: ``column`` (1-based) and ``reason``; the message names both."""

    def __init__(self, expr: str, column: int, reason: str):
        self.expr, self.column, self.reason = expr, column, reason
        super().__init__(f"bad spec {expr!r}: column {column}: {reason}")


def _tokens(expr: str):
    """(kind, text, column) for every token; kinds: '->', '|', '(', ')', 'letter'."""
    i = 0
    while i < len(expr):
        ch = expr[i]
        if ch.isspace():
            i += 1
        elif expr.startswith("->", i):
            yield "->", "->", i + 1
            i += 2
        elif ch in "|()":
            yield ch, ch, i + 1
            i += 1
        elif ch.isalpha() and ch.isascii():
            yield "letter", ch, i + 1
            i += 1
        else:
            raise SpecSyntaxError(expr, i + 1, f"unexpected character {ch!r} (use letters, G, '->', '|' and "
                                               "parentheses)")
    yield "end", "", len(expr) + 1


def parse_spec(expr: str, maze) -> Spec:
    """Parse a spec expression over ``maze``'s letters into a :class:`Spec` (avoiding its obstacles).

    Grammar (``|`` binds tighter than ``->``; whitespace is ignored)::

        expr   := choice ('->' choice)*
        choice := step ('|' step)*
        step   := LETTER | '(' expr ')'

    A LETTER is one of the maze's subgoal letters ``a``..``z`` or ``G`` (the goal); the start ``S``
    is implicit.  Every way through the expression must end in ``G``: the maze's task is to reach
    its goal, and success is measured on the task graph the spec compiles to.  Errors raise
    :class:`SpecSyntaxError` (a :class:`~specrefine.core.errors.SpecError`) naming the 1-based column.
    """
    expr = str(expr)
    if not expr.strip():
        raise SpecSyntaxError(expr, 1, "empty specification (e.g. '(a | b) -> G')")
    toks = list(_tokens(expr))
    _check_nesting(expr, toks)
    pos = 0
    letters = sorted(maze.subgoals)
    have = f"the maze has {', '.join(letters)} and G" if letters else "the maze has only G"

    def peek():
        return toks[pos]

    def take():
        nonlocal pos
        pos += 1
        return toks[pos - 1]

    def step():
        kind, text, col = take()
        if kind == "letter":
            if text == "S":
                raise SpecSyntaxError(expr, col, "'S' is implicit (every spec starts at the start region)")
            if text != "G" and text not in maze.subgoals:
                raise SpecSyntaxError(expr, col, f"no region {text!r} in maze {maze.name!r} ({have})")
            return ("reach", text, col)
        if kind == "(":
            if peek()[0] == ")":
                raise SpecSyntaxError(expr, col, "empty parentheses '()'")
            inner = sequence()
            if peek()[0] != ")":
                raise SpecSyntaxError(expr, col, "unbalanced parenthesis: this '(' is never closed")
            take()
            return inner
        if kind in ("->", "|"):
            raise SpecSyntaxError(expr, col, f"{text!r} needs a step before it")
        if kind == ")":
            raise SpecSyntaxError(expr, col, "a step is missing before ')'")
        raise SpecSyntaxError(expr, col, "the expression ends where a step is missing")

    def operand(op, op_col):
        kind, _, col = peek()
        if kind in ("end", ")", "->", "|"):
            raise SpecSyntaxError(expr, op_col, f"dangling {op!r}: a step must follow it")
        return step()

    def choice():
        options = [step()]
        while peek()[0] == "|":
            _, _, col = take()
            options.append(operand("|", col))
        return options[0] if len(options) == 1 else ("choice", options)

    def sequence():
        parts = [choice()]
        while peek()[0] == "->":
            _, _, col = take()
            if peek()[0] in ("end", ")", "->", "|"):
                raise SpecSyntaxError(expr, col, "dangling '->': a step must follow it")
            parts.append(choice())
        return parts[0] if len(parts) == 1 else ("seq", parts)

    tree = sequence()
    kind, text, col = peek()
    if kind == ")":
        raise SpecSyntaxError(expr, col, "unbalanced parenthesis: ')' without a matching '('")
    if kind != "end":
        raise SpecSyntaxError(expr, col, f"expected '->' or '|' before {text!r}")
    for letter, col in _last_steps(tree):
        if letter != "G":
            raise SpecSyntaxError(expr, col, f"the spec must end in G (the goal), but a way through it ends at "
                                             f"{letter!r}: add '-> G'")
    return avoiding(_to_spec(tree, maze), maze.obstacles)


MAX_NESTING = 100  #: parentheses inside parentheses (the recursive parser and compiler stay far from Python's limit)


def _check_nesting(expr: str, toks) -> None:
    depth = 0
    for kind, _, col in toks:
        depth += (kind == "(") - (kind == ")")
        if depth > MAX_NESTING:
            raise SpecSyntaxError(expr, col, f"parentheses nested more than {MAX_NESTING} deep")


def _last_steps(tree):
    if tree[0] == "reach":
        return [(tree[1], tree[2])]
    if tree[0] == "seq":
        return _last_steps(tree[1][-1])
    return [x for option in tree[1] for x in _last_steps(option)]


def _to_spec(tree, maze) -> Spec:
    if tree[0] == "reach":
        letter = tree[1]
        return reach(maze.goal if letter == "G" else maze.subgoals[letter], letter)
    parts = [_to_spec(t, maze) for t in tree[1]]
    return seq(*parts) if tree[0] == "seq" else choose(*parts)


def chain_text(maze) -> str:
    """The maze's chain as a spec expression: ``a -> b -> ... -> G`` (``G`` without subgoals)."""
    return " -> ".join([*maze.subgoals, "G"])


def maze_spec_text(maze, spec: str | None = None) -> str:
    """The task's expression: ``spec`` if given, else the maze's ``; spec:`` line, else its chain."""
    if spec is not None:
        return spec
    return maze.spec if getattr(maze, "spec", None) is not None else chain_text(maze)


def maze_spec(maze, spec: str | None = None) -> Spec:
    """The maze's task, avoiding walls and hazards: ``spec`` (an expression, see :func:`parse_spec`) if
    given, else the maze's own default (its ``; spec:`` line, else subgoals a, b, ... in order, then G)."""
    if spec is None and getattr(maze, "spec", None) is None:
        steps = [reach(region, letter) for letter, region in maze.subgoals.items()]
        return avoiding(seq(*steps, reach(maze.goal, "G")), maze.obstacles)
    return parse_spec(maze_spec_text(maze, spec), maze)


def maze_task(maze, spec: str | None = None) -> TaskGraph:
    """The initial task graph of a maze: S -> a -> b -> ... -> G, or the graph of ``spec`` / its ``; spec:`` line."""
    return compile_spec(maze.start, maze_spec(maze, spec), initial="S")
