"""Who proposes refinements: a VLM through LiteLLM (or its recording), or an offline stand-in.

One module per job: :mod:`.base` (queries, feedback, the :class:`Proposer` interface),
:mod:`.prompts` (what the VLM is asked), :mod:`.schema` (how an answer becomes regions or a graph),
:mod:`.vlm` (the VLM proposer), :mod:`.geometric` (the offline planners), :mod:`.factory`
(``make_proposer``).  A new proposer is one new module and one ``register_proposer`` entry.
"""

from .base import CandidateFeedback, EdgeQuery, GraphFeedback, GraphQuery, Proposer
from .factory import PROPOSERS, make_proposer, parse_proposer, register_proposer
from .geometric import GeometricProposer, RandomProposer, grid_path, reach_cells, segment_clear, splice
from .prompts import environment_text, graph_messages, render_prompt, split_messages, system_message
from .schema import check_region, parse_graph, parse_split, region_json
from .vlm import VLMProposer

__all__ = [
    "PROPOSERS", "CandidateFeedback", "EdgeQuery", "GeometricProposer", "GraphFeedback", "GraphQuery", "Proposer",
    "RandomProposer", "VLMProposer", "check_region", "environment_text", "graph_messages", "grid_path",
    "make_proposer", "parse_graph", "parse_proposer", "parse_split", "reach_cells", "region_json",
    "register_proposer", "render_prompt", "segment_clear", "splice", "split_messages", "system_message",
]
