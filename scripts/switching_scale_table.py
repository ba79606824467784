"""The slow-turn rule's check at scale (docs/ant_experiments.md, "Issue 42, lever 1 at scale"), from the reports of
scripts/device_switching.sh; writes FOLDER/checks.md and prints it. Only (path, seed) pairs that both rules finished
count, so the two rules are judged on the same episodes.

    .venv/bin/python scripts/switching_scale_table.py FOLDER     # FOLDER: data/results/ant/switching_scale
"""

import json
import re
import sys
from pathlib import Path

from specrefine.core.results import difference_text, newcombe_ci, rate_text, wilson_ci
from specrefine.core.runfolder import write_atomic
from specrefine.experiments.legs import kind_table

RULES = ("at-region", "slow-turn")
NAME = re.compile(r"u_chain_2_s(\d)_centre_(at-region|slow-turn)_seed(\d+)\.json")


def paired_reports(folder: Path) -> dict[tuple[int, int], dict[str, dict]]:
    """Reports by (path seed, episode seed), only where every rule's report exists."""
    found: dict[tuple[int, int], dict[str, dict]] = {}
    for file in sorted(folder.glob("u_chain_2_s*_centre_*_seed*.json")):
        match = NAME.fullmatch(file.name)
        if match:
            path, rule, seed = int(match[1]), match[2], int(match[3])
            found.setdefault((path, seed), {})[rule] = json.loads(file.read_text())
    return {key: reports for key, reports in sorted(found.items()) if set(reports) == set(RULES)}


def pooled(reports: list[dict]) -> tuple[int, int]:
    return sum(r["walls"]["success"] for r in reports), sum(r["episodes"] for r in reports)


def worst_legs(path: int, reports: list[dict], top: int = 2) -> list[str]:
    """Table rows of the ``top`` legs of one path that lose the most episodes, pooled over its reports."""
    legs = reports[0]["legs"]
    lost = [sum(r["walls"]["per_leg"][i][k] for r in reports for k in ("flipped", "avoid", "timeout"))
            for i in range(len(legs))]
    started = [sum(r["walls"]["per_leg"][i]["started"] for r in reports) for i in range(len(legs))]
    rows = []
    for i in sorted(range(len(legs)), key=lambda i: -lost[i])[:top]:
        lo, hi = wilson_ci(lost[i], started[i])
        turn = legs[i]["turn_deg"]
        rows.append(f"| u_chain_2 s{path} | {i} | {'first' if turn is None else f'{turn:.0f}'} | "
                    f"{legs[i]['length_m']:.1f} | {lost[i]} / {started[i]:,} = {lost[i] / started[i]:.4f} "
                    f"[{lo:.4f}, {hi:.4f}] | {lost[i]} of {sum(lost)} |")
    return rows


def table(folder: Path) -> str:
    pairs = paired_reports(folder)
    if not pairs:
        return "No (path, seed) pair has both rules' reports yet."
    by_rule = {rule: [reports[rule] for reports in pairs.values()] for rule in RULES}
    totals = {rule: pooled(by_rule[rule]) for rule in RULES}
    lines = [f"Held-out U-chain 2 paths, centre goal points, stage 5, with walls; {len(pairs)} (path, episode seed) "
             "pairs that both rules finished:", "", "| path | seeds | at-region | slow-turn | slow-turn - at-region |",
             "|---|---|---|---|---|"]
    for path in sorted({p for p, _ in pairs}):
        rows = {rule: pooled([r[rule] for (p, _), r in pairs.items() if p == path]) for rule in RULES}
        seeds = [s for p, s in pairs if p == path]
        lines.append(f"| u_chain_2 s{path} | {len(seeds)} | {rate_text(*rows['at-region'])} | "
                     f"{rate_text(*rows['slow-turn'])} | {difference_text(*rows['slow-turn'], *rows['at-region'])} |")
    lines.append(f"| pooled | {len(pairs)} | {rate_text(*totals['at-region'])} | {rate_text(*totals['slow-turn'])} | "
                 f"{difference_text(*totals['slow-turn'], *totals['at-region'])} |")
    diffs = [pooled([r["slow-turn"]])[0] - pooled([r["at-region"]])[0] for r in pairs.values()]
    lo, hi = newcombe_ci(*totals["slow-turn"], *totals["at-region"])
    verdict = ("slow-turn's gain shown" if lo > 0 else "slow-turn harms" if hi < 0 else "no difference shown")
    lines += ["", f"Pairs where slow-turn succeeds more often: {sum(d > 0 for d in diffs)}, less often: "
                  f"{sum(d < 0 for d in diffs)}, as often: {sum(d == 0 for d in diffs)}. Rule (fixed before the run): "
                  f"**{verdict}** (Newcombe 95 %, as if independent; the episodes are paired, so it is conservative)."]
    lines += ["", "Where a path loses its episodes (both rules and every seed pooled): its two legs that lose the most",
              "", "| path | leg | turn (deg) | length (m) | lost / started | share of the path's lost episodes |",
              "|---|---|---|---|---|---|"]
    for path in sorted({p for p, _ in pairs}):
        lines += worst_legs(path, [r for (p, _), reports in pairs.items() if p == path for r in reports.values()])
    for rule in RULES:
        lines += ["", f"Lost episodes by kind of leg, {rule} (legs counted once per report):", "",
                  kind_table(by_rule[rule])]
    return "\n".join(lines)


def main(folder: Path) -> str:
    text = "\n".join(["# slow-turn against at-region at scale (docs/ant_experiments.md, 'Issue 42, lever 1 at scale')",
                      "", table(folder), ""])
    write_atomic(folder / "checks.md", text)
    return text


if __name__ == "__main__":
    print(main(Path(sys.argv[1] if len(sys.argv) > 1 else "data/results/ant/switching_scale")))
