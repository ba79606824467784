"""The tables of the slow-turn switching rule's checks (docs/ant_experiments.md, "Issue 42, lever 1"), from the files
of scripts/ant_switching_checks.sh; writes OUT/checks.md and prints it.

    .venv/bin/python scripts/switching_table.py [OUT]     # OUT: data/results/ant/switching_checks
"""

import json
import sys
from pathlib import Path

from specrefine.core.results import difference_text, rate_text
from specrefine.core.runfolder import write_atomic
from specrefine.experiments.legs import kind_table

RULES = ("at-region", "slow-turn")
STAGE5 = Path("data/results/ant/stage5_checks")  # stage 5's own checks: sampled goal points, at-region


def held_out(out: Path, points: str, rule: str) -> dict[int, dict]:
    """The held-out U-chain 2 reports of one goal-point rule and switching rule run so far, by the path's seed."""
    files = {s: out / f"u_chain_2_s{s}_{points}_{rule}.json" for s in (0, 1, 2)}
    if points == "sampled" and rule == "at-region":  # not rerun yet: the stage-5 checks' files (the same episodes)
        files = {s: f if f.exists() else STAGE5 / f"u_chain_2_s{s}_stage5.json" for s, f in files.items()}
    return {s: json.loads(f.read_text()) for s, f in files.items() if f.exists()}


def outcome_text(walls: dict) -> str:
    o = walls["outcomes"]
    return (f"{walls['success']} ({o.get('flipped', 0)} flips, {o.get('avoid', 0)} avoid, "
            f"{o.get('timeout', 0)} timeouts)")


def held_out_table(out: Path, points: str) -> list[str]:
    reports = {rule: held_out(out, points, rule) for rule in RULES}
    lines = [f"Held-out U-chain 2 paths, {points} goal points, 300 episodes each, seed 77, stage 5, with walls:", "",
             "| path | at-region | slow-turn |", "|---|---|---|"]
    for s in (0, 1, 2):
        cells = [outcome_text(reports[rule][s]["walls"]) if s in reports[rule] else "not run" for rule in RULES]
        lines.append(f"| u_chain_2 s{s} | {' | '.join(cells)} |")
    pooled = {rule: (sum(r["walls"]["success"] for r in rs.values()), sum(r["episodes"] for r in rs.values()))
              for rule, rs in reports.items()}
    lines.append(f"| pooled | {' | '.join(rate_text(*pooled[rule]) for rule in RULES)} |")
    paths = {rule: set(rs) for rule, rs in reports.items()}
    if paths["at-region"] == paths["slow-turn"] and paths["slow-turn"]:
        lines += ["", f"slow-turn - at-region, pooled over the same {len(paths['slow-turn'])} path(s): "
                      f"{difference_text(*pooled['slow-turn'], *pooled['at-region'])} (Newcombe 95 %, as if "
                      "independent: the episodes are paired, so it is conservative)"]
    for rule in RULES:
        if reports[rule]:
            lines += ["", f"Lost episodes by kind of leg, {points} goal points, {rule}:", "",
                      kind_table(list(reports[rule].values()))]
    return lines


def chain_table(out: Path) -> list[str]:
    lines = ["Eight goals in a row, open floor, 3-5 m, 200 episodes, seed 5, stage 5:", "",
             "| rule | success [95 % CI] | flips | timeouts | mean speed at a switch (m/s) |", "|---|---|---|---|---|"]
    for rule in RULES:
        path = out / f"chain8_{rule}.json"
        if not path.exists() and rule == "at-region":
            path = STAGE5 / "chain8_stage5.json"
        if path.exists():
            d = json.loads(path.read_text())
            lo, hi = d["success_ci95"]
            speed = d.get("mean_switch_speed_mps")
            lines.append(f"| {rule} ({path}) | {d['success_rate']:.3f} [{lo:.3f}, {hi:.3f}] | {sum(d['flipped'])} | "
                         f"{sum(d['timed_out'])} | {'' if speed is None else f'{speed:.2f}'} |")
    return lines


def main(out: Path) -> str:
    text = "\n".join(["# The slow-turn switching rule's checks (docs/ant_experiments.md, 'Issue 42, lever 1')", "",
                      *chain_table(out), "", *held_out_table(out, "centre"), "", *held_out_table(out, "sampled"), ""])
    write_atomic(out / "checks.md", text)
    return text


if __name__ == "__main__":
    print(main(Path(sys.argv[1] if len(sys.argv) > 1 else "data/results/ant/switching_checks")))
