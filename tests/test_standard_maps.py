"""Gymnasium-Robotics maps as mazes: Maze.from_gymnasium, gr:NAME in Python, the CLI and the sweep."""

from __future__ import annotations

import json

import numpy as np
import pytest

import specrefine
from specrefine.cli import main
from specrefine.core.errors import MazeError
from specrefine.core.mazes import Maze, load_maze
from specrefine.core.standard_maps import D4RL_GOALS, gymnasium_maps
from specrefine.runs.sweep import grid, read_table, run_sweep
from specrefine.runs.sweep import main as sweep_main

FAST = ["--rollouts", "8", "--episodes", "16"]
# start and goal cells (row, col) every shipped map must give (module docstring of specrefine.core.standard_maps)
EXPECTED = {
    "U_MAZE": ((1, 1), (3, 1)), "EMPTY_MAZE": ((1, 1), (3, 1)), "MEDIUM_MAZE": ((1, 1), (6, 6)),
    "LARGE_MAZE": ((1, 1), (7, 9)), "OPEN": ((1, 1), (3, 5)), "OPEN_DIVERSE_G": ((1, 1), (3, 5)),
    "OPEN_DIVERSE_GR": ((1, 1), (3, 5)), "MEDIUM_MAZE_DIVERSE_G": ((1, 1), (6, 5)),
    "MEDIUM_MAZE_DIVERSE_GR": ((1, 1), (6, 5)), "LARGE_MAZE_DIVERSE_G": ((1, 1), (3, 10)),
    "LARGE_MAZE_DIVERSE_GR": ((1, 1), (3, 10)),
}


def test_every_gymnasium_map_resolves_by_name_with_its_start_and_goal():
    maps = gymnasium_maps()
    assert set(maps) == set(EXPECTED)
    for name, (start, goal) in EXPECTED.items():
        maze = load_maze(f"gr:{name}")
        assert maze.name == f"gr:{name}"
        assert maze.cells("S") == [start] and maze.cells("G") == [goal], name
        walls = [[ch == "#" for ch in row] for row in maze.grid]
        assert walls == [[cell == 1 for cell in row] for row in maps[name]]  # walls exactly as the map's


def test_d4rl_maps_take_d4rl_evaluation_goals():
    for name, cell in D4RL_GOALS.items():
        assert load_maze(f"gr:{name}").cells("G") == [cell]


def test_from_gymnasium_follows_r_g_c():
    r, g, c = "r", "g", "c"
    two_resets = Maze.from_gymnasium([[1, 1, 1, 1, 1], [1, r, 0, g, 1], [1, r, 1, 0, 1], [1, 1, 1, 1, 1]])
    assert two_resets.cells("S") == [(1, 1), (2, 1)] and two_resets.cells("G") == [(1, 3)]
    # several goals: the one farthest from the start; c cells: the first is the start
    combined = Maze.from_gymnasium([[1, 1, 1, 1, 1, 1], [1, c, 0, c, 0, c, ], [1, 1, 1, 1, 1, 1]], name="line")
    assert combined.cells("S") == [(1, 1)] and combined.cells("G") == [(1, 5)] and combined.name == "line"
    # no goal candidates but a reset: the farthest free cell, as any free cell may be a goal there
    lone = Maze.from_gymnasium([[1, 1, 1, 1], [1, 0, r, 1], [1, 0, 1, 1], [1, 1, 1, 1]], cell_size=4.0)
    assert lone.cells("S") == [(1, 2)] and lone.cells("G") == [(2, 1)] and lone.cell_size == 4.0


def test_coordinates_match_gymnasium_robotics():
    """cell <-> xy as maze_v4.Maze.cell_rowcol_to_xy / cell_xy_to_rowcol (origin at the centre, y up)."""
    from gymnasium_robotics.envs.maze.maze_v4 import Maze as GRMaze

    maze = load_maze("gr:LARGE_MAZE").for_agent("ant")
    theirs = GRMaze(gymnasium_maps()["LARGE_MAZE"], maze_size_scaling=4.0, maze_height=0.5)
    for cell in [(1, 1), (7, 9), (3, 10), (0, 0)]:
        np.testing.assert_allclose(maze.cell_to_xy(*cell), theirs.cell_rowcol_to_xy(np.array(cell)), atol=1e-12)
        xy = maze.cell_to_xy(*cell) + np.array([1.3, -0.7])
        assert tuple(maze.xy_to_cell(xy)) == tuple(theirs.cell_xy_to_rowcol(xy))


@pytest.mark.parametrize("bad,needle", [
    ([], "non-empty list"),
    ([[1, 1], [1]], "ragged"),
    ([[1, 1, 1], [1, 2, 1], [1, 1, 1]], "unknown cell 2"),
    ([[1, 1, 1], [1, "x", 1], [1, 1, 1]], "unknown cell 'x'"),
    ([[1, 1, 1], [1, True, 1], [1, 1, 1]], "unknown cell True"),
    ([[1, 1, 1], [1, 1, 1]], "no free cell"),
    ([[1, 1, 1, 1, 1], [1, "r", 1, "g", 1], [1, 1, 1, 1, 1]], "no goal cell is reachable"),
    ("U_MAZE", "non-empty list of rows"),
])
def test_malformed_lists_are_one_line_maze_errors(bad, needle):
    with pytest.raises(MazeError) as info:
        Maze.from_gymnasium(bad, name="mine")
    assert needle in str(info.value) and "\n" not in str(info.value)


def test_setup_takes_a_standard_map():
    exp = specrefine.setup("gr:U_MAZE", agent="point", policy="scripted", rollouts=8)
    assert exp.maze.name == "gr:U_MAZE" and exp.maze.cell_size == 1.0
    assert exp.graph.region(exp.graph.initial).contains(exp.maze.cell_to_xy(1, 1)[None])[0]


def test_cli_refines_a_standard_map(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(["refine", "gr:U_MAZE", "--agent", "point", "--method", "dirl", "--seed", "0", "--out", str(out),
                 *FAST])
    assert code == 0, capsys.readouterr().err
    data = json.loads((out / "result.json").read_text())
    assert data["maze"] == "gr:U_MAZE" and data["episodes"] == 16 and 0.0 <= data["success_rate"] <= 1.0
    assert json.loads((out / "run.json").read_text())["maze_grid"] == list(load_maze("gr:U_MAZE").grid)


def test_cli_unknown_standard_map_exits_2_with_one_line(tmp_path, capsys):
    code = main(["refine", "gr:NO_SUCH_MAZE", "--out", str(tmp_path / "o"), *FAST])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "NO_SUCH_MAZE" in err and "U_MAZE" in err
    assert not (tmp_path / "o").exists()


def test_sweep_runs_a_standard_map(tmp_path):
    cells = grid(["gr:U_MAZE"], ["dirl"], ["geometric"], [0], agent="point", rollouts=8, episodes=16, preset="paper")
    assert cells[0].id == "gr-U_MAZE__point__dirl__none__s0"
    (row,) = read_table(run_sweep(cells, tmp_path, workers=1))
    assert row["status"] == "ok" and row["maze"] == "gr:U_MAZE" and row["episodes"] == 16


def test_sweep_unknown_standard_map_exits_2_before_running(tmp_path, capsys):
    code = sweep_main(["--mazes", "gr:NOPE", "--methods", "dirl", "--seeds", "0", "--out", str(tmp_path / "s")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "NOPE" in err
    assert not (tmp_path / "s" / "results.csv").exists()
