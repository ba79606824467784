"""One live line on stderr while a refinement run works, so that a long run (the Ant: minutes) is seen to work:

    00:12 search | best path 0.81 (to c) | 41 evaluations | 310,528 sim steps | 6 proposer calls

the elapsed time, the phase (search, measurement, calibration), the search's current estimate of its best path
(to the vertex it last closed, then the found path's), the evaluator's counters and the proposer's calls,
refreshed every second (what does not fit the terminal's width is cut from the end).  ``tqdm.auto``: a notebook
gets a widget.  Shown when stderr is a terminal or in a notebook (``enabled=None``); never for ``enabled=False``
(``specrefine refine --quiet``, sweep cells).

:func:`counted` is the bar of a loop over items (``official``'s episodes, a sweep's cells): tqdm's on a terminal or
in a notebook; elsewhere (a log file, a pipe) one plain line per ``every`` items, as a log wants it, never the
carriage-return redraws of a bar.
"""

from __future__ import annotations

import math
import shutil
import sys
import threading
import time

from tqdm.auto import tqdm


def _in_notebook() -> bool:
    ipython = sys.modules.get("IPython")
    try:
        return ipython is not None and "IPKernelApp" in ipython.get_ipython().config
    except AttributeError:  # no IPython session (get_ipython() is None)
        return False


def wanted(enabled: bool | None) -> bool:
    """``enabled``, or when None: whether stderr is a terminal or this runs in a notebook."""
    if enabled is not None:
        return enabled
    return bool(getattr(sys.stderr, "isatty", lambda: False)()) or _in_notebook()


def counted(items, total: int, desc: str, unit: str = "item", every: int | None = None, **tqdm_kw):
    """``items``, counted on stderr as they go: a tqdm bar where one is shown (:func:`wanted`), else a line such
    as ``official u_maze: 20/200 episodes (4 s)`` after every ``every`` items (default: a tenth of ``total``) and
    after the last."""
    if wanted(None):
        return tqdm(items, total=total, desc=desc, unit=unit, file=sys.stderr, **tqdm_kw)
    return _lines(items, total, desc, unit, every or max(1, math.ceil(total / 10)))


def _lines(items, total: int, desc: str, unit: str, every: int):
    t0 = time.time()
    done = 0
    for item in items:
        yield item
        done += 1
        if done % every == 0 or done == total:
            print(f"{desc}: {done}/{total} {unit}s ({time.time() - t0:.0f} s)", file=sys.stderr, flush=True)


class RunProgress:
    """``with RunProgress(evaluator, proposer) as shown:`` then ``shown.step(step)`` for each search step and
    ``shown.phase(name)`` as the run moves on; the counters are read from ``evaluator`` and ``proposer``."""

    def __init__(self, evaluator, proposer=None, *, enabled: bool | None = None, every: float = 1.0):
        self.evaluator, self.proposer, self.every = evaluator, proposer, every
        self.phase_name, self.estimate, self.towards = "search", None, None
        self.enabled = wanted(enabled)
        self._bar = None
        self._stop = threading.Event()
        self._ticker = None

    def __enter__(self) -> RunProgress:
        if self.enabled:
            columns, rows = shutil.get_terminal_size()  # a terminal that reports 0 x 0 (a bare pty) gets 80 x 24
            self._bar = tqdm(total=None, file=sys.stderr, bar_format="{elapsed} {desc}", leave=False,
                             desc=self.line(), ncols=columns, nrows=rows)
            self._ticker = threading.Thread(target=self._tick, daemon=True, name="run-progress")
            self._ticker.start()
        return self

    def __exit__(self, *exc) -> None:
        if self._bar is not None:
            self._stop.set()
            self._ticker.join()
            self._bar.close()
            self._bar = None

    def phase(self, name: str) -> None:
        self.phase_name = name
        self.refresh()

    def step(self, step: dict) -> None:
        """Follow the search's steps (``RefinementSearch``'s ``on_step``, the one-shot baseline's)."""
        if step.get("event") == "expand" and "cost" in step:  # Dijkstra closes the best path to this vertex
            self.estimate, self.towards = math.exp(-step["cost"]), step.get("vertex")
        elif step.get("event") == "done" and "predicted_success" in step:
            self.estimate, self.towards = step["predicted_success"], None
        elif step.get("event") == "candidate" and "predicted_success" in step:  # the one-shot baseline's best so far
            self.estimate = max(self.estimate or 0.0, step["predicted_success"])
        self.refresh()

    def line(self) -> str:
        ev, proposer = self.evaluator, self.proposer
        parts = [self.phase_name]
        if self.estimate is not None:
            parts.append(f"best path {self.estimate:.2f}" + (f" (to {self.towards})" if self.towards else ""))
        parts += [f"{ev.evaluations + getattr(ev, 'disk_hits', 0)} evaluations", f"{int(ev.sim_steps):,} sim steps",
                  f"{int(getattr(proposer, 'proposer_calls', 0) or 0)} proposer calls"]
        return " | ".join(parts)

    def refresh(self) -> None:
        if self._bar is not None:
            self._bar.set_description_str(self.line(), refresh=True)

    def _tick(self) -> None:
        while not self._stop.wait(self.every):  # the elapsed time and counters move during a long evaluation too
            self.refresh()
