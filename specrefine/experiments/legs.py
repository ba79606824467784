"""Legs per room, per-leg failure and cost of the runs of sweep tables, one markdown line per (maze, method, proposer,
policy) pooled over seeds (issue 30: where a long chain loses its episodes).

    python -m specrefine.experiments.legs data/results/ant/comparison.csv --method ours --proposer geometric
    python -m specrefine.experiments.legs data/results/ant/levers_*.csv

Per-leg failure is 1 - s^(1/L) with s the pooled success and L the mean number of legs on the measured paths: what
each leg would lose if legs failed independently and alike. Rooms: N of a ``u_chain_N`` maze (blank otherwise).

Leg profiles (``--profiles RUN/result.json ... --out FILE.json``): each run's measured per-leg failure (among the
episodes that started the leg) beside the search's estimate of that leg, small enough to ship, and
``profile_table`` on them: whether the lost episodes spread over every leg or gather on a few, and ``turn_table``:
the legs that turn against the straight ones, lost episodes pooled over the runs.

Leg kinds of re-run paths (``--failures FILE.json ...``, the reports of ``python -m specrefine.experiments.failures``):
flips, wall contacts (avoid) and timeouts per kind of leg (first, straight, turning at 45 degrees or more), pooled over
the files, with the walls (``kind_table``).
"""
import json
import sys

from ..core.argtypes import OneLineParser, exit_code_quiet_on_broken_pipe
from ..core.errors import SpecrefineError
from ..core.graph import TaskGraph
from ..core.mazes import u_chain
from ..core.results import wilson_ci
from ..core.runfolder import output_file, read_result, write_atomic
from ..runs.sweep import is_done, read_checked_table

HEADER = ("| maze | method | proposer | policy | seeds | success [95 % CI] | legs | legs per room | per-leg failure | "
          "evaluations | sim steps | wall s |\n|---|---|---|---|---|---|---|---|---|---|---|---|")


def rooms(maze: str) -> int | None:
    return chain[0] if (chain := u_chain(maze)) else None


def pooled(runs) -> tuple[int, int]:
    """(successes, episodes) over runs."""
    return sum(round(r["success_rate"] * r["episodes"]) for r in runs), sum(int(r["episodes"]) for r in runs)


def line(key: tuple, runs: list[dict]) -> str:
    maze, method, proposer, policy = key
    ok, n = pooled(runs)
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


def leg_turns(result: dict) -> list[float | None]:
    """Each leg's turn from the leg before it, in degrees between the lines joining its vertices' aims (a vertex's
    fixed point, else its set's centre); None for the first leg."""
    from .failures import path_aims, turn_angles

    path = result.get("path") or []
    if len(path) < 2 or not result.get("graph"):
        return []
    return [None if t is None else round(t, 1)
            for t in turn_angles(path_aims(TaskGraph.from_dict(result["graph"]), path))]


def leg_profile(result: dict) -> dict:
    """One run's legs: measured failure (1 - leg success on the 200 fresh episodes), the search's estimate and each
    leg's turn (:func:`leg_turns`)."""
    return {k: result.get(k) for k in ("maze", "method", "proposer", "seed", "episodes", "episode_outcomes")} | {
        "leg_failure": [round(1.0 - float(p), 6) for p in result.get("leg_success") or []],
        "search_estimate": [float(p) for p in result.get("edge_probabilities") or []],
        "turn_degrees": leg_turns(result)}


def leg_episodes(profile: dict) -> list[tuple[int, int]]:
    """(episodes that started the leg, episodes it lost) per leg, from the run's episodes and per-leg failures."""
    started, out = int(profile["episodes"]), []
    for failure in profile["leg_failure"]:
        lost = round(started * failure)
        out.append((started, lost))
        started -= lost
    return out


def turn_kind(turn: float | None, straight_below: float = 45.0) -> str:
    return "first leg" if turn is None else "straight" if turn < straight_below else "turning"


TURN_HEADER = ("| legs | count | episodes started | lost | failure per leg [95 % CI] |\n|---|---|---|---|---|")


LEG_KINDS = ("first leg", "straight", "turning")


def turn_table(profiles, after: bool = False) -> str:
    """Lost episodes pooled by the kind of leg (first, straight, turning at 45 degrees or more); ``after``: by the
    kind of the leg and of the leg before it ("straight after turning"), to tell a leg's own loss from what the
    leg before it hands on."""
    pooled_by: dict[str, list[int]] = {}
    for p in profiles:
        if not p.get("turn_degrees") or p.get("episodes") is None:
            raise SpecrefineError(f"profile of {p.get('maze')} seed {p.get('seed')} has no turns or episodes: make "
                                  "it again with --profiles from the run's result.json")
        kinds = [turn_kind(turn) for turn in p["turn_degrees"]]
        for i, (kind, (started, lost)) in enumerate(zip(kinds, leg_episodes(p), strict=True)):
            key = f"{kind} after {kinds[i - 1]}" if after and i else kind
            acc = pooled_by.setdefault(key, [0, 0, 0])
            acc[0], acc[1], acc[2] = acc[0] + 1, acc[1] + started, acc[2] + lost
    lines = [TURN_HEADER]
    order = [kind if not after or kind == LEG_KINDS[0] else f"{kind} after {before}"
             for kind in LEG_KINDS for before in (LEG_KINDS if after and kind != LEG_KINDS[0] else (None,))]
    for kind in order:
        if kind in pooled_by:
            count, started, lost = pooled_by[kind]
            lo, hi = wilson_ci(lost, started)
            lines.append(f"| {kind} | {count} | {started:,} | {lost} | {lost / started:.4f} [{lo:.4f}, {hi:.4f}] |")
    return "\n".join(lines)


KIND_HEADER = ("| legs | count | episodes started | flipped | avoid | timeout | failure per leg [95 % CI] |\n"
               "|---|---|---|---|---|---|---|")


def kind_table(reports, variant: str = "walls") -> str:
    """Lost episodes of re-run paths (``failures`` reports) pooled by the kind of leg, split by how they ended."""
    pooled_by: dict[str, dict[str, int]] = {}
    for report in reports:
        try:
            rows = zip(report["legs"], report[variant]["per_leg"], strict=True)
            for leg, row in rows:
                acc = pooled_by.setdefault(turn_kind(leg["turn_deg"]), dict.fromkeys(
                    ("count", "started", "flipped", "avoid", "timeout"), 0))
                acc["count"] += 1
                for key in ("started", "flipped", "avoid", "timeout"):
                    acc[key] += int(row[key])
        except (KeyError, TypeError, ValueError) as exc:
            raise SpecrefineError(f"not a failures report with per-leg counts ({type(exc).__name__}: {exc})") from None
    lines = [KIND_HEADER]
    for kind in ("first leg", "straight", "turning"):
        if kind in pooled_by:
            acc = pooled_by[kind]
            lost = acc["flipped"] + acc["avoid"] + acc["timeout"]
            lo, hi = wilson_ci(lost, acc["started"])
            lines.append(f"| {kind} | {acc['count']} | {acc['started']:,} | {acc['flipped']} | {acc['avoid']} | "
                         f"{acc['timeout']} | {lost / acc['started']:.4f} [{lo:.4f}, {hi:.4f}] |")
    return "\n".join(lines)


def worst_share(failures, share: float = 0.2) -> float:
    """The part of the summed per-leg failure that the worst ``share`` of the legs carry."""
    ordered = sorted(failures, reverse=True)
    total = sum(ordered)
    return sum(ordered[:max(1, int(len(ordered) * share))]) / total if total else 0.0


PROFILE_HEADER = ("| maze | seed | legs | legs losing episodes (measured) | legs the search saw fail | worst leg's "
                  "failure | worst 20 % of legs' share of the failure | avoid / flipped / timeout |\n"
                  "|---|---|---|---|---|---|---|---|")


def profile_table(profiles) -> str:
    lines = [PROFILE_HEADER]
    for p in sorted(profiles, key=lambda p: (p["seed"], rooms(p["maze"]) or 0, p["maze"])):
        out = p["episode_outcomes"] or {}
        seen = sum(e < 1.0 for e in p["search_estimate"])
        losing = sum(f > 0 for f in p["leg_failure"])
        lines.append(f"| {p['maze']} | {p['seed']} | {len(p['leg_failure'])} | {losing} | {seen} | "
                     f"{max(p['leg_failure']):.3f} | "
                     f"{worst_share(p['leg_failure']):.2f} | {out.get('avoid', 0)} / {out.get('flipped', 0)} / "
                     f"{out.get('timeout', 0)} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = OneLineParser(prog="python -m specrefine.experiments.legs", description=__doc__.splitlines()[0])
    ap.add_argument("tables", nargs="+", help="sweep tables (with --profiles: runs' result.json files)")
    ap.add_argument("--method")
    ap.add_argument("--proposer")
    ap.add_argument("--profiles", action="store_true", help="the inputs are result.json files: write their leg "
                                                            "profiles to --out and print profile_table")
    ap.add_argument("--out", help="with --profiles: the JSON file to write")
    ap.add_argument("--failures", action="store_true", help="the inputs are reports of experiments.failures: print "
                                                            "their lost episodes by kind of leg (kind_table)")
    ap.add_argument("--turns", action="store_true", help="with --profiles: also print the lost episodes pooled by "
                                                         "straight and turning legs")
    ap.add_argument("--after", action="store_true", help="with --turns: pool by the kind of each leg and of the leg "
                                                         "before it")
    args = ap.parse_args(argv)
    if args.turns and not args.profiles:
        ap.error("--turns needs --profiles")
    if args.after and not args.turns:
        ap.error("--after needs --turns")
    try:
        if args.out:
            output_file(args.out)  # before reading the inputs
        if args.failures:
            reports = []
            for path in args.tables:
                try:
                    with open(path) as fh:
                        reports.append(json.load(fh))
                except (OSError, ValueError) as exc:
                    raise SpecrefineError(f"{path}: not a readable JSON report ({type(exc).__name__})") from None
            print(kind_table(reports))
            return 0
        if args.profiles:
            profiles = [leg_profile(read_result(path)) for path in args.tables]
            if args.out:
                write_atomic(args.out, json.dumps(profiles, indent=1) + "\n")
            print(profile_table(profiles))
            if args.turns:
                print("\n" + turn_table(profiles, after=args.after))
            return 0
        print(report(args.tables, args.method, args.proposer))
    except SpecrefineError as exc:  # a missing or malformed table: one line
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
