"""The goal-reaching training task of the goal-conditioned policy, as a TorchRL env over a BatchedSim.

Its own module because TorchRL is slow to import (``torchrl.data`` pulls in Ray where installed):
evaluation and refinement use :class:`specrefine.sim.simulator.BatchedSim` alone and never import it.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import torch
from tensordict import TensorDict
from torchrl.data import Bounded, Categorical, Composite, Unbounded
from torchrl.envs import EnvBase

from ..core.agents import ReachTask, get_agent
from ..core.errors import SpecrefineError
from ..core.mazes import Maze
from ..core.regions import CompiledRegion
from .simulator import BatchedSim, contact_margin, direction_of_travel, sample_goals, sample_turn_goals


class GoalReachEnv(EnvBase):
    """TorchRL env, batch_size [n]: reach a goal on the open floor (training task).

    Reward = ``progress_scale`` x (metres closer to the goal) + ``success_bonus`` on reaching
    it - ``flip_penalty`` on flipping - ``step_cost`` per step.  Done on success, flip or ``max_steps``; finished
    envs are reset by TorchRL's partial ``_reset`` (the collector does it automatically).  With
    ``task.goals_per_episode`` = m > 1, the first m - 1 successes draw a new goal from the current (moving)
    state instead, as a compositional policy switches subtasks, and ``max_steps`` counts per goal.  With
    ``task.goal_radius`` = (lo, hi), each goal counts as reached within its own radius drawn from [lo, hi]
    (a refined graph's goal regions are that size: the next goal arrives while the agent still moves).

    ``maze`` (training among walls): episodes start at a free cell's centre and every goal is the centre of a
    neighbouring free cell, as the oracle's waypoints along a corridor, turning where the corridor turns and not
    going back unless it ends; touching a wall (closer than the evaluator's clearance, the body radius plus MuJoCo's
    contact margin) ends the episode with ``task.wall_penalty``. The policy's observation stays as it is: the walls
    are in the physics only.

    ``goal_points`` = "sampled" (with ``maze``): each goal is a uniform point of the neighbouring cell at least the
    clearance from its walls instead of its centre, as the sampled goal-point rule aims, some of them by a wall.

    ``turn`` = (lo, hi) degrees (open floor only): every chained goal after the first turns by lo-hi degrees from the
    direction the agent travels when it switches (``simulator.sample_turn_goals``), at whatever speed it has: the
    goal switches where the U-chain paths lose most episodes (issue 42).  The first goal of an episode stays uniform.

    ``lookahead`` (open floor only): the observation also carries the goal after the current one
    (``BatchedSim.observe``'s ``next_goals``; the current one on an episode's last goal). Each goal after the first is
    then drawn one goal ahead, from the goal before it (with ``turn``: turning from that leg's line, from where it was
    drawn to the goal), so that the policy sees it before the switch.
    """

    def __init__(self, agent: str, n: int, seed: int = 0, nthread: int | None = None, task: ReachTask | None = None,
                 frame: str = "world", maze: Maze | None = None, turn: tuple[float, float] | None = None,
                 goal_points: str = "centre", lookahead: bool = False):
        super().__init__(batch_size=torch.Size([n]), device="cpu")
        if turn is not None and maze is not None:
            raise SpecrefineError("turning goals (--turn-goals) are drawn on the open floor: not with --train-maze")
        if lookahead and maze is not None:
            raise SpecrefineError("the look-ahead (--lookahead) draws its goals on the open floor: not with "
                                  "--train-maze")
        if goal_points not in ("centre", "sampled") or (goal_points == "sampled" and maze is None):
            raise SpecrefineError(f"training goal points {goal_points!r}: 'centre', or 'sampled' with --train-maze")
        self.turn, self.goal_points = turn, goal_points
        self.maze = None if maze is None else maze.for_agent(agent)
        self.sim = BatchedSim(agent, self.maze, n, nthread=nthread)
        if self.maze is not None:
            self._walls = CompiledRegion(self.maze.walls)
            self.clearance = get_agent(agent).body_radius + contact_margin(self.sim.model)
            self._free = np.array(self.maze.free_cells())
            self.cell = np.zeros((n, 2), dtype=np.int64)  # the cell of each env's current goal (or start)
            self.came_from = np.zeros((n, 2), dtype=np.int64)
        self.frame = frame  # the observation frame of the policy being trained (simulator.BatchedSim.observe)
        self.task = task or get_agent(agent).reach_task
        self.rng = np.random.default_rng(seed)
        self.goals = np.zeros((n, 2))
        self.lookahead = lookahead
        self.next_goals = np.zeros((n, 2))  # with lookahead: the goal after the current one
        self.leg_from = np.zeros((n, 2))  # with lookahead: where the current goal was drawn from
        self.obs_dim = self.sim.obs_dim + (2 if lookahead else 0)
        self.dist = np.zeros(n)
        self.radius = np.full(n, self.task.success_radius)
        self.t = np.zeros(n, dtype=np.int64)
        self.goal_index = np.zeros(n, dtype=np.int64)  # goals reached so far in this episode
        bs = self.batch_size
        self.observation_spec = Composite(
            observation=Unbounded((*bs, self.obs_dim), dtype=torch.float32),
            success=Categorical(2, (*bs, 1), dtype=torch.bool), flipped=Categorical(2, (*bs, 1), dtype=torch.bool),
            wall=Categorical(2, (*bs, 1), dtype=torch.bool), shape=bs)
        self.action_spec = Bounded(-1.0, 1.0, (*bs, self.sim.act_dim), dtype=torch.float32)
        self.reward_spec = Unbounded((*bs, 1), dtype=torch.float32)
        flag = Categorical(2, (*bs, 1), dtype=torch.bool)
        self.done_spec = Composite(done=flag.clone(), terminated=flag.clone(), truncated=flag.clone(), shape=bs)

    def _set_seed(self, seed: int | None):
        self.rng = np.random.default_rng(seed)

    def _obs_td(self, observation, success, flipped, wall) -> TensorDict:
        flags = {k: torch.from_numpy(v).unsqueeze(-1) for k, v in (("success", success), ("flipped", flipped),
                                                                  ("wall", wall))}
        return TensorDict({"observation": torch.from_numpy(observation), **flags}, batch_size=self.batch_size)

    def _reset(self, tensordict: TensorDict | None = None, **kwargs) -> TensorDict:
        mask = np.ones(self.sim.n, dtype=bool)
        if tensordict is not None and "_reset" in tensordict.keys():
            mask = tensordict["_reset"].reshape(self.sim.n).numpy().copy()
        zeros = np.zeros(self.sim.n, dtype=bool)
        out = self._obs_td(self.restart(np.flatnonzero(mask)), zeros, zeros, zeros)
        out.update(self._dones(zeros, zeros))
        return out

    def restart(self, idx: np.ndarray) -> np.ndarray:
        """Start new episodes in the envs ``idx``; returns every env's observation (numpy: the trainer's collector
        calls this and :meth:`advance` directly, without TorchRL's per-step machinery)."""
        if self.maze is None:
            self.sim.reset(rng=self.rng, idx=idx)
        else:
            self.cell[idx] = self.came_from[idx] = self._free[self.rng.integers(len(self._free), size=len(idx))]
            self.sim.reset(xy=self.maze.cell_to_xy(self.cell[idx, 0], self.cell[idx, 1]).reshape(len(idx), 2),
                           rng=self.rng, idx=idx)
        self.goal_index[idx] = 0
        self._new_goals(idx, chained=False)
        self.t[idx] = 0
        return self.observe()

    def observe(self) -> np.ndarray:
        """Every env's policy observation (with the next goals where the policy looks ahead)."""
        return self.sim.observe(self.goals, self.frame, self.next_goals if self.lookahead else None)

    def _new_goals(self, idx: np.ndarray, chained: bool = True) -> None:
        """Draw the next goal (and, with ``task.goal_radius``, its radius) of the envs ``idx``, from where they are;
        ``chained``: a switch within the episode (turning with ``turn``), not its first goal."""
        task = self.task
        if self.lookahead:
            self.leg_from[idx] = self.goals[idx] if chained else self.sim.xy[idx]
        if self.lookahead and chained:  # drawn a goal ahead
            self.goals[idx] = self.next_goals[idx]
        elif self.maze is None and chained and self.turn is not None:
            xy = self.sim.xy[idx]
            travel = direction_of_travel(self.sim.qvel[idx, :2], self.goals[idx] - xy)
            self.goals[idx] = sample_turn_goals(xy, travel, task.goal_min, task.goal_max, self.turn, self.rng)
        elif self.maze is None:
            self.goals[idx] = sample_goals(self.sim.xy[idx], task.goal_min, task.goal_max, self.rng)
        else:
            for i in idx:
                self.came_from[i], self.cell[i] = self.cell[i].copy(), self._next_cell(self.cell[i], self.came_from[i])
            self.goals[idx] = self.maze.cell_to_xy(self.cell[idx, 0], self.cell[idx, 1]).reshape(len(idx), 2)
            if self.goal_points == "sampled":  # within the cell, never closer to a wall than the clearance
                half = self.maze.cell_size / 2 - self.clearance
                self.goals[idx] += self.rng.uniform(-half, half, size=(len(idx), 2))
        self.dist[idx] = np.linalg.norm(self.goals[idx] - self.sim.xy[idx], axis=1)
        if task.goal_radius is not None:
            self.radius[idx] = self.rng.uniform(*task.goal_radius, size=len(idx))
        if self.lookahead:
            self._plan_next(idx)

    def _plan_next(self, idx: np.ndarray) -> None:
        """The goal after the current one of the envs ``idx``: drawn from the current goal, as the next switch will
        take it; the current goal itself on an episode's last goal."""
        task = self.task
        self.next_goals[idx] = self.goals[idx]
        ahead = idx[self.goal_index[idx] + 1 < task.goals_per_episode]
        if not len(ahead):
            return
        goals = self.goals[ahead]
        if self.turn is None:
            self.next_goals[ahead] = sample_goals(goals, task.goal_min, task.goal_max, self.rng)
        else:
            self.next_goals[ahead] = sample_turn_goals(goals, goals - self.leg_from[ahead], task.goal_min,
                                                       task.goal_max, self.turn, self.rng)

    def touching(self, xy: np.ndarray) -> np.ndarray:
        """Which positions touch a wall: closer than the evaluator's clearance (none on the open floor)."""
        if self.maze is None:
            return np.zeros(len(xy), dtype=bool)
        return self._walls.below(xy, self.clearance)

    def _next_cell(self, cell: np.ndarray, came_from: np.ndarray) -> np.ndarray:
        """A random free neighbour of ``cell``, not the one it was reached from unless it is the only one."""
        r, c = (int(v) for v in cell)
        nbs = [nb for nb in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)) if self.maze.is_free(*nb)]
        ahead = [nb for nb in nbs if nb != tuple(int(v) for v in came_from)] or nbs
        return np.array(ahead[self.rng.integers(len(ahead))])

    def _dones(self, terminated: np.ndarray, truncated: np.ndarray) -> dict:
        t = torch.from_numpy(terminated).unsqueeze(-1)
        tr = torch.from_numpy(truncated).unsqueeze(-1)
        return {"terminated": t, "truncated": tr, "done": t | tr}

    def _sideways(self, before: np.ndarray) -> np.ndarray:
        """Distance moved across the line from the previous position to the goal, this step."""
        to_goal = self.goals - before
        unit = to_goal / np.maximum(np.linalg.norm(to_goal, axis=1, keepdims=True), 1e-9)
        moved = self.sim.xy - before
        return np.abs(moved[:, 0] * unit[:, 1] - moved[:, 1] * unit[:, 0])

    def _step(self, tensordict: TensorDict) -> TensorDict:
        step = self.advance(tensordict["action"].numpy())
        out = self._obs_td(step.observation, step.success, step.flipped, step.wall)
        out["reward"] = torch.from_numpy(step.reward).unsqueeze(-1)
        out.update(self._dones(step.terminated, step.truncated))
        return out

    def advance(self, action: np.ndarray) -> Transition:
        """One control step of every env, numpy in and out (what :meth:`_step` wraps in a TensorDict)."""
        before = self.sim.xy.copy()
        self.sim.step(action)
        self.t += 1
        dist = np.linalg.norm(self.goals - self.sim.xy, axis=1)
        success, flipped = dist < self.radius, self.sim.flipped
        task = self.task
        hit = self.touching(self.sim.xy)
        success &= ~hit
        if task.arrive_speed is not None:
            success &= np.linalg.norm(self.sim.qvel[:, :2], axis=1) < task.arrive_speed
        reward = (task.progress_scale * (self.dist - dist) + task.success_bonus * success
                  - task.flip_penalty * flipped - task.step_cost - task.lateral_cost * self._sideways(before)
                  - task.tilt_cost * (1.0 - self.sim.up) - task.wall_penalty * hit)
        self.dist = dist
        more = success & ~flipped & (self.goal_index + 1 < task.goals_per_episode)  # (success excludes a wall hit)
        if more.any():  # chained goals: the next one starts from here, at whatever speed the agent has
            self.goal_index[more] += 1
            self.t[more] = 0
            self._new_goals(np.flatnonzero(more))
        terminated = (success & ~more) | flipped | hit
        truncated = ~terminated & (self.t >= task.max_steps)
        return Transition(self.observe(), reward.astype(np.float32), success, flipped, hit,
                          terminated, truncated)


class Transition(NamedTuple):
    """One control step of every env (rows), as :meth:`GoalReachEnv.advance` returns it."""

    observation: np.ndarray  # after the step (float32)
    reward: np.ndarray  # float32
    success: np.ndarray  # bool, as are the rest
    flipped: np.ndarray
    wall: np.ndarray
    terminated: np.ndarray
    truncated: np.ndarray
