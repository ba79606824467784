"""Maze maps: the ``*.maze`` text format, cell <-> (x, y), and the regions a task uses.

Format (one grid row per line): ``#`` wall, ``.`` free, ``S`` start cell(s), ``G`` goal
cell(s), ``a``..``z`` subgoal cells (one letter = one region, visited in alphabetical
order), ``~`` hazard cells (free floor the body can cross, with no wall geometry in the
simulator, but part of every subtask's avoid set: touching one fails the task).  Lines
starting with ``;`` are comments, blank lines are ignored, and anything outside the grid is
wall.  A comment line ``; spec: EXPR`` gives the maze's default task as a spec expression
(``specrefine.core.spec.parse_spec``, e.g. ``; spec: (a | b) -> G``) in place of the chain
S -> a -> b -> ... -> G; ``--spec`` on the command line overrides it.

A grid has at most ``MAX_SIDE`` rows and as many columns (every shipped and standard map has at most 21), wherever
it comes from (a file, ``random:RxC:SEED``, ``gr:NAME``, ``Maze.from_gymnasium``); a larger one is one MazeError
line before anything is built from it.

Coordinates follow Gymnasium-Robotics' ``maze_v4.py``: the origin is the centre of the
map, x grows with the column, y grows upwards (row 0 is the top row), and every cell is
``cell_size`` metres wide (1.0 for the point mass, 4.0 for the Ant).
"""

from __future__ import annotations

import re
from collections import deque
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from .agents import AGENTS, get_agent
from .errors import MazeError, SpecrefineError
from .paths import data_dir, regular_file
from .regions import Box, Region, union

MAZE_DIR = data_dir() / "mazes"
CELL_SIZE = {name: agent.cell_size for name, agent in AGENTS.items()}  # metres per cell, by agent
_LEGAL = set("#.SG~") | set("abcdefghijklmnopqrstuvwxyz")
HAZARD = "~"
_SPEC_LINE = re.compile(r"^\s*;\s*spec\s*:\s*(.*)$")
MAX_SIDE = 100  # rows, and columns, of a grid: the shipped and Gymnasium-Robotics maps have at most 21
MAX_FILE_BYTES = 1_000_000  # a .maze file: a full 100 x 100 grid is 10 kB, the rest is room for comments


@dataclass(frozen=True)
class Maze:
    name: str
    grid: tuple[str, ...]
    cell_size: float = 1.0
    spec: str | None = None  # the default task from a '; spec: EXPR' line (None: the chain S -> a -> ... -> G)

    @property
    def rows(self) -> int:
        return len(self.grid)

    @property
    def cols(self) -> int:
        return len(self.grid[0])

    def scaled(self, cell_size: float) -> Maze:
        return Maze(self.name, self.grid, cell_size, self.spec)

    def for_agent(self, agent: str) -> Maze:
        return self.scaled(get_agent(agent).cell_size)

    @classmethod
    def from_gymnasium(cls, map_list, name: str = "gymnasium_map", cell_size: float = 1.0) -> Maze:
        """A Gymnasium-Robotics map (rows of 1 / 0 / 'r' / 'g' / 'c'); start and goal as in
        :mod:`specrefine.core.standard_maps`."""
        from .standard_maps import maze_text

        if isinstance(map_list, (list, tuple)) and (len(map_list) > MAX_SIDE or any(
                isinstance(row, (list, tuple)) and len(row) > MAX_SIDE for row in map_list)):
            raise MazeError(f"{name}: the map is larger than {MAX_SIDE} x {MAX_SIDE} cells")
        return parse_maze(maze_text(map_list, name=name), name, cell_size)

    # --- coordinates (Gymnasium-Robotics convention) -------------------------------
    @property
    def width(self) -> float:
        return self.cols * self.cell_size

    @property
    def height(self) -> float:
        return self.rows * self.cell_size

    def cell_to_xy(self, row, col) -> np.ndarray:
        """Centre of cell (row, col); works on arrays (broadcast against each other)."""
        x = (np.asarray(col) + 0.5) * self.cell_size - self.width / 2
        y = self.height / 2 - (np.asarray(row) + 0.5) * self.cell_size
        return np.stack(np.broadcast_arrays(x, y), axis=-1).astype(float)

    def xy_to_cell(self, xy) -> np.ndarray:
        """(row, col) integer indices of the cell holding each point (may lie outside the grid)."""
        xy = np.asarray(xy, dtype=float)
        col = np.floor((xy[..., 0] + self.width / 2) / self.cell_size).astype(int)
        row = np.floor((self.height / 2 - xy[..., 1]) / self.cell_size).astype(int)
        return np.stack([row, col], axis=-1)

    def cell_box(self, row: int, col: int) -> Box:
        x, y = self.cell_to_xy(row, col)
        h = self.cell_size / 2
        return Box(x - h, y - h, x + h, y + h)

    def bounds(self) -> tuple[float, float, float, float]:
        return (-self.width / 2, -self.height / 2, self.width / 2, self.height / 2)

    # --- cells and regions -------------------------------------------------------
    def cells(self, char: str) -> list[tuple[int, int]]:
        return [(r, c) for r, line in enumerate(self.grid) for c, ch in enumerate(line) if ch == char]

    def is_free(self, row: int, col: int) -> bool:
        return 0 <= row < self.rows and 0 <= col < self.cols and self.grid[row][col] != "#"

    def free_cells(self) -> list[tuple[int, int]]:
        return [(r, c) for r in range(self.rows) for c in range(self.cols) if self.is_free(r, c)]

    def passable(self, row: int, col: int) -> bool:
        """Free and not a hazard: a cell a route may use (``is_free`` also counts hazards, the body can cross them)."""
        return self.is_free(row, col) and self.grid[row][col] != HAZARD

    def passable_cells(self) -> list[tuple[int, int]]:
        return [(r, c) for r in range(self.rows) for c in range(self.cols) if self.passable(r, c)]

    def region_of(self, cells) -> Region:
        """Union of cells, merged into maximal horizontal runs so it stays small."""
        cells = sorted(set(cells))
        boxes, run = [], None
        for r, c in cells:
            if run and run[0] == r and run[2] == c - 1:
                run = (r, run[1], c)
            else:
                if run:
                    boxes.append(self._run_box(*run))
                run = (r, c, c)
        boxes.append(self._run_box(*run))
        return union(boxes)

    def _run_box(self, row, c0, c1) -> Box:
        a, b = self.cell_box(row, c0), self.cell_box(row, c1)
        return Box(a.xmin, a.ymin, b.xmax, b.ymax)

    @property
    def start(self) -> Region:
        return self.region_of(self.cells("S"))

    @property
    def goal(self) -> Region:
        return self.region_of(self.cells("G"))

    @cached_property
    def subgoals(self) -> dict[str, Region]:
        letters = sorted({ch for line in self.grid for ch in line if ch.islower()})
        return {ch: self.region_of(self.cells(ch)) for ch in letters}

    @cached_property
    def walls(self) -> Region:
        """Wall cells plus a frame of walls around the grid (outside the grid is wall)."""
        wall_cells = self.cells("#")
        x0, y0, x1, y1 = self.bounds()
        t = self.cell_size
        frame = [Box(x0 - t, y1, x1 + t, y1 + t), Box(x0 - t, y0 - t, x1 + t, y0),
                 Box(x0 - t, y0, x0, y1), Box(x1, y0, x1 + t, y1)]
        return union(([self.region_of(wall_cells)] if wall_cells else []) + frame)

    @cached_property
    def hazards(self) -> Region | None:
        """The hazard cells ``~`` (None if there are none): free floor, but avoided by every subtask."""
        cells = self.cells(HAZARD)
        return self.region_of(cells) if cells else None

    @cached_property
    def obstacles(self) -> Region:
        """What every subtask avoids: the walls plus the hazards (exactly ``walls`` when there are no hazards)."""
        return self.walls if self.hazards is None else union([*self.walls.parts(), *self.hazards.parts()])

    @cached_property
    def free(self) -> Region:
        return self.region_of(self.free_cells())

    def describe(self) -> str:
        """The environment description handed to a VLM (geometry, frame, regions)."""
        lines = [
            f"Maze '{self.name}': {self.rows} rows x {self.cols} columns, cell size {self.cell_size} m.",
            "Frame: origin at the map centre, x to the right (columns), y up (row 0 is the top row).",
            f"Map extent: x in [{-self.width / 2:g}, {self.width / 2:g}], "
            f"y in [{-self.height / 2:g}, {self.height / 2:g}].",
            "Cell (row, col) has centre x = (col + 0.5) * cell - width/2, y = height/2 - (row + 0.5) * cell.",
            "Grid ('#' wall, '.' free, 'S' start, 'G' goal, letters = subgoals"
            + (", '~' hazard: free floor that counts as touching an obstacle" if self.hazards else "") + "):",
            *("    " + line for line in self.grid),
        ]
        return "\n".join(lines)


def parse_maze(text: str, name: str = "<maze>", cell_size: float = 1.0) -> Maze:
    """Parse maze text; any problem raises MazeError('name:line:col: what')."""
    rows, width, first_line, spec_line = [], None, None, None
    text = text.removeprefix("\ufeff")  # a UTF-8 byte order mark, as some editors write
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.rstrip("\r\n").rstrip()
        if not line.strip() or line.lstrip().startswith(";"):
            m = _SPEC_LINE.match(line)
            if m:
                if spec_line is not None:
                    raise MazeError(f"{name}:{lineno}:1: a second '; spec:' line (line {spec_line[0]} has one)")
                spec_line = (lineno, m.start(1), m.group(1).rstrip())
            continue
        for col, ch in enumerate(line, start=1):
            if ch not in _LEGAL:
                raise MazeError(f"{name}:{lineno}:{col}: unknown character {ch!r} (use # . S G ~ or a-z)")
        if len(line) > MAX_SIDE or len(rows) == MAX_SIDE:
            raise MazeError(f"{name}:{lineno}:1: the grid is larger than {MAX_SIDE} x {MAX_SIDE} cells")
        if width is None:
            width, first_line = len(line), lineno
        elif len(line) != width:
            raise MazeError(
                f"{name}:{lineno}:{min(len(line), width) + 1}: ragged row: {len(line)} columns, "
                f"line {first_line} has {width}"
            )
        rows.append((lineno, line))
    if not rows:
        raise MazeError(f"{name}:1:1: empty maze: no grid rows")
    maze = Maze(Path(name).stem, tuple(line for _, line in rows), cell_size)
    _check_cells(maze, name, [lineno for lineno, _ in rows])
    if spec_line is not None:
        from .errors import SpecError
        from .spec import parse_spec

        lineno, offset, expr = spec_line
        try:
            parse_spec(expr, maze)
        except SpecError as exc:
            col = offset + getattr(exc, "column", 1)
            raise MazeError(f"{name}:{lineno}:{col}: '; spec:' line: {getattr(exc, 'reason', exc)}") from None
        maze = Maze(maze.name, maze.grid, cell_size, expr)
    return maze


def _check_cells(maze: Maze, name: str, linenos: list[int]) -> None:
    where = lambda cell: f"{name}:{linenos[cell[0]]}:{cell[1] + 1}"  # noqa: E731
    starts, goals = maze.cells("S"), maze.cells("G")
    if not starts:
        raise MazeError(f"{name}:{linenos[0]}:1: no start cell 'S'")
    if not goals:
        raise MazeError(f"{name}:{linenos[0]}:1: no goal cell 'G'")
    reached = reachable_cells(maze, starts)
    safe = reachable_cells(maze, starts, maze.passable)  # without crossing a hazard '~'
    only_hazards = " (only through hazard cells '~', which every subtask avoids)"
    for goal in goals:
        if goal not in safe:
            raise MazeError(f"{where(goal)}: goal cell 'G' is not reachable from the start through free cells"
                            + (only_hazards if goal in reached else ""))
    to_goal = reachable_cells(maze, goals, maze.passable)
    for start in starts:  # the initial distribution covers every S cell, so each must lead to the goal
        if start not in to_goal:
            raise MazeError(f"{where(start)}: start cell 'S' cannot reach the goal through free cells"
                            + (only_hazards if start in reachable_cells(maze, goals) else ""))
    for letter in maze.subgoals:
        for cell in maze.cells(letter):
            if cell not in safe:
                raise MazeError(f"{where(cell)}: subgoal {letter!r} is not reachable from the start through free "
                                "cells" + (only_hazards if cell in reached else ""))


def reachable_cells(maze: Maze, sources, through=None) -> set[tuple[int, int]]:
    """Cells 4-connected to ``sources`` through cells where ``through(row, col)`` (default ``maze.is_free``)."""
    through = through or maze.is_free
    seen, queue = set(sources), deque(sources)
    while queue:
        r, c = queue.popleft()
        for nb in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
            if nb not in seen and through(*nb):
                seen.add(nb)
                queue.append(nb)
    return seen


def random_maze(rooms: tuple[int, int], seed: int, loops: float = 0.25, cell_size: float = 1.0) -> Maze:
    """A corridor maze for training among walls, none of the benchmark's layouts: a spanning tree of rooms[0] x
    rooms[1] one-cell rooms (randomised depth-first search), each room joined to its neighbours by one-cell
    corridors, plus a fraction ``loops`` of the remaining walls between rooms opened; S top-left, G bottom-right."""
    rows, cols = (int(k) for k in rooms)
    if rows < 2 or cols < 2 or not 0 <= loops <= 1:
        raise MazeError(f"random maze {rows}x{cols}, loops {loops:g}: needs at least 2x2 rooms and 0 <= loops <= 1")
    if 2 * max(rows, cols) + 1 > MAX_SIDE:
        most = (MAX_SIDE - 1) // 2
        raise MazeError(f"random maze {rows}x{cols}: at most {most}x{most} rooms (a grid of {MAX_SIDE} x {MAX_SIDE} "
                        "cells)")
    rng = np.random.default_rng(seed)
    grid = [["#"] * (2 * cols + 1) for _ in range(2 * rows + 1)]
    seen, stack = {(0, 0)}, [(0, 0)]
    grid[1][1] = "."
    while stack:
        r, c = stack[-1]
        nbs = [(r + dr, c + dc) for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1))
               if 0 <= r + dr < rows and 0 <= c + dc < cols and (r + dr, c + dc) not in seen]
        if not nbs:
            stack.pop()
            continue
        nr, nc = nbs[rng.integers(len(nbs))]
        grid[2 * nr + 1][2 * nc + 1] = "."
        grid[r + nr + 1][c + nc + 1] = "."
        seen.add((nr, nc))
        stack.append((nr, nc))
    inner = [(r, c) for r in range(1, 2 * rows) for c in range(1, 2 * cols) if (r + c) % 2 == 1 and grid[r][c] == "#"]
    for k in rng.permutation(len(inner))[: round(loops * len(inner))]:
        r, c = inner[k]
        grid[r][c] = "."
    grid[1][1], grid[2 * rows - 1][2 * cols - 1] = "S", "G"
    return Maze(_random_maze_name(rows, cols, seed), tuple("".join(line) for line in grid), cell_size)


def _random_maze_name(rows: int, cols: int, seed: int) -> str:
    return f"random_{rows}x{cols}_s{seed}"


RANDOM_PREFIX = "random:"


def load_maze(path, cell_size: float = 1.0) -> Maze:
    """Load a maze file; a bare name like 'u_maze' is looked up in data/mazes/, 'gr:NAME' is the
    Gymnasium-Robotics map NAME (``specrefine.core.standard_maps``) and 'random:RxC:SEED' the generated corridor
    maze of R x C rooms (:func:`random_maze`: S top-left, G bottom-right, none of the benchmark's layouts)."""
    from .standard_maps import PREFIX, standard_text

    if isinstance(path, str) and path.startswith(PREFIX):
        name, text = standard_text(path)
        return parse_maze(text, name, cell_size)
    if isinstance(path, str) and path.startswith(RANDOM_PREFIX):
        return _random_from_text(path, cell_size)
    path = Path(path)
    if not path.exists() and not path.suffix and (MAZE_DIR / f"{path}.maze").exists():
        path = MAZE_DIR / f"{path}.maze"
    if not path.exists() and not path.is_symlink() and not path.suffix:
        raise MazeError(_unknown_name(str(path)))
    try:
        if regular_file(path, "maze file").stat().st_size > MAX_FILE_BYTES:
            raise MazeError(f"{path}: larger than {MAX_FILE_BYTES:,} bytes: not a maze file")
        text = path.read_text(encoding="utf-8")
    except SpecrefineError as exc:
        raise MazeError(str(exc)) from None
    except OSError as exc:
        raise MazeError(f"{path}: cannot read maze file ({exc.strerror or exc})") from None
    except UnicodeDecodeError:
        raise MazeError(f"{path}:1:1: not a text file") from None
    return parse_maze(text, str(path), cell_size)


def _unknown_name(name: str) -> str:
    """One line for a maze name that is neither a file nor a shipped maze: the nearest shipped names."""
    import difflib

    names = sorted(p.relative_to(MAZE_DIR).with_suffix("").as_posix() for p in MAZE_DIR.rglob("*.maze"))
    near = difflib.get_close_matches(name, names, n=3, cutoff=0.6)
    hint = f"nearest: {', '.join(near)}" if near else f"shipped: {', '.join(n for n in names if '/' not in n)}"
    return (f"{name}: no such maze (not a file, not in data/mazes/; {hint}; or gr:NAME, random:RxC:SEED, "
            f"a path to a .maze file)")


def random_name(spec: str) -> str:
    """The name a generated maze's spec gives its Maze (``random:RxC:SEED`` -> ``random_RxC_sSEED``, as a run's
    result.json records it); any other spec as it is (a sweep table records the spec)."""
    text = spec.strip().lower()
    if not text.startswith(RANDOM_PREFIX):
        return spec
    try:
        return _random_maze_name(*_random_spec(text))
    except MazeError:
        return spec


def _random_spec(text: str) -> tuple[int, int, int]:
    """``random:RxC:SEED`` -> (R, C, SEED); a one-line MazeError otherwise."""
    try:
        rooms, seed = text.removeprefix(RANDOM_PREFIX).split(":")
        r, c = (int(k) for k in rooms.lower().split("x"))
        seed = int(seed)
    except ValueError:
        raise MazeError(f"random maze {text!r}: expected random:RxC:SEED, e.g. random:4x6:0") from None
    if seed < 0:
        raise MazeError(f"random maze {text!r}: the seed must be >= 0")
    return r, c, seed


def _random_from_text(text: str, cell_size: float) -> Maze:
    r, c, seed = _random_spec(text)
    return random_maze((r, c), seed, cell_size=cell_size)


def benchmark_mazes() -> dict[str, Path]:
    """The shipped benchmark suite, name -> file."""
    return {p.stem: p for p in sorted(MAZE_DIR.glob("*.maze"))}


def u_chain(name: str) -> tuple[int, bool] | None:
    """(rooms, with subgoals) of a shipped U-chain's name (``u_chain_3_subgoals`` -> (3, True)); None for any other."""
    m = re.fullmatch(r"u_chain_(\d+)(_subgoals)?", name)
    return (int(m.group(1)), bool(m.group(2))) if m else None
