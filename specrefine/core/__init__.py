"""The core: regions, mazes, agents as data, specifications, task graphs, run folders and result tables.

Imports neither MuJoCo, torch nor matplotlib (``tests/test_layers.py`` checks it), so every layer above may use it.
"""
