"""Simulation and the goal policy: the batched MuJoCo simulator, the policy network, its PPO training and checks."""
