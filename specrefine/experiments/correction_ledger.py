"""What each run's correction decided, one row per run, read from its run folder (issue 39).

    specrefine correction-ledger runs/ant_corrector_redraw --out data/results/corrector/ledger/redraw

Descriptive, no rule. For every finished run whose search corrected its path (``correct-check`` steps in its
``steps.jsonl``): its passes; the path's legs at the first check and at the end; the legs it tried to correct; the
alternatives it took, by kind; the wins a second draw refuted (``ours-corrector-crosscheck``); and each pass's fresh
estimate of the path at its end, beside the success measured in the run's fresh episodes; and where its proposer calls
went, the search's (before the first check) and each pass's (issue 39's cost). The last of those estimates
minus the measured success says how much the correction's own check flatters the path it chose (it chose the path on
those rollouts). Writes ``ledger.csv``, ``ledger.md`` and ``ledger.png`` (each run's last check against its measured
success, with the measured success's 95 % interval); without ``--out`` prints the summary.
"""

from __future__ import annotations

import csv
from collections import Counter
from pathlib import Path

import numpy as np

from ..core.errors import SpecrefineError
from ..core.results import wilson_ci
from ..core.runfolder import ensure_dir, locked, save_figure, write_atomic
from ..core.tables import csv_text
from .corrector_diagnosis import events
from .taxonomy import Run, read_runs

CALLS = ("proposer_calls", "search_calls", "pass_calls")
BEFORE_CALLS = ("cell", "maze", "agent", "method", "proposer", "seed", "passes", "legs_at_check", "legs_at_end",
                "legs_tried", "taken", "taken_by_kind", "refuted", "check_p", "pass_end_p", "last_p", "success_rate",
                "episodes", "last_p_minus_success", "last_p_above_interval")
COLUMNS = BEFORE_CALLS + CALLS  # a ledger written before the calls were read has BEFORE_CALLS; its calls are unknown


def refuted(step: dict) -> int:
    """The wins of one ``correct-leg`` step that the second draw refuted (the path scored at least as well there)."""
    return sum(1 for t in step["tried"] if "p_window_second" in t and t["p_window_second"] <= t["p_current_second"])


def taken_kinds(row: dict) -> Counter:
    """A row's ``taken_by_kind`` ("split:2 bypass:1") as counts."""
    return Counter({kind: int(n) for kind, n in (entry.split(":") for entry in row["taken_by_kind"].split())})


def calls_by_phase(run: Run, checks: list[dict]) -> dict:
    """The run's proposer calls, the search's (up to the first check) and each pass's ("19;11"); "" where its log or
    result predates the counts."""
    marks = [c.get("proposer_calls") for c in checks] + [run.result.get("proposer_calls")]
    if any(m is None for m in marks):
        return dict.fromkeys(CALLS, "")
    return {"proposer_calls": marks[-1], "search_calls": marks[0],
            "pass_calls": ";".join(str(b - a) for a, b in zip(marks, marks[1:]))}


def ledger_row(run: Run) -> dict | None:
    """The row of one run, or None where its search made no correction."""
    checks, dones = events(run, "correct-check"), events(run, "correct-done")
    if not checks or not dones:
        return None
    r, legs = run.result, events(run, "correct-leg")
    taken = Counter(s["accepted"] for s in legs if s["accepted"])
    success, episodes, last = float(r["success_rate"]), int(r["episodes"]), float(dones[-1]["p"])
    high = wilson_ci(round(success * episodes), episodes)[1]
    return {"cell": run.cell, "maze": r["maze"], "agent": r.get("agent", ""), "method": r["method"],
            "proposer": r["proposer"], "seed": r["seed"], "passes": len(dones),
            "legs_at_check": len(checks[0]["path"]) - 1, "legs_at_end": len(dones[-1]["path"]) - 1,
            "legs_tried": len(legs), "taken": sum(taken.values()),
            "taken_by_kind": " ".join(f"{kind}:{n}" for kind, n in sorted(taken.items())),
            "refuted": sum(map(refuted, legs)), "check_p": float(checks[0]["p"]),
            "pass_end_p": ";".join(f"{d['p']:.4f}" for d in dones), "last_p": last,
            "success_rate": success, "episodes": episodes, "last_p_minus_success": last - success,
            "last_p_above_interval": last > high, **calls_by_phase(run, checks)}


INTS = ("seed", "passes", "legs_at_check", "legs_at_end", "legs_tried", "taken", "refuted", "episodes")
FLOATS = ("check_p", "last_p", "success_rate", "last_p_minus_success")


def ledger(runs: list[Run]) -> list[dict]:
    rows = [row for row in map(ledger_row, runs) if row is not None]
    if not rows:
        raise SpecrefineError("no finished run with a correction (correct-check steps) in the folders given")
    return _sorted(rows)


def _sorted(rows: list[dict]) -> list[dict]:
    return sorted(rows, key=lambda row: (row["method"], row["proposer"], row["seed"], row["maze"]))


def read_ledger(path: Path) -> list[dict]:
    """The rows of a ledger.csv this command wrote, typed as ``ledger_row`` makes them; none if there is no file."""
    if not path.exists():
        return []
    try:
        with path.open(newline="") as fh:
            reader = csv.DictReader(fh)
            if tuple(reader.fieldnames or ()) not in (COLUMNS, BEFORE_CALLS):
                raise ValueError("its columns are not a ledger's")
            return [{**dict.fromkeys(CALLS, ""), **row, **{c: int(row[c]) for c in INTS},
                     **{c: float(row[c]) for c in FLOATS}, **_calls(row),
                     "last_p_above_interval": {"True": True, "False": False}[row["last_p_above_interval"]]}
                    for row in reader]
    except (ValueError, KeyError, TypeError, csv.Error, UnicodeDecodeError) as exc:
        raise SpecrefineError(f"--keep: {path} is not a ledger this command wrote ({exc})") from None


def _calls(row: dict) -> dict:
    return {c: int(row[c]) for c in CALLS[:2] if row.get(c, "") != ""}


def calls_line(group: list[dict]) -> str:
    """Mean proposer calls per run, the search's and each pass's, over the runs whose calls are known."""
    known = [g for g in group if g["proposer_calls"] != ""]
    if not known:
        return "calls not logged"
    passes = [[int(n) for n in g["pass_calls"].split(";")] for g in known]
    per_pass = [np.mean([p[i] for p in passes if len(p) > i]) for i in range(max(map(len, passes)))]
    runs = f"{len(known)} run{'' if len(known) == 1 else 's'}"
    return (f"{np.mean([g['proposer_calls'] for g in known]):.1f} a run over {runs}: search "
            f"{np.mean([g['search_calls'] for g in known]):.1f}, "
            + ", ".join(f"pass {i + 1} {n:.1f}" for i, n in enumerate(per_pass)))


def _run_calls(row: dict) -> str:
    return "" if row["proposer_calls"] == "" else f"{row['search_calls']} + {row['pass_calls'].replace(';', ' + ')}"


def markdown(rows: list[dict]) -> str:
    lines = ["Every proposer here is offline, NOT a VLM. Descriptive (no rule); `specrefine correction-ledger` "
             "(specrefine/experiments/correction_ledger.py) from the run folders.", "",
             "| method | proposer | runs | fresh estimate at the check | at the end of the last pass | measured "
             "| last - measured | last above the measured 95 % interval | taken | refuted |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for (method, proposer), group in _groups(rows).items():
        kinds = sum(map(taken_kinds, group), Counter())
        lines.append(f"| {method} | {proposer} | {len(group)} | {np.mean([g['check_p'] for g in group]):.3f} | "
                     f"{np.mean([g['last_p'] for g in group]):.3f} | "
                     f"{np.mean([g['success_rate'] for g in group]):.3f} | "
                     f"{np.mean([g['last_p_minus_success'] for g in group]):+.3f} | "
                     f"{sum(g['last_p_above_interval'] for g in group)} of {len(group)} | "
                     f"{' '.join(f'{k} {n}' for k, n in sorted(kinds.items())) or 'none'} | "
                     f"{sum(g['refuted'] for g in group)} |")
    lines += ["", "Does the last check flatter longer paths more? Least squares of last - measured on the legs at "
              "the end:", ""]
    lines += [f"- {method} ({proposer}): {length_trend(group)}" for (method, proposer), group in _groups(rows).items()]
    lines += ["", "Where the proposer calls go (the search's, before the first check, and each pass's):", ""]
    lines += [f"- {method} ({proposer}): {calls_line(group)}" for (method, proposer), group in _groups(rows).items()]
    lines += ["", "Per run (`pass_end_p`: each pass's fresh estimate of the path at its end; calls: the search's + "
              "each pass's):", "",
              "| maze | method | seed | passes | legs at check | legs at end | tried | taken | refuted | check | "
              "pass ends | measured | calls |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['maze']} | {r['method']} | {r['seed']} | {r['passes']} | {r['legs_at_check']} | "
              f"{r['legs_at_end']} | {r['legs_tried']} | {r['taken_by_kind'] or 'none'} | {r['refuted']} | "
              f"{r['check_p']:.3f} | {r['pass_end_p'].replace(';', ', ')} | {r['success_rate']:.3f} | "
              f"{_run_calls(r)} |" for r in rows]
    return "\n".join(lines) + "\n"


def length_trend(group: list[dict]) -> str:
    """The slope of last - measured per 10 legs at the end, and Pearson's r, over a group's runs."""
    legs = np.array([g["legs_at_end"] for g in group], dtype=float)
    gap = np.array([g["last_p_minus_success"] for g in group])
    if len(group) < 3 or np.ptp(legs) == 0 or np.ptp(gap) == 0:
        return f"{len(group)} run{'' if len(group) == 1 else 's'}, too few or too alike for a trend"
    slope = np.polyfit(legs, gap, 1)[0]
    r = np.corrcoef(legs, gap)[0, 1]
    return (f"{slope * 10:+.3f} per 10 legs (Pearson r {r:+.2f}) over {len(group)} runs of "
            f"{int(legs.min())}-{int(legs.max())} legs")


def figure(rows: list[dict]):
    """Each run's last fresh check (x) against its measured success and 95 % interval (y), a marker per method;
    a run below the diagonal was flattered by its check."""
    from ..pictures.render import subplots

    fig, ax = subplots(figsize=(5.2, 5.0))
    low = 1.0
    for (method, proposer), group in _groups(rows).items():
        x = np.array([g["last_p"] for g in group])
        y = np.array([g["success_rate"] for g in group])
        ci = np.array([wilson_ci(round(g["success_rate"] * g["episodes"]), g["episodes"]) for g in group])
        ax.errorbar(x, y, yerr=[y - ci[:, 0], ci[:, 1] - y], fmt="o", ms=4, capsize=2, label=f"{method} ({proposer})")
        low = min(low, x.min(), ci[:, 0].min())
    low = min(low, 0.9) - 0.02
    ax.plot([low, 1.0], [low, 1.0], color="grey", lw=1, ls="--", label="check = measured")
    ax.set(xlim=(low, 1.005), ylim=(low, 1.005), xlabel="the correction's last fresh check of the path",
           ylabel="measured success (fresh episodes, 95 % interval)", title="Does the last check flatter the path?")
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    return fig


def _groups(rows: list[dict]) -> dict[tuple, list[dict]]:
    groups: dict[tuple, list[dict]] = {}
    for row in rows:
        groups.setdefault((row["method"], row["proposer"]), []).append(row)
    return groups


def add_arguments(p) -> None:
    from ..core.argtypes import out_path

    p.description = __doc__.split("\n\n")[0]
    p.add_argument("runs", nargs="+", type=Path, help="sweep folders (their cells/) or run folders")
    p.add_argument("--out", type=out_path, default=None,
                   help="folder for ledger.csv, ledger.md and ledger.png (default: the summary printed only)")
    p.add_argument("--keep", action="store_true",
                   help="keep the rows of --out's ledger.csv whose cells are not among RUNS (their folders may be gone "
                        "with another machine); a cell among RUNS gets its row from its folder (default: off)")


def run(args, p) -> int:
    if args.keep and args.out is None:
        p.error("--keep needs --out (the ledger whose rows it keeps)")
    rows = ledger(read_runs(args.runs))
    given = {row["cell"] for row in rows}
    kept = [row for row in read_ledger(args.out / "ledger.csv") if row["cell"] not in given] if args.keep else []
    rows = _sorted(rows + kept)
    text = markdown(rows)
    if args.out is None:
        print(text, end="")
        return 0
    with locked(ensure_dir(args.out)):
        write_atomic(args.out / "ledger.csv", csv_text(rows, COLUMNS))
        write_atomic(args.out / "ledger.md", text)
        save_figure(figure(rows), args.out / "ledger.png", dpi=110)
    print(f"{len(rows)} run{'' if len(rows) == 1 else 's'} with a correction"
          f"{f' ({len(kept)} kept from the ledger)' if args.keep else ''} -> {args.out}/ledger.{{csv,md,png}}")
    return 0


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("correction-ledger", argv, prog="python -m specrefine.experiments.correction_ledger")


if __name__ == "__main__":
    raise SystemExit(main())
