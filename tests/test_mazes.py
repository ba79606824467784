"""specrefine.core.mazes: maze files, cell <-> xy, regions, and malformed files through the CLI."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from specrefine import cli
from specrefine.core.errors import MazeError
from specrefine.core.mazes import CELL_SIZE, MAZE_DIR, Maze, benchmark_mazes, load_maze, parse_maze
from specrefine.core.regions import is_subset

BENCHMARK = benchmark_mazes()

# --- the shipped benchmark suite -------------------------------------------------


def test_benchmark_suite_is_complete():
    expected = {"split_doorway", "or_maze", "u_maze", "x_maze", "xx_maze_h", "xx_maze_v"}
    expected |= {f"u_chain_{k}" for k in range(1, 6)} | {f"u_chain_{k}_subgoals" for k in range(2, 6)}
    assert expected <= set(BENCHMARK)
    assert all(p.parent == MAZE_DIR and p.suffix == ".maze" for p in BENCHMARK.values())


def test_off_suite_mazes_load_and_stay_out_of_the_suite():
    unseen = sorted((MAZE_DIR / "unseen").glob("*.maze"))
    assert {p.stem for p in unseen} == {"zigzag", "pillars", "detour_subgoal", "spiral"}
    assert not {p.stem for p in unseen} & set(BENCHMARK)  # benchmark_mazes() does not descend into subfolders
    for p in unseen:
        maze = load_maze(p)
        assert maze.name == p.stem and maze.for_agent("point").cell_size == 1.0


@pytest.mark.parametrize("name", sorted(BENCHMARK))
def test_every_shipped_maze_parses(name):
    maze = load_maze(BENCHMARK[name])
    assert maze.name == name
    assert maze.rows >= 3 and all(len(row) == maze.cols for row in maze.grid)
    assert maze.cells("S") and maze.cells("G")
    # start, goal and subgoal regions are the union of their cells
    for char, region in [("S", maze.start), ("G", maze.goal), *maze.subgoals.items()]:
        cells = maze.cells(char)
        assert region.contains(maze.cell_to_xy(*np.array(cells).T)).all()
        assert region.area == pytest.approx(len(cells) * maze.cell_size**2)
    # walls are exactly the wall cells (plus the frame); free cells are not walls
    wall_cells, free_cells = np.array(maze.cells("#")), np.array(maze.free_cells())
    assert maze.walls.contains(maze.cell_to_xy(*wall_cells.T)).all()
    assert not maze.walls.contains(maze.cell_to_xy(*free_cells.T)).any()
    assert maze.free.area == pytest.approx(len(free_cells) * maze.cell_size**2)
    for region in (maze.start, maze.goal, *maze.subgoals.values()):
        assert is_subset(region, maze.free)


def test_u_chain_subgoal_files_match_their_plain_twins():
    for k in range(2, 6):
        plain, sub = load_maze(BENCHMARK[f"u_chain_{k}"]), load_maze(BENCHMARK[f"u_chain_{k}_subgoals"])
        assert plain.rows == sub.rows and plain.cols == sub.cols
        assert [ch for row in sub.grid for ch in row if ch.islower()] == list("abcd"[: k - 1])
        assert plain.free_cells() == sub.free_cells() and not plain.subgoals


@pytest.mark.parametrize("agent", sorted(CELL_SIZE))
def test_walls_include_the_outer_frame(agent):
    maze = parse_maze("S.G\n", "open.maze").for_agent(agent)  # no '#' at all: the frame is the only wall
    x0, y0, x1, y1 = maze.bounds()
    eps = 0.01 * maze.cell_size
    outside = [[x0 - eps, 0], [x1 + eps, 0], [0, y0 - eps], [0, y1 + eps], [x1 + eps, y1 + eps], [x0 - eps, y0 - eps]]
    assert maze.walls.contains(outside).all()
    assert not maze.walls.contains(maze.cell_to_xy(0, np.arange(3))).any()
    # the frame is at least one cell thick
    assert maze.walls.contains([[x0 - 0.9 * maze.cell_size, 0], [0, y1 + 0.9 * maze.cell_size]]).all()


def test_cell_size_per_agent():
    assert CELL_SIZE == {"point": 1.0, "ant": 4.0}
    maze = load_maze("u_maze")
    assert maze.cell_size == 1.0
    ant = maze.for_agent("ant")
    assert ant.cell_size == 4.0 and ant.grid == maze.grid
    assert ant.width == 20.0 and ant.height == 20.0
    assert ant.goal.area == pytest.approx(16.0)


def test_load_by_bare_name_and_path_agree():
    assert load_maze("u_maze") == load_maze(MAZE_DIR / "u_maze.maze")
    assert load_maze(MAZE_DIR / "x_maze.maze", cell_size=4.0).cell_size == 4.0


# --- coordinates (Gymnasium-Robotics convention) ---------------------------------


def test_cell_to_xy_hand_values():
    maze = load_maze("u_maze")  # 5 x 5
    np.testing.assert_allclose(maze.cell_to_xy(0, 0), [-2, 2])
    np.testing.assert_allclose(maze.cell_to_xy(4, 4), [2, -2])
    np.testing.assert_allclose(maze.cell_to_xy(2, 2), [0, 0])
    np.testing.assert_allclose(maze.cell_to_xy(0, 3), [1, 2])  # column -> x, row 0 at the top
    np.testing.assert_allclose(maze.for_agent("ant").cell_to_xy(0, 0), [-8, 8])
    wide = load_maze("u_chain_2")  # 5 rows x 9 cols: even/odd extents
    np.testing.assert_allclose(wide.cell_to_xy(0, 0), [-4, 2])
    np.testing.assert_allclose(wide.bounds(), [-4.5, -2.5, 4.5, 2.5])
    assert tuple(maze.xy_to_cell([-2.4, 2.4])) == (0, 0)
    assert tuple(maze.xy_to_cell([2.4, -2.4])) == (4, 4)
    assert tuple(maze.xy_to_cell([0.6, 0.0])) == (2, 3)
    assert tuple(maze.xy_to_cell([-3.0, 0.0])) == (2, -1)  # outside the grid: out-of-range index


@pytest.mark.parametrize("agent", sorted(CELL_SIZE))
@pytest.mark.parametrize("name", ["u_maze", "xx_maze_v", "u_chain_3_subgoals", "split_doorway"])
def test_cell_xy_round_trip(name, agent):
    maze = load_maze(name).for_agent(agent)
    rows, cols = np.meshgrid(np.arange(maze.rows), np.arange(maze.cols), indexing="ij")
    xy = maze.cell_to_xy(rows, cols)
    assert xy.shape == (maze.rows, maze.cols, 2)
    back = maze.xy_to_cell(xy)
    np.testing.assert_array_equal(back[..., 0], rows)
    np.testing.assert_array_equal(back[..., 1], cols)
    # any point inside a cell maps back to that cell
    rng = np.random.default_rng(0)
    jitter = (rng.random(xy.shape) - 0.5) * 0.98 * maze.cell_size
    np.testing.assert_array_equal(maze.xy_to_cell(xy + jitter), back)
    # the cell box is centred on the cell
    box = maze.cell_box(1, 2)
    np.testing.assert_allclose(box.centre(), maze.cell_to_xy(1, 2))
    assert box.area == pytest.approx(maze.cell_size**2)


@pytest.mark.parametrize("agent", sorted(CELL_SIZE))
@pytest.mark.parametrize("name", ["u_maze", "x_maze", "xx_maze_h", "split_doorway"])
def test_matches_gymnasium_robotics(name, agent):
    maze_v4 = pytest.importorskip("gymnasium_robotics.envs.maze.maze_v4")
    maze = load_maze(name).for_agent(agent)
    grid = [[1 if ch == "#" else 0 for ch in row] for row in maze.grid]
    gym = maze_v4.Maze(grid, maze.cell_size, 0.4)
    for r in range(maze.rows):
        for c in range(maze.cols):
            xy = gym.cell_rowcol_to_xy(np.array([r, c]))
            np.testing.assert_allclose(maze.cell_to_xy(r, c), xy)
            assert tuple(gym.cell_xy_to_rowcol(xy)) == tuple(maze.xy_to_cell(xy)) == (r, c)
    inside = maze.cell_to_xy(1, 1) + np.array([0.3, -0.2]) * maze.cell_size
    assert tuple(gym.cell_xy_to_rowcol(inside)) == tuple(maze.xy_to_cell(inside)) == (1, 1)


# --- parsing ---------------------------------------------------------------------


def test_comments_blank_lines_and_trailing_space_are_ignored():
    text = "; a comment\n\n#####\n   \n; another\n#S.G#  \n\n#####\n; end\n"
    maze = parse_maze(text, "c.maze")
    assert maze.grid == ("#####", "#S.G#", "#####")
    assert maze == parse_maze("#####\n#S.G#\n#####", "c.maze")


def test_crlf_line_endings():
    assert parse_maze("#####\r\n#S.G#\r\n#####\r\n", "w.maze").grid == ("#####", "#S.G#", "#####")


def test_regions_of_several_cells_and_subgoal_order():
    maze = parse_maze("#######\n#SSb..#\n#S##a.#\n#..GG.#\n#######\n", "m.maze")
    assert maze.cells("S") == [(1, 1), (1, 2), (2, 1)]
    assert maze.start.area == pytest.approx(3.0)
    assert list(maze.subgoals) == ["a", "b"]  # alphabetical, not reading order
    assert maze.goal.contains(maze.cell_to_xy(3, 3)) and maze.goal.contains(maze.cell_to_xy(3, 4))
    assert maze.goal.area == pytest.approx(2.0)


def test_describe_mentions_frame_and_grid():
    maze = load_maze("u_maze")
    text = maze.describe()
    assert "origin at the map centre" in text and "y up" in text
    assert all(row in text for row in maze.grid)


def test_maze_is_a_value():
    assert Maze("m", ("S.G",)) == Maze("m", ("S.G",))
    assert Maze("m", ("S.G",)).scaled(4.0).cell_size == 4.0


# --- malformed files -------------------------------------------------------------

# (file content, expected "line:col" or None, words the message must contain)
MALFORMED = {
    "empty": ("", None, "empty"),
    "only_comments": ("; nothing here\n\n;  still nothing\n", None, "empty"),
    "ragged": ("#####\n#S.G#\n####\n", "3:5", "ragged"),
    "ragged_after_comments": ("; c\n\n#####\n; mid\n#S.G#\n#######\n", "6:6", "ragged"),
    "unknown_char": ("#####\n#S?G#\n#####\n", "2:3", "unknown character"),
    "uppercase_letter": ("#####\n#S.G#\n#.X.#\n#####\n", "3:3", "unknown character"),
    "no_start": ("#####\n#..G#\n#####\n", None, "no start"),
    "no_goal": ("#####\n#S..#\n#####\n", None, "no goal"),
    "not_connected": ("#####\n#S#G#\n#####\n", "2:4", "not reachable"),
    "start_cell_cut_off": ("#######\n#S.G#S#\n#######\n", "2:6", "start cell"),
    "unreachable_subgoal": ("#######\n#S.G#a#\n#######\n", "2:6", "subgoal 'a'"),
    "subgoal_behind_wall": ("#######\n#S.G..#\n#####.#\n#b#a..#\n#######\n", "4:2", "subgoal 'b'"),
}


def _run_cli(capsys, argv):
    code = cli.main(argv)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _assert_one_line(err, path, where=None, words=None):
    lines = err.strip("\n").splitlines()
    assert len(lines) == 1, f"expected one line on stderr, got: {err!r}"
    line = lines[0]
    assert "Traceback" not in err
    assert str(path) in line
    if where is not None:
        assert f"{path}:{where}:" in line
    if words is not None:
        assert words in line


@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_malformed_maze_exits_2_with_one_line(case, tmp_path, capsys):
    text, where, words = MALFORMED[case]
    path = tmp_path / f"{case}.maze"
    path.write_text(text)
    code, out, err = _run_cli(capsys, ["refine", str(path), "--out", str(tmp_path / "out")])
    assert code == 2
    assert out == ""
    _assert_one_line(err, path, where, words)
    if where is None:  # a line and column are still given, pointing into the file
        assert re.search(re.escape(str(path)) + r":\d+:\d+: ", err)


def test_malformed_maze_raises_maze_error_in_python():
    for case, (text, _, words) in MALFORMED.items():
        with pytest.raises(MazeError, match=re.escape(words)):
            parse_maze(text, f"{case}.maze")


def test_missing_file_exits_2(tmp_path, capsys):
    path = tmp_path / "nope.maze"
    code, out, err = _run_cli(capsys, ["refine", str(path), "--out", str(tmp_path / "out")])
    assert code == 2 and out == ""
    _assert_one_line(err, path, words="cannot read")


def test_directory_instead_of_file_exits_2(tmp_path, capsys):
    code, _, err = _run_cli(capsys, ["refine", str(tmp_path), "--out", str(tmp_path / "out")])
    assert code == 2
    _assert_one_line(err, tmp_path, words="cannot read")


@pytest.mark.parametrize("payload", [bytes(range(256)) * 4, b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe"],
                         ids=["all_bytes", "png_header"])
def test_binary_file_exits_2(payload, tmp_path, capsys):
    path = tmp_path / "binary.maze"
    path.write_bytes(payload)
    code, out, err = _run_cli(capsys, ["refine", str(path), "--out", str(tmp_path / "out")])
    assert code == 2 and out == ""
    _assert_one_line(err, path, where="1:1")


def test_nul_bytes_in_text_are_unknown_characters(tmp_path, capsys):
    path = tmp_path / "nul.maze"
    path.write_bytes(b"#####\n#S\x00G#\n#####\n")
    code, _, err = _run_cli(capsys, ["refine", str(path)])
    assert code == 2
    _assert_one_line(err, path, where="2:3", words="unknown character")


def test_bad_flags_exit_2_with_one_line(capsys):
    for argv in (["refine"], ["refine", "u_maze", "--agent", "car"], ["refine", "u_maze", "--proposer", "vlm"],
                 ["refine", "u_maze", "--seed", "x"], []):
        with pytest.raises(SystemExit) as exc:
            cli.main(argv)
        assert exc.value.code == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and "error" in err, err


def test_help_explains_every_flag(capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["refine", "--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    for flag in ("MAZE_FILE", "--agent", "--method", "--proposer", "--seed", "--out", "--rollouts", "--episodes"):
        assert flag in out
    for choice in ("point", "ant", "ours", "vlm-oneshot", "symbolic", "dirl", "geometric", "random", "replay:PATH",
                   "litellm:MODEL"):
        assert choice in out


def test_installed_entry_point_rejects_a_ragged_maze(tmp_path):
    exe = Path(sys.executable).with_name("specrefine")
    if not exe.exists():
        pytest.skip("the specrefine entry point is not installed next to this interpreter")
    path = tmp_path / "ragged.maze"
    path.write_text("; a ragged maze\n#####\n#S.G#\n###\n")
    proc = subprocess.run([str(exe), "refine", str(path), "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stdout == ""
    _assert_one_line(proc.stderr, path, where="4:4", words="ragged")
    assert proc.stderr.startswith("specrefine: error: ")


def test_a_generated_maze_is_a_maze_argument_everywhere(tmp_path, capsys):
    from specrefine.cli import main as cli_main
    from specrefine.core.mazes import random_maze
    from specrefine.runs import sweep

    assert load_maze("random:3x4:2").grid == random_maze((3, 4), 2).grid
    assert load_maze("random:3x4:2", cell_size=4.0).cell_size == 4.0
    for bad in ("random:3x4", "random:axb:1", "random:1x4:0", "random:3x3:-1"):
        with pytest.raises(MazeError, match="random maze"):
            load_maze(bad)
    out = tmp_path / "run"
    assert cli_main(["refine", "random:3x3:0", "--method", "dirl", "--rollouts", "8", "--episodes", "16",
                     "--out", str(out), "--quiet"]) == 0
    assert cli_main(["refine", "random:3x:0", "--out", str(tmp_path / "bad")]) == 2
    assert capsys.readouterr().err.strip().count("\n") == 0 and not (tmp_path / "bad").exists()
    (cell,) = sweep.grid(["random:3x3:0"], ["dirl"], ["none"], [0])
    assert cell.id.startswith("random-3x3-0__point__dirl")
