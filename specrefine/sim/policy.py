"""The goal-conditioned subtask policy: observation normaliser + 2x256 tanh-Gaussian actor.

A checkpoint is a small ``torch.save`` dict (float32 ``state_dict`` plus a few header
fields), loaded with ``weights_only=True``; ``load_policy`` checks the header, the shapes and that every
weight is finite, and turns any problem into a one-line :class:`PolicyError`.
"""

from __future__ import annotations

import hashlib
import warnings
from pathlib import Path

import numpy as np
import torch
from torch import nn

from ..core.agents import AGENTS, OBSERVATION_FRAMES
from ..core.errors import PolicyError
from ..core.paths import data_dir, shipped_name

FORMAT = "specrefine-policy"
VERSION = 1
HIDDEN = 256
POLICY_DIR = data_dir() / "policies"
OBS_ACT_DIMS = {name: (a.obs_dim, a.act_dim) for name, a in AGENTS.items()}
LOOKAHEAD_DIM = 2  # the next goal relative to the agent, in the frame of the current goal


def observation_dims(agent: str, lookahead: bool = False) -> tuple[int, int]:
    """(observation, action) sizes of ``agent``'s goal policy, with or without the look-ahead inputs."""
    obs_dim, act_dim = OBS_ACT_DIMS[agent]
    return obs_dim + (LOOKAHEAD_DIM if lookahead else 0), act_dim


def wants_lookahead(policy) -> bool:
    """Whether ``policy`` observes the next goal too (a scripted controller or a plain callable does not)."""
    return bool(getattr(policy, "lookahead", False))


def mlp(n_in: int, n_out: int, hidden: int = HIDDEN) -> nn.Sequential:
    return nn.Sequential(nn.Linear(n_in, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh(),
                         nn.Linear(hidden, n_out))


class Normalizer(nn.Module):
    """Running mean / variance of observations (parallel Welford); output clipped to +-10."""

    def __init__(self, dim: int, clip: float = 10.0):
        super().__init__()
        self.clip = clip
        self.register_buffer("mean", torch.zeros(dim))
        self.register_buffer("var", torch.ones(dim))
        self.register_buffer("count", torch.tensor(1e-4))

    @torch.no_grad()
    def update(self, x: torch.Tensor) -> None:
        x = x.reshape(-1, self.mean.numel()).double()
        n, m, v = x.shape[0], x.mean(0), x.var(0, unbiased=False)
        tot = self.count.double() + n
        delta = m - self.mean.double()
        self.var.copy_((self.var * self.count + v * n + delta**2 * self.count * n / tot) / tot)
        self.mean.copy_(self.mean + delta * n / tot)
        self.count.copy_(tot)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return ((x - self.mean) / torch.sqrt(self.var + 1e-8)).clamp(-self.clip, self.clip)


class GoalPolicy(nn.Module):
    """``forward(obs) -> (loc, scale)`` of a Gaussian squashed by tanh into [-1, 1]."""

    def __init__(self, agent: str, obs_dim: int | None = None, act_dim: int | None = None,
                 observation_frame: str = "world", lookahead: bool = False):
        super().__init__()
        if agent not in OBS_ACT_DIMS:
            raise PolicyError(f"unknown agent {agent!r}; expected one of {', '.join(OBS_ACT_DIMS)}")
        if observation_frame not in OBSERVATION_FRAMES:
            raise PolicyError(f"observation frame {observation_frame!r}; expected one of "
                              f"{', '.join(OBSERVATION_FRAMES)}")
        self.agent = agent
        #: what ``simulator.BatchedSim.observe`` must hand this policy ("world": every policy before the heading frame)
        self.observation_frame = observation_frame
        #: whether it also observes the goal after the current one (``BatchedSim.observe``'s ``next_goals``)
        self.lookahead = bool(lookahead)
        self.obs_dim, self.act_dim = (obs_dim, act_dim) if obs_dim else observation_dims(agent, lookahead)
        self.norm = Normalizer(self.obs_dim)
        self.net = mlp(self.obs_dim, 2 * self.act_dim)
        self.min_scale = 1e-3

    def forward(self, obs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        loc, s = self.net(self.norm(obs)).chunk(2, dim=-1)
        return loc, nn.functional.softplus(s - 0.5) + self.min_scale  # initial scale ~0.47

    @torch.no_grad()
    def act(self, obs: np.ndarray, deterministic: bool = True, generator: torch.Generator | None = None) -> np.ndarray:
        """Actions in [-1, 1] for a batch of observations ``(n, obs_dim)``."""
        loc, scale = self(torch.as_tensor(np.asarray(obs, dtype=np.float32)))
        if not deterministic:
            loc = loc + scale * torch.randn(loc.shape, generator=generator)
        return torch.tanh(loc).numpy()

    @property
    def fingerprint(self) -> str:
        h = hashlib.sha1(self.agent.encode())
        if self.observation_frame != "world":  # the same weights fed another observation are another policy
            h.update(self.observation_frame.encode())
        if self.lookahead:  # only when on: every policy before it keeps its fingerprint
            h.update(b"lookahead")
        for name, t in sorted(self.state_dict().items()):
            h.update(name.encode())
            h.update(t.detach().cpu().float().contiguous().numpy().tobytes())
        return h.hexdigest()[:12]


def widened(policy: GoalPolicy) -> GoalPolicy:
    """``policy`` (without look-ahead) as a look-ahead policy that acts exactly as it does: the first layer gains
    zero columns for the new inputs, whose normaliser statistics start as those of the current goal's (the next
    goal lies about as far away)."""
    if policy.lookahead:
        return policy
    wide = GoalPolicy(policy.agent, observation_frame=policy.observation_frame, lookahead=True)
    state = {k: v.clone() for k, v in policy.state_dict().items()}
    first = state["net.0.weight"]
    state["net.0.weight"] = torch.cat([first, torch.zeros(first.shape[0], LOOKAHEAD_DIM)], dim=1)
    for key in ("norm.mean", "norm.var"):
        state[key] = torch.cat([state[key], state[key][-LOOKAHEAD_DIM:]])
    wide.load_state_dict(state)
    wide.meta = dict(getattr(policy, "meta", {}))
    return wide.train(policy.training)


def save_policy(policy: GoalPolicy, path, meta: dict | None = None) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    from ..core.runfolder import replacing

    state = {k: v.detach().cpu().float().clone() for k, v in policy.state_dict().items()}
    with replacing(path, "wb") as fh:
        header = {"lookahead": True} if policy.lookahead else {}  # files without it load as before
        torch.save({"format": FORMAT, "version": VERSION, "agent": policy.agent, "obs_dim": policy.obs_dim,
                    "act_dim": policy.act_dim, "observation_frame": policy.observation_frame, **header,
                    "state_dict": state, "meta": dict(meta or {})}, fh)


def _resolve(path_or_agent) -> Path:
    if isinstance(path_or_agent, str) and (path_or_agent in OBS_ACT_DIMS or shipped_name(path_or_agent)):
        return POLICY_DIR / f"{path_or_agent}.pt"
    return Path(path_or_agent)


def safe_load(path):
    """``torch.load`` of tensors and plain containers only (``weights_only=True``: a pickle that would run code is
    refused, not run); torch's warnings about the file's pickle protocol are not shown."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return torch.load(path, map_location="cpu", weights_only=True)


def load_policy(path_or_agent) -> GoalPolicy:
    """``'point'`` / ``'ant'`` (the shipped files), a shipped checkpoint's stem (``'ant_stage5'``) or a path ->
    :class:`GoalPolicy` in eval mode."""
    path = _resolve(path_or_agent)
    if not path.is_file():
        raise PolicyError(f"{path}: policy file not found")
    try:
        blob = safe_load(path)
    except Exception as e:  # noqa: BLE001 - truncated zip, pickle garbage, a pickle that needs code to load, ...
        raise PolicyError(f"{path}: not a readable policy file ({type(e).__name__})") from None
    if not isinstance(blob, dict) or blob.get("format") != FORMAT:
        raise PolicyError(f"{path}: not a specrefine policy file")
    if blob.get("version") != VERSION:
        raise PolicyError(f"{path}: policy format version {blob.get('version')}, this code reads {VERSION}")
    agent, lookahead = blob.get("agent"), blob.get("lookahead", False)  # files before the look-ahead carry none
    if not isinstance(lookahead, bool):
        raise PolicyError(f"{path}: header field lookahead is {lookahead!r:.40}, expected true or false")
    if agent not in OBS_ACT_DIMS or (blob.get("obs_dim"), blob.get("act_dim")) != observation_dims(agent, lookahead):
        raise PolicyError(f"{path}: agent/shape header ({agent}, {blob.get('obs_dim')}, {blob.get('act_dim')}) "
                          "does not match a known agent")
    if isinstance(path_or_agent, str) and path_or_agent in OBS_ACT_DIMS and agent != path_or_agent:
        raise PolicyError(f"{path}: holds a {agent} policy, expected {path_or_agent}")
    try:  # files written before the heading frame carry none
        policy = GoalPolicy(agent, observation_frame=blob.get("observation_frame", "world"), lookahead=lookahead)
    except PolicyError as exc:
        raise PolicyError(f"{path}: {exc}") from None
    state = blob.get("state_dict")
    if not isinstance(state, dict):
        raise PolicyError(f"{path}: no weights (state_dict) in the policy file")
    expected = policy.state_dict()
    missing, extra = sorted(set(expected) - set(state)), sorted(set(state) - set(expected))
    if missing or extra:
        raise PolicyError(f"{path}: weights do not fit a {agent} policy (" + "; ".join(
            f"{what} {', '.join(map(str, keys[:4]))}{', ...' if len(keys) > 4 else ''}"
            for what, keys in (("missing", missing), ("unexpected", extra)) if keys) + ")")
    try:
        policy.load_state_dict(state)
    except (RuntimeError, KeyError, TypeError) as e:
        first = " ".join(str(e).split()) or type(e).__name__  # torch names the tensors on its second line
        raise PolicyError(f"{path}: weights do not fit a {agent} policy ({first[:200]})") from None
    broken = [name for name, t in policy.state_dict().items() if not torch.isfinite(t).all()]
    if broken:  # it would run, driving the simulator with NaN actions (tens of thousands of MuJoCo warnings)
        raise PolicyError(f"{path}: weights hold NaN or infinite values ({', '.join(broken[:3])}"
                          f"{', ...' if len(broken) > 3 else ''}); retrain or restore the checkpoint")
    _check_normaliser(policy.norm, path)
    policy.meta = blob.get("meta", {})
    return policy.eval()


def _check_normaliser(norm: Normalizer, path) -> None:
    """Finite is not enough: a negative variance (NaN square root) or a count <= 0 makes every action NaN."""
    if (norm.var < 0).any():
        raise PolicyError(f"{path}: the observation normaliser's variance is negative (norm.var); the policy would "
                          "act with NaN: retrain or restore the checkpoint")
    if not float(norm.count) > 0:
        raise PolicyError(f"{path}: the observation normaliser's count is {float(norm.count):g} (norm.count), not > 0: "
                          "retrain or restore the checkpoint")


class PointController:
    """A straight-line controller for the point mass (no learning, no knowledge of walls).

    It tracks the velocity ``min(gain * |e|, vmax)`` towards the goal (``e`` = goal - xy) with a
    proportional force: ``a = clip(kv * (v* - v), -1, 1)``.  Observation layout as in
    :class:`~specrefine.sim.simulator.BatchedSim` for the point: velocity (2), goal - xy (2).  Deterministic;
    a stand-in policy for tests and for notebooks without a trained checkpoint.
    """

    agent = "point"

    def __init__(self, gain: float = 4.0, vmax: float = 2.0, kv: float = 0.2):
        self.gain, self.vmax, self.kv = float(gain), float(vmax), float(kv)
        self.fingerprint = f"point-line-g{self.gain:g}-v{self.vmax:g}-k{self.kv:g}"

    def act(self, obs, deterministic: bool = True) -> np.ndarray:
        obs = np.asarray(obs, dtype=np.float64)
        e = obs[:, 2:4]
        d = np.linalg.norm(e, axis=1, keepdims=True)
        v_star = e * np.minimum(self.gain, self.vmax / np.maximum(d, 1e-9))
        return np.clip(self.kv * (v_star - obs[:, 0:2]), -1.0, 1.0)

    __call__ = act
