"""Subtask evaluation: estimate, by batched rollouts of the goal policy, how often a subtask succeeds.

``Evaluator.evaluate(start, goal, avoid)`` estimates the probability that the goal-conditioned
policy, started from ``start`` (uniform in a region where the agent fits: ``spawn_radius`` from
walls, for the Ant the reach of its legs; or the end states of a preceding edge's successes, each used
as evenly as n allows: :func:`spread_draw`), reaches
``goal`` before entering ``avoid`` and before flipping, within ``horizon`` control steps. Entering
means touching: ``avoid.signed_distance(xy) < clearance`` where ``Evaluator.clearance`` = the
agent's body radius + MuJoCo's contact margin (pass the same ``Evaluator.clearance`` to
:func:`specrefine.evaluation.monitor.satisfies`). The policy's goal point is ``goal_point`` if given, else a
point sampled uniformly from ``goal`` per rollout, at least ``clearance`` from walls where the
region allows (the paper's "representative waypoint randomly sampled from the inclusion set of the
subtask's goal vertex"; ``goal_points="sampled"``), or with ``goal_points="centre"`` the goal region's centre in
every rollout (beyond the paper: the policy's legs between sampled points are longer and more varied than the
legs it then runs; :meth:`Evaluator.aim`).  ``switching`` names when the policy is fed a leg's goal point
(:mod:`specrefine.sim.switching`): ``at-region`` (the paper's: as soon as the leg starts) or ``slow-turn``
(beyond the paper: a leg that starts with the torso moving fast and away from its goal first brakes).
:class:`EvaluationFacts` says the rule in words for the VLM.

All ``n`` rollouts of a call (of every uncached subtask of an ``evaluate_many`` call) run in one
:class:`~specrefine.sim.simulator.BatchedSim` (one per batch size, built lazily and reused); a rollout that
has finished is frozen (zero action, excluded from the checks, its trajectory padded with its last
point) and the loop stops once all have finished. The evaluator places the episodes (start states, goal points);
the loop that runs them is :mod:`specrefine.evaluation.rollouts`.

Reproducible: the seed fixes start states, goal points and (through them) the deterministic policy
and physics, so the same seed gives the same numbers: bit for bit when the same call runs again on
one machine (or is read back from the cache); through another batch shape (``evaluate_many``, the
compaction of finished rollouts), thread count or CPU, the same successes (barring a rollout that
ends within rounding of a boundary), with floats equal to a tolerance. Results are cached in memory
and, with ``cache_dir``, on disk: one compressed ``.npz`` per entry, named by the SHA-256 of the
canonical JSON key (start distribution, goal, avoid, goal point, policy fingerprint, n, horizon,
seed, agent, maze, clearance, switching rule unless ``at-region``, code version), written atomically (a run
interrupted midway keeps every entry it finished); an unreadable or mismatching entry is ignored with a warning and
recomputed.

``run_compositional`` runs a compositional policy (a sequence of legs, the goal switching when a
leg's goal region is reached) end to end, through the same loop.  Result types live in
:mod:`specrefine.core.results`, the monitor in :mod:`specrefine.evaluation.monitor`.
"""

from __future__ import annotations

import hashlib
import json
import logging
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..core.agents import get_agent
from ..core.errors import SpecrefineError
from ..core.mazes import Maze
from ..core.paper import PAPER
from ..core.regions import CompiledRegion, Region
from ..core.results import (
    CompositionalResult,
    EdgeResult,
    StartStates,
    unreached,
    wilson_ci,
)
from ..sim.switching import AT_REGION, switching_rule
from .cache import ResultCache
from .rollouts import Controls, Plan, RolloutLoop, rows_stepped

log = logging.getLogger(__name__)  # one line per record (no echoed source line, as a warning has)

CACHE_VERSION = 2  # 2: start states from a preceding edge drawn by spread_draw (1: with replacement)
#: where a leg's policy aims when its goal vertex has no fixed point: a point drawn in the goal region per rollout
#: (the paper's rule), the goal region's centre, or its clearest point (:func:`clearest_point`; beyond the paper)
GOAL_POINTS = ("sampled", "centre", "clear")
CLEAR_GRID = 40  # grid points per cell side (or region side) ``clearest_point`` searches: 0.1 m for the Ant's cell


def clearest_point(region: Region, obstacles: CompiledRegion, cell_size: float) -> np.ndarray:
    """The point of ``region`` nearest its centre among those as far from ``obstacles`` (walls and hazards) as the
    region allows, up to half a cell: in a corridor one cell wide, the centre moved across to the corridor's middle
    line, and a centre already that clear stays.  Searched on a grid over the region's bounds, of 1/40 cell or 1/40
    of the bounds' shorter side where that is finer (to within one grid step); the centre itself when no grid point
    lies in the region."""
    centre = np.asarray(region.centre(), dtype=float)
    x0, y0, x1, y1 = region.bounds()
    step = min(cell_size, x1 - x0, y1 - y0) / CLEAR_GRID
    xs, ys = np.arange(x0, x1 + step / 2, step), np.arange(y0, y1 + step / 2, step)
    grid = np.vstack([np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2), centre])
    grid = grid[region.contains(grid)]
    if not len(grid):
        return centre
    clearance = obstacles.signed_distance(grid)
    clear = grid[clearance >= min(clearance.max(), cell_size / 2) - step]
    return clear[np.argmin(np.sum((clear - centre) ** 2, axis=1))]


@dataclass(frozen=True)
class EvaluationFacts:
    """What the evaluator does, as a prompt tells it to a VLM: read from the code, never restated by hand.

    The goal point of a subtask whose goal vertex has no fixed point is drawn uniformly inside the
    goal region, at least ``clearance`` from walls where the region allows (``Evaluator.sample_free``);
    success is the agent's centre entering the goal region before touching the avoid set (coming
    within ``clearance`` of it), before flipping and within ``horizon`` control steps.
    """

    agent: str
    clearance: float  # m
    horizon: int  # control steps per subtask
    control_period: float  # s per control step
    rollouts: int  # per subtask evaluation
    goal_points: str = PAPER.goal_points  # GOAL_POINTS

    @property
    def horizon_seconds(self) -> float:
        return self.horizon * self.control_period

    @classmethod
    def default(cls, agent: str, maze: Maze, rollouts: int = PAPER.rollouts) -> EvaluationFacts:
        """The facts of an ``Evaluator(maze, agent, ...)`` with default settings, without building one."""
        from ..sim.simulator import build_model, contact_margin

        spec = get_agent(agent)
        clearance = spec.body_radius + contact_margin(build_model(agent, maze))
        return cls(agent, clearance, spec.default_horizon, spec.timestep * spec.frame_skip, rollouts)


def _region_key(region: Region) -> dict:
    return region.to_dict()


# --- the evaluator --------------------------------------------------------------------------------
class Evaluator:
    """N batched rollouts of a goal policy per subtask, with counters and a cache.

    maze: the maze at the agent's scale (``maze.for_agent(agent)``); regions passed to the methods are
    in its metres.  policy: a :class:`~specrefine.sim.policy.GoalPolicy` or any callable obs -> actions in
    [-1, 1] (an object with ``.act(obs)`` is called that way; a ``fingerprint`` attribute identifies
    it in cache keys; without one, results are cached in memory only).
    """

    MIN_BATCH = 8  # running rollouts are compacted into batches of 8, 16, 32, ... (never below 8)
    MEMO_SIZE = 512  # results kept in memory (least recently used dropped; the disk cache keeps everything)

    def __init__(self, maze: Maze, agent: str, policy, n: int = PAPER.rollouts, horizon: int | None = None,
                 seed: int = 0, cache_dir=None, nthread: int | None = None,
                 goal_points: str = PAPER.goal_points, switching: str = AT_REGION):
        from ..sim.simulator import build_model, contact_margin, footprint_radius

        spec = get_agent(agent)
        if goal_points not in GOAL_POINTS:
            raise SpecrefineError(f"goal points {goal_points!r}: expected one of {', '.join(GOAL_POINTS)}")
        self.goal_points = goal_points
        self.hold = switching_rule(switching)  # checks the name
        self.switching = switching
        if abs(maze.cell_size - spec.cell_size) > 1e-9:
            raise SpecrefineError(f"maze {maze.name!r} has cell size {maze.cell_size:g} m but the {agent} uses "
                                  f"{spec.cell_size:g} m: pass maze.for_agent({agent!r})")
        self.maze, self.agent, self.policy = maze, agent, policy
        self.n, self.seed, self.nthread = int(n), seed, nthread
        self.horizon = int(horizon) if horizon is not None else spec.default_horizon
        self.agent_radius = float(spec.body_radius)  # the agent entry's (and BatchedSim's) body radius
        self._model = model = build_model(agent, maze)  # shared by the sims of every batch size
        #: contacts become active at this gap (MuJoCo geom margins), so touching a wall = closer than this
        self.contact_margin = contact_margin(model)
        #: the avoid test: a rollout enters O(e) when O(e).signed_distance(xy) < clearance
        self.clearance = self.agent_radius + self.contact_margin
        #: fresh starts (default pose) keep this far from walls: the body radius, or the legs' reach if larger
        self.spawn_radius = max(self.clearance, footprint_radius(model) + self.contact_margin)
        self.cache = ResultCache(cache_dir, self.MEMO_SIZE)
        self.evaluations = 0  # subtask evaluations actually simulated
        self.sim_steps = 0  # environment steps simulated (evaluate + run_compositional)
        self.simulating: str | None = None  # what the simulator runs right now, for a live display (runs.progress)
        self.run_steps = 0  # the same, as a run in one go would have simulated them (cache_dir's earlier work too)
        self._act = policy.act if hasattr(policy, "act") else policy
        self.observation_frame = getattr(policy, "observation_frame", "world")
        self.lookahead = bool(getattr(policy, "lookahead", False))  # it observes the next leg's goal point too
        self._sims: dict[int, object] = {}
        self._compiled: dict[Region, CompiledRegion] = {}
        self._walls = self.compiled(maze.obstacles)  # starts and goal points keep clear of walls and hazards
        self._clearest: dict[Region, np.ndarray] = {}  # goal_points="clear": each region's point, found once
        grid = "\n".join(maze.grid) + f"|{maze.cell_size!r}"
        self._maze_digest = hashlib.sha256(grid.encode()).hexdigest()[:16]

    # --- plumbing ------------------------------------------------------------------------------
    @property
    def cache_dir(self) -> Path | None:
        return self.cache.folder

    @property
    def cache_hits(self) -> int:
        return self.cache.hits

    @property
    def disk_hits(self) -> int:
        """Reads of cache_dir: results an earlier (interrupted) run wrote, and any result read again once the memory
        cache is full (so not a count of evaluations: :attr:`run_evaluations` is)."""
        return self.cache.disk_hits

    @property
    def run_evaluations(self) -> int:
        """Subtask evaluations as a run in one go would have made them: those simulated here and those an earlier run
        of cache_dir simulated, each once (as ``run_steps`` counts their steps)."""
        return self.evaluations + self.cache.read_back

    @property
    def cached_steps(self) -> int:
        """Environment steps of the evaluations read from cache_dir that this process never simulated (an earlier run
        of the same folder did), each counted once and as the batch that simulated it stepped it: sim_steps +
        cached_steps (``run_steps``) is the same for a run done in one go, one resumed after a kill and a rerun."""
        return self.run_steps - self.sim_steps

    @property
    def control_period(self) -> float:
        """Seconds per control step."""
        spec = get_agent(self.agent)
        return spec.timestep * spec.frame_skip

    def facts(self) -> EvaluationFacts:
        """What this evaluator does, in the terms a prompt states it (see :class:`EvaluationFacts`)."""
        return EvaluationFacts(self.agent, self.clearance, self.horizon, self.control_period, self.n,
                               self.goal_points)

    @property
    def body_radius(self) -> float:
        """Former name of :attr:`clearance` (torso + contact margin), kept for older notebooks."""
        return self.clearance

    def sim(self, batch: int | None = None):
        """The BatchedSim of ``batch`` rows (default: ``n``; built on first use, then reused)."""
        from ..sim.simulator import BatchedSim

        batch = int(batch or self.n)
        if batch not in self._sims:
            self._sims[batch] = BatchedSim(self.agent, self.maze, batch, nthread=self.nthread, model=self._model)
        return self._sims[batch]

    @property
    def built_sims(self) -> tuple:
        """The BatchedSims built so far (one per batch size the evaluations have used)."""
        return tuple(self._sims.values())

    def compiled(self, region: Region) -> CompiledRegion:
        c = self._compiled.get(region)
        if c is None:
            if len(self._compiled) > 256:
                self._compiled.clear()
            c = self._compiled[region] = CompiledRegion(region)
        return c

    @property
    def policy_fingerprint(self) -> str | None:
        fp = getattr(self.policy, "fingerprint", None)
        return str(fp) if fp is not None else None

    def aim(self, goal: Region, point=None):
        """The fixed point a leg to ``goal`` aims at: ``point`` if given, else the goal's centre when
        ``goal_points`` is "centre", its clearest point when "clear" (:func:`clearest_point`); None: a point is drawn
        per rollout (``sample_free``)."""
        if point is not None or self.goal_points == "sampled":
            return point
        if self.goal_points == "centre":
            return np.asarray(goal.centre(), dtype=float)
        return self.clearest(goal)

    def clearest(self, region: Region) -> np.ndarray:
        """``region``'s point nearest its centre among those as clear of walls and hazards as it allows, up to half a
        cell (:func:`clearest_point`; found once per region)."""
        if region not in self._clearest:
            self._clearest[region] = clearest_point(region, self._walls, self.maze.cell_size)
        return self._clearest[region]

    def sample_free(self, region: Region, k: int, rng: np.random.Generator, clearance: float | None = None
                    ) -> np.ndarray:
        """``k`` points uniform in ``region`` at least ``clearance`` (default: ``self.clearance``) from walls.

        Falls back to plain uniform samples if the region has (almost) no such points.
        """
        clearance = self.clearance if clearance is None else clearance
        chunks, got = [], 0
        for _ in range(64):
            pts = region.sample(max(2 * (k - got), 16), rng)
            ok = pts[~self._walls.below(pts, clearance)]
            chunks.append(ok[: k - got])
            got += len(chunks[-1])
            if got >= k:
                return np.concatenate(chunks)
        log.warning("region %s has almost no room for the agent's body; sampling it plainly", region.to_dict())
        return np.concatenate(chunks + [region.sample(k - got, rng)])

    def spawn_points(self, region: Region, k: int, rng: np.random.Generator) -> np.ndarray:
        """Fresh start positions in ``region``: clear of walls by ``spawn_radius`` where the region allows it."""
        if self.spawn_radius > self.clearance and not self._has_room(region, self.spawn_radius, rng):
            return self.sample_free(region, k, rng)  # a tight start region: the body still fits, the legs may not
        return self.sample_free(region, k, rng, self.spawn_radius)

    def _has_room(self, region: Region, clearance: float, rng: np.random.Generator) -> bool:
        probe = region.sample(256, np.random.default_rng(rng.integers(2**32)))
        return bool((~self._walls.below(probe, clearance)).mean() > 0.01)

    def _key(self, kind: str, start, legs, n: int, seed, fp: str | None) -> tuple[str, str]:
        if isinstance(start, StartStates):
            start_key = {"states": start.digest(), "m": len(start)}
        else:
            start_key = _region_key(start)
        fp = fp or f"id:{id(self.policy)}"
        legs_key = [[_region_key(g), _region_key(a), None if p is None else [float(v) for v in np.ravel(p)]]
                    for g, a, p in legs]
        body = {"v": CACHE_VERSION, "kind": kind, "agent": self.agent, "maze": self._maze_digest,
                "start": start_key, "legs": legs_key, "policy": fp, "n": int(n), "horizon": self.horizon,
                "seed": seed if isinstance(seed, int) else repr(seed), "r": self.clearance,
                "spawn": self.spawn_radius}
        if self.switching != AT_REGION:  # at-region keeps the keys it always had: its caches stay valid
            body["switching"] = self.switching
        text = json.dumps(body, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:40], text

    # --- public API ----------------------------------------------------------------------------
    MAX_EPISODES = 2048  # evaluate_many simulates at most this many episodes side by side

    def evaluate(self, start: Region | StartStates, goal: Region, avoid: Region, goal_point=None, seed=None,
                 n: int | None = None) -> EdgeResult:
        """Success probability of the subtask start -> goal avoiding ``avoid`` (see the module docstring)."""
        return self.evaluate_many([(start, goal, avoid, goal_point)], seed=seed, n=n)[0]

    def fresh_copy(self, cache_dir=None) -> Evaluator:
        """The same evaluator (maze, agent, policy, n, horizon, seed) with zero counters and its own cache."""
        return Evaluator(self.maze, self.agent, self.policy, n=self.n, horizon=self.horizon, seed=self.seed,
                         cache_dir=cache_dir, nthread=self.nthread, goal_points=self.goal_points,
                         switching=self.switching)

    def evaluate_many(self, subtasks, seed=None, n: int | None = None) -> list[EdgeResult]:
        """``evaluate`` for each ``(start, goal, avoid, goal_point)``; the uncached ones are simulated together.

        The same successes as one ``evaluate`` call each (every subtask is seeded on its own), in far
        fewer, larger simulator steps; trajectories agree to float tolerance (the policy sees another
        batch shape).
        """
        n = int(n or self.n)
        seed = self.seed if seed is None else seed
        fp = self.policy_fingerprint  # hashed once per call (it hashes the weights); None: no disk cache
        results: list[EdgeResult | None] = [None] * len(subtasks)
        todo: dict[str, tuple] = {}  # key -> (text, task, positions)
        one_go: dict[str, int] = {}  # key -> position: what a run in one go simulates here, in its order
        for i, (start, goal, avoid, goal_point) in enumerate(subtasks):
            legs = [(goal, avoid, self.aim(goal, goal_point))]  # a centre is keyed as the fixed point it is
            key, text = self._key("edge", start, legs, n, seed, fp)
            if key in todo:  # asked twice in one batch: simulated once, the second is a cache hit
                todo[key][2].append(i)
            elif (hit := self.cache.lookup(key, text, disk=fp is not None)) is not None:
                results[i] = hit
                if self.cache.first_read(key):
                    one_go[key] = i
            elif isinstance(start, StartStates) and len(start) == 0:
                # nothing reached the start: p = 0, nothing run
                results[i] = unreached(start.states.shape[1] if start.states.ndim == 2 else 0)
            else:
                todo[key] = (text, (start, legs, n, seed), [i])
                one_go[key] = i
        batch = max(1, self.MAX_EPISODES // n)
        pending = list(todo.items())
        for lo in range(0, len(pending), batch):
            chunk = pending[lo:lo + batch]
            for (key, (text, _, positions)), out in zip(chunk, self._rollout_many([t for _, (_, t, _) in chunk])):
                res = _edge_result(out, n)
                self.evaluations += 1
                self.cache.add(key, text, res, disk=fp is not None)
                results[positions[0]] = res
                for i in positions[1:]:
                    self.cache.hits += 1
                    results[i] = replace(res, cached=True)
        firsts = list(one_go.values())
        for lo in range(0, len(firsts), batch):
            self.run_steps += rows_stepped(np.concatenate([results[i].lengths for i in firsts[lo:lo + batch]]),
                                           self.MIN_BATCH)
        return results

    def evaluate_edge(self, graph, u: str, v: str, start: Region | StartStates | None = None, seed=None,
                      n: int | None = None) -> EdgeResult:
        """``evaluate`` on the graph edge u -> v (start defaults to I(u); goal point = v's point, if any)."""
        return self.evaluate(graph.region(u) if start is None else start, graph.region(v), graph.avoid(u, v),
                             goal_point=graph.goal_point(v), seed=seed, n=n)

    def run_compositional(self, start: Region | StartStates, legs, n: int | None = None, seed=None
                          ) -> CompositionalResult:
        """Run the compositional policy: legs ``[(goal, avoid, goal_point | None), ...]`` end to end.

        Each episode starts in ``start`` and pursues leg 0's goal point; on reaching a leg's goal region it
        switches to the next leg (fresh ``horizon`` steps per leg; its goal point fed as ``switching`` says).  It
        fails on entering the current leg's avoid set, flipping, or running out of a leg's horizon.
        """
        n = int(n or self.n)
        seed = self.seed if seed is None else seed
        legs = [(leg[0], leg[1], self.aim(leg[0], leg[2] if len(leg) == 3 else None)) for leg in legs]
        if not legs:
            raise SpecrefineError("run_compositional needs at least one leg")
        out = self._rollout(start, legs, n, seed)
        self.run_steps += rows_stepped(out["lengths"], self.MIN_BATCH)
        success = out["legs_done"] == len(legs)
        k = int(success.sum())
        return CompositionalResult(p=k / n, ci=wilson_ci(k, n), n=n, successes=k, success=success,
                                   legs_done=out["legs_done"], trajectories=out["trajectories"], lengths=out["lengths"],
                                   steps=out["steps"], outcome=out["outcome"], n_legs=len(legs))

    run_path = run_compositional  # the former name (notebooks written against it)

    def run_graph_path(self, graph, path: list[str], n: int | None = None, seed=None) -> CompositionalResult:
        """``run_compositional`` along a vertex path of a task graph, from I(path[0])."""
        return self.run_compositional(graph.region(path[0]), path_legs(graph, path), n=n, seed=seed)

    # --- placing and running rollouts ------------------------------------------------------------
    def _rollout(self, start, legs, n: int, seed) -> dict:
        return self._rollout_many([(start, legs, n, seed)])[0]

    def _rollout_many(self, tasks: list[tuple]) -> list[dict]:
        """Run several ``(start, legs, n, seed)`` tasks side by side in one batch; one result dict per task."""
        # small-batch inference is fastest on one torch thread; more threads only contend with MuJoCo's
        episodes = sum(n for _, _, n, _ in tasks)
        self.simulating = f"simulating {episodes} episodes" + (f" of {len(tasks)} subtasks" if len(tasks) > 1 else "")
        try:
            with _torch_threads(1):
                return self._rollout_batches(tasks)
        finally:
            self.simulating = None

    def _start_rows(self, sim, rows: np.ndarray, start, n: int, rng: np.random.Generator) -> None:
        if isinstance(start, StartStates):
            if len(start) == 0:
                raise SpecrefineError("empty start distribution (no successful rollouts to start from)")
            sim.reset(states=start.states[spread_draw(len(start), n, rng)], idx=rows)
        else:
            sim.reset(xy=self.spawn_points(start, n, rng), rng=rng, idx=rows)

    def _rollout_batches(self, tasks: list[tuple]) -> list[dict]:
        """Place every task's n episodes (start states, goal points; each task seeded on its own, so they do not
        depend on its neighbours) in rows of one BatchedSim and run them (:class:`~.rollouts.RolloutLoop`)."""
        counts = np.array([n for _, _, n, _ in tasks])
        first = np.concatenate([[0], np.cumsum(counts)])
        N, n_legs = int(first[-1]), np.array([len(legs) for _, legs, _, _ in tasks])
        L = int(n_legs.max())
        sim = self.sim(-(-N // self.MIN_BATCH) * self.MIN_BATCH)
        goal_pts = np.zeros((L, N, 2))
        goal_id = np.zeros((len(tasks), L), dtype=np.int64)  # (task, leg) -> index into goals
        avoid_id = np.zeros_like(goal_id)
        goals, avoids = [], []
        for j, (start, legs, n, seed) in enumerate(tasks):
            rng = np.random.default_rng(seed)
            rows = np.arange(first[j], first[j + 1])
            self._start_rows(sim, rows, start, n, rng)
            for k, (goal, avoid, point) in enumerate(legs):
                goal_pts[k, rows] = np.broadcast_to(np.asarray(point, dtype=float).reshape(2), (n, 2)) \
                    if point is not None else self.sample_free(goal, n, rng)
                goal_id[j, k] = _index_of(goals, self.compiled(goal))
                avoid_id[j, k] = _index_of(avoids, self.compiled(avoid))
        if sim.n > N:  # padding rows: copies of row 0, never checked
            sim.reset(states=np.repeat(sim.get_state()[:1], sim.n - N, axis=0), idx=np.arange(N, sim.n))
        plan = Plan(first, n_legs, goal_pts, goal_id, avoid_id, goals, avoids)
        controls = Controls(self._act, self.observation_frame, self.sim, self.horizon, self.clearance, self.MIN_BATCH,
                            self.hold, self.lookahead)
        loop = RolloutLoop(plan, sim, controls).run()
        self.sim_steps += loop.sim_steps
        return loop.outputs()


def spread_draw(m: int, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` indices into ``m`` start states, each used n // m or n // m + 1 times (which get the extra use drawn
    at random), in random order.

    Why not ``n`` draws with replacement: policy and physics are deterministic, so two rollouts from the same
    state are one rollout, and a leg whose goal point is fixed (``goal_points="centre"``) never tells them apart.
    Drawn with replacement leg after leg, the n rollouts of a chain descend from fewer and fewer first states (a
    particle filter without noise: about 2n / k of them after k legs), and a chained estimate of a long path
    judges its later legs on a handful of distinct rollouts: on the Ant's 51-leg U-chain 5 path every leg showed
    128 of 128 while 200 end-to-end episodes lost 23 % (docs/corrector.md, "Chained estimates"). Spread, the n
    rollouts stay as many distinct ones as the previous leg's successes, as in n end-to-end episodes."""
    idx = np.concatenate([np.tile(np.arange(m), n // m), rng.choice(m, n % m, replace=False)])
    return rng.permutation(idx)


def _edge_result(out: dict, n: int) -> EdgeResult:
    success = out["legs_done"] == 1
    k = int(success.sum())
    return EdgeResult(p=k / n, ci=wilson_ci(k, n), n=n, successes=k, success=success,
                      trajectories=out["trajectories"], lengths=out["lengths"],
                      end_states=StartStates(out["end_states"][success], out["end_xy"][success]),
                      steps=out["steps"], outcome=out["outcome"])


def _index_of(items: list, item) -> int:
    """Position of ``item`` (by identity) in ``items``, appending it if new."""
    for i, x in enumerate(items):
        if x is item:
            return i
    items.append(item)
    return len(items) - 1


def path_legs(graph, path: list[str]) -> list[tuple[Region, Region, np.ndarray | None]]:
    """Legs ``(I(v), O(u, v), point(v))`` for consecutive vertices of a path in a task graph."""
    return [(graph.region(v), graph.avoid(u, v), graph.goal_point(v)) for u, v in zip(path, path[1:], strict=False)]


@contextmanager
def _torch_threads(k: int):
    import torch

    before = torch.get_num_threads()
    torch.set_num_threads(k)
    try:
        yield
    finally:
        torch.set_num_threads(before)


