"""Run every numbered notebook through papermill with its smoke parameters.

Each ``notebooks/NN_*.ipynb`` is one test (select them with ``-m notebooks``, skip them with
``-m "not notebooks"``).  A notebook's own ``parameters`` cell IS its smoke set; the optional
``notebooks/smoke.json`` overrides it::

    {"05_astar_refinement": {"ROLLOUTS": 4, "timeout_s": 600}}

Keys are notebook file names or stems.  UPPERCASE keys are parameters (each must exist in the
notebook's ``parameters`` cell); lowercase keys are harness settings: ``timeout_s`` (whole
notebook, default ``DEFAULT_TIMEOUT_S``).  The notebook runs in a subprocess (so the timeout is
hard) with cwd ``notebooks/``, on a kernel named ``python3`` that is this interpreter, with
``MPLBACKEND=Agg``; the executed copy is written to a temporary directory and its path is in the
failure message.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

NB_DIR = Path(__file__).resolve().parent.parent / "notebooks"
NOTEBOOKS = sorted(NB_DIR.glob("[0-9][0-9]_*.ipynb"))
SMOKE_FILE = NB_DIR / "smoke.json"
DEFAULT_TIMEOUT_S = 300
HARNESS_KEYS = {"timeout_s"}


def _smoke_settings(nb: Path) -> tuple[dict, dict]:
    """(parameter overrides, harness settings) for one notebook from notebooks/smoke.json."""
    table = json.loads(SMOKE_FILE.read_text()) if SMOKE_FILE.exists() else {}
    entry = {**table.get(nb.stem, {}), **table.get(nb.name, {})}
    params = {k: v for k, v in entry.items() if k.isupper()}
    harness = {k: v for k, v in entry.items() if not k.isupper()}
    unknown = set(harness) - HARNESS_KEYS
    assert not unknown, f"{SMOKE_FILE.name}: unknown settings {sorted(unknown)} for {nb.name}"
    return params, harness


def _parameters_cells(nb: Path):
    return [c for c in nbformat.read(nb, as_version=4).cells if "parameters" in c.get("metadata", {}).get("tags", [])]


def _parameter_names(nb: Path) -> set[str]:
    import papermill

    return set(papermill.inspect_notebook(str(nb)))


@pytest.fixture(scope="session")
def venv_kernel_env(tmp_path_factory) -> dict:
    """Environment whose kernel 'python3' is this interpreter (the venv), whatever else is installed."""
    root = tmp_path_factory.mktemp("jupyter")
    spec_dir = root / "kernels" / "python3"
    spec_dir.mkdir(parents=True)
    spec = {"argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
            "display_name": "Python 3 (specrefine venv)", "language": "python"}
    (spec_dir / "kernel.json").write_text(json.dumps(spec))
    env = dict(os.environ)
    env["JUPYTER_PATH"] = os.pathsep.join([str(root), *filter(None, [env.get("JUPYTER_PATH")])])
    env["MPLBACKEND"] = "Agg"
    env["PYDEVD_DISABLE_FILE_VALIDATION"] = "1"
    return env


def test_notebooks_are_found():
    names = [nb.name for nb in NOTEBOOKS]
    for expected in ("03_edge_split.ipynb", "04_vertex_refinement.ipynb", "05_astar_refinement.ipynb",
                     "06_experiments.ipynb"):
        assert expected in names


@pytest.mark.parametrize("nb", NOTEBOOKS, ids=[nb.stem for nb in NOTEBOOKS])
def test_notebook_has_uppercase_parameters(nb):
    cells = _parameters_cells(nb)
    assert len(cells) == 1, f"{nb.name}: needs exactly one cell tagged 'parameters', found {len(cells)}"
    names = _parameter_names(nb)
    assert names, f"{nb.name}: the parameters cell defines nothing"
    lower = sorted(n for n in names if not n.isupper())
    assert not lower, f"{nb.name}: parameters must be UPPERCASE names, got {lower}"
    overrides, _ = _smoke_settings(nb)
    assert set(overrides) <= names, f"{SMOKE_FILE.name}: {sorted(set(overrides) - names)} not parameters of {nb.name}"


@pytest.mark.notebooks
@pytest.mark.parametrize("nb", NOTEBOOKS, ids=[nb.stem for nb in NOTEBOOKS])
def test_notebook_runs_with_smoke_parameters(nb, tmp_path, venv_kernel_env):
    params, harness = _smoke_settings(nb)
    timeout = int(harness.get("timeout_s", DEFAULT_TIMEOUT_S))
    out = tmp_path / nb.name
    params_file = tmp_path / "params.json"  # JSON is YAML
    params_file.write_text(json.dumps(params))
    cmd = [sys.executable, "-m", "papermill", str(nb), str(out), "-f", str(params_file), "-k", "python3",
           "--cwd", str(NB_DIR), "--no-progress-bar", "--execution-timeout", str(timeout),
           "--start-timeout", "120"]
    proc = subprocess.Popen(cmd, env=venv_kernel_env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)
    try:
        log, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)  # papermill and the kernel it started, nothing else
        log, _ = proc.communicate()
        pytest.fail(f"{nb.name} did not finish within {timeout} s (smoke parameters {params}); "
                    f"partial output in {out}\n{log[-4000:]}")
    assert proc.returncode == 0, f"{nb.name} failed (smoke parameters {params}); executed copy in {out}\n{log[-6000:]}"
    executed = nbformat.read(out, as_version=4)
    errors = [o for c in executed.cells if c.cell_type == "code" for o in c.get("outputs", [])
              if o.get("output_type") == "error"]
    assert not errors, f"{nb.name}: error outputs in {out}"
    ran = [c for c in executed.cells if c.cell_type == "code" and c.source.strip()]
    assert all(c.get("execution_count") for c in ran), f"{nb.name}: some code cells did not run"
