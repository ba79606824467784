"""Every refinement method in one registry: its search, whether it asks a proposer, what it is, its colour.

:data:`METHODS` maps a method's name to its :class:`Method`; ``specrefine refine --method``, the sweep's
``--methods``, the pipeline's dispatch (:func:`run_search`) and the figures' colours all read it.  A new method is
its module (a function ``search(job: SearchJob) -> SearchResult``) and one :func:`register_method` call; a
variant of ours is one entry with :func:`ours_variant` (what it changes in ``SearchConfig``). A registration is
checked when it is made (a safe name, a built-in not replaced unless ``replace=True``, a function to search with,
``ours_variant``'s fields), so a mistake is one line there, never a traceback after a run has started. Plugins
(:mod:`specrefine.core.plugins`) register through the same call before the command line is built.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from ..core.agents import get_agent
from ..core.errors import SpecrefineError
from ..core.names import check_callable, check_registration
from .queries import candidate_picture, edge_query_builder

if TYPE_CHECKING:  # an annotation only: runs.config reads the registry for its choices
    from .config import RunConfig

KNOBS = ("w", "d", "k")  # the search settings of RunConfig a method may read


@dataclass(frozen=True)
class SearchJob:
    """What a method's search gets: the run's configuration and the task it refines."""

    config: RunConfig  # resolved: evaluation is "fixed" or "adaptive"
    graph: object  # the original task graph (TaskGraph)
    evaluator: object  # SubtaskEvaluator
    proposer: object | None  # a Proposer, for methods that ask one
    maze: object  # the Maze at the agent's scale
    on_step: Callable[[dict], None] | None = None  # each search step, as it happens (steps.jsonl)


@dataclass(frozen=True)
class Method:
    name: str
    search: Callable[[SearchJob], object]  # -> refine.SearchResult
    description: str  # one line for --help
    asks_proposer: bool = True
    colour: str = "#757575"  # in the figures
    knobs: tuple[str, ...] = KNOBS  # which of w, d, k its search reads (a sweep varies only those)


METHODS: dict[str, Method] = {}
BUILT_IN: frozenset[str] = frozenset()  # set below, once the package's own methods are registered


def register_method(name: str, search: Callable[[SearchJob], object], description: str, *,
                    asks_proposer: bool = True, colour: str = "#757575", knobs: tuple[str, ...] = KNOBS,
                    replace: bool = False) -> Method:
    """Make ``name`` a method everywhere (``--method``, the sweep, the figures). A built-in method is replaced only
    with ``replace=True``; a bad name, search or knob is a one-line :class:`SpecrefineError`."""
    check_registration("method", name, METHODS, BUILT_IN, replace)
    check_callable("method", name, "search", search)
    unknown = set(knobs) - set(KNOBS)
    if isinstance(knobs, str) or unknown:
        raise SpecrefineError(f"method {name!r}: knobs must be a tuple of {', '.join(KNOBS)}, got {knobs!r}")
    method = Method(name, search, str(description), bool(asks_proposer), colour, tuple(knobs))
    METHODS[name] = method
    return method


def get_method(name: str) -> Method:
    try:
        return METHODS[name]
    except KeyError:
        raise SpecrefineError(f"unknown method {name!r}: use one of {', '.join(METHODS)}") from None


class _View(Mapping):
    """A live read-only view of the registry: name -> ``get(method)`` for the methods ``keep`` accepts."""

    def __init__(self, get, keep=lambda m: True):
        self._get, self._keep = get, keep

    def __getitem__(self, name):
        method = METHODS.get(name)
        if method is None or not self._keep(method):
            raise KeyError(name)
        return self._get(method)

    def __iter__(self):
        return (name for name, m in METHODS.items() if self._keep(m))

    def __len__(self):
        return sum(1 for _ in self)


#: the methods that ask a proposer (``method in PROPOSER_METHODS``; iterating gives their names)
PROPOSER_METHODS = _View(lambda m: m.description, keep=lambda m: m.asks_proposer)
METHOD_COLOURS = _View(lambda m: m.colour)


def run_search(config: RunConfig, graph, evaluator, proposer, maze, on_step=None):
    """The search of ``config.method`` on ``graph`` -> ``SearchResult``."""
    method = get_method(config.method)
    return method.search(SearchJob(config.resolved(), graph, evaluator, proposer, maze, on_step))


# --- the built-in methods ------------------------------------------------------------------------
def dirl(job: SearchJob):
    from ..refine import shortest_path

    return shortest_path(job.graph, job.evaluator, seed=job.config.seed)


def symbolic(job: SearchJob):
    from ..refine import RefinementSearch, SearchConfig

    cfg = SearchConfig.from_run(job.config, edge_refinement=False)
    return RefinementSearch(job.graph, job.evaluator, config=cfg, on_step=job.on_step).run()


def ours_variant(**changes) -> Callable[[SearchJob], object]:
    """Algorithm 3 with ``changes`` to its SearchConfig (``shortcut_reach="policy"``: the agent's goal range); a
    field SearchConfig lacks is a one-line :class:`SpecrefineError` here, when the variant is made."""
    from ..refine.search import check_changes

    check_changes(changes)
    check_changes(changes.get("rescue") or {})

    def search(job: SearchJob):
        from ..refine import RefinementSearch, SearchConfig

        c, variant = job.config, _policy_reach(changes, get_agent(job.config.agent).reach_task.goal_max)
        cfg = SearchConfig.from_run(c, **variant)
        images = getattr(job.proposer, "sees_images", True)  # offline proposers: no picture is drawn (seconds per run)
        query_for = edge_query_builder(job.maze, c.agent, job.evaluator.facts(), images=images)
        return RefinementSearch(job.graph, job.evaluator, proposer=job.proposer, config=cfg, on_step=job.on_step,
                                query_for=query_for, picture=candidate_picture(job.maze) if images else None).run()

    return search


def _policy_reach(changes: dict, reach: float) -> dict:
    """``changes`` with each reach given as "policy" (here and in a rescue's changes) set to ``reach``: as far as
    the policy was trained to reach a goal."""
    out = {k: reach if k in ("shortcut_reach", "correct_reach") and v == "policy" else v for k, v in changes.items()}
    if out.get("rescue"):
        out["rescue"] = _policy_reach(out["rescue"], reach)
    return out


def vlm_oneshot(job: SearchJob, budget: tuple[int, int] | None = None):
    from ..refine.oneshot import oneshot

    c = job.config
    return oneshot(job.graph, job.evaluator, job.proposer, maze=job.maze, agent=c.agent, w=c.w, rounds=c.d,
                   seed=c.seed, on_step=job.on_step, budget=budget)


def vlm_oneshot_matched(job: SearchJob):
    return vlm_oneshot(job, budget=budget_of_ours(job))


def budget_of_ours(job: SearchJob) -> tuple[int, int]:
    """(proposer calls, subtask evaluations) that ``ours`` spends on this task and seed (run here, on its own cache)."""
    from ..proposers import make_proposer

    evaluator = job.evaluator
    cache = evaluator.cache_dir.parent / "budget_cache" if evaluator.cache_dir is not None else None
    twin = evaluator.fresh_copy(cache_dir=cache)
    proposer = make_proposer(job.proposer.spec, seed=job.config.seed)
    METHODS["ours"].search(replace(job, evaluator=twin, proposer=proposer, on_step=None))
    return proposer.proposer_calls, twin.run_evaluations


# the paper's Sec. 5.1, plus controls (every control removes one thing from ours) and what goes beyond the paper
register_method("ours", ours_variant(), "Alg. 3: Dijkstra-order search with proposer edge splits and vertex subsets",
                colour="#1565c0")
register_method("ours-novertex", ours_variant(vertex_refinement=False, split_tuning=False),
                "control: ours without vertex refinement anywhere (neither the search's vertex subsets nor "
                "Algorithm 2 inside an edge split)", colour="#64b5f6")
register_method("ours-nosearchvertex", ours_variant(vertex_refinement=False),
                "control: ours without the search's own vertex subsets (an edge split still tunes its later "
                "candidates with Algorithm 2)", colour="#90caf9")
register_method("ours-notune", ours_variant(split_tuning=False),
                "control: ours with an edge split's later candidates evaluated as proposed (no Algorithm 2 inside "
                "the split, Alg. 1 line 10)", colour="#4db6ac")
register_method("ours-nofeedback", ours_variant(split_feedback=False),
                "control: ours with an edge split's later round asked afresh, without the earlier candidates' "
                "results", colour="#80cbc4")
register_method("ours-d1", ours_variant(d=1),
                "the paper's d = 1: no later round in an edge split (its samples, feedback and tuning)",
                colour="#00897b", knobs=("w", "k"))
register_method("ours-tunecheck", ours_variant(tuning_check=True),
                "Algorithm 3 where a split's tuned chain (Alg. 1 line 10) is kept only if it beats the chain as "
                "proposed on the same fresh rollouts (refine/edge_split.py)", colour="#5d4037")
register_method("ours-confirm", ours_variant(confirm_pick=True),
                "Algorithm 3 where a split's pick from a later round (tuned or as proposed) is kept only if it beats "
                "the first round's best on the same fresh rollouts (refine/edge_split.py)", colour="#795548")
register_method("ours-repair", ours_variant(repair=True),
                "beyond the paper: ours, and when no split candidate succeeds end to end, its failing legs are split "
                "once more before it is judged (refine/repair.py)", colour="#6a1b9a")
register_method("ours-repair-tuned", ours_variant(repair=True, repair_tuning=True),
                "beyond the paper: ours-repair, and a repaired chain is tuned by Algorithm 2 (vertex subsets) before "
                "it is judged", colour="#ab47bc")
register_method("ours-polish", ours_variant(polish_rollouts=128),
                "beyond the paper: ours, then the found path's legs estimated again on 128 rollouts and its weak "
                "waypoints tuned by Algorithm 2 on those estimates (refine/polish.py)", colour="#00838f")
register_method("ours-shortcut", ours_variant(shortcut_reach="policy"),
                "beyond the paper: ours, then shortcut edges over the found path's waypoints (one long leg where it "
                "beats several short ones; refine/shortcut.py)", colour="#283593")
#: ours-corrector's settings; each variant of it changes one or two of them
CORRECTOR = dict(repair=True, repair_depth=3, dead_weight=100.0, correct_rollouts=4, correct_reach="policy")
register_method("ours-corrector", ours_variant(**CORRECTOR),
                "beyond the paper: ours with repair to three levels and any feasible chain preferred to a dead "
                "edge, then the found path's legs estimated again on 4x fresh rollouts and its weak legs split, "
                "split over or bypassed while the path gains (refine/correct.py)",
                colour="#c62828")
register_method("ours-corrector-gated", ours_variant(**CORRECTOR | dict(correct_min_failures=3)),
                "beyond the paper: ours-corrector asking the proposer about a leg of the found path only when at "
                "least 3 of its 4n fresh rollouts failed (a leg with fewer is only bypassed)", colour="#7f0000")
register_method("ours-corrector-lean", ours_variant(**CORRECTOR | dict(correct_lean=True)),
                "beyond the paper: ours-corrector whose legs must earn their place: alternatives judged by the "
                "product of the legs' posterior means, and every waypoint of the corrected path offered its bypass",
                colour="#ff7043")
register_method("ours-corrector-precise", ours_variant(**CORRECTOR | dict(correct_rollouts=16,
                                                                          correct_min_failures=3)),
                "beyond the paper: ours-corrector-gated with the found path checked on 16n fresh rollouts per leg "
                "instead of 4n, so that the gate (3 fresh failures) finds legs losing about 1 % and their "
                "alternatives are judged on four times the rollouts", colour="#4e342e")
register_method("ours-corrector-trim", ours_variant(**CORRECTOR | dict(correct_rollouts=16, correct_min_failures=3,
                                                                       correct_lean=True)),
                "beyond the paper: ours-corrector-precise judging the correction by the legs' posterior means and "
                "offering every waypoint of the corrected path its bypass (ours-corrector-lean's rule on the "
                "512-rollout check)", colour="#3e2723")
register_method("ours-corrector-recheck", ours_variant(**CORRECTOR | dict(correct_rollouts=16, correct_min_failures=3,
                                                                          correct_passes=2)),
                "beyond the paper: ours-corrector-precise with its correction run again on a fresh draw, so that a "
                "leg chosen on one draw's rollouts is judged on rollouts that did not choose it", colour="#1b5e20")
#: frugal asking: a weak leg's alternatives cheapest first, the first win taken, each split in one proposer round
FRUGAL = dict(correct_first_win=True, correct_rounds=1)
register_method("ours-corrector-frugal", ours_variant(**CORRECTOR | dict(correct_rollouts=16, correct_min_failures=3)
                                                      | FRUGAL),
                "beyond the paper: ours-corrector-precise asking the proposer less in its correction: a weak leg's "
                "alternatives cheapest first (bypass, split, split over the next waypoint), stopping at the first "
                "that wins, and each of its splits in one proposer round (the leg's failure picture already in it)",
                colour="#006064")
#: ours-corrector-thrift: recheck's two passes, frugal's asking, and a higher gate (docs/corrector.md, "Within 3x")
THRIFT = dict(correct_rollouts=16, correct_min_failures=6, correct_passes=2, correct_first_win=True, correct_rounds=1)
register_method("ours-corrector-thrift", ours_variant(**CORRECTOR | THRIFT),
                "beyond the paper: ours-corrector-recheck asking the proposer as ours-corrector-frugal does "
                "(cheapest alternative first, one round per split) and only about legs with at least 6 of their 512 "
                "fresh rollouts failed; a leg with fewer is only bypassed", colour="#0d47a1")
register_method("ours-corrector-polish", ours_variant(**CORRECTOR | THRIFT | dict(polish_rollouts=512)),
                "beyond the paper: ours-corrector-thrift polishing the found path before its correction: each inner "
                "waypoint whose leg in fails at least twice in 512 fresh rollouts is narrowed by Algorithm 2 (k "
                "subsets of its region) where that raises its two legs' product (ours-polish's step)",
                colour="#4a148c")
#: ours-corrector-persist: polish, corrected until no leg is dead (docs/corrector.md, "Corrected until alive")
PERSIST = dict(polish_rollouts=512, correct_while_dead=True)
register_method("ours-corrector-persist", ours_variant(**CORRECTOR | THRIFT | PERSIST),
                "beyond the paper: ours-corrector-polish whose correction goes on while the path it leaves has a "
                "leg that never succeeded on its fresh check: pass after pass, each on a fresh draw, until no leg is "
                "dead or the search's budget of 30 edge splits is spent", colour="#880e4f")
#: ours-corrector-snap: persist, a waypoint centred in a wall moved clear of it (docs/corrector.md, "Snapped out of
#: the wall")
SNAP = dict(snap_waypoints=True)
register_method("ours-corrector-snap", ours_variant(**CORRECTOR | THRIFT | PERSIST | SNAP),
                "beyond the paper: ours-corrector-persist taking a reply whose waypoint is centred in a wall with "
                "that waypoint moved to the nearest point clear of walls by the agent's clearance (within one cell), "
                "instead of rejecting the reply", colour="#ad1457")
#: ours-corrector-extend: snap, whose correction of a dead path may go on to 3x the search's budget (docs/corrector.md,
#: "A budget that grows where the run would end at 0")
EXTEND = SNAP | dict(dead_budget=90)
register_method("ours-corrector-extend", ours_variant(**CORRECTOR | THRIFT | PERSIST | EXTEND),
                "beyond the paper: ours-corrector-snap whose correction of a path with a dead leg may go on past the "
                "search's budget of 30 edge splits, up to 90 in all; a path with no dead leg is corrected as snap "
                "corrects it, at the same cost", colour="#6a1b9a")
#: ours-corrector-keep: snap, a dead edge of the found path replaced by its declined split (docs/corrector.md, "A
#: declined split kept where the path is dead"); ours-corrector-fallback gives it up at half the budget left
KEEP = SNAP | dict(keep_declined=True)
register_method("ours-corrector-keep", ours_variant(**CORRECTOR | THRIFT | PERSIST | KEEP),
                "beyond the paper: ours-corrector-snap whose found path, where an edge of it never succeeded, takes "
                "the split of that edge the search declined with the most legs alive before its first dead one, so "
                "that the correction repairs that split's dead legs instead of asking for the whole edge again",
                colour="#4527a0")
register_method("ours-corrector-fallback",
                ours_variant(**CORRECTOR | THRIFT | PERSIST | KEEP | dict(keep_fallback=True)),
                "beyond the paper: ours-corrector-keep whose path, where the kept split is still dead after half the "
                "budget left, goes back to the edge it replaced and is corrected as snap corrects it with the rest",
                colour="#283593")
#: ours-corrector-advance: snap, a dead path keeping the ground a reply won (docs/corrector.md, "Ground kept where the
#: path is dead")
ADVANCE = SNAP | dict(correct_advance=True)
register_method("ours-corrector-advance", ours_variant(**CORRECTOR | THRIFT | PERSIST | ADVANCE),
                "beyond the paper: ours-corrector-snap whose correction of a dead leg keeps the legs a reply got "
                "alive: the reply's split cut after its live legs replaces the leg where it gets nearer the leg's "
                "end, and the next query spans only the rest", colour="#00695c")
register_method("ours-corrector-advance-extend", ours_variant(**CORRECTOR | THRIFT | PERSIST | ADVANCE | EXTEND),
                "beyond the paper: ours-corrector-advance whose correction of a path with a dead leg may go on past "
                "the search's budget of 30 edge splits, up to 90 in all (ours-corrector-extend's budget)",
                colour="#004d40")
#: ours-corrector-roadmap: advance-extend, a dead leg first offered a chain over every reply's waypoints pooled
#: (docs/corrector.md, "Replies pooled into a roadmap")
ROADMAP = dict(correct_roadmap=True)
ROADMAPPED = CORRECTOR | THRIFT | PERSIST | ADVANCE | EXTEND | ROADMAP  # roadmap's settings, which its variants extend
register_method("ours-corrector-roadmap", ours_variant(**ROADMAPPED),
                "beyond the paper: ours-corrector-advance-extend whose correction of a dead leg, while the path is "
                "dead, first tries a chain over the waypoints of every reply of the run pooled (best first toward the "
                "leg's end, legs within the policy's reach, no proposer call), then asks the proposer as before",
                colour="#1a237e")
#: ours-corrector-sound: roadmap, its chain built only on legs that succeed on at least half their rollouts
#: (docs/corrector.md, "Sound legs for the roadmap")
SOUND = dict(roadmap_sound=0.5)
register_method("ours-corrector-sound",
                ours_variant(**ROADMAPPED | SOUND),
                "beyond the paper: ours-corrector-roadmap whose chain over the pooled waypoints builds only on legs "
                "that succeed on at least half their rollouts (a weaker leg is remembered as a dead one is), so "
                "that no chain starts the rest of the path from a few lucky states", colour="#311b92")
#: ours-corrector-memory: roadmap, each search starting from what the searches before it reached from the same origin
#: (docs/corrector.md, "A roadmap that remembers")
MEMORY = dict(roadmap_remember=True)
register_method("ours-corrector-memory",
                ours_variant(**ROADMAPPED | MEMORY),
                "beyond the paper: ours-corrector-roadmap whose chain search over the pooled waypoints starts from "
                "the nodes the searches before it reached from the same origin, so that its evaluations go to legs "
                "not tried yet instead of re-reaching them", colour="#4a148c")
#: ours-corrector-explore: memory, a chain search that runs out of legs adding waypoints of its own at half the
#: policy's reach from what it reached (docs/corrector.md, "A roadmap that explores")
EXPLORE = dict(roadmap_explore=0.5)
register_method("ours-corrector-explore",
                ours_variant(**ROADMAPPED | MEMORY | EXPLORE),
                "beyond the paper: ours-corrector-memory whose chain search over the pooled waypoints, where it has "
                "tried every leg within reach of what it reached, adds waypoints of its own at half the policy's "
                "reach in eight directions from each node reached, judged by the rollouts as any other, so that a way "
                "no reply names can be found", colour="#880e4f")
#: ours-corrector-probe: memory, a chain search that runs out of legs probing from the node reached nearest the goal
#: (docs/corrector.md, "Probes from the nearest node")
PROBE = dict(roadmap_probe=0.5)
register_method("ours-corrector-probe",
                ours_variant(**ROADMAPPED | MEMORY | PROBE),
                "beyond the paper: ours-corrector-memory whose chain search, where it has tried every leg within "
                "reach of what it reached, adds eight waypoints at half the policy's reach around the node reached "
                "nearest the leg's end not probed yet, tried from that node only, and goes on", colour="#ad1457")
#: ours-corrector-deep: probe, each roadmap search allowed 360 subtask evaluations instead of 120
#: (docs/corrector.md, "Longer searches for the probes")
DEEP = dict(roadmap_evaluations=360)
register_method("ours-corrector-deep",
                ours_variant(**ROADMAPPED | MEMORY | PROBE | DEEP),
                "beyond the paper: ours-corrector-probe whose roadmap searches may each spend 360 subtask "
                "evaluations instead of 120, so that a search probing its way out of a pocket is not cut off and "
                "started again after one more proposer call", colour="#6a1b9a")
#: ours-corrector-mend: deep, a live leg below 0.9 on the fresh check also offered the roadmap's chain to its end,
#: after the proposer's alternatives (docs/corrector.md, "Weak legs mended on the roadmap")
MEND = dict(roadmap_weak=0.9)
MENDED = ROADMAPPED | MEMORY | PROBE | DEEP | MEND  # mend's settings, which its variants extend
register_method("ours-corrector-mend",
                ours_variant(**MENDED),
                "beyond the paper: ours-corrector-deep whose correction also offers a live leg that fails on more "
                "than a tenth of its fresh rollouts the roadmap's chain to its end (the pooled waypoints and probes, "
                "no proposer call), after the proposer's alternatives and whatever budget they left", colour="#7b1fa2")
#: ours-corrector-bridge: mend, whose weak leg is also offered the roadmap's chain from the leg before it
#: (docs/corrector.md, "Bridged from the leg before")
BRIDGE = dict(roadmap_bridge=True)
register_method("ours-corrector-bridge",
                ours_variant(**MENDED | BRIDGE),
                "beyond the paper: ours-corrector-mend whose weak leg is also offered, last, the roadmap's chain from "
                "the start of the leg before it to its end on legs as sound, replacing the waypoint between them: a "
                "leg that fails because of how it is entered fails from every node near its start", colour="#8e24aa")
#: ours-corrector-backtrack: mend, whose dead leg of a dead path is also offered the roadmap's chain from the path's
#: start (docs/corrector.md, "Ground given back")
BACKTRACK = dict(roadmap_backtrack=True)
register_method("ours-corrector-backtrack",
                ours_variant(**MENDED | BACKTRACK),
                "beyond the paper: ours-corrector-mend whose dead leg of a dead path, where its alternatives all lose, "
                "is also offered the roadmap's chain from the path's start (or the last subgoal before it) to the "
                "leg's end: ground won toward the goal is otherwise never given back, and a pocket walled off from the "
                "goal holds the run",
                colour="#5e35b1")
#: ours-corrector-fine: backtrack, whose roadmap searches give each node a second ring of probes at half the radius
#: once every node reached has its first (docs/corrector.md, "Finer probes")
FINE = dict(roadmap_rings=2)
register_method("ours-corrector-fine",
                ours_variant(**MENDED | BACKTRACK | FINE),
                "beyond the paper: ours-corrector-backtrack whose roadmap search, once every node it reached has had "
                "its eight probes, gives each node, nearest the goal first, eight more at half the distance turned by "
                "an eighth of a turn: one ring steps over a turn in a corridor narrower than its spacing",
                colour="#3949ab")
#: ours-corrector-span: fine, whose weak leg is also offered the roadmap's chains from its start past its end, to each
#: of the next two vertices of its split (docs/corrector.md, "Weak legs mended past their end")
SPAN = dict(roadmap_span=2)
register_method("ours-corrector-span",
                ours_variant(**MENDED | BACKTRACK | FINE | SPAN),
                "beyond the paper: ours-corrector-fine whose weak leg is also offered, last, the roadmap's chains from "
                "its start to each of the next two vertices of its split past its end, on legs as sound: a mend that "
                "enters the leg's end from another side can kill the next leg, which a chain past it judges together",
                colour="#283593")
#: ours-corrector-span-bridge: span, whose weak leg is also offered the roadmap's chain from the leg before it, as
#: bridge's is (docs/corrector.md, "Entered another way: span with the bridge")
SPAN_BRIDGE = MENDED | BACKTRACK | FINE | SPAN | BRIDGE  # the point mass's default (core/agents.py)
register_method("ours-corrector-span-bridge",
                ours_variant(**SPAN_BRIDGE),
                "beyond the paper: ours-corrector-span whose weak leg is also offered, after its own chain, the "
                "roadmap's chain from the start of the leg before it to its end, on legs as sound, replacing the "
                "waypoint between them: a waypoint whose arrivals every next leg loses (one a deaf proposer put "
                "against a wall) is stepped round, not searched from", colour="#1a237e")
#: ours-corrector-guard: deep, a correction's win on its window kept only if the whole path checked again scores no
#: lower (docs/corrector.md, "A window's win checked on the whole path")
GUARD = dict(correct_guard=True)
register_method("ours-corrector-guard",
                ours_variant(**ROADMAPPED | MEMORY | PROBE | DEEP | GUARD),
                "beyond the paper: ours-corrector-deep whose correction keeps an alternative that wins on its window "
                "(the changed legs and the one after) only if the whole path, checked again from the window on, "
                "scores no lower than before: a split can win its window and leave a weak leg downstream worse",
                colour="#4527a0")
register_method("ours-corrector-confirm", ours_variant(**CORRECTOR | dict(confirm_pick=True)),
                "beyond the paper: ours-corrector whose edge splits (the search's and the correction's) keep a later "
                "round's pick only if it beats the first round's best on the same fresh rollouts (ours-confirm's "
                "check)", colour="#bf360c")
#: ours-corrector-reaim: confirm, whose correction also offers a weak leg's end waypoints aimed clear of the walls
#: (docs/corrector.md, "Aimed clear of the walls")
register_method("ours-corrector-reaim", ours_variant(**CORRECTOR | dict(confirm_pick=True, correct_reaim=True)),
                "beyond the paper: ours-corrector-confirm whose correction also offers a weak leg, before any "
                "proposer call, the waypoint at either end of it aimed at the point of its region nearest the "
                "centre among those as clear of walls as the region allows (the region, so the task, unchanged)",
                colour="#e65100")
#: ours-corrector-redraw: confirm, whose correction runs a second pass on a fresh draw (docs/corrector.md, "A second
#: draw for the Ant")
REDRAW = CORRECTOR | dict(confirm_pick=True, correct_passes=2)
register_method("ours-corrector-redraw", ours_variant(**REDRAW),
                "beyond the paper: ours-corrector-confirm whose correction, when done, runs once more from the path "
                "it left on a fresh draw of its own (new first states, a budget of one proposer split per leg), so "
                "that a leg chosen on one draw's rollouts is judged again on rollouts that did not choose it",
                colour="#3e2723")
#: ours-corrector-redraw-rescue: redraw, whose path, where its correction leaves a dead leg, is corrected once more as
#: span-bridge corrects (docs/corrector.md, "A rescue for the Ant's default")
register_method("ours-corrector-redraw-rescue", ours_variant(**REDRAW | dict(rescue=SPAN_BRIDGE)),
                "beyond the paper: ours-corrector-redraw whose path, where its correction leaves a leg that never "
                "succeeded on its last fresh check, is corrected once more as ours-corrector-span-bridge corrects "
                "(the replies pooled with its own probes into a roadmap; up to 90 proposer splits in all): a proposer "
                "that gives nothing valid, or never uses its feedback, leaves redraw at 0; a path redraw leaves "
                "alive is never touched", colour="#d84315")
#: ours-corrector-redraw-rescue-floor: the rescue, whose correction also mends live legs above mend's level while the
#: path is below FLOOR (docs/corrector.md, "Weak legs judged by the path")
FLOOR = dict(roadmap_floor=0.85)
register_method("ours-corrector-redraw-rescue-floor", ours_variant(**REDRAW | dict(rescue=SPAN_BRIDGE | FLOOR)),
                "beyond the paper: ours-corrector-redraw-rescue whose rescue, while the path's fresh check is below "
                "0.85, also offers the roadmap's chain to a live leg below 0.85 ** (1 / legs), not only below 0.9: "
                "thirteen legs at 0.92-1.00, each above mend's level, took an Ant path to 0.75", colour="#ffab40")
#: ours-corrector-sparing: redraw, whose two passes ask the proposer only about a leg with at least 3 fresh failures
#: (docs/corrector.md, "A gate for the Ant's corrector")
SPARING = REDRAW | dict(correct_min_failures=3)
register_method("ours-corrector-sparing", ours_variant(**SPARING),
                "beyond the paper: ours-corrector-redraw whose correction, on both passes, asks the proposer about a "
                "leg only where at least 3 of its 4n fresh rollouts failed (128 at n = 32); a leg with one or two "
                "failures is offered its bypass only, which asks nothing, so that the proposer is not asked about a "
                "leg whose loss the draw cannot tell from none", colour="#a1887f")
#: ours-corrector-sparing-frugal: sparing, asking as frugal does (docs/corrector.md, "Sparing and frugal: the Ant")
SPARING_FRUGAL = SPARING | FRUGAL
register_method("ours-corrector-sparing-frugal", ours_variant(**SPARING_FRUGAL),
                "beyond the paper: ours-corrector-sparing asking the proposer as ours-corrector-frugal does: a weak "
                "leg's alternatives cheapest first (bypass, split, split over the next waypoint), the first that "
                "wins taken, and each of the correction's splits in one proposer round (the leg's failure picture "
                "already in it)", colour="#6d4c41")
#: ours-corrector-wide: redraw, then one more pass on a wide draw (docs/ant_experiments.md, "Issue 42, lever 8")
register_method("ours-corrector-wide",
                ours_variant(**REDRAW | dict(correct_wide=16, correct_wide_min_failures=3)),
                "beyond the paper: ours-corrector-redraw whose correction, when its two passes are done, runs once "
                "more on a wide fresh draw (16x n rollouts per leg, 512 on the Ant) and asks the proposer only about "
                "a leg with at least 3 failures there (other weak legs are offered their bypass only), so that a leg "
                "losing a per cent or two, which 128 rollouts see about twice, is found and one losing a tenth of "
                "that is not chased", colour="#5d4037")
#: ours-corrector-crosscheck: confirm, whose correction takes an alternative only where it also wins on a second draw
#: (docs/corrector.md, "Wins checked on a second draw")
register_method("ours-corrector-crosscheck",
                ours_variant(**CORRECTOR | dict(confirm_pick=True, correct_crosscheck=True)),
                "beyond the paper: ours-corrector-confirm whose correction takes an alternative that wins on the "
                "check's fresh rollouts only if it also beats the path over the same legs on a second fresh draw "
                "of its own (new first states; no proposer call)", colour="#4e342e")
register_method("ours-corrector-retry", ours_variant(**CORRECTOR | dict(correct_rollouts=16, correct_min_failures=3,
                                                                       empty_retries=2)),
                "beyond the paper: ours-corrector-precise asking the proposer again, up to twice, when its reply "
                "to an edge split of the search gave no valid candidate (within the budget of 30)",
                colour="#33691e")
register_method("ours-deeprepair", ours_variant(repair=True, repair_depth=3),
                "lever of ours-corrector alone: ours-repair repairing a leg's split with a dead leg of its own, to "
                "three levels", colour="#8e24aa")
register_method("ours-feasible", ours_variant(dead_weight=100.0),
                "lever of ours-corrector alone: ours with a never-succeeding leg weighing 100, so that any chain that "
                "succeeds at all beats a dead edge", colour="#d81b60")
register_method("ours-checked", ours_variant(correct_rollouts=4, correct_reach="policy"),
                "lever of ours-corrector alone: ours, then the found path checked on 4x fresh rollouts per leg and "
                "its weak legs split, split over or bypassed while the path gains (refine/correct.py)",
                colour="#ef5350")
register_method("vlm-oneshot", vlm_oneshot,
                "baseline: whole-graph refinement in one query + one feedback round, best of 2 x w",
                colour="#ef6c00", knobs=("w", "d"))
register_method("vlm-oneshot-matched", vlm_oneshot_matched,
                "control: one-shot best-of-N, spending what ours spent (proposer calls, subtask evaluations) on the "
                "same task and seed", colour="#ffb74d")
register_method("symbolic", symbolic, "baseline: the search with vertex subsets only", asks_proposer=False,
                colour="#8d6e63", knobs=("k",))
register_method("dirl", dirl, "baseline: no refinement, Dijkstra on the input graph", asks_proposer=False,
                colour="#9e9e9e", knobs=())

BUILT_IN = frozenset(METHODS)  # registered by the package itself: replaced only with replace=True
