"""Where ours-corrector still loses and where its proposer calls go, read from the run folders (issue 39).

    specrefine corrector-diagnosis runs/corrector --reference runs/taxonomy --out data/results/corrector/diagnosis

Descriptive, no rule. Reads the finished run folders (``result.json``, ``steps.jsonl``) of ``ours-corrector`` (the
``corrector`` grid's sweep folder) and of ``ours`` and the oracle (``ours`` x ``geometric``; the ``taxonomy`` grid's
sweep folder and its ``oracle/``), at ``imperfect:mild`` and ``imperfect:moderate``:

- the losses on the long U-chains (``--mazes``): episodes lost per outcome (an avoid region touched, the time out),
  legs per path, and the mean loss per leg (1 - the leg's success in the 200 fresh episodes);
- the correction on those mazes: legs at its check and at its end, legs corrected, alternatives accepted (and those
  accepted by a gain of one rollout), its fresh estimate of the path before and after against the measured success;
- its proposer splits on every maze of the grid, by the fresh failures of the leg they were spent on, and the cost
  in proposer calls over ``ours``'s had the splits of legs with at most 1 or 2 fresh failures not been made (each run's
  proposer calls scaled by the share of its Algorithm 1 calls kept: an estimate, not a run).

Writes ``diagnosis.md`` and ``diagnosis.json``.
"""

from __future__ import annotations

import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np

from ..core.errors import SpecrefineError
from ..core.runfolder import ensure_dir, locked, write_atomic
from .grids import SCALING_MAZES
from .taxonomy import Run, read_runs

METHOD = "ours-corrector"
PROPOSERS = ("imperfect:mild", "imperfect:moderate")
LONG_MAZES = ("u_chain_4", "u_chain_4_subgoals", "u_chain_5", "u_chain_5_subgoals")
CHECK_ROLLOUTS = 128  # the correction's fresh rollouts per leg (4 x n, n = 32)
FAILURE_BINS = (1, 2, 3, 4)  # the last: at least 4
GATES = (2, 3)  # projected: proposer splits only on legs with at least this many fresh failures


def events(run: Run, name: str) -> list[dict]:
    return [s for s in run.steps if s.get("event") == name]


def fresh_failures(step: dict) -> int:
    """The corrected leg's failures in the correction's fresh rollouts (from its logged estimate)."""
    return round((1.0 - step["p_leg"]) * CHECK_ROLLOUTS)


def proposer_splits(step: dict) -> int:
    """Algorithm 1 calls a correct-leg step logged (its split and its split over the next waypoint)."""
    return sum(1 for t in step["tried"] if t["kind"] != "bypass")


def losses(runs: list[Run]) -> dict:
    """Outcomes of the fresh episodes, legs per path and the mean loss per leg."""
    outcomes, legs = Counter(), []
    for run in runs:
        outcomes.update(run.result.get("episode_outcomes") or {})
        legs.append([1.0 - p for p in run.result.get("leg_success") or [] if p is not None])
    flat = [x for path in legs for x in path]
    episodes = sum(outcomes.values())
    return {"runs": len(runs), "success": float(np.mean([r.result["success_rate"] for r in runs])) if runs else None,
            "episodes": episodes, "outcomes": dict(outcomes),
            "legs_per_path": float(np.mean([len(p) for p in legs])) if legs else None,
            "loss_per_leg": float(np.mean(flat)) if flat else None,
            "legs_losing": sum(1 for x in flat if x > 0), "legs": len(flat)}


def correction(runs: list[Run]) -> dict:
    """What the correction did on ``runs`` (ours-corrector), and its fresh estimates against the measured success."""
    checks = [events(r, "correct-check")[0] for r in runs]
    dones = [events(r, "correct-done")[0] for r in runs]
    legs = [s for r in runs for s in events(r, "correct-leg")]
    accepted = [s for s in legs if s["accepted"]]
    gains = [round((max(t["p_window"] for t in s["tried"]) - s["p_window"]) * CHECK_ROLLOUTS, 1) for s in accepted]
    return {"runs": len(runs), "legs_at_check": float(np.mean([len(c["path"]) - 1 for c in checks])),
            "legs_at_end": float(np.mean([len(r.result["path"]) - 1 for r in runs])),
            "legs_corrected": len(legs), "accepted": len(accepted),
            "accepted_by_kind": dict(Counter(s["accepted"] for s in accepted)),
            "accepted_by_one_rollout": sum(1 for g in gains if g <= 1.0),
            "fresh_p_before": float(np.mean([c["p"] for c in checks])),
            "fresh_p_after": float(np.mean([d["p"] for d in dones])),
            "measured": float(np.mean([r.result["success_rate"] for r in runs]))}


def splits_by_failures(runs: list[Run]) -> list[dict]:
    """The correction's Algorithm 1 calls by the fresh failures of the leg they were spent on."""
    out = []
    for i, low in enumerate(FAILURE_BINS):
        last = i == len(FAILURE_BINS) - 1
        legs = [s for r in runs for s in events(r, "correct-leg")
                if fresh_failures(s) == low or (last and fresh_failures(s) >= low)]
        out.append({"fresh_failures": f">= {low}" if last else str(low), "legs": len(legs),
                    "splits": sum(map(proposer_splits, legs)),
                    "accepted_split": sum(1 for s in legs if s["accepted"] in ("split", "resplit")),
                    "accepted_bypass": sum(1 for s in legs if s["accepted"] == "bypass")})
    return out


def total_splits(run: Run) -> int:
    done = events(run, "done")
    return int(done[-1].get("splits_generated") or 0) if done else 0


def cost(runs: list[Run], ours: dict[tuple, Run], proposer: str) -> dict:
    """Proposer calls over ours's on the paired cells, Algorithm 1 calls by phase, and the gates' projection."""
    pairs = [(r, ours[key]) for r in runs if (key := cell_key(r)) in ours and r.result["proposer"] == proposer]
    mine = sum(r.result["proposer_calls"] for r, _ in pairs)
    theirs = sum(o.result["proposer_calls"] for _, o in pairs)
    splits = sum(total_splits(r) for r, _ in pairs)
    corrected = sum(proposer_splits(s) for r, _ in pairs for s in events(r, "correct-leg"))
    entry = {"proposer": proposer, "pairs": len(pairs), "proposer_calls": mine, "ours_proposer_calls": theirs,
             "ratio": mine / theirs if theirs else None, "algorithm1_calls": splits,
             "algorithm1_in_correction": corrected}
    for gate in GATES:
        kept = sum(r.result["proposer_calls"] * (1 - skipped(r, gate) / max(total_splits(r), 1)) for r, _ in pairs)
        entry[f"projected_ratio_gate_{gate}"] = kept / theirs if theirs else None
    return entry


def skipped(run: Run, gate: int) -> int:
    return sum(proposer_splits(s) for s in events(run, "correct-leg") if fresh_failures(s) < gate)


def cell_key(run: Run) -> tuple:
    r = run.result
    return r["maze"], r["proposer"], r["seed"]


def study(corrector: list[Run], ours: list[Run], oracle: list[Run], mazes=LONG_MAZES) -> dict:
    mine = [r for r in corrector if r.result.get("method") == METHOD and r.result.get("proposer") in PROPOSERS]
    if not mine:
        raise SpecrefineError(f"no finished {METHOD} run at {' or '.join(PROPOSERS)} in the folders given")
    long_ = [r for r in mine if r.result["maze"] in mazes]
    theirs = {cell_key(r): r for r in ours if r.result.get("method") == "ours"}
    oracle_long = [r for r in oracle if r.result["maze"] in mazes and r.result.get("proposer") == "geometric"]
    ours_long = [theirs[k] for k in map(cell_key, long_) if k in theirs]
    return {"mazes": list(mazes), "losses": {METHOD: losses(long_), "ours": losses(ours_long),
                                             "oracle": losses(oracle_long)},
            "correction": correction(long_), "splits_by_failures": splits_by_failures(mine),
            "cost": [cost(mine, theirs, p) for p in PROPOSERS], "runs": len(mine),
            "cost_u_chains": [cost([r for r in mine if r.result["maze"] in SCALING_MAZES], theirs, p)
                              for p in PROPOSERS]}


def _f(x, fmt="{:.3f}") -> str:
    return "—" if x is None else fmt.format(x)


def markdown(s: dict) -> str:
    mazes = ", ".join(s["mazes"])
    lines = ["Every proposer here is offline, NOT a VLM. Descriptive (no rule); `specrefine corrector-diagnosis` "
             "(specrefine/experiments/corrector_diagnosis.py) from the run folders of the `corrector` and `taxonomy` "
             "grids.", "", f"Losses on {mazes} at mild and moderate (seeds 0-3; the oracle: ours x geometric, "
             "seeds 0-3):", "",
             "| runs of | runs | mean success | episodes | lost: avoid touched | lost: timeout | legs per path | "
             "mean loss per leg | legs losing any |", "|---|---|---|---|---|---|---|---|---|"]
    for name, e in s["losses"].items():
        o = e["outcomes"]
        lines.append(f"| {name} | {e['runs']} | {_f(e['success'])} | {e['episodes']} | {o.get('avoid', 0)} | "
                     f"{o.get('timeout', 0)} | {_f(e['legs_per_path'], '{:.1f}')} | {_f(e['loss_per_leg'], '{:.4f}')}"
                     f" | {e['legs_losing']} of {e['legs']} |")
    c = s["correction"]
    kinds = ", ".join(f"{k} {v}" for k, v in sorted(c["accepted_by_kind"].items()))
    lines += ["", f"The correction on the same {c['runs']} runs: legs per path {c['legs_at_check']:.1f} at its check, "
              f"{c['legs_at_end']:.1f} at its end; {c['legs_corrected']} legs corrected, {c['accepted']} alternatives "
              f"accepted ({kinds}), {c['accepted_by_one_rollout']} of them by a gain of one rollout of "
              f"{CHECK_ROLLOUTS}; its fresh estimate of the path {c['fresh_p_before']:.3f} before (mean), "
              f"{c['fresh_p_after']:.3f} after, measured {c['measured']:.3f} (200 fresh episodes).", "",
              f"The correction's proposer splits on every maze of the grid (mild and moderate, {s['runs']} runs), by "
              f"the fresh failures (of {CHECK_ROLLOUTS}) of the leg they were spent on:", "",
              "| fresh failures | legs corrected | Algorithm 1 calls | split accepted | bypass accepted |",
              "|---|---|---|---|---|"]
    for e in s["splits_by_failures"]:
        lines.append(f"| {e['fresh_failures']} | {e['legs']} | {e['splits']} | {e['accepted_split']} | "
                     f"{e['accepted_bypass']} |")
    lines += ["", "Proposer calls over ours's on the paired cells (every maze of the grid); Algorithm 1 calls in all "
              "and in the correction (its logged splits: a lower bound); projected: each run's proposer calls scaled "
              "by the share of its Algorithm 1 calls left without the correction's splits of legs with fewer fresh "
              "failures than the gate (an estimate from the logs, not a run).", "",
              *COST_HEADER, *map(_cost_row, s["cost"]), "",
              "The same on the U-chain cells alone (U-chain 1-5 with and without subgoals: the cells of grid "
              "`corrector-gated`):", "", *COST_HEADER, *map(_cost_row, s["cost_u_chains"])]
    return "\n".join(lines) + "\n"


COST_HEADER = ("| proposer | pairs | proposer calls | ours | ratio | Algorithm 1 calls | in the correction | "
               + " | ".join(f"projected, gate {g}" for g in GATES) + " |", "|---|---|---|---|---|---|---|"
               + "---|" * len(GATES))


def _cost_row(e: dict) -> str:
    return (f"| {e['proposer']} | {e['pairs']} | {e['proposer_calls']} | {e['ours_proposer_calls']} | "
            f"{_f(e['ratio'], '{:.2f}x')} | {e['algorithm1_calls']} | {e['algorithm1_in_correction']} | "
            + " | ".join(_f(e[f"projected_ratio_gate_{g}"], "{:.2f}x") for g in GATES) + " |")


def add_arguments(p) -> None:
    from ..core.argtypes import out_path

    p.description = __doc__.split("\n\n")[0]
    p.add_argument("runs", type=Path, help="the corrector grid's sweep folder (its cells/) or run folders' parent")
    p.add_argument("--reference", type=Path, required=True,
                   help="the taxonomy grid's sweep folder: ours in its cells/, the oracle in its oracle/")
    p.add_argument("--out", type=out_path, default=None, help="folder for diagnosis.md and diagnosis.json "
                                                              "(default: diagnosis.md printed only)")


def run(args, p) -> int:
    try:
        s = study(read_runs([args.runs]), read_runs([args.reference]), read_runs([args.reference / "oracle"]))
        text = markdown(s)
        if args.out is None:
            print(text, end="")
            return 0
        with locked(ensure_dir(args.out)):
            write_atomic(args.out / "diagnosis.md", text)
            write_atomic(args.out / "diagnosis.json", json.dumps(s, indent=1) + "\n")
    except (KeyError, IndexError) as exc:
        print(f"{p.prog}: error: a run folder lacks what a finished {METHOD} run logs ({exc!r})", file=sys.stderr)
        return 2
    print(f"-> {args.out}/diagnosis.md")
    return 0


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("corrector-diagnosis", argv, prog="python -m specrefine.experiments.corrector_diagnosis")


if __name__ == "__main__":
    raise SystemExit(main())
