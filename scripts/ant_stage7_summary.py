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


def main(folder="data/results/ant/stage7_checks", new="stage7", base="stage5") -> None:
    folder = Path(folder)
    rows, verdicts = [f"| check | {base} | {new} | rule |", "| --- | --- | --- | --- |"], {}
    of = {t: load(folder, f"open_floor_{t}.json") for t in (base, new)}
    if all(of.values()):
        verdicts[1] = of[new]["success_rate"] >= 0.98
        cells = [f"{rate(round(d['success_rate'] * d['episodes']), d['episodes'])}, flips {d['flip_rate']:.1%}"
                 for d in (of[base], of[new])]
        rows.append(f"| 1. open floor, 500 episodes | {cells[0]} | {cells[1]} | at least 0.98: "
                    f"{'holds' if verdicts[1] else 'fails'} |")
    for number, name, label in ((2, "chain8", "eight goals in a row, 200"), (4, "turn_chain8",
                                                                          "eight turning goals (90-180 deg), 500")):
        d = {t: load(folder, f"{name}_{t}.json") for t in (base, new)}
        if not all(d.values()):
            continue
        kb, nb, kn, nn = d[base]["reached"][-1], d[base]["episodes"], d[new]["reached"][-1], d[new]["episodes"]
        if number == 2:
            verdicts[2] = wilson_ci(kn, nn)[1] >= wilson_ci(kb, nb)[0]
            rule = f"overlap or above: {'holds' if verdicts[2] else 'fails'}"
        else:
            verdicts[4] = kn >= kb and sum(d[new]["flipped"]) <= sum(d[base]["flipped"])
            lo, hi = newcombe_ci(kn, nn, kb, nb)
            rule = (f"success not below, flips not above: {'holds' if verdicts[4] else 'fails'}; difference "
                    f"{kn / nn - kb / nb:+.3f} [{lo:+.3f}, {hi:+.3f}] (Newcombe)")
        rows.append(f"| {number}. {label} | {chain_cell(d[base])} | {chain_cell(d[new])} | {rule} |")
    for points, label in (("", "3. held out U-chain 2"), ("centre_", "5. held out U-chain 2, centre points")):
        h = {t: held_out(folder, t, points) for t in (base, new)}
        if not all(h.values()):
            continue
        for s in range(3):
            rows.append(f"| {label} s{s}, 300 | {h[base][0][s]} | {h[new][0][s]} | |")
        (_, kb, nb), (_, kn, nn) = h[base], h[new]
        if points == "":
            verdicts[3] = kn >= kb
        rule = f"not below {kb}: {'holds' if kn >= kb else 'fails'}" if points == "" else "descriptive"
        rows.append(f"| {label} pooled, 900 | {rate(kb, nb)} | {rate(kn, nn)} | {rule} |")
    print("\n".join(rows))
    missing = [c for c in (1, 2, 3, 4) if c not in verdicts]
    print("\n" + (f"checks not yet run: {missing}" if missing else
                  f"adopted by the rule: {'yes' if all(verdicts.values()) else 'no'}"))


if __name__ == "__main__":
    main(*sys.argv[1:])
