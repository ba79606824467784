"""The look-ahead repair grid's claims (docs/proposers.md, "Look-ahead repair"), decided as fixed there.

    python -m specrefine.experiments.repair_claims data/results/repair/results.csv --out data/results/repair

Per preset, 95 % percentile bootstrap intervals over (maze, seed) cells (specrefine.experiments.comparison's
resamples and seed): the paired difference ours-repair - ours on the multi-room cells and on every cell (helps /
hurts / undecided), the paper's two claims with ours-repair in place of ours (specrefine.experiments.comparison's
rules), and, descriptive, the runs at success 0 and the paired cost ratios. Writes claims.md, claims.json, mazes.md
(mean success per maze and method, Student-t interval over seeds), summary.md (README's table, a line per preset) and
specrefine.experiments.comparison's figures of the three methods (figure4.png, figure5.png, error_levels.png). A
preset with a missing cell is marked partial.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from ..core.argtypes import OneLineParser, out_path
from ..core.errors import SpecrefineError
from ..core.mazes import benchmark_mazes
from ..core.runfolder import ensure_dir, locked, save_figure, write_atomic
from ..runs.sweep import read_checked_table
from . import comparison as cmp
from .grids import GRIDS

GRID = GRIDS["repair"]
PRESETS = GRID.proposers  # the order they run in
METHODS = GRID.methods
SEEDS = GRID.seeds
REPAIR_CLAIM = "ours-repair - ours"


def paired_claim(cells: dict, failed: set, proposer: str, mazes, scope: str, pair=("ours-repair", "ours"),
                 seeds=SEEDS) -> dict:
    """Mean of the paired success difference first - second (ours-repair - ours) over (maze, seed) cells; helps if
    its interval lies above 0, hurts if below."""
    entry = cmp.paired_difference(cells, failed, proposer, *pair, seeds, mazes)
    verdict = {"higher": "helps", "lower": "hurts"}.get(entry["verdict"], "undecided")
    return entry | {"claim": f"{pair[0]} - {pair[1]}, {scope}", "verdict": verdict}


def as_ours(cells: dict) -> dict:
    """The cells with ours-repair in the place of ours (for specrefine.experiments.comparison's claims on 'ours')."""
    return {(maze, "ours" if m == "ours-repair" else m, p, s): v for (maze, m, p, s), v in cells.items()
            if m != "ours"}


def paper_claims(cells: dict, failed: set, proposer: str) -> list[dict]:
    """The paper's two claims with ours-repair as 'ours', and the rooms entries of ours and vlm-oneshot beside."""
    repaired, repaired_failed = as_ours(cells), set(as_ours(dict.fromkeys(failed)))
    ratio = cmp.ratio_claim(repaired, repaired_failed, proposer, SEEDS)
    ratio |= {"claim": "ours-repair >= 2x one-shot on multi-room tasks", "method": "ours-repair / vlm-oneshot"}
    rooms = cmp.rooms_claim(repaired, repaired_failed, proposer, "ours", SEEDS)
    rooms |= {"claim": f"ours-repair {cmp.ROOMS_CLAIM_TEXT}", "method": "ours-repair", "paper": "flat"}
    return [ratio, rooms] + [cmp.rooms_claim(cells, failed, proposer, m, SEEDS) for m in ("ours", "vlm-oneshot")]


def costs(rows: list[dict], proposer: str, pair=("ours-repair", "ours"), methods=METHODS) -> dict:
    """Descriptive: runs at success 0 per method; first / second (ours-repair / ours) ratio of mean evaluations and
    proposer calls over the cells where both ran."""
    by = {(r["maze"], r["method"], r["seed"]): r for r in cmp._task_rows(rows, "point")
          if r["proposer"] == proposer and cmp.is_done(r)}
    zeros = {m: sum(1 for (_, method, _), r in by.items() if method == m and r["success_rate"] == 0)
             for m in methods}
    runs = {m: sum(1 for (_, method, _) in by if method == m) for m in methods}
    pairs = [(by[(maze, pair[0], s)], r) for (maze, m, s), r in by.items()
             if m == pair[1] and (maze, pair[0], s) in by]

    def ratio(key):
        return float(np.mean([a[key] for a, _ in pairs]) / np.mean([b[key] for _, b in pairs])) if pairs else None

    return {"proposer": proposer, "zero_runs": zeros, "runs": runs, "pairs": len(pairs),
            "evaluations_ratio": ratio("evaluations"), "proposer_calls_ratio": ratio("proposer_calls")}


def _zero_runs(cost: dict) -> str:
    return ", ".join(f"{cost['zero_runs'][m]}/{cost['runs'][m]}" for m in cost["runs"])


def _times(ratio: float | None) -> str:
    return "—" if ratio is None else f"{ratio:.2f}x"


def _interval(e) -> str:
    if e["estimate"] != e["estimate"]:  # nan
        return "—"
    sign = "" if e["kind"] == "ratio" else "+"
    return f"{e['estimate']:{sign}.3f} [{e['ci_low']:{sign}.3f}, {e['ci_high']:{sign}.3f}]"


def markdown(entries: list[dict], cost_rows: list[dict], pair=("ours-repair", "ours")) -> str:
    lines = [f"{cmp.OFFLINE_NOTE}. Point mass; 95 % bootstrap percentile intervals ({cmp.BOOTSTRAP_RESAMPLES} "
             f"resamples, numpy seed {cmp.BOOTSTRAP_SEED}) over (maze, seed) cells; multi-room = "
             f"{', '.join(cmp.MULTI_ROOM_MAZES)}; change 1→5 rooms = least-squares slope x 4 on u_chain_1..5, flat "
             f"within ±{cmp.FLAT_TOLERANCE}. *partial*: cells of the fixed grid are missing.", "",
             "| proposer | claim | estimate [95 % CI] | verdict | cells (seeds) | missing |",
             "|---|---|---|---|---|---|"]
    for e in entries:
        verdict = e["verdict"] + ("" if e["complete"] else " (*partial*)")
        seeds = ",".join(map(str, e["seeds"])) or "none"
        lines.append(f"| {e['proposer']} | {e['claim']} | {_interval(e)} | {verdict} | {e['n_cells']}/"
                     f"{e['n_expected']} ({seeds}) | {cmp._missing_summary(e['missing'])} |")
    methods = list(cost_rows[0]["runs"]) if cost_rows else list(METHODS)
    lines += ["", "| proposer | runs at success 0 (of runs): " + ", ".join(methods) +
              f" | {pair[0]} / {pair[1]}: evaluations, proposer calls (pairs) |", "|---|---|---|"]
    for c in cost_rows:
        lines.append(f"| {c['proposer']} | {_zero_runs(c)} | {_times(c['evaluations_ratio'])}, "
                     f"{_times(c['proposer_calls_ratio'])} ({c['pairs']}) |")
    return "\n".join(lines)


def maze_table(cells: dict, proposer: str) -> str:
    """Mean success per maze and method over the seeds that ran, with a Student-t 95 % interval."""
    lines = [f"{proposer} ({cmp.OFFLINE_NOTE}): mean success over seeds {SEEDS} [95 % t interval]", "",
             "| maze | " + " | ".join(METHODS) + " |", "|---|" + "---|" * len(METHODS)]
    for maze in sorted(benchmark_mazes()):
        row = []
        for m in METHODS:
            values = [cells[(maze, m, proposer, s)] for s in SEEDS if (maze, m, proposer, s) in cells]
            row.append(_mean_text(values))
        lines.append(f"| {maze} | " + " | ".join(row) + " |")
    return "\n".join(lines)


def _mean_text(values: list[float]) -> str:
    if not values:
        return "—"
    mean, lo, hi = cmp.mean_ci(values)
    return f"{mean:.3f} [{lo:.3f}, {hi:.3f}] (n={len(values)})"


@dataclass
class Study:
    """Everything the grid decides and describes, from its table's rows."""
    entries: list  # the claims of every preset (paired, then the paper's)
    costs: list  # one dict per preset: runs at success 0, cost ratios
    maze_tables: list  # one markdown table per preset

    @property
    def markdown(self) -> str:
        return markdown(self.entries, self.costs)

    def summary(self) -> str:
        """README's table: one line per preset, the decided claims with their verdicts and the descriptive counts."""
        lines = ["| preset | ours-repair - ours, multi-room | ours-repair - ours, every maze | ours-repair / one-shot, "
                 "multi-room | ours-repair, change 1→5 rooms | runs at 0: ours, ours-repair, one-shot | "
                 "evaluations, proposer calls (ours-repair / ours) |", "|---|---|---|---|---|---|---|"]
        for preset, cost in zip(PRESETS, self.costs):
            mine = [e for e in self.entries if e["proposer"] == preset][:4]
            cells = [f"{_interval(e)} {e['verdict']}" + ("" if e["complete"] else " (*partial*)") for e in mine]
            ratios = f"{_times(cost['evaluations_ratio'])}, {_times(cost['proposer_calls_ratio'])}"
            lines.append(f"| {preset.split(':')[1]} | " + " | ".join(cells) + f" | {_zero_runs(cost)} | {ratios} |")
        return "\n".join(lines)


def study(rows: list[dict]) -> Study:
    cells, failed = cmp.table_cells(rows, "point")
    out = Study([], [], [])
    for p in PRESETS:
        out.entries += [paired_claim(cells, failed, p, cmp.MULTI_ROOM_MAZES, "multi-room"),
                        paired_claim(cells, failed, p, sorted(benchmark_mazes()), "every maze"),
                        *paper_claims(cells, failed, p)]
        out.costs.append(costs(rows, p))
        out.maze_tables.append(maze_table(cells, p))
    return out


TUNED = GRIDS["repair-tuned"]
TUNED_PAIR = ("ours-repair-tuned", "ours-repair")


def tuned_study(rows: list[dict]) -> tuple[list[dict], list[dict], str]:
    """The repair-tuned grid (docs/proposers.md, "Tuning a repaired chain"): per preset, the paired difference
    ours-repair-tuned - ours-repair on the multi-room cells and on every cell, runs at 0, the cost ratios."""
    cells, failed = cmp.table_cells(rows, "point")
    entries, cost_rows = [], []
    scopes = ((cmp.MULTI_ROOM_MAZES, "multi-room"), (sorted(benchmark_mazes()), "every maze"))
    for p in TUNED.proposers:
        entries += [paired_claim(cells, failed, p, mazes, scope, TUNED_PAIR, TUNED.seeds) for mazes, scope in scopes]
        cost_rows.append(costs(rows, p, TUNED_PAIR, TUNED_PAIR))
    return entries, cost_rows, markdown(entries, cost_rows, TUNED_PAIR)


def main(argv=None) -> int:
    ap = OneLineParser(prog="python -m specrefine.experiments.repair_claims", description=__doc__.splitlines()[0])
    ap.add_argument("table")
    ap.add_argument("--out", required=True, type=out_path)
    ap.add_argument("--tuned", action="store_true", help="TABLE is the repair-tuned grid's (data/results/repair/"
                                                         "tuned.csv): writes tuned_claims.md and tuned_claims.json")
    args = ap.parse_args(argv)
    try:
        rows = read_checked_table(args.table)
        with locked(ensure_dir(args.out)):
            print(write_tuned(rows, args) if args.tuned else write_claims(rows, args))
    except SpecrefineError as exc:
        ap.exit(2, f"{ap.prog}: error: {exc}\n")
    return 0


def write_tuned(rows, args) -> str:
    entries, cost_rows, text = tuned_study(rows)
    write_atomic(args.out / "tuned_claims.md", text + "\n")
    write_atomic(args.out / "tuned_claims.json", json.dumps(cmp._jsonable(
        {"table": str(args.table), "claims": entries, "costs": cost_rows}), indent=1) + "\n")
    return (f"{len(rows)} rows -> {args.out}: tuned_claims.md, tuned_claims.json "
            f"({sum(not e['complete'] for e in entries)} of {len(entries)} entries partial)")


def write_claims(rows, args) -> str:
    result = study(rows)
    about = {"table": str(args.table), "note": cmp.OFFLINE_NOTE, "presets": list(PRESETS), "seeds": list(SEEDS),
             "bootstrap_resamples": cmp.BOOTSTRAP_RESAMPLES, "bootstrap_seed": cmp.BOOTSTRAP_SEED}
    write_atomic(args.out / "claims.json", json.dumps(cmp._jsonable(
        {"about": about, "claims": result.entries, "costs": result.costs}), indent=1) + "\n")
    write_atomic(args.out / "claims.md", result.markdown + "\n")
    write_atomic(args.out / "mazes.md", "\n\n".join(result.maze_tables) + "\n")
    write_atomic(args.out / "summary.md", result.summary() + "\n")
    for name, fig in cmp.comparison_figures(rows, GRID).items():
        save_figure(fig, args.out / f"{name}.png", dpi=110)
    partial = sum(not e["complete"] for e in result.entries)
    return (f"{len(rows)} rows -> {args.out}: claims.md, claims.json, mazes.md, summary.md, figures "
            f"({partial} of {len(result.entries)} entries partial)")


if __name__ == "__main__":
    from ..core.argtypes import exit_code_quiet_on_broken_pipe

    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
