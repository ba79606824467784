"""Batched MuJoCo agents (point mass, Ant) in a maze built from a :class:`~specrefine.core.mazes.Maze`.

One process holds the full physics state of all ``n`` rollouts as one ``(n, state_dim)`` array
(``mjSTATE_FULLPHYSICS``) and advances them together with ``mujoco.rollout`` (a persistent thread
pool, ``nthread`` threads, default min(2, cores)); no gym env per rollout.  Measured on this shared
2-core machine, batch 32, random actions, env steps/s: Ant rollout 2 threads 6.7k, 1 thread 5.5k,
Python loop of ``mj_step(model, data, nstep=frame_skip)`` over 32 MjData 3.6k; point 74.7k vs 55.8k.
So rollout is the only code path.

Physics (the same for training and evaluation; the model is built here and nowhere else):

* point: Gymnasium-Robotics ``point.xml`` (sphere r = 0.1 m, gear 100, no gravity), Euler
  integrator, timestep 0.01 s, frame_skip 5 -> control period ``dt`` = 0.05 s.  As in
  ``PointEnv`` the planar velocity is clipped to [-5, 5] m/s (here once per control step).
  Unlike ``PointEnv`` the action is clipped to the unit disc, not the unit square: with a
  per-axis bound, diagonal thrust is free and a learned policy swings wide arcs that hit walls.
  Cell 1 m.  Observation (4) = velocity (2) + (goal - xy) (2).
* ant: Gymnasium ``ant.xml``, RK4 integrator, timestep 0.01 s, frame_skip 5 -> ``dt`` = 0.05 s
  (the AntMaze settings).  Cell 4 m.  Observation (29) = qpos without x, y (13) + qvel (14) +
  goal - torso xy (2), the last expressed in the torso's heading (yaw) frame so that the
  policy does not have to learn the rotation.  An Ant whose torso up-vector points below the
  horizon (z-component of the body z axis < 0) is ``flipped``.

Walls are static box geoms, one per part of ``maze.walls`` (``maze=None``: open floor).
``body_radius`` for wall checks on (x, y): point 0.1 m (the sphere), Ant 0.5 m (torso 0.25 m + hips).
``default_horizon`` (control steps per subtask evaluation): point 100 steps (5 s, about six cells);
Ant 300 steps (15 s; the shipped policy needs 92 steps on average for goals 2-6 m away, and a
subtask should span at most its reach of one 4 m cell or so, so longer only costs time on
rollouts that wander).
"""

from __future__ import annotations

import os
from pathlib import Path

import mujoco
import numpy as np
from mujoco import rollout

from ..core.agents import OBSERVATION_FRAMES, get_agent
from ..core.errors import SpecrefineError
from ..core.mazes import Maze

_INTEGRATORS = {"euler": mujoco.mjtIntegrator.mjINT_EULER, "rk4": mujoco.mjtIntegrator.mjINT_RK4}


def _asset(module: str, *parts: str) -> Path:
    """A file shipped inside an installed package, found without importing it (gymnasium_robotics warns at import)."""
    import importlib.util

    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        raise SpecrefineError(f"package {module!r} is not installed; it provides the agent's MuJoCo model")
    return Path(spec.origin).parent.joinpath(*parts)


def footprint_radius(model: mujoco.MjModel) -> float:
    """Horizontal reach of the agent's geoms from its root in the default pose (Ant: leg tips, 1.21 m).

    Spawning closer than this to a wall puts a leg inside it; MuJoCo then pushes it out violently and
    the Ant flips in its first half second.
    """
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    root = data.qpos[:2]
    reach = 0.0
    for i in np.flatnonzero(model.geom_bodyid > 0):
        centre, axis, size = data.geom_xpos[i], data.geom_xmat[i].reshape(3, 3)[:, 2], model.geom_size[i]
        half = size[1] if model.geom_type[i] == mujoco.mjtGeom.mjGEOM_CAPSULE else 0.0
        for end in (centre - half * axis, centre + half * axis):
            reach = max(reach, float(np.hypot(*(end[:2] - root))) + float(size[0]))
    return reach


def contact_margin(model: mujoco.MjModel) -> float:
    """The gap at which the agent's contacts with walls become active (the sum of both geoms' margins)."""
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, i) or "" for i in range(model.ngeom)]
    wall_margin = max([model.geom_margin[i] for i, nm in enumerate(names) if nm.startswith("wall_")], default=0.0)
    agent_margin = float(model.geom_margin[model.geom_bodyid > 0].max(initial=0.0))
    return float(wall_margin + agent_margin)


def build_model(agent: str, maze: Maze | None) -> mujoco.MjModel:
    """The agent's MJCF plus one static box geom per wall part of ``maze``."""
    spec_ = get_agent(agent)
    spec = mujoco.MjSpec.from_file(str(_asset(*spec_.mjcf)))
    spec.option.integrator = _INTEGRATORS[spec_.integrator]
    spec.option.timestep = spec_.timestep
    if maze is not None:
        h = spec_.wall_half_height
        for i, box in enumerate(maze.for_agent(agent).walls.parts()):
            x0, y0, x1, y1 = box.bounds()
            spec.worldbody.add_geom(
                name=f"wall_{i}", type=mujoco.mjtGeom.mjGEOM_BOX,
                size=[(x1 - x0) / 2, (y1 - y0) / 2, h], pos=[(x0 + x1) / 2, (y0 + y1) / 2, 0 if spec_.planar else h],
                contype=1, conaffinity=1, rgba=[0.4, 0.4, 0.5, 1])
    return spec.compile()


def torso_up(quat: np.ndarray) -> np.ndarray:
    """z-component of the body z axis of unit quaternions (w, x, y, z), one per row: < 0 is flipped."""
    _, qx, qy, _ = np.asarray(quat, dtype=float).T
    return 1.0 - 2.0 * (qx * qx + qy * qy)


def heading(quat: np.ndarray) -> np.ndarray:
    """The yaw (rad) of unit quaternions (w, x, y, z), one per row."""
    w, x, y, z = np.asarray(quat, dtype=float).T
    return np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def _rotated(vec: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Planar vectors ``vec`` (n, 2) in the frame turned by ``yaw`` (n,)."""
    c, s = np.cos(yaw), np.sin(yaw)
    return np.stack([c * vec[:, 0] + s * vec[:, 1], -s * vec[:, 0] + c * vec[:, 1]], axis=1)


def free_body_observation(qpos: np.ndarray, qvel: np.ndarray, rel: np.ndarray, frame: str = "world",
                          next_rel: np.ndarray | None = None) -> np.ndarray:
    """A free-joint body's policy observation from its qpos without x, y (z, quaternion, joints), qvel and the goal
    relative to it, rows alike (``BatchedSim.observe`` and the official environment's policy share it); with
    ``next_rel`` (the goal after it, relative to the body) the look-ahead inputs last, in the goal's frame."""
    if frame not in OBSERVATION_FRAMES:
        raise SpecrefineError(f"observation frame must be one of {', '.join(OBSERVATION_FRAMES)}, got {frame!r}")
    qpos, qvel = np.array(qpos, dtype=float), np.array(qvel, dtype=float)
    yaw = heading(qpos[:, 1:5])
    if frame == "heading":
        qpos[:, 1:5] = _without_yaw(qpos[:, 1:5], yaw)
        qvel[:, 0:2] = _rotated(qvel[:, 0:2], yaw)
    goals = [_rotated(np.asarray(r, dtype=float), yaw) for r in (rel, next_rel) if r is not None]
    return np.concatenate([qpos, qvel, *goals], axis=1).astype(np.float32)


class BatchedSim:
    """``n`` copies of one agent in one maze, stepped together.  See the module docstring."""

    STATE_SPEC = mujoco.mjtState.mjSTATE_FULLPHYSICS

    def __init__(self, agent: str, maze: Maze | None, n: int, nthread: int | None = None,
                 model: mujoco.MjModel | None = None):
        """``model``: ``build_model(agent, maze)`` when already built (an evaluator's sims of every batch size
        share one: compiling it costs ~0.1 s)."""
        if n < 1:
            raise SpecrefineError(f"BatchedSim needs n >= 1 rollouts, got {n}")
        self.agent, self.n, self.maze = agent, int(n), maze
        self._spec = get_agent(agent)
        self.model = build_model(agent, maze) if model is None else model
        m = self.model
        self.frame_skip = self._spec.frame_skip
        self.dt = self._spec.timestep * self.frame_skip
        self.body_radius = self._spec.body_radius
        self.default_horizon = self._spec.default_horizon
        self.act_dim = m.nu
        self.obs_dim = m.nv + 2 if self._spec.planar else (m.nq - 2) + m.nv + 2
        self.state_dim = mujoco.mj_stateSize(m, self.STATE_SPEC)
        self._qpos = slice(1, 1 + m.nq)  # FULLPHYSICS layout: time, qpos, qvel, act, ...
        self._qvel = slice(1 + m.nq, 1 + m.nq + m.nv)
        self.nthread = max(1, min(os.cpu_count() or 1, 2) if nthread is None else int(nthread))
        self._datas = [mujoco.MjData(m) for _ in range(self.nthread)]
        self._pool = rollout.Rollout(nthread=self.nthread if self.nthread > 1 else 0)
        self._models = [m] * self.n  # skip_checks=True wants the per-rollout list already expanded
        self._out = np.zeros((self.n, self.frame_skip, self.state_dim))
        self._state = np.zeros((self.n, self.state_dim))
        #: called as ``physics_observer(states, ctrl, nstep)`` before each physics call of :meth:`step` (the rows'
        #: full-physics states and the controls they are stepped with; copy what you keep): lets a benchmark
        #: record and replay the exact physics work of an evaluation.  None: no call.
        self.physics_observer = None
        self.reset()

    # --- state -------------------------------------------------------------------------------
    def _default_state(self, k: int, rng: np.random.Generator | None) -> np.ndarray:
        d = self._datas[0]
        mujoco.mj_resetData(self.model, d)
        base = np.empty(self.state_dim)
        mujoco.mj_getState(self.model, d, base, self.STATE_SPEC)
        states = np.tile(base, (k, 1))
        noise = self._spec.reset_noise
        if rng is not None and noise:  # Gymnasium's reset noise, not on x, y
            nq, nv = self.model.nq, self.model.nv
            states[:, 3:1 + nq] += rng.uniform(-noise, noise, size=(k, nq - 2))
            states[:, self._qvel] += noise * rng.standard_normal((k, nv))
        return states

    def reset(self, xy=None, states=None, rng: np.random.Generator | None = None, idx=None) -> None:
        """Place rollouts ``idx`` (default: all) at ``xy`` in the default pose, or restore ``states``."""
        idx = np.arange(self.n) if idx is None else np.asarray(idx)
        k = len(idx) if idx.dtype != bool else int(idx.sum())
        if states is not None:
            states = np.asarray(states, dtype=float)
            if states.shape != (k, self.state_dim):
                raise SpecrefineError(f"reset: states must have shape ({k}, {self.state_dim}), got {states.shape}")
            self._state[idx] = states
            return
        new = self._default_state(k, rng)
        if xy is not None:
            xy = np.asarray(xy, dtype=float)
            if xy.shape != (k, 2):
                raise SpecrefineError(f"reset: xy must have shape ({k}, 2), got {xy.shape}")
            new[:, 1:3] = xy
        self._state[idx] = new

    def get_state(self) -> np.ndarray:
        return self._state.copy()

    @property
    def qpos(self) -> np.ndarray:
        return self._state[:, self._qpos]

    @property
    def qvel(self) -> np.ndarray:
        return self._state[:, self._qvel]

    @property
    def xy(self) -> np.ndarray:
        return self._state[:, 1:3].copy()

    @property
    def up(self) -> np.ndarray:
        """z-component of the torso's z axis: 1 upright, 0 on its side, < 0 upside down (point: always 1)."""
        if self._spec.planar:
            return np.ones(self.n)
        return torso_up(self.qpos[:, 3:7])

    @property
    def flipped(self) -> np.ndarray:
        return self.up < 0.0

    # --- observe / step --------------------------------------------------------------------
    def observe(self, goals: np.ndarray, frame: str = "world", next_goals: np.ndarray | None = None) -> np.ndarray:
        """The policy's observation of reaching ``goals`` (one per row).

        ``frame="world"`` (the shipped policies): the torso's quaternion and linear velocity as MuJoCo holds them,
        so they carry the absolute heading.  ``frame="heading"``: both with the heading taken out (the quaternion
        of roll and pitch alone, the velocity in the heading frame), so behaviour cannot depend on the compass
        direction of travel.  The goal is in the heading frame and the angular velocity in the body frame in both;
        at heading 0 the two observations are equal.  The point mass has no heading: both frames are the same.
        ``next_goals`` (a look-ahead policy's, ``GoalPolicy.lookahead``): the goal after each row's current one,
        appended relative to the agent in the current goal's frame (no next goal: pass the current one).
        """
        if frame not in OBSERVATION_FRAMES:
            raise SpecrefineError(f"observation frame must be one of {', '.join(OBSERVATION_FRAMES)}, got {frame!r}")
        rel = np.asarray(goals, dtype=float).reshape(self.n, 2) - self._state[:, 1:3]
        next_rel = None if next_goals is None else np.asarray(next_goals, dtype=float).reshape(self.n, 2) - \
            self._state[:, 1:3]
        if self._spec.planar:
            return np.concatenate([self.qvel, rel, *([] if next_rel is None else [next_rel])], axis=1).astype(
                np.float32)
        return free_body_observation(self.qpos[:, 2:], self.qvel, rel, frame, next_rel)

    def step(self, actions: np.ndarray) -> None:
        ctrl = np.clip(np.asarray(actions, dtype=float).reshape(self.n, 1, self.act_dim), -1.0, 1.0)
        if self._spec.action_in_disc:  # force bounded in norm, not per axis: then straight is the fastest way to a goal
            ctrl /= np.maximum(np.linalg.norm(ctrl, axis=-1, keepdims=True), 1.0)
        ctrl = np.ascontiguousarray(np.broadcast_to(ctrl, (self.n, self.frame_skip, self.act_dim)))
        if self.physics_observer is not None:
            self.physics_observer(self._state, ctrl, self.frame_skip)
        self._pool.rollout(self._models, self._datas, self._state, ctrl, nstep=self.frame_skip,
                           state=self._out, skip_checks=True)
        self._state[:] = self._out[:, -1]
        if self._spec.max_speed is not None:
            v = self._spec.max_speed
            np.clip(self._state[:, self._qvel], -v, v, out=self._state[:, self._qvel])

    def close(self) -> None:
        if self._pool is not None:
            self._pool.close()
            self._pool = None

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown
            pass


def _without_yaw(quat: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """conj(q_yaw) * q for rows (w, x, y, z): the rotation left once the heading is removed, with w >= 0."""
    w, x, y, z = quat.T
    c, s = np.cos(yaw / 2), np.sin(yaw / 2)
    out = np.stack([c * w + s * z, c * x + s * y, c * y - s * x, c * z - s * w], axis=1)
    return np.where(out[:, :1] < 0, -out, out)  # q and -q are one rotation: one sign, or it jumps at yaw = pi


# --- goal-conditioned reach task for training (open floor) -----------------------------------
def sample_goals(xy: np.ndarray, lo: float, hi: float, rng: np.random.Generator) -> np.ndarray:
    """Goals at a uniform distance in [lo, hi] and a uniform direction from each row of ``xy``."""
    r = rng.uniform(lo, hi, size=len(xy))
    a = rng.uniform(-np.pi, np.pi, size=len(xy))
    return xy + np.stack([r * np.cos(a), r * np.sin(a)], axis=1)


def sample_turn_goals(xy: np.ndarray, travel: np.ndarray, lo: float, hi: float, turn_deg: tuple[float, float],
                      rng: np.random.Generator) -> np.ndarray:
    """Goals at a uniform distance in [lo, hi] from each row of ``xy``, in a direction that turns by a uniform
    angle in ``turn_deg`` (degrees, either side at random) from that row's ``travel`` direction (any nonzero
    vector; a zero row counts as heading east): the goal switches of a path that turns."""
    r = rng.uniform(lo, hi, size=len(xy))
    turn = np.radians(rng.uniform(*turn_deg, size=len(xy))) * rng.choice((-1.0, 1.0), size=len(xy))
    a = np.arctan2(travel[:, 1], travel[:, 0]) + turn  # arctan2(0, 0) = 0: east
    return xy + np.stack([r * np.cos(a), r * np.sin(a)], axis=1)


def direction_of_travel(velocity: np.ndarray, fallback: np.ndarray, min_speed: float = 0.2) -> np.ndarray:
    """Each row's planar ``velocity``, or ``fallback`` (e.g. towards the goal just reached) where the agent moves
    slower than ``min_speed`` m/s, whose velocity says little about where it is going."""
    slow = np.linalg.norm(velocity, axis=1) < min_speed
    return np.where(slow[:, None], fallback, velocity)
