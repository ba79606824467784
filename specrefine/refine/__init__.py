"""Specification refinement: edge split (Alg. 1), vertex subset (Alg. 2), A* with refinement (Alg. 3)."""

from .common import Leg, LegEstimates, estimate_legs, evaluate_path, weight
from .edge_split import SplitCandidate, SplitOutcome, edge_split
from .search import RefinementSearch, SearchConfig, SearchResult, shortest_path
from .vertex import ChainChoice, refine_chain, sample_subsets

__all__ = [
    "ChainChoice", "Leg", "LegEstimates", "RefinementSearch", "SearchConfig", "SearchResult", "SplitCandidate",
    "SplitOutcome", "edge_split", "estimate_legs", "evaluate_path", "refine_chain", "sample_subsets",
    "shortest_path", "weight",
]
