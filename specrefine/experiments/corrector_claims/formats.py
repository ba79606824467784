"""How the claims write a number, a difference with its interval, a paired difference and a cost ratio (claims.md,
the rules' rows and README's passages)."""

from __future__ import annotations

import math


def _num(x, fmt="{:.3f}") -> str:
    return "—" if x is None or (isinstance(x, float) and math.isnan(x)) else fmt.format(x)


def _diff(e) -> str:
    if "difference" not in e:
        return "—"
    return f"{e['difference']:+.3f} [{e['ci_low']:+.3f}, {e['ci_high']:+.3f}]"


def _paired_text(e: dict) -> str:
    if math.isnan(e["estimate"]):
        return "—"
    return f"difference {e['estimate']:+.3f} [{e['ci_low']:+.3f}, {e['ci_high']:+.3f}] over {e['n_cells']} cells"


def _ant_interval(e: dict) -> str:
    """An Ant paired difference (``paired_rows``) with its interval."""
    lo, hi = e["ci"]
    return f"{e['difference']:+.3f} [{lo:+.3f}, {hi:+.3f}]"


def _ant_paired_text(e: dict) -> str:
    if not e["cells"]:
        return "no cell in both yet"
    return f"{_ant_interval(e)} over {e['cells']} cell{'s' * (e['cells'] > 1)} (Newcombe 95 %, pooled)"


def _ant_against(e: dict | None, against: str | None) -> str:
    """The Ant table's cell for a grid's difference from the corrector it was judged against (None: the reference)."""
    if e is None:
        return "— (the reference)"
    if not e["cells"]:
        return f"vs {against}: no cell in both yet"
    return f"{_ant_interval(e)} vs {against}, {e['cells']}"


def _signed(e: dict) -> str:
    return "—" if math.isnan(e["estimate"]) else f"{e['estimate']:+.3f} [{e['ci_low']:+.3f}, {e['ci_high']:+.3f}]"


def _cost_pair(c: dict) -> str:
    """Proposer calls and evaluations over another method's, as the Ant table's cell."""
    if not c["pairs"]:
        return "—"
    return (f"{_num(c['proposer_calls_ratio'], '{:.2f}x')}, {_num(c['evaluations_ratio'], '{:.2f}x')} "
            f"({c['pairs']} pairs)")


def _cost_table(label: str, named: list[tuple[str, dict]]) -> list[str]:
    """A markdown table of cost ratios over another method's, a row per (name, cost) of ``named``."""
    keys = ("proposer_calls_ratio", "evaluations_ratio", "sim_steps_ratio")
    return (["", f"| {label} | pairs | proposer calls | evaluations | simulator steps |", "|---|---|---|---|---|"]
            + [f"| {name} | {c['pairs']} | " + " | ".join(_num(c[k], "{:.2f}x") for k in keys) + " |"
               for name, c in named])


def _cost_text(c: dict) -> str:
    return (f"{c['proposer'].split(':')[1]} ({c['pairs']} pairs) {_num(c['evaluations_ratio'], '{:.1f}x')} the "
            f"evaluations, {_num(c['proposer_calls_ratio'], '{:.1f}x')} the proposer calls, "
            f"{_num(c['sim_steps_ratio'], '{:.1f}x')} the simulator steps")


def _partial(entry: dict) -> str:
    return "" if entry["complete"] else f", partial: {entry['n_cells']} of {entry['n_expected']} cells"
