"""Evaluator throughput.  ``python -m specrefine.bench evaluator --agent {point,ant} [--batch 32]``

:func:`bench_evaluator` returns one dict (the subcommand prints it as ONE JSON line).
``env_steps_per_s`` is measured through the evaluator's real code path
(:meth:`specrefine.evaluation.evaluator.Evaluator.evaluate`: start sampling, policy in the loop, observation,
batched physics, region checks, bookkeeping), counting every simulated environment step.  In the
same run it measures the raw ceiling of the same MuJoCo model: ``mujoco.rollout`` stepping the same
batch with random controls, as one long call (``raw_rollout_steps_per_s``) and one call per
control step (``raw_per_step_steps_per_s``, what any step-wise loop pays), and reports the ratios.
The two are interleaved over a few rounds (medians reported).  Because wall-clock rates swing when
other jobs share the cores, the same work is also reported per CPU-second of this process
(``*_per_cpu_s``, ``cpu_ratio_vs_raw_rollout``).

:func:`bench_gymenv` (``python -m specrefine.bench gymenv``) is the usual "one gym env per rollout" way for
comparison: ``torchrl.envs.GymEnv`` around Gymnasium-Robotics' maze, one environment, random actions.
"""

from __future__ import annotations

import os
import platform
import time
from pathlib import Path

import numpy as np

from ..core.agents import get_agent
from ..core.mazes import load_maze


def open_room(agent: str, cells: int | None = None):
    """A square room with walls only around it; S in the centre, G in the middle of the top row.

    Rollouts of an untrained (or trained) policy neither hit walls nor reach G within the horizon, so
    every batch runs full length: the loop's steady-state cost, not early exits, is measured.
    """
    from ..core.mazes import parse_maze

    cells = cells or get_agent(agent).bench_room_cells
    rows = ["#" * cells] + ["#" + "." * (cells - 2) + "#" for _ in range(cells - 2)] + ["#" * cells]
    mid = cells // 2
    rows[mid] = rows[mid][:mid] + "S" + rows[mid][mid + 1:]
    rows[1] = rows[1][:mid] + "G" + rows[1][mid + 1:]
    return parse_maze("\n".join(rows), "open_room").for_agent(agent)


def _cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def _policy(agent: str):
    from ..sim.policy import POLICY_DIR, GoalPolicy, load_policy

    path = POLICY_DIR / f"{agent}.pt"
    if path.exists():
        return load_policy(agent), f"shipped {path.relative_to(POLICY_DIR.parent.parent)}"
    return GoalPolicy(agent).eval(), "fresh GoalPolicy (untrained, 2x256)"


def _raw_rollout(model, n: int, frame_skip: int, nthread: int, steps: int, rng) -> tuple[float, float, float]:
    """Steps/s of mujoco.rollout on the same model: one long call (wall and CPU time), and one call per step."""
    import mujoco
    from mujoco import rollout

    datas = [mujoco.MjData(model) for _ in range(nthread)]
    d = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    s0 = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, d, s0, spec)
    state0 = np.tile(s0, (n, 1))
    models = [model] * n
    lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
    ctrl = np.repeat(rng.uniform(lo, hi, size=(n, steps, 1, model.nu)), frame_skip, axis=2).reshape(n, -1, model.nu)
    with rollout.Rollout(nthread=nthread if nthread > 1 else 0) as pool:
        out = np.zeros((n, steps * frame_skip, state0.shape[1]))
        pool.rollout(models, datas, state0, ctrl[:, : 10 * frame_skip], nstep=10 * frame_skip, skip_checks=True)
        t, c = time.perf_counter(), time.process_time()
        pool.rollout(models, datas, state0, ctrl, nstep=steps * frame_skip, state=out, skip_checks=True)
        long_call = n * steps / (time.perf_counter() - t)
        long_cpu = n * steps / (time.process_time() - c)
        state = state0.copy()
        out1 = np.zeros((n, frame_skip, state0.shape[1]))
        t = time.perf_counter()
        for k in range(steps):
            c = np.ascontiguousarray(ctrl[:, k * frame_skip:(k + 1) * frame_skip])
            pool.rollout(models, datas, state, c, nstep=frame_skip, state=out1, skip_checks=True)
            state[:] = out1[:, -1]
        per_step = n * steps / (time.perf_counter() - t)
    return long_call, per_step, long_cpu


def _recorded_steps(ev, maze, seed: int) -> list[tuple[int, np.ndarray, np.ndarray, int]]:
    """One evaluation's physics calls as (rows, states before, controls, physics steps) per control step, for
    :func:`_replay` (each of the evaluator's built sims reports its physics calls while it runs)."""
    calls = []

    def record(states, ctrl, nstep):
        calls.append((len(states), states.copy(), ctrl.copy(), nstep))

    sims = ev.built_sims
    for sim in sims:
        sim.physics_observer = record
    try:
        ev.evaluate(maze.start, maze.goal, maze.walls, seed=seed)
    finally:
        for sim in sims:
            sim.physics_observer = None
    return calls


def _replay(model, calls, nthread: int) -> tuple[float, float]:
    """Steps/s (wall, CPU) of mujoco.rollout redoing exactly the recorded calls: the same states, controls and
    batch sizes, one call per control step as the evaluator makes them; the evaluator's own ceiling."""
    import mujoco
    from mujoco import rollout

    datas = [mujoco.MjData(model) for _ in range(nthread)]
    outs = {}
    with rollout.Rollout(nthread=nthread if nthread > 1 else 0) as pool:
        t, c = time.perf_counter(), time.process_time()
        for n, initial, ctrl, nstep in calls:
            out = outs.setdefault((n, nstep), np.zeros((n, nstep, initial.shape[1])))
            pool.rollout([model] * n, datas, initial, ctrl, nstep=nstep, state=out, skip_checks=True)
        steps = sum(n for n, *_ in calls)
        return steps / (time.perf_counter() - t), steps / (time.process_time() - c)


def bench_evaluator(agent: str = "point", batch: int = 32, seconds: float = 6.0, horizon: int | None = None,
                    torch_threads: int = 1, nthread: int | None = None, scenario: str = "open",
                    rounds: int = 3) -> dict:
    """Evaluator env steps/s and the raw mujoco.rollout ceiling, interleaved over ``rounds`` rounds (medians)."""
    import mujoco
    import torch

    from ..evaluation.evaluator import Evaluator

    torch.set_num_threads(torch_threads)
    maze = open_room(agent) if scenario == "open" else load_maze(scenario).for_agent(agent)
    policy, policy_note = _policy(agent)
    ev = Evaluator(maze, agent, policy, n=batch, horizon=horizon, seed=0, nthread=nthread)
    sim = ev.sim(batch)
    ev.evaluate(maze.start, maze.goal, maze.walls, seed=10_000)  # warm-up: builds the sims, touches every path
    rng = np.random.default_rng(0)
    evals, raws, per_steps, outcomes, seed, total_steps, total_time = [], [], [], {}, 0, 0, 0.0
    evals_cpu, raws_cpu, replays, replays_cpu = [], [], [], []
    calls = _recorded_steps(ev, maze, seed=20_000)  # the work of one evaluation, replayed raw each round
    for _ in range(rounds):
        ev.sim_steps = 0
        t0, c0 = time.perf_counter(), time.process_time()
        while True:
            res = ev.evaluate(maze.start, maze.goal, maze.walls, seed=seed)
            seed += 1
            for k, v in res.counts().items():
                outcomes[k] = outcomes.get(k, 0) + v
            if time.perf_counter() - t0 >= seconds / rounds:
                break
        dt = time.perf_counter() - t0
        evals.append(ev.sim_steps / dt)
        evals_cpu.append(ev.sim_steps / (time.process_time() - c0))
        total_steps, total_time = total_steps + ev.sim_steps, total_time + dt
        raw_long, raw_step, raw_cpu = _raw_rollout(sim.model, batch, sim.frame_skip, sim.nthread,
                                                   min(ev.horizon, 200), rng)
        raws.append(raw_long)
        raws_cpu.append(raw_cpu)
        per_steps.append(raw_step)
        replay, replay_cpu = _replay(sim.model, calls, sim.nthread)
        replays.append(replay)
        replays_cpu.append(replay_cpu)
    env_sps, raw_long, raw_step, env_cpu, raw_cpu, same, same_cpu = (
        float(np.median(x)) for x in (evals, raws, per_steps, evals_cpu, raws_cpu, replays, replays_cpu))
    return {
        "bench": "evaluator", "agent": agent, "batch": batch, "env_steps_per_s": round(env_sps, 1),
        "raw_rollout_steps_per_s": round(raw_long, 1), "ratio_vs_raw_rollout": round(env_sps / raw_long, 3),
        "raw_per_step_steps_per_s": round(raw_step, 1), "ratio_vs_raw_per_step": round(env_sps / raw_step, 3),
        # per CPU-second of this process (all threads): robust when other jobs share the cores
        "env_steps_per_cpu_s": round(env_cpu, 1), "raw_rollout_steps_per_cpu_s": round(raw_cpu, 1),
        "cpu_ratio_vs_raw_rollout": round(env_cpu / raw_cpu, 3),
        # the same physics (the evaluator's recorded states, controls and batch sizes) through mujoco.rollout alone:
        # random controls keep an Ant standing, a policy makes it run, and running costs more per step
        "raw_same_work_steps_per_s": round(same, 1), "ratio_vs_same_work": round(env_sps / same, 3),
        "cpu_ratio_vs_same_work": round(env_cpu / same_cpu, 3),
        "rounds": rounds, "per_round_ratio": [round(e / r, 3) for e, r in zip(evals, raws, strict=True)],
        "evaluations": seed, "env_steps": total_steps, "seconds": round(total_time, 2), "horizon": ev.horizon,
        "scenario": maze.name, "outcomes": outcomes, "policy": policy_note,
        "integrator": {0: "Euler", 1: "RK4"}.get(int(sim.model.opt.integrator), str(int(sim.model.opt.integrator))),
        "timestep": float(sim.model.opt.timestep), "frame_skip": sim.frame_skip, "mujoco_nthread": sim.nthread,
        "torch_threads": torch.get_num_threads(), "cpus": os.cpu_count(), "cpu": _cpu_name(),
        "load_avg_1m": round(os.getloadavg()[0], 2), "mujoco": mujoco.__version__, "torch": torch.__version__,
    }



GYM_IDS = {"ant": "AntMaze_UMaze-v5", "point": "PointMaze_UMaze-v3"}


def bench_gymenv(agent: str, steps: int = 2000) -> dict:
    try:
        import gymnasium as gym
        import gymnasium_robotics
        from torchrl.envs import GymEnv

        gym.register_envs(gymnasium_robotics)
        env = GymEnv(GYM_IDS[agent])
        env.set_seed(0)
        env.rollout(50, break_when_any_done=False)  # warm-up
        t = time.perf_counter()
        env.rollout(steps, break_when_any_done=False)
        dt = time.perf_counter() - t
        env.close()
        return {"env": GYM_IDS[agent], "steps": steps, "env_steps_per_s": round(steps / dt, 1)}
    except Exception as e:  # not installed / cannot build here
        return {"env": GYM_IDS[agent], "skipped": f"{type(e).__name__}: {str(e)[:200]}"}
