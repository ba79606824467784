"""``specrefine corrector-claims``: its options, and the run that writes claims.md, claims.json, rooms.png and
glance.png and fills the markers of ``--fill``'s files."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from ...core.runfolder import ensure_dir, locked, save_figure, write_atomic
from .. import ant_fresh
from .ant import ant_fresh_study, ant_study
from .anyproposer import any_markdown, any_study
from .default import default_markdown, default_studies, default_verdict, gr_markdown, gr_study
from .figure import rooms_figure
from .frontpage import fill, front
from .glance import glance_figure, glance_panels
from .point import held_out_study, levers_study, point_study
from .report import markdown
from .rescue import PAIRS, pair_markdown, pair_studies, pair_verdict
from .rules import variant_verdicts, verdicts
from .statements import statement_markdown, statement_studies
from .variants import variant_studies


def add_arguments(p) -> None:
    from ...core.argtypes import out_path

    p.description = sys.modules[__package__].__doc__.split("\n\n")[0]  # the package's docstring (__init__.py)
    p.add_argument("--out", type=out_path, default=Path("data/results/corrector"),
                   help="folder for claims.md and claims.json (default: data/results/corrector)")
    p.add_argument("--fill", type=Path, nargs="+", default=[], metavar="FILE",
                   help="rewrite the '<!-- front corrector NAME -->' passages of these files (README.md, "
                        "docs/corrector.md) from the same studies")


def run(args, p) -> int:
    for path in args.fill:  # before any work: a file to fill is a regular file that exists
        if not path.is_file() or path.is_symlink():
            print(f"{p.prog}: error: --fill {path}: not a regular file", file=sys.stderr)
            return 2
    point, ant, held_out = point_study(), ant_study(), held_out_study()
    levers = levers_study()
    variants = variant_studies()
    fresh, defaults, gr, anyone = ant_fresh_study(), default_studies(), gr_study(), any_study()
    statements, pairs = statement_studies(), pair_studies()
    record = {"point": point, "held_out": held_out, "ant": ant, "levers": levers, "ant_fresh": fresh, **variants,
              "point_default": defaults, "point_default_gr": gr, "any_proposer": anyone, "statements": statements,
              "rules": verdicts(point, ant) + [v for vs in variants.values() if vs for v in variant_verdicts(vs)]
              + [default_verdict(d) for d in defaults] + [pair_verdict(p, pairs[p.marker]) for p in PAIRS],
              **{p.marker.replace("-", "_"): pairs[p.marker] for p in PAIRS},
              "front": front(point, held_out, levers=levers, ant=ant, fresh=fresh, defaults=defaults, gr=gr,
                             anyone=anyone, statements=statements, pairs=pairs, **variants)}
    with locked(ensure_dir(args.out)):
        tail = "\n".join(ant_fresh.markdown(fresh)) + "\n" if fresh else ""
        tail += "".join("\n".join(default_markdown(d)) + "\n" for d in defaults)
        tail += "\n".join(gr_markdown(gr)) + "\n" if gr else ""
        tail += "\n".join(any_markdown(anyone)) + "\n" if anyone else ""
        tail += "".join("\n".join(statement_markdown(d)) + "\n" for d in statements.values() if d)
        tail += "".join("\n".join(pair_markdown(p, pairs[p.marker])) + "\n" for p in PAIRS if pairs[p.marker])
        write_atomic(args.out / "claims.md", markdown(point, ant, held_out, levers, **variants) + tail)
        write_atomic(args.out / "claims.json", json.dumps(record, indent=1, default=float) + "\n")
        save_figure(rooms_figure(point), args.out / "rooms.png", dpi=110)
        save_figure(glance_figure(glance_panels()), args.out / "glance.png", dpi=110)
    for path in args.fill:
        fill(path, record["front"])
    print(f"-> {args.out}/claims.md")
    return 0


def main(argv=None) -> int:
    from ...core.commands import run_command

    return run_command("corrector-claims", argv, prog="python -m specrefine.experiments.corrector_claims")
