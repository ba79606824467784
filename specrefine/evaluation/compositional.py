"""The compositional policy a run outputs, as an object for an ordinary Gymnasium loop.

It holds the refined path (one leg per edge of the chosen path of the refined graph: the goal region
I(v), the avoid set O(u, v) and v's fixed goal point, if any), the goal-conditioned policy and the
goal-switching rule of :meth:`specrefine.evaluation.evaluator.Evaluator.run_compositional`:

* at ``reset`` every leg gets its goal point: the vertex's fixed point (a run with ``goal_points="centre"``
  records its goal regions' centres as fixed points), else a point drawn uniformly in its goal region at least
  ``clearance`` from walls and hazards (``Evaluator.sample_free``, the evaluator's own rule and code);
* at every decision the agent's position is checked first: while it lies in the current leg's goal
  region the policy moves on to the next leg (several at once if the regions overlap); then the goal
  policy is fed the current leg's goal point (the last leg's once all are done);
* a goal policy with look-ahead (``GoalPolicy.lookahead``) is also fed the next leg's goal point (on the last leg,
  the last leg's own; while the switching rule holds a leg's start, that leg's point), as the evaluator feeds it;
* ``switching`` names when it is fed that point (:mod:`specrefine.sim.switching`): ``at-region`` (the
  paper's, the default) at once; ``slow-turn`` first holds a leg that starts with the torso moving fast and away
  from its goal point, feeding the agent's own position until the rule lets go (the evaluator's rule and code).

``act`` takes a Gymnasium-Robotics maze observation (the dict of ``PointMaze_*-v3`` /
``AntMaze_*-v5``): the agent's xy is ``achieved_goal``; ``observation`` is qpos and qvel of the
point mass (x, y, vx, vy) or qpos without x, y and qvel of the Ant (27 values: build AntMaze with
``include_cfrc_ext_in_observation=False``), from which the torso's heading is read (quaternion at
``observation[1:5]``).  It builds this package's policy observation from them exactly as
:meth:`specrefine.sim.simulator.BatchedSim.observe` does, and returns the control this package's simulator
would apply (clipped to [-1, 1]; for the point mass, to the unit disc).

``env_dt`` (seconds between ``act`` calls) keeps this package's control period
(``Agent.timestep * Agent.frame_skip``, 0.05 s): PointMaze steps 0.01 s (frame_skip 1), so the policy
decides on every 5th call and holds its action in between; AntMaze steps 0.05 s, one decision per call.

Saved as ``RUN_DIR/policy.json`` (atomically): the legs, the maze, the horizon and the goal policy by
reference (the checkpoint the run used, ``shipped`` or an absolute path, with its fingerprint: no copy of
300 kB per sweep cell); loading reads JSON and ``torch.load(weights_only=True)`` only, and refuses a
checkpoint whose fingerprint is not the recorded one (retrained since the run).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.agents import get_agent
from ..core.errors import PolicyError, SpecrefineError
from ..core.mazes import Maze
from ..core.regions import CompiledRegion, Region, from_dict
from ..sim.switching import AT_REGION, SWITCHING, switching_rule

FORMAT, VERSION = "specrefine-compositional-policy", 1
POLICY_JSON = "policy.json"
SWITCHING_RULE = ("legs in path order; at each decision, while the agent's xy is inside the current leg's goal "
                  "region, advance to the next leg; the goal policy is fed the current leg's goal point (fixed "
                  "vertex point, else drawn at reset uniformly in the goal region at least clearance from walls)")


@dataclass(frozen=True)
class Leg:
    vertex: str
    goal: Region
    avoid: Region
    point: tuple[float, float] | None


class CompositionalPolicy:
    """``reset(observation)`` / ``act(observation) -> action`` along a run's refined path (module docstring)."""

    def __init__(self, agent: str, maze: Maze, legs: list[Leg], goal_policy, horizon: int,
                 env_dt: float | None = None, switching: str = AT_REGION):
        from .evaluator import Evaluator

        if not legs:
            raise SpecrefineError("a compositional policy needs at least one leg (the run found no path)")
        if isinstance(horizon, bool) or not isinstance(horizon, int | np.integer) or horizon < 1:
            raise SpecrefineError(f"horizon {horizon!r:.40}: the decisions per leg must be a whole number >= 1")
        spec = get_agent(agent)
        self.switching, self._hold = switching, switching_rule(switching)
        self.agent, self.maze, self.legs, self.goal_policy, self.horizon = agent, maze, list(legs), goal_policy, horizon
        self.control_period = spec.timestep * spec.frame_skip
        self.match_env_dt(env_dt)
        self._sampler = Evaluator(maze, agent, goal_policy, n=1)  # the evaluator's goal-point rule and clearance
        self.clearance = self._sampler.clearance
        self._goals = [CompiledRegion(leg.goal) for leg in self.legs]
        self._avoids = [CompiledRegion(leg.avoid) for leg in self.legs]
        self.reset()

    def match_env_dt(self, env_dt: float | None) -> None:
        """``act`` is called every ``env_dt`` seconds: decide every ``hold`` calls (None: every call)."""
        if env_dt is not None and (isinstance(env_dt, bool) or not isinstance(env_dt, int | float | np.number)
                                   or not np.isfinite(env_dt) or env_dt <= 0):
            raise SpecrefineError(f"env_dt {env_dt!r:.40}: the seconds between act calls must be a positive number")
        self.env_dt = None if env_dt is None else float(env_dt)
        self.hold = 1 if env_dt is None else max(1, round(self.control_period / self.env_dt))

    def spawn_point(self, region: Region, rng: np.random.Generator) -> np.ndarray:
        """Where this package's evaluator starts an episode in ``region``: uniform in it, clear of walls by the
        evaluator's spawn radius (the Ant: its legs' reach) where the region allows it."""
        return self._sampler.spawn_points(region, 1, rng)[0]

    # --- the loop ------------------------------------------------------------------------------
    def reset(self, observation=None, *, seed=None) -> None:
        """Start an episode: draw the goal points (``seed``: an int or a numpy Generator) and take leg 0."""
        rng = np.random.default_rng(seed)
        sample = self._sampler.sample_free
        self.goal_points = np.array([leg.point if leg.point is not None else sample(leg.goal, 1, rng)[0]
                                     for leg in self.legs], dtype=float)
        self.leg, self.decisions_in_leg, self._calls, self._action = 0, 0, 0, None
        self.holding = self._hold is not None  # the switching rule may hold the leg's start (slow-turn)
        if observation is not None:
            self.update(observation)

    def act(self, observation) -> np.ndarray:
        """The control for this environment step (a new decision every ``hold`` calls)."""
        if self._calls % self.hold == 0 or self._action is None:
            self.update(observation)
            last = len(self.legs) - 1
            point = self.goal_points[min(self.leg, last)]
            goal = self._aim(observation, point)
            after = None
            if getattr(self.goal_policy, "lookahead", False):  # the next leg's point; braking, its own leg's
                after = point if self.holding else self.goal_points[min(self.leg + 1, last)]
            obs = policy_observation(self.agent, observation, goal, getattr(self.goal_policy, "observation_frame",
                                                                            "world"), after)
            self._action = self._control(np.asarray(self._act(obs[None]), dtype=np.float64)[0])
            self.decisions_in_leg += 1
        self._calls += 1
        return self._action.copy()

    @property
    def done(self) -> bool:
        """Every leg's goal region has been reached."""
        return self.leg >= len(self.legs)

    @property
    def timed_out(self) -> bool:
        """The current leg has used its ``horizon`` decisions (the evaluator's per-leg time limit)."""
        return not self.done and self.decisions_in_leg >= self.horizon

    def touching(self, xy) -> bool:
        """The agent at ``xy`` touches the current leg's avoid set (closer than ``clearance``)."""
        if self.done:
            return False
        return bool(self._avoids[self.leg].below(np.asarray(xy, dtype=float).reshape(1, 2), self.clearance)[0])

    def update(self, observation) -> None:
        """Move on past every leg whose goal region holds the agent now (``act`` does this at each decision)."""
        point = agent_xy(observation).reshape(1, 2)
        while not self.done and self._goals[self.leg].contains(point)[0]:
            self.leg += 1
            self.decisions_in_leg = 0
            self.holding = self._hold is not None

    def _aim(self, observation, goal) -> np.ndarray:
        """Where the policy aims at this decision: its own position while the switching rule holds the leg's start,
        else ``goal``."""
        if not self.holding:
            return goal
        xy = agent_xy(observation)
        self.holding = bool(self._hold.holding(agent_velocity(self.agent, observation)[None], (goal - xy)[None],
                                               [self.decisions_in_leg])[0])
        return xy if self.holding else goal

    def _act(self, obs):
        return self.goal_policy.act(obs) if hasattr(self.goal_policy, "act") else self.goal_policy(obs)

    def _control(self, action: np.ndarray) -> np.ndarray:
        if not np.isfinite(action).all():
            raise PolicyError("the goal policy acts with NaN or infinite values: retrain it or restore its checkpoint")
        action = np.clip(action, -1.0, 1.0)
        if get_agent(self.agent).action_in_disc:
            action = action / max(float(np.linalg.norm(action)), 1.0)
        return action

    # --- files -----------------------------------------------------------------------------------
    @classmethod
    def load(cls, run_dir, env_dt: float | None = None) -> CompositionalPolicy:
        """The policy saved in ``run_dir`` (``policy.json`` + its goal policy); problems are one PolicyError line."""
        from ..core.records import check_policy, read_json

        path = Path(run_dir) / POLICY_JSON
        if not path.exists() and not path.is_symlink():
            raise PolicyError(f"{path}: no compositional policy (not a finished run folder, or the run found no "
                              "path)")
        data = read_json(path, "compositional policy", PolicyError)
        if not isinstance(data, dict) or data.get("format") != FORMAT or data.get("version") != VERSION:
            raise PolicyError(f"{path}: not a specrefine compositional policy (format {FORMAT} v{VERSION})")
        check_policy(data, path, PolicyError)
        maze = Maze(data["maze"], tuple(data["maze_grid"]), float(data["cell_size"]))
        legs = [Leg(leg["vertex"], from_dict(leg["goal"]), from_dict(leg["avoid"]),
                    None if leg["point"] is None else tuple(float(v) for v in leg["point"])) for leg in data["legs"]]
        switching = data.get("switching_rule", AT_REGION)  # a policy saved before the rules were named: the paper's
        if switching not in SWITCHING:
            raise PolicyError(f"{path}: switching_rule {switching!r:.40} is not one of {', '.join(SWITCHING)}")
        goal_policy = _load_goal_policy(data["agent"], data["goal_policy"])
        return cls(data["agent"], maze, legs, goal_policy, data["horizon"], env_dt=env_dt, switching=switching)

    def to_dict(self, goal_policy_record: dict) -> dict:
        return {"format": FORMAT, "version": VERSION, "agent": self.agent, "maze": self.maze.name,
                "maze_grid": list(self.maze.grid), "cell_size": self.maze.cell_size, "horizon": self.horizon,
                "control_period": self.control_period, "clearance": self.clearance,
                "switching": SWITCHING_RULE if self._hold is None else f"{SWITCHING_RULE}; {self._hold.describe()}",
                "switching_rule": self.switching,
                "legs": [{"vertex": leg.vertex, "goal": leg.goal.to_dict(), "avoid": leg.avoid.to_dict(),
                          "point": None if leg.point is None else list(leg.point)} for leg in self.legs],
                "goal_policy": goal_policy_record}


def save_run_policy(run_dir, maze: Maze, agent: str, graph, path: list[str], evaluator) -> Path | None:
    """Write ``run_dir/policy.json`` for ``path`` of ``graph`` as ``evaluator`` runs it (its goal policy and horizon).

    ``maze`` at the agent's scale.  The goal policy is recorded by reference: the checkpoint the run used
    (``run_dir/run.json``'s ``policy``: ``shipped`` or a path, made absolute) and its fingerprint, or the
    scripted :class:`~specrefine.sim.policy.PointController`'s gains.  Nothing is written (None) when the run
    found no path or its goal policy is neither (a stand-in evaluator's callable).
    """
    run_dir = Path(run_dir)
    record = _goal_policy_record(run_dir, getattr(evaluator, "policy", None))
    if not path or len(path) < 2 or record is None:
        return None
    aim = getattr(evaluator, "aim", lambda goal, point: point)  # the evaluator's rule: a centre becomes a fixed point
    points = [aim(graph.region(v), graph.goal_point(v)) for v in path[1:]]
    legs = [Leg(v, graph.region(v), graph.avoid(u, v), None if p is None else tuple(float(x) for x in p))
            for u, v, p in zip(path, path[1:], points, strict=False)]
    policy = CompositionalPolicy(agent, maze, legs, evaluator.policy, int(evaluator.horizon),
                                 switching=getattr(evaluator, "switching", AT_REGION))
    data = policy.to_dict(record) | {"path": list(path)}
    from ..core.runfolder import write_atomic

    target = run_dir / POLICY_JSON
    write_atomic(target, json.dumps(data, indent=1))
    return target


def _goal_policy_record(run_dir: Path, goal_policy) -> dict | None:
    from ..core.paths import shipped_name
    from ..core.runfolder import RECORD
    from ..sim.policy import GoalPolicy, PointController

    if isinstance(goal_policy, PointController):
        return {"scripted": {"gain": goal_policy.gain, "vmax": goal_policy.vmax, "kv": goal_policy.kv},
                "fingerprint": goal_policy.fingerprint}
    if not isinstance(goal_policy, GoalPolicy):
        return None
    try:
        checkpoint = json.loads((run_dir / RECORD).read_text()).get("policy", "shipped")
    except (OSError, ValueError, AttributeError):
        checkpoint = "shipped"
    if checkpoint in (None, "shipped"):
        checkpoint = "shipped"
    elif not shipped_name(checkpoint):  # a shipped checkpoint stays a name, found wherever the package is
        checkpoint = str(Path(checkpoint).resolve())
    return {"checkpoint": checkpoint, "fingerprint": goal_policy.fingerprint}


def _load_goal_policy(agent: str, record: dict):
    from ..core.paths import shipped_name
    from ..sim.policy import PointController, load_policy

    if "scripted" in record:
        policy = PointController(**{k: float(v) for k, v in record["scripted"].items()})
    else:
        checkpoint = record["checkpoint"]
        policy = load_policy(agent if checkpoint == "shipped" else checkpoint if shipped_name(checkpoint)
                             else Path(checkpoint))
    if getattr(policy, "agent", agent) != agent or policy.fingerprint != record.get("fingerprint"):
        raise PolicyError(f"goal policy {record.get('checkpoint', 'scripted')}: fingerprint {policy.fingerprint}, "
                          f"the run used {record.get('fingerprint')} (retrained or replaced since the run)")
    return policy


# --- observations ------------------------------------------------------------------------------------
def agent_xy(observation) -> np.ndarray:
    """The agent's (x, y) from a Gymnasium-Robotics maze observation (its ``achieved_goal``)."""
    xy = _finite(observation, "achieved_goal")
    if xy.size != 2:
        raise SpecrefineError(f"an observation's achieved_goal is the agent's (x, y), got {xy.size} values")
    return xy.reshape(2)


def agent_velocity(agent: str, observation) -> np.ndarray:
    """The agent's planar velocity (vx, vy) from a Gymnasium-Robotics maze observation: the point mass's qvel, the
    Ant's free joint's linear velocity (world frame, as ``BatchedSim.qvel[:, :2]``)."""
    spec = get_agent(agent)
    body = _finite(observation, "observation")
    start = 2 if spec.planar else body.size - spec.act_dim - 6  # after qpos (without x, y)
    if body.size < start + 2:
        raise SpecrefineError(f"an {agent} observation has no velocity: {body.size} values")
    return body[start:start + 2]


def _finite(observation, key: str) -> np.ndarray:
    """``observation[key]`` as finite floats, else one SpecrefineError line (a diverged or foreign environment)."""
    try:
        values = np.asarray(observation[key], dtype=float).ravel()
    except (KeyError, IndexError, TypeError, ValueError):
        raise SpecrefineError(f"not a Gymnasium-Robotics maze observation: no numbers under {key!r}") from None
    if not np.isfinite(values).all():
        raise SpecrefineError(f"the observation's {key} holds NaN or infinite values (a diverged simulation?)")
    return values


def policy_observation(agent: str, observation, goal, frame: str = "world", next_goal=None) -> np.ndarray:
    """This package's policy observation (``BatchedSim.observe`` in ``frame``, with ``next_goal`` its look-ahead
    inputs) from a Gymnasium-Robotics maze observation."""
    from ..sim.simulator import free_body_observation

    spec = get_agent(agent)
    body = _finite(observation, "observation")
    xy = agent_xy(observation)
    rel = (np.asarray(goal, dtype=float).reshape(2) - xy)[None]
    next_rel = None if next_goal is None else (np.asarray(next_goal, dtype=float).reshape(2) - xy)[None]
    if spec.planar:  # PointMaze: (x, y, vx, vy) -> velocity, goal - xy (, next goal - xy)
        if body.size != 4:
            raise SpecrefineError(f"a PointMaze observation has 4 values (x, y, vx, vy), got {body.size}")
        return np.concatenate([body[2:4], rel[0], *([] if next_rel is None else [next_rel[0]])]).astype(np.float32)
    if body.size != spec.obs_dim - 2:  # AntMaze: qpos[2:] (13) + qvel (14)
        raise SpecrefineError(f"an {agent} observation needs {spec.obs_dim - 2} values (qpos without x, y, and qvel; "
                              f"contact forces off), got {body.size}")
    nq = body.size - spec.act_dim - 6  # qpos without x, y: z, quaternion, joints; then qvel: 6 + joints
    return free_body_observation(body[None, :nq], body[None, nq:], rel, frame, next_rel)[0]


def torso_flipped(agent: str, observation) -> bool:
    """The Ant's torso points below the horizon (never, for a planar agent)."""
    from ..sim.simulator import torso_up

    if get_agent(agent).planar:
        return False
    body = _finite(observation, "observation")
    if body.size < 5:
        raise SpecrefineError(f"an {agent} observation starts with z and the torso's quaternion: {body.size} values")
    return bool(torso_up(body[1:5][None])[0] < 0.0)
