"""A worked plugin: a method and a proposer of your own, on the command line and in sweeps.

    specrefine --plugin examples/greedy_plugin.py refine u_maze --method ours-greedy --proposer straight:2
    specrefine sweep --plugin examples/greedy_plugin.py --mazes u_maze --methods ours ours-greedy \\
        --proposers straight geometric --seeds 0 1

(or ``--plugin examples.greedy_plugin`` from the repository root, or an entry point of your package:
``[project.entry-points."specrefine.methods"] greedy = "mypackage.greedy_plugin"``; docs/interfaces.md, "Plugins").

* ``ours-greedy``: ``ours`` that takes any refinement which beats progress at all (tau held at 0, where ``ours``
  raises it from 0.02 to 0.1 as it accepts refinements): a variant is the SearchConfig fields it changes.
* ``straight`` / ``straight:N``: N waypoints (default 1) evenly spaced on the straight line from the edge's start
  to its goal, those inside a wall left out. An offline toy, not a VLM. A proposer implements ``split`` (and
  ``graph`` for the one-shot baseline); the base class counts its queries and ``make_proposer`` gives it its string.
"""

from __future__ import annotations

import numpy as np

from specrefine.core.errors import SpecrefineError
from specrefine.core.regions import Disc
from specrefine.proposers import Proposer, register_proposer
from specrefine.proposers.geometric import clear_of_obstacles
from specrefine.runs.methods import ours_variant, register_method


class StraightLineProposer(Proposer):
    name = "straight line (example plugin, offline, not a VLM)"

    def __init__(self, waypoints: int):
        super().__init__()
        self.waypoints = waypoints

    def split(self, q, w, feedback=()):
        start, goal = np.asarray(q.start.centre(), float), np.asarray(q.goal.centre(), float)
        radius = 0.3 * q.maze.cell_size
        points = [start + (goal - start) * i / (self.waypoints + 1) for i in range(1, self.waypoints + 1)]
        free = [p for p in points if clear_of_obstacles(q.maze, p[None], radius)[0]]
        return [[Disc(float(x), float(y), radius) for x, y in free]] if free else []

    def graph(self, q, w, feedback=()):
        return []  # no whole-graph answers: the one-shot baseline then keeps the input graph


def parse_waypoints(options: str) -> int:
    if not options:
        return 1
    if not options.isdigit() or not 1 <= int(options) <= 20:
        raise SpecrefineError(f"invalid proposer 'straight:{options}': give 1 to 20 waypoints, e.g. straight:2")
    return int(options)


register_method("ours-greedy", ours_variant(tau0=0.0, tau_step=0.0, tau_max=0.0),
                "example plugin: ours accepting any refinement that beats progress (tau held at 0)",
                colour="#2e7d32")
register_proposer("straight", lambda n, **_: StraightLineProposer(n), parse_waypoints, usage="straight[:N]",
                  description="example plugin: N waypoints on the straight line, offline, not a VLM")
