"""What each `imperfect` preset injects, measured on its own replies (no rollouts, no comparison).

    python scripts/imperfect_rates.py > data/results/imperfect_rates.json

For every preset and every maze in data/mazes: edge queries S -> G of the maze's first edge and
whole-graph queries of the maze's task graph, 100 replies each (seed 0), each reply checked by the
same validation a real VLM reply gets (``parse_split`` / ``parse_graph``).
"""

from __future__ import annotations

import json
import sys

from specrefine.core.errors import ProposalRejected
from specrefine.core.mazes import benchmark_mazes, load_maze
from specrefine.core.spec import maze_task
from specrefine.proposers import EdgeQuery, GraphQuery, parse_graph, parse_split
from specrefine.proposers.imperfect import ALPHA_ON, PRESETS, ErrorModelClient

REPLIES = 100


def rates(config, maze) -> dict:
    graph = maze_task(maze)
    u, v = graph.edges()[0]
    edge = EdgeQuery(maze, "point", graph.region(u), graph.region(v), graph.avoid(u, v), 0.0, 32, None)
    whole = GraphQuery(maze, "point", graph, 0.0, 32, None)
    out = {}
    for kind, query, parse in (("split", edge, lambda t: parse_split(t, maze)),
                               ("graph", whole, lambda t: parse_graph(t, maze, graph))):
        client = ErrorModelClient(config, seed=0)
        client.context = (kind, query, [])
        rejected = 0
        for text in client.complete([], n=REPLIES):
            try:
                parse(text)
            except ProposalRejected:
                rejected += 1
        turns = sum(r.get("turns", 0) for r in client.injected)
        out[kind] = {"rejected": rejected / REPLIES,
                     "turns_dropped": sum(r.get("dropped", 0) for r in client.injected) / max(turns, 1),
                     "mean_turns_spanned": sum(r["span_turns"] for r in client.injected) / REPLIES}
    return out


def main() -> int:
    presets = {**PRESETS, f"moderate,alpha={ALPHA_ON}": PRESETS["moderate"].__class__(
        **{**PRESETS["moderate"].__dict__, "alpha": ALPHA_ON})}
    table = {name: {stem: rates(cfg, load_maze(path).for_agent("point"))
                    for stem, path in sorted(benchmark_mazes().items())} for name, cfg in presets.items()}
    json.dump(table, sys.stdout, indent=1)
    print()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
