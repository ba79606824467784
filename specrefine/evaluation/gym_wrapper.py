"""A Gymnasium wrapper that judges a run's task as ``specrefine official`` does, step by step, in ``info``.

:class:`TaskJudge` wraps a Gymnasium-Robotics maze environment (``PointMaze_*-v3`` / ``AntMaze_*-v5``) around
a :class:`~specrefine.evaluation.compositional.CompositionalPolicy` and the ORIGINAL task graph of its run.
``reset`` starts the policy's episode (its goal points drawn from the judge's own generator); every ``step``
then applies the rule of ``specrefine official`` (it runs its episodes through this class):

* the episode ends (``terminated``) when the agent touches the current leg's avoid set (closer than the
  evaluator's clearance: walls and hazards), flips (the Ant), has reached every leg's goal region, or has used
  a leg's ``horizon`` decisions;
* then the whole trajectory (the agent's xy at every environment step) is judged by this package's monitor on
  the original task: ``info["task_success"]`` (a flipped Ant fails).

``info`` also carries ``"outcome"`` (None while the episode runs, then ``"success"``, ``"avoid"``,
``"flipped"``, ``"timeout"``, or ``"truncated"`` when the wrapped environment's own time limit came first; a
truncated episode is judged on the steps it had), ``"avoid_contact"``, ``"timeout"`` and ``"leg"`` (the current
leg's index).  The wrapped environment's own ``info["success"]`` is left as it is: it is another test
(within 0.45 m of the environment's goal point at that step, walls never counted; docs/official_env.md).

Without ``options``, ``reset`` draws its start cell uniformly from the maze's start cells and aims the
environment at its first goal cell, from the judge's generator, as ``specrefine official`` does: the same
``seed`` (the judge's, and the environment's on the first ``reset``) gives the same episodes.
"""

from __future__ import annotations

import gymnasium
import numpy as np

from .compositional import CompositionalPolicy, agent_xy, torso_flipped
from .monitor import satisfies

OUTCOMES = ("success", "avoid", "flipped", "timeout", "truncated")


class TaskJudge(gymnasium.Wrapper):
    """``env`` judged on ``task`` (a TaskGraph: the run's original task) while ``policy`` drives it."""

    def __init__(self, env, policy: CompositionalPolicy, task, seed=None):
        super().__init__(env)
        self.policy, self.task = policy, task
        self.rng = np.random.default_rng(seed)  # the episodes' start cells and goal points
        self.outcome: str | None = None
        self._xy: list[np.ndarray] = []
        self._obs = None

    def reset(self, *, seed=None, options=None):
        if options is None:
            starts = self.policy.maze.cells("S")
            options = {"reset_cell": np.array(starts[self.rng.integers(len(starts))]),
                       "goal_cell": np.array(self.policy.maze.cells("G")[0])}
        obs, info = self.env.reset(seed=seed, options=options)
        self.policy.reset(obs, seed=self.rng)
        self._obs, self._xy = obs, [agent_xy(obs)]
        self.outcome = self._ending(obs)
        return obs, {**info, **self._info()}

    def step(self, action):
        if self.outcome is not None:  # decided already (at reset, before any step): nothing moves
            return self._obs, 0.0, True, False, self._info()
        action = np.asarray(action, dtype=self.action_space.dtype)
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._obs = obs
        self._xy.append(agent_xy(obs))
        self.outcome = self._ending(obs)
        if self.outcome is None and (terminated or truncated):
            self.outcome = "truncated"
        ended = self.outcome not in (None, "truncated")
        return obs, reward, ended, self.outcome == "truncated", {**info, **self._info()}

    @property
    def trajectory(self) -> np.ndarray:
        """The agent's xy at every environment step of the current episode (its start included)."""
        return np.array(self._xy)

    def _ending(self, obs) -> str | None:
        """How the episode ends at ``obs``, if it does (the order of ``specrefine official``'s checks)."""
        policy = self.policy
        if policy.touching(self._xy[-1]):
            return "avoid"
        if torso_flipped(policy.agent, obs):
            return "flipped"
        policy.update(obs)
        if policy.done:
            return "success"
        if policy.timed_out:
            return "timeout"
        return None

    def _info(self) -> dict:
        judged = self.outcome is not None
        success = judged and self.outcome != "flipped" and bool(
            satisfies(self.task, self.trajectory[None], clearance=self.policy.clearance)[0])
        return {"task_success": success, "outcome": self.outcome, "avoid_contact": self.outcome == "avoid",
                "timeout": self.outcome == "timeout", "leg": self.policy.leg}
