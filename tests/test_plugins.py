"""Plugins the CLI and the sweep honour (examples/greedy_plugin.py through the command line, an installed entry
point), and registrations refused in one line when they would break something."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from specrefine.core.errors import SpecrefineError
from specrefine.proposers import Proposer, make_proposer, register_proposer
from specrefine.proposers.factory import PROPOSERS
from specrefine.runs.methods import METHODS, dirl, ours_variant, register_method
from specrefine.runs.sweep import read_table

ROOT = Path(__file__).resolve().parent.parent
PLUGIN = ROOT / "examples" / "greedy_plugin.py"
TINY = ["--rollouts", "8", "--episodes", "10", "-w", "1", "-d", "1", "-k", "1"]


def specrefine(*args, path=()):
    """``python -m specrefine ARGS`` from the repository root, with ``path`` also importable."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), *map(str, path)])}
    return subprocess.run([sys.executable, "-m", "specrefine", *map(str, args)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=600)


def test_the_example_plugin_runs_through_refine(tmp_path):
    done = specrefine("--plugin", PLUGIN, "refine", "split_doorway", "--method", "ours-greedy", "--proposer",
                      "straight:2", *TINY, "--out", tmp_path / "run")
    assert done.returncode == 0, done.stderr[-2000:]
    data = json.loads((tmp_path / "run" / "result.json").read_text())
    assert (data["method"], data["proposer"]) == ("ours-greedy", "straight:2")
    assert data["proposer_calls"] >= 1 and data["proposer_is_vlm"] is False
    # after the command, as a dotted module from the working directory, and in its help
    helped = specrefine("refine", "--plugin", "examples.greedy_plugin", "--help")
    assert helped.returncode == 0 and "ours-greedy" in helped.stdout and "straight[:N]" in helped.stdout


def test_the_example_plugin_runs_in_a_sweep(tmp_path):
    done = specrefine("sweep", "--plugin", PLUGIN, "--mazes", "split_doorway", "--methods", "ours-greedy",
                      "--proposers", "straight", "--seeds", "0", "--rollouts", "8", "--episodes", "10", "--workers",
                      "1", "--out", tmp_path / "s")
    assert done.returncode == 0, done.stderr[-2000:]
    (row,) = read_table(tmp_path / "s" / "results.csv")
    assert (row["status"], row["method"], row["proposer"]) == ("ok", "ours-greedy", "straight")


def test_an_installed_entry_point_is_loaded_before_the_parser(tmp_path):
    site = tmp_path / "site"
    (site / "myplugin-0.1.dist-info").mkdir(parents=True)
    (site / "myplugin-0.1.dist-info" / "METADATA").write_text("Metadata-Version: 2.1\nName: myplugin\nVersion: 0.1\n")
    (site / "myplugin-0.1.dist-info" / "entry_points.txt").write_text(
        "[specrefine.methods]\nmine = myplugin:register\n")
    (site / "myplugin.py").write_text(
        "def register():\n"
        "    from specrefine.runs.methods import dirl, register_method\n"
        "    register_method('dirl-mine', dirl, 'an installed plugin', asks_proposer=False)\n")
    helped = specrefine("refine", "--help", path=[site])
    assert helped.returncode == 0 and "dirl-mine" in helped.stdout, helped.stderr
    (site / "myplugin.py").write_text("raise RuntimeError('broken on purpose')\n")
    broken = specrefine("refine", "--help", path=[site])
    lines = broken.stderr.strip().splitlines()
    assert broken.returncode == 2 and len(lines) == 1 and "'mine'" in lines[0] and "broken on purpose" in lines[0]


def test_a_plugin_that_cannot_load_is_one_line(tmp_path):
    for plugin in ("no_such_module_anywhere", tmp_path / "absent.py"):
        done = specrefine("--plugin", plugin, "refine", "u_maze", "--out", tmp_path / "r")
        lines = done.stderr.strip().splitlines()
        assert done.returncode == 2 and len(lines) == 1 and str(plugin) in lines[0], done.stderr
    bad = tmp_path / "bad.py"
    bad.write_text("from specrefine.runs.methods import ours_variant, register_method\n"
                   "register_method('ours-typo', ours_variant(vertex_refinment=False), 'a typo')\n")
    done = specrefine("--plugin", bad, "refine", "u_maze", "--out", tmp_path / "r")
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1 and "vertex_refinment" in lines[0], done.stderr
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize("name", [5, "", "../../evil", "a b", "ours:x", "-x"])
def test_unsafe_names_are_refused(name):
    with pytest.raises(SpecrefineError, match="name"):
        register_method(name, dirl, "x")
    with pytest.raises(SpecrefineError, match="name"):
        register_proposer(name, lambda *a, **k: None, lambda s: s)
    assert name not in METHODS and name not in PROPOSERS


def test_built_ins_are_not_replaced_unless_asked():
    ours, geometric = METHODS["ours"], PROPOSERS["geometric"]
    with pytest.raises(SpecrefineError, match="built in"):
        register_method("ours", dirl, "not ours")
    with pytest.raises(SpecrefineError, match="built in"):
        register_proposer("geometric", geometric.build, geometric.parse)
    assert METHODS["ours"] is ours and PROPOSERS["geometric"] is geometric
    try:
        assert register_method("ours", dirl, "replaced", replace=True).search is dirl
    finally:
        METHODS["ours"] = ours


def test_nonsense_registrations_are_refused():
    with pytest.raises(SpecrefineError, match="search must be a function"):
        register_method("ok-name", 42, "x")
    with pytest.raises(SpecrefineError, match="build must be a function"):
        register_proposer("ok-name", None, lambda s: s)
    with pytest.raises(SpecrefineError, match="knobs"):
        register_method("ok-name", dirl, "x", knobs=("w", "z"))
    with pytest.raises(SpecrefineError, match="SearchConfig has no field 'vertex_refinment'"):
        ours_variant(vertex_refinment=False)
    assert "ok-name" not in METHODS and "ok-name" not in PROPOSERS


def test_the_base_class_counts_queries_and_make_proposer_names_them():
    """A proposer that implements only ``split`` is counted and named without doing either itself."""

    class Quiet(Proposer):
        def split(self, q, w, feedback=()):
            return []

    register_proposer("quiet-example", lambda options, **_: Quiet(), lambda s: s)
    try:
        proposer = make_proposer("quiet-example:abc")
        assert proposer.spec == "quiet-example:abc" and proposer.queries == 0
        assert proposer.propose_split(None, 3) == [] and proposer.propose_split(None, 3, ()) == []
        assert proposer.queries == 2 and proposer.describe()["proposer_calls"] == 2
    finally:
        del PROPOSERS["quiet-example"]


def test_a_fresh_worker_loads_the_sweeps_plugins_before_its_cell(tmp_path):
    """A Ray worker is a fresh process: run_cell gets the sweep's --plugin modules and loads them itself."""
    code = ("import sys; from specrefine.runs.sweep import Cell, run_cell; "
            "cell = Cell.of('split_doorway', 'point', 'ours-greedy', 'straight', 0, rollouts=8, episodes=10, w=1, d=1,"
            " k=1); "
            f"row = run_cell(cell, {str(tmp_path)!r}, ({str(PLUGIN)!r},)); "
            "print(row['status'], row['method'], row['proposer'], row.get('error', ''))")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=600,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split()[:3] == ["ok", "ours-greedy", "straight"], done.stdout
