"""The package's modules import each other without cycles, and no layer imports a layer above it (README, Package)."""

from __future__ import annotations

import ast
from pathlib import Path

import networkx as nx

PACKAGE = Path(__file__).resolve().parents[1] / "specrefine"

#: README's layers, lowest first; a module may import its own layer and those before it
LAYERS = [
    {"errors", "paths", "paper", "argtypes", "regions", "agents", "results", "tables"},
    {"mazes", "standard_maps", "spec", "graph", "runfolder"},
    {"sim", "policy", "reach_env", "policy_eval", "curves", "train", "render"},
    {"evaluate", "monitor", "compositional"},
    {"proposers", "vlm"},
    {"refine"},
    {"queries", "methods", "runconfig", "experiment", "calibrate", "progress", "pipeline", "sweep", "cli",
     "official", "failures", "explore", "notebook", "bench", "specrefine"},
    {"figures", "comparison", "repair_claims"},
]


def _imports() -> nx.DiGraph:
    """Edges between top-level modules (``specrefine.X``), function-level imports included, type-only ones not."""
    graph = nx.DiGraph()
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE.parent).with_suffix("").parts
        here = rel[1] if len(rel) > 1 and rel[1] != "__init__" else "specrefine"
        package = list(rel[:-1]) if path.name != "__init__.py" else list(rel[:-1])
        graph.add_node(here)
        tree = ast.parse(path.read_text())
        type_only = {id(n) for node in ast.walk(tree) if isinstance(node, ast.If)
                     and getattr(node.test, "id", None) == "TYPE_CHECKING" for n in ast.walk(node)}
        for node in ast.walk(tree):
            if id(node) in type_only or not isinstance(node, ast.ImportFrom | ast.Import):
                continue
            if isinstance(node, ast.ImportFrom):
                base = package[:len(package) - node.level + 1] if node.level else []
                names = [".".join(base + ([node.module] if node.module else []) + ([a.name] if not node.module else []))
                         for a in node.names] if node.level else [node.module or ""]
            else:
                names = [a.name for a in node.names]
            for name in names:
                parts = name.split(".")
                if parts[0] == "specrefine":
                    there = parts[1] if len(parts) > 1 else "specrefine"
                    if there != here:
                        graph.add_edge(here, there)
    return graph


def test_no_import_cycles():
    assert list(nx.simple_cycles(_imports())) == []


def test_every_module_has_a_layer_and_imports_none_above_it():
    graph = _imports()
    layer = {m: i for i, group in enumerate(LAYERS) for m in group}
    assert sorted(set(graph) - set(layer)) == []  # a new module: give it a layer here and in README
    upward = sorted((a, b) for a, b in graph.edges if layer[b] > layer[a])
    assert upward == []
