"""specrefine.core.spec and specrefine.core.graph: compilation, maze tasks, JSON round trip, check_refines."""

import json

import pytest

from specrefine.core.errors import InvalidRefinement, SpecError, SpecrefineError
from specrefine.core.graph import TaskGraph, Violation, assert_refines, check_refines, path_graph
from specrefine.core.mazes import load_maze
from specrefine.core.regions import Box, Disc, Union, is_subset
from specrefine.core.spec import avoiding, choose, compile_spec, maze_spec, maze_task, reach, seq

START = Box(-1, -1, 0, 0)
A, B, C, D = Box(0, 0, 1, 1), Box(2, 0, 3, 1), Box(0, 2, 1, 3), Box(4, 4, 5, 5)
WALL, POOL = Box(5, 5, 6, 6), Disc(8, 8, 1)

# --- compilation -----------------------------------------------------------------


def _avoid_boxes(graph, u, v):
    return set(graph.avoid(u, v).parts())


def test_reach_compiles_to_one_edge():
    g = compile_spec(START, avoiding(reach(A, "a"), WALL))
    assert g.initial == "v0" and g.vertices() == ["v0", "a"]
    assert g.edges() == [("v0", "a")] and g.finals == {"a"}
    assert g.region("v0") == START and g.region("a") == A
    assert g.avoid("v0", "a") == WALL


def test_seq_compiles_to_a_path():
    g = compile_spec(START, avoiding(seq(reach(A, "a"), reach(B, "b"), reach(C, "c")), WALL))
    assert g.edges() == [("v0", "a"), ("a", "b"), ("b", "c")]
    assert g.finals == {"c"}


def test_choose_branches_and_joins():
    spec = seq(reach(A, "a"), choose(reach(B, "b"), reach(C, "c")), reach(D, "d"))
    g = compile_spec(START, avoiding(spec, WALL))
    assert set(g.vertices()) == {"v0", "a", "b", "c", "d"}
    assert set(g.edges()) == {("v0", "a"), ("a", "b"), ("a", "c"), ("b", "d"), ("c", "d")}
    assert g.finals == {"d"}


def test_choose_at_the_end_gives_several_finals():
    g = compile_spec(START, avoiding(choose(reach(A, "a"), seq(reach(B, "b"), reach(C, "c"))), WALL))
    assert set(g.edges()) == {("v0", "a"), ("v0", "b"), ("b", "c")}
    assert g.finals == {"a", "c"}


def test_avoiding_accumulates_inward_only():
    spec = avoiding(seq(reach(A, "a"), avoiding(reach(B, "b"), POOL), reach(C, "c")), WALL)
    g = compile_spec(START, spec)
    assert _avoid_boxes(g, "v0", "a") == {WALL}
    assert _avoid_boxes(g, "a", "b") == {WALL, POOL}
    assert _avoid_boxes(g, "b", "c") == {WALL}


def test_compile_level_avoid_applies_everywhere():
    g = compile_spec(START, seq(reach(A, "a"), avoiding(reach(B, "b"), POOL)), avoid=WALL)
    assert _avoid_boxes(g, "v0", "a") == {WALL}
    assert _avoid_boxes(g, "a", "b") == {WALL, POOL}


def test_unnamed_and_clashing_reaches_get_fresh_names():
    g = compile_spec(START, avoiding(seq(reach(A), reach(B, "b"), reach(C, "b")), WALL))
    assert len(g.vertices()) == 4 and len(set(g.vertices())) == 4
    assert g.region("b") == B
    (last,) = g.finals
    assert last != "b" and g.region(last) == C and g.g.nodes[last]["label"] == "b"


def test_single_part_combinators_collapse():
    assert seq(reach(A)) == reach(A)
    assert choose(reach(A)) == reach(A)


@pytest.mark.parametrize(
    "make, words",
    [
        (lambda: reach("not a region"), "reach() needs a Region"),
        (lambda: reach((0, 0, 1, 1)), "reach() needs a Region"),
        (lambda: seq(), "seq() needs at least one"),
        (lambda: choose(), "choose() needs at least one"),
        (lambda: seq(reach(A), A), "seq() takes specifications"),
        (lambda: choose(reach(A), "b"), "choose() takes specifications"),
        (lambda: avoiding(reach(A), "walls"), "avoiding() needs a Region"),
        (lambda: avoiding(A, WALL), "avoiding() takes specifications"),
        (lambda: compile_spec(START, reach(A)), "every reach must avoid something"),
        (lambda: compile_spec(START, "reach A", avoid=WALL), "not a specification"),
        (lambda: compile_spec("start", reach(A), avoid=WALL), "start Region"),
        (lambda: compile_spec(START, reach(A), avoid=[WALL]), "avoid to be a Region"),
    ],
)
def test_bad_combinator_arguments_are_spec_errors(make, words):
    with pytest.raises(SpecError) as exc:
        make()
    msg = str(exc.value)
    assert words in msg
    assert "\n" not in msg and isinstance(exc.value, SpecrefineError)


# --- maze tasks ------------------------------------------------------------------


def test_maze_task_without_subgoals_is_one_edge():
    maze = load_maze("u_maze")
    g = maze_task(maze)
    assert g.initial == "S" and g.vertices() == ["S", "G"]
    assert g.edges() == [("S", "G")] and g.finals == {"G"}
    assert g.region("S") == maze.start and g.region("G") == maze.goal
    assert g.avoid("S", "G") == maze.walls
    assert check_refines(g, g) == []


@pytest.mark.parametrize("rooms", [2, 3, 5])
def test_maze_task_with_subgoals_is_a_path_in_letter_order(rooms):
    maze = load_maze(f"u_chain_{rooms}_subgoals").for_agent("ant")
    g = maze_task(maze)
    letters = list("abcd"[: rooms - 1])
    chain = ["S", *letters, "G"]
    assert g.vertices() == chain
    assert g.edges() == list(zip(chain, chain[1:], strict=False))
    assert g.finals == {"G"}
    for letter in letters:
        assert g.region(letter) == maze.subgoals[letter]
    for u, v in g.edges():
        assert is_subset(maze.walls, g.avoid(u, v)) and is_subset(g.avoid(u, v), maze.walls)


def test_maze_spec_is_an_avoiding_spec_over_the_walls():
    maze = load_maze("u_chain_2_subgoals")
    g = compile_spec(maze.start, maze_spec(maze), initial="S")
    assert g == maze_task(maze)


# --- TaskGraph basics and JSON round trip ----------------------------------------


def _rich_graph() -> TaskGraph:
    walls = Union((Box(-5, -5, 5, -4), Box(-5, 4, 5, 5), Disc(0, 0, 0.5)))
    g = TaskGraph("S")
    g.add_vertex("S", Union((Box(-4, -3, -3, -2), Box(-3, -3, -2, -2))), label="start")
    g.add_vertex("G", Box(3, 2, 4, 3), point=(3.5, 2.5))
    x = g.add_vertex(None, Disc(0, 2, 0.4), point=[0.0, 2.0], refines=None)
    y = g.add_vertex(None, Box(1, 1, 2, 2), refines=None, label="door")
    g.add_vertex("H", Box(3, -3, 4, -2))
    g.add_edge("S", x, walls, parent=("S", "G"))
    g.add_edge(x, y, Union((walls, Box(0, 0, 1, 1))), parent=["S", "G"])
    g.add_edge(y, "G", walls, parent=("S", "G"))
    g.add_edge("S", "H", Box(10, 10, 11, 11))
    g.finals = {"G", "H"}
    return g


def test_json_round_trip_is_lossless():
    g = _rich_graph()
    text = g.to_json()
    back = TaskGraph.from_json(text)
    assert back == g
    assert back.to_json() == text
    assert TaskGraph.from_dict(json.loads(text)) == g
    # regions, points and provenance come back with their types
    for v in g.vertices():
        assert back.region(v) == g.region(v) and type(back.region(v)) is type(g.region(v))
        assert back.g.nodes[v] == g.g.nodes[v]
    for u, v in g.edges():
        assert back.g.edges[u, v] == g.g.edges[u, v]
    assert back.initial == "S" and back.finals == {"G", "H"}
    assert back.goal_point("G").tolist() == [3.5, 2.5] and back.goal_point("S") is None
    assert back.g.nodes["x0"]["refines"] is None and back.g.nodes["G"]["refines"] == "G"
    assert back.g.edges["x0", "x1"]["parent"] == ("S", "G") and back.g.edges["S", "H"]["parent"] == ("S", "H")
    assert back.g.nodes["x1"]["label"] == "door"


def test_round_trip_keeps_checking_and_fresh_names():
    g = _rich_graph()
    back = g.copy()
    assert back == g and back is not g
    assert back.fresh_name() not in g.vertices()
    back.add_vertex(None, Box(0, 0, 1, 1))
    assert back != g and len(back.vertices()) == len(g.vertices()) + 1


def test_graph_rejects_cycles_and_unknown_vertices():
    g = path_graph([A, B, C], WALL)
    assert g.edges() == [("v0", "v1"), ("v1", "v2")] and g.finals == {"v2"}
    with pytest.raises(ValueError, match="cycle"):
        g.add_edge("v2", "v0", WALL)
    assert g.edges() == [("v0", "v1"), ("v1", "v2")]
    with pytest.raises(KeyError):
        g.add_edge("v0", "nope", WALL)
    assert g.successors("v1") == ["v2"] and g.predecessors("v1") == ["v0"]


# --- check_refines -------------------------------------------------------------------

S_REG, G_REG = Box(0, 0, 2, 2), Box(8, 0, 10, 2)
WALLS = Union((Box(4, 0, 5, 3), Box(-1, -1, 11, 0)))


def _original() -> TaskGraph:
    return path_graph([S_REG, G_REG], WALLS, names=["S", "G"])


def _split(points, avoid=WALLS, parent=("S", "G"), g=None):
    """S -> x0 -> x1 -> ... -> G, every new edge implementing `parent`."""
    g = g or TaskGraph("S")
    if "S" not in g.g:
        g.add_vertex("S", S_REG)
        g.add_vertex("G", G_REG)
    chain = ["S"] + [g.add_vertex(None, Box(x, y, x + 0.5, y + 0.5), refines=None) for x, y in points] + ["G"]
    for a, b in zip(chain, chain[1:], strict=False):
        g.add_edge(a, b, avoid, parent=parent)
    g.finals = {"G"}
    return g


def _conditions(problems):
    return [str(p) for p in problems]


def test_identical_graph_refines_itself():
    assert check_refines(_original(), _original()) == []
    assert_refines(_original(), _original())


def test_accepts_vertex_subset():
    g = _original()
    g.g.nodes["G"]["region"] = Box(8.5, 0.5, 9.5, 1.5)
    g.g.nodes["S"]["region"] = Disc(1, 1, 0.5)
    assert check_refines(g, _original()) == []


def test_accepts_renamed_vertex_that_refines_original():
    g = TaskGraph("s1")
    g.add_vertex("s1", Box(0, 0, 1, 1), refines="S")
    g.add_vertex("g1", Box(9, 0, 10, 1), refines="G")
    g.add_edge("s1", "g1", WALLS, parent=("S", "G"))
    g.finals = {"g1"}
    assert check_refines(g, _original()) == []


def test_accepts_edge_split_with_intermediate_vertices():
    g = _split([(4.2, 5)])
    assert len(g.edges()) == 2
    assert check_refines(g, _original()) == []
    assert check_refines(_split([(3, 4), (6, 4), (7, 1)]), _original()) == []


def test_accepts_stricter_avoid_set_on_split_edges():
    stricter = Union((*WALLS.parts(), Disc(6, 6, 1)))
    assert check_refines(_split([(4.2, 5)], avoid=stricter), _original()) == []


def test_accepts_split_of_a_split():
    g = _split([(4.2, 5)])
    # split x0 -> G again: remove it and put x0 -> x1 -> G in its place, same parent
    g.g.remove_edge("x0", "G")
    x1 = g.add_vertex(None, Box(7, 4, 7.5, 4.5), refines=None)
    g.add_edge("x0", x1, WALLS, parent=("S", "G"))
    g.add_edge(x1, "G", WALLS, parent=("S", "G"))
    assert g.edges() == [("S", "x0"), ("x0", "x1"), ("x1", "G")]
    assert check_refines(g, _original()) == []


def test_accepts_split_and_subset_combined_on_a_longer_original():
    original = path_graph([S_REG, Box(4, 4, 6, 6), G_REG], WALLS, names=["S", "M", "G"])
    g = TaskGraph("S")
    g.add_vertex("S", Box(0.5, 0.5, 1.5, 1.5))
    g.add_vertex("M", Box(4.5, 4.5, 5.5, 5.5))  # vertex subset
    g.add_vertex("G", G_REG)
    w = g.add_vertex(None, Disc(2, 4, 0.3), refines=None)
    g.add_edge("S", w, WALLS, parent=("S", "M"))  # edge split of S -> M
    g.add_edge(w, "M", WALLS, parent=("S", "M"))
    g.add_edge("M", "G", WALLS, parent=("M", "G"))
    g.finals = {"G"}
    assert check_refines(g, original) == []
    assert check_refines(TaskGraph.from_json(g.to_json()), original) == []


def test_accepts_keeping_one_branch_of_a_choice():
    original = compile_spec(S_REG, avoiding(choose(reach(A, "a"), reach(B, "b")), WALLS), initial="S")
    g = TaskGraph("S")
    g.add_vertex("S", S_REG)
    g.add_vertex("b", Box(2.2, 0.2, 2.8, 0.8))
    g.add_edge("S", "b", WALLS)
    g.finals = {"b"}
    assert check_refines(g, original) == []


def test_rejects_vertex_that_is_not_a_subset():
    g = _original()
    g.g.nodes["G"]["region"] = Box(8, 0, 10.5, 2)
    (problem,) = check_refines(g, _original())
    assert isinstance(problem, Violation)
    assert problem.where == "vertex G"
    assert "I'(G) is not a subset of I(G)" in problem.condition


def test_rejects_split_that_drops_the_avoid_set():
    g = _split([(4.2, 5)], avoid=Box(4, 0, 5, 3))  # the floor wall is missing
    problems = _conditions(check_refines(g, _original()))
    assert len(problems) == 2
    assert all("does not contain the avoid set of its parent S->G" in p for p in problems)
    assert problems[0].startswith("edge S->x0")


def test_rejects_broken_chain():
    g = _split([(4.2, 5)])
    g.g.remove_edge("x0", "G")  # x0 leads nowhere
    g.add_edge("S", "G", WALLS, parent=("S", "G"))
    problems = _conditions(check_refines(g, _original()))
    assert problems == ["edge S->x0: end x0 neither refines G nor leads on in a split of S->G"]


def test_rejects_chain_that_starts_from_nowhere():
    g = _split([(4.2, 5)])
    g.g.remove_edge("S", "x0")
    problems = _conditions(check_refines(g, _original()))
    assert problems == ["edge x0->G: start x0 neither refines S nor continues a split of S->G"]


def test_rejects_chain_mixing_parents():
    original = compile_spec(S_REG, avoiding(choose(reach(A, "a"), reach(B, "b")), WALLS), initial="S")
    g = TaskGraph("S")
    for v in ("S", "a", "b"):
        g.add_vertex(v, original.region(v))
    x = g.add_vertex(None, C, refines=None)
    g.add_edge("S", x, WALLS, parent=("S", "a"))
    g.add_edge(x, "b", WALLS, parent=("S", "b"))
    g.finals = {"a", "b"}
    problems = _conditions(check_refines(g, original))
    assert "edge S->x0: end x0 neither refines a nor leads on in a split of S->a" in problems
    assert "edge x0->b: start x0 neither refines S nor continues a split of S->b" in problems


def test_rejects_wrong_initial():
    g = _split([(4.2, 5)])
    g.initial = "x0"
    problems = _conditions(check_refines(g, _original()))
    assert problems == ["vertex x0: initial vertex must refine the original initial 'S'"]
    g.initial = "missing"
    assert "initial vertex must refine" in _conditions(check_refines(g, _original()))[0]


def test_rejects_final_that_refines_no_final():
    g = _split([(4.2, 5)])
    g.finals = {"G", "x0"}
    problems = _conditions(check_refines(g, _original()))
    assert problems == ["vertex x0: final vertex must refine an original final vertex"]
    g.finals = {"S"}
    assert _conditions(check_refines(g, _original())) == ["vertex S: final vertex must refine an original final vertex"]


def test_rejects_unknown_parent_edge_and_unknown_original_vertex():
    g = _split([(4.2, 5)], parent=("S", "Q"))
    problems = _conditions(check_refines(g, _original()))
    assert problems == ["edge S->x0: parent edge S->Q is not in the original graph",
                        "edge x0->G: parent edge S->Q is not in the original graph"]
    g = _original()
    g.add_vertex("Z", Box(20, 20, 21, 21))
    assert _conditions(check_refines(g, _original())) == ["vertex Z: refines unknown original vertex 'Z'"]


def test_reversed_edge_parent_is_rejected():
    original = path_graph([S_REG, Box(4, 4, 6, 6), G_REG], WALLS, names=["S", "M", "G"])
    g = original.copy()
    g.g.edges["M", "G"]["parent"] = ("S", "M")
    problems = _conditions(check_refines(g, original))
    assert "edge M->G: start M neither refines S nor continues a split of S->M" in problems
    assert "edge M->G: end G neither refines M nor leads on in a split of S->M" in problems


def test_assert_refines_raises_one_line():
    g = _split([(4.2, 5)], avoid=Box(4, 0, 5, 3))
    with pytest.raises(InvalidRefinement) as exc:
        assert_refines(g, _original())
    msg = str(exc.value)
    assert "\n" not in msg
    assert "does not contain the avoid set" in msg and "(+1 more)" in msg
