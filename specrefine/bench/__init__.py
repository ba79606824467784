"""Throughput benchmarks, one home: ``python -m specrefine.bench SUBCOMMAND`` prints one JSON line.

    python -m specrefine.bench evaluator --agent {point,ant} [--batch 32]   # Evaluator vs raw mujoco.rollout
    python -m specrefine.bench gymenv --agent ant     # the same, and TorchRL GymEnv(AntMaze_UMaze-v5), one run
    python -m specrefine.bench train --agent ant      # PPO frames/s: our config vs TorchRL's minibatch-64 one
    python -m specrefine.bench refine --agent ant     # a refinement run's cost: fixed vs adaptive evaluation

``evaluator`` is the stable contract (at least ``env_steps_per_s``: policy in the loop, batch of 32
rollouts, the evaluator's real code path).  Measured numbers and how they were taken: ``benchmarks/README.md``.
"""

from .evaluator import bench_evaluator, bench_gymenv, open_room
from .refinement import bench_refinement
from .training import bench_train

__all__ = ["bench_evaluator", "bench_gymenv", "bench_refinement", "bench_train", "open_room"]
