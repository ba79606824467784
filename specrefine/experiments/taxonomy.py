"""Why a refinement run ended below the oracle: one cause per run, read from its folder (issue 39).

    specrefine taxonomy runs/taxonomy --oracle data/results/corrector/taxonomy_oracle.csv --out data/results/corrector

A run "ends below the oracle" when its success is more than ``--margin`` (0.05) below the mean success of ``ours``
with the ``geometric`` proposer (the oracle planner) on the same maze. Each such run gets the first cause that
applies, read from its ``steps.jsonl`` (what the search did) and its ``result.json`` (the path's legs as the search
estimated them, and as 200 fresh episodes measured them):

- ``budget-spent``: the path keeps a never-succeeding leg and the search had used its whole budget of edge splits;
- ``repair-gave-up``: the path keeps a never-succeeding leg; the look-ahead repair split a dead leg and that split
  had a dead leg of its own (or no candidate), so the repaired split was not feasible;
- ``split-declined-dead-legs``: the path keeps a never-succeeding leg; its split was generated, every candidate had
  a dead leg, and the split was declined (or the repair's feasible chain cost more than the dead edge);
- ``no-split-offered``: the path keeps a never-succeeding leg and no split of it gave any valid candidate (the
  proposer's replies were rejected, or it was never asked): an error that no split fixed;
- ``estimate-refuted``: every leg succeeds at times, and the search's estimate of some leg lies above the 95 %
  Wilson interval of that leg's success in the fresh episodes (a lucky estimate);
- ``weak-legs-accepted``: every leg succeeds at times, the estimates agree with the fresh episodes, and the path's
  legs together lose what the oracle's do not (small losses that compound).

Writes ``taxonomy.csv`` (one row per run below the oracle, with every cause that applies in ``flags``) and
``taxonomy.md`` (runs per cause, method and proposer).
"""

from __future__ import annotations

import csv
import json
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path

from ..core.errors import SpecrefineError
from ..core.mazes import random_name
from ..core.records import read_result
from ..core.results import wilson_ci
from ..core.runfolder import ensure_dir, locked, write_atomic
from ..core.tables import csv_text

CAUSES = ("budget-spent", "repair-gave-up", "split-declined-dead-legs", "no-split-offered", "estimate-refuted",
          "weak-legs-accepted")
MARGIN = 0.05
COLUMNS = ("cell", "maze", "method", "proposer", "seed", "success_rate", "oracle", "cause", "flags", "path_legs",
           "dead_legs", "refuted_legs", "weak_legs", "splits_generated", "max_edge_splits", "proposer_calls")


@dataclass
class Run:
    """What the taxonomy reads of one finished run folder."""

    cell: str
    result: dict
    steps: list = field(default_factory=list)

    @property
    def path_edges(self) -> list[tuple[str, str]]:
        path = self.result.get("path") or []
        return list(zip(path, path[1:]))


def read_run(folder: Path) -> Run | None:
    """A finished run (result.json and steps.jsonl), or None."""
    result_path, steps_path = folder / "result.json", folder / "steps.jsonl"
    if not (result_path.is_file() and steps_path.is_file()):
        return None
    result = read_result(result_path)
    try:
        steps = [json.loads(line) for line in steps_path.read_text().splitlines() if line.strip()]
    except (OSError, ValueError) as exc:
        raise SpecrefineError(f"{folder}: unreadable run ({exc})") from None
    return Run(folder.name, result, steps)


def oracle_means(table: Path) -> dict[str, float]:
    """Mean success per maze of ours with the geometric proposer in ``table`` (a sweep's results.csv)."""
    rates = defaultdict(list)
    with open(table, newline="") as fh:
        for row in csv.DictReader(fh):
            if row.get("method") == "ours" and row.get("proposer") == "geometric" and row.get("status") == "ok":
                rates[random_name(row["maze"])].append(float(row["success_rate"]))  # as result.json names it
    if not rates:
        raise SpecrefineError(f"{table}: no finished ours x geometric rows to take the oracle from")
    return {maze: sum(v) / len(v) for maze, v in rates.items()}


def refuted(estimate: float, measured: float | None, episodes: int) -> bool:
    """The search's estimate lies above the 95 % Wilson interval of the leg's success measured on ``episodes``."""
    if measured is None or episodes <= 0:
        return False
    return estimate > wilson_ci(round(measured * episodes), episodes)[1]


def flags_of(run: Run) -> dict:
    """Every cause that applies to ``run``, with the counts behind them."""
    r, steps = run.result, run.steps
    estimates = r.get("edge_probabilities") or []
    measured = r.get("leg_success") or []
    dead = [i for i, p in enumerate(estimates) if p <= 0.0]
    done = next((s for s in reversed(steps) if s.get("event") == "done"), {})
    splits, budget = done.get("splits_generated"), done.get("max_edge_splits")
    starts = _leg_starts(r)
    bad = [i for i, (p, m) in enumerate(zip(estimates, measured)) if p > 0 and refuted(p, m, starts[i])]
    weak = [i for i, p in enumerate(estimates) if 0.0 < p < 1.0]
    dead_edges = {run.path_edges[i] for i in dead if i < len(run.path_edges)}
    generated = [s for s in steps if s.get("event") == "split-generated" and tuple(s.get("edge", ())) in dead_edges]
    repaired = [s for s in steps if s.get("event") == "split-repaired" and tuple(s.get("edge", ())) in dead_edges]
    flags = []
    if dead:
        if splits is not None and budget is not None and splits >= budget:
            flags.append("budget-spent")
        if any(s.get("p_after") is None or min(s["p_after"]) <= 0.0 for s in repaired):
            flags.append("repair-gave-up")
        if any(s.get("candidates") for s in generated):
            flags.append("split-declined-dead-legs")
        else:
            flags.append("no-split-offered")
    else:
        if bad:
            flags.append("estimate-refuted")
        flags.append("weak-legs-accepted")
    return {"flags": flags, "dead_legs": len(dead), "refuted_legs": len(bad), "weak_legs": len(weak),
            "splits_generated": splits, "max_edge_splits": budget}


def _leg_starts(result: dict) -> list[int]:
    """Episodes that started each leg of the path, from the run's per-leg success and its episode count."""
    episodes = int(result.get("episodes") or 0)
    out, alive = [], float(episodes)
    for p in result.get("leg_success") or []:
        out.append(round(alive))
        alive *= p if p is not None else 0.0
    return out


def classify(runs: list[Run], oracle: dict[str, float], margin: float = MARGIN) -> list[dict]:
    """One row per run that ends more than ``margin`` below the oracle on its maze (see the module docstring)."""
    rows = []
    for run in runs:
        r = run.result
        maze = r.get("maze")
        if maze not in oracle or r.get("success_rate") is None or r["success_rate"] >= oracle[maze] - margin:
            continue
        f = flags_of(run)
        cause = next(c for c in CAUSES if c in f["flags"])
        rows.append({"cell": run.cell, "maze": maze, "method": r.get("method"), "proposer": r.get("proposer"),
                     "seed": r.get("seed"), "success_rate": r["success_rate"], "oracle": round(oracle[maze], 4),
                     "cause": cause, "flags": " ".join(f["flags"]), "path_legs": len(run.path_edges),
                     "dead_legs": f["dead_legs"], "refuted_legs": f["refuted_legs"], "weak_legs": f["weak_legs"],
                     "splits_generated": f["splits_generated"], "max_edge_splits": f["max_edge_splits"],
                     "proposer_calls": r.get("proposer_calls")})
    return rows


def summary_md(rows: list[dict], runs: list[Run], margin: float = MARGIN) -> str:
    """Runs per cause, for each method and proposer (the runs read beside)."""
    total = Counter((r.result.get("method"), r.result.get("proposer")) for r in runs)
    counts = Counter((row["method"], row["proposer"], row["cause"]) for row in rows)
    lines = [f"Runs more than {margin:.2f} below the oracle (ours x geometric, mean per maze), by their first cause "
             "(specrefine/experiments/taxonomy.py). Every proposer here is offline, NOT a VLM.", "",
             "| method | proposer | runs | below the oracle | " + " | ".join(CAUSES) + " |",
             "|---|---|---|---|" + "---|" * len(CAUSES)]
    for method, proposer in sorted(total):
        below = sum(counts[(method, proposer, c)] for c in CAUSES)
        lines.append(f"| {method} | {proposer} | {total[(method, proposer)]} | {below} | "
                     + " | ".join(str(counts[(method, proposer, c)]) for c in CAUSES) + " |")
    return "\n".join(lines) + "\n"


def run_folders(folder: Path) -> list[Path]:
    """A sweep folder's cells (``cells/*``), or the run folder itself."""
    return sorted((folder / "cells").iterdir()) if (folder / "cells").is_dir() else [folder]


def read_runs(folders: list[Path]) -> list[Run]:
    """Every finished run under the sweep folders (their ``cells/*``) or run folders given."""
    runs = []
    for folder in folders:
        if not folder.is_dir():
            raise SpecrefineError(f"{folder}: not a folder")
        runs += [run for run in map(read_run, run_folders(folder)) if run is not None]
    return runs


def add_arguments(p) -> None:
    from ..core.argtypes import out_path

    p.description = __doc__.split("\n\n")[0]
    p.add_argument("runs", nargs="+", type=Path, help="sweep folders (their cells/) or run folders")
    p.add_argument("--oracle", type=Path, required=True, help="a results table with ours x geometric rows")
    p.add_argument("--margin", type=float, default=MARGIN, help="below the oracle by more than this (default: 0.05)")
    p.add_argument("--out", type=out_path, default=None,
                   help="folder for taxonomy.csv and taxonomy.md (default: the summary printed only)")


def run(args, p) -> int:
    runs = read_runs(args.runs)
    rows = classify(runs, oracle_means(args.oracle), args.margin)
    text = summary_md(rows, runs, args.margin)
    if args.out is None:
        print(text, end="")
        return 0
    with locked(ensure_dir(args.out)):
        write_atomic(args.out / "taxonomy.csv", csv_text(rows, COLUMNS))
        write_atomic(args.out / "taxonomy.md", text)
    print(f"{len(rows)} of {len(runs)} runs below the oracle -> {args.out}/taxonomy.{{csv,md}}")
    return 0


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("taxonomy", argv, prog="python -m specrefine.experiments.taxonomy")


if __name__ == "__main__":
    raise SystemExit(main())
