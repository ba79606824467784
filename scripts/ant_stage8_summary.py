"""The table of stage 8's checks (the look-ahead) against stage 5 (docs/ant_experiments.md, "Issue 42, lever 2"), from
the JSON files of scripts/ant_stage8_checks.sh, with the verdict of each check's rule fixed there.

    .venv/bin/python scripts/ant_stage8_summary.py [OUT_DIR [NEW_TAG [BASE_TAG]]]
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ant_stage7_summary import chain_cell, held_out, load, rate  # noqa: E402  (the same cells as stage 7's table)

from specrefine.core.results import newcombe_ci, wilson_ci  # noqa: E402


def main(folder="data/results/ant/stage8_checks", new="stage8", base="stage5") -> None:
    folder = Path(folder)
    rows, verdicts = [f"| check | {base} | {new} | rule |", "| --- | --- | --- | --- |"], {}
    of = {t: load(folder, f"open_floor_{t}.json") for t in (base, new)}
    if all(of.values()):
        verdicts[1] = of[new]["success_rate"] >= 0.98
        cells = [f"{rate(round(d['success_rate'] * d['episodes']), d['episodes'])}, flips {d['flip_rate']:.1%}"
                 for d in (of[base], of[new])]
        rows.append(f"| 1. open floor, 500 episodes | {cells[0]} | {cells[1]} | at least 0.98: "
                    f"{'holds' if verdicts[1] else 'fails'} |")
    for number, name, label in ((2, "chain8", "eight goals in a row (planned), 200"),
                                (4, "turn_chain8", "eight turning goals (90-180 deg, planned), 500")):
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
    for points, label in (("centre_", "3. held out U-chain 2, centre points"),
                          ("", "5. held out U-chain 2, sampled points")):
        h = {t: held_out(folder, t, points) for t in (base, new)}
        if not all(h.values()):
            continue
        for s in range(3):
            rows.append(f"| {label} s{s}, 300 | {h[base][0][s]} | {h[new][0][s]} | |")
        (_, kb, nb), (_, kn, nn) = h[base], h[new]
        if points:
            verdicts[3] = kn > kb
            lo, hi = newcombe_ci(kn, nn, kb, nb)
            rule = (f"above {kb}: {'holds' if verdicts[3] else 'fails'}; difference {kn / nn - kb / nb:+.3f} "
                    f"[{lo:+.3f}, {hi:+.3f}] (Newcombe)")
        else:
            rule = "descriptive"
        rows.append(f"| {label} pooled, 900 | {rate(kb, nb)} | {rate(kn, nn)} | {rule} |")
    print("\n".join(rows))
    missing = [c for c in (1, 2, 3, 4) if c not in verdicts]
    print("\n" + (f"checks not yet run: {missing}" if missing else
                  f"adopted by the rule: {'yes' if all(verdicts.values()) else 'no'}"))


if __name__ == "__main__":
    main(*sys.argv[1:])
