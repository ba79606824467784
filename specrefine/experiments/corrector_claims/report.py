"""claims.md: the rules with their verdicts, then every study's cells as markdown tables."""

from __future__ import annotations

import math

from .. import comparison as cmp
from .ant import ANT_BEFORE, ANT_GRID, ANT_METHOD, ANT_SEEDS
from .common import CENTRE, HELD_OUT_SEEDS, METHOD, POINT_SEEDS, POLISH, SELF_CONTAINED, VARIANTS, _known
from .formats import _ant_paired_text, _cost_text, _diff, _num, _paired_text, _signed
from .rules import _sided, helps_word, variant_verdicts, verdicts


def markdown(point: dict, ant: dict | None, held_out: dict | None = None, levers: dict | None = None,
             **variants: dict | None) -> str:
    """claims.md; ``variants``: the studies by their ``VARIANTS`` name (absent or None: not run)."""
    _known(variants)
    lines = [f"{cmp.OFFLINE_NOTE}. Point mass unless named; pooled over seeds {list(POINT_SEEDS)} (Ant: "
             f"{list(ANT_SEEDS)}), 200 fresh episodes per run; rules fixed in docs/corrector.md before the grids ran.",
             "", "| rule | estimate | verdict |", "|---|---|---|"]
    lines += [f"| {v['rule']} | {v['value']} | {v['verdict']} |" for v in verdicts(point, ant)]
    lines += ["", "Per U-chain (point): ours-corrector vs the oracle (ours x geometric), pooled over seeds; Newcombe "
              "95 % interval of the difference.", "",
              "| proposer | maze | runs | ours-corrector | oracle | difference |", "|---|---|---|---|---|---|"]
    for e in point["per_maze"] + point["severe"]:
        lines.append(f"| {e['proposer']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | "
                     f"{_num(e['reference_success'])} | {_diff(e)} |")
    lines += ["", "Every suite maze (point): ours-corrector - ours, pooled over seeds (Newcombe 95 %).", "",
              "| proposer | maze | runs (ours) | ours-corrector | ours | difference |", "|---|---|---|---|---|---|"]
    for e in point["versus_ours"]:
        lines.append(f"| {e['proposer']} | {e['maze']} | {e['runs']} ({e['reference_runs']}) | {_num(e['success'])} | "
                     f"{_num(e['reference_success'])} | {_diff(e)} |")
    lines += ["", "Change from 1 to 5 rooms (least-squares slope x 4 on u_chain_1..5; 95 % bootstrap over seeds), and "
              "runs at 0 on the U-chains.", "", "| proposer | method | change 1→5 rooms | verdict |",
              "|---|---|---|---|"]
    for e in point["rooms"]:
        lines.append(f"| {e['proposer']} | {e['method']} | {cmp._interval_text(e)} | {e['verdict']} |")
    lines += ["", "| proposer | " + " | ".join(f"{m} at 0" for m in (METHOD, "ours", "ours-repair")) + " |",
              "|---|---|---|---|"]
    for z in point["zero"]:
        lines.append(f"| {z['proposer']} | " + " | ".join(f"{z[m][0]}/{z[m][1]}" for m in
                                                          (METHOD, "ours", "ours-repair")) + " |")
    lines += ["", "| proposer | ratio | estimate [95 % CI] | verdict |", "|---|---|---|---|"]
    for e in point["ratio"]:
        lines.append(f"| {e['proposer']} | {e['method']} | {cmp._interval_text(e)} | {e['verdict']} |")
    lines += ["", "Cost: mean of ours-corrector over mean of ours on the same cells.", "",
              "| proposer | pairs | evaluations | proposer calls | simulator steps |", "|---|---|---|---|---|"]
    for c in point["costs"] + ([ant["costs"] | {"proposer": "Ant " + ant["costs"]["proposer"]}] if ant else []):
        lines.append(f"| {c['proposer']} | {c['pairs']} | {_num(c['evaluations_ratio'], '{:.2f}x')} | "
                     f"{_num(c['proposer_calls_ratio'], '{:.2f}x')} | {_num(c['sim_steps_ratio'], '{:.2f}x')} |")
    if held_out:
        lines += ["", "Held out (descriptive; the grid was fixed before it ran, no rule beyond reporting every cell): "
                  "layouts outside the suite and two error mixes no method was developed on (`HELD_OUT_MIXES` in "
                  "specrefine/experiments/grids.py, A and B), pooled over seeds "
                  f"{list(HELD_OUT_SEEDS)}; Newcombe 95 % interval of ours-corrector - ours. Runs at 0: "
                  + ", ".join(f"{m} {z}" for m, z in held_out["zero"].items()) + f" (of {held_out['runs']} each).",
                  "", "| mix | maze | runs | ours-corrector | ours | ours-corrector - ours | oracle |",
                  "|---|---|---|---|---|---|---|"]
        for e in held_out["per_maze"]:
            lines.append(f"| {e['mix']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | "
                         f"{_num(e['reference_success'])} | {_diff(e)} | {_num(e['oracle'])} |")
        lines += ["", "| held-out mix | pairs | evaluations | proposer calls | simulator steps |",
                  "|---|---|---|---|---|"]
        for c in held_out["costs"]:
            lines.append(f"| {c['proposer']} | {c['pairs']} | {_num(c['evaluations_ratio'], '{:.2f}x')} | "
                         f"{_num(c['proposer_calls_ratio'], '{:.2f}x')} | {_num(c['sim_steps_ratio'], '{:.2f}x')} |")
    if ant:
        lines += ant_markdown(ant)
    if levers:
        lines += levers_markdown(levers)
    for name in VARIANTS:
        if variants.get(name):
            lines += variant_markdown(variants[name])
    return "\n".join(lines) + "\n"


def ant_markdown(ant: dict) -> list[str]:
    """The Ant's cells per maze in ANT_GRID, each of ANT_CANDIDATES and ANT_BEFORE, their paired differences and
    ratios."""
    candidates = ant["candidates"]
    lines = ["", f"The Ant (imperfect:moderate, stage 5, centre goal points), pooled per maze (Wilson 95 %): "
             f"`{ANT_GRID}` ({ANT_METHOD}); " + "; ".join(f"`{c['grid']}` ({c['method']}, the Ant's corrector if "
                                                          "its rule holds)" for c in candidates)
             + " (docs/corrector.md, 'Aimed clear of the walls: the Ant' and 'A second draw for the Ant'); "
             f"`{ANT_BEFORE}`, ours-corrector on the same cells (stopped at its 10; 'The Ant with a confirmed pick'), "
             f"described. The rules read `{ant['grid']}`.", "",
             f"| maze | {ANT_METHOD}: runs | success [95 % CI] | "
             + "".join(f"{c['method']}: runs | success [95 % CI] | " for c in candidates)
             + f"{ANT_BEFORE}: runs | success |", "|---|---|---|" + "---|---|" * len(candidates) + "---|---|"]
    for i, (e, old) in enumerate(zip(ant["confirm"], ant["before"])):
        new = "".join(f"{c['per_maze'][i]['runs']} | {_rate_ci(c['per_maze'][i])} | " for c in candidates)
        lines.append(f"| {e['maze']} | {e['runs']} | {_rate_ci(e)} | {new}{old['runs']} | {_num(old['success'])} |")
    lines += [""] + [f"{c['method']} - {ANT_METHOD} on the cells both ran: {_ant_paired_text(c['paired'])}."
                     for c in candidates] + [
              f"{ANT_METHOD} - ours-corrector on the cells both ran: {_ant_paired_text(ant['paired'])}.",
              "", "Cost of each candidate: mean proposer calls and evaluations over those of "
              f"{ANT_METHOD} and of ours on the cells both ran.", "",
              "| method | pairs with confirm | calls | evaluations | pairs with ours | calls | evaluations |",
              "|---|---|---|---|---|---|---|"] + [
              f"| {c['method']} | {_cost_cells(c['cost_vs_confirm'])} | {_cost_cells(c['cost_vs_ours'])} |"
              for c in candidates] + [
              "", "| ratio | estimate [95 % CI] | verdict |", "|---|---|---|"]
    lines += [f"| {e['method']} | {cmp._interval_text(e)} | {e['verdict']} |" for e in ant["ratio"]]
    return lines + [line for s in ant["successors"] for line in successor_markdown(s)]


def successor_markdown(s: dict) -> list[str]:
    """A successor's cells per maze, its difference from the corrector it follows and its cost."""
    return ["", f"`{s['grid']}` ({s['method']}, in place of {s['followed_method']} if its rule holds; "
            f"docs/corrector.md, '{s['section']}'), pooled per maze (Wilson 95 %):", "",
            "| maze | runs | success [95 % CI] |", "|---|---|---|"] + [
            f"| {e['maze']} | {e['runs']} | {_rate_ci(e)} |" for e in s["per_maze"]] + [
            "", f"{s['method']} - {s['followed_method']} on the cells both ran: "
            f"{_ant_paired_text(s['paired'])}. Its mean cost over {s['followed_method']}'s: "
            f"{_cost_text(s['cost_vs_followed'])}; over ours's: {_cost_text(s['cost_vs_ours'])}."] + (
            [f"{s['method']} - {s['control'][0]} (the one change, described) on the cells both ran: "
             f"{_ant_paired_text(s['control'][1])}."] if s["control"] else [])


def _cost_cells(c: dict) -> str:
    """A cost's pairs, proposer calls and evaluations ratios as three table cells."""
    return " | ".join([str(c["pairs"])] + ["—" if math.isnan(c[key]) else f"{c[key]:.2f}x"
                                           for key in ("proposer_calls_ratio", "evaluations_ratio")])


def _rate_ci(e: dict) -> str:
    return _num(e["success"]) + (f" [{e['ci_low']:.3f}, {e['ci_high']:.3f}]" if "ci_low" in e else "")


def levers_markdown(lv: dict) -> list[str]:
    lines = ["", f"Each lever alone (grid `corrector-levers`: {', '.join(lv['mazes'])}, seeds {lv['seeds']}): pooled "
             "success, and the paired difference lever - reference over the same cells (95 % bootstrap over cells); "
             "against the method without the lever: helps above 0, hurts below, else undecided.", "",
             "| proposer | lever | runs | success | - ours | - ours-repair | - ours-corrector | proposer calls / ours "
             "| cells with the same success as ours / ours-corrector |",
             "|---|---|---|---|---|---|---|---|---|"]
    for e in lv["entries"]:
        v = e["versus"]
        repair = f"{_signed(v['ours-repair'])} {helps_word(v['ours-repair'])}" if "ours-repair" in v else "—"
        lines.append(f"| {e['proposer']} | {e['lever']} | {e['runs']} | {_num(e['success'])} | "
                     f"{_signed(v['ours'])} {helps_word(v['ours'])} | {repair} | {_signed(v[METHOD])} "
                     f"{_sided(v[METHOD])} | {_num(e['costs']['proposer_calls_ratio'], '{:.2f}x')} | "
                     f"{e['same']['ours']} / {e['same'][METHOD]} |")
    return lines


def variant_markdown(vs: dict) -> list[str]:
    method, grid, ref = vs["method"], vs["grid"], vs["reference"]
    short = method.removeprefix(f"{METHOD}-")
    lines = ["", f"`{method}` (grid `{grid}`; its rules fixed before it ran, docs/corrector.md):", "",
             "| rule | estimate | verdict |", "|---|---|---|"]
    lines += [f"| {v['rule']} | {v['value']} | {v['verdict']} |" for v in variant_verdicts(vs)]
    lines += ["", f"Cost beside {ref}'s on the same cells (mean over the mean of ours):", "",
              "| proposer | method | pairs | evaluations | proposer calls | simulator steps |",
              "|---|---|---|---|---|---|"]
    for mine, full in zip(vs["costs"], vs["corrector_costs"]):
        for name, c in ((method, mine), (ref, full)):
            lines.append(f"| {c['proposer']} | {name} | {c['pairs']} | {_num(c['evaluations_ratio'], '{:.2f}x')} | "
                         f"{_num(c['proposer_calls_ratio'], '{:.2f}x')} | {_num(c['sim_steps_ratio'], '{:.2f}x')} |")
    lines += ["", f"Per U-chain: {method} vs the oracle, pooled over seeds (Newcombe 95 %).", "",
              f"| proposer | maze | runs | {short} | oracle | difference |", "|---|---|---|---|---|---|"]
    lines += [f"| {e['proposer']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | "
              f"{_num(e['reference_success'])} | {_diff(e)} |" for e in vs["per_maze"] + vs.get("severe", [])]
    if vs.get("versus_ours"):
        whose = "its grids' code and settings" if method in SELF_CONTAINED else \
            "its own grids' code, before the spread start states"
        lines += ["", f"Every suite maze: {method} - ours, pooled over seeds (Newcombe 95 %; ours at {whose}).", "",
                  f"| proposer | maze | runs (ours) | {short} | ours | difference |", "|---|---|---|---|---|---|"]
        lines += [f"| {e['proposer']} | {e['maze']} | {e['runs']} ({e['reference_runs']}) | {_num(e['success'])} | "
                  f"{_num(e['reference_success'])} | {_diff(e)} |" for e in vs["versus_ours"]]
    if vs.get("fresh"):
        lines += fresh_markdown(vs["fresh"])
    if vs.get("new"):
        lines += new_markdown(vs["new"])
    if vs.get("informed"):
        lines += new_markdown(vs["informed"], informed=True)
    if vs.get("check"):
        lines += new_markdown(vs["check"])
    if "oracle_versus_paper" in vs:
        lines += ["", "Described beside its rules: the oracle (ours, geometric) as this grid runs it, against the "
                  f"oracle at the paper's settings (grid taxonomy) {_paired_text(vs['oracle_versus_paper'])} "
                  "(paired, U-chains, 95 % bootstrap)."]
    if "severe_vs_corrector" in vs:
        lines += ["", f"Severe (described): {method} - {ref} {_paired_text(vs['severe_vs_corrector'])}; - "
                  f"ours-repair {_paired_text(vs['severe_vs_repair'])} (paired, U-chains, 95 % bootstrap)."]
    if any(e["runs"] for e in vs["held_out"]):
        lines += ["", f"Held out (descriptive): {method} - {ref} per layout and mix (Newcombe 95 %), ours beside.",
                  "", f"| mix | maze | runs | {short} | {ref} | difference | ours |",
                  "|---|---|---|---|---|---|---|"]
        lines += [f"| {e['mix']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | {_num(e['reference_success'])}"
                  f" | {_diff(e)} | {_num(e['ours'])} |" for e in vs["held_out"]]
        lines += ["", "| held-out mix | method | pairs | evaluations | proposer calls | simulator steps |",
                  "|---|---|---|---|---|---|"]
        lines += [f"| {c['proposer']} | {c['method']} | {c['pairs']} | {_num(c['evaluations_ratio'], '{:.2f}x')} | "
                  f"{_num(c['proposer_calls_ratio'], '{:.2f}x')} | {_num(c['sim_steps_ratio'], '{:.2f}x')} |"
                  for c in vs["held_out_costs"]]
    return lines


def fresh_markdown(fresh: dict) -> list[str]:
    lines = ["", "Fresh layouts for the centre rule (described; docs/corrector.md): per generated maze and mix "
             f"(C, D), pooled over seeds; polish at centre - polish at sampled (Newcombe 95 %); {CENTRE} - "
             f"{POLISH} paired over the cells: {_paired_text(fresh['paired'])}. Runs at 0: "
             + ", ".join(f"{m} {z}" for m, z in fresh["zero"].items()) + f" (of {fresh['runs']} each).", "",
             "| mix | maze | runs | polish (centre) | polish (sampled) | difference | ours (centre) | oracle (centre) "
             "| oracle (sampled) |", "|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {e['mix']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | {_num(e['reference_success'])} | "
              f"{_diff(e)} | {_num(e['ours'])} | {_num(e['oracle'])} | {_num(e['oracle_sampled'])} |"
              for e in fresh["per_maze"]]
    return lines


def new_markdown(new: dict, informed: bool = False) -> list[str]:
    method, ref = new["method"], new["reference"]
    polish = " | polish (centre)" if "reference_paired" in new else ""
    what = "The cells that informed it, not held out" if informed else "Layouts and mixes no run had used"
    lines = ["", f"{what} (grid `{new['grid']}`; docs/corrector.md): per generated maze and "
             f"mix ({', '.join(new['names'])}), pooled over seeds; {method} - {ref} (Newcombe 95 %), paired over the "
             f"cells: {_paired_text(new['paired'])}"
             + (f"; {ref} - {CENTRE}: {_paired_text(new['reference_paired'])}" if "reference_paired" in new else "")
             + ". Runs at 0: " + ", ".join(f"{m} {z}" for m, z in new["zero"].items()) + f" (of {new['runs']} each).",
             "", f"| mix | maze | runs | {method} | {ref} | difference{polish} | ours (centre) | oracle (centre) |",
             "|---|---|---|---|---|---|" + "---|" * (2 + bool(polish))]
    lines += [f"| {e['mix']} | {e['maze']} | {e['runs']} | {_num(e['success'])} | {_num(e['reference_success'])} | "
              f"{_diff(e)}" + (f" | {_num(e['polish'])}" if polish else "") + f" | {_num(e['ours'])} | "
              f"{_num(e['oracle'])} |" for e in new["per_maze"]]
    return lines
