"""The studies on layouts and mixes no run had used: each variant's new-layout grids (``NEW_STUDIES``), the fresh
layouts of the centre rule, and the reported corrector over every new set (``unseen``)."""

from __future__ import annotations

import math
from pathlib import Path

from .. import comparison as cmp
from ..grids import (
    ADVANCE_CHECK_MAZES,
    ADVANCE_CHECK_MIXES,
    ADVANCE_MAZES,
    ADVANCE_MIXES,
    BACKTRACK_MAZES,
    BACKTRACK_MIXES,
    CHECK_MAZES,
    CHECK_MIXES,
    DEAF,
    DEEP_CHECK_MAZES,
    DEEP_CHECK_MIXES,
    DEEP_MAZES,
    DEEP_MIXES,
    EXTEND_MAZES,
    EXTEND_MIXES,
    FALLBACK_MAZES,
    FALLBACK_MIXES,
    FINE_CHECK_MAZES,
    FINE_CHECK_MIXES,
    FINE_MAZES,
    FINE_MIXES,
    FRESH_MAZES,
    FRESH_MIXES,
    GRIDS,
    KEEP_MAZES,
    KEEP_MIXES,
    MEMORY_MAZES,
    MEMORY_MIXES,
    MEND_CHECK_MAZES,
    MEND_CHECK_MIXES,
    MEND_MAZES,
    MEND_MIXES,
    NEW_MAZES,
    NEW_MIXES,
    OTHER_POINT_MAZES,
    PROBE_MAZES,
    PROBE_MIXES,
    ROADMAP_CHECK_MAZES,
    ROADMAP_CHECK_MIXES,
    ROADMAP_MAZES,
    ROADMAP_MIXES,
    ROOT,
    SCALING_MAZES,
    SNAP_MAZES,
    SNAP_MIXES,
    SOUND_MAZES,
    SOUND_MIXES,
    SPAN_BRIDGE_MAZES,
    SPAN_BRIDGE_MIXES,
    SPAN_MAZES,
    SPAN_MIXES,
)
from .common import (
    ADVANCE,
    BACKTRACK,
    CENTRE,
    DEEP,
    EXTEND,
    FALLBACK,
    FINE,
    KEEP,
    MEMORY,
    MEND,
    ORACLE,
    PERSIST,
    POLISH,
    PROBE,
    ROADMAP,
    SHOWN_BESIDE,
    SNAP,
    SOUND,
    SPAN,
    SPAN_BRIDGE,
    VARIANT_GRIDS,
    VARIANTS,
    episodes_of,
    load,
    named,
    paired_across,
    per_maze,
    reference_of,
    table_name,
    zero_runs,
)

#: a variant run on layouts and mixes no run had used, beside its reference: (grid, mazes, mixes, mix names)
NEW_STUDIES = {PERSIST: ("corrector-persist-new", NEW_MAZES, NEW_MIXES, ("E", "F")),
               SNAP: ("corrector-snap-new", SNAP_MAZES, SNAP_MIXES, ("G", "H")),
               "check": ("corrector-snap-check", CHECK_MAZES, CHECK_MIXES, ("I", "J")),  # a last check, described
               EXTEND: ("corrector-extend-new", EXTEND_MAZES, EXTEND_MIXES, ("K", "L")),
               KEEP: ("corrector-keep-new", KEEP_MAZES, KEEP_MIXES, ("M", "N")),
               FALLBACK: ("corrector-fallback-new", FALLBACK_MAZES, FALLBACK_MIXES, ("O", "P")),
               ADVANCE: ("corrector-advance-new", ADVANCE_MAZES, ADVANCE_MIXES, ("Q", "R")),
               "advance-check": ("corrector-advance-check", ADVANCE_CHECK_MAZES, ADVANCE_CHECK_MIXES, ("S", "T")),
               ROADMAP: ("corrector-roadmap-new", ROADMAP_MAZES, ROADMAP_MIXES, ("U", "V")),
               "roadmap-check": ("corrector-roadmap-check", ROADMAP_CHECK_MAZES, ROADMAP_CHECK_MIXES, ("W", "X")),
               SOUND: ("corrector-sound-new", SOUND_MAZES, SOUND_MIXES, ("Y", "Z")),
               MEMORY: ("corrector-memory-new", MEMORY_MAZES, MEMORY_MIXES, ("AA", "AB")),
               PROBE: ("corrector-probe-new", PROBE_MAZES, PROBE_MIXES, ("AC", "AD")),
               DEEP: ("corrector-deep-new", DEEP_MAZES, DEEP_MIXES, ("AE", "AF")),
               "deep-check": ("corrector-deep-check", DEEP_CHECK_MAZES, DEEP_CHECK_MIXES, ("AG", "AH")),
               MEND: ("corrector-mend-new", MEND_MAZES, MEND_MIXES, ("AL", "AM")),
               "mend-check": ("corrector-mend-check", MEND_CHECK_MAZES, MEND_CHECK_MIXES, ("AN", "AO", "AP", "AQ")),
               BACKTRACK: ("corrector-backtrack-new", BACKTRACK_MAZES, BACKTRACK_MIXES, ("AR", "AS")),
               FINE: ("corrector-fine-new", FINE_MAZES, FINE_MIXES, ("AT", "AU")),
               "fine-random": ("corrector-fine-random", SCALING_MAZES + OTHER_POINT_MAZES, ("random",), ("random",)),
               SPAN: ("corrector-span-new", SPAN_MAZES, SPAN_MIXES, ("random", "AX")),
               "fine-check": ("corrector-fine-check", FINE_CHECK_MAZES, FINE_CHECK_MIXES, ("AV", "AW")),
               "deaf": ("corrector-span-bridge", SCALING_MAZES, (DEAF,), ("deaf",)),
               SPAN_BRIDGE: ("corrector-span-bridge-new", SPAN_BRIDGE_MAZES, SPAN_BRIDGE_MIXES, ("BA", "BB"))}
NEW_GRIDS = tuple(grid for grid, *_ in NEW_STUDIES.values())
#: the new-layout study of a last check after a variant's adoption
LAST_CHECK = {ADVANCE: "advance-check", ROADMAP: "roadmap-check", DEEP: "deep-check", MEND: "mend-check",
              FINE: "fine-check"}
#: the new-layout study whose cells informed a variant (beside snap's, which names its own)
INFORMED_ON = {EXTEND: "check", KEEP: EXTEND, FALLBACK: KEEP, ADVANCE: FALLBACK, ROADMAP: "advance-check",
               SOUND: "roadmap-check", MEMORY: SOUND, PROBE: MEMORY,
               DEEP: PROBE, BACKTRACK: "mend-check", FINE: BACKTRACK, SPAN: "fine-random", SPAN_BRIDGE: "deaf"}
#: a variant's studies on cells beside its new ones (README's markers NAME-PART): those that informed it, a last check
INFORMED_PARTS = {m: ("informed",) * (m in INFORMED_ON or m == SNAP) + ("check",) * (m in LAST_CHECK or m == SNAP)
                  for m in (SNAP, *INFORMED_ON, *LAST_CHECK)}


def new_study(method: str, root: Path = ROOT, on: str | None = None, reference: str | None = None) -> dict | None:
    """Described (docs/corrector.md, "Corrected until alive", "Snapped out of the wall"): the variant beside its
    reference, polish at centre points, ours and the oracle on layouts and mixes no run had used; runs at 0; the
    variant - its reference paired over the cells (and the reference - polish where polish is not it)."""
    grid, mazes, mixes, names = NEW_STUDIES[on or method]
    rows, ref = _new_rows(grid, root), reference or reference_of(method)
    if on and grid != VARIANT_GRIDS[method]:  # the variant's own cells there come from its grid's part on them
        rows += [r for r in load(GRIDS[VARIANT_GRIDS[method]].tables, root) if r["proposer"] in mixes]
    if not any(r["method"] == method for r in rows):
        return None
    mazes, seeds = tuple(table_name(m) for m in mazes), GRIDS[grid].seeds
    polish = ref not in (CENTRE, "ours") and any(r["method"] == CENTRE for r in rows)  # a grid that ran polish
    others = [("ours", "ours"), ("oracle", ORACLE)] + ([("polish", CENTRE)] if polish else [])
    entries = []
    for mix, name in zip(mixes, names):
        for e in per_maze(rows, mix, mazes, seeds, reference=(ref, "*"), method=method):
            extra = {key: episodes_of(rows, e["maze"], *((m, mix) if isinstance(m, str) else m), seeds)
                     for key, m in others}
            entries.append(e | {"mix": name} | {k: c[0] / c[1] if c[1] else math.nan for k, c in extra.items()})
    cells, failed = cmp.table_cells(rows, "point")
    beside = tuple(sorted({r["method"] for r in rows} & ({*VARIANTS.values(), *SHOWN_BESIDE}) - {method, ref, CENTRE}))
    shown = tuple(dict.fromkeys((method, ref) + ((CENTRE,) if polish else ()) + beside + ("ours",)))
    study = {"grid": grid, "method": method, "reference": ref, "names": list(names), "per_maze": entries,
             "zero": {m: sum(zero_runs(rows, m, mix, mazes)[0] for mix in mixes) for m in shown},
             "runs": sum(e["runs"] for e in entries),
             "paired": paired_across(cells, failed, mixes, method, ref, seeds, mazes)}
    if polish:
        study["reference_paired"] = paired_across(cells, failed, mixes, ref, CENTRE, seeds, mazes)
    return study


def _new_rows(grid: str, root: Path) -> list[dict]:
    """A new-layout grid's rows, polish named as the centre variant it is."""
    return named(load(GRIDS[grid].tables, root), CENTRE)


FRESH_GRIDS = ("corrector-centre-fresh", "corrector-sampled-fresh")  # docs/corrector.md, "Fresh layouts ..."
FRESH_NAMES = dict(zip(FRESH_MIXES, ("C", "D")))


def fresh_study(root: Path = ROOT) -> dict | None:
    """Described (docs/corrector.md, "Fresh layouts for the centre rule"): polish at centre points beside polish at
    sampled points, ours (centre) and the oracle at both, per fresh layout and mix; runs at 0; the paired difference
    of the two polish runs over the cells both ran (bootstrap over cells)."""
    centre, sampled = (load(GRIDS[name].tables, root) for name in FRESH_GRIDS)
    rows = [r | {"method": CENTRE} if r["method"] == POLISH else r for r in centre]
    rows += [r | {"method": "oracle (sampled)"} if r["method"] == ORACLE[0] else r for r in sampled]
    if not any(r["method"] == CENTRE for r in rows):
        return None
    mazes, seeds = tuple(table_name(m) for m in FRESH_MAZES), GRIDS[FRESH_GRIDS[0]].seeds
    entries = []
    for mix in FRESH_MIXES:
        for e in per_maze(rows, mix, mazes, seeds, reference=(POLISH, "*"), method=CENTRE):
            refs = (("ours", ("ours", mix)), ("oracle", ORACLE), ("oracle_sampled", ("oracle (sampled)", ORACLE[1])))
            extra = {name: episodes_of(rows, e["maze"], *ref, seeds) for name, ref in refs}
            entries.append(e | {"mix": FRESH_NAMES[mix]} | {k: c[0] / c[1] if c[1] else math.nan
                                                              for k, c in extra.items()})
    cells, failed = cmp.table_cells(rows, "point")
    zero = {m: sum(zero_runs(rows, m, mix, mazes)[0] for mix in FRESH_MIXES) for m in (CENTRE, POLISH, "ours")}
    return {"per_maze": entries, "zero": zero, "runs": sum(e["runs"] for e in entries),
            "paired": paired_across(cells, failed, FRESH_MIXES, CENTRE, POLISH, seeds, mazes)}


def unseen(root: Path = ROOT, method: str = SNAP) -> list[dict]:
    """``method`` (README's reported corrector) on every set of new layouts and mixes that ran it, in the order the
    sets were made: its runs at 0 and done, the oracle's lowest success there."""
    out = []
    for grid, mazes, mixes, names in NEW_STUDIES.values():
        rows = load(GRIDS[grid].tables, root)
        if not any(r["method"] == method for r in rows):
            continue
        mazes = tuple(table_name(m) for m in mazes)
        zero = [zero_runs(rows, method, mix, mazes) for mix in mixes]
        oracle = [float(r["success_rate"]) for r in rows if (r["method"], r["proposer"]) == ORACLE and cmp.is_done(r)]
        out.append({"grid": grid, "mixes": "/".join(names), "zero": sum(z for z, _ in zero),
                    "runs": sum(n for _, n in zero), "oracle_min": min(oracle) if oracle else math.nan})
    return out
