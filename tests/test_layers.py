"""The package's layers (README, Package): no import cycle between modules or between sub-packages, no sub-package
importing a layer above it, and a core that imports neither MuJoCo, torch nor matplotlib."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import networkx as nx

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "specrefine"

#: README's layers, lowest first: a sub-package (or top-level module) may import its own layer and those before it;
#: ``specrefine`` is the package's ``__init__.py``
LAYERS = [
    {"core"},
    {"pictures"},
    {"sim"},
    {"evaluation"},
    {"vlm"},
    {"proposers"},
    {"refine"},
    {"runs"},
    {"experiments"},
    {"cli", "bench", "specrefine"},
]
HEAVY = ("mujoco", "torch", "matplotlib")  # what the core must not import


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _targets(node, package: list[str], modules: set[str]) -> list[str]:
    """The package's modules an import statement loads (``from P import m``: the module P.m when it is one, else P)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    base = package[:len(package) - node.level + 1] if node.level else []
    base = ".".join(base + (node.module.split(".") if node.module else []))
    return [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names]


def _imports() -> nx.DiGraph:
    """Edges between the package's modules, function-level imports included, type-only ones not."""
    paths = sorted(PACKAGE.rglob("*.py"))
    modules = {_module_name(p) for p in paths}
    graph = nx.DiGraph()
    for path in paths:
        here = _module_name(path)
        package = here.split(".") if path.name == "__init__.py" else here.split(".")[:-1]
        graph.add_node(here)
        tree = ast.parse(path.read_text())
        type_only = {id(n) for node in ast.walk(tree) if isinstance(node, ast.If)
                     and getattr(node.test, "id", None) == "TYPE_CHECKING" for n in ast.walk(node)}
        for node in ast.walk(tree):
            if id(node) in type_only or not isinstance(node, ast.ImportFrom | ast.Import):
                continue
            for there in _targets(node, package, modules):
                if there.split(".")[0] == "specrefine" and there != here:
                    assert there in modules, f"{here} imports {there}, which is not a module of the package"
                    graph.add_edge(here, there)
    return graph


def _part(module: str) -> str:
    """A module's layer unit: its sub-package (``specrefine.runs.sweep`` -> ``runs``), ``cli``, or ``specrefine`` (the
    package's ``__init__.py`` and ``__main__.py``)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[1] != "__main__" else "specrefine"


def _parts_graph() -> nx.DiGraph:
    graph = _imports()
    parts = nx.DiGraph()
    parts.add_nodes_from(_part(m) for m in graph)
    parts.add_edges_from((_part(a), _part(b)) for a, b in graph.edges if _part(a) != _part(b))
    return parts


def test_no_import_cycles_between_modules():
    assert list(nx.simple_cycles(_imports())) == []


def test_no_import_cycles_between_sub_packages():
    assert list(nx.simple_cycles(_parts_graph())) == []


def test_every_sub_package_has_a_layer_and_imports_none_above_it():
    graph = _parts_graph()
    layer = {part: i for i, group in enumerate(LAYERS) for part in group}
    assert sorted(set(graph) - set(layer)) == []  # a new sub-package: give it a layer here and in README
    assert sorted(set(layer) - set(graph)) == []
    upward = sorted((a, b) for a, b in graph.edges if layer[b] > layer[a])
    assert upward == []
    modules = _imports()
    upward_modules = sorted((a, b) for a, b in modules.edges if layer[_part(b)] > layer[_part(a)])
    assert upward_modules == []


def test_readme_names_the_same_layers_in_the_same_order():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    paragraph = text.split("\n## Package\n", 1)[1].strip().split("\n\n", 1)[0]
    named = [{"specrefine" if name == "__init__" else name for name in re.findall(r"`(\w+)(?:/|\.py)`", segment)}
             for segment in re.split(r"\s→\s", paragraph)]
    assert named == LAYERS


def test_the_core_imports_neither_mujoco_nor_torch_nor_matplotlib():
    core = sorted(_module_name(p) for p in (PACKAGE / "core").glob("*.py"))
    assert "specrefine.core.graph" in core and "specrefine.core.runfolder" in core
    probe = (f"import importlib, sys\nfor m in {core!r}:\n    importlib.import_module(m)\n"
             f"print(sorted(h for h in {HEAVY!r} if h in sys.modules))")
    proc = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip() == "[]"


def test_one_figure_convention_no_pyplot():
    """Every figure is a ``pictures.render.PngFigure`` (no pyplot: no global backend or state, nothing to close)."""
    users = []
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            else:
                continue
            if any(n.startswith("matplotlib.pyplot") or n == "matplotlib.use" for n in names):
                users.append(str(path.relative_to(PACKAGE)))
    assert users == []
