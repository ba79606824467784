"""Where runs' time goes, from their result.json: the search, the 200-episode measurement and the calibration, with
evaluations and simulator steps beside (issue 30's cost goal).

    python -m specrefine.experiments.cost /tmp/cost_u5/result.json /tmp/cost_u5_s1/result.json \\
        --about what="Ant U-chain 5, one run alone" --about machine="2-core AMD EPYC" \\
        --out data/results/ant/scaling/cost_u_chain_5.json

``--about KEY=TEXT`` (repeatable) writes what the result files cannot know (how the runs were timed, on which
machine) ahead of the runs, in the order given. ``scripts/cost_u_chain_5.sh`` runs the two refines and calls this.
"""

from __future__ import annotations

import json
import sys

from ..core.argtypes import OneLineParser, exit_code_quiet_on_broken_pipe, result_file
from ..core.errors import SpecrefineError
from ..core.runfolder import output_file, read_result, write_atomic

FIELDS = ("seed", "success_rate", "episodes", "path_edges", "evaluations", "sim_steps", "wall_seconds",
          "search_seconds", "measure_seconds", "calibrate_seconds")


def run_cost(result: dict, source: str = "result.json") -> dict:
    missing = [k for k in FIELDS if k not in result]
    if missing:
        raise SpecrefineError(f"{source}: no {', '.join(missing)} (a run from before the cost fields were written?)")
    return {k: result[k] for k in FIELDS}


def about_pair(text: str) -> tuple[str, str]:
    key, sep, value = text.partition("=")
    if not sep or not key.strip():
        raise SpecrefineError(f"--about {text!r}: write it as KEY=TEXT")
    return key.strip(), value


def main(argv=None) -> int:
    ap = OneLineParser(prog="python -m specrefine.experiments.cost", description=__doc__.splitlines()[0])
    ap.add_argument("results", nargs="+", type=result_file, help="runs' folders or their result.json files")
    ap.add_argument("--about", action="append", default=[], metavar="KEY=TEXT", help="written ahead of the runs")
    ap.add_argument("--out", required=True, help="the JSON file to write (whole, or not at all)")
    args = ap.parse_args(argv)
    try:
        output_file(args.out)  # before reading the runs
        report = dict(about_pair(a) for a in args.about)
        report["runs"] = [run_cost(read_result(path), str(path)) for path in args.results]
        write_atomic(args.out, json.dumps(report, indent=1) + "\n")
    except SpecrefineError as exc:  # a missing or malformed result, a bad --about: one line, nothing written
        print(f"error: {exc}", file=sys.stderr)
        return 2
    for run in report["runs"]:
        print(f"seed {run['seed']}: {run['wall_seconds']:.0f} s (search {run['search_seconds']:.0f}, measurement "
              f"{run['measure_seconds']:.0f}, calibration {run['calibrate_seconds']:.0f}); "
              f"{run['evaluations']:,} evaluations, {run['sim_steps']:,} simulator steps")
    return 0


if __name__ == "__main__":
    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
