"""Issue 13: the offline planners stay usable on big mazes, and vectorising them changed no route.

``data/planner_routes.json`` holds, per shipped maze (data/mazes and data/mazes/unseen) and agent, the
SHA-256 of every proposal the geometric and imperfect planners made before their line-of-sight test
was vectorised (recorded with the code of commit 2fd381f); the planner must still make exactly those.
Regenerate it only for a deliberate change of the planner: ``python tests/test_planner_scale.py``.
"""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from specrefine.core.mazes import MAX_SIDE, MAZE_DIR, Maze, load_maze, parse_maze
from specrefine.core.spec import maze_task
from specrefine.evaluation.evaluator import EvaluationFacts
from specrefine.proposers import CandidateFeedback, EdgeQuery, make_proposer
from specrefine.proposers.geometric import clear_of_obstacles

ROUTES = Path(__file__).parent / "data" / "planner_routes.json"
SHIPPED = sorted(MAZE_DIR.glob("*.maze")) + sorted((MAZE_DIR / "unseen").glob("*.maze"))


def planner_routes(path: Path, agent: str) -> list:
    """What each offline planner proposes for every edge of the maze's task (and S -> G): a round, then feedback."""
    maze = load_maze(path).for_agent(agent)
    g = maze_task(maze)
    pairs = [(g.region(u), g.region(v)) for u, v in g.edges()] + [(maze.start, maze.goal)]
    facts = EvaluationFacts.default(agent, maze)  # once per maze, not once per prompt (it builds a MuJoCo model)
    out = []
    for spec in ("geometric", "imperfect:moderate"):
        p = make_proposer(spec, seed=1)
        for start, goal in pairs:
            q = EdgeQuery(maze, agent, start, goal, maze.obstacles, 0.25, 32, None, graph=g, facts=facts)
            first = p.propose_split(q, 3)
            fb = [CandidateFeedback(c, [0.9 - 0.4 * ((i + k) % 2) for i in range(len(c) + 1)])
                  for k, c in enumerate(first)]
            out += [[r.to_dict() for r in c] for c in first + p.propose_split(q, 3, fb)]
    return out


def digest(routes: list) -> str:
    """SHA-256 of the proposals, numbers to 9 decimals (a last-bit difference of another libm is no change)."""
    rounded = json.loads(json.dumps(routes), parse_float=lambda text: round(float(text), 9))
    return hashlib.sha256(json.dumps(rounded).encode()).hexdigest()


def all_digests() -> dict:
    return {f"{p.relative_to(MAZE_DIR)}:{agent}": digest(planner_routes(p, agent)) for p in SHIPPED
            for agent in ("point", "ant")}


@pytest.mark.slow
def test_planners_make_the_recorded_routes_on_every_shipped_maze():
    recorded = json.loads(ROUTES.read_text())
    assert set(recorded) == {f"{p.relative_to(MAZE_DIR)}:{a}" for p in SHIPPED for a in ("point", "ant")}
    changed = [key for key, value in all_digests().items() if recorded[key] != value]
    assert not changed, f"the planners propose other routes than before on {changed}"



def random_maze(side: int, seed: int) -> Maze:
    """Walls, hazards and floor at random (no checks: only the geometry matters here)."""
    cells = np.random.default_rng(seed).choice(list("#~..."), (side, side))
    return Maze("random", tuple("".join(row) for row in cells))


@pytest.mark.parametrize("maze", [load_maze(MAZE_DIR / "unseen" / "pillars.maze"), load_maze("hazard_pool"),
                                  random_maze(40, 0), random_maze(40, 1).for_agent("ant")], ids=lambda m: m.name)
def test_the_grid_clearance_test_is_the_exact_one(maze):
    x0, y0, x1, y1 = maze.bounds()
    pts = np.random.default_rng(0).uniform((x0 - 1, y0 - 1), (x1 + 1, y1 + 1), (20000, 2))
    for margin in np.array([0.0, 0.15, 0.35, 0.45, 0.7, 1.5]) * maze.cell_size:
        exact = maze.obstacles.signed_distance(pts) >= margin
        assert (clear_of_obstacles(maze, pts, margin) == exact).all(), margin


def open_maze(side: int) -> str:
    """A room of side x side cells (walls around), S and G in opposite corners."""
    inner = ["#" + "." * (side - 2) + "#" for _ in range(side - 2)]
    inner[0], inner[-1] = "#S" + inner[0][2:], inner[-1][:-2] + "G#"
    return "\n".join(["#" * side, *inner, "#" * side]) + "\n"


PLAN = """
import sys
from specrefine.core.mazes import load_maze
from specrefine.proposers import EdgeQuery, make_proposer
maze = load_maze(sys.argv[1])
q = EdgeQuery(maze, "point", maze.start, maze.goal, maze.obstacles, 0.0, 32, None)
print([len(c) for c in make_proposer("geometric", seed=0).propose_split(q, 2)])
"""


def test_planning_on_the_largest_open_maze_allowed_finishes(tmp_path):
    """On 300x300 it took 105 s for one sample (w = 2: past 120 s) before the planner was vectorised; mazes are now
    capped at MAX_SIDE cells a side (issue 40), so the largest allowed is planned. The guard is generous: no speed
    ratio."""
    (tmp_path / "open.maze").write_text(open_maze(MAX_SIDE))
    proc = subprocess.run([sys.executable, "-c", PLAN, str(tmp_path / "open.maze")], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    counts = json.loads(proc.stdout)
    assert len(counts) == 2 and all(1 <= n <= 32 for n in counts), counts


def test_a_big_avoid_set_is_inside_itself_without_pairwise_tests(monkeypatch):
    """Each refined edge checks that it avoids what its parent avoided: on a 300x300 maze, 600 wall boxes against
    600 took 360,000 box tests per edge (15 s of a refine run); the largest maze allowed now is MAX_SIDE a side."""
    from specrefine.core import regions

    walls = parse_maze(open_maze(MAX_SIDE)).obstacles
    tests = []
    monkeypatch.setattr(regions, "_part_in_part", lambda *args: tests.append(args))
    assert regions.is_subset(walls, walls) and not tests


if __name__ == "__main__":
    ROUTES.write_text(json.dumps(all_digests(), indent=0) + "\n")
    sys.exit(0)
