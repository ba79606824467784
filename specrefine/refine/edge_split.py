"""Edge split refinement (Algorithm 1).

The proposer (a VLM, or an offline stand-in) is asked for w candidate paths replacing
the edge u -> v; each candidate is evaluated subtask by subtask.  In each of the d - 1
follow-up rounds the proposer sees every earlier candidate's per-subtask success and
rollouts, and the new candidates are tuned by the chain vertex refinement (Algorithm 2,
line 10 of Algorithm 1).  The best of the d x w candidates by product of success
probabilities is returned.  Rounds stop early once a candidate succeeded in every rollout:
no later candidate could be selected over it.

Controls (each removes one thing): ``feedback=False`` asks the later rounds afresh, without the earlier
candidates' results; ``tune=False`` evaluates the later rounds' candidates as proposed, without Algorithm 2.

Beyond the paper (``tune_check_seed``, method ``ours-tunecheck``): Algorithm 2 picks the best of many chains on
the same noisy estimates that then stand for it, so a tuned chain's estimate is the winner of a draw, not a measure.
Its tuned chain is therefore kept only if it beats the chain as proposed on fresh rollouts, both chains run from the
same start states on the same fresh seed (paired; a tie keeps the proposal), and the candidate carries the winner's
fresh estimates.

Beyond the paper (``confirm_seed``, method ``ours-confirm``): the same holds across candidates. A later round runs only
because the first round's best failed somewhere, and its pick is the best of several candidates on one draw each, so
the pick (tuned or as proposed) replaces the first round's best only if it beats it on fresh rollouts, paired as
above (a tie keeps the first round's), and carries the winner's fresh estimates.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..core.paper import PAPER
from ..core.regions import Region
from .common import Leg, SubtaskEvaluator, estimate_legs
from .vertex import refine_chain

log = logging.getLogger(__name__)


@dataclass
class SplitCandidate:
    waypoints: list[Region]  # intermediate vertices x_1 .. x_{k-1}
    results: list  # EdgeResults of the k subtasks
    round: int
    tuned: bool = False  # went through the chain vertex refinement
    repaired: int = 0  # legs split once more by the look-ahead repair (repair.py; method ours-repair)
    check: tuple[float, float] | None = None  # (proposed, tuned) on fresh rollouts, when the tuning was checked

    @property
    def probabilities(self) -> list[float]:
        return [r.p for r in self.results]

    @property
    def p(self) -> float:
        return float(np.prod(self.probabilities)) if self.results else 0.0


@dataclass
class SplitOutcome:
    best: SplitCandidate | None
    candidates: list[SplitCandidate] = field(default_factory=list)
    evaluations: int = 0
    confirm: tuple[float, float] | None = None  # (first round's best, later pick) on fresh rollouts, when confirmed


def split_legs(waypoints, goal, avoid, goal_point=None) -> list[Leg]:
    """The subtasks of a split u -> x_1 -> ... -> v: one leg per waypoint, then the edge's own goal."""
    return [Leg(x, avoid) for x in waypoints] + [Leg(goal, avoid, goal_point)]


def edge_split(evaluator: SubtaskEvaluator, proposer, query, *, start, goal_point=None, w: int = PAPER.w,
               d: int = PAPER.d, k: int = PAPER.k, rng: np.random.Generator, picture: Callable | None = None,
               racing=None, feedback: bool = True, tune: bool = True, tune_check_seed: int | None = None,
               confirm_seed: int | None = None) -> SplitOutcome:
    """Algorithm 1 for the edge described by ``query`` (an EdgeQuery), started from ``start``. ``tune_check_seed``:
    a tuned chain is checked against its proposal on fresh rollouts of this seed; ``confirm_seed``: a later round's
    pick against the first round's best (None: the paper, unchecked)."""
    from ..proposers import CandidateFeedback

    outcome = SplitOutcome(best=None)
    avoid, goal = query.avoid, query.goal
    for round_ in range(d):
        if outcome.candidates and max(c.p for c in outcome.candidates) >= 1.0:
            break  # nothing can beat a candidate that never failed (max keeps the first of ties anyway)
        if round_ and feedback:
            seen = [CandidateFeedback(waypoints=c.waypoints, subtask_success=c.probabilities,
                                      image_png=picture(c) if picture else None) for c in outcome.candidates]
            proposals = proposer.propose_split(query, w, seen)
        else:
            proposals = proposer.propose_split(query, w)
        if not proposals:
            log.info("edge split round %d: the proposer returned no valid candidate", round_ + 1)
        for waypoints in (p for p in proposals if p):
            if round_ == 0 or not tune:
                legs = split_legs(waypoints, goal, avoid, goal_point)
                path = estimate_legs(evaluator, start, legs)
                outcome.evaluations += len(legs)
                candidate = SplitCandidate(list(waypoints), path.results, round_)
            else:
                # adaptive: a candidate is only chosen if it beats the best so far, so nothing below it is explored
                floor = max((c.p for c in outcome.candidates), default=0.0) if racing is not None else 0.0
                choice = refine_chain(evaluator, start, list(waypoints), goal, [avoid] * (len(waypoints) + 1),
                                      k, rng, goal_point, racing=racing, floor=floor)
                outcome.evaluations += choice.evaluations
                candidate = SplitCandidate(choice.regions, choice.results, round_, tuned=True)
                if tune_check_seed is not None and choice.regions != list(waypoints):
                    candidate = checked_tuning(evaluator, start, list(waypoints), candidate, goal, avoid, goal_point,
                                               seed=tune_check_seed)
                    outcome.evaluations += 2 * len(candidate.results)
            outcome.candidates.append(candidate)
    if outcome.candidates:
        outcome.best = max(outcome.candidates, key=lambda c: c.p)
        if confirm_seed is not None and outcome.best.round > 0:
            confirm_pick(evaluator, start, outcome, goal, avoid, goal_point, seed=confirm_seed)
    return outcome


def duel(evaluator: SubtaskEvaluator, start, incumbent: list[Region], challenger: list[Region], goal, avoid,
         goal_point, *, seed: int):
    """Both chains' legs estimated on the same fresh rollouts (seed ``seed``, from the same start states)."""
    return [estimate_legs(evaluator, start, split_legs(ws, goal, avoid, goal_point), seed=seed)
            for ws in (incumbent, challenger)]


def confirm_pick(evaluator: SubtaskEvaluator, start, outcome: SplitOutcome, goal, avoid, goal_point, *,
                 seed: int) -> None:
    """``outcome.best`` (a later round's) against the first round's best on the same fresh rollouts: the winner,
    with its fresh estimates, becomes ``outcome.best`` (a tie keeps the first round's). Nothing to confirm against
    when the first round had no candidate that ever succeeded."""
    first = max((c for c in outcome.candidates if c.round == 0), key=lambda c: c.p, default=None)
    if first is None or first.p <= 0.0:
        return
    later = outcome.best
    fresh = duel(evaluator, start, first.waypoints, later.waypoints, goal, avoid, goal_point, seed=seed)
    outcome.evaluations += len(first.results) + len(later.results)
    outcome.confirm = (fresh[0].p, fresh[1].p)
    won = later if fresh[1].p > fresh[0].p else first
    outcome.best = SplitCandidate(won.waypoints, fresh[won is later].results, won.round, tuned=won.tuned,
                                  check=won.check)


def checked_tuning(evaluator: SubtaskEvaluator, start, proposed: list[Region], tuned: SplitCandidate, goal, avoid,
                   goal_point, *, seed: int) -> SplitCandidate:
    """The tuned chain if it beats ``proposed`` on the same fresh rollouts (seed ``seed``), else the proposal; either
    way with the winner's fresh estimates."""
    fresh = duel(evaluator, start, proposed, tuned.waypoints, goal, avoid, goal_point, seed=seed)
    won = fresh[1].p > fresh[0].p
    return SplitCandidate(tuned.waypoints if won else proposed, fresh[won].results, tuned.round, tuned=won,
                          check=(fresh[0].p, fresh[1].p))
