"""Each variant of the corrector by the rules of its docs/corrector.md section: its study against its reference, its
held-out cells, and its adoption rule."""

from __future__ import annotations

import math
from pathlib import Path

from .. import comparison as cmp
from ..grids import GRIDS, HELD_OUT_MAZES, HELD_OUT_MIXES, OTHER_POINT_MAZES, ROOT, SCALING_MAZES
from .common import (
    ADOPTABLE,
    ADOPTION_FLOOR,
    CENTRE,
    HELD_OUT_SEEDS,
    METHOD,
    MIX_NAMES,
    NO_MORE,
    NON_INFERIORITY,
    ORACLE,
    PERSIST,
    POINT_SEEDS,
    SELF_CONTAINED,
    SNAP,
    VARIANT_GRIDS,
    VARIANT_SUITE,
    VARIANTS,
    _below_ours,
    as_ours,
    costs,
    episodes_of,
    load,
    named,
    paired_across,
    per_maze,
    reference_of,
    table_name,
    zero_runs,
)
from .layouts import INFORMED_ON, LAST_CHECK, NEW_STUDIES, _new_rows, fresh_study, new_study


def variant_study(method: str, root: Path = ROOT) -> dict | None:
    """A variant of the corrector (``VARIANT_GRIDS``) by the rules of its docs/corrector.md section: against its
    reference (``VARIANT_REFERENCE``, else ours-corrector; paired, U-chains, mild and moderate), the corrector's own
    rules, its cost beside the reference's, the held-out cells and, where its grid ran severe, severe against
    ours-repair."""
    grid, ref = GRIDS[VARIANT_GRIDS[method]], reference_of(method)
    rows = variant_rows(method, root)
    if not any(r["method"] == method for r in rows):
        return None
    cells, failed = cmp.table_cells(rows, "point")
    presets = ("imperfect:mild", "imperfect:moderate")
    study = {"method": method, "grid": grid.name, "reference": ref, "per_maze": [], "rooms": [], "zero": [],
             "costs": [], "corrector_costs": [], "ratio": [],
             "versus_corrector": paired_across(cells, failed, presets, method, ref, POINT_SEEDS, SCALING_MAZES)}
    for proposer in presets:
        study["per_maze"] += per_maze(rows, proposer, SCALING_MAZES, POINT_SEEDS, method=method)
        study["rooms"].append(cmp.rooms_claim(cells, failed, proposer, method, POINT_SEEDS))
        study["ratio"].append(cmp.ratio_claim(as_ours(cells, method), set(as_ours(dict.fromkeys(failed), method)),
                                              proposer, POINT_SEEDS) | {"method": f"{method} / vlm-oneshot"})
        study["zero"].append({"proposer": proposer, "runs": zero_runs(rows, method, proposer, SCALING_MAZES)})
        study["costs"].append(costs(rows, proposer, SCALING_MAZES, POINT_SEEDS, first=method))
        ran = {(r["maze"], r["seed"]) for r in rows if r["method"] == method and r["proposer"] == proposer
               and cmp.is_done(r)}  # the reference's cost on the cells the variant ran
        study["corrector_costs"].append(costs([r for r in rows if (r["maze"], r["seed"]) in ran], proposer,
                                              SCALING_MAZES, POINT_SEEDS, first=ref))
    if method in VARIANT_SUITE:
        suite = rows + named(load(GRIDS[VARIANT_SUITE[method]].tables, root), method)
        if method in SELF_CONTAINED:  # ours at the same settings: the suite grid of the variant whose grids run it
            suite += [r for r in load(GRIDS[VARIANT_SUITE[CENTRE]].tables, root) if r["method"] == "ours"]
        study["versus_ours"] = [e for p in presets for e in per_maze(suite, p, SCALING_MAZES + OTHER_POINT_MAZES,
                                                                     POINT_SEEDS, reference=("ours", "*"),
                                                                     method=method)]
    study["held_out"] = variant_held_out(method, root)
    study["held_out_costs"] = variant_held_out_costs(method, root)
    if method in SELF_CONTAINED:
        study["every_episode"] = {p: zero_runs(rows, method, p, SCALING_MAZES, rate=1.0) for p in presets}
    if method == CENTRE:
        study["oracle_versus_paper"] = _oracle_versus_paper(rows, root)
        study["fresh"] = fresh_study(root)
    if "imperfect:severe" in grid.proposers:
        study["severe"] = per_maze(rows, "imperfect:severe", SCALING_MAZES, POINT_SEEDS, method=method)
        study["severe_vs_repair"] = cmp.paired_difference(cells, failed, "imperfect:severe", method, "ours-repair",
                                                          POINT_SEEDS, SCALING_MAZES)
        study["severe_vs_corrector"] = cmp.paired_difference(cells, failed, "imperfect:severe", method, ref,
                                                             POINT_SEEDS, SCALING_MAZES)
        study["severe_zero"] = {m: zero_runs(rows, m, "imperfect:severe", SCALING_MAZES) for m in (method, ref)}
        study["severe_baselines"] = {m: zero_runs(rows, m, "imperfect:severe", SCALING_MAZES)
                                     for m in ("ours", "ours-repair")}
        study["costs"].append(costs(rows, "imperfect:severe", SCALING_MAZES, POINT_SEEDS, first=method))
    if method == SNAP:  # on persist's new cells, which informed it, and a last check (described)
        study["informed"] = new_study(SNAP, root, on=PERSIST)
        study["check"] = new_study(SNAP, root, on="check", reference="ours")
    if method in INFORMED_ON:  # on the cells that informed it
        study["informed"] = new_study(method, root, on=INFORMED_ON[method])
    if method in LAST_CHECK:  # a last check after its adoption (described)
        study["check"] = new_study(method, root, on=LAST_CHECK[method])
    if method in NEW_STUDIES:
        study["new"] = new_study(method, root)
        study["adoption"] = adoption(study, cells, failed, root)
    return study


def adoption(study: dict, cells: dict, failed: set, root: Path = ROOT) -> dict:
    """A variant's adoption rule against its reference (docs/corrector.md, "Corrected until alive" and "Snapped out
    of the wall"): (1) no worse on the U-chains at mild and moderate (paired lower end >= -NON_INFERIORITY) and below
    ours on no suite maze; (2) fewer runs at 0 over the severe U-chain cells and its new cells together, and their
    paired difference >= 0."""
    method, ref = study["method"], study["reference"]
    grid, mazes, mixes, _ = NEW_STUDIES[method]
    new_cells, new_failed = cmp.table_cells(_new_rows(grid, root), "point")
    groups = [(cells, failed, "imperfect:severe", SCALING_MAZES, POINT_SEEDS)]
    groups += [(new_cells, new_failed, mix, tuple(table_name(m) for m in mazes), GRIDS[grid].seeds) for mix in mixes]
    both = {(f"{maze} {p} s{seed}", m, "all", 0): v for c, _, p, names, seeds in groups
            for (maze, m, q, seed), v in c.items() if q == p and maze in names and seed in seeds}
    both_failed = {(f"{maze} {p} s{seed}", m, "all", 0) for _, f, p, names, seeds in groups
                   for (maze, m, q, seed) in f if q == p}
    labels = [f"{maze} {p} s{seed}" for _, _, p, names, seeds in groups for maze in names for seed in seeds]
    paired = cmp.paired_difference(both, both_failed, "all", method, ref, (0,), labels)
    floor = ADOPTION_FLOOR.get(method, 0.0)  # runs at 0, or below the floor (a dead run is one), over the same cells
    zero = {m: sum(1 for (_, who, _, _), v in both.items() if who == m and (v <= 0.0 or v < floor))
            for m in (method, ref)}
    versus, suite = study["versus_corrector"], study.get("versus_ours", [])
    below = [e for p in ("imperfect:mild", "imperfect:moderate") for e in _below_ours(suite, p)]
    first = (not math.isnan(versus["estimate"]) and versus["ci_low"] >= -NON_INFERIORITY and not below)
    fewer = zero[method] <= zero[ref] if method in NO_MORE else zero[method] < zero[ref]
    second = fewer and not math.isnan(paired["estimate"]) and paired["estimate"] >= 0
    suite_done = bool(suite) and all(e["runs"] == len(POINT_SEEDS) for e in suite)
    complete = versus["complete"] and paired["complete"] and suite_done
    return {"no_worse": first, "fewer_zero": second, "zero": zero, "floor": floor, "paired": paired,
            "below_ours": below, "complete": complete, "adopted": first and second and complete}


def _oracle_versus_paper(rows: list[dict], root: Path) -> dict:
    """The oracle of a self-contained variant's grid (its settings) against the taxonomy grid's oracle (the paper's
    settings), paired over the U-chain cells (bootstrap over cells), described beside its rules."""
    mine = [r | {"method": "oracle (its settings)"} for r in rows if (r["method"], r["proposer"]) == ORACLE]
    paper = [r | {"method": "oracle (paper)"} for r in load(GRIDS["taxonomy"].tables, root)
             if (r["method"], r["proposer"]) == ORACLE]
    cells, failed = cmp.table_cells(mine + paper, "point")
    return cmp.paired_difference(cells, failed, ORACLE[1], "oracle (its settings)", "oracle (paper)", POINT_SEEDS,
                                 SCALING_MAZES)


def variant_rows(method: str, root: Path = ROOT) -> list[dict]:
    """The rows a variant is judged on: its grid's (under its name), its reference's and the oracle's, ours's,
    ours-repair's and the one-shot's."""
    return _base_rows(method, root) + _reference_rows(method, root) + named(
        load(GRIDS[VARIANT_GRIDS[method]].tables, root), method)


def _base_rows(method: str, root: Path) -> list[dict]:
    """The oracle's, ours's, ours-repair's and the one-shot's rows a variant is judged with: the taxonomy and
    corrector grids', or none for a variant whose grid runs its own (``SELF_CONTAINED``)."""
    return [] if method in SELF_CONTAINED else load(GRIDS["taxonomy"].tables + GRIDS["corrector"].tables, root)


def variant_studies(root: Path = ROOT) -> dict[str, dict | None]:
    """Every variant's study by its short name (README's marker, claims.json's key)."""
    studies = {name: variant_study(method, root) for name, method in VARIANTS.items()}
    snap, persist = studies.get("snap"), studies.get("persist")
    if snap:  # snap is adopted only where persist is, or would be but for its second part ("Snapped out of the wall")
        held = bool(persist) and persist["adoption"]["no_worse"]
        snap["adoption"] |= {"reference_no_worse": held, "adopted": snap["adoption"]["adopted"] and held}
    short = {method: name for name, method in VARIANTS.items()}
    for name in ADOPTABLE[::-1][2:]:  # in the order made, after persist and snap: adopted only where its reference is
        later, reference = studies.get(name), studies.get(short[reference_of(VARIANTS[name])])
        if later:
            held = bool(reference) and reference["adoption"]["adopted"]
            later["adoption"] |= {"reference_adopted": held, "adopted": later["adoption"]["adopted"] and held}
    return studies


def _reference_rows(method: str, root: Path, held_out: bool = False) -> list[dict]:
    """The rows of the variant's reference where that is another variant, under its name (``held_out``: its
    held-out part's only)."""
    ref = reference_of(method)
    if ref == METHOD:
        return []
    rows = named(load(_held_out_tables(ref) if held_out else GRIDS[VARIANT_GRIDS[ref]].tables, root), ref)
    if ref in SELF_CONTAINED and reference_of(ref) in SELF_CONTAINED:  # its oracle, ours, ... are its reference's
        rows += _reference_rows(ref, root, held_out)
    return rows


def _held_out_tables(method: str) -> tuple:
    """The tables of the held-out part(s) of a variant's grids (a self-contained variant's: its suite grid's,
    its own oracle's included)."""
    grid = GRIDS[(VARIANT_SUITE if method in SELF_CONTAINED else VARIANT_GRIDS)[method]]
    return tuple(grid.part_table(i) for i, part in enumerate(grid.parts)
                 if set(part.proposers) <= set(HELD_OUT_MIXES) | {ORACLE[1]} and part.mazes == HELD_OUT_MAZES)


def _held_out_rows(method: str, root: Path) -> list[dict]:
    base = [] if method in SELF_CONTAINED else load(GRIDS["corrector-held-out"].tables, root)
    return (base + _reference_rows(method, root, held_out=True)
            + named(load(_held_out_tables(method), root), method))


def variant_held_out_costs(method: str, root: Path = ROOT) -> list[dict]:
    """Per held-out mix: the variant's and its reference's mean cost over ours's on the same cells."""
    rows = _held_out_rows(method, root)
    mazes = tuple(table_name(m) for m in HELD_OUT_MAZES)
    return [costs(rows, mix, mazes, HELD_OUT_SEEDS, first=m) | {"proposer": f"mix {MIX_NAMES[mix]}", "method": m}
            for mix in HELD_OUT_MIXES for m in (method, reference_of(method))]


def variant_held_out(method: str, root: Path = ROOT) -> list[dict]:
    rows = _held_out_rows(method, root)
    mazes = tuple(table_name(m) for m in HELD_OUT_MAZES)
    out = []
    for mix in HELD_OUT_MIXES:
        for e in per_maze(rows, mix, mazes, HELD_OUT_SEEDS, reference=(reference_of(method), "*"), method=method):
            k, n, _ = episodes_of(rows, e["maze"], "ours", mix, HELD_OUT_SEEDS)
            out.append(e | {"mix": MIX_NAMES[mix], "ours": k / n if n else math.nan})
    return out
