"""Errors a user can cause.  The CLI prints them as one line and exits 2."""


class SpecrefineError(Exception):
    """Bad input (maze file, spec, checkpoint, VLM reply, API failure): a one-line message."""


class MazeError(SpecrefineError):
    pass


class SpecError(SpecrefineError):
    pass


class InvalidRefinement(SpecrefineError):
    """A refined task graph does not imply the original one (Theorem 4.1 violated)."""
