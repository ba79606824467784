"""``python -m specrefine``: the ``specrefine`` command line."""

import sys

from .cli import main

sys.exit(main())
