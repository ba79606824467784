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


def _ant_paired_text(e: dict) -> str:
    if not e["cells"]:
        return "no cell in both yet"
    lo, hi = e["ci"]
    return (f"{e['difference']:+.3f} [{lo:+.3f}, {hi:+.3f}] over {e['cells']} "
            f"cell{'s' * (e['cells'] > 1)} (Newcombe 95 %, pooled)")


def _signed(e: dict) -> str:
    return "—" if math.isnan(e["estimate"]) else f"{e['estimate']:+.3f} [{e['ci_low']:+.3f}, {e['ci_high']:+.3f}]"


def _cost_text(c: dict) -> str:
    return (f"{c['proposer'].split(':')[1]} ({c['pairs']} pairs) {_num(c['evaluations_ratio'], '{:.1f}x')} the "
            f"evaluations, {_num(c['proposer_calls_ratio'], '{:.1f}x')} the proposer calls, "
            f"{_num(c['sim_steps_ratio'], '{:.1f}x')} the simulator steps")


def _partial(entry: dict) -> str:
    return "" if entry["complete"] else f", partial: {entry['n_cells']} of {entry['n_expected']} cells"
