"""Run again, with this checkout's code, the cells behind the first N rows of a sweep table, into a new OUT.

    python scripts/rerun_table_rows.py data/results/imperfect/results.csv --rows 485 --out runs/imperfect_rerun \
        --workers 2

For a table whose first rows came from older code (data/results/imperfect: rows 1-485, commit 6f3114f): the cells
are rebuilt from the rows (maze, agent, method, proposer, seed, rollouts, episodes, spec), the sweep runs them
(resumable, as ``specrefine.runs.sweep``), and ``--compare`` lists the columns in which the new rows differ
from the old.
``--compare --shared`` compares only the cells both tables hold, e.g. the reruns inside another grid:

    python scripts/rerun_table_rows.py data/results/imperfect/results.csv --rows 1360 --out data/results/repair \
        --compare --shared
"""
import argparse
from pathlib import Path

from specrefine.runs.sweep import Cell, read_table, run_sweep

SEARCH_COLUMNS = ("success_rate", "evaluations", "proposer_calls", "path_edges", "graph_vertices", "graph_edges",
                  "refinements", "search_estimate")  # what a code change that keeps the search must keep


def cells_of(rows) -> list[Cell]:
    return [Cell.of(r["maze"], r["agent"], r["method"], r["proposer"], int(r["seed"]),
                    rollouts=int(r.get("rollouts_per_evaluation") or 32), episodes=int(r.get("episodes") or 200),
                    spec=r.get("spec") or "", evaluation=r.get("evaluation") or "fixed",
                    policy=r.get("policy") or "shipped", goal_points=r.get("goal_points") or "sampled") for r in rows]


def compare(old_rows, new_rows) -> list[str]:
    """One line per cell whose new row differs from the old one in a SEARCH_COLUMNS column."""
    new = {r["cell"]: r for r in new_rows}
    out = []
    for o in old_rows:
        n = new.get(o["cell"])
        if n is None:
            out.append(f"{o['cell']}: not rerun yet")
            continue
        diff = [f"{c} {o.get(c)} -> {n.get(c)}" for c in SEARCH_COLUMNS if o.get(c) != n.get(c)]
        if diff:
            out.append(f"{o['cell']}: " + "; ".join(diff))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("table")
    ap.add_argument("--rows", type=int, required=True, help="the first ROWS rows of TABLE")
    ap.add_argument("--out", required=True)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--compare", action="store_true", help="only compare OUT/results.csv with TABLE's rows")
    ap.add_argument("--shared", action="store_true",
                    help="with --compare: only the cells OUT/results.csv also holds (another grid's reruns)")
    args = ap.parse_args()
    old = read_table(args.table)[: args.rows]
    if not args.compare:
        run_sweep(cells_of(old), args.out, workers=args.workers)
    new = read_table(Path(args.out) / "results.csv")
    if args.shared:
        ids = {r["cell"] for r in new}
        old = [r for r in old if r["cell"] in ids]
    lines = compare(old, new)
    print("\n".join(lines) or f"all {len(old)} rows agree in {', '.join(SEARCH_COLUMNS)}")
    if lines and args.shared:
        print(f"({len(lines)} of {len(old)} shared cells differ)")


if __name__ == "__main__":
    from specrefine.core.argtypes import script_exit_code

    raise SystemExit(script_exit_code(main))
