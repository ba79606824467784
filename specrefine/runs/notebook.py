"""Key figures of a notebook, recorded in its outputs so that tests (and readers) can read them back.

In a notebook::

    from specrefine import record
    record("predicted_success", run.data["predicted_success"], tol=1 / ROLLOUTS)

displays one line (``predicted_success = 1.0  (± 0.125)``) and, in the same output, a JSON bundle of
MIME type ``application/vnd.specrefine.record+json`` that papermill keeps in the executed notebook.
``read_records(path)`` returns ``{name: {"value": ..., "tol": ..., "rel": ...}}`` from an executed
notebook; ``tests/test_notebooks.py`` compares them with ``tests/notebook_expected/*.json``.

``tol`` (absolute) and ``rel`` (relative) say how far the figure may move at the same seed and
parameters on another x86-64 CPU, where batched float math differs in the last bits; leave both
out for a value that must match exactly (paths, counts, names). A success rate estimated from n
rollouts is a count over n: ``tol=1 / n`` allows one borderline rollout to come out the other way.
The same idea as recommenders' ``store_metadata`` / scrapbook's ``glue``, without a dependency.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
from pathlib import Path

MIME = "application/vnd.specrefine.record+json"
PACKAGE_DIR = Path(__file__).resolve().parents[1]  # specrefine/, above runs/
NB_DIR = PACKAGE_DIR.parent / "notebooks"
TIERS = {"smoke": "smoke.json", "full": "full.json"}  # parameter files in notebooks/ (smoke.json is optional)
HARNESS_KEYS = {"timeout_s", "note"}
DEFAULT_TIMEOUT_S = 300


def _jsonable(value):
    """Plain JSON types: numpy scalars and arrays, tuples and paths become floats, ints, lists, strings."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return float(value)
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, Path):
        return str(value)
    if hasattr(value, "tolist"):  # numpy scalar or array, torch tensor
        return _jsonable(value.tolist())
    raise TypeError(f"record: cannot store a {type(value).__name__} ({value!r}); give a number, string or list")


def record(name: str, value, *, tol: float | None = None, rel: float | None = None):
    """Display ``name = value`` and store it in the cell's output for ``read_records``; returns the value."""
    from IPython.display import display

    stored = _jsonable(value)
    if isinstance(stored, float) and not math.isfinite(stored):
        stored = str(stored)  # JSON has no inf/nan; compare as text
    bounds = [f"± {tol:g}" if tol is not None else "", f"± {rel:.0%} rel" if rel is not None else ""]
    text = f"{name} = {stored!r}" + (f"  ({', '.join(b for b in bounds if b)})" if any(bounds) else "")
    payload = {"name": name, "value": stored, "tol": tol, "rel": rel}
    display({MIME: payload, "text/plain": text}, raw=True,
            metadata={MIME: {"package": str(PACKAGE_DIR)}})
    return value


#: a notebook parameter -> the command-line rule it follows: a LIMITS name (argtypes), or "agent", "method",
#: "proposer" (a list of them for the plural names)
PARAMETER_RULES = {"ROLLOUTS": "rollouts", "EPISODES": "episodes", "EVAL_EPISODES": "episodes", "SEED": "seed",
                   "SEEDS": ["seed"], "W": "w", "D": "d", "K": "k", "WORKERS": "workers", "CHAIN": "chain",
                   "AGENT": "agent", "METHOD": "method", "METHODS": ["method"], "PROPOSER": "proposer",
                   "PROPOSERS": ["proposer"], "GOAL_POINTS": "goal_points"}


def check_parameters(params: dict) -> None:
    """A notebook's parameters (its ``globals()`` after the parameters cell) checked by the command line's rules
    (``specrefine refine`` / ``python -m specrefine.runs.sweep``): a bad value is a one-line
    :class:`~specrefine.core.errors.SpecrefineError` naming the parameter, before the notebook does any work."""
    for name, rule in PARAMETER_RULES.items():
        if name not in params:
            continue
        value = params[name]
        if isinstance(rule, list):
            if not isinstance(value, (list, tuple)) or not value:
                raise _bad(name, value, "a non-empty list")
            for item in value:
                _check_value(name, item, rule[0])
        else:
            _check_value(name, value, rule)


def _check_value(name: str, value, rule: str) -> None:
    import argparse

    from ..core.agents import AGENTS
    from ..core.argtypes import LIMITS, bounded_int
    from .config import proposer_arg
    from .pipeline import METHODS

    if rule in LIMITS:
        if isinstance(value, bool) or not isinstance(value, int):
            raise _bad(name, value, "a whole number")
        check = bounded_int(rule)
    else:
        from ..evaluation.evaluator import GOAL_POINTS

        names = {"agent": AGENTS, "method": METHODS, "goal_points": GOAL_POINTS}.get(rule)

        def check(text):
            if names is not None and text not in names:
                raise argparse.ArgumentTypeError(f"use one of {', '.join(names)}")
            return proposer_arg(text) if rule == "proposer" else text

        if not isinstance(value, str):
            raise _bad(name, value, "a string")
    try:
        check(str(value))
    except argparse.ArgumentTypeError as exc:
        raise _bad(name, value, str(exc)) from None


def _bad(name: str, value, why: str):
    from ..core.errors import SpecrefineError

    return SpecrefineError(f"notebook parameter {name} = {value!r}: {why}")


def read_records(notebook) -> dict:
    """``{name: {"value", "tol", "rel", "package"}}`` from an executed notebook (a path or an nbformat node)."""
    import nbformat

    nb = nbformat.read(str(notebook), as_version=4) if isinstance(notebook, (str, Path)) else notebook
    found = {}
    for cell in nb.cells:
        for out in cell.get("outputs", []) if cell.cell_type == "code" else []:
            payload = out.get("data", {}).get(MIME)
            if payload is None:
                continue
            if payload["name"] in found:
                raise ValueError(f"figure {payload['name']!r} recorded twice")
            package = out.get("metadata", {}).get(MIME, {}).get("package")
            found[payload["name"]] = {"value": payload["value"], "tol": payload.get("tol"),
                                      "rel": payload.get("rel"), "package": package}
    return found


def compare(recorded: dict, expected: dict) -> list[str]:
    """Mismatches between ``read_records`` output and ``{name: {"value", "tol"?, "rel"?}}``, one line each.

    Every recorded figure needs an expected value and every expected one must be recorded. Strings,
    booleans and None match exactly; numbers within ``tol + rel * |expected|`` (exactly when neither is
    given); lists and dicts element by element with the figure's tolerance.
    """
    problems = []
    for name in sorted(set(expected) - set(recorded)):
        problems.append(f"figure {name!r}: expected {expected[name]['value']!r} but the notebook did not record it")
    for name in sorted(set(recorded) - set(expected)):
        problems.append(f"figure {name!r} = {recorded[name]['value']!r}: recorded but has no expected value")
    for name in sorted(set(recorded) & set(expected)):
        exp = expected[name]
        tol, rel = exp.get("tol") or 0.0, exp.get("rel") or 0.0
        for where, got, want in _diff(recorded[name]["value"], exp["value"], tol, rel, name):
            bound = "exactly" if not (tol or rel) else f"within {tol:g}" + (f" + {rel:g} relative" if rel else "")
            problems.append(f"figure {where} = {got!r}, expected {want!r} {bound}")
    return problems


def _diff(got, want, tol, rel, where):
    def number(x):
        return isinstance(x, (int, float)) and not isinstance(x, bool)

    if number(got) and number(want):
        if abs(got - want) > tol + rel * abs(want) + 1e-12 * (tol > 0 or rel > 0):
            yield where, got, want
    elif isinstance(got, list) and isinstance(want, list):
        if len(got) != len(want):
            yield f"{where} (length {len(got)}, expected {len(want)})", got, want
        else:
            for i, (g, w) in enumerate(zip(got, want)):
                yield from _diff(g, w, tol, rel, f"{where}[{i}]")
    elif isinstance(got, dict) and isinstance(want, dict):
        if set(got) != set(want):
            yield f"{where} (keys differ: {sorted(set(got) ^ set(want))})", got, want
        else:
            for k in want:
                yield from _diff(got[k], want[k], tol, rel, f"{where}[{k!r}]")
    elif got != want or type(got) is not type(want):
        yield where, got, want


def tier_settings(nb: Path, tier: str) -> tuple[dict, dict]:
    """(parameter overrides, harness settings) of one notebook in ``notebooks/<tier>.json``.

    Keys are notebook file names or stems; keys starting with ``_`` are comments. UPPERCASE keys
    are parameters, lowercase ones harness settings: ``timeout_s`` (whole notebook) and ``note``
    (what the tier is for this notebook, shown at the top of an executed copy).
    """
    path = NB_DIR / TIERS[tier]
    table = json.loads(path.read_text()) if path.exists() else {}
    entry = {**table.get(nb.stem, {}), **table.get(nb.name, {})}
    params = {k: v for k, v in entry.items() if k.isupper()}
    harness = {k: v for k, v in entry.items() if not k.isupper() and not k.startswith("_")}
    unknown = set(harness) - HARNESS_KEYS
    if unknown:
        raise ValueError(f"{path.name}: unknown settings {sorted(unknown)} for {nb.name}")
    return params, harness


KERNEL = "specrefine"  # the kernel the notebooks' metadata names (`make venv` / `make lab` register it in .venv)


def kernel_env(root: Path, mpl_backend: str | None = "Agg") -> dict:
    """Environment whose Jupyter kernels ``specrefine`` (:data:`KERNEL`, the name in the notebooks' metadata) and
    ``python3`` are this interpreter, whatever else is installed or not; PYTHONPATH passes through.

    ``mpl_backend="Agg"`` (the test runs: no figure is rendered to PNG unless a cell asks for one);
    ``None``: the kernel's own inline backend, as a reader gets it (``display(fig)`` shows a picture).
    """
    spec = {"argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
            "display_name": "Python 3 (specrefine)", "language": "python"}
    for name in (KERNEL, "python3"):
        spec_dir = Path(root) / "kernels" / name
        spec_dir.mkdir(parents=True, exist_ok=True)
        (spec_dir / "kernel.json").write_text(json.dumps(spec))
    env = dict(os.environ)
    env["JUPYTER_PATH"] = os.pathsep.join([str(root), *filter(None, [env.get("JUPYTER_PATH")])])
    env.pop("MPLBACKEND", None)
    if mpl_backend:
        env["MPLBACKEND"] = mpl_backend
    env["PYDEVD_DISABLE_FILE_VALIDATION"] = "1"
    return env


def execute(nb: Path, out: Path, params: dict, *, env: dict, timeout: int,
            cwd: Path = NB_DIR) -> tuple[int | None, str]:
    """Run ``nb`` through papermill in a subprocess (hard timeout); (return code or None on timeout, log)."""
    out = Path(out)
    params_file = out.with_suffix(".params.json")  # JSON is YAML
    params_file.write_text(json.dumps(params))
    cmd = [sys.executable, "-m", "papermill", str(nb), str(out), "-f", str(params_file), "-k", KERNEL,
           "--cwd", str(cwd), "--no-progress-bar", "--execution-timeout", str(timeout), "--start-timeout", "120"]
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)
    try:
        log, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)  # papermill and the kernel it started, nothing else
        log, _ = proc.communicate()
        return None, log
    return proc.returncode, log


def _git(*args) -> str:
    try:
        return subprocess.run(["git", "-C", str(NB_DIR.parent), *args], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""


def for_readers(nb):
    """``nb`` (an executed nbformat node) without what only this run and machine had: papermill's per-cell
    timestamps (a regenerated copy differs only where results do) and the package path ``record`` notes for the
    test's kernel check (a local path). Returns ``nb``, changed in place."""
    nb.metadata.pop("papermill", None)
    for cell in nb.cells:
        cell.metadata.pop("papermill", None)
        cell.metadata.pop("execution", None)
        for out in cell.get("outputs", []):
            meta = out.get("metadata", {})
            meta.get(MIME, {}).pop("package", None)
            if MIME in meta and not meta[MIME]:
                del meta[MIME]
    return nb


def write_executed(stems: list[str] | None, tier: str, out_dir: Path) -> int:
    """Executed copies of the notebooks (outputs and figures) for readers; 0 when all ran."""
    from ..core.errors import SpecrefineError
    from ..core.runfolder import ensure_dir, locked, output_file

    numbered = sorted(NB_DIR.glob("[0-9][0-9]_*.ipynb"))
    if unmatched := [s for s in stems or () if not any(nb.stem.startswith(s) for nb in numbered)]:
        raise SpecrefineError(f"no numbered notebook matches {', '.join(map(repr, unmatched))} "
                              f"(have: {', '.join(nb.stem for nb in numbered)})")
    chosen = [nb for nb in numbered if not stems or any(nb.stem.startswith(s) for s in stems)]
    out_dir = ensure_dir(out_dir)
    outs = [output_file(out_dir / nb.name) for nb in chosen]  # all checked before the first notebook runs
    runs = ensure_dir(NB_DIR.parent / "runs" / "executed")
    with locked(runs):  # another `notebook executed` would delete these folders under this one
        return _execute_all(chosen, outs, tier, runs)


def _execute_all(notebooks: list[Path], outs: list[Path], tier: str, runs: Path) -> int:
    import shutil
    import tempfile
    import time

    import nbformat
    from nbformat.v4 import new_markdown_cell

    from ..core.runfolder import write_atomic

    commit = _git("rev-parse", "--short=12", "HEAD") or "unknown"
    dirty = bool(_git("status", "--porcelain", "--untracked-files=no", "--", "specrefine", "notebooks", "data"))
    failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        env = kernel_env(Path(tmp), mpl_backend=None)  # the inline backend, as a reader's kernel has it
        env["PYTHONPATH"] = os.pathsep.join([str(NB_DIR.parent), *filter(None, [env.get("PYTHONPATH")])])
        for nb, out in zip(notebooks, outs):
            params, harness = tier_settings(nb, tier)
            run_dir = runs / nb.stem  # fresh: no evaluation cache from earlier runs
            if run_dir.is_symlink():
                run_dir.unlink()  # the link only: what it points at is not this command's
            shutil.rmtree(run_dir, ignore_errors=True)
            params = {**params, "OUT_DIR": f"../runs/executed/{nb.stem}"}
            ran = Path(tmp) / nb.name  # papermill's own output; the copy for readers is written whole below
            t0 = time.time()
            code, log = execute(nb, ran, params, env=env, timeout=int(harness.get("timeout_s", DEFAULT_TIMEOUT_S)))
            wall = time.time() - t0
            print(f"{nb.name}: {'ok' if code == 0 else 'FAILED'} in {wall:.0f} s -> {out}", flush=True)
            if code != 0:
                failed += 1
                print(log[-3000:])
                if not ran.exists():
                    continue
            copy = for_readers(nbformat.read(ran, as_version=4))
            shown = ", ".join(f"{k}={v!r}" for k, v in params.items() if k != "OUT_DIR") or "the notebook's defaults"
            note = harness.get("note", "")
            header = (f"> **Executed copy** of [`notebooks/{nb.name}`](../{nb.name}) for reading: produced by "
                      f"`make executed` at commit `{commit}`{' (with uncommitted changes)' if dirty else ''}, "
                      f"{time.strftime('%Y-%m-%d')}, in {wall / 60:.1f} min on a 2-core CPU machine, with the "
                      f"**{tier}** parameters of `notebooks/{TIERS[tier]}`: {shown}."
                      + (f"\n>\n> {note}" if note else "")
                      + "\n>\n> The widget (notebook 05's slider) needs a live kernel; edit and run the notebook "
                        "itself, not this copy.")
            copy.cells.insert(0, new_markdown_cell(header))
            copy.metadata["specrefine"] = {"executed_copy_of": f"notebooks/{nb.name}", "commit": commit,
                                           "uncommitted_changes": dirty, "tier": tier, "parameters": params,
                                           "ok": code == 0, "wall_s": round(wall)}
            write_atomic(out, nbformat.writes(copy) + "\n")
    return 1 if failed else 0


def add_arguments(p) -> None:
    from ..core.argtypes import out_path

    p.description = "Executed copies of the numbered notebooks (make executed); needs the 'notebooks' extra."
    sub = p.add_subparsers(dest="notebook_command", required=True, metavar="{executed}")
    what = "run the notebooks with a tier's parameters and keep the outputs"
    ex = sub.add_parser("executed", help=what, description=what)
    ex.add_argument("--tier", choices=sorted(TIERS), default="full", help="the parameters (notebooks/TIER.json)")
    ex.add_argument("--out", type=out_path, default=NB_DIR / "executed", help="where the executed copies go")
    ex.add_argument("notebooks", nargs="*", help="stems or number prefixes (e.g. 05); default all")


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("notebook", argv, prog="python -m specrefine.runs.notebook")


def run(args, p) -> int:
    from ..core.extras import require

    for module in ("papermill", "nbformat", "ipykernel"):  # what executing a notebook needs
        require(module, "notebooks", "specrefine notebook")
    return write_executed(args.notebooks, args.tier, args.out)


if __name__ == "__main__":
    sys.exit(main())
