"""One markdown line per run of a sweep table: success and predicted success with their 95 % intervals, and the cost.

    python scripts/per_maze_report.py data/results/ant/comparison.csv --method ours --proposer geometric

The closing notes' per-maze lists (issue 15) are this script's output; runs without an ``ok`` row are listed as
such, so a partial table says what it lacks.
"""
import argparse

from specrefine.sweep import is_done, read_table


def line(r: dict) -> str:
    if not is_done(r):
        return f"| {r['maze']} | {r['seed']} | {r.get('status')}: {r.get('error', '')[:60]} | | | | |"
    pred = (f"{r['predicted_success']:.3f} [{r['predicted_ci_low']:.3f}, {r['predicted_ci_high']:.3f}]"
            if isinstance(r.get("predicted_ci_low"), float) else "—")
    inside = ("" if pred == "—" else
              " (inside)" if r["predicted_ci_low"] <= r["success_rate"] <= r["predicted_ci_high"] else " (OUTSIDE)")
    return (f"| {r['maze']} | {r['seed']} | {r['success_rate']:.3f} [{r['success_ci_low']:.3f}, "
            f"{r['success_ci_high']:.3f}] | {pred}{inside} | {r['evaluations']:,} | {r['sim_steps']:,} | "
            f"{r['wall_seconds']:.0f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("table")
    ap.add_argument("--method", required=True)
    ap.add_argument("--proposer", default=None, help="default: any (dirl and symbolic have 'none')")
    args = ap.parse_args()
    rows = [r for r in read_table(args.table) if r.get("method") == args.method
            and (args.proposer is None or r.get("proposer") == args.proposer)]
    rows.sort(key=lambda r: (r["maze"], r["seed"]))
    print(f"{args.method} / {args.proposer or 'any proposer'}: {len(rows)} runs ({args.table})\n")
    print("| maze | seed | success [95 % CI] | predicted [95 % CI] | evaluations | sim steps | wall s |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(line(r))


if __name__ == "__main__":
    main()
