"""specrefine.experiments.legs: legs per room and per-leg failure pool episodes over seeds."""
import pytest

from specrefine.experiments import legs


def _run(seed, rate, path_edges):
    return {"maze": "u_chain_2", "method": "ours", "proposer": "geometric", "policy": "/x/ant_stage4.pt",
            "seed": seed, "success_rate": rate, "episodes": 200, "path_edges": path_edges, "evaluations": 100,
            "sim_steps": 1000, "wall_seconds": 10.0}


def test_a_line_pools_episodes_and_gives_legs_per_room_and_per_leg_failure():
    line = legs.line(("u_chain_2", "ours", "geometric", "ant_stage4.pt"), [_run(0, 0.9, 10), _run(1, 0.8, 14)])
    cells = [c.strip() for c in line.strip("|").split("|")]
    assert cells[4] == "2" and cells[5].startswith("0.850 [")  # 340 of 400 episodes
    assert cells[6] == "12.0" and cells[7] == "6.0"  # mean legs, over two rooms
    assert float(cells[8]) == pytest.approx(1 - 0.85 ** (1 / 12), abs=1e-4)
    assert legs.rooms("u_chain_5_subgoals") == 5 and legs.rooms("or_maze") is None
