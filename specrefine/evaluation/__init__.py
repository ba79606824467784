"""Estimating subtasks and paths: the rollout evaluator, the specification monitor, the compositional policy."""
