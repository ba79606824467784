"""Fold the controls' rerun (bash scripts/run_grid.sh controls) into the offline comparison's table (issue 27).

    python scripts/merge_controls.py data/results/imperfect/results.csv data/results/controls/results.csv

The table's `ours-novertex` rows were run when that name meant "no vertex refinement by the search" (an edge split
still tuned its later candidates with Algorithm 2): they become `ours-nosearchvertex`, the name of that behaviour
now (the same code path: 12 of its cells run again with today's code agree in every outcome column, see
data/results/README.md). The rerun's rows (ours-novertex as redefined, ours-notune, ours-nofeedback) are appended.
Refuses to run twice (the table would hold two ours-novertex definitions).
"""

from __future__ import annotations

import argparse
import csv
import sys

from specrefine.core.runfolder import replacing


def main(table: str, controls: str) -> int:
    with open(table, newline="") as fh:
        reader = csv.DictReader(fh)
        header, rows = reader.fieldnames, list(reader)
    if any(r["method"] == "ours-nosearchvertex" for r in rows):
        print(f"{table} already holds ours-nosearchvertex rows: merged before", file=sys.stderr)
        return 2
    for r in rows:
        if r["method"] == "ours-novertex":
            r["method"] = "ours-nosearchvertex"
            r["cell"] = r["cell"].replace("__ours-novertex__", "__ours-nosearchvertex__")
    with open(controls, newline="") as fh:
        new = [{k: r.get(k, "") for k in header} for r in csv.DictReader(fh)]
    with replacing(table, "w", newline="") as fh:  # whole, never through a link
        writer = csv.DictWriter(fh, header)
        writer.writeheader()
        writer.writerows(rows + new)
    print(f"{table}: {len(rows)} rows ({sum(r['method'] == 'ours-nosearchvertex' for r in rows)} renamed) "
          f"+ {len(new)} from {controls}")
    return 0


if __name__ == "__main__":
    from specrefine.core.argtypes import script_exit_code

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("table", help="the offline comparison's results.csv (rewritten whole)")
    ap.add_argument("controls", help="the controls' results.csv (its rows appended)")
    args = ap.parse_args()
    raise SystemExit(script_exit_code(main, args.table, args.controls))
