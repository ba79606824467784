"""The point mass's studies of ours-corrector itself: its rules' cells, the held-out cells (described) and each lever
alone."""

from __future__ import annotations

import math
from pathlib import Path

from ...core.errors import SpecrefineError
from .. import comparison as cmp
from ..grids import GRIDS, HELD_OUT_MAZES, HELD_OUT_MIXES, OTHER_POINT_MAZES, ROOT, SCALING_MAZES
from .common import (
    HELD_OUT_SEEDS,
    LEVERS,
    METHOD,
    MIX_NAMES,
    ORACLE,
    POINT_SEEDS,
    as_ours,
    costs,
    episodes_of,
    load,
    per_maze,
    table_name,
    zero_runs,
)


def point_study(root: Path = ROOT) -> dict:
    tax, cor = GRIDS["taxonomy"], GRIDS["corrector"]
    rows = load(tax.tables + cor.tables, root)
    if not rows:
        raise SpecrefineError("no corrector or taxonomy table found: run the grids (docs/corrector.md)")
    cells, failed = cmp.table_cells(rows, "point")
    study = {"per_maze": [], "rooms": [], "ratio": [], "zero": [], "costs": [], "versus_ours": [],
             "severe_vs_repair": None}
    for proposer in ("imperfect:mild", "imperfect:moderate"):
        study["per_maze"] += per_maze(rows, proposer, SCALING_MAZES, POINT_SEEDS)
        study["versus_ours"] += per_maze(rows, proposer, SCALING_MAZES + OTHER_POINT_MAZES, POINT_SEEDS,
                                         reference=("ours", "*"))
        for method in (METHOD, "ours", "ours-repair", "vlm-oneshot"):
            study["rooms"].append(cmp.rooms_claim(cells, failed, proposer, method, POINT_SEEDS))
        study["ratio"].append(cmp.ratio_claim(as_ours(cells, METHOD), set(as_ours(dict.fromkeys(failed), METHOD)),
                                              proposer, POINT_SEEDS) | {"method": f"{METHOD} / vlm-oneshot"})
        study["ratio"].append(cmp.ratio_claim(cells, failed, proposer, POINT_SEEDS) | {"method": "ours / vlm-oneshot"})
        study["costs"].append(costs(rows, proposer, SCALING_MAZES + OTHER_POINT_MAZES, POINT_SEEDS))
    for proposer in ("imperfect:mild", "imperfect:moderate", "imperfect:severe"):
        study["zero"].append({"proposer": proposer} | {m: zero_runs(rows, m, proposer, SCALING_MAZES)
                                                        for m in (METHOD, "ours", "ours-repair")})
    study["curves"] = {p: {"/".join(m): [episodes_of(rows, f"u_chain_{n}", m[0], m[1] if m[1] != "*" else p,
                                                     POINT_SEEDS) for n in range(1, 6)]
                           for m in (ORACLE, (METHOD, "*"), ("ours", "*"), ("ours-repair", "*"), ("vlm-oneshot", "*"))}
                       for p in ("imperfect:mild", "imperfect:moderate", "imperfect:severe")}
    study["severe_vs_repair"] = cmp.paired_difference(cells, failed, "imperfect:severe", METHOD, "ours-repair",
                                                      POINT_SEEDS, SCALING_MAZES)
    study["severe"] = per_maze(rows, "imperfect:severe", SCALING_MAZES, POINT_SEEDS)
    study["costs"].append(costs(rows, "imperfect:severe", SCALING_MAZES, POINT_SEEDS))
    return study


def held_out_study(root: Path = ROOT) -> dict | None:
    """Descriptive (no rule was fixed beyond reporting every cell): per held-out maze and error mix, ours-corrector
    beside ours and the oracle, pooled over the seeds; and the cost ratios."""
    rows = load(GRIDS["corrector-held-out"].tables, root)
    if not any(r["method"] == METHOD for r in rows):
        return None
    mazes = tuple(table_name(m) for m in HELD_OUT_MAZES)
    entries = []
    for mix in HELD_OUT_MIXES:
        for e in per_maze(rows, mix, mazes, HELD_OUT_SEEDS, reference=("ours", "*")):
            k, n, _ = episodes_of(rows, e["maze"], *ORACLE, HELD_OUT_SEEDS)
            entries.append(e | {"mix": MIX_NAMES[mix], "oracle": k / n if n else math.nan})
    zeros = {m: sum(zero_runs(rows, m, mix, mazes)[0] for mix in HELD_OUT_MIXES) for m in (METHOD, "ours")}
    return {"per_maze": entries, "zero": zeros, "runs": sum(e["runs"] for e in entries),
            "costs": [costs(rows, mix, mazes, HELD_OUT_SEEDS) | {"proposer": f"mix {MIX_NAMES[mix]}"}
                      for mix in HELD_OUT_MIXES]}


def levers_study(root: Path = ROOT) -> dict | None:
    """Each lever alone against ours (and ours-repair for the deep repair) and against ours-corrector on the
    corrector-levers grid's cells: pooled success, paired difference (bootstrap over cells), cost."""
    grid = GRIDS["corrector-levers"]
    rows = load(GRIDS["taxonomy"].tables + GRIDS["corrector"].tables + grid.tables, root)
    if not any(r["method"] in LEVERS for r in rows):
        return None
    cells, failed = cmp.table_cells(rows, "point")
    entries = []
    for proposer in grid.proposers:
        for lever in LEVERS:
            references = ("ours",) + (("ours-repair",) if lever == "ours-deeprepair" else ()) + (METHOD,)
            k, n, runs = pooled(rows, grid.mazes, lever, proposer, grid.seeds)
            entries.append({"proposer": proposer, "lever": lever, "runs": runs, "success": k / n if n else math.nan,
                            "versus": {ref: cmp.paired_difference(cells, failed, proposer, lever, ref, grid.seeds,
                                                                  grid.mazes) for ref in references},
                            "same": {ref: same_cells(cells, proposer, lever, ref, grid.mazes, grid.seeds)
                                     for ref in references},
                            "costs": costs(rows, proposer, grid.mazes, grid.seeds, first=lever)})
    return {"mazes": list(grid.mazes), "seeds": list(grid.seeds), "entries": entries,
            "n_expected": len(grid.mazes) * len(grid.seeds)}


def same_cells(cells, proposer, first, second, mazes, seeds) -> int:
    """Cells where both ran with the same success (the lever never acted: its code path is the reference's)."""
    pairs = [(cells.get((m, first, proposer, s)), cells.get((m, second, proposer, s))) for m in mazes for s in seeds]
    return sum(1 for a, b in pairs if a is not None and a == b)


def pooled(rows, mazes, method, proposer, seeds) -> tuple[int, int, int]:
    """(successes, episodes, runs) of ``method`` over ``mazes``, pooled."""
    counts = [episodes_of(rows, maze, method, proposer, seeds) for maze in mazes]
    return tuple(sum(c[i] for c in counts) for i in range(3))
