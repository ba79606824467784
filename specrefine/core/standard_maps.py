"""Gymnasium-Robotics maze maps as this package's :class:`~specrefine.core.mazes.Maze`.

A Gymnasium-Robotics map is a list of rows, each a list of ``1`` (wall), ``0`` (free), ``'r'`` (a
reset cell), ``'g'`` (a goal cell) or ``'c'`` (a cell that may be either);
``gymnasium_robotics.envs.maze.maps`` ships U_MAZE, MEDIUM_MAZE, LARGE_MAZE, their ``_DIVERSE_G`` /
``_DIVERSE_GR`` variants, OPEN and EMPTY_MAZE.  ``gr:NAME`` names one of them wherever a maze file
is accepted.

Start and goal.  Gymnasium-Robotics (``maze_v4.Maze.make_maze``) draws the agent's reset cell
uniformly from the ``r`` and ``c`` cells and the goal cell uniformly from the ``g`` and ``c`` cells;
without ``r`` or ``c`` cells any free cell may be a reset cell, without ``g`` or ``c`` cells any free
cell may be a goal.  A task here has one start region S and one goal region G, so:

* **start** S: all ``r`` cells (several ``r`` cells are the initial distribution, uniform over them,
  as Gymnasium-Robotics draws its reset cell); with no ``r`` cell, the first ``c`` cell in reading
  order; with neither, the first free cell in reading order (top left: D4RL's start cell (1, 1) on
  every shipped map).
* **goal** G: ONE cell, the reachable goal candidate (``g`` and ``c`` cells other than the start)
  farthest from the start in 4-connected steps through free cells (the first in reading order on a
  tie), i.e. the hardest of the goals Gymnasium-Robotics may draw.  Several goal cells are not made a
  union: "reach any of them" would be a different, easier task than any one episode there.
* a map with **no** ``g`` / ``c`` cell takes D4RL's evaluation goal when its walls are those of a
  D4RL AntMaze map (``D4RL_GOALS``: the ``*_TEST`` maps of D4RL's ``locomotion/maze_env.py`` used by
  antmaze-umaze / medium / large): U_MAZE (3, 1), MEDIUM_MAZE (6, 6), LARGE_MAZE (7, 9); any other
  map takes the free cell farthest from the start.

Coordinates: the same as this package's (``maze_v4.Maze.cell_rowcol_to_xy``: origin at the map centre,
x with the column, y up, row 0 the top row); Gymnasium-Robotics scales a cell to 1 m (PointMaze) or
4 m (AntMaze), as ``Agent.cell_size`` does here.  (D4RL itself put the origin at the start cell and
had y grow with the row index, a mirror image; the cells (row, col) are the same.)
"""

from __future__ import annotations

import importlib.util
from collections import deque
from pathlib import Path

from .errors import MazeError

PREFIX = "gr:"
#: D4RL's evaluation goal cell (row, col) for the AntMaze maps (their ``*_TEST`` maps: U_MAZE_TEST,
#: BIG_MAZE_TEST, HARDEST_MAZE_TEST in D4RL's locomotion/maze_env.py); start (1, 1) on all three
D4RL_GOALS = {"U_MAZE": (3, 1), "MEDIUM_MAZE": (6, 6), "LARGE_MAZE": (7, 9)}
_CELLS = {"r", "g", "c"}


def gymnasium_maps() -> dict[str, list]:
    """Every map of ``gymnasium_robotics.envs.maze.maps``, by name.

    The file is loaded on its own (it is plain lists), not through the package, whose import prints a
    notice on stderr and registers hundreds of environments.
    """
    spec = importlib.util.find_spec("gymnasium_robotics")
    if spec is None or spec.origin is None:
        raise MazeError("gr: maps need the package 'gymnasium_robotics', which is not installed")
    path = Path(spec.origin).parent / "envs" / "maze" / "maps.py"
    module_spec = importlib.util.spec_from_file_location("_gymnasium_robotics_maps", path)
    module = importlib.util.module_from_spec(module_spec)
    module_spec.loader.exec_module(module)
    return {name: value for name, value in vars(module).items()
            if name.isupper() and isinstance(value, list) and value and isinstance(value[0], list)}


def standard_text(ref: str) -> tuple[str, str]:
    """``'gr:NAME'`` -> (its maze name, the ``.maze`` text of that Gymnasium-Robotics map); an unknown name is one
    MazeError line.  ``mazes.load_maze`` parses it."""
    name = ref[len(PREFIX):] if ref.startswith(PREFIX) else ref
    maps = gymnasium_maps()
    if name not in maps:
        raise MazeError(f"{ref}: no Gymnasium-Robotics map {name!r}; known: {', '.join(sorted(maps))}")
    return f"{PREFIX}{name}", maze_text(maps[name], name=f"{PREFIX}{name}")


def maze_text(map_list, name: str = "gymnasium_map") -> str:
    """A Gymnasium-Robotics map (list of lists of 1 / 0 / 'r' / 'g' / 'c') as ``.maze`` text, start and goal by the
    rules of the module docstring (``mazes.Maze.from_gymnasium`` parses it)."""
    rows = _checked(map_list, name)
    walls = [[cell == 1 for cell in row] for row in rows]
    free = [(r, c) for r, row in enumerate(walls) for c, wall in enumerate(row) if not wall]
    if not free:
        raise MazeError(f"{name}: the map has no free cell")
    of = lambda kind: [(r, c) for r, c in free if rows[r][c] == kind]  # noqa: E731
    starts = of("r") or (of("c") or free)[:1]
    is_start = set(starts)
    distance = _steps(walls, starts)
    d4rl = D4RL_GOALS.get(_d4rl_name(walls)) if not (of("g") or of("c")) else None
    candidates = [cell for cell in of("g") + of("c") if cell not in is_start] or free
    reachable = [cell for cell in candidates if cell in distance and cell not in is_start]
    if d4rl is None and not reachable:
        raise MazeError(f"{name}: no goal cell is reachable from the start {starts[0]}")
    goal = d4rl or max(sorted(reachable), key=lambda cell: distance[cell])  # max keeps the first on a tie
    grid = [["#" if wall else "." for wall in row] for row in walls]
    for (r, c), ch in [(cell, "S") for cell in starts] + [(goal, "G")]:
        grid[r][c] = ch
    return "\n".join("".join(row) for row in grid)


def to_gymnasium(maze) -> list[list[int]]:
    """The maze's walls as a Gymnasium-Robotics ``maze_map`` (1 wall, 0 free; hazards are free floor)."""
    return [[1 if ch == "#" else 0 for ch in row] for row in maze.grid]


def _checked(map_list, name: str) -> list[list]:
    """The rows of a well-formed map, else one MazeError line naming the first problem."""
    if not isinstance(map_list, (list, tuple)) or not map_list:
        raise MazeError(f"{name}: a Gymnasium-Robotics map is a non-empty list of rows, got {type(map_list).__name__}")
    width = None
    for r, row in enumerate(map_list):
        if not isinstance(row, (list, tuple)) or not row:
            raise MazeError(f"{name}: row {r} is not a non-empty list")
        if width is None:
            width = len(row)
        elif len(row) != width:
            raise MazeError(f"{name}: ragged map: row {r} has {len(row)} cells, row 0 has {width}")
        for c, cell in enumerate(row):
            if not (cell in _CELLS if isinstance(cell, str) else not isinstance(cell, bool) and cell in (0, 1)):
                raise MazeError(f"{name}: row {r}, column {c}: unknown cell {cell!r} (use 1, 0, 'r', 'g' or 'c')")
    return [list(row) for row in map_list]


def _steps(walls: list[list[bool]], sources) -> dict[tuple[int, int], int]:
    """4-connected steps through free cells from the nearest of ``sources``."""
    rows, cols = len(walls), len(walls[0])
    dist = {cell: 0 for cell in sources}
    queue = deque(sources)
    while queue:
        r, c = queue.popleft()
        for nr, nc in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
            if 0 <= nr < rows and 0 <= nc < cols and not walls[nr][nc] and (nr, nc) not in dist:
                dist[nr, nc] = dist[r, c] + 1
                queue.append((nr, nc))
    return dist


def _d4rl_name(walls: list[list[bool]]) -> str | None:
    """The D4RL AntMaze map with exactly these walls (None: none)."""
    maps = gymnasium_maps()
    for name in D4RL_GOALS:
        if [[cell == 1 for cell in row] for row in maps[name]] == walls:
            return name
    return None
