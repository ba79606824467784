"""Run every numbered notebook through papermill and check the key figures it records.

Two tiers of parameters:

* **smoke** (default suite, marker ``notebooks``): each notebook's own ``parameters`` cell, with
  optional overrides from ``notebooks/smoke.json``;
* **full** (marker ``notebooks_full``, skipped unless selected: ``make notebooks-full`` or
  ``pytest -m notebooks_full``): the overrides in ``notebooks/full.json``.

Keys of those files are notebook file names or stems (``_``-keys are comments). UPPERCASE keys are
parameters (each must exist in the notebook's ``parameters`` cell); lowercase keys are harness
settings: ``timeout_s`` (whole notebook, default 300 s) and ``note``. ``OUT_DIR`` is always set to a
fresh temporary directory, so no evaluation cache from an earlier run changes the counts. The
notebook runs in a subprocess (so the timeout is hard) with cwd ``notebooks/``, on a kernel named
``specrefine`` (the notebooks' own, passed to papermill explicitly) that is this interpreter
(PYTHONPATH passes through; the test checks that the kernel
imported THIS checkout's ``specrefine``), with ``MPLBACKEND=Agg``.

**Values under regression.** The last cell of every notebook calls ``specrefine.record(name,
value, tol=..., rel=...)`` for its key figures (success probabilities, predicted and measured
success, evaluation counts, the chosen path). ``test_notebook_values_*`` reads them back from the
executed notebook of the run test (each notebook runs once per tier) and compares them with
``tests/notebook_expected/<tier>.json``: discrete values (paths, counts, names) exactly, floats
within the tolerance stored with them (one rollout or episode out of n: how far a figure may move at
the same seed on another x86-64 CPU). The failure message names the notebook and the figure.

**Regenerating the expected values is a decision, not a fix.** When a test here fails, first find out
why the figure moved. Only when the new behaviour is intended, regenerate and commit the diff with
the reason::

    make notebook-expected         # smoke tier: pytest -m notebooks --update-notebook-expected
    make notebook-expected-full    # full tier

The tolerances written are the ones the notebook's ``record`` calls state.
"""

from __future__ import annotations

import json
from pathlib import Path

import nbformat
import pytest

from specrefine.runs.notebook import DEFAULT_TIMEOUT_S, TIERS, compare, execute, kernel_env, read_records, tier_settings

REPO = Path(__file__).resolve().parent.parent  # the checkout under test (its kernel must import this one)
NOTEBOOKS = sorted((REPO / "notebooks").glob("[0-9][0-9]_*.ipynb"))
EXPECTED_DIR = Path(__file__).resolve().parent / "notebook_expected"
IDS = [nb.stem for nb in NOTEBOOKS]
_EXECUTED: dict[tuple[str, str], tuple[Path | None, str]] = {}  # (tier, stem) -> (executed copy or None, failure)


def _parameters_cells(nb: Path):
    return [c for c in nbformat.read(nb, as_version=4).cells if "parameters" in c.get("metadata", {}).get("tags", [])]


def _parameter_names(nb: Path) -> set[str]:
    import papermill

    return set(papermill.inspect_notebook(str(nb)))


@pytest.fixture(scope="session")
def venv_kernel_env(tmp_path_factory) -> dict:
    """Environment whose kernel 'specrefine' is this interpreter (the venv), whatever else is installed."""
    return kernel_env(tmp_path_factory.mktemp("jupyter"))


def _run(nb: Path, tier: str, tmp_root: Path, env: dict) -> Path:
    """Execute ``nb`` with ``tier``'s parameters once per session; the executed copy (or pytest.fail)."""
    key = (tier, nb.stem)
    if key not in _EXECUTED:
        params, harness = tier_settings(nb, tier)
        work = tmp_root / f"{tier}_{nb.stem}"
        work.mkdir(parents=True, exist_ok=True)
        if "OUT_DIR" in _parameter_names(nb):
            params = {**params, "OUT_DIR": str(work / "out")}
        timeout = int(harness.get("timeout_s", DEFAULT_TIMEOUT_S))
        out = work / nb.name
        code, log = execute(nb, out, params, env=env, timeout=timeout)
        failure = ""
        if code is None:
            failure = f"{nb.name} did not finish within {timeout} s ({tier} parameters {params}); " \
                      f"partial output in {out}\n{log[-4000:]}"
        elif code != 0:
            failure = f"{nb.name} failed ({tier} parameters {params}); executed copy in {out}\n{log[-6000:]}"
        else:
            executed = nbformat.read(out, as_version=4)
            errors = [o for c in executed.cells if c.cell_type == "code" for o in c.get("outputs", [])
                      if o.get("output_type") == "error"]
            ran = [c for c in executed.cells if c.cell_type == "code" and c.source.strip()]
            if errors:
                failure = f"{nb.name}: error outputs in {out}"
            elif not all(c.get("execution_count") for c in ran):
                failure = f"{nb.name}: some code cells did not run ({out})"
        _EXECUTED[key] = (out, failure)
    out, failure = _EXECUTED[key]
    if failure:
        pytest.fail(failure, pytrace=False)
    return out


def _check_values(nb: Path, tier: str, executed: Path, update: bool):
    recorded = read_records(executed)
    assert recorded, f"{nb.name}: no figures recorded (its last cell should call specrefine.record)"
    packages = {r["package"] for r in recorded.values()}
    assert packages == {str(REPO / "specrefine")}, \
        f"{nb.name}: the kernel imported specrefine from {packages}, not from this checkout {REPO}"
    path = EXPECTED_DIR / f"{tier}.json"
    table = json.loads(path.read_text()) if path.exists() else {}
    if update:
        table[nb.stem] = {name: {k: v for k, v in r.items() if k != "package" and v is not None}
                          for name, r in recorded.items()}
        EXPECTED_DIR.mkdir(exist_ok=True)
        path.write_text(json.dumps(dict(sorted(table.items())), indent=1) + "\n")
        return
    assert nb.stem in table, f"{nb.name}: no expected {tier} values in {path.relative_to(REPO)}; " \
                             f"regenerate deliberately with `make notebook-expected{'-full' * (tier == 'full')}`"
    problems = compare(recorded, table[nb.stem])
    assert not problems, (f"{nb.name} ({tier} parameters) moved from {path.relative_to(REPO)}:\n  "
                          + "\n  ".join(problems) + f"\nexecuted copy: {executed}\n(see this file's docstring "
                          "before regenerating: that is a decision, not a fix)")


def test_notebooks_are_found():
    names = [nb.name for nb in NOTEBOOKS]
    for expected in ("03_edge_split.ipynb", "04_vertex_refinement.ipynb", "05_astar_refinement.ipynb",
                     "06_experiments.ipynb"):
        assert expected in names


@pytest.mark.parametrize("nb", NOTEBOOKS, ids=IDS)
def test_notebook_has_uppercase_parameters(nb):
    cells = _parameters_cells(nb)
    assert len(cells) == 1, f"{nb.name}: needs exactly one cell tagged 'parameters', found {len(cells)}"
    names = _parameter_names(nb)
    assert names, f"{nb.name}: the parameters cell defines nothing"
    lower = sorted(n for n in names if not n.isupper())
    assert not lower, f"{nb.name}: parameters must be UPPERCASE names, got {lower}"
    for tier, file in TIERS.items():
        overrides, _ = tier_settings(nb, tier)
        assert set(overrides) <= names, f"{file}: {sorted(set(overrides) - names)} not parameters of {nb.name}"


@pytest.mark.parametrize("nb", NOTEBOOKS, ids=IDS)
def test_notebook_names_the_projects_kernel(nb):
    from specrefine.runs.notebook import KERNEL

    assert json.loads(nb.read_text())["metadata"]["kernelspec"]["name"] == KERNEL == "specrefine"


@pytest.mark.parametrize("nb", NOTEBOOKS, ids=IDS)
def test_notebook_committed_without_outputs(nb):
    cells = nbformat.read(nb, as_version=4).cells
    dirty = [i for i, c in enumerate(cells) if c.cell_type == "code" and (c.outputs or c.execution_count)]
    assert not dirty, f"{nb.name}: cells {dirty} carry outputs; executed copies belong in notebooks/executed/"


@pytest.mark.notebooks
@pytest.mark.parametrize("nb", NOTEBOOKS, ids=IDS)
def test_notebook_runs_with_smoke_parameters(nb, tmp_path_factory, venv_kernel_env):
    _run(nb, "smoke", tmp_path_factory.getbasetemp() / "notebooks", venv_kernel_env)


@pytest.mark.notebooks
@pytest.mark.parametrize("nb", NOTEBOOKS, ids=IDS)
def test_notebook_values_smoke(nb, tmp_path_factory, venv_kernel_env, request):
    executed = _run(nb, "smoke", tmp_path_factory.getbasetemp() / "notebooks", venv_kernel_env)
    _check_values(nb, "smoke", executed, request.config.getoption("--update-notebook-expected"))


@pytest.mark.notebooks_full
@pytest.mark.parametrize("nb", NOTEBOOKS, ids=IDS)
def test_notebook_values_full(nb, tmp_path_factory, venv_kernel_env, request):
    executed = _run(nb, "full", tmp_path_factory.getbasetemp() / "notebooks", venv_kernel_env)
    _check_values(nb, "full", executed, request.config.getoption("--update-notebook-expected"))


def test_the_readmes_papermill_command_keeps_out_dir_in_the_checkout():
    """Run from the checkout's root, README's papermill command runs the notebook from its own folder, so the
    notebook's relative OUT_DIR lands inside the checkout (it once wrote ``../runs/nb05`` one folder above it)."""
    import re
    import shlex

    readme = (REPO / "README.md").read_text()
    (line,) = [line for line in readme.splitlines() if line.startswith(".venv/bin/papermill ")]
    args = shlex.split(line)
    nb_path = REPO / args[1]
    cwd = REPO / args[args.index("--cwd") + 1]
    assert cwd == nb_path.parent
    params = "".join(_parameters_cells(nb_path)[0]["source"])
    out_dir = re.search(r'^OUT_DIR = "([^"]+)"', params, re.M).group(1)
    assert (cwd / out_dir).resolve().is_relative_to(REPO)
