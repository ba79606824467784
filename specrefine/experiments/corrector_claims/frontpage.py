"""The ``<!-- front corrector NAME -->`` passages of README.md and docs/corrector.md: their texts from the studies
(``front``, ``rules_table``) and the rewrite of a file's markers (``fill``)."""

from __future__ import annotations

import math
import re
from pathlib import Path

from ...core.errors import SpecrefineError
from ...core.mazes import u_chain
from ...core.runfolder import locked, write_atomic
from .. import ant_fresh
from .. import comparison as cmp
from ..grids import GRIDS, ROOT
from .ant import ANT_BEFORE, ANT_CANDIDATES, ANT_FIRST, ANT_FLOOR, ANT_GRID, ANT_METHOD, ANT_SEEDS, ANT_SUCCESSORS
from .anyproposer import any_study, any_text
from .common import (
    ADOPTABLE,
    COST_CAP,
    GATED,
    HELD_OUT_SEEDS,
    METHOD,
    MIX_NAMES,
    NON_INFERIORITY,
    REPORTED,
    TOLERANCE,
    VARIANT_GRIDS,
    VARIANT_SUITE,
    VARIANTS,
    _below_ours,
    _known,
)
from .default import DEFAULTS, default_marker, default_studies, default_text, default_verdict, gr_study, gr_text
from .formats import _ant_against, _cost_pair, _cost_text, _num, _paired_text, _partial, _signed
from .layouts import FRESH_GRIDS, INFORMED_PARTS, NEW_GRIDS, NEW_STUDIES, unseen
from .rescue import PAIRS, pair_studies, pair_text, pair_verdict
from .rules import (
    _adoption_rows,
    _cost_verdict,
    _mazes_run,
    _verdict,
    helps_word,
    variant_verdicts,
    verdicts,
    versus_corrector,
)
from .statements import STATEMENTS, statement_studies, statement_text

MARKER = re.compile(r"(<!-- front corrector ([\w-]+) -->)(.*?)(<!-- /front corrector \2 -->)", re.S)


def fill(path: Path, texts: dict[str, str]) -> None:
    """Rewrite every ``<!-- front corrector NAME -->`` passage of ``path`` with ``texts[NAME]`` (whole file, atomic;
    a marker with no text is an error, and nothing is written). A text of several lines keeps the indentation of its
    marker's line, so that a table stays inside its list item."""
    source = path.read_text()
    unknown = sorted({m.group(2) for m in MARKER.finditer(source)} - set(texts))
    if unknown:
        raise SpecrefineError(f"{path}: no text for the marker(s) {', '.join(unknown)}")

    def text(m: re.Match) -> str:
        line = source[source.rfind("\n", 0, m.start()) + 1:m.start()]
        indent = line if not line.strip() else ""
        body = re.sub(r"\n[ \t]+(?=\n)", "\n", texts[m.group(2)].replace("\n", "\n" + indent))
        return m.group(1) + body + m.group(4)

    with locked(path.parent):
        write_atomic(path, MARKER.sub(text, source))


def rules_table(variant: dict | None, point: dict, ant: dict | None, defaults: list[dict] = (),
                pairs: dict | None = None) -> str:
    """Issue 39's rules for the reported variant, the held-out cells it is described on, the point mass's default
    methods (``default_studies``) and the Ant's rules (the paired studies' last, ``pair_studies``), as one markdown
    table (README's front page)."""
    if not variant:
        return "not run yet"
    method = variant["method"]
    rows = [dict(v, rule=v["rule"].removeprefix(f"{method}, ")) for v in variant_verdicts(variant)]
    order = [v for v in rows if "cost at most" not in v["rule"] and not v["rule"].startswith(method)]
    order += [v for v in rows if "cost at most" in v["rule"]] + [v for v in rows if v["rule"].startswith(method)]
    order += [row for mix in MIX_NAMES.values() if (row := _held_out_row(variant, mix))]
    order += [default_verdict(d) for d in defaults]
    order += [v for v in verdicts(point, ant) if v["rule"].startswith("Ant")]
    order += [pair_verdict(pair, (pairs or {}).get(pair.marker)) for pair in PAIRS]
    table = [f"| rule ({method} unless named) | estimate [95 % CI] | verdict |", "|---|---|---|"]
    table += [f"| {v['rule']} | {v['value']} | {v['verdict']} |" for v in order]
    return "\n" + "\n".join(table) + "\n\n"  # the markers on lines of their own, around the table


def _held_out_row(variant: dict, mix: str) -> dict | None:
    """The variant's held-out cells of one error mix as a described row: success per layout, cost over ours."""
    method = variant["method"]
    held = [e for e in variant["held_out"] if e["runs"] and e["mix"] == mix]
    cost = next((c for c in variant.get("held_out_costs", []) if c["method"] == method
                 and c["proposer"] == f"mix {mix}" and c["pairs"]), None)
    if not (held and cost):
        return None
    return {"rule": f"held out, mix {mix} ({len(held)} layouts, seeds {list(HELD_OUT_SEEDS)}): success per layout; "
                    "proposer calls, evaluations over ours",
            "value": f"{min(e['success'] for e in held):.3f}-{max(e['success'] for e in held):.3f}; "
                     f"{_num(cost['proposer_calls_ratio'], '{:.2f}x')}, {_num(cost['evaluations_ratio'], '{:.2f}x')} "
                     f"over {cost['pairs']} pairs",
            "verdict": "described" + (f" (over {COST_CAP}x)" if _cost_verdict(cost) != "holds" else "")}


def progress(name: str, root: Path = ROOT) -> tuple[int, int]:
    """(cells done in the shipped tables, cells) of grid ``name``."""
    from ..grids import status

    parts = status(GRIDS[name], root)
    return sum(p.done for p in parts), sum(p.total for p in parts)


def front(point: dict, held_out: dict | None, root: Path = ROOT, levers: dict | None = None,
          ant: dict | None = None, fresh: dict | None = None, defaults: list[dict] | None = None,
          gr: dict | None = None, anyone: dict | None = None, statements: dict | None = None,
          pairs: dict | None = None, **variants: dict | None) -> dict[str, str]:
    """README's sentences, by marker name (``<!-- front corrector NAME -->``), from the studies (``variants`` by
    their ``VARIANTS`` name; ``fresh``: ``ant_fresh_study``'s; ``defaults`` and ``gr``: ``default_studies``'s and
    ``gr_study``'s, ``anyone`` ``any_study``'s, ``statements`` ``statement_studies``'s, computed here when not
    given)."""
    _known(variants)
    grids = ("corrector", "taxonomy", "corrector-held-out", ANT_FIRST, "corrector-levers",
             *(VARIANT_GRIDS[m] for m in VARIANTS.values()), *VARIANT_SUITE.values(), *FRESH_GRIDS, *NEW_GRIDS,
             *(st.grid for st in STATEMENTS), ANT_BEFORE, ANT_GRID, *ANT_CANDIDATES, *ANT_SUCCESSORS,
             *(pair.grid for pair in PAIRS))
    counts = {name: progress(name, root) for name in grids}
    out = {"status": "cells done: " + ", ".join(f"{name} {d} of {t}" for name, (d, t) in counts.items())
                     + ("" if all(d == t for d, t in counts.values()) else "; the grids resume next session")}
    for proposer in ("imperfect:mild", "imperfect:moderate", "imperfect:severe"):
        level = proposer.split(":")[1]
        mazes = [e for e in point["per_maze"] + point["severe"] if e["proposer"] == proposer]
        ran = [e for e in mazes if e["runs"]]
        if not ran:
            out[level] = "not run yet"
            continue
        within = sum(1 for e in ran if e["success"] >= e["reference_success"] - TOLERANCE)
        rooms = next((e for e in point["rooms"] if e["proposer"] == proposer and e["method"] == METHOD), None)
        zero = next(z for z in point["zero"] if z["proposer"] == proposer)
        curve = [f"{k / n:.3f}" for k, n, _ in point["curves"][proposer]["/".join((METHOD, "*"))] if n]
        text = (f"1-5 rooms {', '.join(curve)}; within {TOLERANCE} of the oracle on {within} of {len(ran)} "
                f"U-chains" + ("" if len(ran) == len(mazes) else f" run so far (of {len(mazes)})"))
        if rooms is not None:
            text += f", {cmp._interval_text(rooms)} ({rooms['verdict']}{_partial(rooms)})"
        text += (f"; runs at 0: {zero[METHOD][0]} of {zero[METHOD][1]} (ours {zero['ours'][0]} of "
                 f"{zero['ours'][1]}, ours-repair {zero['ours-repair'][0]} of {zero['ours-repair'][1]})")
        out[level] = text
    ratios = [e for e in point["ratio"] if e["method"].startswith(METHOD)]
    out["ratio"] = "; ".join(f"{e['proposer'].split(':')[1]} {cmp._interval_text(e)} ({e['verdict']}{_partial(e)})"
                             for e in ratios)
    out["cost"] = "; ".join(_cost_text(c) for c in point["costs"] if c["pairs"])
    out["levers"] = _levers_text(levers) if levers else "not run yet"
    for name in VARIANTS:
        study = variants.get(name)
        out[name] = ((gated_text if name == "gated" else variant_text)(study)) if study else "not run yet"
        if study:
            v = study["versus_corrector"]
            out[f"{name}-paired"] = f"{_signed(v)} over {v['n_cells']} paired U-chain cells"
        if study and "oracle_versus_paper" in study:
            out[f"{name}-oracle"] = _paired_text(study["oracle_versus_paper"])
            out[f"{name}-runs"] = "; ".join(f"{p.split(':')[1]} {k} of {n}" for p, (k, n) in
                                            study["every_episode"].items())
            out[f"{name}-fresh"] = fresh_text(study["fresh"]) if study.get("fresh") else "not run yet"
            if study.get("severe_zero", {}).get(study["method"], (0, 0))[1]:
                k, n = study["severe_zero"][study["method"]]
                out[f"{name}-severe-zero"] = f"{k} of {n}"
        if VARIANTS[name] in NEW_STUDIES:
            out[f"{name}-new"] = new_text(study["new"]) if study and study.get("new") else "not run yet"
            out[f"{name}-adoption"] = adoption_text(study) if study else "not run yet"
        for part in INFORMED_PARTS.get(VARIANTS[name], ()):
            out[f"{name}-{part}"] = new_text(study[part]) if study and study.get(part) else "not run yet"
    out["ant"] = ant_text(ant) if ant else "not run yet"
    out["ant-forecast"] = forecast_text(ant) if ant else "not run yet"
    out["unseen"] = unseen_text(unseen(root))
    defaults = default_studies(root) if defaults is None else defaults
    pairs = pair_studies(root) if pairs is None else pairs
    out["table"] = rules_table(variants.get(reported(variants)), point, ant, defaults, pairs)
    for pair in PAIRS:
        out[pair.marker] = pair_text(pair, pairs[pair.marker])
    for _, method in DEFAULTS:
        out[default_marker(method)] = default_text(next((d for d in defaults if d["method"] == method), None))
    out["point-default-gr"] = gr_text(gr_study(root) if gr is None else gr)
    out["any-proposer"] = any_text(any_study(root) if anyone is None else anyone)
    for marker, d in (statement_studies(root) if statements is None else statements).items():
        out[marker] = statement_text(d)
    out["reported"] = f"`{VARIANTS[reported(variants)]}`"
    out["reported-severe"] = severe_text(variants.get(reported(variants)))
    if held_out:
        done = [e for e in held_out["per_maze"] if e["runs"]]
        lo = min(e["success"] for e in done)
        hi = max(e["success"] for e in done)
        lo_o, hi_o = min(e["reference_success"] for e in done), max(e["reference_success"] for e in done)
        out["held-out"] = (f"ours-corrector {lo:.3f}-{hi:.3f} per layout and mix where ours gives {lo_o:.3f}-"
                           f"{hi_o:.3f}; runs at 0: {held_out['zero'][METHOD]} of {held_out['runs']} against "
                           f"{held_out['zero']['ours']} of {held_out['runs']}")
    out["ant-fresh"] = ant_fresh.front_text(fresh)
    return out


def unseen_text(sets: list[dict]) -> str:
    if not sets:
        return "not run yet"
    return "; ".join(f"{e['mixes']} {e['zero']} of {e['runs']}" for e in sets) + " (the oracle at least " + \
        f"{min(e['oracle_min'] for e in sets):.3f} on every one of those runs' cells)"


def severe_text(vs: dict | None) -> str:
    """The reported variant at imperfect:severe on the U-chains: per maze against the oracle, runs at 0 beside ours's
    and ours-repair's (the same settings' cells), and its cost over ours's there."""
    ran = [e for e in (vs or {}).get("severe", []) if e["runs"]]
    if not ran:
        return "not run yet"
    within = sum(1 for e in ran if e["success"] >= e["reference_success"] - TOLERANCE)
    zero = {**vs["severe_zero"], **vs.get("severe_baselines", {})}
    runs = ", ".join(f"{m} {zero[m][0]} of {zero[m][1]}" for m in (vs["method"], "ours", "ours-repair")
                     if m in zero and zero[m][1])
    cost = next((c for c in vs["costs"] if c["proposer"] == "imperfect:severe" and c["pairs"]), None)
    text = (f"{min(e['success'] for e in ran):.3f}-{max(e['success'] for e in ran):.3f} per U-chain, within "
            f"{TOLERANCE} of the oracle on {within} of {len(ran)}; runs at 0: {runs}")
    if cost:
        text += (f"; {_num(cost['proposer_calls_ratio'], '{:.2f}x')} ours's proposer calls and "
                 f"{_num(cost['evaluations_ratio'], '{:.2f}x')} its evaluations over {cost['pairs']} pairs")
    return text


def reported(variants: dict) -> str:
    """The variant README's rules table reads: the latest of ``ADOPTABLE`` adopted by its rule, else ``REPORTED``."""
    return next((name for name in ADOPTABLE if (variants.get(name) or {}).get("adoption", {}).get("adopted")),
                REPORTED)


def ant_text(ant: dict) -> str:
    """The Ant's grids as one markdown table (README's front page): success per maze pooled over the seeds run (runs
    in brackets), mazes below ANT_FLOOR, the pooled difference from the corrector each grid was judged against
    (ANT_METHOD for ANT_BEFORE and the candidates, the followed one for a successor), the mean cost over ours's and
    where the grid stands."""
    rows = [(ANT_GRID, ANT_METHOD, ant["confirm"], None, None, ant["confirm_costs"], None),
            (ANT_BEFORE, METHOD, ant["before"], ant["paired"], ANT_METHOD, ant["before_costs"], "stopped")]
    rows += [(c["grid"], c["method"], c["per_maze"], c["paired"], ANT_METHOD, c["cost_vs_ours"], None)
             for c in ant["candidates"]]
    rows += [(c["grid"], c["method"], c["per_maze"], c["paired"], c["followed_method"], c["cost_vs_ours"], None)
             for c in ant["successors"]]
    mazes = [e["maze"] for e in ant["confirm"]]
    head = (["grid (method)"] + [_maze_label(m) for m in mazes]
            + [f"below {ANT_FLOOR}", "difference [95 % CI], cells", "proposer calls, evaluations over ours", "status"])
    table = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for grid, method, per_maze, paired, against, cost, status in rows:
        ran = [e for e in per_maze if e["runs"]]
        low = sum(e["success"] < ANT_FLOOR for e in ran)
        cells = [f"{e['success']:.3f} ({e['runs']})" if e["runs"] else "—" for e in per_maze]
        table.append("| " + " | ".join(
            [f"{grid} ({method})", *cells, f"{low} of {len(ran)}" if ran else "—",
             _ant_against(paired, against), _cost_pair(cost),
             "read by the Ant's rules" if grid == ant["grid"] else status or _cells_run(per_maze)]) + " |")
    seeds = f"{min(ANT_SEEDS)}-{max(ANT_SEEDS)}"
    return ("\n" + f"Success per maze pooled over seeds {seeds} (runs in brackets; Un: U-chain of n rooms, s: with "
            "subgoals), `imperfect:moderate`, stage 5:\n\n" + "\n".join(table) + "\n\n")


def forecast_text(ant: dict) -> str:
    """Each Ant successor still running: its proposer calls and evaluations over ours's forecast for its whole grid
    (``ant.cost_forecast``)."""
    parts = []
    for c in ant["successors"]:
        calls, evals = c["calls_forecast"], c["evaluations_forecast"]
        cells, run = calls["cells"], calls["run"]
        if 0 < run < cells:
            parts.append(f"{c['method']} {calls['forecast']:.2f}x `ours`'s proposer calls ({_cap(calls)}) and "
                         f"{evals['forecast']:.2f}x its evaluations ({_cap(evals)}) over the {cells} cells (its {run} "
                         f"cells run at {calls['ratio_to_followed']:.2f}x and {evals['ratio_to_followed']:.2f}x "
                         f"{c['followed_method']}'s, those ratios carried to the other {cells - run}); within the "
                         f"cap over the grid its other {cells - run} cells could spend at most "
                         f"{max(calls['left_per_cell'], 0):.1f} proposer calls and "
                         f"{max(evals['left_per_cell'], 0):.0f} evaluations a cell on average, where "
                         f"{c['followed_method']} spent {calls['followed_left_per_cell']:.1f} and "
                         f"{evals['followed_left_per_cell']:.0f} on them")
    return "; ".join(parts) or "no successor running"


def _cap(forecast: dict) -> str:
    return f"{'within' if forecast['forecast'] <= COST_CAP else 'above'} the {COST_CAP}x cap"


def _maze_label(maze: str) -> str:
    """u_chain_3_subgoals -> U3s (another name as it is)."""
    chain = u_chain(maze)
    return f"U{chain[0]}{'s' * chain[1]}" if chain else maze


def _cells_run(per_maze: list[dict]) -> str:
    done = sum(e["runs"] for e in per_maze)
    expected = len(per_maze) * len(ANT_SEEDS)
    return "complete" if done >= expected else f"{done} of {expected} cells"


def _levers_text(lv: dict) -> str:
    parts = []
    for proposer in dict.fromkeys(e["proposer"] for e in lv["entries"]):
        here = [e for e in lv["entries"] if e["proposer"] == proposer and e["runs"]]
        parts.append(f"{proposer.split(':')[1]}: " + ("; ".join(
            f"{e['lever']} {_num(e['success'])} ({_signed(e['versus']['ours'])} over ours, "
            f"{helps_word(e['versus']['ours'])}; {_signed(e['versus'][METHOD])} against {METHOD}, {_proposer_calls(e)})"
            for e in here) or "not run yet"))
    return ". ".join(parts)


def _proposer_calls(e: dict) -> str:
    return f"{_num(e['costs']['proposer_calls_ratio'], '{:.1f}x')} the proposer calls of ours"


def gated_text(gs: dict) -> str:
    v = gs["versus_corrector"]
    costs = "; ".join(f"{c['proposer'].split(':')[1]} {_num(c['proposer_calls_ratio'], '{:.1f}x')} ({c['pairs']} pairs)"
                      for c in gs["costs"])
    ok = not math.isnan(v["estimate"]) and v["ci_low"] >= -NON_INFERIORITY
    return (f"proposer calls over ours: {costs}; {GATED} - {METHOD} {_signed(v)} over {v['n_cells']} of "
            f"{v['n_expected']} paired cells (no worse by -{NON_INFERIORITY}: {_verdict(ok, v['complete'])})")


def variant_text(vs: dict) -> str:
    """A variant against its reference, its change over rooms per preset and its proposer calls."""
    _, verdict = versus_corrector(vs)
    v, ref = vs["versus_corrector"], vs["reference"]
    parts = [f"{vs['method']} - {ref} {_signed(v)} over {v['n_cells']} of {v['n_expected']} paired cells "
             f"({verdict})"]
    for rooms, c, zero in zip(vs["rooms"], vs["costs"], vs["zero"]):
        level = rooms["proposer"].split(":")[1]
        mazes = [e for e in vs["per_maze"] if e["proposer"] == rooms["proposer"] and e["runs"]]
        within = sum(1 for e in mazes if e["success"] >= e["reference_success"] - TOLERANCE)
        parts.append(f"{level}: within {TOLERANCE} of the oracle on {within} of {len(mazes)} U-chains, "
                     f"{cmp._interval_text(rooms)} ({rooms['verdict']}{_partial(rooms)}), runs at 0: "
                     f"{zero['runs'][0]} of {zero['runs'][1]}, "
                     f"{_num(c['proposer_calls_ratio'], '{:.1f}x')} the proposer calls of ours"
                     + "".join(f", one-shot {cmp._interval_text(r)} ({r['verdict']}{_partial(r)})"
                               for r in vs.get("ratio", []) if r["proposer"] == rooms["proposer"]))
    if "severe_zero" in vs and vs["severe_zero"][vs["method"]][1]:
        zero = vs["severe_zero"]
        parts.append(f"severe: runs at 0 {zero[vs['method']][0]} of {zero[vs['method']][1]} ({ref} "
                     f"{zero[ref][0]} of {zero[ref][1]}), - {ref} {_signed(vs['severe_vs_corrector'])}, - "
                     f"ours-repair {_signed(vs['severe_vs_repair'])}{_partial(vs['severe_vs_repair'])}")
    if vs.get("versus_ours"):
        below = {level: _below_ours(vs["versus_ours"], f"imperfect:{level}") for level in ("mild", "moderate")}
        parts.append("every suite maze: below ours on " + ", ".join(
            f"{len(m)} of {_mazes_run(vs['versus_ours'], f'imperfect:{level}')} at {level}"
            + (f" ({', '.join(m)})" if m else "") for level, m in below.items()))
    held = [e for e in vs["held_out"] if e["runs"]]
    if held:
        both = [e for e in held if e["reference_runs"]]
        beside = (f"{ref} {min(e['reference_success'] for e in both):.3f}-"
                  f"{max(e['reference_success'] for e in both):.3f}; higher on "
                  f"{sum(e['success'] > e['reference_success'] for e in both)}, lower on "
                  f"{sum(e['success'] < e['reference_success'] for e in both)} of {len(both)}"
                  + ("" if len(both) == len(held) else " run by both") if both else f"{ref} not run there")
        parts.append(f"held out: {min(e['success'] for e in held):.3f}-{max(e['success'] for e in held):.3f} per "
                     f"layout and mix ({beside})")
        mine = [c for c in vs.get("held_out_costs", []) if c["method"] == vs["method"] and c["pairs"]]
        if mine:
            parts[-1] += ", " + ", ".join(f"{c['proposer']} {_num(c['proposer_calls_ratio'], '{:.1f}x')}"
                                          for c in mine) + " the proposer calls of ours"
    return "; ".join(parts)


def new_text(new: dict) -> str:
    short = lambda m: m.removeprefix(f"{METHOD}-")  # noqa: E731
    mine, ref = short(new["method"]), short(new["reference"])
    return _layouts_text(new, f"{mine} ", f", {ref} ", f"; {mine} - {ref} ")


def _layouts_text(study: dict, first: str, second: str, paired: str) -> str:
    """A new-layout or fresh study in one line: the first method's range per layout and mix, the second's, their
    paired difference and the runs at 0 (``first``, ``second``, ``paired``: the words before each)."""
    done = [e for e in study["per_maze"] if e["runs"]]
    both = [e for e in done if e["reference_runs"]]
    text = (f"{first}{min(e['success'] for e in done):.3f}-{max(e['success'] for e in done):.3f} per layout and mix "
            f"over {study['runs']} runs ({len(done)} of {len(study['per_maze'])} layouts and mixes run)")
    if both:
        text += (f"{second}{min(e['reference_success'] for e in both):.3f}-"
                 f"{max(e['reference_success'] for e in both):.3f}{paired}{_paired_text(study['paired'])}")
    return text + "; runs at 0: " + ", ".join(f"{m} {z}" for m, z in study["zero"].items())


def adoption_text(study: dict) -> str:
    rows = _adoption_rows(study)
    return (f"(1) no worse on the U-chains, {rows[0]['value']} ({rows[0]['verdict']}); (2) {rows[1]['value']} "
            f"({rows[1]['verdict']}): **{rows[2]['verdict']}**")


def fresh_text(fresh: dict) -> str:
    return _layouts_text(fresh, "", "; at sampled points ", "; centre - sampled ")
