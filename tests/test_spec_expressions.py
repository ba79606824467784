"""Spec expressions (``--spec``): the parser, its errors, the compiled graphs, the CLI and the sweep."""

from __future__ import annotations

import csv
import json

import pytest

from specrefine.cli import main
from specrefine.core.errors import MazeError, SpecError, SpecrefineError
from specrefine.core.graph import TaskGraph
from specrefine.core.mazes import load_maze, parse_maze
from specrefine.core.spec import SpecSyntaxError, chain_text, maze_spec_text, maze_task, parse_spec
from specrefine.runs.sweep import COLUMNS, PROVENANCE, Cell, _append, grid, read_table, run_sweep, summarise

# a b c subgoals, one goal; every region reachable
TEXT = """\
#######
#S.a..#
#..b.c#
#....G#
#######
"""
FAST = ["--rollouts", "8", "--episodes", "16"]


@pytest.fixture(scope="module")
def maze():
    return parse_maze(TEXT, "abc.maze")


def edges(graph: TaskGraph) -> set[tuple[str, str]]:
    return set(graph.edges())


# --- grammar ---------------------------------------------------------------------


def test_choice_then_merge_compiles_to_the_diamond(maze):
    g = maze_task(maze, "(a | b) -> c -> G")
    assert g.initial == "S" and sorted(g.vertices()) == ["G", "S", "a", "b", "c"]
    assert edges(g) == {("S", "a"), ("S", "b"), ("a", "c"), ("b", "c"), ("c", "G")}
    assert g.finals == {"G"}
    assert g.region("S") == maze.start and g.region("G") == maze.goal
    for letter in "abc":
        assert g.region(letter) == maze.subgoals[letter]
    assert all(g.avoid(u, v) == maze.obstacles for u, v in g.edges())


def test_choice_binds_tighter_than_sequence(maze):
    assert maze_task(maze, "a | b -> c -> G") == maze_task(maze, "(a | b) -> c -> G")
    assert maze_task(maze, "a -> b | c -> G") == maze_task(maze, "a -> (b | c) -> G")
    assert edges(maze_task(maze, "a -> b | c -> G")) == {("S", "a"), ("a", "b"), ("a", "c"), ("b", "G"),
                                                        ("c", "G")}


def test_parentheses_nest_and_whitespace_is_ignored(maze):
    g = maze_task(maze, "((a->c)|b)->G")
    assert edges(g) == {("S", "a"), ("a", "c"), ("c", "G"), ("S", "b"), ("b", "G")}
    assert maze_task(maze, "  ( ( a -> c ) | b )  ->  G ") == g
    assert maze_task(maze, "(((G)))") == maze_task(maze, "G")
    # a choice of whole routes, each ending in G: each branch has its own goal vertex, both final
    g = maze_task(maze, "(a -> G) | (b -> c -> G)")
    (other,) = g.finals - {"G"}
    assert edges(g) == {("S", "a"), ("a", "G"), ("S", "b"), ("b", "c"), ("c", other)}
    assert g.finals == {"G", other} and g.region(other) == maze.goal


def test_a_letter_may_repeat_and_g_may_appear_midway(maze):
    g = maze_task(maze, "a -> G -> b -> G")
    assert len(g.vertices()) == 5 and len(g.finals) == 1
    (final,) = g.finals
    assert final != "G" and g.region(final) == maze.goal  # the second G is a fresh vertex


def test_default_is_the_chain(maze):
    assert chain_text(maze) == "a -> b -> c -> G" and maze_spec_text(maze) == "a -> b -> c -> G"
    assert maze_task(maze) == maze_task(maze, "a -> b -> c -> G")
    u = load_maze("u_maze")
    assert maze_spec_text(u) == "G" and maze_task(u, "G") == maze_task(u)


ERRORS = {  # expression: (column, words)
    "": (1, "empty"),
    "   ": (1, "empty"),
    "(a | b -> G": (1, "never closed"),
    "a -> (b -> G": (6, "never closed"),
    "a -> G)": (7, "without a matching '('"),
    "a ->": (3, "dangling '->'"),
    "a -> -> G": (3, "dangling '->'"),
    "(a ->) -> G": (4, "dangling '->'"),
    "a | -> G": (3, "dangling '|'"),
    "-> G": (1, "needs a step before it"),
    "| a -> G": (1, "needs a step before it"),
    "a -> d -> G": (6, "no region 'd'"),
    "a -> X -> G": (6, "no region 'X'"),
    "S -> a -> G": (1, "'S' is implicit"),
    "a b -> G": (3, "expected '->' or '|'"),
    "() -> G": (1, "empty parentheses"),
    "a => G": (3, "unexpected character '='"),
    "a - > G": (3, "unexpected character '-'"),
    "a -> b": (6, "must end in G"),
    "(a | b)": (2, "must end in G"),
    "a -> G | b": (10, "must end in G"),
}


@pytest.mark.parametrize("expr", sorted(ERRORS))
def test_bad_expressions_name_the_column(maze, expr):
    column, words = ERRORS[expr]
    with pytest.raises(SpecSyntaxError) as info:
        parse_spec(expr, maze)
    err = info.value
    assert isinstance(err, SpecError) and isinstance(err, SpecrefineError)  # a user error: exit 2
    assert err.column == column and words in err.reason, (err.column, str(err))
    assert f"column {column}:" in str(err) and "\n" not in str(err)


# --- the maze's default spec line ----------------------------------------------------


def test_spec_line_sets_the_default_task():
    m = parse_maze("; spec: (a | b) -> G\n" + TEXT, "choice.maze")
    assert m.spec == "(a | b) -> G" and maze_spec_text(m) == "(a | b) -> G"
    assert maze_task(m) == maze_task(m, "(a | b) -> G")
    assert maze_task(m, "c -> G") != maze_task(m)  # an explicit spec overrides the line
    assert m.for_agent("ant").spec == m.spec
    plain = parse_maze("; a comment that mentions spec: nothing\n" + TEXT, "plain.maze")
    assert plain.spec is None


@pytest.mark.parametrize("line,where,words", [
    ("; spec: (a | q) -> G", "1:14", "no region 'q'"),
    (";spec:a ->", "1:9", "dangling '->'"),
    ("; spec:", "1:8", "empty"),
])
def test_bad_spec_line_is_a_maze_error_at_its_file_line_column(line, where, words):
    with pytest.raises(MazeError, match=rf"^bad\.maze:{where}: '; spec:' line: .*{words}"):
        parse_maze(line + "\n" + TEXT, "bad.maze")


def test_two_spec_lines_are_rejected():
    with pytest.raises(MazeError, match=r"two\.maze:2:1: a second '; spec:' line"):
        parse_maze("; spec: a -> G\n; spec: b -> G\n" + TEXT, "two.maze")


def test_two_doors_ships_a_choice():
    m = load_maze("two_doors")
    assert "|" in m.spec
    g = maze_task(m)
    assert edges(g) == {("S", "a"), ("S", "b"), ("a", "c"), ("b", "c"), ("c", "G")}


# --- command line ----------------------------------------------------------------------


def run_cli(args) -> int:
    try:
        return main(args)
    except SystemExit as exc:
        return exc.code


@pytest.mark.parametrize("expr,column", [("a -> c -> G", 6), ("(a | b -> G", 1), ("a ->", 3), ("", 1),
                                         ("a | b", 1)])
def test_bad_spec_exits_2_with_one_line(tmp_path, capsys, expr, column):
    out = tmp_path / "o"
    code = run_cli(["refine", "u_chain_3_subgoals", "--method", "dirl", "--spec", expr, "--out", str(out), *FAST])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and f"column {column}:" in err and "Traceback" not in err, err
    assert not out.exists()  # rejected before anything is written


def test_refine_with_a_spec_records_it(tmp_path, capsys):
    out = tmp_path / "o"
    code = run_cli(["refine", "two_doors", "--method", "dirl", "--spec", "b -> c -> G", "--out", str(out), *FAST])
    assert code == 0, capsys.readouterr().err
    data = json.loads((out / "result.json").read_text())
    assert data["spec"] == "b -> c -> G"
    original = TaskGraph.from_dict(data["input_graph"])
    assert edges(original) == {("S", "b"), ("b", "c"), ("c", "G")} and data["path"] == ["S", "b", "c", "G"]
    # without --spec: the maze's own '; spec:' line, a choice; DiRL takes one branch of it
    code = run_cli(["refine", "two_doors", "--method", "dirl", "--out", str(tmp_path / "d"), *FAST])
    assert code == 0
    data = json.loads((tmp_path / "d" / "result.json").read_text())
    assert data["spec"] == load_maze("two_doors").spec and len(data["input_graph"]["edges"]) == 5
    assert data["path"][0] == "S" and data["path"][-2:] == ["c", "G"]


# --- sweep -------------------------------------------------------------------------------


def test_cell_ids_carry_the_spec_only_when_given():
    plain = Cell.of("u_maze", "point", "dirl", "none", 0, preset="paper")  # the paper's: no suffix
    assert plain.id == "u_maze__point__dirl__none__s0" and plain.spec == ""
    cells = grid(["two_doors"], ["dirl"], ["geometric"], [0], specs=[None, "(a | b) -> c -> G", "b -> c -> G"],
                 preset="paper")
    ids = [c.id for c in cells]
    assert ids[0] == "two_doors__point__dirl__none__s0"
    assert ids[1] == "two_doors__Pa-or-bQ-then-c-then-G__point__dirl__none__s0"
    assert ids[2] == "two_doors__b-then-c-then-G__point__dirl__none__s0"
    assert all("/" not in i and " " not in i for i in ids)
    per_maze = grid(["two_doors=b -> c -> G", "u_maze"], ["dirl"], ["geometric"], [0], specs=["G"])
    assert [(c.maze, c.spec) for c in per_maze] == [("two_doors", "b -> c -> G"), ("u_maze", "G")]


def test_sweep_rows_have_a_spec_column_and_groups(tmp_path):
    cells = grid(["two_doors"], ["dirl"], ["geometric"], [0], agent="point", rollouts=8, episodes=16,
                 specs=[None, "b -> c -> G"])
    table = run_sweep(cells, tmp_path, workers=1)
    with table.open() as fh:
        assert next(csv.reader(fh)) == COLUMNS and "spec" in COLUMNS
    rows = read_table(table)
    assert [r["status"] for r in rows] == ["ok", "ok"], [r["error"] for r in rows]
    assert sorted(r["spec"] for r in rows) == ["", "b -> c -> G"]
    assert sorted(s["maze"] for s in summarise(rows)) == ["two_doors", "two_doors [b -> c -> G]"]


def test_rows_go_into_an_older_table_in_its_own_columns(tmp_path):
    old = tmp_path / "results.csv"
    with old.open("w", newline="") as fh:
        csv.writer(fh).writerow(COLUMNS[:COLUMNS.index("spec")])  # a table from before the spec column
    _append(old, {"cell": "x", "maze": "u_maze", "status": "ok", "spec": ""})
    with old.open() as fh:
        header, row = list(csv.reader(fh))
    # its own columns, and the provenance columns every row records (policy_fingerprint, commit)
    assert header == COLUMNS[:COLUMNS.index("spec")] + list(PROVENANCE) and row[0] == "x" and len(row) == len(header)
    with pytest.raises(ValueError, match="no 'spec' column"):
        _append(old, {"cell": "y", "maze": "u_maze", "status": "ok", "spec": "G"})


def test_sweep_rejects_a_bad_spec_before_running(tmp_path, capsys):
    from specrefine.runs.sweep import main as sweep_main

    code = sweep_main(["--mazes", "two_doors", "--methods", "dirl", "--seeds", "0", "--specs", "a -> z -> G",
                       "--out", str(tmp_path)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "column 6:" in err and "two_doors" in err
    assert not (tmp_path / "results.csv").exists()
