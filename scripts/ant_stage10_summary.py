"""The table of stage 10's checks (goals near walls) against stage 5 (docs/ant_experiments.md, "Issue 42, lever 9"),
from the JSON files of scripts/ant_stage8_checks.sh, with the verdict of each check's rule fixed there.

    .venv/bin/python scripts/ant_stage10_summary.py [OUT_DIR [NEW_TAG [BASE_TAG]]]
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ant_stage7_summary import chain_rows, held_out_rows, open_floor_row, overlap_rule  # noqa: E402

from specrefine.core.results import difference_text  # noqa: E402

CHECKS = (1, 2, 3, 4, 5)


def overlap_with_difference(kb, nb, kn, nn, base: dict, new: dict) -> tuple[bool, str]:
    """Checks 2 and 4: the new policy's interval overlaps stage 5's or lies above it."""
    ok, text = overlap_rule(kb, nb, kn, nn, base, new)
    return ok, f"{text}; difference {difference_text(kn, nn, kb, nb)} (Newcombe)"


def count_rule(verdicts: dict, number: int, above: bool):
    """The pooled held-out row's rule: ``above`` stage 5's count (the aim) or not below it (the guard)."""
    def rule(kb, nb, kn, nn):
        verdicts[number] = kn > kb if above else kn >= kb
        return (f"{'above' if above else 'not below'} {kb}: {'holds' if verdicts[number] else 'fails'}; difference "
                f"{difference_text(kn, nn, kb, nb)} (Newcombe)")
    return rule


def main(folder="data/results/ant/stage10_checks", new="stage10", base="stage5") -> None:
    folder, verdicts = Path(folder), {}
    rows = [f"| check | {base} | {new} | rule |", "| --- | --- | --- | --- |"]
    rows += open_floor_row(folder, base, new, verdicts)
    rows += chain_rows(folder, base, new, {2: "eight goals in a row (planned), 200",
                                           4: "eight turning goals (90-180 deg, planned), 500"}, verdicts,
                       {2: overlap_with_difference, 4: overlap_with_difference})
    rows += held_out_rows(folder, base, new, "", "3. held out U-chain 2, sampled points", count_rule(verdicts, 3, True))
    rows += held_out_rows(folder, base, new, "centre_", "5. held out U-chain 2, centre points",
                          count_rule(verdicts, 5, False))
    missing = [c for c in CHECKS if c not in verdicts]
    print("\n".join(rows))
    print("\n" + (f"checks not yet run: {missing}" if missing else
                  f"put forward by the rule: {'yes' if all(verdicts.values()) else 'no'}"))


if __name__ == "__main__":
    main(*sys.argv[1:])
