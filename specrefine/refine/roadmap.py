"""Every reply's waypoints pooled into a roadmap (beyond the paper: method ``ours-corrector-roadmap``).

With a proposer that errs on long spans (dropped turns, wrong branches, errors that grow with the turns a query
spans), no one reply to a dead leg may be right, while its waypoints, taken together, lie along the way: a reply
that skips a turn still names regions in the corridors before and after it. The correction of a dead path
otherwise judges each reply alone and throws the rest away (docs/corrector.md, "Replies pooled into a roadmap").

The roadmap keeps every waypoint any reply of the run proposed (one per place: a waypoint within ``merge`` of one
kept already adds nothing). For a dead leg a -> b it searches a chain a -> x_1 -> ... -> x_k -> b over those
waypoints, best first by straight distance to b: the rollouts that reached a node start its legs, a leg is tried
only between nodes at most ``reach`` apart (the policy's goal range), a leg that never succeeded is remembered and
not tried again, and the search stops at b or after ``evaluations`` subtask evaluations. What it uses is what a
real reply gives: the waypoints and rollouts, no planner and no map. The chain is a refinement of a -> b like any
split (Theorem 4.1 holds), and the correction judges it on its fresh rollouts like any other alternative; where it
does not reach b, its live part is offered as ``advance`` offers a reply's live legs.

``sound`` (method ``ours-corrector-sound``): a leg is built on only where at least that fraction of its rollouts
succeed; a weaker one is remembered as a dead one is. Without it one success in 128 makes a node reached, and a
chain can start with a leg that succeeds on 2 % of its rollouts: every later leg then starts from those few states,
the path is no longer dead, and the larger budget for a dead path stops with the path alive at a few per cent
(docs/corrector.md, "Sound legs for the roadmap").

``remember`` (method ``ours-corrector-memory``): a search keeps the nodes it reached from its origin (their start
states and the node before) for the next search from the same origin, which starts from them and spends its
evaluations on legs not tried yet. Without it only dead legs are remembered, and where the way to the goal first leads
away from it every search from that origin spends its evaluations re-reaching what the one before reached
(docs/corrector.md, "A roadmap that remembers").

``explore`` (method ``ours-corrector-explore``): where a search has tried every leg within reach of what it reached
and has evaluations left, it adds waypoints of its own, ``explore`` x ``reach`` from each node reached in eight
directions, and goes on; the rollouts judge them as any other leg (one in a wall never succeeds and is remembered
dead). Without it the roadmap holds only what the replies named, and where no reply names the way (a detour away
from the goal that every reply skips), no search can find it (docs/corrector.md, "A roadmap that explores").

``probe`` (method ``ours-corrector-probe``): the same, one node at a time and kept to it: where a search runs out of
legs, the node reached nearest the goal that has not been probed gets eight waypoints ``probe`` x ``reach`` out, tried
from that node only, and the search goes on. Exploring every node at once adds legs from every node within reach of
every new waypoint, and each search then spends its evaluations on dead ones (docs/corrector.md, "Probes from the
nearest node").

``rings`` (method ``ours-corrector-fine``): where every node reached has had its probes and the search still has
evaluations, each node, nearest the goal first, gets another ring at half the radius, turned by an eighth of a
turn, up to ``rings`` rings per node. One ring of eight at half the policy's reach steps over a turn in a corridor
narrower than the ring's spacing (a point past the corner lies in the wall beside it), so a search in a maze of 1 m
corridors can spend its probes and stop with evaluations left and the way on untried (docs/corrector.md, "Finer
probes"). Until a search has spent every node's first ring nothing changes.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass, field

import numpy as np

from ..core.regions import Disc, Region
from .common import SubtaskEvaluator, evaluate_all, start_of


@dataclass
class Chain:
    """A chain of pooled waypoints from a leg's start: its regions, whether it ends in the leg's goal, its
    evaluations, how many nodes its search started from that the searches before it had reached, and how many waypoints
    it added of its own (``explore``)."""

    waypoints: list[Region]
    reaches_goal: bool
    evaluations: int
    remembered: int = 0
    explored: int = 0  # waypoints the search added of its own


@dataclass
class Roadmap:
    reach: float  # the longest leg tried (straight distance between region centres)
    merge: float = 0.25  # a waypoint this near one kept already adds nothing
    evaluations: int = 120  # subtask evaluations per search at most
    sound: float = 0.0  # a leg is built on only where at least this fraction of its rollouts succeed (0: any success)
    remember: bool = False  # a search starts from the nodes the searches before it reached from the same origin
    explore: float = 0.0  # where a search runs out of legs to try: waypoints this x reach from each node (0: none)
    probe: float = 0.0  # where a search runs out of legs: eight waypoints this x reach from one node, its own (0: none)
    rings: int = 1  # probe rings per node at most, each at half the radius of the one before and turned by pi / 8
    explore_radius: float = 0.3  # the radius of a waypoint the search adds
    points: list[Region] = field(default_factory=list)
    dead: set = field(default_factory=set)  # (from, to) centres of legs that never succeeded (or were not sound)
    trees: dict = field(default_factory=dict)  # origin centre -> {pooled node: (start states, node before)}
    explored: set = field(default_factory=set)  # centres whose eight directions were added
    probes: dict = field(default_factory=dict)  # a probe's index in points -> the centre of the node it is tried from
    _centres: np.ndarray = field(default_factory=lambda: np.empty((0, 2)), init=False, repr=False, compare=False)

    def add(self, regions) -> None:
        """Pool ``regions`` (a reply's waypoints)."""
        for region in regions:
            centre = np.asarray(region.centre(), dtype=float)
            if all(np.linalg.norm(centre - np.asarray(self.points[i].centre())) > self.merge
                   for i in self._near(centre, self._pooled(), self.merge)):
                self.points.append(region)

    def _pooled(self) -> np.ndarray:
        """The pooled waypoints' centres, (n, 2), kept as the points grow (only ``add`` appends to them)."""
        have = len(self._centres)
        if have > len(self.points):  # points replaced from outside: start again
            self._centres, have = np.empty((0, 2)), 0
        if have < len(self.points):
            new = np.asarray([p.centre() for p in self.points[have:]], dtype=float).reshape(-1, 2)
            self._centres = np.vstack([self._centres, new])
        return self._centres

    @staticmethod
    def _near(here, centres: np.ndarray, radius: float, order=None) -> np.ndarray:
        """The indices (in ``order``, default ascending) of ``centres`` within about ``radius`` of ``here``: a
        superset, by a vectorised distance with a margin, of those the per-node test that follows keeps, so that
        testing only these gives the same answer as testing every node (the many waypoints of a run of the random
        proposer made the per-node scan most of a run's time)."""
        order = np.arange(len(centres)) if order is None else order
        close = np.linalg.norm(centres - np.asarray(here, dtype=float), axis=1) <= radius + 1e-9
        return order[close[order]]

    def chain(self, evaluator: SubtaskEvaluator, start, origin: Region, goal: Region, avoid: Region,
              goal_point=None, sound: float | None = None) -> Chain:
        """The best-first chain from ``start`` (the start states of the leg from ``origin``) toward ``goal`` over
        the pooled waypoints: to ``goal`` if found, else to the node reached nearest ``goal`` (none: no waypoints).
        ``sound``: this search builds only on legs at least that fraction of whose rollouts succeed (a weak leg's
        mend: the leg itself must not count as reaching); a leg below it but not below the roadmap's own ``sound`` is
        not remembered as dead, and the search neither starts from nor keeps a remembered tree."""
        first = np.asarray(origin.centre(), dtype=float)
        floor, own_floor = max(self.sound, sound or 0.0), sound is None
        reached: dict[int, tuple] = {-1: (start, None)}  # node -> (its start states, the node before it)
        if self.remember and own_floor:
            reached.update(self.trees.get(self._key(first, first), {}))
        nodes, centres, to_goal = self._nodes(goal)
        queue, remembered, added = self._queue(first, reached, centres, to_goal), len(reached) - 1, 0
        used, best = 0, min((v for v in reached if v >= 0), key=lambda v: to_goal[v], default=-1)
        while used < self.evaluations:
            if not queue:  # every leg within reach of what was reached is tried
                more = (self._explore(first, reached, centres) if self.explore > 0 else
                        self._probe(first, reached, centres, to_goal) if self.probe > 0 else 0)
                if not more:
                    break
                added += more
                nodes, centres, to_goal = self._nodes(goal)
                queue = self._queue(first, reached, centres, to_goal)
            _, u = heapq.heappop(queue)
            here = first if u < 0 else centres[u]
            near = self._untried(here, centres, to_goal, exclude={u, *reached})[:self.evaluations - used]
            if not near:
                continue
            results = evaluate_all(evaluator, [(reached[u][0], nodes[v], avoid, goal_point if v == len(nodes) - 1
                                                else None) for v in near])
            used += len(near)
            for v, result in zip(near, results):
                if result.successes == 0 or result.p < self.sound:
                    self.dead.add(self._key(here, centres[v]))
                if result.successes == 0 or result.p < floor:
                    continue
                reached[v] = (start_of(result), u)
                heapq.heappush(queue, (float(to_goal[v]), v))
                if to_goal[v] < (to_goal[best] if best >= 0 else np.inf):
                    best = v
            if len(nodes) - 1 in reached:
                best = len(nodes) - 1
                break
        if self.remember and own_floor:
            self.trees[self._key(first, first)] = {v: r for v, r in reached.items() if 0 <= v < len(self.points)}
        order = []
        while best >= 0:
            order.append(best)
            best = reached[best][1]
        regions = [nodes[v] for v in reversed(order)]
        reaches = bool(regions) and order[0] == len(nodes) - 1
        return Chain(regions[:-1] if reaches else regions, reaches, used, remembered, added)

    def _nodes(self, goal: Region) -> tuple[list, np.ndarray, np.ndarray]:
        """The search's nodes (the pooled waypoints, then ``goal``), their centres and straight distances to it."""
        nodes = [*self.points, goal]
        centres = np.asarray([r.centre() for r in nodes], dtype=float)
        return nodes, centres, np.linalg.norm(centres - centres[-1], axis=1)

    @staticmethod
    def _to_goal(first, centres, to_goal, v: int) -> float:
        """Node ``v``'s straight distance to the goal (``centres[-1]``); the origin's (``first``) for v < 0."""
        return float(np.linalg.norm(first - centres[-1])) if v < 0 else float(to_goal[v])

    def _queue(self, first, reached: dict, centres, to_goal) -> list:
        """The search's frontier: the origin and every node reached, nearest the goal first."""
        queue = [(self._to_goal(first, centres, to_goal, v), v) for v in reached]
        heapq.heapify(queue)
        return queue

    def _ring(self, here, step: float, ring: int = 0) -> range:
        """Eight waypoints ``step`` from ``here``, turned by ``ring`` x pi / 8, pooled, unless ``here`` had that
        ring already; their indices in points (those not merged into one kept already)."""
        before, key = len(self.points), self._key(here, here) + ((ring,) if ring else ())
        if key not in self.explored:
            self.explored.add(key)
            self.add(Disc(float(here[0] + step * np.cos(a)), float(here[1] + step * np.sin(a)), self.explore_radius)
                     for a in (np.arange(8) * 2 + ring) * np.pi / 8)
        return range(before, len(self.points))

    def _explore(self, first, reached: dict, centres) -> int:
        """Waypoints ``explore`` x ``reach`` from each node reached not explored yet, in eight directions, pooled;
        how many were new."""
        return sum(len(self._ring(first if v < 0 else centres[v], self.explore * self.reach)) for v in reached)

    def _probe(self, first, reached: dict, centres, to_goal) -> int:
        """Eight waypoints ``probe`` x ``reach`` out from the node reached nearest the goal not probed yet, pooled as
        that node's own; where every node reached has that ring, the next ring (``rings``); how many were new (0:
        every node reached has all its rings)."""
        nearest_first = sorted(reached, key=lambda v: self._to_goal(first, centres, to_goal, v))
        for ring in range(self.rings):
            for v in nearest_first:
                here = first if v < 0 else centres[v]
                new = self._ring(here, self.probe * self.reach / 2 ** ring, ring)
                self.probes |= dict.fromkeys(new, self._key(here, here))
                if new:
                    return len(new)
        return 0

    def _untried(self, here, centres, to_goal, exclude: set) -> list[int]:
        """The nodes within reach of ``here``, nearest the goal first, but those in ``exclude``, the dead legs and
        the probes of other nodes."""
        own = self._key(here, here)
        return [v for v in self._near(here, centres, self.reach, np.argsort(to_goal)) if v not in exclude
                and np.linalg.norm(centres[v] - here) <= self.reach and self._key(here, centres[v]) not in self.dead
                and self.probes.get(v, own) == own]

    @staticmethod
    def _key(a, b) -> tuple:
        return tuple(np.round(np.concatenate([a, b]), 3))
