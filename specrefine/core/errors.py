"""Every error a user can cause, in one place.  The CLI prints any of them as one line and exits 2.

All derive from :class:`SpecrefineError`.  A few also derive from ``ValueError`` (bad values handed
to a constructor or parser), so that code written against the standard exception still catches them.
"""


class SpecrefineError(Exception):
    """Bad input (maze file, spec, checkpoint, VLM reply, API failure): a one-line message."""


class MazeError(SpecrefineError):
    """A malformed ``*.maze`` file: ``file:line:column: what``."""


class SpecError(SpecrefineError):
    """A malformed task specification."""


class RegionError(SpecrefineError, ValueError):
    """An impossible region (empty box, non-positive radius, unknown type, points of the wrong shape)."""


class GraphError(SpecrefineError, ValueError):
    """A task graph that cannot be built (an edge that would close a cycle)."""


class InvalidRefinement(SpecrefineError):
    """A refined task graph does not imply the original one (Theorem 4.1 violated)."""


class PolicyError(SpecrefineError):
    """A policy file is missing, corrupt, or does not fit the agent."""


class VLMError(SpecrefineError):
    """A VLM call failed for a reason the user must fix or wait out (one line)."""


class VLMConfigError(VLMError):
    """Missing API key, unknown model, key rejected."""


class VLMUnavailable(VLMError):
    """Provider down, unreachable or rate-limiting after all retries."""


class ReplayMiss(VLMError):
    """A replayed run asked something the recording has no answer for."""


class ProposalRejected(SpecrefineError, ValueError):
    """A proposal (VLM reply) that cannot be used; ``str(exc)`` is the one-line reason.

    A proposer logs it, re-asks once and drops the candidate: it never ends a run.
    """


class RunFolderError(SpecrefineError):
    """An output folder that cannot be used: not a directory, unwritable, in use, or holding another run."""


class RecordError(SpecrefineError):
    """A run's record (result.json, policy.json) that cannot be read or breaks its schema (``core.records``)."""


class SweepError(SpecrefineError):
    """A sweep that cannot go on as asked (its --out holds cells run with other parameters)."""
