"""Where the Ant's gap between this package's simulator and the official AntMaze comes from: each run's policy in
the official environment with this package's reset rules put in, one at a time and together.

    PYTHONPATH=$PWD python scripts/official_gap_ant.py [--episodes 200] [--out data/official/ant_gap.json]

Runs (fixed before any ran, docs/official_env.md "The Ant's gap"): the AntMaze grid's six gr:LARGE_MAZE `ours`
runs (geometric and imperfect:moderate, seeds 0-2), first with both package rules (``--start package
--reset-noise package``) on all six, then each rule alone on the three imperfect:moderate runs. Seed 0 as the
runs' plain official episodes, so start cells and goal points are paired with them. Resumable: the record is
rewritten whole after every variant and a variant already in it is skipped.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

RUNS = "runs/antmaze/cells/gr-LARGE_MAZE__ant__ours__{proposer}__s{seed}__adaptive"
PROPOSERS = ("geometric", "imperfect-moderate")
#: (start, reset_noise) in the order they run: both rules on every run, then each alone on the erring runs
VARIANTS = [(("package", "package"), PROPOSERS), (("package", "official"), ("imperfect-moderate",)),
            (("official", "package"), ("imperfect-moderate",))]
KEEP = ("success_rate", "success_ci", "episodes", "outcomes")
UNLABELLED = "successes_not_labelled_success"  # successes whose policy run ended otherwise (record's "note")
NOTE = ("success_rate counts an episode as a success when its trajectory met the ORIGINAL task and the Ant did not "
        "flip (specrefine.runs.official); outcomes name how the compositional policy's own run ended. An episode "
        "whose trajectory met the task while the run ended otherwise (a wall contact or a timeout) is a success "
        f"under another label: {UNLABELLED} counts them where there are any; successes = outcomes['success'] + "
        f"{UNLABELLED}.")


def side(data: dict) -> dict:
    """One simulator's and reset's entry: KEEP, and the successes its outcome labels do not name."""
    entry = {k: data[k] for k in KEEP}
    unlabelled = round(entry["success_rate"] * entry["episodes"]) - entry["outcomes"].get("success", 0)
    return entry | ({UNLABELLED: unlabelled} if unlabelled else {})


def variant_name(start: str, noise: str) -> str:
    return f"start={start},reset_noise={noise}"


LABELS = {"this_simulator": "this simulator", variant_name("official", "official"): "official",
          variant_name("package", "package"): "official, package start and reset noise",
          variant_name("package", "official"): "official, package start",
          variant_name("official", "package"): "official, package reset noise"}


def gap_table(record: dict) -> str:
    """Per proposer and variant, pooled over the runs that have it: success, and its difference from this
    simulator on the same runs (Newcombe 95 %)."""
    from specrefine.core.results import difference_text, rate_text

    def counts(entry, key):
        side = entry[key]
        return round(side["success_rate"] * side["episodes"]), side["episodes"]

    lines = ["| proposer | simulator and reset | seeds | success [95 % CI] (episodes) | minus this simulator "
             "[95 % CI] |", "|---|---|---|---|---|"]
    for proposer in PROPOSERS:
        entries = {name.split("__s")[1][0]: e for name, e in sorted(record["runs"].items())
                   if f"__{proposer}__" in name}
        for key, label in LABELS.items():
            have = {seed: e for seed, e in entries.items() if key in e}
            if not have:
                continue
            k, n = map(sum, zip(*(counts(e, key) for e in have.values())))
            ks, ns = map(sum, zip(*(counts(e, "this_simulator") for e in have.values())))
            diff = "—" if key == "this_simulator" else difference_text(k, n, ks, ns)
            lines.append(f"| {proposer.replace('-', ':')} | {label} | {','.join(have)} | {rate_text(k, n)} | {diff} |")
    return "\n".join(lines)


def main() -> None:
    from specrefine.core.records import read_json
    from specrefine.core.runfolder import writable_parent, write_atomic
    from specrefine.runs.official import run_official

    p = argparse.ArgumentParser()
    p.add_argument("--episodes", type=int, default=200)
    p.add_argument("--out", type=Path, default=Path("data/official/ant_gap.json"))
    args = p.parse_args()
    writable_parent(args.out)  # before any run: no link, device or folder
    record = read_json(args.out, "gap record") if args.out.exists() else {
        "command": f"PYTHONPATH=$PWD python scripts/official_gap_ant.py --episodes {args.episodes}",
        "episodes": args.episodes, "seed": 0, "note": NOTE, "runs": {}}
    for (start, noise), proposers in VARIANTS:
        for proposer in proposers:
            for seed in (0, 1, 2):
                run = Path(RUNS.format(proposer=proposer, seed=seed))
                entry = record["runs"].setdefault(run.name, {})
                if not entry:
                    result = json.loads((run / "result.json").read_text())
                    plain = json.loads((run / "official.json").read_text())
                    entry["this_simulator"] = side(result | {"outcomes": result["episode_outcomes"]})
                    entry[variant_name("official", "official")] = side(plain)
                name = variant_name(start, noise)
                if name in entry:
                    continue
                tmp = args.out.with_name(f".{run.name}.official.json")
                data = run_official(run, args.episodes, 0, start=start, reset_noise=noise, out=tmp)
                tmp.unlink()
                entry[name] = side(data)
                write_atomic(args.out, json.dumps(record, indent=1) + "\n")
                print(run.name, name, data["success_rate"], data["outcomes"], flush=True)


if __name__ == "__main__":
    from specrefine.core.argtypes import script_exit_code

    raise SystemExit(script_exit_code(main))
