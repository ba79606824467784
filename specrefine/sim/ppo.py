"""PPO's advantages and clipped loss on plain tensors: the math of TorchRL's ``GAE`` and ``ClipPPOLoss`` as the trainer
configures them (advantage normalised per minibatch, l2 value loss, Monte-Carlo entropy of the TanhNormal), without
their per-call TensorDict and functional-parameter machinery. ``tests/test_train.py`` checks both against TorchRL.
"""

from __future__ import annotations

import torch
from tensordict import TensorDict
from torch import nn

from .collect import LOG_PROB, tanh_normal
from .policy import GoalPolicy


@torch.no_grad()
def add_advantages(batch: TensorDict, critic: nn.Module, gamma: float, lmbda: float) -> None:
    """GAE over a collected batch ``[n_envs, steps]``: writes ``state_value``, ``advantage`` and ``value_target``.

    The critic runs once per distinct observation: a step's next observation is the following step's observation
    unless the episode ended there, so only those and the batch's last column are evaluated again."""
    from torchrl.objectives.value.functional import vec_generalized_advantage_estimate

    nxt = batch["next"]
    value = critic(batch["observation"])
    done = nxt["done"]
    fresh = done.squeeze(-1).clone()
    fresh[:, -1] = True  # the step after the batch's last one is not in it
    next_value = torch.empty_like(value)
    next_value[:, :-1] = value[:, 1:]
    next_value[fresh] = critic(nxt["observation"][fresh])
    advantage, target = vec_generalized_advantage_estimate(gamma, lmbda, value, next_value, nxt["reward"], done=done,
                                                           terminated=nxt["terminated"], time_dim=-2)
    batch.update({"state_value": value, "advantage": advantage, "value_target": target})


class ClipPPO:
    """The clipped PPO loss of one minibatch (a flat slice of a batch that went through :func:`add_advantages`)."""

    def __init__(self, policy: GoalPolicy, critic: nn.Module, clip_epsilon: float, entropy_coef: float,
                 critic_coef: float):
        self.policy, self.critic = policy, critic
        eps = torch.tensor(clip_epsilon)
        self.log_clip = ((-eps).log1p(), eps.log1p())
        self.entropy_coef, self.critic_coef = entropy_coef, critic_coef

    def __call__(self, mb: TensorDict) -> dict[str, torch.Tensor]:
        """``loss_objective``, ``loss_critic``, ``loss_entropy`` (to sum) and the diagnostics ``kl_approx``,
        ``clip_fraction``, ``entropy``."""
        advantage = mb["advantage"]
        advantage = (advantage - advantage.mean()) / advantage.std().clamp_min(torch.finfo(torch.float).resolution)
        dist = tanh_normal(self.policy, mb["observation"])
        log_prob, old = dist.log_prob(mb["action"]), mb[LOG_PROB]
        log_weight = (log_prob - old).unsqueeze(-1)
        clipped = log_weight.clamp(*self.log_clip)
        gain = torch.stack([log_weight.exp() * advantage, clipped.exp() * advantage], -1).min(dim=-1).values
        # the entropy has no closed form under tanh: one reparameterised draw, as TorchRL (the same random numbers)
        with torch.set_grad_enabled(torch.is_grad_enabled() and self.entropy_coef != 0):
            entropy = -dist.rsample_and_log_prob((1,))[1].mean(0).unsqueeze(-1)
        value = self.critic(mb["observation"])
        return {"loss_objective": (-gain).mean(), "loss_critic": (self.critic_coef * (mb["value_target"] - value) ** 2)
                .mean(), "loss_entropy": (-self.entropy_coef * entropy).mean(),
                "kl_approx": (old - log_prob).detach().mean(), "clip_fraction": (clipped != log_weight).float().mean(),
                "entropy": entropy.detach().mean()}
