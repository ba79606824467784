"""The table of stage 7's checks against stage 5 (docs/ant_experiments.md, "Issue 42, lever 3"), from the JSON files
of scripts/ant_stage7_checks.sh, with the verdict of each check's rule fixed there.

    .venv/bin/python scripts/ant_stage7_summary.py [OUT_DIR [NEW_TAG [BASE_TAG]]]
"""
import json
import sys
from pathlib import Path

from specrefine.core.results import newcombe_ci, wilson_ci


def load(folder: Path, name: str) -> dict | None:
    path = folder / name
    return json.loads(path.read_text()) if path.is_file() and path.stat().st_size else None


def rate(k: int, n: int) -> str:
    lo, hi = wilson_ci(k, n)
    return f"{k}/{n} = {k / n:.3f} [{lo:.3f}, {hi:.3f}]"


def chain_cell(d: dict) -> str:
    n, k = d["episodes"], d["reached"][-1]
    return (f"{rate(k, n)}; flips {sum(d['flipped'])}, timeouts {sum(d['timed_out'])}; "
            f"{d['mean_switch_speed_mps']:.2f} m/s at the switches" if d.get("mean_switch_speed_mps") is not None
            else f"{rate(k, n)}; flips {sum(d['flipped'])}, timeouts {sum(d['timed_out'])}")


def held_out(folder: Path, tag: str, points: str = "") -> tuple[list[str], int, int] | None:
    cells, ok, n = [], 0, 0
    for s in (0, 1, 2):
        d = load(folder, f"u_chain_2_s{s}_{points}{tag}.json")
        if d is None:
            return None
        w = d["walls"]
        out = w["outcomes"]
        cells.append(f"{w['success']} ({out.get('flipped', 0)} flips, {out.get('avoid', 0)} avoid, "
                     f"{out.get('timeout', 0)} timeouts)")
        ok, n = ok + w["success"], n + d["episodes"]
    return cells, ok, n


def open_floor_row(folder: Path, base: str, new: str, verdicts: dict) -> list[str]:
    """Check 1's row (at least 0.98 on the open floor), when both files are there."""
    of = {t: load(folder, f"open_floor_{t}.json") for t in (base, new)}
    if not all(of.values()):
        return []
    verdicts[1] = of[new]["success_rate"] >= 0.98
    cells = [f"{rate(round(d['success_rate'] * d['episodes']), d['episodes'])}, flips {d['flip_rate']:.1%}"
             for d in (of[base], of[new])]
    return [f"| 1. open floor, 500 episodes | {cells[0]} | {cells[1]} | at least 0.98: "
            f"{'holds' if verdicts[1] else 'fails'} |"]


def overlap_rule(kb, nb, kn, nn, base: dict, new: dict) -> tuple[bool, str]:
    """Check 2's rule: the new policy's interval overlaps the base's or lies above it."""
    ok = wilson_ci(kn, nn)[1] >= wilson_ci(kb, nb)[0]
    return ok, f"overlap or above: {'holds' if ok else 'fails'}"


def turn_rule(kb, nb, kn, nn, base: dict, new: dict) -> tuple[bool, str]:
    """Check 4's rule: success not below the base's, flips not above."""
    ok = kn >= kb and sum(new["flipped"]) <= sum(base["flipped"])
    lo, hi = newcombe_ci(kn, nn, kb, nb)
    return ok, (f"success not below, flips not above: {'holds' if ok else 'fails'}; difference "
                f"{kn / nn - kb / nb:+.3f} [{lo:+.3f}, {hi:+.3f}] (Newcombe)")


def chain_rows(folder: Path, base: str, new: str, labels: dict, verdicts: dict,
               rules: dict | None = None) -> list[str]:
    """Checks 2 (eight goals) and 4 (turning goals), each judged by ``rules[number](kb, nb, kn, nn, base_json,
    new_json) -> (holds, text)`` (default: :func:`overlap_rule`, :func:`turn_rule`); ``labels``: check number ->
    its label in the table."""
    rules = rules or {2: overlap_rule, 4: turn_rule}
    rows = []
    for number, name in ((2, "chain8"), (4, "turn_chain8")):
        d = {t: load(folder, f"{name}_{t}.json") for t in (base, new)}
        if not all(d.values()):
            continue
        kb, nb, kn, nn = d[base]["reached"][-1], d[base]["episodes"], d[new]["reached"][-1], d[new]["episodes"]
        verdicts[number], rule = rules[number](kb, nb, kn, nn, d[base], d[new])
        rows.append(f"| {number}. {labels[number]} | {chain_cell(d[base])} | {chain_cell(d[new])} | {rule} |")
    return rows


def held_out_rows(folder: Path, base: str, new: str, points: str, label: str, rule) -> list[str]:
    """The held-out paths' rows (per seed, then pooled); ``rule(kb, nb, kn, nn)`` -> the pooled row's last cell."""
    h = {t: held_out(folder, t, points) for t in (base, new)}
    if not all(h.values()):
        return []
    rows = [f"| {label} s{s}, 300 | {h[base][0][s]} | {h[new][0][s]} | |" for s in range(3)]
    (_, kb, nb), (_, kn, nn) = h[base], h[new]
    return rows + [f"| {label} pooled, 900 | {rate(kb, nb)} | {rate(kn, nn)} | {rule(kb, nb, kn, nn)} |"]


def verdict_line(verdicts: dict) -> str:
    missing = [c for c in (1, 2, 3, 4) if c not in verdicts]
    return f"checks not yet run: {missing}" if missing else \
        f"adopted by the rule: {'yes' if all(verdicts.values()) else 'no'}"


def main(folder="data/results/ant/stage7_checks", new="stage7", base="stage5") -> None:
    folder, verdicts = Path(folder), {}

    def not_below(kb, nb, kn, nn):
        verdicts[3] = kn >= kb
        return f"not below {kb}: {'holds' if verdicts[3] else 'fails'}"

    rows = [f"| check | {base} | {new} | rule |", "| --- | --- | --- | --- |"]
    rows += open_floor_row(folder, base, new, verdicts)
    rows += chain_rows(folder, base, new, {2: "eight goals in a row, 200", 4: "eight turning goals (90-180 deg), 500"},
                       verdicts)
    rows += held_out_rows(folder, base, new, "", "3. held out U-chain 2", not_below)
    rows += held_out_rows(folder, base, new, "centre_", "5. held out U-chain 2, centre points",
                          lambda *counts: "descriptive")
    print("\n".join(rows))
    print("\n" + verdict_line(verdicts))

if __name__ == "__main__":
    main(*sys.argv[1:])
