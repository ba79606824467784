"""The PPO trainer's on-policy batches: a :class:`~specrefine.sim.reach_env.GoalReachEnv` stepped by the policy on
numpy arrays, one TensorDict per batch.

It collects what TorchRL's ``Collector`` collected for the trainer before (the keys the update reads, shape
``[n_envs, steps]``): the same actions from the same random draws and the same partial resets, so a seeded run sees
the same batches (``tests/test_train.py`` compares the two). What is gone is the per-step TensorDict, spec and
reset machinery around the env and the actor, which cost a third of a second per Ant batch.
"""

from __future__ import annotations

import numpy as np
import torch
from tensordict import TensorDict

from .policy import GoalPolicy
from .reach_env import GoalReachEnv

#: where the log-probability of the sampled action is kept (the name TorchRL's ``ProbabilisticActor`` gives it)
LOG_PROB = "action_log_prob"


def tanh_normal(policy: GoalPolicy, obs: torch.Tensor):
    """The policy's action distribution at ``obs``, as the trainer's ``ProbabilisticActor`` builds it."""
    from torchrl.modules import TanhNormal

    loc, scale = policy(obs)
    return TanhNormal(loc, scale, low=-1.0, high=1.0)


class BatchCollector:
    """Batches of ``steps`` control steps of every env of ``env``, the policy sampling its actions."""

    def __init__(self, env: GoalReachEnv, policy: GoalPolicy, steps: int):
        self.env, self.policy, self.steps = env, policy, steps
        self.obs = env.restart(np.arange(env.sim.n))  # every env starts an episode, as the TorchRL collector did

    def __iter__(self):
        while True:
            yield self.collect()

    @torch.no_grad()
    def collect(self) -> TensorDict:
        env, n, T = self.env, self.env.sim.n, self.steps
        obs = np.empty((n, T, env.obs_dim), dtype=np.float32)
        next_obs = np.empty_like(obs)
        action = np.empty((n, T, env.sim.act_dim), dtype=np.float32)
        log_prob = np.empty((n, T), dtype=np.float32)
        reward = np.empty((n, T), dtype=np.float32)
        flags = {key: np.empty((n, T), dtype=bool) for key in ("success", "flipped", "wall", "terminated",
                                                                "truncated")}
        for t in range(T):
            obs[:, t] = self.obs
            a, lp = tanh_normal(self.policy, torch.from_numpy(self.obs)).rsample_and_log_prob()
            action[:, t] = a.numpy()
            log_prob[:, t] = lp.numpy()
            step = env.advance(action[:, t])
            next_obs[:, t] = step.observation
            reward[:, t] = step.reward
            for key, arr in flags.items():
                arr[:, t] = getattr(step, key)
            done = step.terminated | step.truncated
            self.obs = env.restart(np.flatnonzero(done)) if done.any() else step.observation
        column = {key: torch.from_numpy(arr).unsqueeze(-1) for key, arr in flags.items()}
        column["done"] = column["terminated"] | column["truncated"]
        nxt = {"observation": torch.from_numpy(next_obs), "reward": torch.from_numpy(reward).unsqueeze(-1), **column}
        return TensorDict({"observation": torch.from_numpy(obs), "action": torch.from_numpy(action),
                           LOG_PROB: torch.from_numpy(log_prob), "next": TensorDict(nxt, batch_size=[n, T])},
                          batch_size=[n, T])
