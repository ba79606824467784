"""Pictures of a maze, its task graph and rollouts (matplotlib ``Figure`` objects); the core below, nothing else."""
