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


def test_leg_profiles_say_how_the_lost_episodes_spread_over_the_legs(tmp_path):
    import json

    result = {"maze": "u_chain_2", "agent": "ant", "method": "ours", "proposer": "geometric", "seed": 0, "path": [],
              "graph": {}, "leg_success": [1.0, 0.9, 0.99, 1.0, 0.98], "edge_probabilities": [1.0, 0.75, 1.0, 1.0, 1.0],
              "episode_outcomes": {"success": 170, "avoid": 20, "flipped": 10}}
    profile = legs.leg_profile(result)
    assert profile["leg_failure"] == pytest.approx([0.0, 0.1, 0.01, 0.0, 0.02])
    assert legs.worst_share(profile["leg_failure"]) == pytest.approx(0.1 / 0.13)  # the worst 1 of 5 legs
    line = legs.profile_table([profile]).splitlines()[-1]
    assert line == "| u_chain_2 | 0 | 5 | 3 | 1 | 0.100 | 0.77 | 20 / 10 / 0 |"
    path = tmp_path / "result.json"
    path.write_text(json.dumps(result))
    assert legs.main([str(path), "--profiles", "--out", str(tmp_path / "p.json")]) == 0
    assert json.loads((tmp_path / "p.json").read_text()) == [profile]
    path.write_text("[1, 2]")
    assert legs.main([str(path), "--profiles"]) == 2  # not a result.json: one line, exit 2
