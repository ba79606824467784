"""``specrefine official RUN_DIR``: a finished run's compositional policy in the official Gymnasium-Robotics env.

The environment is ``PointMaze_UMaze-v3`` (point mass) or ``AntMaze_UMaze-v5`` (Ant) made with the
run's own maze as ``maze_map`` (walls 1, everything else 0: hazards are free floor there), so any maze
runs, standard or not; ``env_id`` names the registered environment whose map has the same walls when
there is one.  The environment keeps its own model, reset and step; it is made with
``continuing_task=True, reset_target=False`` (never terminates and never moves its goal on reaching
it: the task is judged here, not by its reward) and a ``max_episode_steps`` that never cuts an episode
before the run's own time limit.  AntMaze is made with ``include_cfrc_ext_in_observation=False`` (the
27 values this package's policy observes).

Each episode: ``reset(options={"reset_cell": a start cell S (uniform over them), "goal_cell": the first
goal cell})`` (the environment adds its own uniform noise of +-0.25 cell to both), then
:class:`~specrefine.evaluation.compositional.CompositionalPolicy` ``act`` per step (with the run's switching rule,
``policy.json``'s ``switching_rule``: ``at-region`` for a run from before the rules were named).  An episode ends,
as in the evaluator, when the agent touches the current leg's avoid set (closer than the run's clearance), flips
(Ant), has reached every leg's goal region, or uses a leg's ``horizon`` decisions.  Its xy at every
environment step is then judged by this package's monitor on the ORIGINAL task (``result.json``'s
``input_graph``: walls and hazards avoided, the original goal reached); a flipped Ant fails.

Two of this package's reset rules can replace the environment's, one at a time or both, to find where a gap
between the simulators comes from (docs/official_env.md): ``start="package"`` moves the agent, after the
environment's reset, to a point drawn as this package's evaluator spawns (uniform in the original task's start
region, clear of walls by the spawn radius), and ``reset_noise="package"`` adds this package's reset noise
(``Agent.reset_noise``: the Ant's qpos[2:] +-0.1 uniform, qvel 0.1 N(0, 1); none for the point mass).  Their
draws come from a stream of their own, so the episodes' start cells and goal points stay those of the plain run.

An interrupted run (Ctrl-C) keeps its finished episodes in ``official.partial.json`` (``interrupted: true``,
``episodes_asked``) and writes no ``official.json``; a later complete run removes that file.

``RUN_DIR/official.json`` (written atomically; ``out`` elsewhere): ``env_id``, ``episodes``, ``success_rate``,
``success_ci`` (95 % Wilson), ``sim_success_rate`` / ``sim_success_ci`` / ``sim_episodes`` (the run's
own measurement in this package's simulator), ``outcomes``, ``seed`` and the settings used.
"""

from __future__ import annotations

import contextlib
import io
import json
import time
from pathlib import Path

import gymnasium
import numpy as np

from ..core.agents import get_agent
from ..core.errors import SpecrefineError
from ..core.records import read_result
from ..core.results import wilson_ci
from ..core.runfolder import output_file, write_atomic, writing_into
from ..core.standard_maps import to_gymnasium
from ..evaluation.compositional import CompositionalPolicy
from ..evaluation.gym_wrapper import TaskJudge
from .config import preset_text
from .progress import counted

OFFICIAL_JSON = "official.json"
RESET_RULES = ("official", "package")  # whose start / reset noise an episode begins with (module docstring)
#: agent -> (registered environment family, version, extra keyword arguments)
ENVIRONMENTS = {"point": ("PointMaze", "v3", {}), "ant": ("AntMaze", "v5", {"include_cfrc_ext_in_observation": False})}


def _gymnasium():
    """gymnasium with the Gymnasium-Robotics environments registered (its import notice on stderr swallowed)."""
    with contextlib.redirect_stderr(io.StringIO()):
        import gymnasium
        import gymnasium_robotics

        gymnasium.register_envs(gymnasium_robotics)
    return gymnasium


def env_id(maze, agent: str) -> str:
    """The registered id whose map has the maze's walls (e.g. ``AntMaze_Large-v5``), else the base id used."""
    gym = _gymnasium()
    family, version, _ = ENVIRONMENTS[agent]
    walls = to_gymnasium(maze)
    for name, spec in gym.registry.items():
        if name.startswith(f"{family}_") and name.endswith(f"-{version}") and "Dense" not in name:
            their = spec.kwargs.get("maze_map")
            if their is not None and [[int(c == 1) for c in row] for row in their] == walls:
                return name
    return f"{family}_UMaze-{version} (maze_map of the run's maze {maze.name})"


def make_env(maze, agent: str, max_episode_steps: int):
    """The official environment on ``maze``'s walls (see the module docstring)."""
    gym = _gymnasium()
    family, version, extra = ENVIRONMENTS[agent]
    env = gym.make(f"{family}_UMaze-{version}", maze_map=to_gymnasium(maze), continuing_task=True,
                   reset_target=False, max_episode_steps=max_episode_steps, **extra)
    # Gymnasium-Robotics writes the maze's model to a file in the temp folder and never removes it (one per
    # environment made); the model is loaded by now, so the file goes.
    Path(env.unwrapped.tmp_xml_file_path).unlink(missing_ok=True)
    return env


def judged_env(run_dir, seed=None, *, start: str = "official", reset_noise: str = "official",
               max_episode_steps: int | None = None) -> TaskJudge:
    """The official environment of a finished run, judged as ``specrefine official`` judges it: a
    :class:`~specrefine.evaluation.gym_wrapper.TaskJudge` (its ``policy`` the run's, matched to the environment's
    step) on the run's ORIGINAL task.  ``seed``: the episodes' start cells and goal points; ``start`` /
    ``reset_noise``: whose reset rule (module docstring); ``max_episode_steps``: default, never before the run's
    own time limit."""
    for name, rule in (("start", start), ("reset_noise", reset_noise)):
        if rule not in RESET_RULES:
            raise SpecrefineError(f"{name} {rule!r}: expected one of {', '.join(RESET_RULES)}")
    run_dir = Path(run_dir)
    result = _read_result(run_dir)
    original = _original_task(run_dir, result)
    policy = CompositionalPolicy.load(run_dir)
    agent, maze = policy.agent, policy.maze
    if (result["agent"], result["maze"]) != (agent, maze.name):
        raise SpecrefineError(f"{run_dir}: result.json is of the {result['agent']} in {result['maze']!r:.40}, "
                              f"policy.json of the {agent} in {maze.name!r:.40}: not one run's records")
    if agent not in ENVIRONMENTS:
        raise SpecrefineError(f"{run_dir}: no official Gymnasium-Robotics environment for the {agent}")
    probe = make_env(maze, agent, 1)
    policy.match_env_dt(probe.unwrapped.model.opt.timestep * _inner(probe).frame_skip)
    probe.close()
    env = make_env(maze, agent, max_episode_steps or episode_steps(policy))
    if start == "package" or reset_noise == "package":
        env = PackageReset(env, policy, original.region(original.initial) if start == "package" else None,
                           reset_noise == "package", np.random.default_rng([seed or 0, 1]))
    return TaskJudge(env, policy, original, seed=seed)


def episode_steps(policy: CompositionalPolicy) -> int:
    """Environment steps that never cut an episode before the run's own time limit (every leg's horizon)."""
    return len(policy.legs) * policy.horizon * policy.hold + 1


def run_official(run_dir, episodes: int = 200, seed: int = 0, *, start: str = "official",
                 reset_noise: str = "official", out=None) -> dict:
    """Run ``episodes`` official episodes of the run's policy; writes and returns ``RUN_DIR/official.json``
    (or ``out``).  ``start`` / ``reset_noise``: "official" (the environment's own) or "package" (this package's
    rule, module docstring)."""
    t0 = time.time()
    run_dir = Path(run_dir)
    result = _read_result(run_dir)
    target = run_dir / OFFICIAL_JSON if out is None else Path(out)
    what = "--out" if out is not None else "the record"
    with writing_into(target, what):  # checked before any episode; the run folder's lock held while writing into it
        output_file(partial_path(target), what)
        return _run(run_dir, result, episodes, seed, start, reset_noise, target, t0)


def _run(run_dir: Path, result: dict, episodes: int, seed: int, start: str, reset_noise: str, target: Path,
         t0: float) -> dict:
    """``run_official``'s episodes and record, once its outputs are checked (and its run folder's lock held)."""
    from ..evaluation.evaluator import _torch_threads

    sim = {f"sim_{key}": result.get(key) for key in ("success_rate", "success_ci", "episodes")}  # the run's own
    sim = sim if None not in sim.values() else dict.fromkeys(sim)  # measurement, whole or not at all
    env = judged_env(run_dir, seed, start=start, reset_noise=reset_noise)
    policy, maze = env.policy, env.policy.maze
    success, outcomes = [], {}
    interrupted = False
    with _torch_threads(1):  # one observation per step: fastest on one thread, and no contention with MuJoCo
        try:
            for episode in counted(range(episodes), episodes, f"official {maze.name}", "episode", leave=False):
                ok, outcome = _episode(env, seed if episode == 0 else None)
                success.append(ok)
                outcomes[outcome] = outcomes.get(outcome, 0) + 1
        except KeyboardInterrupt:
            interrupted = True
    env.close()
    k, n = int(np.sum(success)), len(success)
    data = {"env_id": env_id(maze, policy.agent), "episodes": n, "success_rate": k / n if n else 0.0,
            "success_ci": list(wilson_ci(k, n)), **sim, "outcomes": outcomes, "seed": seed, "agent": policy.agent,
            "maze": maze.name, "preset": _run_preset(result),
            "preset_text": preset_text(result | {"preset": _run_preset(result)}),
            "settings": {"env_dt": policy.env_dt, "hold": policy.hold, "control_period": policy.control_period,
                         "horizon_per_leg": policy.horizon, "legs": len(policy.legs),
                         "max_episode_steps": episode_steps(policy), "continuing_task": True, "reset_target": False,
                         "clearance": policy.clearance, "start": start, "reset_noise": reset_noise,
                         "switching": policy.switching},
            "wall_seconds": time.time() - t0}
    partial = partial_path(target)
    if interrupted:  # keep the finished episodes beside, never as, the complete record
        write_atomic(partial, json.dumps({**data, "interrupted": True, "episodes_asked": episodes}, indent=2))
        raise KeyboardInterrupt
    partial.unlink(missing_ok=True)
    write_atomic(target, json.dumps(data, indent=2))
    return data


def _episode(env: TaskJudge, seed) -> tuple[bool, str]:
    """One episode to its end, as docs/official_env.md's loop runs it: (success on the original task, outcome)."""
    obs, info = env.reset(seed=seed)
    terminated = truncated = False
    while not (terminated or truncated):
        obs, _, terminated, truncated, info = env.step(env.policy.act(obs))
    return info["task_success"], info["outcome"]


class PackageReset(gymnasium.Wrapper):
    """The environment's reset, then this package's start and/or reset noise (module docstring)."""

    def __init__(self, env, policy: CompositionalPolicy, start_region, noise: bool, rng):
        super().__init__(env)
        self.policy, self.start_region, self.noise, self.rng = policy, start_region, noise, rng

    def reset(self, *, seed=None, options=None):
        _, info = self.env.reset(seed=seed, options=options)
        return _reset_as_package(self.env, self.policy, self.start_region, self.noise, self.rng), info


def partial_path(target) -> Path:
    """Where an interrupted run keeps its finished episodes: ``official.partial.json`` beside ``official.json``."""
    target = Path(target)
    return target.with_name(f"{target.stem}.partial{target.suffix}")


def _reset_as_package(env, policy: CompositionalPolicy, start_region, noise: bool, rng) -> dict:
    """After the environment's reset: the agent moved to a package spawn point in ``start_region`` (if given)
    and/or given the package's reset noise; the observation of that state."""
    inner = _inner(env)
    qpos, qvel = inner.data.qpos.copy(), inner.data.qvel.copy()
    if start_region is not None:
        qpos[:2] = policy.spawn_point(start_region, rng)
    scale = get_agent(policy.agent).reset_noise
    if noise and scale:
        qpos[2:] += rng.uniform(-scale, scale, size=len(qpos) - 2)
        qvel += scale * rng.standard_normal(len(qvel))
    inner.set_state(qpos, qvel)
    inner_obs = inner._get_obs()  # PointEnv returns (obs, info), the Ant's env the array
    return env.unwrapped._get_obs(inner_obs[0] if isinstance(inner_obs, tuple) else inner_obs)


def _inner(env):
    """The MuJoCo env inside a Gymnasium-Robotics maze env (its frame_skip)."""
    maze_env = env.unwrapped
    return getattr(maze_env, "point_env", None) or maze_env.ant_env


def _original_task(run_dir: Path, result: dict):
    from ..core.graph import TaskGraph

    try:
        return TaskGraph.from_dict(result["input_graph"])
    except (KeyError, TypeError, ValueError) as exc:
        raise SpecrefineError(f"{run_dir / 'result.json'}: no usable input_graph ({type(exc).__name__})") from None


def _read_result(run_dir: Path) -> dict:
    """The run's result.json, checked by the records' schema, with the task the episodes are judged on."""
    path = run_dir / "result.json"
    if not path.exists() and not path.is_symlink():
        raise SpecrefineError(f"{path}: not found: RUN_DIR must be a finished 'specrefine refine' run folder")
    result = read_result(path)
    if "input_graph" not in result:
        raise SpecrefineError(f"{path}: no input_graph (the original task the episodes are judged on)")
    return result


def _run_preset(result: dict) -> str:
    """The run's preset, from its result.json ("none": a run from before presets, whose settings it records)."""
    preset = result.get("preset")
    return preset if preset in ("best", "paper") else "none"


def summary(data: dict) -> str:
    lo, hi = data["success_ci"]
    line = (f"official {data['env_id']}: success on the original task {data['success_rate']:.3f} "
            f"(95% CI {lo:.3f}-{hi:.3f}, {data['episodes']} episodes; the run's preset: "
            f"{data.get('preset_text', data.get('preset', '?'))}")
    rule = (data.get("settings") or {}).get("switching", "at-region")
    line += ")" if rule == "at-region" else f"; switching: {rule})"
    if data.get("sim_success_rate") is not None:
        slo, shi = data["sim_success_ci"]
        line += (f"\nthis package's simulator: {data['sim_success_rate']:.3f} (95% CI {slo:.3f}-{shi:.3f}, "
                 f"{data['sim_episodes']} episodes)")
    return line
