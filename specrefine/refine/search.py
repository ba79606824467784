"""A* search over the task graph with interleaved refinement (Algorithm 3).

Progress is the search of a single-source shortest path with edge weights -log p,
evaluated lazily when an edge's source vertex is closed, starting from the end states of
the successful rollouts that reached it (DiRL).  The heuristic is zero, so progress is
Dijkstra's order; what makes the search "inadmissible" is the refinement in between.

Between two progress steps, refinements of the open frontier compete with progress:
for every open vertex v (reached from the closed vertex u), an edge split of u -> v
(Algorithm 1) and, where deg_in(v) = deg_out(v) = 1, a vertex subset of v (Algorithm 2).
A refinement's cost is the cost its far endpoint would have afterwards (for a vertex
subset, cost(v) minus the gain it brings to v's successor).  The cheapest is incorporated
while it beats the cheapest open vertex by tau; tau grows linearly from 0.02 by 0.02 per
incorporated refinement, capped at 0.1.  Two prunings skip generating refinements that
cannot pass that test (they never change the outcome): an edge split is only generated
when cost(u) < c_progress - tau and cost(v) - cost(u) > tau.

Every accepted refinement is checked against the input graph (Theorem 4.1); a failure
raises InvalidRefinement, because it is a bug.  Every step is recorded for replay.
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ..core.graph import TaskGraph, assert_refines
from ..core.paper import PAPER
from .common import UNREACHED, Leg, SubtaskEvaluator, estimate_legs, live_start, start_of, weight
from .correct import CHECK_SEED_OFFSET, PASS_SEED_STEP, Check, correct, path_legs
from .edge_split import SplitCandidate, edge_split
from .polish import polish
from .racing import Racing
from .repair import cheapest, repair
from .roadmap import Roadmap
from .shortcut import add_shortcuts, shortcuts
from .vertex import refine_chain

EVALUATIONS = ("fixed", "adaptive")
SPLIT_PICKS = ("estimate", "confirmed")  # the paper's pick (best estimate), or confirmed on fresh rollouts
POLISH_SEED_OFFSET = 7919  # polishing draws its rollouts apart from the search's (and the measurement's) seeds
TUNE_CHECK_SEED_OFFSET = 15_485_863  # the tuning check's fresh rollouts: apart from every other estimate's
CONFIRM_SEED_OFFSET = 32_452_843  # the confirmation's fresh rollouts: apart from every other estimate's


@dataclass
class SearchConfig:
    w: int = PAPER.w  # candidate edge splits per proposer query
    d: int = PAPER.d  # proposer rounds per edge split
    k: int = PAPER.k  # subsets sampled per vertex refinement
    edge_refinement: bool = True
    vertex_refinement: bool = True  # the search's own vertex refinements (Algorithm 3)
    split_tuning: bool = True  # Algorithm 2 on an edge split's later-round candidates (Algorithm 1, line 10)
    tuning_check: bool = False  # beyond the paper: a tuned chain kept only if it beats its proposal on fresh rollouts
    confirm_pick: bool = False  # beyond the paper: a later round's pick kept only if it beats the first round's best
    split_feedback: bool = True  # later rounds of an edge split see the earlier candidates' results
    tau0: float = 0.02
    tau_step: float = 0.02
    tau_max: float = 0.1
    max_edge_splits: int = 30  # budget of Algorithm 1 calls (proposer queries) per search
    seed: int = 0
    evaluation: str = "fixed"  # "fixed": every estimate on n rollouts (the paper); "adaptive": racing.py
    repair: bool = False  # beyond the paper: split a candidate's failing legs before it is judged (repair.py)
    repair_tuning: bool = False  # beyond the paper: Algorithm 2 on a repaired chain before it is judged
    shortcut_reach: float | None = None  # beyond the paper: shortcut edges up to this long on the path (shortcut.py)
    polish_rollouts: int | None = None  # beyond the paper: the path's weak waypoints tuned on this many rollouts
    repair_depth: int = 1  # beyond the paper: levels of repair (a repaired leg's split with a dead leg of its own)
    correct_rollouts: int | None = None  # beyond the paper: the found path checked on this many x n fresh rollouts
    #                                      per leg and its weak legs corrected (correct.py; method ours-corrector)
    correct_splits_per_leg: float = 1.0  # the correction's proposer splits: this many per leg of the found path
    dead_weight: float | None = None  # beyond the paper: the weight of a leg that never succeeded (None: -log(0.5/n))
    correct_reach: float | None = None  # the correction drops a waypoint only where the leg it makes is this short
    correct_min_failures: int = 1  # the correction asks the proposer about a leg only with this many fresh failures
    correct_lean: bool = False  # the correction judges by posterior means and offers every waypoint its bypass
    correct_passes: int = 1  # the correction again on a fresh draw, from the path it left: this many passes in all
    correct_wide: int | None = None  # beyond the paper: after the passes, one more on a wide draw of this many x n
    #                                  fresh rollouts per leg, the proposer asked only about a leg with at least
    #                                  correct_wide_min_failures failures there (method ours-corrector-wide)
    correct_wide_min_failures: int = 3
    correct_while_dead: bool = False  # beyond the paper: further passes while the corrected path has a leg that never
    #                                   succeeded on its fresh check, until the search's max_edge_splits are spent
    dead_budget: int | None = None  # beyond the paper: while the path still has such a dead leg, those passes go on
    #                                 up to this many Algorithm 1 calls in all (None: max_edge_splits; the budget
    #                                 grows only where the run would otherwise end at 0: ours-corrector-extend)
    correct_first_win: bool = False  # the correction asks for a leg's alternatives cheapest first, stops at a win
    correct_rounds: int | None = None  # proposer rounds of the correction's Algorithm 1 calls (None: d)
    snap_waypoints: bool = False  # beyond the paper: a reply's waypoint centred in a wall is moved clear of it
    #                               (by the agent's clearance, within one cell) instead of the reply being rejected
    keep_declined: bool = False  # beyond the paper: a dead edge of the found path is replaced by its declined edge
    #                              split with the most legs alive before its first dead one, so that the correction
    #                              repairs that split's dead legs instead of asking for the whole edge again
    keep_fallback: bool = False  # with keep_declined: where the kept split's correction leaves the path dead at half
    #                              the budget left, the path goes back to the edge it replaced, corrected as before
    correct_reaim: bool = False  # beyond the paper: the correction also offers a weak leg's end waypoints aimed at
    #                              their regions' clearest points (correct.py; method ours-corrector-reaim)
    correct_crosscheck: bool = False  # beyond the paper: the correction takes a win only if it also wins on a second
    #                                   draw (correct.py; method ours-corrector-crosscheck)
    correct_advance: bool = False  # beyond the paper: a dead leg's split cut after its live legs replaces the path
    #                                where it gets nearer the leg's end (correct.py; method ours-corrector-advance)
    correct_roadmap: bool = False  # beyond the paper: a dead leg of a dead path is first offered a chain over every
    #                                reply's waypoints pooled (roadmap.py; method ours-corrector-roadmap)
    roadmap_sound: float = 0.0  # beyond the paper: the roadmap's chain builds only on legs at least this fraction of
    #                             whose rollouts succeed (0: any success; roadmap.py; method ours-corrector-sound)
    roadmap_remember: bool = False  # beyond the paper: a roadmap search starts from the nodes the searches before it
    #                                 reached from the same origin (roadmap.py; method ours-corrector-memory)
    roadmap_explore: float = 0.0  # beyond the paper: a roadmap search that runs out of legs adds waypoints this
    #                               fraction of correct_reach from what it reached (roadmap.py; ours-corrector-explore)
    roadmap_probe: float = 0.0  # beyond the paper: the same from one node at a time, nearest the goal first, its own
    #                             waypoints tried from it only (roadmap.py; method ours-corrector-probe)
    roadmap_rings: int = 1  # beyond the paper: probe rings per node, each at half the radius of the one before, once
    #                         every node reached has the one before (roadmap.py; 2: method ours-corrector-fine)
    roadmap_evaluations: int = 120  # subtask evaluations one roadmap search may spend at most (roadmap.py; 360:
    #                                 method ours-corrector-deep)
    correct_guard: bool = False  # beyond the paper: a correction's win on its window is kept only if the whole path,
    #                              checked again from the window on, scores no lower (correct.py; ours-corrector-guard)
    roadmap_weak: float = 0.0  # beyond the paper: a live leg whose fresh success is below this is also offered the
    #                            roadmap's chain, after the proposer's alternatives and whatever budget is left (0:
    #                            dead legs of dead paths only; correct.py; method ours-corrector-mend)
    roadmap_bridge: bool = False  # beyond the paper: such a weak leg is also offered the chain from the leg before it
    #                               (correct.py; method ours-corrector-bridge)
    roadmap_backtrack: bool = False  # beyond the paper: a dead leg of a dead path whose alternatives all lose is also
    #                                  offered the chain from the path's start (correct.py; ours-corrector-backtrack)
    roadmap_span: int = 0  # beyond the paper: such a weak leg is also offered the chains from its start to each of
    #                        this many vertices of its split past its end (correct.py; 2: method ours-corrector-span)
    roadmap_floor: float = 0.0  # beyond the paper: while the path's fresh check is below this, a live leg is also
    #                             weak below floor ** (1 / legs), where that is above roadmap_weak: legs that each lose
    #                             a few per cent and together take the path under it (correct.py; the rescue's changes
    #                             of method ours-corrector-redraw-rescue-floor)
    empty_retries: int = 0  # beyond the paper: an edge split whose reply gave no valid candidate is asked again
    #                         this many times at most, within the budget (method ours-corrector-retry)
    rescue: dict | None = None  # beyond the paper: where the correction leaves a leg that never succeeded on its
    #                             last fresh check, the path is corrected once more with these changes to this
    #                             config (method ours-corrector-redraw-rescue: span-bridge's correction); a path it
    #                             leaves alive is never touched, so on every such run the method is its base

    def __post_init__(self):
        if self.evaluation not in EVALUATIONS:
            raise ValueError(f"evaluation must be one of {', '.join(EVALUATIONS)}, got {self.evaluation!r}")
        if self.correct_passes < 1:
            raise ValueError(f"correct_passes must be at least 1, got {self.correct_passes!r}")
        if self.correct_wide is not None and (self.correct_wide < 1 or not self.correct_rollouts):
            raise ValueError(f"correct_wide must be at least 1 and needs correct_rollouts, got {self.correct_wide!r}")
        if self.correct_wide_min_failures < 1:
            raise ValueError(f"correct_wide_min_failures must be at least 1, got {self.correct_wide_min_failures!r}")
        if self.empty_retries < 0:
            raise ValueError(f"empty_retries must be at least 0, got {self.empty_retries!r}")
        if self.dead_budget is not None and self.dead_budget < 1:
            raise ValueError(f"dead_budget must be at least 1 (or None: max_edge_splits), got {self.dead_budget!r}")
        if self.correct_roadmap and not (self.correct_reach and self.correct_reach > 0):
            raise ValueError("correct_roadmap needs correct_reach > 0 (the longest leg its chain may try; methods "
                             "give 'policy', the agent's goal range)")
        if self.roadmap_bridge and not self.roadmap_weak:
            raise ValueError("roadmap_bridge needs roadmap_weak > 0 (it bridges the weak legs mend offers its chain)")
        if self.roadmap_span < 0:
            raise ValueError(f"roadmap_span must be at least 0, got {self.roadmap_span!r}")
        if self.roadmap_span and not self.roadmap_weak:
            raise ValueError("roadmap_span needs roadmap_weak > 0 (it spans past the weak legs mend offers its chain)")
        for name in ("roadmap_remember", "roadmap_explore", "roadmap_probe", "roadmap_weak", "roadmap_backtrack"):
            if getattr(self, name) and not self.correct_roadmap:
                raise ValueError(f"{name} needs correct_roadmap (it changes the roadmap's searches)")
        for name in ("roadmap_explore", "roadmap_probe"):
            fraction = getattr(self, name)
            if not 0.0 <= fraction <= 1.0:
                raise ValueError(f"{name} must lie in [0, 1] (a fraction of correct_reach), got {fraction!r}")
        if self.roadmap_evaluations < 1:
            raise ValueError(f"roadmap_evaluations must be at least 1, got {self.roadmap_evaluations!r}")
        if self.roadmap_rings < 1:
            raise ValueError(f"roadmap_rings must be at least 1, got {self.roadmap_rings!r}")
        if self.roadmap_rings > 1 and not self.roadmap_probe:
            raise ValueError("roadmap_rings > 1 needs roadmap_probe > 0 (they are the probes' finer rings)")
        if self.roadmap_floor and not self.roadmap_weak:
            raise ValueError("roadmap_floor needs roadmap_weak > 0 (it raises the level below which mend's chain is "
                             "offered)")
        for name in ("roadmap_sound", "roadmap_weak", "roadmap_floor"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise ValueError(f"{name} must lie in [0, 1], got {getattr(self, name)!r}")
        if self.correct_rounds is not None and self.correct_rounds < 1:
            raise ValueError(f"correct_rounds must be at least 1 (or None: d), got {self.correct_rounds!r}")
        if self.rescue is not None:
            if not self.correct_rollouts:
                raise ValueError("rescue needs correct_rollouts (it follows the correction)")
            check_changes(self.rescue)
            self.rescued()  # its own checks

    def rescued(self) -> SearchConfig:
        """The configuration a rescue corrects with: this one with ``rescue``'s changes (and no further rescue)."""
        return replace(self, **(self.rescue or {}), rescue=None)

    @classmethod
    def from_run(cls, run, **changes) -> SearchConfig:
        """The search a run's configuration asks for (``run``: a resolved ``runs.config.RunConfig``: its w, d, k,
        seed and evaluation), with ``changes`` to any field; an unknown field is a one-line SpecrefineError."""
        check_changes(changes)
        taken = {name: getattr(run, name) for name in FROM_RUN}
        taken["confirm_pick"] = getattr(run, "split_pick", None) == "confirmed"  # a method's own setting wins
        return cls(**{**taken, **changes})


FROM_RUN = ("w", "d", "k", "seed", "evaluation")  # what a run's configuration sets in its search


def check_changes(changes: dict) -> None:
    """A one-line SpecrefineError if ``changes`` names a field SearchConfig does not have."""
    from dataclasses import fields

    from ..core.errors import SpecrefineError

    unknown = sorted(set(changes) - {f.name for f in fields(SearchConfig)})
    if unknown:
        raise SpecrefineError(f"SearchConfig has no field {', '.join(map(repr, unknown))}: use "
                              f"{', '.join(f.name for f in fields(SearchConfig))}")


def _confirm_log(outcome) -> dict:
    """The split's confirmation for steps.jsonl: both fresh products and which pick was kept (none: not confirmed)."""
    if outcome.confirm is None:
        return {}
    first, later = outcome.confirm
    return {"confirm": {"first_round": first, "later": later, "kept": "later" if later > first else "first round"}}


@dataclass
class Refinement:
    kind: str  # "split" or "vertex"
    u: str
    v: str
    cost: float
    data: object  # SplitCandidate or ChainChoice


@dataclass
class SearchResult:
    graph: TaskGraph
    path: list[str] | None
    edge_probabilities: list[float]
    steps: list[dict]
    refinements: int
    edge_splits_generated: int
    vertex_refinements_generated: int
    roadmap: Roadmap | None = None  # the correction's pooled waypoints, probes and searches (roadmap methods)

    @property
    def predicted_success(self) -> float:
        return float(math.prod(self.edge_probabilities)) if self.path else 0.0


@dataclass
class _Frontier:
    cost: dict = field(default_factory=dict)  # v -> best cost (closed and open)
    parent: dict = field(default_factory=dict)
    arrivals: dict = field(default_factory=dict)  # v -> start distribution of its out-edges
    open: set = field(default_factory=set)
    closed: list = field(default_factory=list)  # in closing order


class RefinementSearch:
    def __init__(self, graph: TaskGraph, evaluator: SubtaskEvaluator, *, proposer=None, config=None,
                 query_for: Callable | None = None, picture: Callable | None = None,
                 on_step: Callable[[dict], None] | None = None):
        self.original = graph
        self.graph = graph.copy()
        self.evaluator = evaluator
        self.proposer = proposer
        self.cfg = config or SearchConfig()
        self.query_for = query_for  # (graph, u, v, EdgeResult) -> EdgeQuery for the proposer
        self.picture = picture  # SplitCandidate -> PNG bytes for proposer feedback
        self.on_step = on_step
        self.rng = np.random.default_rng(self.cfg.seed)
        self.racing = Racing.for_budget(evaluator.n) if self.cfg.evaluation == "adaptive" else None
        self.tau = self.cfg.tau0
        self.f = _Frontier()
        self.results: dict[tuple[str, str], object] = {}
        self.memo: dict[tuple, Refinement | None] = {}
        self.steps: list[dict] = []
        self.accepted = 0
        self.splits_generated = 0
        self.vertex_generated = 0
        self._extended = False  # the correction has gone past max_edge_splits (dead_budget), logged once
        self._draws = 0  # the correction's fresh draws so far (a rescue's passes draw apart from them)
        # the pooled replies: kept from the first split where the correction or its rescue may search them
        pooled = self.cfg.rescued() if self.cfg.rescue else self.cfg
        self.roadmap = (Roadmap(reach=pooled.correct_reach, sound=pooled.roadmap_sound,
                                remember=pooled.roadmap_remember, explore=pooled.roadmap_explore,
                                probe=pooled.roadmap_probe, rings=pooled.roadmap_rings,
                                evaluations=pooled.roadmap_evaluations)
                        if self.cfg.correct_roadmap or pooled.correct_roadmap else None)
        if self.cfg.edge_refinement and (proposer is None or query_for is None):
            raise ValueError("edge refinement needs a proposer and a query builder")

    # --- the loop (Algorithm 3) ----------------------------------------------------
    def run(self) -> SearchResult:
        g, f = self.graph, self.f
        f.cost[g.initial], f.arrivals[g.initial] = 0.0, g.region(g.initial)
        f.open.add(g.initial)
        final = None
        while f.open:
            u = min(f.open, key=lambda v: (f.cost[v], v))
            f.open.discard(u)
            f.closed.append(u)
            self._log("expand", vertex=u, cost=f.cost[u])
            if u in g.finals:
                final = u
                break
            for v in g.successors(u):
                self._relax(u, v)
            self._refine()
        path = self._trace(final)
        if path and self.cfg.shortcut_reach:
            path = self._shortcut(path)
        before = None
        if path and self.cfg.keep_declined:
            if self.cfg.keep_fallback:  # what the kept split replaces, for its fallback
                before = (self.graph.copy(), list(path), dict(self.results))
            path = self._take_declined(path)
        if path and self.cfg.polish_rollouts:
            self._polish(path)
        if path and self.cfg.correct_rollouts:
            self._log("correct-begin", path=path)  # its counts: what the search (and polish) spent
            if before is not None and path != before[1]:
                path, alive = self._correct_kept(path, before)
            else:
                path, alive = self._correct(path)
            if not alive and self.cfg.rescue:
                path = self._rescue(path)
        probs = [self.results[(a, b)].p for a, b in zip(path, path[1:])] if path else []
        self._log("done", path=path, predicted_success=float(math.prod(probs)) if path else 0.0,
                  probabilities=probs, splits_generated=self.splits_generated,
                  max_edge_splits=self.cfg.max_edge_splits,
                  **({"dead_budget": self.cfg.dead_budget} if self.cfg.dead_budget is not None else {}))
        return SearchResult(self.graph, path, probs, self.steps, self.accepted, self.splits_generated,
                            self.vertex_generated, self.roadmap if self.cfg.correct_roadmap else None)

    def _relax(self, u: str, v: str) -> None:
        f = self.f
        if v in f.closed:  # Dijkstra: a closed vertex's cost is final (weights are >= 0)
            return
        result = self.results.get((u, v))
        if result is None:
            result = self._evaluate(f.arrivals[u], v, (u, v))
            self.results[(u, v)] = result
            self._log("evaluate", edge=[u, v], p=result.p, ci=list(result.ci))
        c = f.cost[u] + self._weight(result.p)
        if v not in f.open or c < f.cost[v]:
            f.cost[v], f.parent[v], f.arrivals[v] = c, u, start_of(result)
            f.open.add(v)

    def _weight(self, p: float) -> float:
        """An edge's weight: -log p, with p = 0 guarded by half a success in n rollouts (the paper's search) or,
        given ``dead_weight``, weighing that much, so that any chain that succeeds at all beats one that never does."""
        if p <= 0.0 and self.cfg.dead_weight is not None:
            return self.cfg.dead_weight
        return weight(p, self.evaluator.n)

    def _evaluate(self, start, v: str, edge):
        g = self.graph
        return estimate_legs(self.evaluator, start, [Leg(g.region(v), g.avoid(*edge), g.goal_point(v))]).results[0]

    def _refine(self) -> None:
        f = self.f
        while f.open:
            c_progress = min(f.cost[v] for v in f.open)
            best = self._best_refinement(c_progress)
            if best is None or not best.cost < c_progress - self.tau:
                if best is not None:
                    self._log("refine-declined", kind=best.kind, edge=[best.u, best.v], cost=best.cost,
                              c_progress=c_progress, tau=self.tau)
                return
            self._apply(best)
            self._log("refine-accept", kind=best.kind, edge=[best.u, best.v], cost=best.cost,
                      c_progress=c_progress, tau=self.tau, graph=self.graph.to_dict())
            self.tau = min(self.tau + self.cfg.tau_step, self.cfg.tau_max)

    # --- generating refinements ("Update refinements") -------------------------------
    def _best_refinement(self, c_progress: float) -> Refinement | None:
        candidates = []
        for v in sorted(self.f.open, key=lambda x: self.f.cost[x]):
            u = self.f.parent.get(v)
            if u is None or self.f.arrivals.get(u) is None:  # nothing reaches u: nothing to evaluate from
                continue
            if self.cfg.edge_refinement and self._split_may_win(u, v, c_progress):
                candidates.append(self._memo(("split",) + self._signature(u, v), self._gen_split, u, v))
            if self.cfg.vertex_refinement and self._vertex_eligible(v):
                w = self.graph.successors(v)[0]
                sig = ("vertex",) + self._signature(u, v) + self._signature(v, w)
                candidates.append(self._memo(sig, self._gen_vertex, u, v, w))
        candidates = [c for c in candidates if c is not None]
        return min(candidates, key=lambda c: c.cost) if candidates else None

    def _split_may_win(self, u, v, c_progress) -> bool:
        f = self.f
        if f.cost[u] >= c_progress - self.tau or f.cost[v] - f.cost[u] <= self.tau:
            return False
        sig = ("split",) + self._signature(u, v)
        return sig in self.memo or self.splits_generated < self.cfg.max_edge_splits

    def _vertex_eligible(self, v) -> bool:
        g = self.graph
        return g.is_chain_vertex(v) and g.successors(v)[0] not in self.f.closed

    def _signature(self, u, v) -> tuple:
        g = self.graph
        return (u, v, json.dumps(g.region(u).to_dict()), json.dumps(g.region(v).to_dict()))

    def _memo(self, sig, generate, *args):
        if sig not in self.memo:
            self.memo[sig] = generate(*args)
        return self.memo[sig]

    def _gen_split(self, u, v) -> Refinement | None:
        f = self.f
        for attempt in range(1 + self.cfg.empty_retries):
            if attempt and self.splits_generated >= self.cfg.max_edge_splits:
                break
            outcome = self._ask_split(u, v, attempt)
            if outcome.candidates:
                break
        best = outcome.best
        if best is None:
            return None
        if self.cfg.repair and best.p == 0.0:
            best = self._repair(u, v, cheapest(outcome.candidates, self.evaluator.n)) or best
        cost = f.cost[u] + sum(self._weight(p) for p in best.probabilities)
        return Refinement("split", u, v, cost, best)

    def _ask_split(self, u, v, attempt: int):
        """One Algorithm 1 call on the search's edge u -> v (``attempt`` > 0: asked again after a reply that gave
        no valid candidate), logged."""
        outcome = self._split_leg(self.graph, u, v, self.results[(u, v)], self.f.arrivals[u])
        budget = [self.splits_generated, self.cfg.max_edge_splits]  # Algorithm 1 calls so far, of the budget
        retry = {"asked_again": attempt} if attempt else {}
        self._log("split-generated", edge=[u, v], splits=budget, **retry, candidates=[
            {"round": c.round, "tuned": c.tuned, "p": c.p, "probabilities": c.probabilities,
             "waypoints": [x.to_dict() for x in c.waypoints],
             **({"check": {"proposed": c.check[0], "tuned": c.check[1]}} if c.check else {})}
            for c in outcome.candidates], **_confirm_log(outcome))
        return outcome

    def _split_leg(self, chain_graph, a, b, result, start, d: int | None = None):
        """Algorithm 1 on a -> b of ``chain_graph`` (a leg of a candidate or of the found path), from ``start``, in
        ``d`` proposer rounds (None: the configuration's)."""
        self.splits_generated += 1
        query = self.query_for(chain_graph, a, b, result)
        if self.cfg.snap_waypoints:
            query = replace(query, snap=float(getattr(self.evaluator, "clearance", 0.0)))
        outcome = edge_split(self.evaluator, self.proposer, query, start=start,
                             goal_point=chain_graph.goal_point(b), w=self.cfg.w, d=d or self.cfg.d, k=self.cfg.k,
                             rng=self.rng, picture=self.picture, racing=self.racing,
                             feedback=self.cfg.split_feedback, tune=self.cfg.split_tuning,
                             tune_check_seed=self.cfg.seed + TUNE_CHECK_SEED_OFFSET if self.cfg.tuning_check else None,
                             confirm_seed=self.cfg.seed + CONFIRM_SEED_OFFSET if self.cfg.confirm_pick else None)
        if self.roadmap is not None:
            for candidate in outcome.candidates:
                self.roadmap.add(candidate.waypoints)
        return outcome

    def _repair(self, u, v, candidate):
        repaired = repair(candidate, self.graph, u, v, start=self.f.arrivals[u], evaluator=self.evaluator,
                          split_leg=self._split_leg, may_split=lambda: self.splits_generated < self.cfg.max_edge_splits,
                          depth=self.cfg.repair_depth)
        after = dict(p_after=repaired.probabilities, legs_repaired=repaired.repaired,
                     waypoints=[x.to_dict() for x in repaired.waypoints]) if repaired else \
            dict(p_after=None, legs_repaired=0, waypoints=None)
        self._log("split-repaired", edge=[u, v], p_before=candidate.probabilities,
                  splits=[self.splits_generated, self.cfg.max_edge_splits], **after)
        if repaired is not None and self.cfg.repair_tuning and repaired.p > 0.0:
            repaired = self._tune_repaired(u, v, repaired)
        return repaired

    def _tune_repaired(self, u, v, candidate):
        """Algorithm 2 on the repaired chain's waypoints, as Algorithm 1 tunes its later-round candidates."""
        g = self.graph
        choice = refine_chain(self.evaluator, self.f.arrivals[u], list(candidate.waypoints), g.region(v),
                              [g.avoid(u, v)] * (len(candidate.waypoints) + 1), self.cfg.k, self.rng,
                              g.goal_point(v), racing=self.racing)
        self._log("split-repair-tuned", edge=[u, v], p_before=candidate.probabilities,
                  p_after=[r.p for r in choice.results], waypoints=[x.to_dict() for x in choice.regions])
        return SplitCandidate(choice.regions, choice.results, candidate.round, tuned=True,
                              repaired=candidate.repaired)

    def _gen_vertex(self, u, v, w) -> Refinement | None:
        self.vertex_generated += 1
        f, g = self.f, self.graph
        avoids = [g.avoid(u, v), g.avoid(v, w)]
        choice = refine_chain(self.evaluator, f.arrivals[u], [g.region(v)], g.region(w), avoids, self.cfg.k,
                              self.rng, g.goal_point(w), racing=self.racing)
        current = estimate_legs(self.evaluator, f.arrivals[u],
                                [Leg(g.region(v), avoids[0], g.goal_point(v)), Leg(g.region(w), avoids[1],
                                                                                   g.goal_point(w))])
        gain = sum(self._weight(r.p) for r in current.results) - sum(self._weight(r.p) for r in choice.results)
        self._log("vertex-generated", vertex=v, p_current=current.p, p_best=choice.p,
                  region=choice.regions[0].to_dict())
        if choice.regions[0] == g.region(v) or gain <= 0:
            return None
        return Refinement("vertex", u, v, f.cost[v] - gain, choice)

    # --- incorporating a refinement ------------------------------------------------
    def _apply(self, ref: Refinement) -> None:
        g = self.graph
        if ref.kind == "split":
            self.results.pop((ref.u, ref.v), None)
            names = g.split_edge(ref.u, ref.v, ref.data.waypoints)
            self.results[(ref.u, (names or [ref.v])[0])] = ref.data.results[0]
        else:
            g.narrow_vertex(ref.v, ref.data.regions[0])
            self.results[(ref.u, ref.v)] = ref.data.results[0]
        self.accepted += 1
        assert_refines(g, self.original)
        self._reopen()

    def _reopen(self) -> None:
        """Recompute the open set's tentative costs from the closed vertices ("Update open")."""
        f = self.f
        for v in list(f.open):
            f.cost.pop(v, None)
            f.parent.pop(v, None)
            f.arrivals.pop(v, None)
        f.open.clear()
        for u in f.closed:
            for v in self.graph.successors(u):
                if v not in f.closed:
                    self._relax(u, v)

    # --- beyond the paper: a declined split taken where the found path is dead ------------------
    def _take_declined(self, path: list[str]) -> list[str]:
        """Each edge of the found path that never succeeded, replaced by the split of it the search declined with the
        longest live start (a refinement of the graph, so Theorem 4.1 holds); an edge with no such split stays."""
        g = self.graph
        for a, b in list(zip(path, path[1:])):
            if self.results[(a, b)].p > 0.0:
                continue
            splits = [r for r in self.memo.values() if r is not None and r.kind == "split" and (r.u, r.v) == (a, b)]
            best = max(splits, key=lambda r: live_start(r.data.probabilities), default=None)
            if best is None or live_start(best.data.probabilities) == 0:
                continue
            names = g.split_edge(a, b, best.data.waypoints)
            self.results.pop((a, b), None)
            chain = [a, *names, b]
            self.results.update(zip(zip(chain, chain[1:]), best.data.results))
            i = path.index(a)
            path = path[:i + 1] + names + path[i + 1:]
            self._log("declined-kept", edge=[a, b], legs=len(best.data.results),
                      alive=live_start(best.data.probabilities), waypoints=[x.to_dict() for x in best.data.waypoints])
        assert_refines(g, self.original)
        return path

    # --- beyond the paper: polishing the found path (polish.py) --------------------------
    def _polish(self, path: list[str]) -> None:
        g = self.graph
        for step in polish(g, path, self.evaluator, rollouts=self.cfg.polish_rollouts, k=self.cfg.k, rng=self.rng,
                           seed=self.cfg.seed + POLISH_SEED_OFFSET):
            self._log("path-polished", vertex=step.vertex, p_before=step.p_before, p_after=step.p_after,
                      changed=step.changed, region=g.region(step.vertex).to_dict())
        assert_refines(g, self.original)
        self._estimate_again(path)

    def _estimate_again(self, path: list[str]) -> None:
        """The path's estimates again on the search's own rollouts, so that its prediction is made as before."""
        g = self.graph
        estimates = estimate_legs(self.evaluator, g.region(path[0]), path_legs(g, path)).results
        for edge, result in zip(zip(path, path[1:]), estimates):
            self.results[edge] = result

    # --- beyond the paper: correcting the found path on fresh rollouts (correct.py) ------
    def _correct_kept(self, path: list[str], before: tuple) -> tuple[list[str], bool]:
        """The correction of a path that took a declined split (keep_fallback): up to half the budget left, and where
        the path is still dead then, back to the graph, path and estimates before the split was taken, corrected
        within the rest as a path without it would have been -> (the path, whether it was left alive)."""
        limit = self._dead_limit()
        path, alive = self._correct(path, limit=self.splits_generated + (limit - self.splits_generated) // 2)
        if alive or self.splits_generated >= limit:
            return path, alive
        self.graph, path, self.results = before[0], list(before[1]), dict(before[2])
        self._log("declined-dropped", path=path, splits=[self.splits_generated, limit],
                  reason="the kept split's path is still dead")
        return self._correct(path)

    def _rescue(self, path: list[str]) -> list[str]:
        """The correction once more, with ``rescue``'s changes, on draws of its own: the path its correction left has
        a leg that never succeeded, and a proposer that gives nothing valid (or never uses its feedback) leaves the
        base method's correction nothing else to try there (docs/corrector.md, "A rescue for the Ant's default")."""
        self._log("rescue", path=path, reason="the correction left a leg that never succeeded",
                  changes=sorted(self.cfg.rescue))
        self.cfg = self.cfg.rescued()
        return self._correct(path, first_pass=self._draws)[0]

    def _correct(self, path: list[str], limit: int | None = None, first_pass: int = 0) -> tuple[list[str], bool]:
        """The correction (correct.py), ``correct_passes`` times: each pass on its own fresh draw (new first
        states, so a leg chosen on one pass's rollouts is judged again on rollouts that did not choose it), with a
        budget of its own -> (the path, whether its last fresh check found no dead leg). ``first_pass``: the draws
        used before (a rescue's passes draw apart from the correction's)."""
        for pass_ in range(first_pass, first_pass + self.cfg.correct_passes):
            path, check = self._correct_pass(path, pass_)
        pass_, limit = first_pass + self.cfg.correct_passes, limit or self._dead_limit()
        if self.cfg.correct_wide:
            path, check = self._correct_pass(path, pass_, wide=True)
            pass_ += 1
        while self.cfg.correct_while_dead and check.p <= 0.0 and self.splits_generated < limit:
            if self.splits_generated >= self.cfg.max_edge_splits and not self._extended:
                self._extended = True
                self._log("budget-extended", splits=[self.splits_generated, limit], reason="the path has a dead leg")
            asked = self.splits_generated
            path, check = self._correct_pass(path, pass_, budget=limit)
            pass_ += 1
            if self.splits_generated == asked:  # nothing left to ask about (no fresh rollout reaches the dead leg)
                break
        assert_refines(self.graph, self.original)
        self._estimate_again(path)
        self._draws = pass_  # the next pass draws apart from every one so far
        return path, check.p > 0.0

    def _dead_limit(self) -> int:
        """The Algorithm 1 calls the correction of a dead path may reach: ``dead_budget``, else the search's."""
        return self.cfg.max_edge_splits if self.cfg.dead_budget is None else self.cfg.dead_budget

    def _correct_pass(self, path: list[str], pass_: int, budget: int | None = None,
                      wide: bool = False) -> tuple[list[str], Check]:
        """One pass of the correction on its own fresh draw -> (the path, its fresh check). ``budget``: the Algorithm
        1 calls the search may have made when the pass ends (None: the calls so far plus its share per leg);
        ``wide``: the pass on ``correct_wide`` x n rollouts per leg, asking only about legs with
        ``correct_wide_min_failures`` failures (a leg losing a per cent or two shows several there, one losing a
        tenth of that mostly none)."""
        n = self.evaluator.n
        rollouts, min_failures = ((self.cfg.correct_wide, self.cfg.correct_wide_min_failures) if wide
                                  else (self.cfg.correct_rollouts, self.cfg.correct_min_failures))
        if budget is None:
            budget = self.splits_generated + math.ceil(self.cfg.correct_splits_per_leg * (len(path) - 1))

        split_once = functools.partial(self._split_leg, d=self.cfg.correct_rounds)

        def split_leg(graph, a, b, result, start):
            outcome = split_once(graph, a, b, result, start)
            best = outcome.best
            if best is not None and best.p == 0.0 and self.cfg.repair:
                best = repair(cheapest(outcome.candidates, n), graph, a, b, start=start, evaluator=self.evaluator,
                              split_leg=split_once, may_split=lambda: self.splits_generated < budget,
                              depth=self.cfg.repair_depth) or best
            if best is not None and best.p == 0.0 and self.cfg.correct_advance:  # the reply that got furthest alive
                best = max([best, *outcome.candidates], key=lambda c: live_start(c.probabilities))
            return best

        reach = self.cfg.correct_reach or 0.0
        single = self.cfg.correct_passes == 1 and not self.cfg.correct_while_dead and not self.cfg.correct_wide
        tag = dict(correct_pass=pass_ + 1) | (dict(wide_rollouts=rollouts * n) if wide else {})
        log = self._log if single else (lambda event, **detail: self._log(event, **detail, **tag))
        self.graph, path, check = correct(self.graph, path, self.evaluator, rollouts=rollouts * n,
                                      seed=self.cfg.seed + CHECK_SEED_OFFSET + pass_ * PASS_SEED_STEP,
                                      split_leg=split_leg, may_split=lambda: self.splits_generated < budget,
                                      reach=reach, clearance=getattr(self.evaluator, "clearance", 0.0), log=log,
                                      min_failures=min_failures, lean=self.cfg.correct_lean,
                                      first_win=self.cfg.correct_first_win, advance=self.cfg.correct_advance,
                                      roadmap=self._roadmap_chain if self.cfg.correct_roadmap else None,
                                      roadmap_weak=self.cfg.roadmap_weak, floor=self.cfg.roadmap_floor,
                                      guard=self.cfg.correct_guard,
                                      bridge=self.cfg.roadmap_bridge, backtrack=self.cfg.roadmap_backtrack,
                                      span=self.cfg.roadmap_span,
                                      reaim=self.evaluator.clearest if self.cfg.correct_reaim else None,
                                      crosscheck=self.cfg.correct_crosscheck)
        return path, check

    def _roadmap_chain(self, graph, a, b, start, sound: float | None = None):
        """The pooled waypoints' chain for the leg a -> b (roadmap.py; ``sound``: a weak leg's floor), logged."""
        found = self.roadmap.chain(self.evaluator, start, graph.region(a), graph.region(b), graph.avoid(a, b),
                                   graph.goal_point(b), sound=sound)
        extra = dict(remembered=found.remembered) if self.roadmap.remember else {}
        extra |= dict(explored=found.explored) if self.roadmap.explore or self.roadmap.probe else {}
        extra |= dict(sound=sound) if sound is not None else {}
        self._log("roadmap", edge=[a, b], pooled=len(self.roadmap.points), waypoints=len(found.waypoints),
                  reaches_end=found.reaches_goal, evaluations=found.evaluations, **extra)
        return found

    # --- beyond the paper: shortcut edges over the found path (shortcut.py) -------------
    def _shortcut(self, path: list[str]) -> list[str]:
        g = self.graph
        found = shortcuts(g, path, self.cfg.shortcut_reach, getattr(self.evaluator, "clearance", 0.0))
        if not found:
            return path
        add_shortcuts(g, path, found)
        assert_refines(g, self.original)
        into = {j: [j - 1] + [s.i for s in found if s.j == j] for j in range(1, len(path))}
        cost, arrivals, best = [0.0], [g.region(path[0])], {}
        for j in range(1, len(path)):
            options = []
            for i in into[j]:
                start = arrivals[i]
                result = UNREACHED if start is None else self._evaluate(start, path[j], (path[i], path[j]))
                options.append((cost[i] + self._weight(result.p), i, result))
            # a tie keeps the found path's leg (the larger i): 32 of 32 rollouts cannot tell a leg that loses 2 % from
            # one that loses none, and giving ties to the longer legs lost 0.207 of the Ant's episodes on U-chain 3
            # and 5 (docs/ant_experiments.md section 5, 'B with G, the tie fixed')
            c, i, result = min(options, key=lambda o: (o[0], -o[1]))
            cost.append(c)
            arrivals.append(start_of(result))
            best[j] = (i, result)
        chosen, j = [len(path) - 1], len(path) - 1
        while j:
            i, result = best[j]
            self.results[(path[i], path[j])] = result
            chosen.append(i)
            j = i
        new = [path[k] for k in reversed(chosen)]
        self._log("shortcut", added=[[path[s.i], path[s.j]] for s in found], path_before=path, path=new,
                  probabilities=[self.results[(a, b)].p for a, b in zip(new, new[1:])])
        return new

    def _trace(self, final) -> list[str] | None:
        if final is None:
            return None
        path = [final]
        while path[-1] != self.graph.initial:
            path.append(self.f.parent[path[-1]])
        return path[::-1]

    def _log(self, event: str, **detail) -> None:
        step = {"step": len(self.steps), "event": event, "open": sorted(self.f.open),
                "closed": list(self.f.closed), **detail}
        calls = getattr(self.proposer, "proposer_calls", None)
        if calls is not None:  # the proposer's calls so far: what each phase of the search cost can be read off
            step["proposer_calls"] = calls
        # and the evaluations and simulator steps so far (named apart from a step's own, e.g. a roadmap search's)
        step.update({f"{key}_so_far": count for key, count in evaluator_counts(self.evaluator).items()})
        self.steps.append(step)
        if self.on_step:
            self.on_step(step)


def evaluator_counts(evaluator) -> dict:
    """The evaluations and simulator steps so far, counted as result.json counts them (an earlier run's cached work in
    the same folder included, so a resumed run logs what a run in one go would); {} for an evaluator without
    counters."""
    if not hasattr(evaluator, "evaluations"):
        return {}
    return {"evaluations": int(getattr(evaluator, "run_evaluations", evaluator.evaluations)),
            "sim_steps": int(getattr(evaluator, "run_steps", evaluator.sim_steps))}


def shortest_path(graph: TaskGraph, evaluator: SubtaskEvaluator, seed: int = 0) -> SearchResult:
    """DiRL: no refinement, just the lazy shortest-path search over the input graph."""
    cfg = SearchConfig(edge_refinement=False, vertex_refinement=False, seed=seed)
    return RefinementSearch(graph, evaluator, config=cfg).run()
