"""Goal-conditioned PPO (TorchRL building blocks), CleanRL-style: one file, one config dataclass whose
documented fields are the command line; PPO diagnostics (approximate KL, clip fraction, entropy, value loss,
explained variance) go into the curves.

    python -m specrefine.sim.train --agent point --frames 400000 --out runs/point
    python -m specrefine.sim.train --agent ant --frames 10000000 --out runs/ant_train --resume
    python -m specrefine.sim.train --agent ant --evaluate data/policies/ant.pt --episodes 500
    python -m specrefine.sim.train --agent ant --evaluate ant --chain 8 --goal-range 3 5   # goals in a row

Task: reach a goal sampled on the open floor (``specrefine.sim.reach_env.GoalReachEnv``); the policy never
sees a maze.  ``OUT/`` receives ``checkpoint.pt`` (everything needed to resume), ``policy.pt``
(the shippable policy), ``log.jsonl`` (one line per batch) and ``curve.png``.

This module is the config, the PPO loop and its checkpoints, and the command line.  ``--evaluate`` runs the
open-floor evaluation of :mod:`specrefine.sim.policy_eval`; the figures (``curve.png``, success against distance,
rollouts) are drawn by :mod:`specrefine.sim.curves`.  Their functions are importable from here too (notebook 01).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path

import numpy as np
import torch
from tensordict.nn import TensorDictModule
from torch import nn
from tqdm.auto import tqdm

from ..core.agents import AGENTS, get_agent
from ..core.argtypes import bounded_int, out_path
from ..core.errors import SpecrefineError
from ..core.runfolder import ensure_dir, locked, open_append, output_file, save_figure, writing_into
from .collect import BatchCollector
from .curves import plot_curve, plot_rollouts, plot_success_by_distance, read_log
from .policy import GoalPolicy, load_policy, mlp, safe_load, save_policy, widened
from .policy_eval import evaluate_chain, evaluate_reach, success_by_distance, summary
from .ppo import ClipPPO, add_advantages
from .reach_env import GoalReachEnv
from .switching import AT_REGION, SWITCHING

__all__ = ["PPO_DIAGNOSTICS", "Config", "Trainer", "config_arguments", "explained_variance", "make_config", "main",
           "make_modules", "train",
           # the evaluation and its figures live in policy_eval and curves; importable from here (notebook 01)
           "evaluate_chain", "evaluate_reach", "plot_curve", "plot_rollouts", "plot_success_by_distance", "read_log",
           "success_by_distance", "summary"]


def knob(default, help: str):
    """A documented config field: its ``help`` becomes the command line's (``python -m specrefine.sim.train -h``)."""
    return field(default=default, metadata={"help": help})


@dataclass
class Config:
    """Every training knob; each field is also a ``--field-name`` option (default: the agent's entry)."""

    agent: str = knob("point", "a registered agent (specrefine.core.agents)")
    frames: int = knob(300_000, "total environment frames")
    seed: int = knob(0, "seed of torch and the goal sampler")
    num_envs: int = knob(64, "environments stepped together")
    steps_per_env: int = knob(32, "steps per environment per batch (frames per batch = num_envs x steps_per_env)")
    epochs: int = knob(4, "PPO epochs per batch")
    minibatch: int = knob(1024, "PPO minibatch size (large: the update is cheap per frame)")
    lr: float = knob(3e-4, "Adam learning rate")
    anneal_lr: bool = knob(True, "anneal the learning rate linearly to 5%% of lr")
    gamma: float = knob(0.99, "discount")
    gae_lambda: float = knob(0.95, "GAE lambda")
    clip_epsilon: float = knob(0.2, "PPO clip range")
    entropy_coef: float = knob(0.0, "entropy bonus coefficient")
    critic_coef: float = knob(0.5, "value loss coefficient")
    max_grad_norm: float = knob(0.5, "gradient norm clip")
    torch_threads: int = knob(1, "torch threads")
    update_threads: int | None = knob(None, "torch threads of the PPO update (default: torch_threads); the "
                                            "collection keeps torch_threads, as MuJoCo's threads have the cores then")
    sim_threads: int = knob(2, "mujoco.rollout threads")
    checkpoint_every_s: float = knob(120.0, "seconds between checkpoints")
    goals_per_episode: int = knob(1, "> 1: chain this many goals per episode, each drawn where the last was reached")
    init: str | None = knob(None, "fine-tune from a trainer checkpoint.pt (actor + critic) or a policy file "
                                  "('ant', 'point' or a policy.pt: actor only, the critic starts afresh)")
    critic_warmup_frames: int = knob(0, "first train the critic alone for this many frames (after --init POLICY)")
    tilt_cost: float | None = knob(None, "reward -= this x (1 - torso up z) per step (default: the agent's task)")
    flip_penalty: float | None = knob(None, "reward -= this on flipping (default: the agent's task)")
    lateral_cost: float | None = knob(None, "reward -= this x metres moved across the line to the goal "
                                            "(default: the agent's task)")
    observation_frame: str = knob("world", "the policy's observation: 'world' (torso quaternion and velocity as "
                                           "MuJoCo holds them, as every shipped policy) or 'heading' (the heading "
                                           "taken out: behaviour independent of the direction of travel)")
    switch_radius: tuple[float, float] | None = knob(None, "each goal counts as reached within a radius drawn "
                                                           "from [LO, HI] m (default: the task's success radius)")
    train_maze: str | None = knob(None, "train among walls: 'random:RxC:SEED' (a generated corridor maze of R x C "
                                        "rooms, none of the benchmark's layouts) or any maze the CLI takes; goals "
                                        "are neighbouring cells' centres (default: the open floor)")
    wall_penalty: float | None = knob(None, "with --train-maze: touching a wall ends the episode with this "
                                            "penalty (default: the agent's task)")
    train_goal_points: str = knob("centre", "with --train-maze: each goal at the neighbouring cell's 'centre' or "
                                            "'sampled', a uniform point of it at least the body's clearance from "
                                            "its walls (as the sampled goal-point rule aims: some by a wall)")
    turn_goals: tuple[float, float] | None = knob(None, "open floor, chained goals: every goal after an episode's "
                                                        "first turns by LO-HI degrees (either side) from the "
                                                        "direction of travel at the switch; with --evaluate --chain: "
                                                        "the same for the evaluated goals (default: any direction)")
    lookahead: bool = knob(False, "the policy also observes the goal after the current one (open floor; chained "
                                  "goals are then drawn one ahead); --init from a policy without it widens its first "
                                  "layer with zero weights, so training starts from that policy's behaviour")

    @property
    def frames_per_batch(self) -> int:
        return self.num_envs * self.steps_per_env


#: logged per batch (mean over minibatches): log key -> ClipPPOLoss output
PPO_DIAGNOSTICS = {"approx_kl": "kl_approx", "clip_fraction": "clip_fraction", "entropy": "entropy",
                   "value_loss": "loss_critic"}


def explained_variance(target: torch.Tensor, value: torch.Tensor) -> float:
    """1 - Var(target - value) / Var(target): 1 for a perfect critic, <= 0 for a useless one (nan if Var = 0)."""
    target, value = target.detach().reshape(-1).double(), value.detach().reshape(-1).double()
    var = target.var()
    return float(1.0 - (target - value).var() / var) if var > 0 else float("nan")


def _radius_range(pair) -> tuple[float, float]:
    lo, hi = (float(x) for x in pair)
    if not 0 < lo <= hi:
        raise SpecrefineError(f"--switch-radius {lo:g} {hi:g}: needs 0 < LO <= HI (metres)")
    return lo, hi


def turn_range(pair) -> tuple[float, float]:
    """``--turn-goals LO HI``: degrees, 0 <= LO <= HI <= 180, else a one-line error."""
    lo, hi = (float(x) for x in pair)
    if not 0 <= lo <= hi <= 180:
        raise SpecrefineError(f"--turn-goals {lo:g} {hi:g}: needs 0 <= LO <= HI <= 180 (degrees)")
    return lo, hi


def config_arguments(parser: argparse.ArgumentParser) -> None:
    """One ``--field-name`` option per :class:`Config` field (except ``agent``), default None = the agent's."""
    types = {"int": int, "float": float, "str": str, "str | None": str, "float | None": float, "int | None": int}
    for f in fields(Config):
        if f.name == "agent":
            continue
        flag = "--" + f.name.replace("_", "-")
        help_text = f"{f.metadata['help']} (default: {f.default})"
        if f.type == "bool":
            parser.add_argument(flag, action=argparse.BooleanOptionalAction, default=None, help=help_text)
        elif f.type == "tuple[float, float] | None":
            parser.add_argument(flag, type=float, nargs=2, metavar=("LO", "HI"), default=None, help=help_text)
        else:
            parser.add_argument(flag, type=types[f.type], default=None, help=help_text)


def make_config(agent: str, **overrides) -> Config:
    """The agent's training defaults (``specrefine.core.agents``) with ``overrides`` on top."""
    cfg = replace(Config(agent=agent), **{**get_agent(agent).train, **overrides})
    if cfg.wall_penalty is not None and cfg.train_maze is None:
        raise SpecrefineError("--wall-penalty needs --train-maze (on the open floor there is no wall to touch)")
    if cfg.train_goal_points not in ("centre", "sampled"):
        raise SpecrefineError(f"--train-goal-points {cfg.train_goal_points}: 'centre' or 'sampled'")
    if cfg.train_goal_points == "sampled" and cfg.train_maze is None:
        raise SpecrefineError("--train-goal-points sampled needs --train-maze (on the open floor a goal is any point)")
    if cfg.turn_goals is not None:
        cfg = replace(cfg, turn_goals=turn_range(cfg.turn_goals))
        if cfg.train_maze is not None:
            raise SpecrefineError("--turn-goals draws goals on the open floor: not with --train-maze")
    if cfg.lookahead and cfg.train_maze is not None:
        raise SpecrefineError("--lookahead draws its goals on the open floor: not with --train-maze")
    return cfg


def training_maze(text: str | None):
    """``--train-maze``: None (open floor) or any maze the CLI takes, 'random:RxC:SEED' (``core.mazes.random_maze``)
    among them."""
    from ..core.mazes import load_maze

    return None if text is None else load_maze(text)


# --- networks ---------------------------------------------------------------------------------
def make_modules(policy: GoalPolicy, env: GoalReachEnv):
    """TorchRL wrappers: a TanhNormal ``ProbabilisticActor`` around the policy, a ``ValueOperator``."""
    from torchrl.modules import ProbabilisticActor, TanhNormal, ValueOperator

    actor = ProbabilisticActor(
        TensorDictModule(policy, in_keys=["observation"], out_keys=["loc", "scale"]),
        in_keys=["loc", "scale"], spec=env.action_spec, distribution_class=TanhNormal,
        distribution_kwargs={"low": -1.0, "high": 1.0}, return_log_prob=True)
    critic = ValueOperator(nn.Sequential(policy.norm, mlp(policy.obs_dim, 1)), in_keys=["observation"])
    return actor, critic


# --- training ---------------------------------------------------------------------------------
def read_checkpoint(path, option: str) -> dict:
    """A trainer checkpoint's dict, loaded safely (tensors and plain containers only: no code runs); anything
    else, or a file that needs more than that to load, is a one-line error naming ``option``."""
    path = Path(path)
    if not path.is_file():
        raise SpecrefineError(f"{option} {path}: no such checkpoint file (or not a regular file)")
    try:
        ck = safe_load(path)
    except Exception as e:  # noqa: BLE001 - a pickle that needs code, a truncated zip, garbage: all refused
        raise SpecrefineError(f"{option} {path}: not a trainer checkpoint that loads safely (tensors and plain "
                              f"containers only; {type(e).__name__})") from None
    if not isinstance(ck, dict):
        raise SpecrefineError(f"{option} {path}: not a trainer checkpoint (holds a {type(ck).__name__})")
    missing = [key for key in CHECKPOINT_KEYS if key not in ck]
    if missing:
        raise SpecrefineError(f"{option} {path}: not a trainer checkpoint (no {', '.join(missing)})")
    return ck


CHECKPOINT_KEYS = ("loss", "optim", "frames", "iteration", "torch_rng")  # what save_checkpoint writes


def _first_line(exc: Exception) -> str:
    text = str(exc).strip()
    return f"{type(exc).__name__}: {text.splitlines()[0][:160]}" if text else type(exc).__name__


class Trainer:
    def __init__(self, cfg: Config, out: str | Path, resume: bool = False, progress: bool = True):
        from torchrl.objectives import ClipPPOLoss

        self.cfg, self.out, self.progress = cfg, ensure_dir(out), progress
        torch.set_num_threads(cfg.torch_threads)
        torch.manual_seed(cfg.seed)
        optional = {k: v for k in ("tilt_cost", "flip_penalty", "lateral_cost", "wall_penalty")
                    if (v := getattr(cfg, k)) is not None}
        if cfg.switch_radius is not None:
            optional["goal_radius"] = _radius_range(cfg.switch_radius)
        task = replace(get_agent(cfg.agent).reach_task, goals_per_episode=cfg.goals_per_episode, **optional)
        # the policy first: a bad --observation-frame is one line before the simulator is built
        self.policy = GoalPolicy(cfg.agent, observation_frame=cfg.observation_frame, lookahead=cfg.lookahead)
        self.env = GoalReachEnv(cfg.agent, cfg.num_envs, seed=cfg.seed, nthread=cfg.sim_threads, task=task,
                                frame=cfg.observation_frame, maze=training_maze(cfg.train_maze), turn=cfg.turn_goals,
                                goal_points=cfg.train_goal_points, lookahead=cfg.lookahead)
        self.actor, self.critic = make_modules(self.policy, self.env)
        # TorchRL's loss holds the actor's and critic's parameters: its state_dict is a checkpoint's "loss" (every
        # checkpoint so far); the update computes the same loss with ppo.ClipPPO, without its per-call machinery
        self.loss = ClipPPOLoss(self.actor, self.critic, clip_epsilon=cfg.clip_epsilon,
                                entropy_coeff=cfg.entropy_coef, critic_coeff=cfg.critic_coef,
                                loss_critic_type="l2", normalize_advantage=True)
        self.value = self.critic.module  # observation -> value, the plain module
        self.ppo = ClipPPO(self.policy, self.value, cfg.clip_epsilon, cfg.entropy_coef, cfg.critic_coef)
        self.optim = torch.optim.Adam(self.loss.parameters(), lr=cfg.lr, eps=1e-5)
        self.frames, self.iteration, self.wall = 0, 0, 0.0
        if resume and (self.out / "checkpoint.pt").is_file():
            self._load_checkpoint(self.out / "checkpoint.pt")
        elif cfg.init:
            self._load_weights(cfg.init)
        self.collector = BatchCollector(self.env, self.policy, cfg.steps_per_env)
        self.ep_return = np.zeros(cfg.num_envs)

    # checkpointing
    def _load_checkpoint(self, path: Path) -> None:
        ck = read_checkpoint(path, "--resume")
        try:
            self.loss.load_state_dict(ck["loss"])
            self.optim.load_state_dict(ck["optim"])
            self.frames, self.iteration = int(ck["frames"]), int(ck["iteration"])
            self.wall = float(ck.get("wall", 0.0))
            torch.set_rng_state(ck["torch_rng"])
        except (KeyError, TypeError, ValueError, RuntimeError) as e:
            raise SpecrefineError(f"--resume {path}: not a trainer checkpoint of this agent ({_first_line(e)})") \
                from None
        self.env.rng = np.random.default_rng(self.cfg.seed + self.iteration)

    def _load_weights(self, init: str) -> None:
        """Start from another run's actor, critic and observation statistics (frames and optimiser start afresh),
        or from a policy file's actor and observation statistics (the critic starts afresh)."""
        from ..core.errors import PolicyError

        path = Path(init)
        try:
            shipped = load_policy(init)
        except PolicyError:
            shipped = None
        if shipped is not None:
            if shipped.agent != self.cfg.agent:
                raise SpecrefineError(f"--init {init}: a {shipped.agent} policy, not one for the {self.cfg.agent}")
            if shipped.lookahead and not self.cfg.lookahead:
                raise SpecrefineError(f"--init {init}: a look-ahead policy; train it on with --lookahead")
            self.policy.load_state_dict((widened(shipped) if self.cfg.lookahead else shipped).state_dict())
            return
        ck = read_checkpoint(path, "--init")
        try:
            self.loss.load_state_dict(ck["loss"])
        except (KeyError, TypeError, ValueError, RuntimeError) as e:
            raise SpecrefineError(f"--init {path}: not a trainer checkpoint of this agent ({_first_line(e)})") \
                from None

    def save_checkpoint(self) -> None:
        from ..core.runfolder import replacing

        with replacing(self.out / "checkpoint.pt", "wb") as fh:  # whole, and never through a link
            torch.save({"config": asdict(self.cfg), "loss": self.loss.state_dict(), "optim": self.optim.state_dict(),
                        "frames": self.frames, "iteration": self.iteration, "wall": self.wall,
                        "torch_rng": torch.get_rng_state()}, fh)
        save_policy(self.policy, self.out / "policy.pt", {"frames": self.frames, "config": asdict(self.cfg)})
        plot_curve(self.out / "log.jsonl", self.out / "curve.png")

    # one PPO update on a collected batch
    def update(self, batch) -> dict:
        threads = torch.get_num_threads()
        torch.set_num_threads(self.cfg.update_threads or self.cfg.torch_threads)
        try:
            return self._update(batch)
        finally:
            torch.set_num_threads(threads)

    def _update(self, batch) -> dict:
        cfg = self.cfg
        if cfg.anneal_lr:
            for g in self.optim.param_groups:
                g["lr"] = cfg.lr * max(0.05, 1.0 - self.frames / cfg.frames)
        add_advantages(batch, self.value, cfg.gamma, cfg.gae_lambda)
        flat = batch.reshape(-1)
        critic_only = self.frames < cfg.critic_warmup_frames  # a fresh critic's advantages would steer the actor wrong
        stats: dict[str, list[float]] = {key: [] for key in ("loss", *PPO_DIAGNOSTICS)}
        for _ in range(cfg.epochs):
            for idx in torch.randperm(flat.shape[0]).split(cfg.minibatch):
                losses = self.ppo(flat[idx])
                total = losses["loss_critic"] if critic_only else \
                    losses["loss_objective"] + losses["loss_critic"] + losses.get("loss_entropy", 0.0)
                self.optim.zero_grad()
                total.backward()
                nn.utils.clip_grad_norm_(self.loss.parameters(), cfg.max_grad_norm)
                self.optim.step()
                stats["loss"].append(total.item())
                for key, name in PPO_DIAGNOSTICS.items():
                    if name in losses:
                        stats[key].append(float(losses[name].detach().float().mean()))
        self.policy.norm.update(batch["observation"])  # after the update: stored log-probs stay valid
        out = {key: float(np.mean(v)) for key, v in stats.items() if v}
        return out | {"explained_variance": explained_variance(flat["value_target"], flat["state_value"])}

    def episode_stats(self, batch) -> dict:
        nxt = batch["next"]
        done = nxt["done"].squeeze(-1).numpy()
        rew = nxt["reward"].squeeze(-1).numpy()
        returns = []
        for t in range(done.shape[1]):
            self.ep_return += rew[:, t]
            returns.extend(self.ep_return[done[:, t]])
            self.ep_return[done[:, t]] = 0.0
        n_done = int(done.sum())
        succ = int(nxt["success"].squeeze(-1).numpy()[done].sum())
        flips = int(nxt["flipped"].squeeze(-1).numpy()[done].sum())
        walls = int(nxt["wall"].squeeze(-1).numpy()[done].sum())
        return {"episodes": n_done, "success_rate": succ / n_done if n_done else float("nan"),
                "flip_rate": flips / n_done if n_done else float("nan"),
                "wall_rate": walls / n_done if n_done else float("nan"),
                "return": float(np.mean(returns)) if returns else float("nan")}

    def train(self) -> Path:
        with locked(self.out):  # a second trainer here would interleave its log and checkpoints with this one's
            return self._train()

    def _train(self) -> Path:
        cfg = self.cfg
        bar = tqdm(total=cfg.frames, initial=min(self.frames, cfg.frames), unit="frames",
                   disable=not self.progress, dynamic_ncols=True)
        last_ck = time.time()
        log = open_append(self.out / "log.jsonl", "training log")  # never through a link
        t_batch = time.time()
        while self.frames < cfg.frames:
            batch = self.collector.collect()
            info = self.episode_stats(batch)
            info.update(self.update(batch))
            self.frames += batch.numel()
            self.iteration += 1
            now = time.time()
            self.wall += now - t_batch
            info.update(frames=self.frames, iteration=self.iteration, wall_s=round(self.wall, 2),
                        fps=round(batch.numel() / (now - t_batch), 1))
            t_batch = now
            log.write(json.dumps(info) + "\n")
            log.flush()
            bar.update(batch.numel())
            bar.set_postfix(success=f"{info['success_rate']:.2f}", ret=f"{info['return']:.2f}", fps=int(info["fps"]))
            if now - last_ck > cfg.checkpoint_every_s:
                self.save_checkpoint()
                last_ck = now
        log.close()
        bar.close()
        self.save_checkpoint()
        return self.out / "policy.pt"


def train(agent: str, frames: int, out, resume: bool = False, progress: bool = True, **overrides) -> Path:
    """Train (or continue) a policy; returns the path of ``OUT/policy.pt``."""
    return Trainer(make_config(agent, frames=frames, **overrides), out, resume, progress).train()


# --- command line -----------------------------------------------------------------------------
def add_arguments(ap) -> None:
    ap.description = __doc__.split("\n\n")[0]
    ap.add_argument("--agent", choices=list(AGENTS), required=True, help="the agent to train (required)")
    ap.add_argument("--out", type=out_path, default=None,
                    help="run directory (checkpoint, log, curve) (default: none; required for training)")
    ap.add_argument("--resume", action="store_true", help="continue from OUT/checkpoint.pt")
    ap.add_argument("--evaluate", metavar="POLICY",
                    help="only evaluate POLICY ('point', 'ant' or a path) (default: none: train)")
    ap.add_argument("--episodes", type=bounded_int("episodes"), default=500, help="with --evaluate: episodes")
    ap.add_argument("--goal-range", type=float, nargs=2, default=None, metavar=("LO", "HI"),
                    help="with --evaluate: goal distances in m (default: the agent's reach task's)")
    ap.add_argument("--plot", metavar="PNG",
                    help="with --evaluate: save the success-vs-distance plot here (default: none)")
    ap.add_argument("--no-progress", action="store_true", help="no progress bar")
    ap.add_argument("--chain", type=bounded_int("chain"), default=None, metavar="K",
                    help="with --evaluate: K goals in a row per episode, no reset (see evaluate_chain) "
                         "(default: one goal per episode)")
    ap.add_argument("--switching", choices=SWITCHING, default=AT_REGION,
                    help="with --evaluate --chain: when the policy is fed the next goal: at-region (at once) or "
                         "slow-turn (a fast, turned start brakes first; specrefine.sim.switching) (default: "
                         "at-region)")
    ap.add_argument("--planned-goals", action=argparse.BooleanOptionalAction, default=None,
                    help="with --evaluate --chain: draw each episode's goals before it starts, each from the goal "
                         "before it, so every policy meets the same goals and a look-ahead policy sees the next "
                         "(default: on for a look-ahead policy, else off: each goal drawn where the last was reached)")
    config_arguments(ap)


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("train", argv, prog="python -m specrefine.sim.train")


def run(args, ap) -> int:
    seed = args.seed or 0
    try:
        if args.evaluate and args.chain:
            lo, hi = args.goal_range or (None, None)
            turn = None if args.turn_goals is None else turn_range(args.turn_goals)
            res = evaluate_chain(load_policy(args.evaluate), args.episodes, args.chain, lo, hi, seed=seed, turn=turn,
                                 switching=args.switching, planned=args.planned_goals)
            print(json.dumps(res))
            return 0
        if args.evaluate:
            if args.turn_goals is not None:
                raise SpecrefineError("--turn-goals with --evaluate needs --chain K (a turn needs a goal before it)")
            lo, hi = args.goal_range or (None, None)
            if args.plot:
                output_file(args.plot, "--plot")  # before any episode: no link, device or missing folder
            res = evaluate_reach(load_policy(args.evaluate), args.episodes, lo, hi, seed=seed)
            print(json.dumps(summary(res)))
            if args.plot:
                with writing_into(args.plot, "--plot") as path:
                    save_figure(plot_success_by_distance(res), path, dpi=90)
            return 0
        if not args.out:
            raise SpecrefineError("--out DIR is required for training")
        overrides = {f.name: getattr(args, f.name) for f in fields(Config)
                     if f.name != "agent" and getattr(args, f.name) is not None}
        cfg = make_config(args.agent, **overrides)
        path = Trainer(cfg, args.out, args.resume, progress=not args.no_progress).train()
        print(f"policy written to {path}")
        return 0
    except SpecrefineError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
