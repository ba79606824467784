"""``python -m specrefine.experiments.corrector_claims``: the command's older path (``specrefine corrector-claims``)."""

from .cli import main

raise SystemExit(main())
