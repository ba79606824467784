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


def _turning_result():
    """S -> a -> b -> G: east 4 m, east 4 m, then north 4 m (discs at the aims, b fixed at a point)."""
    def disc(name, x, y, point=None):
        return {"name": name, "region": {"type": "disc", "cx": x, "cy": y, "r": 1.0}, "point": point,
                "refines": name, "label": None}

    avoid = {"type": "box", "xmin": 20, "ymin": 20, "xmax": 21, "ymax": 21}
    graph = {"initial": "S", "finals": ["G"],
             "vertices": [disc("S", 0, 0), disc("a", 4, 0), disc("b", 7, 7, point=[8.0, 0.0]), disc("G", 8, 4)],
             "edges": [{"u": u, "v": v, "avoid": avoid, "parent": [u, v]} for u, v in ("Sa", "ab", "bG")]}
    return {"maze": "u_chain_1", "agent": "ant", "method": "ours", "proposer": "geometric", "seed": 0, "episodes": 200,
            "path": ["S", "a", "b", "G"], "graph": graph, "leg_success": [1.0, 0.99, 0.95],
            "edge_probabilities": [1.0, 1.0, 1.0], "episode_outcomes": {"success": 188, "flipped": 12}}


def test_legs_are_told_apart_by_their_turn_and_lost_episodes_pool_by_kind():
    profile = legs.leg_profile(_turning_result())
    assert profile["turn_degrees"] == [None, 0.0, 90.0]  # b's fixed point, not its disc's centre, is its aim
    assert legs.leg_episodes(profile) == [(200, 0), (200, 2), (198, 10)]
    table = legs.turn_table([profile, profile]).splitlines()
    assert table[2].startswith("| first leg | 2 | 400 | 0 | 0.0000 [")
    assert table[3].startswith("| straight | 2 | 400 | 4 | 0.0100 [")
    assert table[4].startswith("| turning | 2 | 396 | 20 | 0.0505 [")
    after = legs.turn_table([profile, profile], after=True).splitlines()
    assert [row.split(" | ")[0] for row in after[2:]] == ["| first leg", "| straight after first leg",
                                                          "| turning after straight"]
    assert after[3].startswith("| straight after first leg | 2 | 400 | 4 | 0.0100 [")
    assert after[4].startswith("| turning after straight | 2 | 396 | 20 | 0.0505 [")


def test_a_leg_is_pooled_with_the_kind_of_the_leg_before_it():
    profile = {"maze": "u_chain_1", "seed": 0, "episodes": 100, "leg_failure": [0.0, 0.01, 0.0, 0.02],
               "turn_degrees": [None, 90.0, 90.0, 0.0]}
    rows = {row.split(" | ")[0].removeprefix("| "): row.split(" | ")[1:4]
            for row in legs.turn_table([profile], after=True).splitlines()[2:]}
    assert rows == {"first leg": ["1", "100", "0"], "turning after first leg": ["1", "100", "1"],
                    "turning after turning": ["1", "99", "0"], "straight after turning": ["1", "99", "2"]}


def test_a_profile_without_turns_is_refused_in_one_line(tmp_path, capsys):
    import json

    with pytest.raises(legs.SpecrefineError, match="no turns"):
        legs.turn_table([{"maze": "u_chain_2", "seed": 0, "leg_failure": [0.1]}])
    path = tmp_path / "result.json"
    path.write_text(json.dumps(_turning_result()))
    assert legs.main([str(path), "--profiles", "--turns"]) == 0
    assert "| turning | 1 | 198 | 10 |" in capsys.readouterr().out
    assert legs.main([str(path), "--profiles", "--turns", "--after"]) == 0
    assert "| turning after straight | 1 | 198 | 10 |" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        legs.main([str(path), "--turns"])  # --turns alone: argparse's usage line, exit 2


def _report(turns, per_leg):
    return {"legs": [{"leg": k, "turn_deg": t} for k, t in enumerate(turns)],
            "walls": {"per_leg": [{"leg": k, "started": s, "flipped": f, "avoid": a, "timeout": t}
                                  for k, (s, f, a, t) in enumerate(per_leg)]}}


def test_failure_reports_pool_flips_contacts_and_timeouts_by_kind_of_leg(tmp_path, capsys):
    import json

    one = _report([None, 10.0, 90.0], [(100, 0, 1, 0), (99, 2, 0, 0), (97, 3, 1, 1)])
    two = _report([None, 120.0], [(100, 0, 0, 0), (100, 1, 0, 0)])
    rows = {r.split("|")[1].strip(): [c.strip() for c in r.strip("|").split("|")]
            for r in legs.kind_table([one, two]).splitlines()[2:]}
    assert rows["first leg"][1:6] == ["2", "200", "0", "1", "0"]
    assert rows["straight"][1:6] == ["1", "99", "2", "0", "0"]
    assert rows["turning"][1:6] == ["2", "197", "4", "1", "1"] and rows["turning"][6].startswith("0.0305 [")
    (tmp_path / "a.json").write_text(json.dumps(one))
    (tmp_path / "bad.json").write_text(json.dumps({"legs": []}))
    assert legs.main(["--failures", str(tmp_path / "a.json")]) == 0
    assert "| turning | 1 | 97 |" in capsys.readouterr().out
    assert legs.main(["--failures", str(tmp_path / "bad.json")]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_a_u_chains_name_gives_its_rooms_and_subgoals_and_nothing_else_does():
    from specrefine.core.mazes import benchmark_mazes, u_chain

    assert u_chain("u_chain_3_subgoals") == (3, True) and u_chain("u_chain_12") == (12, False)
    assert all(u_chain(bad) is None for bad in ("u_chain_", "u_chain_3_sub", "xu_chain_3", "u_chain_3 ", "u_maze"))
    chains = {n: c for n in benchmark_mazes() if (c := u_chain(n))}
    assert sorted(chains.values()) == sorted([(n, False) for n in range(1, 6)] + [(n, True) for n in range(2, 6)])
