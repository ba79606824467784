"""The agent registry is the one home of per-agent facts: the simulator, policy and CLI agree with it."""

import pytest

from specrefine import cli
from specrefine.core.agents import AGENTS, get_agent
from specrefine.core.errors import SpecrefineError
from specrefine.core.mazes import load_maze
from specrefine.sim.policy import GoalPolicy
from specrefine.sim.simulator import BatchedSim
from specrefine.sim.train import make_config


@pytest.mark.parametrize("name", sorted(AGENTS))
def test_entry_matches_the_simulator_and_policy(name):
    agent = AGENTS[name]
    sim = BatchedSim(name, None, 2, nthread=1)
    assert (sim.obs_dim, sim.act_dim) == (agent.obs_dim, agent.act_dim)
    assert sim.body_radius == agent.body_radius and sim.default_horizon == agent.default_horizon
    assert sim.dt == pytest.approx(agent.timestep * agent.frame_skip)
    policy = GoalPolicy(name)
    assert (policy.obs_dim, policy.act_dim) == (agent.obs_dim, agent.act_dim)
    assert load_maze("u_maze").for_agent(name).cell_size == agent.cell_size
    assert make_config(name).frames == agent.train["frames"]
    sim.close()


def test_cli_offers_exactly_the_registered_agents():
    agent = next(a for a in cli.build_parser("refine").commands["refine"]._actions if a.dest == "agent")
    assert tuple(agent.choices) == tuple(AGENTS)


def test_unknown_agent_is_a_one_line_error():
    with pytest.raises(SpecrefineError, match="unknown agent 'cat'; expected one of point, ant"):
        get_agent("cat")
