"""What the prompts tell the VLM about the agent, the regions and the evaluation is what the code does."""

import re

import numpy as np
import pytest

from specrefine.core.agents import AGENTS
from specrefine.core.mazes import load_maze
from specrefine.core.spec import maze_task
from specrefine.evaluation.evaluator import EvaluationFacts, Evaluator
from specrefine.proposers import EdgeQuery, GraphQuery, graph_messages, split_messages
from specrefine.sim.policy import PointController
from specrefine.vlm import messages_to_text


def _rendered(agent: str):
    maze = load_maze("split_doorway").for_agent(agent)
    evaluator = Evaluator(maze, agent, PointController(), n=8, seed=0)
    graph = maze_task(maze)
    u, v = graph.edges()[0]
    facts = evaluator.facts()
    edge = EdgeQuery(maze=maze, agent=agent, start=graph.region(u), goal=graph.region(v), avoid=graph.avoid(u, v),
                     success=0.25, n=8, image_png=None, graph=graph, facts=facts)
    whole = GraphQuery(maze=maze, agent=agent, graph=graph, success=0.25, n=8, image_png=None, facts=facts)
    return evaluator, [messages_to_text(split_messages(edge)), messages_to_text(graph_messages(whole))]


@pytest.mark.parametrize("agent", sorted(AGENTS))
def test_prompts_state_the_evaluators_numbers_and_goal_rule(agent):
    evaluator, texts = _rendered(agent)
    entry = AGENTS[agent]
    assert evaluator.clearance > entry.body_radius  # the contact margin is part of the stated clearance
    for text in texts:
        stated = {float(x) for x in re.findall(r"within ([0-9.]+) m of one", text)}
        assert stated and all(abs(x - evaluator.clearance) < 5e-4 for x in stated), (stated, evaluator.clearance)
        assert f"{evaluator.horizon} control steps ({evaluator.horizon * evaluator.control_period:g} s)" in text
        assert f"up to {entry.policy_reach:g} m away" in text and entry.description in text
        assert "drawn uniformly at random inside the next region" in text
        assert "centre of the next region" not in text
    assert EvaluationFacts.default(agent, evaluator.maze, rollouts=8) == evaluator.facts()


def test_goal_points_are_uniform_in_the_region_as_the_prompt_says():
    """The evaluator really samples the goal point inside the goal region, spread over it (not its centre)."""
    maze = load_maze("split_doorway").for_agent("point")
    evaluator = Evaluator(maze, "point", PointController(), n=8, seed=0)
    goal = maze.goal
    pts = evaluator.sample_free(goal, 200, np.random.default_rng(0))
    assert np.all(goal.contains(pts))
    assert np.all(maze.walls.signed_distance(pts) >= evaluator.clearance - 1e-9)
    assert np.std(pts, axis=0).max() > 0.1  # spread over the region, not a fixed centre
