"""Each rule of docs/corrector.md with its estimate and verdict ("partial" while a cell is missing): the corrector's,
the Ant's and each variant's (claims.md's rules table, claims.json's "rules")."""

from __future__ import annotations

import math

from .. import comparison as cmp
from .ant import ANT_FLOOR, ANT_METHOD, ANT_SEEDS
from .common import COST_CAP, GATED, METHOD, NO_MORE, NON_INFERIORITY, POINT_SEEDS, TOLERANCE, _below_ours
from .formats import _ant_paired_text, _num, _paired_text


def verdicts(point: dict, ant: dict | None) -> list[dict]:
    """Each rule of docs/corrector.md with its verdict ("partial" while a cell is missing)."""
    out = []
    for proposer in ("imperfect:mild", "imperfect:moderate"):
        mazes = [e for e in point["per_maze"] if e["proposer"] == proposer]
        complete = all(e["runs"] == len(POINT_SEEDS) for e in mazes)
        within = [e for e in mazes if e["success"] >= e["reference_success"] - TOLERANCE]
        out.append({"rule": f"{proposer}: within {TOLERANCE} of the oracle on every U-chain",
                    "value": f"{len(within)} of {len(mazes)} mazes", "verdict": _verdict(len(within) == len(mazes),
                                                                                        complete)})
        rooms = next(e for e in point["rooms"] if e["proposer"] == proposer and e["method"] == METHOD)
        out.append({"rule": f"{proposer}: flat from 1 to 5 rooms", "value": cmp._interval_text(rooms),
                    "verdict": rooms["verdict"] + ("" if rooms["complete"] else " (partial)")})
        zero = next(z for z in point["zero"] if z["proposer"] == proposer)[METHOD]
        out.append({"rule": f"{proposer}: no run at 0", "value": f"{zero[0]} of {zero[1]} runs at 0",
                    "verdict": _verdict(zero[0] == 0, complete)})
        out.append(_suite_rule(point["versus_ours"], proposer, f"{proposer}"))
        ratio = next(e for e in point["ratio"] if e["proposer"] == proposer and e["method"].startswith(METHOD))
        out.append({"rule": f"{proposer}: {METHOD} >= 2x the one-shot on multi-room (point)",
                    "value": cmp.ratio_rule_text(ratio), "verdict": ratio["verdict"]
                    + ("" if ratio["complete"] else " (partial)")})
    severe = point["severe_vs_repair"]
    out.append({"rule": "imperfect:severe: no worse than ours-repair (paired, U-chains)",
                "value": _paired_text(severe), "verdict": ("no worse" if severe["verdict"] != "lower"
                                                                  else "worse") + ("" if severe["complete"]
                                                                                   else " (partial)")})
    for c in point["costs"]:
        out.append({"rule": f"{c['proposer']}: cost at most {COST_CAP}x ours (evaluations, proposer calls)",
                    "value": f"{_num(c['evaluations_ratio'], '{:.2f}x')}, {_num(c['proposer_calls_ratio'], '{:.2f}x')}"
                             f" over {c['pairs']} pairs",
                    "verdict": _cost_verdict(c)})
    if ant:
        out += _ant_verdicts(ant)
    return out


def _ant_verdicts(ant: dict) -> list[dict]:
    """The Ant's floor and ratio rules on the adopted grid, and each candidate corrector's adoption rule."""
    floor = f"Ant ({ant['method']}), imperfect:moderate: at least {ANT_FLOOR} on every maze"
    if not any(e["runs"] for e in ant["per_maze"]):
        out = [{"rule": floor, "value": f"{ant['grid']}: no cell yet", "verdict": "not run yet"}]
    else:
        complete = all(e["runs"] == len(ANT_SEEDS) for e in ant["per_maze"])
        ran = [e for e in ant["per_maze"] if e["runs"]]
        low = [e["maze"] for e in ran if e["success"] < ANT_FLOOR]
        ratio = ant["ratio"][0]
        scope = "" if complete else f" run so far (of {len(ant['per_maze'])})"
        out = [{"rule": floor, "value": f"below on {len(low)} of the {len(ran)} mazes{scope}"
                + (f": {', '.join(low)}" if low else ""),
                "verdict": _verdict(not low, complete)},
               {"rule": f"Ant: {ant['method']} >= 2x the one-shot on multi-room", "value": cmp.ratio_rule_text(ratio),
                "verdict": ratio["verdict"] + ("" if ratio["complete"] else " (partial)")},
               _ant_cost_verdict(ant)]
    return out + [_candidate_verdict(c, ant["method"]) for c in ant["candidates"]] + \
        [_successor_verdict(s, ant["method"]) for s in ant["successors"]]


def _ant_cost_verdict(ant: dict) -> dict:
    """Issue 39's cap on the Ant: the read corrector's mean proposer calls and evaluations over ours's, on the cells
    both ran (ours from the scaling grid's erring runs)."""
    c = ant["costs"]
    return {"rule": f"Ant ({ant['method']}), imperfect:moderate: cost at most {COST_CAP}x ours (proposer calls, "
                    "evaluations)",
            "value": f"{_num(c['proposer_calls_ratio'], '{:.2f}x')}, {_num(c['evaluations_ratio'], '{:.2f}x')} over "
                     f"{c['pairs']} pairs",
            "verdict": _cost_verdict(c)}


def _successor_verdict(s: dict, read: str) -> dict:
    """A successor's rule: "adopted" when the Ant's rules read it, the parts missed where its rule does not hold."""
    e, calls = s["paired"], s["cost_vs_followed"]["proposer_calls_ratio"]
    if not e["complete"]:
        verdict = f"undecided ({e['cells']} of {e['expected']} cells)"
    elif not s["adopted"]:
        verdict = f"not adopted ({', '.join(part for part, held in s['parts'].items() if not held)} missed)"
    else:
        verdict = "adopted" if s["method"] == read else f"holds; {read} read"
    value = _ant_paired_text(e) + ("" if math.isnan(calls) else f"; proposer calls {calls:.2f}x")
    return {"rule": f"Ant: {s['method']} in place of {s['followed_method']}: {s['rule']}", "value": value,
            "verdict": verdict}


def _candidate_verdict(candidate: dict, read: str) -> dict:
    """A candidate's adoption rule: "adopted" when the Ant's rules read it, "holds" when its rule holds but another
    candidate with a higher pooled success is read."""
    e = candidate["paired"]
    if not e["complete"]:
        verdict = f"undecided ({e['cells']} of {e['expected']} cells)"
    else:
        verdict = "not adopted" if not candidate["adopted"] else "adopted" if candidate["method"] == read else \
            f"holds; {read} read (higher pooled success)"
    return {"rule": f"Ant: {candidate['method']} - {ANT_METHOD} above 0 (95 % interval, every paired cell; adopted "
                    "as the Ant's corrector)", "value": _ant_paired_text(e), "verdict": verdict}


def _cost_verdict(c: dict) -> str:
    worst = max(c["evaluations_ratio"], c["proposer_calls_ratio"])
    if math.isnan(worst):
        return "undecided (no pairs)"
    return "holds" if worst <= COST_CAP else "does not hold"


def _verdict(ok: bool, complete: bool) -> str:
    return ("holds" if ok else "does not hold") + ("" if complete else " (partial)")


def helps_word(entry: dict) -> str:
    """The lever-alone rule's word for a paired difference against the method without it."""
    word = {"higher": "helps", "lower": "hurts"}.get(entry["verdict"], "undecided")
    return word + ("" if entry["complete"] else f" (partial: {entry['n_cells']} of {entry['n_expected']} cells)")


def _sided(entry: dict) -> str:
    return entry["verdict"] + ("" if entry["complete"] else f" (partial: {entry['n_cells']} of "
                                                             f"{entry['n_expected']} cells)")


def versus_corrector(vs: dict) -> tuple[str, str]:
    """(rule, verdict) of a variant against its reference, as its section of docs/corrector.md fixed it: the gate
    is to be no worse (lower end >= -NON_INFERIORITY); the later variants help (lower end > 0), are no worse, or are
    worse."""
    v, method = vs["versus_corrector"], vs["method"]
    scope = f"{method} - {vs['reference']} (paired, U-chains, mild and moderate)"
    known = not math.isnan(v["estimate"])
    no_worse = known and v["ci_low"] >= -NON_INFERIORITY
    if method == GATED:
        return f"{scope}: lower end >= -{NON_INFERIORITY}", _verdict(no_worse, v["complete"])
    word = "helps" if known and v["ci_low"] > 0 else "no worse" if no_worse else "worse" if known else "undecided"
    return (f"{scope}: helps if the lower end > 0, no worse if >= -{NON_INFERIORITY}",
            word + ("" if v["complete"] else " (partial)"))


def _mazes_run(versus: list[dict], proposer: str) -> str:
    """How many suite mazes the method has runs on at ``proposer``: 'N' when all of them, else 'N run (of M)'."""
    mine = [e for e in versus if e["proposer"] == proposer]
    ran = sum(1 for e in mine if e["runs"])
    return f"{ran}" if ran == len(mine) else f"{ran} run (of {len(mine)})"


def _suite_rule(versus: list[dict], proposer: str, name: str) -> dict:
    """The issue's rule 'not below ours on any suite maze' at ``proposer``, its row named ``name``."""
    mine, below = [e for e in versus if e["proposer"] == proposer], _below_ours(versus, proposer)
    return {"rule": f"{name}: not below ours on any suite maze (Newcombe)",
            "value": f"below on {len(below)} of {_mazes_run(versus, proposer)}" + (f" ({', '.join(below)})" if below
                                                                                   else ""),
            "verdict": _verdict(not below, all(e["runs"] == len(POINT_SEEDS) for e in mine))}


def variant_verdicts(vs: dict) -> list[dict]:
    """The rules of the variant's section of docs/corrector.md."""
    method, out = vs["method"], []
    for c in vs["costs"]:
        ratios = f"{_num(c['proposer_calls_ratio'], '{:.2f}x')}, {_num(c['evaluations_ratio'], '{:.2f}x')}"
        out.append({"rule": f"{method}, {c['proposer']}: cost at most {COST_CAP}x ours (proposer calls, evaluations)",
                    "value": f"{ratios} over {c['pairs']} pairs", "verdict": _cost_verdict(c)})
    rule, verdict = versus_corrector(vs)
    out.append({"rule": rule, "value": _paired_text(vs["versus_corrector"]), "verdict": verdict})
    for proposer in ("imperfect:mild", "imperfect:moderate"):
        mazes = [e for e in vs["per_maze"] if e["proposer"] == proposer]
        within = [e for e in mazes if e["runs"] and e["success"] >= e["reference_success"] - TOLERANCE]
        complete = all(e["runs"] == len(POINT_SEEDS) and e["reference_runs"] for e in mazes)
        out.append({"rule": f"{method}, {proposer}: within {TOLERANCE} of the oracle on every U-chain",
                    "value": f"{len(within)} of {len(mazes)} mazes", "verdict": _verdict(len(within) == len(mazes),
                                                                                        complete)})
        rooms = next(e for e in vs["rooms"] if e["proposer"] == proposer)
        out.append({"rule": f"{method}, {proposer}: flat from 1 to 5 rooms", "value": cmp._interval_text(rooms),
                    "verdict": rooms["verdict"] + ("" if rooms["complete"] else " (partial)")})
        zero = next(z for z in vs["zero"] if z["proposer"] == proposer)["runs"]
        out.append({"rule": f"{method}, {proposer}: no run at 0", "value": f"{zero[0]} of {zero[1]} runs at 0",
                    "verdict": _verdict(zero[0] == 0, complete)})
        if vs.get("versus_ours"):
            out.append(_suite_rule(vs["versus_ours"], proposer, f"{method}, {proposer}"))
        ratio = next((e for e in vs.get("ratio", []) if e["proposer"] == proposer), None)
        if ratio is not None:
            out.append({"rule": f"{method}, {proposer}: >= 2x the one-shot on multi-room (point)",
                        "value": cmp.ratio_rule_text(ratio),
                        "verdict": ratio["verdict"] + ("" if ratio["complete"] else " (partial)")})
    if "severe_vs_repair" in vs:
        severe = vs["severe_vs_repair"]
        verdict = "not run" if math.isnan(severe["estimate"]) else \
            ("no worse" if severe["verdict"] != "lower" else "worse") + ("" if severe["complete"] else " (partial)")
        out.append({"rule": f"{method}, imperfect:severe: no worse than ours-repair (paired, U-chains)",
                    "value": _paired_text(severe), "verdict": verdict})
    if "adoption" in vs:
        out += _adoption_rows(vs)
    return out


def _adoption_rows(vs: dict) -> list[dict]:
    """The two parts of persist's adoption rule (docs/corrector.md, "Corrected until alive") and its outcome."""
    a, method, ref = vs["adoption"], vs["method"], vs["reference"]
    pending = "" if a["complete"] else " (partial)"
    runs = f"runs below {a['floor']:g}" if a.get("floor") else "runs at 0"
    below = f"; below ours on {', '.join(a['below_ours'])}" if a["below_ours"] else "; below ours on no suite maze"
    return [{"rule": f"{method}, adoption 1: no worse than {ref} (U-chains, mild and moderate) and below ours on no "
                     "suite maze", "value": _paired_text(vs["versus_corrector"]) + below,
             "verdict": ("holds" if a["no_worse"] else "does not hold") + pending},
            {"rule": f"{method}, adoption 2: {'no more' if method in NO_MORE else 'fewer'} {runs} than {ref} over "
                     "the severe and new cells, paired difference >= 0",
             "value": f"{runs}: {a['zero'][method]} against {a['zero'][ref]}; {_paired_text(a['paired'])}",
             "verdict": ("holds" if a["fewer_zero"] else "does not hold") + pending},
            {"rule": f"{method}: adopted (README's rules table reads it)", "value": "both parts hold"
             if a["no_worse"] and a["fewer_zero"] else "not both parts",
             "verdict": ("adopted" if a["adopted"] else "not adopted") + pending}]
