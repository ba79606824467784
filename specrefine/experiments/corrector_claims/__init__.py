"""The corrector grids' claims (docs/corrector.md, "The rules"), decided as fixed there.

    specrefine corrector-claims --out data/results/corrector

Reads the shipped tables of the grids ``taxonomy`` (ours, ours-repair and the oracle), ``corrector`` (ours-corrector
and the one-shot), ``corrector-held-out`` (described, no rule) and, where present, ``corrector-levers`` (each lever
alone), the corrector variants' grids and ``ant-corrector-confirm`` (``ant-corrector-spread`` and
``ant-corrector-reaim`` and ``ant-corrector-redraw`` beside it; one of them read instead once its adoption rule holds)
with the
Ant scaling grid's one-shot;
writes claims.md and claims.json (every rule with its estimate, interval and verdict, every cell counted) and
rooms.png (success over rooms per method and preset, point mass) and glance.png (the reported correctors per
U-chain beside the oracle, ours and the one-shot, both agents). A rule with a cell missing is
marked partial. ``--fill FILE ...`` also rewrites the ``<!-- front corrector NAME -->`` passages of those files
(README.md, docs/corrector.md) from the same studies::

    specrefine corrector-claims --out data/results/corrector --fill README.md docs/corrector.md
"""

from __future__ import annotations

# what the command and the tests read here (as from the single module this package was); the rest from its module:
# common (names, constants, shared helpers), point, ant, layouts, variants (the studies), formats, rules (verdicts),
# report (claims.md), frontpage (README's passages, fill), figure (rooms.png), glance (glance.png), cli (the command)
from ...core.errors import SpecrefineError
from ..grids import (
    ADVANCE_CHECK_MIXES,
    ADVANCE_MIXES,
    BACKTRACK_MIXES,
    CHECK_MIXES,
    DEEP_MIXES,
    EXTEND_MIXES,
    FALLBACK_MIXES,
    FINE_MIXES,
    FRESH_MAZES,
    FRESH_MIXES,
    KEEP_MIXES,
    MEMORY_MIXES,
    MEND_CHECK_MIXES,
    MEND_MIXES,
    NEW_MAZES,
    PROBE_MIXES,
    ROADMAP_CHECK_MIXES,
    ROADMAP_MIXES,
    SNAP_MIXES,
    SOUND_MIXES,
    SPAN_MIXES,
)
from .ant import (
    ANT_BEFORE,
    ANT_CANDIDATES,
    ANT_FLOOR,
    ANT_GRID,
    ANT_METHOD,
    ANT_REAIM,
    ANT_REDRAW,
    ANT_SPAN,
    ANT_SPARING,
    ANT_SPARING_FRUGAL,
    ANT_SUCCESSORS,
    ANT_WIDE,
    REAIM,
    REDRAW,
    SPARING,
    SPARING_FRUGAL,
    WIDE,
    Successor,
    ant_fresh_study,
    ant_study,
)
from .cli import add_arguments, main, run
from .common import (
    ADOPTABLE,
    ADVANCE,
    BACKTRACK,
    CENTRE,
    DEEP,
    EXTEND,
    FALLBACK,
    FINE,
    GATED,
    KEEP,
    LEAN,
    MEMORY,
    MEND,
    METHOD,
    PERSIST,
    POINT_SEEDS,
    POLISH,
    PRECISE,
    PROBE,
    RECHECK,
    ROADMAP,
    SNAP,
    SOUND,
    SPAN,
    SPAN_BRIDGE,
    SPREAD,
    TRIM,
    VARIANT_GRIDS,
    VARIANTS,
    load,
    reference_of,
    table_name,
)
from .frontpage import (
    adoption_text,
    ant_text,
    fill,
    forecast_text,
    fresh_text,
    front,
    gated_text,
    new_text,
    reported,
    rules_table,
    unseen_text,
    variant_text,
)
from .layouts import INFORMED_PARTS, fresh_study, new_study, unseen
from .point import held_out_study, levers_study, point_study
from .report import levers_markdown, markdown, variant_markdown
from .rules import helps_word, variant_verdicts, verdicts
from .variants import variant_studies, variant_study

__all__ = [
    "ADOPTABLE", "ADVANCE", "ADVANCE_CHECK_MIXES", "ADVANCE_MIXES", "ANT_BEFORE", "ANT_CANDIDATES", "ANT_FLOOR",
    "ANT_GRID", "ANT_METHOD", "ANT_REAIM", "ANT_REDRAW", "ANT_SPAN", "ANT_SPARING", "ANT_SPARING_FRUGAL",
    "ANT_SUCCESSORS", "ANT_WIDE", "BACKTRACK", "BACKTRACK_MIXES", "CENTRE", "CHECK_MIXES", "DEEP", "DEEP_MIXES",
    "EXTEND", "EXTEND_MIXES", "FALLBACK", "FINE", "FINE_MIXES",
    "FALLBACK_MIXES", "FRESH_MAZES", "FRESH_MIXES", "GATED", "INFORMED_PARTS", "KEEP", "KEEP_MIXES", "LEAN",
    "MEMORY", "MEMORY_MIXES", "MEND", "MEND_CHECK_MIXES", "MEND_MIXES", "METHOD", "NEW_MAZES", "PERSIST",
    "POINT_SEEDS", "POLISH",
    "PRECISE", "PROBE",
    "PROBE_MIXES", "REAIM", "RECHECK", "REDRAW", "ROADMAP", "ROADMAP_CHECK_MIXES", "ROADMAP_MIXES", "SNAP",
    "SNAP_MIXES", "SOUND", "SOUND_MIXES", "SPAN", "SPAN_BRIDGE", "SPAN_MIXES", "SPARING", "SPARING_FRUGAL", "SPREAD",
    "SpecrefineError", "Successor",
    "TRIM", "VARIANTS", "VARIANT_GRIDS", "WIDE", "add_arguments", "ant_fresh_study", "ant_study", "fill",
    "fresh_study", "front", "held_out_study", "levers_markdown", "levers_study", "load", "main", "markdown",
    "new_study", "point_study", "reference_of", "reported", "rules_table", "run", "table_name", "unseen",
    "variant_markdown", "variant_studies", "variant_study", "variant_verdicts", "verdicts", "adoption_text",
    "ant_text", "forecast_text", "fresh_text", "gated_text", "helps_word", "new_text", "unseen_text", "variant_text",
]
