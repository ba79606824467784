"""Legs per room, per-leg failure and cost of the runs of sweep tables, one markdown line per (maze, method, proposer,
policy) pooled over seeds (issue 30: where a long chain loses its episodes).

    python -m specrefine.experiments.legs data/results/ant/comparison.csv --method ours --proposer geometric
    python -m specrefine.experiments.legs data/results/ant/levers_*.csv

Per-leg failure is 1 - s^(1/L) with s the pooled success and L the mean number of legs on the measured paths: what
each leg would lose if legs failed independently and alike. Rooms: N of a ``u_chain_N`` maze (blank otherwise).
"""
import argparse
import re
import sys

from ..core.argtypes import exit_code_quiet_on_broken_pipe
from ..core.errors import SpecrefineError
from ..core.results import wilson_ci
from ..runs.sweep import is_done, read_checked_table

HEADER = ("| maze | method | proposer | policy | seeds | success [95 % CI] | legs | legs per room | per-leg failure | "
          "evaluations | sim steps | wall s |\n|---|---|---|---|---|---|---|---|---|---|---|---|")


def rooms(maze: str) -> int | None:
    m = re.fullmatch(r"u_chain_(\d+)(_subgoals)?", maze)
    return int(m.group(1)) if m else None


def line(key: tuple, runs: list[dict]) -> str:
    maze, method, proposer, policy = key
    ok = sum(round(r["success_rate"] * r["episodes"]) for r in runs)
    n = sum(int(r["episodes"]) for r in runs)
    lo, hi = wilson_ci(ok, n)
    legs = sum(r["path_edges"] for r in runs) / len(runs)
    per_room = f"{legs / rooms(maze):.1f}" if rooms(maze) else ""
    fail = 1 - (ok / n) ** (1 / legs) if legs and ok else float("nan")
    mean = lambda k: sum(r[k] for r in runs) / len(runs)  # noqa: E731
    return (f"| {maze} | {method} | {proposer} | {policy} | {len(runs)} | {ok / n:.3f} [{lo:.3f}, {hi:.3f}] | "
            f"{legs:.1f} | {per_room} | {fail:.4f} | {mean('evaluations'):,.0f} | {mean('sim_steps'):,.0f} | "
            f"{mean('wall_seconds'):.0f} |")


def report(tables, method=None, proposer=None) -> str:
    groups: dict[tuple, list[dict]] = {}
    for table in tables:
        for r in read_checked_table(table):
            if is_done(r) and method in (None, r["method"]) and proposer in (None, r["proposer"]):
                policy = str(r.get("policy") or "shipped").rsplit("/", 1)[-1]
                groups.setdefault((r["maze"], r["method"], r["proposer"], policy), []).append(r)
    order = sorted(groups, key=lambda k: (rooms(k[0]) or 0, k))
    return "\n".join([HEADER, *(line(k, groups[k]) for k in order)])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m specrefine.experiments.legs", description=__doc__.splitlines()[0])
    ap.add_argument("tables", nargs="+")
    ap.add_argument("--method")
    ap.add_argument("--proposer")
    args = ap.parse_args(argv)
    try:
        print(report(args.tables, args.method, args.proposer))
    except SpecrefineError as exc:  # a missing or malformed table: one line
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
