"""The goal-reaching training task of the goal-conditioned policy, as a TorchRL env over a BatchedSim.

Its own module because TorchRL is slow to import (``torchrl.data`` pulls in Ray where installed):
evaluation and refinement use :class:`specrefine.sim.simulator.BatchedSim` alone and never import it.
"""

from __future__ import annotations

import numpy as np
import torch
from tensordict import TensorDict
from torchrl.data import Bounded, Categorical, Composite, Unbounded
from torchrl.envs import EnvBase

from ..core.agents import ReachTask, get_agent
from .simulator import BatchedSim, sample_goals


class GoalReachEnv(EnvBase):
    """TorchRL env, batch_size [n]: reach a goal on the open floor (training task).

    Reward = ``progress_scale`` x (metres closer to the goal) + ``success_bonus`` on reaching
    it - ``flip_penalty`` on flipping - ``step_cost`` per step.  Done on success, flip or ``max_steps``; finished
    envs are reset by TorchRL's partial ``_reset`` (the collector does it automatically).  With
    ``task.goals_per_episode`` = m > 1, the first m - 1 successes draw a new goal from the current (moving)
    state instead, as a compositional policy switches subtasks, and ``max_steps`` counts per goal.  With
    ``task.goal_radius`` = (lo, hi), each goal counts as reached within its own radius drawn from [lo, hi]
    (a refined graph's goal regions are that size: the next goal arrives while the agent still moves).
    """

    def __init__(self, agent: str, n: int, seed: int = 0, nthread: int | None = None, task: ReachTask | None = None,
                 frame: str = "world"):
        super().__init__(batch_size=torch.Size([n]), device="cpu")
        self.sim = BatchedSim(agent, None, n, nthread=nthread)
        self.frame = frame  # the observation frame of the policy being trained (simulator.BatchedSim.observe)
        self.task = task or get_agent(agent).reach_task
        self.rng = np.random.default_rng(seed)
        self.goals = np.zeros((n, 2))
        self.dist = np.zeros(n)
        self.radius = np.full(n, self.task.success_radius)
        self.t = np.zeros(n, dtype=np.int64)
        self.goal_index = np.zeros(n, dtype=np.int64)  # goals reached so far in this episode
        bs = self.batch_size
        self.observation_spec = Composite(
            observation=Unbounded((*bs, self.sim.obs_dim), dtype=torch.float32),
            success=Categorical(2, (*bs, 1), dtype=torch.bool), flipped=Categorical(2, (*bs, 1), dtype=torch.bool),
            shape=bs)
        self.action_spec = Bounded(-1.0, 1.0, (*bs, self.sim.act_dim), dtype=torch.float32)
        self.reward_spec = Unbounded((*bs, 1), dtype=torch.float32)
        flag = Categorical(2, (*bs, 1), dtype=torch.bool)
        self.done_spec = Composite(done=flag.clone(), terminated=flag.clone(), truncated=flag.clone(), shape=bs)

    def _set_seed(self, seed: int | None):
        self.rng = np.random.default_rng(seed)

    def _obs_td(self, success, flipped) -> TensorDict:
        return TensorDict({
            "observation": torch.from_numpy(self.sim.observe(self.goals, self.frame)),
            "success": torch.from_numpy(success).unsqueeze(-1), "flipped": torch.from_numpy(flipped).unsqueeze(-1),
        }, batch_size=self.batch_size)

    def _reset(self, tensordict: TensorDict | None = None, **kwargs) -> TensorDict:
        mask = np.ones(self.sim.n, dtype=bool)
        if tensordict is not None and "_reset" in tensordict.keys():
            mask = tensordict["_reset"].reshape(self.sim.n).numpy().copy()
        idx = np.flatnonzero(mask)
        self.sim.reset(rng=self.rng, idx=idx)
        self._new_goals(idx)
        self.t[idx] = 0
        self.goal_index[idx] = 0
        zeros = np.zeros(self.sim.n, dtype=bool)
        out = self._obs_td(zeros, zeros)
        out.update(self._dones(zeros, zeros))
        return out

    def _new_goals(self, idx: np.ndarray) -> None:
        """Draw the next goal (and, with ``task.goal_radius``, its radius) of the envs ``idx``, from where they are."""
        task = self.task
        self.goals[idx] = sample_goals(self.sim.xy[idx], task.goal_min, task.goal_max, self.rng)
        self.dist[idx] = np.linalg.norm(self.goals[idx] - self.sim.xy[idx], axis=1)
        if task.goal_radius is not None:
            self.radius[idx] = self.rng.uniform(*task.goal_radius, size=len(idx))

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
        before = self.sim.xy.copy()
        self.sim.step(tensordict["action"].numpy())
        self.t += 1
        dist = np.linalg.norm(self.goals - self.sim.xy, axis=1)
        success, flipped = dist < self.radius, self.sim.flipped
        task = self.task
        if task.arrive_speed is not None:
            success &= np.linalg.norm(self.sim.qvel[:, :2], axis=1) < task.arrive_speed
        reward = (task.progress_scale * (self.dist - dist) + task.success_bonus * success
                  - task.flip_penalty * flipped - task.step_cost - task.lateral_cost * self._sideways(before)
                  - task.tilt_cost * (1.0 - self.sim.up))
        self.dist = dist
        more = success & ~flipped & (self.goal_index + 1 < task.goals_per_episode)
        if more.any():  # chained goals: the next one starts from here, at whatever speed the agent has
            self.goal_index[more] += 1
            self.t[more] = 0
            self._new_goals(np.flatnonzero(more))
        terminated = (success & ~more) | flipped
        truncated = ~terminated & (self.t >= task.max_steps)
        out = self._obs_td(success, flipped)
        out["reward"] = torch.from_numpy(reward.astype(np.float32)).unsqueeze(-1)
        out.update(self._dones(terminated, truncated))
        return out
