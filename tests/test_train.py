"""PPO training (tiny seeded point run), policy checkpoints, one-line errors on bad files; open-floor evaluation."""

import json

import numpy as np
import pytest
import torch

from specrefine.core.errors import SpecrefineError
from specrefine.sim.curves import read_log
from specrefine.sim.policy import GoalPolicy, PolicyError, load_policy, save_policy
from specrefine.sim.policy_eval import evaluate_reach
from specrefine.sim.train import Config, Trainer, main, make_config


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("point_run")
    cfg = make_config("point", frames=61_440, seed=0, checkpoint_every_s=1e9)
    path = Trainer(cfg, out, progress=False).train()
    return out, path


def test_tiny_training_run_improves_success(tiny_run):
    out, path = tiny_run
    torch.manual_seed(0)
    untrained = evaluate_reach(GoalPolicy("point"), episodes=200, seed=5)
    trained = evaluate_reach(load_policy(path), episodes=200, seed=5)
    assert trained["success_rate"] >= untrained["success_rate"] + 0.3, (untrained["success_rate"],
                                                                          trained["success_rate"])
    rows = read_log(out / "log.jsonl")
    assert rows[-1]["frames"] >= 61_440 and all(r["fps"] > 0 for r in rows)
    for key in ("approx_kl", "clip_fraction", "entropy", "value_loss", "explained_variance"):  # PPO diagnostics
        assert all(np.isfinite(r[key]) for r in rows), key
    assert all(0.0 <= r["clip_fraction"] <= 1.0 and r["explained_variance"] <= 1.0 for r in rows)
    assert (out / "curve.png").stat().st_size > 1000 and (out / "checkpoint.pt").is_file()


def test_training_curve_has_the_ppo_diagnostics_panels(tiny_run, tmp_path):
    from specrefine.sim.curves import plot_curve

    out, _ = tiny_run
    rows = read_log(out / "log.jsonl")
    fig = plot_curve(out / "log.jsonl")
    panels = {ax.get_title(): ax for ax in fig.axes}
    for key in ("approx_kl", "clip_fraction", "entropy", "explained_variance", "value_loss", "success_rate"):
        assert key in panels, (key, sorted(panels))
        raw = panels[key].get_lines()[0].get_ydata()  # the faint line: the log's values, one per batch
        np.testing.assert_allclose(raw, [r[key] for r in rows])
    old = tmp_path / "log.jsonl"  # a log from before the diagnostics: those panels say so, no error
    old.write_text("\n".join(json.dumps({"frames": i, "success_rate": 0.5, "return": 1.0, "fps": 9.0})
                             for i in (10, 20, 30)))
    panels = {ax.get_title(): ax for ax in plot_curve(old).axes}
    assert not panels["approx_kl"].get_lines() and panels["approx_kl"].texts[0].get_text() == "not in this log"


def test_resume_continues_from_checkpoint(tiny_run, tmp_path):
    out, _ = tiny_run
    import shutil

    run = tmp_path / "run"
    shutil.copytree(out, run)
    before = read_log(run / "log.jsonl")[-1]["frames"]
    trainer = Trainer(make_config("point", frames=before + 2048, seed=0), run, resume=True, progress=False)
    assert trainer.frames == before
    trainer.train()
    assert read_log(run / "log.jsonl")[-1]["frames"] == before + 2048


def test_checkpoint_round_trip(tmp_path):
    torch.manual_seed(1)
    pol = GoalPolicy("ant")
    pol.norm.update(torch.randn(100, 29) * 3 + 1)
    save_policy(pol, tmp_path / "ant.pt", {"note": "x"})
    back = load_policy(tmp_path / "ant.pt")
    assert back.agent == "ant" and back.fingerprint == pol.fingerprint and back.meta == {"note": "x"}
    obs = np.random.default_rng(0).normal(size=(5, 29)).astype(np.float32)
    np.testing.assert_array_equal(back.act(obs), pol.act(obs))
    assert (tmp_path / "ant.pt").stat().st_size < 1_000_000
    pol.net[0].bias.data += 1
    assert pol.fingerprint != back.fingerprint


def _one_line_error(path, match):
    with pytest.raises(PolicyError, match=match) as e:
        load_policy(path)
    assert "\n" not in str(e.value) and isinstance(e.value, SpecrefineError)


def test_corrupt_truncated_or_wrong_files_fail_in_one_line(tmp_path):
    good = tmp_path / "good.pt"
    save_policy(GoalPolicy("point"), good)
    data = good.read_bytes()
    (tmp_path / "truncated.pt").write_bytes(data[: len(data) // 2])
    _one_line_error(tmp_path / "truncated.pt", "not a readable policy file")
    (tmp_path / "garbage.pt").write_bytes(b"\x00garbage" * 50)
    _one_line_error(tmp_path / "garbage.pt", "not a readable policy file")
    torch.save({"weights": torch.zeros(3)}, tmp_path / "other.pt")
    _one_line_error(tmp_path / "other.pt", "not a specrefine policy file")
    blob = torch.load(good, weights_only=True)
    blob["state_dict"]["net.0.weight"] = torch.zeros(256, 7)
    torch.save(blob, tmp_path / "shape.pt")
    _one_line_error(tmp_path / "shape.pt", "weights do not fit")
    blob["version"] = 99
    torch.save(blob, tmp_path / "version.pt")
    _one_line_error(tmp_path / "version.pt", "version 99")
    _one_line_error(tmp_path / "missing.pt", "not found")


def test_shipped_point_policy_loads():
    pol = load_policy("point")
    assert pol.agent == "point" and len(pol.fingerprint) == 12
    assert np.abs(pol.act(np.zeros((3, 4), np.float32))).max() <= 1.0


def test_chained_goal_evaluation_accounts_for_every_episode():
    from specrefine.sim.policy_eval import evaluate_chain

    res = evaluate_chain(load_policy("point"), episodes=64, goals=4, seed=3)
    arrived = [res["episodes"]] + res["reached"][:-1]  # episodes that set out for each goal
    for i in range(4):
        assert res["reached"][i] + res["flipped"][i] + res["timed_out"][i] == arrived[i]
    assert res["flipped"] == [0, 0, 0, 0]  # a point mass cannot flip
    assert res["success_rate"] == res["reached"][-1] / 64 >= 0.9  # the shipped point policy chains goals


def test_init_starts_from_another_runs_weights(tiny_run, tmp_path):
    out, path = tiny_run
    trainer = Trainer(make_config("point", frames=2048, seed=1, init=str(out / "checkpoint.pt")), tmp_path / "ft",
                      progress=False)
    assert trainer.frames == 0 and trainer.policy.fingerprint == load_policy(path).fingerprint
    (tmp_path / "junk.pt").write_bytes(b"not a checkpoint")
    with pytest.raises(SpecrefineError, match="--init .*junk.pt: not a trainer checkpoint"):
        Trainer(make_config("point", frames=2048, init=str(tmp_path / "junk.pt")), tmp_path / "ft2", progress=False)


def test_every_config_field_is_a_documented_option(capsys):
    from dataclasses import fields

    with pytest.raises(SystemExit):
        main(["--agent", "point", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for f in fields(Config):
        if f.name != "agent":
            assert "--" + f.name.replace("_", "-") in text and f.metadata["help"].split(" (")[0][:30] in text, f.name


def test_notebook_imports_from_train_still_work():
    """Notebook 01 imports the evaluation and its figures from specrefine.sim.train; they live in policy_eval,
    curves."""
    from specrefine.sim import curves, policy_eval, train

    for name in ("evaluate_chain", "evaluate_reach", "summary", "success_by_distance"):
        assert getattr(train, name) is getattr(policy_eval, name)
    for name in ("plot_curve", "plot_rollouts", "plot_success_by_distance", "read_log"):
        assert getattr(train, name) is getattr(curves, name)


def test_init_from_a_policy_file_trains_the_fresh_critic_alone_first(tiny_run, tmp_path):
    out, path = tiny_run
    cfg = make_config("point", frames=4096, seed=1, init=str(path), critic_warmup_frames=2048, lateral_cost=0.3,
                      switch_radius=(0.3, 0.6), checkpoint_every_s=1e9)
    trainer = Trainer(cfg, tmp_path / "ft", progress=False)
    shipped = load_policy(path)
    assert trainer.frames == 0 and trainer.policy.fingerprint == shipped.fingerprint
    assert trainer.env.task.lateral_cost == 0.3 and trainer.env.task.goal_radius == (0.3, 0.6)
    actor = {k: v.clone() for k, v in trainer.policy.net.state_dict().items()}
    critic = [p.detach().clone() for p in trainer.critic.parameters()]
    batch = trainer.collector.collect()
    trainer.update(batch)  # inside the warm-up: the critic moves, the actor does not
    for k, v in trainer.policy.net.state_dict().items():
        torch.testing.assert_close(v, actor[k], rtol=0, atol=0)
    assert any(not torch.equal(a, b.detach()) for a, b in zip(critic, trainer.critic.parameters()))
    trainer.frames = 2048
    trainer.update(trainer.collector.collect())  # after it: both
    assert any(not torch.equal(v, actor[k]) for k, v in trainer.policy.net.state_dict().items())
    with pytest.raises(SpecrefineError, match="a point policy, not one for the ant"):
        Trainer(make_config("ant", frames=2048, init=str(path)), tmp_path / "ft3", progress=False)


def test_a_bad_switch_radius_is_one_line(capsys, tmp_path):
    assert main(["--agent", "point", "--out", str(tmp_path / "r"), "--switch-radius", "1.0", "0.5"]) == 2
    assert "needs 0 < LO <= HI" in capsys.readouterr().err


def test_a_policy_file_records_its_observation_frame(tmp_path):
    from specrefine.sim.policy import GoalPolicy, load_policy, save_policy

    world = load_policy("ant")
    heading = GoalPolicy("ant", observation_frame="heading")
    heading.load_state_dict(world.state_dict())
    save_policy(heading, tmp_path / "h.pt")
    back = load_policy(tmp_path / "h.pt")
    assert (world.observation_frame, back.observation_frame) == ("world", "heading")
    assert back.fingerprint != world.fingerprint  # the same weights fed another observation: another policy
    assert load_policy("ant").fingerprint == world.fingerprint  # files without the header stay "world"


def test_training_among_walls_runs_and_logs_wall_touches(tmp_path, capsys):
    cfg = make_config("point", frames=4_096, seed=0, checkpoint_every_s=1e9, train_maze="random:3x3:0",
                      wall_penalty=1.0, goals_per_episode=4)
    Trainer(cfg, tmp_path / "walls", progress=False).train()
    rows = read_log(tmp_path / "walls" / "log.jsonl")
    assert rows and all("wall_rate" in r for r in rows)
    assert all(0.0 <= r["wall_rate"] <= 1.0 for r in rows if r["episodes"])
    for bad in ("random:3:0", "random:axb:1", "random:1x4:0"):
        assert main(["--agent", "point", "--out", str(tmp_path / "r"), "--train-maze", bad]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and ("train-maze" in err or "random maze" in err)


def test_a_wall_penalty_without_walls_is_one_line_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "open"
    assert main(["--agent", "point", "--out", str(out), "--wall-penalty", "5"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--wall-penalty needs --train-maze" in err and not out.exists()


def test_the_batch_collector_collects_what_torchrl_s_collector_did(tmp_path):
    """Same seed, same batches (resets included): the lean collector only drops TorchRL's per-step machinery."""
    from torchrl.collectors import Collector

    from specrefine.sim.collect import BatchCollector

    def trainer():
        return Trainer(make_config("point", seed=3, num_envs=8, steps_per_env=70, checkpoint_every_s=1e9),
                       tmp_path / "run", progress=False)

    ref = trainer()  # the old way: TorchRL's Collector on the trainer's env and actor, from the env's first state
    ref.env.rng = np.random.default_rng(3)
    torch.manual_seed(11)
    col = Collector(ref.env, ref.actor, frames_per_batch=8 * 70, total_frames=-1, auto_register_policy_transforms=False)
    it = iter(col)
    theirs = [next(it), next(it)]
    col.shutdown()
    ours_trainer = trainer()
    torch.manual_seed(11)
    ours = [ours_trainer.collector.collect() for _ in range(2)]
    assert isinstance(ours_trainer.collector, BatchCollector)
    assert sum(int(b["next", "done"].sum()) for b in ours) > 0  # episodes ended and were reset within the batches
    for a, b in zip(theirs, ours, strict=True):
        for key in b.keys(True, True):
            torch.testing.assert_close(b[key], a[key], rtol=0, atol=0, msg=str(key))


@pytest.mark.parametrize("entropy_coef", [0.0, 0.01])
def test_the_ppo_update_computes_torchrl_s_gae_and_clipped_loss(tmp_path, entropy_coef):
    from torchrl.objectives.value import GAE

    cfg = make_config("point", seed=4, num_envs=8, steps_per_env=70, entropy_coef=entropy_coef,
                      checkpoint_every_s=1e9)
    tr = Trainer(cfg, tmp_path / "run", progress=False)
    batch = tr.collector.collect()
    tr.policy.norm.update(batch["observation"])  # a normaliser away from identity, as during training
    ref = batch.clone()
    with torch.no_grad():
        GAE(gamma=cfg.gamma, lmbda=cfg.gae_lambda, value_network=tr.critic, average_gae=False)(ref)
    from specrefine.sim.ppo import add_advantages

    add_advantages(batch, tr.value, cfg.gamma, cfg.gae_lambda)
    for key in ("state_value", "advantage", "value_target"):
        torch.testing.assert_close(batch[key], ref[key], rtol=1e-5, atol=1e-5, msg=key)
    mb = batch.reshape(-1)[torch.randperm(8 * 70)[:256]]
    results = []
    for loss in (tr.loss, tr.ppo):  # TorchRL's, then ours, from the same random state
        torch.manual_seed(7)
        out = loss(mb)
        total = out["loss_objective"] + out["loss_critic"] + out["loss_entropy"]
        tr.optim.zero_grad()
        total.backward()
        grads = [p.grad.clone() for p in tr.loss.parameters()]
        keys = ("loss_objective", "loss_critic", "loss_entropy", "kl_approx", "clip_fraction", "entropy")
        results.append(({k: float(out[k].detach()) for k in keys}, grads))
    (theirs, their_grads), (ours, our_grads) = results
    assert ours == pytest.approx(theirs, rel=1e-5, abs=1e-6)
    for a, b in zip(their_grads, our_grads, strict=True):
        torch.testing.assert_close(b, a, rtol=1e-4, atol=1e-6)


def test_turning_chain_evaluation_and_a_bad_turn_range(capsys):
    from specrefine.sim.policy_eval import evaluate_chain

    plain = evaluate_chain(load_policy("point"), episodes=32, goals=3, seed=3)
    turning = evaluate_chain(load_policy("point"), episodes=32, goals=3, seed=3, turn=(90.0, 180.0))
    assert turning["turn_degrees"] == [90.0, 180.0] and "turn_degrees" not in plain
    assert turning["reached"][0] == plain["reached"][0]  # the first goal is the same, only the later ones turn
    assert turning["mean_switch_speed_mps"] >= 0.0
    for args in (["--turn-goals", "90", "200"], ["--turn-goals", "-1", "10"]):
        assert main(["--agent", "point", "--evaluate", "point", "--chain", "3", *args]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "--turn-goals" in err
    assert main(["--agent", "point", "--evaluate", "point", "--turn-goals", "45", "180"]) == 2
    assert "needs --chain" in capsys.readouterr().err


def test_turn_goals_reach_the_training_env_and_refuse_a_maze(tmp_path):
    trainer = Trainer(make_config("point", frames=2048, seed=0, goals_per_episode=3, turn_goals=(45, 180)),
                      tmp_path / "turn", progress=False)
    assert trainer.env.turn == (45.0, 180.0)
    assert Trainer(make_config("point", frames=2048, seed=0), tmp_path / "plain", progress=False).env.turn is None
    with pytest.raises(SpecrefineError, match="open floor"):
        make_config("point", turn_goals=(45, 180), train_maze="random:3x3:0")


def test_sampled_training_goal_points_need_a_training_maze(tmp_path, capsys):
    out = tmp_path / "open"
    assert main(["--agent", "point", "--out", str(out), "--train-goal-points", "sampled"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "needs --train-maze" in err and not out.exists()
    cfg = make_config("point", train_maze="random:3x3:0", train_goal_points="sampled", goals_per_episode=4)
    assert Trainer(cfg, tmp_path / "walls", progress=False).env.goal_points == "sampled"


def test_the_update_runs_on_its_own_torch_threads_and_gives_them_back(tmp_path):
    tr = Trainer(make_config("point", seed=0, num_envs=8, steps_per_env=32, update_threads=2, checkpoint_every_s=1e9),
                 tmp_path / "run", progress=False)
    seen = []
    step = tr.optim.step
    tr.optim.step = lambda *a, **k: (seen.append(torch.get_num_threads()), step(*a, **k))[1]
    tr.update(tr.collector.collect())
    assert set(seen) == {2} and torch.get_num_threads() == 1  # the collection keeps torch_threads
