"""Correcting the found path (beyond the paper: method ``ours-corrector``, docs/corrector.md).

Algorithm 3 judges each refinement once, on the search's own estimates, against a threshold tau: a leg estimated
at 32 of 32 on a lucky draw is trusted, and a leg at 31 of 32 costs less than tau, so no refinement of it can ever
be accepted although eight such legs lose a fifth of the episodes together. The correction looks at the path the
search found as a whole, on rollouts the search never saw:

1. every leg of the path is estimated again on ``rollouts`` fresh rollouts (a seed apart from the search's and the
   measurement's), each leg started from the end states of the previous leg's successes, as the search does;
2. the weakest leg not tried yet (the lowest fresh estimate below 1) is corrected: its proposer split (Algorithm 1
   on that leg, asked with the picture of its fresh failures; a split with a dead leg is repaired recursively),
   and, where the leg starts or ends at a waypoint of a split, the path without that waypoint (one leg instead of
   two: a shortcut edge of the same split);
3. each alternative path is estimated on the same fresh rollouts (the legs before the change are the same
   estimates), and the best replaces the path when its product of leg estimates is higher;
4. until no leg below 1 is left untried or the correction's budget of proposer splits is spent.

``lean`` (method ``ours-corrector-lean``): a leg must earn its place. An alternative is judged by the product of its
legs' posterior means (s + 1) / (n + 2) (uniform prior) instead of their raw frequencies, so that each leg costs
about one rollout's worth even at 128 of 128, and a split that replaces one leg failing once by three that never
fail on the same draw is no longer taken on that draw alone; it replaces the path when it scores higher. After the
weak legs, every inner waypoint of the path that one split put there is offered its bypass (one leg instead of
two, where the straight leg is clear and in reach), judged the same way: the correction's splits and a proposer's
close waypoints leave paths longer than they need be (27.9 legs against the oracle's 18.8 on U-chain 4-5,
docs/corrector.md), and each switch loses some episodes that 128 rollouts do not show.

``first_win`` (method ``ours-corrector-frugal``): the alternatives to a leg are asked for cheapest first, the bypass
(no proposer call), then the split, then the split over the next waypoint, and the first that wins is taken; a later
one is asked for only when none before it won. Without it every alternative is asked for and the best is taken.

``min_failures`` > 1 (method ``ours-corrector-gated``) asks the proposer about a leg only when at least that many of
its fresh rollouts failed: a leg losing a fraction of a per cent shows one failure in 128 about as often as a sound
one, and splitting it spends proposer calls on noise (docs/corrector.md, 'Where the corrector still loses'). Such a
leg is still offered the bypass, which asks nothing.

``advance`` (method ``ours-corrector-advance``): a dead path keeps the ground a reply won. Where the window's legs
never all succeed, no alternative can gain a rollout's worth there, so a reply whose first legs succeed and whose later
ones do not is thrown away, and the next query spans the whole dead leg again (with an erring proposer, the errors
grow with the turns a query spans). With ``advance`` the split of a dead leg a -> b is also offered cut after its live
legs: a -> x_1 -> ... -> x_k -> b, where x_1 .. x_k are the waypoints before its first never-succeeding leg. It
replaces the path when no alternative wins, the path's fresh check reaches x_k, and x_k lies nearer b than a does (the
straight distance between region centres: waypoints and rollouts only, no planner). The next query is then about
x_k -> b, a shorter span; ground won is never given back while the path is dead, and a path that succeeds at all is
judged as before. While the path is dead only its dead legs are tried: an alternative to a live leg is judged over a
window that holds the dead one, where nothing can win.

``reaim`` (method ``ours-corrector-reaim``): a weak leg is also offered, before any proposer call, the path with
the waypoint at either end of it aimed at another point of the same region: ``reaim(region)``, the point nearest the
region's centre among those as clear of walls as the region allows (``Evaluator.clearest``). A waypoint the proposer
centred near a corridor's wall leaves its leg hugging that wall; aimed at the corridor's middle line the leg keeps
clear of it, and the region, and so the task, stays the same. Judged like any alternative.

``crosscheck`` (method ``ours-corrector-crosscheck``): an alternative that wins on the check's draw replaces the path
only if it also beats it over the same window on a second draw of its own (new first states, the path checked there
too and kept up to date as the first): the best of several alternatives on one draw is the winner of that draw, and
where the differences are a rollout or two (the Ant's legs lose a fraction of a per cent each) the draw picks it as
much as the policy does. On the second draw a strictly higher score suffices (a tie keeps the path). It costs
evaluations, never a proposer call.

``roadmap_weak`` (method ``ours-corrector-mend``): a live leg below that fraction on the fresh check is offered one more
alternative, last: the roadmap's chain over the pooled waypoints and probes to the leg's end, built only on legs at
least that sound, so that the weak leg itself does not count as reaching its end. Without it the roadmap serves only
a dead leg of a dead path, and a live leg the proposer cannot mend stays as it is (docs/corrector.md, "Weak legs
mended on the roadmap").

``floor`` (``SearchConfig.roadmap_floor``; the rescue's changes of method ``ours-corrector-redraw-rescue-floor``): while
the path's fresh check is below ``floor``, a live leg is weak below ``floor ** (1 / legs)`` too, where that is above
``roadmap_weak``: on the Ant, thirteen legs at 0.92-1.00, each above mend's level, took a path to 0.75, and a deaf
proposer's splits could not mend them (docs/corrector.md, "Weak legs judged by the path"). The chain's own legs are
held to the same level (else the weak leg itself would count as reaching its end); it is judged as any alternative.

``roadmap_span`` (method ``ours-corrector-span``): such a weak leg is also offered, last, the roadmap's chain from its
start to each of the next ``span`` vertices past its end that lie on its split, skipping the waypoints between, on
legs as sound. A mend that enters the leg's end from another side changes where the next legs start, and a next leg
that grazed a corner (alive at a few tenths, or even whole) can die from there: the mend loses its window and the
weak leg stays. A chain past that waypoint judges the way on together (docs/corrector.md, "Weak legs mended past
their end").

``roadmap_bridge`` (method ``ours-corrector-bridge``): where mend's chain is offered, the weak leg is also offered,
last, the roadmap's chain from the leg before it to its end, on legs as sound, replacing the waypoint between them.
A leg that fails because of how it is entered (the body arrives at its start too fast, or aimed into the turn) fails
from every node near its start, so no chain from there is sound; a chain that starts one waypoint earlier can enter
the turn another way (docs/corrector.md, "Bridged from the leg before").

``backtrack`` (method ``ours-corrector-backtrack``): a dead leg of a dead path whose alternatives all lose is also
offered, last, the roadmap's chain from the start of its split (the path's start, or the last subgoal before it: a chain
never skips a subgoal) to the dead leg's end. Ground won while the path is dead is
never given back otherwise: where the waypoints nearest the goal lie in a pocket walled off from it (a proposer that
takes the wrong branch, or sees an opening that is not there), every later search starts in the pocket, and the
correction spends its budget there. The chain from the start, over everything pooled and with the start's remembered
tree, may go round (docs/corrector.md, "Ground given back").

``guard`` (method ``ours-corrector-guard``): a win on the window is kept only if the whole path, checked again from the
window on, scores no lower than before. The window is the changed legs and the one after them, but the legs further on
start from the new legs' end states: a split that wins its window can leave the next weak leg downstream worse, and
the path lower than it was (docs/corrector.md, "The point mass's default on Gymnasium-Robotics' maps").

Every alternative is a refinement of the same input edge (a longer or shorter chain of waypoints), so the refined
graph still implies the input graph (Theorem 4.1, checked like every refinement). What the correction sees is what
a real proposer's reply gives: waypoints, pictures and rollouts.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..core.graph import TaskGraph
from .common import Leg, LegEstimates, SubtaskEvaluator, estimate_legs, live_start, start_of
from .shortcut import Shortcut, add_shortcuts, shortcuts

CHECK_SEED_OFFSET = 104_729  # the correction's fresh rollouts: apart from the search's, polish's and the measurement's
CROSS_SEED_OFFSET = 32_452_843  # ``crosscheck``'s second draw: apart from the check's and each pass's
PASS_SEED_STEP = 15_485_863  # each further pass of the correction (SearchConfig.correct_passes) draws apart again


@dataclass
class Check(LegEstimates):
    """Fresh estimates of a path's legs: one EdgeResult per leg, each leg started from the previous one's successes."""

    path: list[str] = field(default_factory=list)


def path_legs(graph: TaskGraph, path: list[str]) -> list[Leg]:
    return [Leg(graph.region(b), graph.avoid(a, b), graph.goal_point(b)) for a, b in zip(path, path[1:])]


def check_path(graph: TaskGraph, path: list[str], evaluator: SubtaskEvaluator, *, rollouts: int, seed: int,
               start) -> Check:
    """The legs of ``path`` estimated on ``rollouts`` fresh rollouts each (seed ``seed``), from ``start`` (None:
    nothing reached path[0], every leg unreached)."""
    estimates = estimate_legs(evaluator, start, path_legs(graph, path), seed=seed, n=rollouts)
    return Check(results=estimates.results, path=list(path))


def posterior_mean(result) -> float:
    """(s + 1) / (n + 2): a leg's success under a uniform prior; 0 for a leg nothing reached."""
    return (result.successes + 1) / (result.n + 2) if result.n > 0 else 0.0


def lean_score(check: Check) -> float:
    """The product of the legs' posterior means: each leg costs about one rollout's worth at n of n."""
    return math.prod(posterior_mean(r) for r in check.results) if check.results else 0.0


def weakest_untried(check: Check, tried: set, dead_only: bool = False) -> int | None:
    """The leg with the lowest fresh estimate below 1 that has not been tried (the first of ties); ``dead_only``: only
    a leg that never succeeded."""
    legs = [i for i, p in enumerate(check.probabilities) if (p <= 0.0 if dead_only else p < 1.0)
            and _leg_key(check, i) not in tried]
    return min(legs, key=lambda i: (check.probabilities[i], i)) if legs else None


def weak_below(check: Check, weak: float, floor: float = 0.0) -> float:
    """The fresh success below which a live leg of ``check``'s path is weak: ``weak``, or, while the path's check is
    below ``floor``, ``floor ** (1 / legs)`` where that is higher (each leg's share of the floor)."""
    if floor and weak and 0.0 < check.p < floor and check.results:
        return max(weak, floor ** (1.0 / len(check.results)))
    return weak


def failures(result) -> int:
    """How many of a leg's rollouts failed."""
    return result.n - result.successes


def _leg_key(check: Check, i: int) -> tuple:
    return tuple(check.path[i:i + 2])


def bypasses(graph: TaskGraph, path: list[str], leg: int, reach: float, clearance: float) -> list[tuple[int, int]]:
    """(i, j) shortcuts over one waypoint at either end of ``leg`` (j = i + 2) that the shortcut rule allows."""
    allowed = {(s.i, s.j) for s in shortcuts(graph, path, reach, clearance) if s.j == s.i + 2}
    return [(i, i + 2) for i in (leg - 1, leg) if (i, i + 2) in allowed]


def reaims(graph: TaskGraph, path: list[str], leg: int, reaim: Callable) -> list[tuple[int, np.ndarray]]:
    """(k, point) for each inner waypoint path[k] at either end of ``leg`` whose ``reaim`` point is not where it
    aims already (its own point, else its region's centre)."""
    out = []
    for k in (leg, leg + 1):
        if 1 <= k <= len(path) - 2:
            region, own = graph.region(path[k]), graph.goal_point(path[k])
            point = np.asarray(reaim(region), dtype=float)
            if not np.allclose(point, region.centre() if own is None else own):
                out.append((k, point))
    return out


def reaimed(graph: TaskGraph, path: list[str], k: int, point) -> tuple[TaskGraph, list[str]]:
    """A copy of ``graph`` where path[k] has a twin of the same region aimed at ``point`` (the same edges in and out
    along the path), and the path through the twin."""
    alt = graph.copy()
    a, v, b = path[k - 1:k + 2]
    twin = alt.add_vertex(None, graph.region(v), point=point, refines=graph.refines(v), label=graph.label(v))
    alt.add_edge(a, twin, graph.avoid(a, v), parent=graph.parent(a, v))
    alt.add_edge(twin, b, graph.avoid(v, b), parent=graph.parent(v, b))
    return alt, path[:k] + [twin] + path[k + 1:]


def one_split(graph: TaskGraph, path: list[str], i: int) -> bool:
    """Whether path[i] -> path[i+1] -> path[i+2] are legs of one split (path[i+1] a waypoint between them)."""
    a, b, c = path[i:i + 3]
    return (graph.refines(b) is None and graph.parent(a, b) == graph.parent(b, c)
            and graph.avoid(a, b) == graph.avoid(b, c))


def bypassed(graph: TaskGraph, path: list[str], i: int, j: int) -> tuple[TaskGraph, list[str]]:
    """A copy of ``graph`` with the shortcut path[i] -> path[j], and the path through it."""
    alt = graph.copy()
    add_shortcuts(alt, path, [Shortcut(i, j)])
    return alt, path[:i + 1] + path[j:]


def spliced(graph: TaskGraph, path: list[str], i: int, j: int, waypoints) -> tuple[TaskGraph, list[str]]:
    """A copy of ``graph`` with path[i] -> path[j] split through ``waypoints`` (j = i + 2: over the waypoint
    path[i+1], through a shortcut edge of its split), and the path through them."""
    alt = graph.copy()
    if j > i + 1:
        add_shortcuts(alt, path, [Shortcut(i, j)])
    names = alt.split_edge(path[i], path[j], waypoints)
    return alt, path[:i + 1] + names + path[j:]


def correct(graph: TaskGraph, path: list[str], evaluator: SubtaskEvaluator, *, rollouts: int, seed: int,
            split_leg: Callable, may_split: Callable[[], bool], reach: float, clearance: float,
            log: Callable[..., None], min_failures: int = 1, lean: bool = False,
            first_win: bool = False, advance: bool = False,
            roadmap: Callable | None = None, reaim: Callable | None = None,
            crosscheck: bool = False, roadmap_weak: float = 0.0, floor: float = 0.0,
            guard: bool = False, bridge: bool = False, backtrack: bool = False, span: int = 0
            ) -> tuple[TaskGraph, list[str], Check]:
    """The corrected (graph, path) and its fresh check. ``split_leg(graph, a, b, result, start)`` -> the best
    split candidate of a -> b (repaired if it has a dead leg) or None; ``may_split()``: the budget allows one.

    An alternative is judged on the legs it changes and the leg after them (the window), from the same fresh start
    states as the current path's legs there; it replaces the path when it gains at least one rollout's worth
    (1 / rollouts) over the window (``lean``: when its posterior score there is higher), and the path's legs from
    the window on are then checked again. ``lean`` then offers every inner waypoint its bypass (module doc).
    ``first_win``: the alternatives are asked for and judged cheapest first; ``advance``: a dead leg's split cut
    after its live legs replaces the path where it gets nearer the leg's end, and while the path is dead only its dead
    legs are tried (module doc); ``roadmap(a, b, start)`` -> a ``roadmap.Chain`` over the run's pooled waypoints,
    offered first for a dead leg of a dead path (its live part as ``advance`` offers a reply's); ``reaim(region)`` ->
    the point a re-aimed waypoint of that region aims at; ``crosscheck``: a win is taken only if it also wins on a
    second draw (module doc); ``roadmap_weak``: a live leg whose fresh success is below it is offered the roadmap's
    chain to its end last, after the proposer's splits and whatever their budget left (``floor``: that level scaled
    to the path while its check is below ``floor``, ``weak_below``); ``guard``: a window's win is kept only if the
    path checked again from the window on scores no lower than before (module doc); ``bridge``: such a leg is also
    offered the chain from the leg before it; ``backtrack``: a dead leg of a dead path, the chain from the start of
    its split; ``span``: such a weak leg, the chains past its end (module doc). No chain skips a subgoal."""
    state = _State(graph, path, check_path(graph, path, evaluator, rollouts=rollouts, seed=seed,
                                           start=graph.region(path[0])), evaluator, rollouts, seed, lean, advance,
                   guard=guard)
    if crosscheck:
        state.second = check_path(graph, path, evaluator, rollouts=rollouts, seed=state.second_seed,
                                  start=graph.region(path[0]))
    log("correct-check", path=path, p=state.check.p, probabilities=state.check.probabilities,
        **({"p_second": state.second.p} if crosscheck else {}))
    tried: set = set()
    while (leg := weakest_untried(state.check, tried, dead_only=advance and state.check.p <= 0.0)) is not None:
        tried.add(_leg_key(state.check, leg))
        weak = weak_below(state.check, roadmap_weak, floor)
        groups = _alternatives(state, leg, evaluator, split_leg, may_split, reach, clearance, min_failures, roadmap,
                               reaim, weak, bridge, backtrack, span)
        if not first_win:
            groups = iter([[option for group in groups for option in group]])
        check, path, seen, accepted = state.check, state.path, [], None
        for group in groups:
            judged, accepted = state.judge(leg, group)
            seen += judged.tried
            if accepted is not None:
                break
        log("correct-leg", leg=leg, edge=path[leg:leg + 2], p_leg=check.probabilities[leg], p_window=judged.current,
            tried=seen, accepted=accepted, **({"weak_below": weak} if weak != roadmap_weak else {}))
    if lean:
        _prune(state, reach, clearance, log)
    log("correct-done", path=state.path, p=state.check.p, probabilities=state.check.probabilities,
        **({"p_second": state.second.p} if crosscheck else {}))
    return state.graph, state.path, state.check


def _alternatives(state: _State, leg: int, evaluator: SubtaskEvaluator, split_leg: Callable,
                  may_split: Callable[[], bool], reach: float, clearance: float, min_failures: int,
                  roadmap: Callable | None = None, reaim: Callable | None = None, roadmap_weak: float = 0.0,
                  bridge: bool = False, backtrack: bool = False, span: int = 0):
    """The alternatives to ``leg`` of the path, cheapest first, as groups of (kind, graph, path): its bypasses and,
    given ``reaim``, its waypoints re-aimed (no proposer call), then, for a dead leg of a dead path given ``roadmap``,
    the chain over the pooled waypoints (no proposer call), then its split, then its split over the next waypoint (one
    Algorithm 1 each), then, for a live leg below ``roadmap_weak``, the pooled waypoints' chain to its end (and given
    ``bridge``, from the leg before it; given ``span``, to each of the next ``span`` vertices of its split past its
    end); given ``backtrack``, for a dead leg of a dead path, the chain from the start of its split. Lazy: a split is
    asked for only when its group is reached."""
    graph, path, check = state.graph, state.path, state.check
    yield [("bypass", *bypassed(graph, path, i, j)) for i, j in bypasses(graph, path, leg, reach, clearance)]
    if reaim is not None:
        yield [("reaim", *reaimed(graph, path, k, point)) for k, point in reaims(graph, path, leg, reaim)]
    if roadmap is not None and check.p <= 0.0 and check.results[leg].p <= 0.0:
        yield _roadmap_options(state, leg, roadmap)
    yield from _splits(state, leg, evaluator, split_leg, may_split, min_failures)
    if backtrack and roadmap is not None and check.p <= 0.0 and check.results[leg].p <= 0.0 \
            and (back := leg - split_start(graph, path, leg)) > 0:
        yield _whole_chain(state, leg, roadmap, "backtrack", back=back)
    if roadmap is not None and check.p > 0.0 and 0.0 < check.results[leg].p < roadmap_weak:
        yield _whole_chain(state, leg, roadmap, "roadmap", sound=roadmap_weak)
        if bridge and leg > 0 and one_split(graph, path, leg - 1):  # it replaces a waypoint of the leg's split
            yield _whole_chain(state, leg, roadmap, "bridge", sound=roadmap_weak, back=1)
        for ahead in range(1, _span_ahead(graph, path, leg, span) + 1):
            yield _whole_chain(state, leg, roadmap, "span", sound=roadmap_weak, ahead=ahead)


def _splits(state: _State, leg: int, evaluator: SubtaskEvaluator, split_leg: Callable, may_split: Callable[[], bool],
            min_failures: int):
    """The proposer's alternatives to ``leg`` (``_alternatives``): its split, then its split over the next waypoint,
    while the budget allows; none for a leg with fewer than ``min_failures`` fresh failures."""
    graph, path, check = state.graph, state.path, state.check
    if failures(check.results[leg]) < min_failures:
        return
    spans = [(leg, leg + 1)] + ([(leg, leg + 2)] if leg + 2 < len(path) and one_split(graph, path, leg) else [])
    for i, j in spans:
        if not may_split():
            return
        leg_start = state.start_of_leg(i)
        if leg_start is None:  # no fresh rollout reaches the leg: nothing to start its split from
            return
        if j == i + 1:
            result = check.results[i]
        else:  # the span over a waypoint: how its straight edge does, for the proposer's picture
            goal = path_legs(graph, path[j - 1:j + 1])[0]
            result = evaluator.evaluate(leg_start, goal.goal, goal.avoid, goal_point=goal.goal_point,
                                        seed=state.seed, n=state.rollouts)
        fix = split_leg(*_with_edge(graph, path, i, j), path[i], path[j], result, leg_start)
        if fix is not None and fix.waypoints:
            options = [("split" if j == i + 1 else "resplit", *spliced(graph, path, i, j, fix.waypoints))]
            live = live_start(fix.probabilities)  # the legs alive before its first dead one
            if state.advance and check.results[leg].p <= 0.0 and 0 < live < len(fix.results):
                options.append(("advance", *spliced(graph, path, i, j, fix.waypoints[:live])))
            yield options


def _roadmap_options(state: _State, leg: int, roadmap: Callable, sound: float | None = None, back: int = 0,
                     ahead: int = 0) -> list:
    """The pooled waypoints' chain for ``leg`` (``sound``: on legs at least that sound only; ``back``: from the start
    of the leg that many before it, ``ahead``: to the end of the leg that many after it, replacing the waypoints
    between): the whole span ("roadmap") where it reaches its end, else its live part ("advance"); none where it
    reaches no waypoint."""
    graph, path, first, end = state.graph, state.path, leg - back, leg + 1 + ahead
    start = state.start_of_leg(first)
    if start is None:
        return []
    found = roadmap(*_with_edge(graph, path, first, end), path[first], path[end], start,
                    **({"sound": sound} if sound is not None else {}))
    if not found.waypoints:
        return []
    return [("roadmap" if found.reaches_goal else "advance", *spliced(graph, path, first, end, found.waypoints))]


def _whole_chain(state: _State, leg: int, roadmap: Callable, kind: str, sound: float | None = None,
                 back: int = 0, ahead: int = 0) -> list:
    """``_roadmap_options``' chain only where it reaches its end, as an option of ``kind``."""
    return [(kind, *option[1:]) for option in _roadmap_options(state, leg, roadmap, sound=sound, back=back,
                                                               ahead=ahead) if option[0] == "roadmap"]


def window_end(path: list[str], leg: int) -> int:
    """The index in ``path`` where the judge's window around ``leg`` ends: the leg, the one after it (a split over the
    next waypoint spans both) and the one after them."""
    return min(leg + 3, len(path) - 1)


def split_start(graph: TaskGraph, path: list[str], leg: int) -> int:
    """The index in ``path`` of the first vertex of ``leg``'s split: the vertices after it up to the leg's start are
    all waypoints of that split. A chain may replace the legs from there, never a subgoal or the task's own vertex."""
    i = leg
    while i > 0 and one_split(graph, path, i - 1):
        i -= 1
    return i


def _span_ahead(graph: TaskGraph, path: list[str], leg: int, span: int) -> int:
    """How many vertices past ``leg``'s end (at most ``span``) a chain from its start may end at: each skipped vertex a
    waypoint of the leg's split, and the end within the judge's window."""
    ahead = 0
    while ahead < span and leg + 2 + ahead <= window_end(path, leg) and one_split(graph, path, leg + ahead):
        ahead += 1
    return ahead


@dataclass
class Judged:
    current: float  # the window's score on the current path
    tried: list  # per alternative: its kind, window score and legs


@dataclass
class _State:
    """The path being corrected, its fresh check, and how alternatives to it are judged."""

    graph: TaskGraph
    path: list[str]
    check: Check
    evaluator: SubtaskEvaluator
    rollouts: int
    seed: int
    lean: bool
    advance: bool = False
    second: Check | None = None  # ``crosscheck``: the path's check on the second draw
    guard: bool = False  # a window's win kept only if the whole path, checked again, scores no lower

    @property
    def second_seed(self) -> int:
        return self.seed + CROSS_SEED_OFFSET

    def score(self, check: Check) -> float:
        return lean_score(check) if self.lean else check.p

    def start_of_leg(self, i: int, check: Check | None = None):
        """Where leg ``i`` of the path starts on the fresh check (or on ``check``): the first region, else the end
        states of the previous leg's successes (None where none succeeded)."""
        return self.graph.region(self.path[0]) if i == 0 else start_of((check or self.check).results[i - 1])

    def crosschecked(self, alt_graph: TaskGraph, alt_path: list[str], s: int, e: int) -> tuple[bool, float, float]:
        """Whether ``alt_path`` beats the path over the window path[s] .. path[e] on the second draw -> (it does,
        the path's score there, the alternative's)."""
        alt = check_path(alt_graph, alt_path[s:alt_path.index(self.path[e]) + 1], self.evaluator,
                         rollouts=self.rollouts, seed=self.second_seed, start=self.start_of_leg(s, self.second))
        current, score = self.score(Check(results=self.second.results[s:e])), self.score(alt)
        return score > current, current, score

    def judge(self, leg: int, options: list) -> tuple[Judged, str | None]:
        """Judge ``options`` (kind, graph, path) against the path over the window around ``leg``; the best replaces
        the path (and the path is checked again from the window on) when it wins. -> (what was judged, the kind
        accepted or None)."""
        graph, path, check = self.graph, self.path, self.check
        e = window_end(path, leg)  # the window: legs s .. e-1, path[s] to path[e], from where an option departs
        s = min([max(leg - 1, 0)] + [_kept(path, p) for _, _, p in options])
        start = self.start_of_leg(s)
        current = self.score(Check(results=check.results[s:e]))
        judged = [(kind, g, p, check_path(g, p[s:p.index(path[e]) + 1], self.evaluator, rollouts=self.rollouts,
                                          seed=self.seed, start=start)) for kind, g, p in options]
        best = max(judged, key=lambda o: self.score(o[3]), default=None)
        if self.lean:
            wins = best is not None and self.score(best[3]) > current
        else:
            wins = best is not None and best[3].p >= current + 1.0 / self.rollouts
        tried = [{"kind": kind, "p_window": self.score(c), "legs": len(p) - 1} for kind, _, p, c in judged]
        if not wins and self.advance and current <= 0.0:
            best, gains = _furthest(graph, path, leg, s, judged)
            wins = best is not None
            for entry, gain in zip(tried, gains):
                if gain is not None:
                    entry["nearer"] = gain
        if wins and self.second is not None and current > 0.0:  # a dead window's advance is judged by ground won
            wins, here, there = self.crosschecked(best[1], best[2], s, e)
            _entry(tried, judged, best).update(p_window_second=there, p_current_second=here)
        if wins:
            before = (self.graph, self.path, self.check, self.second)
            second_start = self.start_of_leg(s, self.second) if self.second is not None else None
            self.graph, self.path = best[1], best[2]
            self.check = self._checked_from(s, check, start, self.seed)
            if self.second is not None:
                self.second = self._checked_from(s, self.second, second_start, self.second_seed)
            if self.guard and self.score(self.check) < self.score(check):  # the path lost what its window won
                _entry(tried, judged, best).update(p_path=self.check.p, p_path_before=check.p, reverted=True)
                self.graph, self.path, self.check, self.second = before
                wins = False
        return Judged(current, tried), best[0] if wins else None

    def _checked_from(self, s: int, check: Check, start, seed: int) -> Check:
        """``check``'s legs before leg ``s``, and the (new) path's legs from there estimated again from ``start``."""
        rest = check_path(self.graph, self.path[s:], self.evaluator, rollouts=self.rollouts, seed=seed, start=start)
        return Check(results=check.results[:s] + rest.results, path=list(self.path))


def _kept(path: list[str], other: list[str]) -> int:
    """The last index up to which ``other`` follows ``path`` (0: only the start)."""
    return next((i - 1 for i, (a, b) in enumerate(zip(path, other)) if a != b), min(len(path), len(other)) - 1)


def _entry(tried: list[dict], judged: list, option) -> dict:
    """The steps-log entry of ``option``, one of ``judged`` (by identity: two options' checks may compare equal)."""
    return tried[next(i for i, o in enumerate(judged) if o is option)]


def _furthest(graph: TaskGraph, path: list[str], leg: int, s: int, judged: list) -> tuple[tuple | None, list]:
    """Of the ``advance`` and ``roadmap`` options judged on a dead window (``judged``: kind, graph, path, check from
    path[s]), the one whose fresh check reaches its last waypoint and which gets nearest the end of the span it
    replaces, if nearer than path[leg] is -> (that option or None, per option how much nearer it gets, None where it
    does not count)."""
    best, gains = None, []
    for option in judged:
        kind, alt, alt_path, alt_check = option
        gain = None
        if kind in ("advance", "roadmap"):
            end = next(k for k in range(leg + 1, len(alt_path)) if alt_path[k] in path)
            if live_start(alt_check.probabilities) >= end - 1 - s:  # every leg up to its last waypoint succeeds
                gain = _distance(graph, path[leg], alt_path[end]) - _distance(alt, alt_path[end - 1], alt_path[end])
        gains.append(gain)
        if gain is not None and gain > 0.0 and (best is None or gain > best[1]):
            best = (option, gain)
    return (best[0] if best else None), gains


def _distance(graph: TaskGraph, a: str, b: str) -> float:
    """The straight distance between the centres of two vertices' regions."""
    return float(np.linalg.norm(np.asarray(graph.region(a).centre()) - np.asarray(graph.region(b).centre())))


def _prune(state: _State, reach: float, clearance: float, log: Callable[..., None]) -> None:
    """Offer each inner waypoint of the path, first to last, its bypass (``lean``: module doc)."""
    m = 1
    while m < len(state.path) - 1:
        allowed = (m - 1, m + 1) in bypasses(state.graph, state.path, m - 1, reach, clearance)
        if not allowed:
            m += 1
            continue
        waypoint = state.path[m]
        judged, accepted = state.judge(m - 1, [("bypass", *bypassed(state.graph, state.path, m - 1, m + 1))])
        log("correct-prune", waypoint=waypoint, p_window=judged.current, tried=judged.tried, accepted=accepted)
        if accepted is None:
            m += 1


def _with_edge(graph: TaskGraph, path: list[str], i: int, j: int) -> tuple[TaskGraph]:
    """The graph the proposer is asked about: with the span's shortcut edge path[i] -> path[j] where j > i + 1."""
    if j == i + 1:
        return (graph,)
    alt = graph.copy()
    add_shortcuts(alt, path, [Shortcut(i, j)])
    return (alt,)
