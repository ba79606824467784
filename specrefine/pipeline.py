"""One refinement run, end to end: maze -> task graph -> refine -> measure -> result.json."""

from __future__ import annotations

from pathlib import Path

from .errors import SpecrefineError
from .mazes import load_maze
from .spec import maze_task


def refine_maze(maze_path, *, agent="point", method="ours", proposer="geometric", seed=0, out=Path("runs/latest"),
                rollouts=32, episodes=200, policy_path=None, w=3, d=2, k=5):
    maze = load_maze(maze_path).for_agent(agent)
    graph = maze_task(maze)
    raise SpecrefineError(f"compiled {graph} for {maze.name}; the refinement search is not built yet")
