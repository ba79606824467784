"""One call that sets up an experiment: ``specrefine.setup(maze, agent=..., proposer=..., seed=..., rollouts=...)``.

It returns an :class:`Experiment` holding the maze at the agent's scale, its task graph, the goal
policy, an :class:`~specrefine.evaluation.evaluator.Evaluator` and (if asked) a proposer.  The notebooks' setup
cells and :func:`specrefine.runs.pipeline.refine_maze` use it, so a setup cell copied into a new notebook
works as it is.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..core.agents import get_agent
from ..core.errors import PolicyError, SpecrefineError
from ..core.graph import TaskGraph
from ..core.mazes import Maze, load_maze
from ..core.paper import PAPER


@dataclass
class Experiment:
    maze: Maze  # at the agent's scale
    agent: str
    graph: TaskGraph  # the task: the maze's own (S -> a -> ... -> G) or a spec's, avoiding walls and hazards
    policy: object
    policy_name: str
    evaluator: object  # specrefine.evaluation.evaluator.Evaluator (or a stand-in passed to setup)
    proposer: object | None  # specrefine.proposers.Proposer, if one was asked for
    seed: int
    out: Path | None

    def describe(self) -> str:
        """Two lines for a notebook: the maze, agent and policy; what the evaluator counts as touching a wall."""
        ev = self.evaluator
        return (f"{self.maze.name}: {self.maze.rows}x{self.maze.cols} cells of {self.maze.cell_size:g} m; "
                f"agent {self.agent}; policy: {self.policy_name}; {self.graph}\n"
                f"{ev.n} rollouts per subtask, horizon {ev.horizon} control steps; a rollout touches a wall within "
                f"{ev.clearance:.3f} m (body radius {ev.agent_radius} m + contact margin); seed {self.seed}")


def load_goal_policy(agent: str, policy="shipped"):
    """``(policy, name)``: ``"shipped"`` (``data/policies/AGENT.pt``), the stem of another shipped checkpoint
    (``"ant_stage5"``), ``"scripted"`` (point only) or a path."""
    from ..core.paths import shipped_name
    from ..sim.policy import PointController, load_policy

    if policy == "scripted":
        if agent != "point":
            raise PolicyError(f"the scripted controller drives the point mass only, not the {agent}")
        return PointController(), "scripted straight-line controller (no learning)"
    if policy in (None, "shipped"):
        return load_policy(agent), f"shipped data/policies/{agent}.pt"
    if shipped_name(policy):
        loaded, name = load_policy(policy), f"shipped data/policies/{policy}.pt"
    else:
        loaded, name = load_policy(Path(policy)), f"trained policy {Path(policy).name}"
    if getattr(loaded, "agent", agent) != agent:
        raise PolicyError(f"{policy}: holds a {loaded.agent} policy, not one for the {agent}: pick the {agent}'s "
                          f"checkpoint (or leave --policy out for the shipped one)")
    return loaded, name


def setup(maze, *, agent: str = "point", proposer: str | None = None, seed: int = 0, rollouts: int = PAPER.rollouts,
          policy="shipped", out=None, cache_dir=None, evaluator=None, record_path=None,
          spec: str | None = None, goal_points: str = PAPER.goal_points, switching: str = "at-region") -> Experiment:
    """Everything an experiment starts from.

    maze: a name in ``data/mazes/``, a ``.maze`` path or a :class:`Maze`; agent: a registered agent
    (``specrefine.core.agents``); proposer: a ``--proposer`` string (``geometric``, ``random``,
    ``replay:PATH``, ``litellm:MODEL``) or None; rollouts: per subtask evaluation; policy:
    ``"shipped"``, ``"scripted"`` or a checkpoint path; out: a directory (created) whose ``cache/``
    keeps evaluations unless ``cache_dir`` says otherwise; evaluator: use this one instead of
    building one; record_path: where a ``litellm:`` proposer records its calls; spec: the task as an
    expression over the maze's letters (``"(a | b) -> c -> G"``, see ``specrefine.core.spec.parse_spec``),
    None = the maze's own task (its ``; spec:`` line, else its chain); goal_points: where a leg's policy aims,
    "sampled" (a point drawn in the goal region per rollout, the paper's rule) or "centre" (``Evaluator.aim``);
    switching: when a leg's policy is fed its goal point, "at-region" (the paper's) or "slow-turn"
    (:mod:`specrefine.sim.switching`).
    """
    from ..core.spec import maze_task
    from ..evaluation.evaluator import Evaluator

    get_agent(agent)
    maze = (maze if isinstance(maze, Maze) else load_maze(maze)).for_agent(agent)
    graph = maze_task(maze, spec)  # a bad spec fails before anything is built or written
    out = Path(out) if out is not None else None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        cache_dir = out / "cache" if cache_dir is None else cache_dir
    if evaluator is None:
        goal_policy, policy_name = load_goal_policy(agent, policy)
        evaluator = Evaluator(maze, agent, goal_policy, n=rollouts, seed=seed, cache_dir=cache_dir,
                              goal_points=goal_points, switching=switching)
    else:
        if (given := getattr(evaluator, "goal_points", PAPER.goal_points)) != goal_points:
            raise SpecrefineError(f"the evaluator given aims at {given} goal points, the run asks for {goal_points}")
        if (given := getattr(evaluator, "switching", "at-region")) != switching:
            raise SpecrefineError(f"the evaluator given switches goals by the {given} rule, the run asks for "
                                  f"{switching}")
        goal_policy, policy_name = getattr(evaluator, "policy", None), "given with the evaluator"
    chosen = None
    if proposer is not None:
        from ..proposers import make_proposer

        chosen = make_proposer(proposer, seed=seed, record_path=record_path)
    return Experiment(maze, agent, graph, goal_policy, policy_name, evaluator, chosen, seed, out)
