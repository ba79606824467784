"""The batched rollout loop behind every evaluation: what :class:`~specrefine.evaluation.evaluator.Evaluator` has
placed in a BatchedSim (start states, and per episode and leg a goal point, goal and avoid region), run to the end.

Each episode pursues its current leg's goal point; on entering the leg's goal region it switches to the next leg
(a point may lie in several consecutive goals: it advances through all of them at once) with a fresh ``horizon``
of control steps. It fails on touching the leg's avoid set (``avoid.below(xy, clearance)``), flipping, or running
out of the leg's horizon. A finished episode is frozen (zero action, no more checks, its trajectory padded with
its last point). When at most half of the rows still run, the running ones are moved (full physics states,
bit-exact) into a smaller BatchedSim (a power of two, at least ``min_batch``), so finished rollouts stop costing
physics. With a switching rule that holds (``Controls.hold``: :mod:`specrefine.sim.switching`'s ``slow-turn``), an
episode at the start of a leg aims at its own position while the rule holds it, then at the leg's goal point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.errors import PolicyError
from ..core.results import AVOID, FLIPPED, SUCCESS, TIMEOUT, UNFINISHED


@dataclass(frozen=True)
class Plan:
    """What runs: ``first[j]:first[j+1]`` are task j's episodes (rows ``0..N-1`` of the sim); ``goal_points[k, e]``
    is episode e's point on leg k; ``goal_id`` / ``avoid_id`` index ``goals`` / ``avoids`` (compiled regions) by
    (task, leg); ``n_legs[j]`` is task j's number of legs."""

    first: np.ndarray
    n_legs: np.ndarray
    goal_points: np.ndarray
    goal_id: np.ndarray
    avoid_id: np.ndarray
    goals: list
    avoids: list

    @property
    def episodes(self) -> int:
        return int(self.first[-1])

    @property
    def task_of(self) -> np.ndarray:
        return np.repeat(np.arange(len(self.n_legs)), np.diff(self.first))


@dataclass(frozen=True)
class Controls:
    """How it runs: ``act(obs)`` the policy, ``frame`` its observation frame, ``sim_of(size)`` the BatchedSim of
    that many rows (for compaction), ``horizon`` control steps per leg, ``clearance`` the avoid test's distance,
    ``hold`` the switching rule's hold at a leg's start (:func:`specrefine.sim.switching.switching_rule`; None:
    ``at-region``), ``lookahead`` whether the policy also observes the next leg's goal point (the last leg's own on
    the last leg; a held row's next goal is its leg's point)."""

    act: object
    frame: str
    sim_of: object
    horizon: int
    clearance: float
    min_batch: int
    hold: object = None
    lookahead: bool = False


class RolloutLoop:
    """One run of a :class:`Plan` from the states in ``sim``: :meth:`run`, then :meth:`outputs` per task."""

    def __init__(self, plan: Plan, sim, controls: Controls):
        self.plan, self.sim, self.c = plan, sim, controls
        N = plan.episodes
        self.task_of = plan.task_of
        self.L_of = plan.n_legs[self.task_of]
        self.L = int(plan.n_legs.max())  # legs of the longest task
        self.T = self.L * controls.horizon + 1
        self.traj = np.empty((N, self.T, 2), dtype=np.float32)
        self.leg = np.zeros(N, dtype=np.int64)
        self.t_leg = np.zeros(N, dtype=np.int64)
        self.active = np.ones(N, dtype=bool)
        self.lengths = np.full(N, self.T, dtype=np.int64)
        self.outcome = np.full(N, UNFINISHED, dtype=np.int8)
        self.holding = np.full(N, controls.hold is not None)  # braking at the start of its leg (slow-turn)
        self.end_states = np.zeros((N, sim.state_dim))
        self.end_xy = np.zeros((N, 2))
        self.episode = np.concatenate([np.arange(N), np.full(sim.n - N, -1)])  # episode of each sim row (-1: padding)
        self.row = np.arange(N)  # sim row of each episode (-1: not in the sim any more)
        self.xy, self.flipped = sim.xy[:N], sim.flipped[:N]  # BatchedSim hands out copies
        self.traj[:, 0] = self.xy
        self.steps = np.zeros(len(plan.n_legs), dtype=np.int64)  # rows held by each task's episodes, per step
        self.padding_steps = 0

    def run(self) -> RolloutLoop:
        import torch

        self._check(0)
        with torch.inference_mode():
            for t in range(1, self.T):
                running = int(self.active.sum())
                if not running:
                    break
                self._compact(running)
                self._step()
                self.traj[:, t] = self.xy
                self.t_leg[self.active] += 1
                self._check(t)
                self._time_out(t)
        return self

    def outputs(self) -> list[dict]:
        """Per task: legs_done, trajectories (cut to the longest episode), lengths, outcome, end states, steps."""
        first, steps = self.plan.first, self.steps.copy()
        if len(steps) == 1:  # a task alone carries the padding rows it was rounded up to
            steps[0] += self.padding_steps
        return [self._task_output(slice(first[j], first[j + 1]), int(steps[j])) for j in range(len(steps))]

    @property
    def sim_steps(self) -> int:
        """Rows stepped, padding included (what the physics cost)."""
        return int(self.steps.sum()) + self.padding_steps

    def _classify(self, sel, ids, regions, test):
        """test(region, points) for the episodes ``sel``, grouped by the region each one is in."""
        out = np.zeros(len(sel), dtype=bool)
        for i in np.unique(ids):
            m = ids == i
            out[m] = test(regions[i], self.xy[sel[m]])
        return out

    def _check(self, t: int) -> None:
        """Classify the running episodes at time t (after the step that led there)."""
        p, r = self.plan, self.c.clearance
        idx = np.flatnonzero(self.active)
        for _ in range(self.L + 1):  # a point may lie in several consecutive goals: advance through all of them
            if not len(idx):
                break
            task, k = self.task_of[idx], self.leg[idx]
            bad = self._classify(idx, p.avoid_id[task, k], p.avoids, lambda a, q: a.below(q, r)) | self.flipped[idx]
            reached = ~bad & self._classify(idx, p.goal_id[task, k], p.goals, lambda g, q: g.contains(q))
            if bad.any():
                b = idx[bad]
                self.outcome[b] = np.where(self.flipped[b], FLIPPED, AVOID)
                self._finish(b, t)
            g = idx[reached]
            self.leg[g] += 1
            self.t_leg[g] = 0
            self.holding[g] = self.c.hold is not None
            done = g[self.leg[g] == self.L_of[g]]
            if len(done):
                self.outcome[done] = SUCCESS
                self._finish(done, t)
                self.end_states[done] = self.sim.get_state()[self.row[done]]
                self.end_xy[done] = self.xy[done]
            idx = g[self.leg[g] < self.L_of[g]]

    def _finish(self, episodes, t: int) -> None:
        self.active[episodes] = False
        self.lengths[episodes] = t + 1

    def _time_out(self, t: int) -> None:
        late = self.active & (self.t_leg >= self.c.horizon)
        if late.any():
            self.outcome[late] = TIMEOUT
            self._finish(late, t)

    def _compact(self, running: int) -> None:
        """Move the running episodes into a smaller batch once they fill at most half of the sim."""
        size = compacted(self.sim.n, running, self.c.min_batch)
        if size == self.sim.n:
            return
        ids = np.flatnonzero(self.active)
        states = self.sim.get_state()[self.row[ids]]
        states = np.concatenate([states, np.repeat(states[:1], size - len(ids), axis=0)])
        self.sim = self.c.sim_of(size)
        self.sim.reset(states=states)
        self.episode = np.concatenate([ids, np.full(size - len(ids), -1)])
        self.row[:] = -1
        self.row[ids] = np.arange(len(ids))

    def _step(self) -> None:
        sim, episode, p = self.sim, self.episode, self.plan
        live = episode >= 0
        ep = np.where(live, episode, episode[0])
        last = self.L_of[ep] - 1
        goals = p.goal_points[np.minimum(self.leg[ep], last), ep]
        after = p.goal_points[np.minimum(self.leg[ep] + 1, last), ep] if self.c.lookahead else None
        if self.c.hold is not None:
            held = self._hold(goals, ep, live)
            if after is not None:  # braking on its own position, it looks ahead to its leg's point
                after[held] = p.goal_points[np.minimum(self.leg[ep[held]], last[held]), ep[held]]
        obs = sim.observe(goals, self.c.frame, after)
        act = np.asarray(self.c.act(obs), dtype=np.float64)
        if not np.isfinite(act).all():  # MuJoCo would warn per step and write MUJOCO_LOG.TXT into the cwd
            raise PolicyError("the policy acts with NaN or infinite values on these observations: "
                              "retrain it or restore its checkpoint")
        act[~(live & self.active[ep])] = 0.0  # finished rollouts stay still
        sim.step(act)
        self.steps += np.bincount(self.task_of[episode[live]], minlength=len(self.steps))
        self.padding_steps += int((~live).sum())
        self.xy[episode[live]] = sim.xy[live]
        self.flipped[episode[live]] = sim.flipped[live]

    def _hold(self, goals: np.ndarray, ep: np.ndarray, live: np.ndarray) -> np.ndarray:
        """The rows still held at their leg's start (the switching rule) aim at their own position (in ``goals``);
        returns those rows."""
        rows = np.flatnonzero(live & self.holding[ep])
        if not len(rows):
            return rows
        xy, episodes = self.sim.xy[rows], ep[rows]
        still = self.c.hold.holding(self.sim.qvel[rows, :2], goals[rows] - xy, self.t_leg[episodes])
        self.holding[episodes] = still
        goals[rows[still]] = xy[still]
        return rows[still]

    def _task_output(self, rows: slice, steps: int) -> dict:
        lengths = self.lengths[rows]
        n = len(lengths)
        used = int(lengths.max(initial=1))
        pad = np.minimum(np.arange(used)[None, :], lengths[:, None] - 1)
        return {"legs_done": self.leg[rows], "trajectories": self.traj[rows][np.arange(n)[:, None], pad],
                "lengths": lengths, "outcome": self.outcome[rows], "end_states": self.end_states[rows],
                "end_xy": self.end_xy[rows], "steps": steps}


def compacted(rows: int, running: int, min_batch: int) -> int:
    """The rows of the sim that ``running`` episodes continue in from a sim of ``rows``: a power of two (at least
    ``min_batch``) once they fill at most half of it, else the same sim."""
    size = max(min_batch, 1 << (running - 1).bit_length())
    return size if size <= rows // 2 else rows


def rows_stepped(lengths, min_batch: int) -> int:
    """The rows a :class:`RolloutLoop` steps (its ``sim_steps``: padding and finished rows included) for episodes of
    these ``lengths`` run side by side from a sim of ``len(lengths)`` rounded up to ``min_batch``.  A batch's cost
    follows from its episodes' lengths alone, so work read back from a cache is counted as the run that simulated it
    counted it."""
    lengths = np.asarray(lengths, dtype=np.int64)
    running = len(lengths) - np.cumsum(np.bincount(lengths))  # running[t]: episodes still going before step t
    rows, total = -(-len(lengths) // min_batch) * min_batch, 0
    for still in running[1:]:
        if not still:
            break
        rows = compacted(rows, int(still), min_batch)
        total += rows
    return total
