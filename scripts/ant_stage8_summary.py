"""The table of stage 8's checks (the look-ahead) against stage 5 (docs/ant_experiments.md, "Issue 42, lever 2"), from
the JSON files of scripts/ant_stage8_checks.sh, with the verdict of each check's rule fixed there.

    .venv/bin/python scripts/ant_stage8_summary.py [OUT_DIR [NEW_TAG [BASE_TAG]]]
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ant_stage7_summary import chain_rows, held_out_rows, open_floor_row, verdict_line  # noqa: E402

from specrefine.core.results import newcombe_ci  # noqa: E402


def main(folder="data/results/ant/stage8_checks", new="stage8", base="stage5") -> None:
    folder, verdicts = Path(folder), {}

    def above(kb, nb, kn, nn):
        verdicts[3] = kn > kb
        lo, hi = newcombe_ci(kn, nn, kb, nb)
        return (f"above {kb}: {'holds' if verdicts[3] else 'fails'}; difference {kn / nn - kb / nb:+.3f} "
                f"[{lo:+.3f}, {hi:+.3f}] (Newcombe)")

    rows = [f"| check | {base} | {new} | rule |", "| --- | --- | --- | --- |"]
    rows += open_floor_row(folder, base, new, verdicts)
    rows += chain_rows(folder, base, new, {2: "eight goals in a row (planned), 200",
                                           4: "eight turning goals (90-180 deg, planned), 500"}, verdicts)
    rows += held_out_rows(folder, base, new, "centre_", "3. held out U-chain 2, centre points", above)
    rows += held_out_rows(folder, base, new, "", "5. held out U-chain 2, sampled points", lambda *counts: "descriptive")
    print("\n".join(rows))
    print("\n" + verdict_line(verdicts))

if __name__ == "__main__":
    main(*sys.argv[1:])
