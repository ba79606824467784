"""One live line while a refinement run works, so that a long run (the Ant: minutes) is seen to work, and why:

    00:12 search | splits 3/30 | simulating 96 episodes of 3 subtasks | best path 0.81 (to c) | 41 evaluations | ...

the elapsed time, the phase (search, "measurement of 200 episodes", calibration, the input task), the edge splits
used of the search's budget (once one is done), what the simulator runs right now (the evaluator's ``simulating``),
the search's current estimate of its best path (to the vertex it last closed, then the found path's), the evaluator's
counters and the proposer's calls, refreshed every second (what does not fit the terminal's width is cut from the
end).  On a terminal: a tqdm line on stderr, cleared at the end.  In a notebook: one text output updated in place,
which ends as the run's last line ("done"), so a saved notebook shows how the run ended, not how it began.  Shown
when stderr is a terminal or in a notebook (``enabled=None``); never for ``enabled=False`` (``specrefine refine
--quiet``, sweep cells).

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

from tqdm import tqdm
from tqdm.auto import tqdm as auto_tqdm


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
        return auto_tqdm(items, total=total, desc=desc, unit=unit, file=sys.stderr, **tqdm_kw)
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
        self.phase_name, self.estimate, self.towards, self.splits = "search", None, None, None
        self.enabled = wanted(enabled)
        self._shown = None  # _TerminalLine or _NotebookLine
        self._stop = threading.Event()
        self._ticker = None

    def __enter__(self) -> RunProgress:
        if self.enabled:
            self._shown = _NotebookLine(self.line()) if _in_notebook() else _TerminalLine(self.line())
            self._ticker = threading.Thread(target=self._tick, daemon=True, name="run-progress")
            self._ticker.start()
        return self

    def __exit__(self, *exc) -> None:
        if self._shown is not None:
            self._stop.set()
            self._ticker.join()
            self.phase_name = "done" if exc[0] is None else "stopped"
            self._shown.close(self.line())
            self._shown = None

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
        if "splits" in step:  # [used, budget] of the search's edge splits
            self.splits = step["splits"]
        self.refresh()

    def line(self) -> str:
        ev, proposer = self.evaluator, self.proposer
        parts = [self.phase_name]
        if self.splits is not None:
            parts.append(f"splits {self.splits[0]}/{self.splits[1]}")
        if getattr(ev, "simulating", None):
            parts.append(ev.simulating)
        if self.estimate is not None:
            parts.append(f"best path {self.estimate:.2f}" + (f" (to {self.towards})" if self.towards else ""))
        parts += [f"{getattr(ev, 'run_evaluations', ev.evaluations)} evaluations", f"{int(ev.sim_steps):,} sim steps",
                  f"{int(getattr(proposer, 'proposer_calls', 0) or 0)} proposer calls"]
        return " | ".join(parts)

    def refresh(self) -> None:
        if self._shown is not None:
            self._shown.show(self.line())

    def _tick(self) -> None:
        while not self._stop.wait(self.every):  # the elapsed time and counters move during a long evaluation too
            self.refresh()


class _TerminalLine:
    """The line on a terminal's stderr (tqdm: the elapsed time, cut to the width), cleared at the end."""

    def __init__(self, text: str):
        columns, rows = shutil.get_terminal_size()  # a terminal that reports 0 x 0 (a bare pty) gets 80 x 24
        self._bar = tqdm(total=None, file=sys.stderr, bar_format="{elapsed} {desc}", leave=False, desc=text,
                         ncols=columns, nrows=rows)

    def show(self, text: str) -> None:
        self._bar.set_description_str(text, refresh=True)

    def close(self, text: str) -> None:
        self._bar.close()


class _NotebookLine:
    """The line as one notebook output, replaced in place (``display_id``); its last text stays in the notebook."""

    def __init__(self, text: str):
        from IPython.display import display

        self._t0 = time.monotonic()
        self._handle = display(self._bundle(text), raw=True, display_id=True)

    def _bundle(self, text: str) -> dict:
        elapsed = int(time.monotonic() - self._t0)
        return {"text/plain": f"{elapsed // 60:02d}:{elapsed % 60:02d} {text}"}

    def show(self, text: str) -> None:
        self._handle.update(self._bundle(text), raw=True)

    def close(self, text: str) -> None:
        self.show(text)
