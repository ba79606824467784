"""A new method and a new proposer are each one registry entry: examples registered here run through refine_maze."""

from __future__ import annotations

import json

import pytest

from specrefine.cli import build_parser
from specrefine.core.errors import SpecrefineError
from specrefine.proposers import PROPOSERS, make_proposer, register_proposer
from specrefine.proposers.geometric import GeometricProposer
from specrefine.refine import shortest_path
from specrefine.runs.methods import METHOD_COLOURS, METHODS, PROPOSER_METHODS, SearchJob, register_method
from specrefine.runs.pipeline import refine_maze
from specrefine.runs.sweep import grid

TINY = dict(agent="point", rollouts=8, episodes=16)


def straight_to_goal(job: SearchJob):
    """The example method: DiRL's shortest path, announcing itself in the step log."""
    job.on_step({"event": "example-method", "k": job.config.k})
    return shortest_path(job.graph, job.evaluator, seed=job.config.seed)


class CountingProposer(GeometricProposer):
    """The example proposer: the geometric one under another name, counting the splits it is asked for."""

    name = "counting (example, offline, not a VLM)"

    def __init__(self, seed, cap):
        super().__init__(seed=seed, max_waypoints=cap)
        self.splits = 0

    def propose_split(self, q, w, feedback=()):
        self.splits += 1
        return super().propose_split(q, w, feedback)


def parse_cap(options: str) -> int:
    if options and not options.isdigit():
        raise SpecrefineError(f"counting:{options}: give the cap as a whole number")
    return int(options or 32)


def build_counting(cap, *, spec, seed, **_):
    proposer = CountingProposer(seed, cap)
    proposer.spec = spec
    return proposer


@pytest.fixture
def registered():
    register_method("straight", straight_to_goal, "example: the input graph's shortest path", asks_proposer=False,
                    colour="#123456", knobs=("k",))
    register_proposer("counting", build_counting, parse_cap, usage="counting[:CAP]", description="example")
    yield
    del METHODS["straight"], PROPOSERS["counting"]


def test_a_registered_method_runs_everywhere_methods_are_named(registered, tmp_path):
    data = refine_maze("u_maze", method="straight", out=tmp_path, k=7, **TINY).data
    steps = [json.loads(line) for line in (tmp_path / "steps.jsonl").read_text().splitlines()]
    assert steps[0] == {"event": "example-method", "k": 7}
    assert data["method"] == "straight" and data["config"]["method"] == "straight" and data["refinements"] == 0
    assert "straight" not in PROPOSER_METHODS and METHOD_COLOURS["straight"] == "#123456"
    args = build_parser().parse_args(["refine", "u_maze", "--method", "straight"])
    assert args.method == "straight"
    cells = grid(["u_maze"], ["straight"], ["geometric", "random"], [0], w=[3, 4], k=[5, 6])
    assert sorted((c.proposer, c.w, c.k) for c in cells) == [("none", 3, 5), ("none", 3, 6)]  # no proposer, no w


def test_a_registered_proposer_runs_through_refine_maze(registered, tmp_path):
    result = refine_maze("u_maze", method="ours", proposer="counting:40", out=tmp_path, **TINY)
    assert result.data["proposer"] == "counting:40" and result.data["proposer_calls"] >= 1
    assert result.data["proposer_is_vlm"] is False
    proposer = make_proposer("counting:40", seed=0)
    assert isinstance(proposer, CountingProposer) and proposer.max_waypoints == 40 and proposer.spec == "counting:40"
    with pytest.raises(SpecrefineError, match="whole number"):
        make_proposer("counting:many")


def test_a_name_no_registry_holds_is_one_line():
    with pytest.raises(SpecrefineError, match="invalid proposer 'counting'"):
        make_proposer("counting")
    with pytest.raises(SpecrefineError, match="unknown method 'straight'"):
        refine_maze("u_maze", method="straight", out="/nonexistent/never-written", **TINY)
