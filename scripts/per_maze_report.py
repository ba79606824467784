"""One markdown line per run of a sweep table: success and predicted success with their 95 % intervals, and the cost.

    python scripts/per_maze_report.py data/results/ant/comparison.csv --method ours --proposer geometric
    python scripts/per_maze_report.py data/results/ant/comparison.csv --method ours --proposer geometric --pooled
    python scripts/per_maze_report.py data/results/ant/comparison.csv --pooled    # every method and proposer

The closing notes' per-maze lists (issue 15) are this script's output; runs without an ``ok`` row are listed as
such, so a partial table says what it lacks.
"""
import argparse

from specrefine.core.argtypes import exit_code_quiet_on_broken_pipe
from specrefine.core.results import wilson_ci
from specrefine.runs.sweep import is_done, read_table


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


def pooled_line(maze: str, runs: list[dict]) -> str:
    """One maze over its seeds: successes pooled over every episode (Wilson CI), predictions inside their CIs."""
    done = [r for r in runs if is_done(r)]
    if not done:
        return f"| {maze} | 0 of {len(runs)} | | | | | |"
    wins = sum(round(r["success_rate"] * r["episodes"]) for r in done)
    n = sum(r["episodes"] for r in done)
    lo, hi = wilson_ci(wins, n)
    inside = sum(r["predicted_ci_low"] <= r["success_rate"] <= r["predicted_ci_high"] for r in done)
    per_seed = ", ".join(f"{r['success_rate']:.3f}" for r in done)
    mean = lambda key: sum(r[key] for r in done) / len(done)  # noqa: E731
    return (f"| {maze} | {len(done)} of {len(runs)} | {wins}/{n} = {wins / n:.3f} [{lo:.3f}, {hi:.3f}] ({per_seed}) | "
            f"{mean('predicted_success'):.3f} ({inside} of {len(done)} inside) | {mean('evaluations'):,.0f} | "
            f"{mean('sim_steps') / 1e6:.2f}M | {mean('wall_seconds'):.0f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("table")
    ap.add_argument("--method", default=None, help="default: every method, one section per method and proposer")
    ap.add_argument("--proposer", default=None, help="default: any (dirl and symbolic have 'none')")
    ap.add_argument("--pooled", action="store_true", help="one line per maze, seeds pooled (means of the costs)")
    args = ap.parse_args()
    table = read_table(args.table)
    sections = [(args.method, args.proposer)] if args.method else sorted(
        {(r["method"], r["proposer"]) for r in table if args.proposer in (None, r["proposer"])})
    for i, (method, proposer) in enumerate(sections):
        print("\n" * (i > 0), end="")
        report(args.table, [r for r in table if r.get("method") == method
                            and (proposer is None or r.get("proposer") == proposer)], method, proposer, args.pooled)


def report(path, rows: list[dict], method: str, proposer: str | None, pooled: bool) -> None:
    rows = sorted(rows, key=lambda r: (r["maze"], r["seed"]))
    print(f"{method} / {proposer or 'any proposer'}: {len(rows)} runs ({path})\n")
    if pooled:
        print("| maze | runs done | success, pooled [95 % CI] (per seed) | predicted, mean (runs inside their CI) | "
              "evaluations | sim steps | wall s |")
        print("|---|---|---|---|---|---|---|")
        for maze in dict.fromkeys(r["maze"] for r in rows):
            print(pooled_line(maze, [r for r in rows if r["maze"] == maze]))
        return
    print("| maze | seed | success [95 % CI] | predicted [95 % CI] | evaluations | sim steps | wall s |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(line(r))


if __name__ == "__main__":
    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
