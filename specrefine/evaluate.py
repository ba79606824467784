"""Subtask evaluation: batched rollouts of the goal policy on a reach-avoid edge, and the monitor.

``Evaluator.evaluate(start, goal, avoid)`` estimates the probability that the goal-conditioned
policy, started from ``start`` (uniform in a region where the agent fits: ``spawn_radius`` from
walls, for the Ant the reach of its legs; or resampled end states of a preceding edge), reaches
``goal`` before entering ``avoid`` and before flipping, within ``horizon`` control steps. Entering
means touching: ``avoid.signed_distance(xy) < body_radius`` where ``Evaluator.body_radius`` = the
simulator's body radius + MuJoCo's contact margin (pass the same ``Evaluator.body_radius`` to
``satisfies``). The policy's goal point is ``goal_point`` if given, else a point sampled uniformly
from ``goal`` per rollout (the paper's "representative waypoint randomly sampled from the inclusion
set of the subtask's goal vertex").

All ``n`` rollouts of a call (of every uncached subtask of an ``evaluate_many`` call) run in one
:class:`~specrefine.sim.BatchedSim` (one per batch size, built lazily and reused); a rollout that
has finished is frozen (zero action, excluded from the checks, its trajectory padded with its last
point) and the loop stops once all have finished.

Reproducible: the seed fixes start states, goal points and (through them) the deterministic policy
and physics, so the same seed gives the same numbers: bit for bit when the same call runs again on
one machine (or is read back from the cache); through another batch shape (``evaluate_many``, the
compaction of finished rollouts), thread count or CPU, the same successes (barring a rollout that
ends within rounding of a boundary), with floats equal to a tolerance. Results are cached in memory
and, with ``cache_dir``, on disk: one compressed ``.npz`` per entry, named by the SHA-256 of the
canonical JSON key (start distribution, goal, avoid, goal point, policy fingerprint, n, horizon,
seed, agent, maze, body radius, code version), written atomically (a run interrupted midway keeps
every entry it finished); an unreadable or mismatching entry is ignored with a warning and
recomputed.

``run_path`` runs a compositional policy (a sequence of legs, the goal switching when a leg's goal
region is reached) end to end; ``satisfies`` is a monitor that checks trajectories against a task
graph's specification (used to measure success on the ORIGINAL task).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import warnings
from collections import OrderedDict
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .errors import SpecrefineError
from .mazes import CELL_SIZE, Maze
from .regions import Box, Disc, Region

CACHE_VERSION = 1
_TINY = float(np.nextafter(0.0, 1.0))  # sd <= 0  <=>  sd < _TINY
SUCCESS, AVOID, FLIPPED, TIMEOUT, UNFINISHED = 0, 1, 2, 3, 4
OUTCOMES = ("success", "avoid", "flipped", "timeout", "unfinished")


# --- results ---------------------------------------------------------------------------------------
@dataclass
class StartStates:
    """A start distribution given by full physics states (resampled with replacement)."""

    states: np.ndarray  # (m, state_dim)
    xy: np.ndarray  # (m, 2)

    def __len__(self) -> int:
        return len(self.states)

    def digest(self) -> str:
        h = hashlib.sha256(np.ascontiguousarray(self.states, dtype=np.float64).tobytes())
        h.update(str(self.states.shape).encode())
        return h.hexdigest()[:32]


@dataclass
class EdgeResult:
    p: float
    ci: tuple[float, float]
    n: int
    successes: int
    success: np.ndarray  # (n,) bool
    trajectories: np.ndarray  # (n, T, 2) float32; row i is valid up to lengths[i], then padded with its last point
    lengths: np.ndarray  # (n,) int: number of valid points (1 + control steps taken)
    end_states: StartStates | None  # states of the successful rollouts at the moment they reached the goal
    steps: int  # environment steps simulated (the batch is stepped together: n x loop iterations)
    cached: bool = False
    outcome: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int8))  # per rollout, see OUTCOMES

    @property
    def weight(self) -> float:
        """-log p (inf for p = 0)."""
        return -math.log(self.p) if self.p > 0 else math.inf

    def counts(self) -> dict[str, int]:
        return {name: int(np.sum(self.outcome == i)) for i, name in enumerate(OUTCOMES) if np.any(self.outcome == i)}


@dataclass
class PathResult:
    p: float
    ci: tuple[float, float]
    n: int
    successes: int
    success: np.ndarray  # (n,) bool: every leg completed
    legs_done: np.ndarray  # (n,) int: legs completed by each episode
    trajectories: np.ndarray  # (n, T, 2) float32, padded like EdgeResult's
    lengths: np.ndarray  # (n,)
    steps: int
    outcome: np.ndarray  # (n,) int8, see OUTCOMES

    n_legs: int = 1

    def counts(self) -> dict[str, int]:
        return {name: int(np.sum(self.outcome == i)) for i, name in enumerate(OUTCOMES) if np.any(self.outcome == i)}

    @property
    def leg_success(self) -> list[float | None]:
        """Empirical success probability of each leg among the episodes that started it (None: none did)."""
        out = []
        for k in range(self.n_legs):
            started = self.legs_done >= k
            out.append(float(np.mean(self.legs_done[started] > k)) if started.any() else None)
        return out


def wilson_ci(successes, n, z: float = 1.96) -> tuple[float, float]:
    """Wilson score interval for a binomial proportion (95 % by default); (0, 1) when n = 0."""
    n = int(n)
    if n <= 0:
        return (0.0, 1.0)
    p = successes / n
    z2 = z * z
    denom = 1 + z2 / n
    centre = (p + z2 / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / denom
    return (max(0.0, centre - half), min(1.0, centre + half))


# --- fast region checks ------------------------------------------------------------------------------
class CompiledRegion:
    """A region's boxes and discs as arrays: signed distances of many points in a few numpy calls.

    ``signed_distance`` gives the same numbers as ``Region.signed_distance`` (the same formula,
    vectorised over parts).  ``below(pts, thr)`` answers ``signed_distance < thr`` exactly but only
    looks at the few boxes near each point (a bucket grid built once per threshold), which keeps the
    wall check of a big maze (hundreds of boxes) cheap in the rollout loop.
    """

    BUCKET_MIN_PARTS = 12  # fewer boxes than this: just compute against all of them

    def __init__(self, region: Region):
        self.region = region
        parts = region.parts()
        boxes = [p for p in parts if isinstance(p, Box)]
        discs = [p for p in parts if isinstance(p, Disc)]
        self.other = [p for p in parts if not isinstance(p, (Box, Disc))]
        self.bc = np.array([[(b.xmin + b.xmax) / 2, (b.ymin + b.ymax) / 2] for b in boxes]).reshape(-1, 2)
        self.bh = np.array([[(b.xmax - b.xmin) / 2, (b.ymax - b.ymin) / 2] for b in boxes]).reshape(-1, 2)
        self.dc = np.array([[d.cx, d.cy] for d in discs]).reshape(-1, 2)
        self.dr = np.array([d.r for d in discs])
        self._grids: dict[float, tuple] = {}

    @staticmethod
    def _box_sd(pts, c, h):
        d = np.abs(pts[:, None, :] - c) - h  # (n, m, 2)
        dx, dy = d[..., 0], d[..., 1]
        return (np.hypot(np.maximum(dx, 0.0), np.maximum(dy, 0.0)) + np.minimum(np.maximum(dx, dy), 0.0)).min(axis=1)

    def _rest_sd(self, pts, out):
        if len(self.dc):
            dd = np.hypot(pts[:, None, 0] - self.dc[None, :, 0], pts[:, None, 1] - self.dc[None, :, 1]) - self.dr
            out = np.minimum(out, dd.min(axis=1))
        for p in self.other:
            out = np.minimum(out, p.signed_distance(pts))
        return out

    def signed_distance(self, pts: np.ndarray) -> np.ndarray:
        pts = np.asarray(pts, dtype=float).reshape(-1, 2)
        out = self._box_sd(pts, self.bc[None], self.bh[None]) if len(self.bc) else np.full(len(pts), np.inf)
        return self._rest_sd(pts, out)

    def contains(self, pts: np.ndarray) -> np.ndarray:
        """``signed_distance(pts) <= 0`` (= below the smallest positive float), exactly."""
        if len(self.bc) < self.BUCKET_MIN_PARTS:
            return self.signed_distance(pts) <= 0.0
        return self.below(pts, _TINY)

    def _grid(self, thr: float):
        """Bucket grid: for every bucket the boxes whose bounding box grown by ``thr`` meets it."""
        g = self._grids.get(thr)
        if g is None:
            lo = (self.bc - self.bh).min(axis=0) - thr - 1e-9
            hi = (self.bc + self.bh).max(axis=0) + thr + 1e-9
            size = float(max(np.median(self.bh.min(axis=1)) * 2, thr, (hi - lo).max() / 256, 1e-6))
            shape = np.maximum(np.ceil((hi - lo) / size).astype(int), 1)
            cells = [[] for _ in range(shape[0] * shape[1])]
            i0 = np.clip(np.floor((self.bc - self.bh - thr - 1e-9 - lo) / size).astype(int), 0, shape - 1)
            i1 = np.clip(np.floor((self.bc + self.bh + thr + 1e-9 - lo) / size).astype(int), 0, shape - 1)
            for j in range(len(self.bc)):
                for ix in range(i0[j, 0], i1[j, 0] + 1):
                    for iy in range(i0[j, 1], i1[j, 1] + 1):
                        cells[ix * shape[1] + iy].append(j)
            k = max(1, max(len(c) for c in cells))
            table = np.full((len(cells), k), len(self.bc))  # padding -> a dummy box far away
            for i, c in enumerate(cells):
                table[i, : len(c)] = c
            c = np.vstack([self.bc, [[1e18, 1e18]]])
            h = np.vstack([self.bh, [[0.0, 0.0]]])
            g = self._grids[thr] = (lo, size, shape, table, c, h)
        return g

    def below(self, pts: np.ndarray, thr: float) -> np.ndarray:
        """``signed_distance(pts) < thr``, exactly, looking only at nearby boxes."""
        pts = np.asarray(pts, dtype=float).reshape(-1, 2)
        if len(self.bc) < self.BUCKET_MIN_PARTS:
            return self.signed_distance(pts) < thr
        lo, size, shape, table, c, h = self._grid(float(thr))
        ij = np.floor((pts - lo) / size).astype(np.int64)
        inside = np.all((ij >= 0) & (ij < shape), axis=1)
        cand = table[np.where(inside, ij[:, 0] * shape[1] + ij[:, 1], 0)]  # (n, k)
        cand[~inside] = len(self.bc)
        out = self._box_sd(pts, c[cand], h[cand])
        return self._rest_sd(pts, out) < thr


def _region_key(region: Region) -> dict:
    return region.to_dict()


# --- the evaluator --------------------------------------------------------------------------------
class Evaluator:
    """N batched rollouts of a goal policy per subtask, with counters and a cache.

    maze: the maze at the agent's scale (``maze.for_agent(agent)``); regions passed to the methods are
    in its metres.  policy: a :class:`~specrefine.policy.GoalPolicy` or any callable obs -> actions in
    [-1, 1] (an object with ``.act(obs)`` is called that way; a ``fingerprint`` attribute identifies
    it in cache keys; without one, results are cached in memory only).
    """

    MIN_BATCH = 8  # running rollouts are compacted into batches of 8, 16, 32, ... (never below 8)
    MEMO_SIZE = 512  # results kept in memory (least recently used dropped; the disk cache keeps everything)

    def __init__(self, maze: Maze, agent: str, policy, n: int = 32, horizon: int | None = None, seed: int = 0,
                 cache_dir=None, nthread: int | None = None):
        import mujoco

        from .sim import agent_spec, build_model, footprint_radius

        if agent not in CELL_SIZE:
            raise SpecrefineError(f"unknown agent {agent!r}; expected one of {', '.join(CELL_SIZE)}")
        if abs(maze.cell_size - CELL_SIZE[agent]) > 1e-9:
            raise SpecrefineError(f"maze {maze.name!r} has cell size {maze.cell_size:g} m but the {agent} uses "
                                  f"{CELL_SIZE[agent]:g} m: pass maze.for_agent({agent!r})")
        spec = agent_spec(agent)
        self.maze, self.agent, self.policy = maze, agent, policy
        self.n, self.seed, self.nthread = int(n), seed, nthread
        self.horizon = int(horizon) if horizon is not None else spec.default_horizon
        self.agent_radius = float(spec.body_radius)  # BatchedSim.body_radius
        model = build_model(agent, maze)
        names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, i) or "" for i in range(model.ngeom)]
        wall_margin = max([model.geom_margin[i] for i, nm in enumerate(names) if nm.startswith("wall_")], default=0.0)
        agent_margin = float(model.geom_margin[model.geom_bodyid > 0].max(initial=0.0))
        #: contacts become active at this gap (MuJoCo geom margins), so touching a wall = closer than this
        self.contact_margin = float(wall_margin + agent_margin)
        #: the avoid test: a rollout enters O(e) when O(e).signed_distance(xy) < body_radius
        self.body_radius = self.agent_radius + self.contact_margin
        self.avoid_radius = self.body_radius  # alias
        #: fresh starts (default pose) keep this far from walls: the body radius, or the legs' reach if larger
        self.spawn_radius = max(self.body_radius, footprint_radius(model) + self.contact_margin)
        self.cache_dir = Path(cache_dir) if cache_dir is not None else None
        self.evaluations = 0  # subtask evaluations actually simulated
        self.sim_steps = 0  # environment steps simulated (evaluate + run_path)
        self.cache_hits = 0
        self.disk_hits = 0  # evaluations found in cache_dir, written by an earlier (interrupted) run
        self._act = policy.act if hasattr(policy, "act") else policy
        self._sims: dict[int, object] = {}
        self._memo: OrderedDict[str, EdgeResult] = OrderedDict()  # LRU, MEMO_SIZE entries
        self._compiled: dict[Region, CompiledRegion] = {}
        self._walls = self.compiled(maze.obstacles)  # starts and goal points keep clear of walls and hazards
        grid = "\n".join(maze.grid) + f"|{maze.cell_size!r}"
        self._maze_digest = hashlib.sha256(grid.encode()).hexdigest()[:16]

    # --- plumbing ------------------------------------------------------------------------------
    def sim(self, n: int | None = None):
        """The BatchedSim of batch ``n`` (built on first use, then reused)."""
        from .sim import BatchedSim

        n = int(n or self.n)
        if n not in self._sims:
            self._sims[n] = BatchedSim(self.agent, self.maze, n, nthread=self.nthread)
        return self._sims[n]

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

    def sample_free(self, region: Region, k: int, rng: np.random.Generator, clearance: float | None = None
                    ) -> np.ndarray:
        """``k`` points uniform in ``region`` at least ``clearance`` (default: the body radius) from walls.

        Falls back to plain uniform samples if the region has (almost) no such points.
        """
        clearance = self.body_radius if clearance is None else clearance
        chunks, got = [], 0
        for _ in range(64):
            pts = region.sample(max(2 * (k - got), 16), rng)
            ok = pts[~self._walls.below(pts, clearance)]
            chunks.append(ok[: k - got])
            got += len(chunks[-1])
            if got >= k:
                return np.concatenate(chunks)
        warnings.warn(f"region {region.to_dict()} has almost no room for the agent's body; sampling it plainly",
                      stacklevel=2)
        return np.concatenate(chunks + [region.sample(k - got, rng)])

    def spawn_points(self, region: Region, k: int, rng: np.random.Generator) -> np.ndarray:
        """Fresh start positions in ``region``: clear of walls by ``spawn_radius`` where the region allows it."""
        if self.spawn_radius > self.body_radius and not self._has_room(region, self.spawn_radius, rng):
            return self.sample_free(region, k, rng)  # a tight start region: the body still fits, the legs may not
        return self.sample_free(region, k, rng, self.spawn_radius)

    def _has_room(self, region: Region, clearance: float, rng: np.random.Generator) -> bool:
        probe = region.sample(256, np.random.default_rng(rng.integers(2**32)))
        return bool((~self._walls.below(probe, clearance)).mean() > 0.01)

    def _key(self, kind: str, start, legs, n: int, seed) -> tuple[str, str]:
        if isinstance(start, StartStates):
            start_key = {"states": start.digest(), "m": len(start)}
        else:
            start_key = _region_key(start)
        fp = self.policy_fingerprint or f"id:{id(self.policy)}"
        legs_key = [[_region_key(g), _region_key(a), None if p is None else [float(v) for v in np.ravel(p)]]
                    for g, a, p in legs]
        body = {"v": CACHE_VERSION, "kind": kind, "agent": self.agent, "maze": self._maze_digest,
                "start": start_key, "legs": legs_key, "policy": fp, "n": int(n), "horizon": self.horizon,
                "seed": seed if isinstance(seed, int) else repr(seed), "r": self.body_radius,
                "spawn": self.spawn_radius}
        text = json.dumps(body, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:40], text

    def _cache_path(self, key: str) -> Path | None:
        if self.cache_dir is None or self.policy_fingerprint is None:
            return None
        return self.cache_dir / key[:2] / f"{key}.npz"

    def _load(self, key: str, text: str) -> EdgeResult | None:
        path = self._cache_path(key)
        if path is None or not path.exists():
            return None
        try:
            with np.load(path, allow_pickle=False) as z:
                if str(z["key"]) != text:
                    raise ValueError("key mismatch")
                success = z["success"].astype(bool)
                n = len(success)
                end = StartStates(z["end_states"].astype(np.float64), z["end_xy"].astype(np.float64))
                res = EdgeResult(p=float(success.mean()) if n else 0.0, ci=wilson_ci(int(success.sum()), n), n=n,
                                 successes=int(success.sum()), success=success, trajectories=z["trajectories"],
                                 lengths=z["lengths"].astype(np.int64), end_states=end, steps=int(z["steps"]),
                                 cached=True, outcome=z["outcome"].astype(np.int8))
                if len(res.lengths) != n or len(res.trajectories) != n or len(end) != res.successes:
                    raise ValueError("inconsistent arrays")
                return res
        except Exception as e:  # corrupt, truncated, foreign: never crash, recompute
            warnings.warn(f"ignoring unreadable cache entry {path}: {type(e).__name__}: {e}", stacklevel=3)
            return None

    def _store(self, key: str, text: str, res: EdgeResult) -> None:
        path = self._cache_path(key)
        if path is None:
            return
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
            with open(tmp, "wb") as f:
                np.savez_compressed(f, key=np.array(text), success=res.success, trajectories=res.trajectories,
                                    lengths=res.lengths, end_states=res.end_states.states, end_xy=res.end_states.xy,
                                    steps=np.array(res.steps), outcome=res.outcome)
            os.replace(tmp, path)
        except OSError as e:
            warnings.warn(f"could not write cache entry {path}: {e}", stacklevel=3)

    # --- public API ----------------------------------------------------------------------------
    MAX_EPISODES = 2048  # evaluate_many simulates at most this many episodes side by side

    def evaluate(self, start: Region | StartStates, goal: Region, avoid: Region, goal_point=None, seed=None,
                 n: int | None = None) -> EdgeResult:
        """Success probability of the subtask start -> goal avoiding ``avoid`` (see the module docstring)."""
        return self.evaluate_many([(start, goal, avoid, goal_point)], seed=seed, n=n)[0]

    def evaluate_many(self, subtasks, seed=None, n: int | None = None) -> list[EdgeResult]:
        """``evaluate`` for each ``(start, goal, avoid, goal_point)``; the uncached ones are simulated together.

        The same successes as one ``evaluate`` call each (every subtask is seeded on its own), in far
        fewer, larger simulator steps; trajectories agree to float tolerance (the policy sees another
        batch shape).
        """
        n = int(n or self.n)
        seed = self.seed if seed is None else seed
        results: list[EdgeResult | None] = [None] * len(subtasks)
        todo: dict[str, tuple] = {}  # key -> (text, task, positions)
        for i, (start, goal, avoid, goal_point) in enumerate(subtasks):
            legs = [(goal, avoid, goal_point)]
            key, text = self._key("edge", start, legs, n, seed)
            if key in todo:  # asked twice in one batch: simulated once, the second is a cache hit
                todo[key][2].append(i)
            elif (hit := self._lookup(key, text)) is not None:
                results[i] = hit
            elif isinstance(start, StartStates) and len(start) == 0:
                results[i] = _unreached_result(start)  # nothing reached the start: p = 0, nothing run
            else:
                todo[key] = (text, (start, legs, n, seed), [i])
        batch = max(1, self.MAX_EPISODES // n)
        pending = list(todo.items())
        for lo in range(0, len(pending), batch):
            chunk = pending[lo:lo + batch]
            for (key, (text, _, positions)), out in zip(chunk, self._rollout_many([t for _, (_, t, _) in chunk])):
                res = _edge_result(out, n)
                self.evaluations += 1
                self._remember(key, res)
                self._store(key, text, res)
                results[positions[0]] = res
                for i in positions[1:]:
                    self.cache_hits += 1
                    results[i] = replace(res, cached=True)
        return results

    def _lookup(self, key: str, text: str) -> EdgeResult | None:
        hit = self._memo.get(key)
        if hit is None:
            hit = self._load(key, text)
            if hit is not None:
                self.disk_hits += 1
                self._remember(key, replace(hit, cached=False))
        else:
            self._memo.move_to_end(key)
        if hit is None:
            return None
        self.cache_hits += 1
        return replace(hit, cached=True)

    def _remember(self, key: str, res: EdgeResult) -> None:
        for a in (res.success, res.trajectories, res.lengths, res.outcome, res.end_states.states, res.end_states.xy):
            a.flags.writeable = False  # shared with the cache: read-only
        self._memo[key] = res
        while len(self._memo) > self.MEMO_SIZE:
            self._memo.popitem(last=False)

    def evaluate_edge(self, graph, u: str, v: str, start: Region | StartStates | None = None, seed=None,
                      n: int | None = None) -> EdgeResult:
        """``evaluate`` on the graph edge u -> v (start defaults to I(u); goal point = v's point, if any)."""
        return self.evaluate(graph.region(u) if start is None else start, graph.region(v), graph.avoid(u, v),
                             goal_point=graph.goal_point(v), seed=seed, n=n)

    def run_path(self, start: Region | StartStates, legs, n: int | None = None, seed=None) -> PathResult:
        """Run the compositional policy: legs ``[(goal, avoid, goal_point | None), ...]`` end to end.

        Each episode starts in ``start`` and pursues leg 0's goal point; on reaching a leg's goal region it
        switches to the next leg (fresh ``horizon`` steps per leg).  It fails on entering the current leg's
        avoid set, flipping, or running out of a leg's horizon.
        """
        n = int(n or self.n)
        seed = self.seed if seed is None else seed
        legs = [tuple(leg) if len(leg) == 3 else (leg[0], leg[1], None) for leg in legs]
        if not legs:
            raise SpecrefineError("run_path needs at least one leg")
        out = self._rollout(start, legs, n, seed)
        success = out["legs_done"] == len(legs)
        k = int(success.sum())
        res = PathResult(p=k / n, ci=wilson_ci(k, n), n=n, successes=k, success=success, legs_done=out["legs_done"],
                         trajectories=out["trajectories"], lengths=out["lengths"], steps=out["steps"],
                         outcome=out["outcome"], n_legs=len(legs))
        return res

    def run_graph_path(self, graph, path: list[str], n: int | None = None, seed=None) -> PathResult:
        """``run_path`` along a vertex path of a task graph, from I(path[0])."""
        return self.run_path(graph.region(path[0]), path_legs(graph, path), n=n, seed=seed)

    # --- the hot loop --------------------------------------------------------------------------
    def _rollout(self, start, legs, n: int, seed) -> dict:
        return self._rollout_many([(start, legs, n, seed)])[0]

    def _rollout_many(self, tasks: list[tuple]) -> list[dict]:
        """Run several ``(start, legs, n, seed)`` tasks side by side in one batch; one result dict per task."""
        # small-batch inference is fastest on one torch thread; more threads only contend with MuJoCo's
        with _torch_threads(1):
            return self._rollout_batches(tasks)

    def _start_rows(self, sim, rows: np.ndarray, start, n: int, rng: np.random.Generator) -> None:
        if isinstance(start, StartStates):
            if len(start) == 0:
                raise SpecrefineError("empty start distribution (no successful rollouts to start from)")
            sim.reset(states=start.states[rng.integers(len(start), size=n)], idx=rows)
        else:
            sim.reset(xy=self.spawn_points(start, n, rng), rng=rng, idx=rows)

    def _rollout_batches(self, tasks: list[tuple]) -> list[dict]:
        """Run every task's n episodes through its legs; the core loop behind ``evaluate`` and ``run_path``.

        Episodes of all tasks live in rows of one BatchedSim (each task seeded on its own, so a task's
        start states and goal points do not depend on its neighbours).  When at most half of the rows
        are still running, the running ones are moved (full physics states, bit-exact) into a smaller
        BatchedSim (a power of two, at least ``MIN_BATCH``), so finished rollouts stop costing physics.
        """
        counts = np.array([n for _, _, n, _ in tasks])
        first = np.concatenate([[0], np.cumsum(counts)])
        N, n_legs = int(first[-1]), np.array([len(legs) for _, legs, _, _ in tasks])
        L = int(n_legs.max())
        task_of = np.repeat(np.arange(len(tasks)), counts)
        L_of = n_legs[task_of]
        sim = self.sim(-(-N // self.MIN_BATCH) * self.MIN_BATCH)
        goal_pts = np.zeros((L, N, 2))
        goal_id = np.zeros((len(tasks), L), dtype=np.int64)  # (task, leg) -> index into goals / avoids
        avoid_id = np.zeros((len(tasks), L), dtype=np.int64)
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
        H, r = self.horizon, self.body_radius
        T = L * H + 1
        traj = np.empty((N, T, 2), dtype=np.float32)
        leg = np.zeros(N, dtype=np.int64)
        t_leg = np.zeros(N, dtype=np.int64)
        active = np.ones(N, dtype=bool)
        lengths = np.full(N, T, dtype=np.int64)
        outcome = np.full(N, UNFINISHED, dtype=np.int8)
        end_states = np.zeros((N, sim.state_dim))
        end_xy = np.zeros((N, 2))
        episode = np.concatenate([np.arange(N), np.full(sim.n - N, -1)])  # episode held by each sim row (-1: padding)
        row = np.arange(N)  # sim row of each episode (-1: not in the sim any more)
        xy, flipped = sim.xy[:N], sim.flipped[:N]
        traj[:, 0] = xy
        steps = np.zeros(len(tasks), dtype=np.int64)  # rows held by each task's episodes, per step
        padding_steps = 0

        def classify(sel, ids, regions, test):
            """test(region, points) for the episodes ``sel``, grouped by the region each one is in."""
            out = np.zeros(len(sel), dtype=bool)
            for i in np.unique(ids):
                m = ids == i
                out[m] = test(regions[i], xy[sel[m]])
            return out

        def check(t: int) -> None:
            """Classify the running episodes at time t (after the step that led there)."""
            idx = np.flatnonzero(active)
            for _ in range(L + 1):  # a point may lie in several consecutive goals: advance through all of them
                if not len(idx):
                    break
                task, k = task_of[idx], leg[idx]
                bad = classify(idx, avoid_id[task, k], avoids, lambda a, p: a.below(p, r)) | flipped[idx]
                reached = ~bad & classify(idx, goal_id[task, k], goals, lambda g, p: g.contains(p))
                if bad.any():
                    b = idx[bad]
                    outcome[b] = np.where(flipped[b], FLIPPED, AVOID)
                    active[b] = False
                    lengths[b] = t + 1
                g = idx[reached]
                leg[g] += 1
                t_leg[g] = 0
                done = g[leg[g] == L_of[g]]
                if len(done):
                    outcome[done] = SUCCESS
                    active[done] = False
                    lengths[done] = t + 1
                    end_states[done] = sim.get_state()[row[done]]
                    end_xy[done] = xy[done]
                idx = g[leg[g] < L_of[g]]

        check(0)
        import torch

        with torch.inference_mode():
            for t in range(1, T):
                running = int(active.sum())
                if not running:
                    break
                size = max(self.MIN_BATCH, 1 << (running - 1).bit_length())
                if size <= sim.n // 2:  # compact: move the running episodes into a smaller batch
                    ids = np.flatnonzero(active)
                    states = sim.get_state()[row[ids]]
                    states = np.concatenate([states, np.repeat(states[:1], size - len(ids), axis=0)])
                    sim = self.sim(size)
                    sim.reset(states=states)
                    episode = np.concatenate([ids, np.full(size - len(ids), -1)])
                    row[:] = -1
                    row[ids] = np.arange(len(ids))
                live = episode >= 0
                ep = np.where(live, episode, episode[0])
                obs = sim.observe(goal_pts[np.minimum(leg[ep], L_of[ep] - 1), ep])
                act = np.asarray(self._act(obs), dtype=np.float64)
                act[~(live & active[ep])] = 0.0  # finished rollouts stay still
                sim.step(act)
                steps += np.bincount(task_of[episode[live]], minlength=len(tasks))
                padding_steps += int((~live).sum())
                xy[episode[live]] = sim.xy[live]
                flipped[episode[live]] = sim.flipped[live]
                traj[:, t] = xy
                t_leg[active] += 1
                check(t)
                late = active & (t_leg >= H)
                if late.any():
                    outcome[late] = TIMEOUT
                    active[late] = False
                    lengths[late] = t + 1
        self.sim_steps += int(steps.sum()) + padding_steps
        if len(tasks) == 1:
            steps[0] += padding_steps
        return [self._task_output(slice(first[j], first[j + 1]), traj, lengths, leg, outcome, end_states, end_xy,
                                  int(steps[j])) for j in range(len(tasks))]

    @staticmethod
    def _task_output(rows: slice, traj, lengths, leg, outcome, end_states, end_xy, steps: int) -> dict:
        lengths = lengths[rows]
        n = len(lengths)
        used = int(lengths.max(initial=1))
        pad = np.minimum(np.arange(used)[None, :], lengths[:, None] - 1)
        return {"legs_done": leg[rows], "trajectories": traj[rows][np.arange(n)[:, None], pad], "lengths": lengths,
                "outcome": outcome[rows], "end_states": end_states[rows], "end_xy": end_xy[rows], "steps": steps}


def _edge_result(out: dict, n: int) -> EdgeResult:
    success = out["legs_done"] == 1
    k = int(success.sum())
    return EdgeResult(p=k / n, ci=wilson_ci(k, n), n=n, successes=k, success=success,
                      trajectories=out["trajectories"], lengths=out["lengths"],
                      end_states=StartStates(out["end_states"][success], out["end_xy"][success]),
                      steps=out["steps"], outcome=out["outcome"])


def _unreached_result(start: StartStates) -> EdgeResult:
    sdim = start.states.shape[1] if start.states.ndim == 2 else 0
    return EdgeResult(0.0, (0.0, 1.0), 0, 0, np.zeros(0, bool), np.zeros((0, 1, 2), np.float32),
                      np.zeros(0, np.int64), StartStates(np.zeros((0, sdim)), np.zeros((0, 2))), 0,
                      outcome=np.zeros(0, np.int8))


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


# --- the monitor --------------------------------------------------------------------------------------
def satisfies(graph, trajectories, lengths=None, body_radius: float = 0.0) -> np.ndarray:
    """Which trajectories satisfy the task graph's specification.

    A trajectory s_0..s_{T-1} satisfies the graph if there are a path v0 = initial -> v1 -> ... -> vk
    (vk final) and times 0 = t0 <= t1 <= ... <= tk < T with s_{ti} in I(vi) and, for every i >= 1, no
    state s_t with t_{i-1} <= t <= t_i inside O(v_{i-1} -> v_i) (signed distance < ``body_radius``).
    Choices in the DAG are resolved nondeterministically: the monitor tracks the set of edges a
    trajectory may currently be traversing (an NFA over edges), vectorised over trajectories.
    """
    traj = np.asarray(trajectories, dtype=float)
    if traj.ndim == 2:
        traj = traj[None]
    n, T = traj.shape[:2]
    lengths = np.full(n, T) if lengths is None else np.asarray(lengths, dtype=np.int64)
    valid = np.arange(T)[None, :] < lengths[:, None]  # (n, T)
    flat = traj.reshape(-1, 2)
    g = graph.g
    order = list(_topological(graph))
    def chunked(fn, *args):  # bounded memory for long trajectories x many boxes
        return np.concatenate([fn(flat[i:i + 32768], *args) for i in range(0, len(flat), 32768)]).reshape(n, T)

    compiled: dict = {}
    comp = lambda region: compiled.setdefault(region, CompiledRegion(region))  # noqa: E731
    in_v = {v: chunked(comp(graph.region(v)).contains) for v in order}
    bad = {}
    for u, v in graph.edges():
        bad[(u, v)] = chunked(comp(graph.avoid(u, v)).below, body_radius)
    active = {e: np.zeros(n, dtype=bool) for e in bad}
    accepted = np.zeros(n, dtype=bool)
    finals = set(graph.finals)
    for t in range(T):
        ok_t = valid[:, t]
        reached = {}
        for v in order:
            r = (in_v[v][:, t] & ok_t) if (t == 0 and v == graph.initial) else np.zeros(n, dtype=bool)
            for u in g.predecessors(v):
                r |= active[(u, v)] & in_v[v][:, t]
            reached[v] = r
            if v in finals:
                accepted |= r
            for w in g.successors(v):
                e = (v, w)
                active[e] = (active[e] | r) & ~bad[e][:, t] & ok_t
        # edges into v were updated before v was visited (topological order), so reaching v at time t
        # uses edges that survived time t -- the avoid check includes the reaching state itself
        if not any(a.any() for a in active.values()):
            break
    return accepted


def _topological(graph):
    import networkx as nx

    return nx.topological_sort(graph.g)


# --- a scripted controller for the point mass ------------------------------------------------------
class PointController:
    """A straight-line controller for the point mass (no learning, no knowledge of walls).

    It tracks the velocity ``min(gain * |e|, vmax)`` towards the goal (``e`` = goal - xy) with a
    proportional force: ``a = clip(kv * (v* - v), -1, 1)``.  Observation layout as in
    :class:`~specrefine.sim.BatchedSim` for the point: velocity (2), goal - xy (2).  Deterministic;
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
