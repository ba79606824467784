"""The evaluator's memory of subtask results: an LRU in memory and, given a folder, a disk cache that a resumed run
reads again (one ``.npz`` per evaluation, written whole, read without pickle; an unreadable entry is recomputed).

Keys and their texts come from the evaluator (they name what a result depends on); the cache checks the stored
text against the asked one, so a hash collision or a foreign file is never taken for a result.
"""

from __future__ import annotations

import logging
import os
from collections import OrderedDict
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..core.results import EdgeResult, StartStates, wilson_ci
from ..core.runfolder import fresh_opener

log = logging.getLogger(__name__)


class ResultCache:
    """Counters: ``hits`` (answered from memory or disk), ``disk_hits`` (read from the folder)."""

    def __init__(self, folder=None, memo_size: int = 512):
        self.folder = Path(folder) if folder is not None else None
        self.memo_size = memo_size
        self.hits = 0
        self.disk_hits = 0
        self._memo: OrderedDict[str, EdgeResult] = OrderedDict()
        self._simulated: set[str] = set()
        self._read_back: set[str] = set()

    def lookup(self, key: str, text: str, disk: bool) -> EdgeResult | None:
        """The stored result of ``key`` (marked cached), from memory, else from disk when ``disk``; None if absent."""
        hit = self._memo.get(key)
        if hit is not None:
            self._memo.move_to_end(key)
        elif disk and (hit := self._load(key, text)) is not None:
            self.disk_hits += 1
            self._remember(key, replace(hit, cached=False))
        if hit is None:
            return None
        self.hits += 1
        return replace(hit, cached=True)

    @property
    def read_back(self) -> int:
        """Results found on disk that this process never simulated (an earlier run of the folder did), each counted
        once however often it is read again after the memory's ``memo_size`` are full."""
        return len(self._read_back)

    def first_read(self, key: str) -> bool:
        """True the first time ``key``, found by :meth:`lookup`, is work this process never simulated (an earlier run
        of the same folder did), else False: each such result is counted once, where a run in one go simulated it."""
        if key in self._simulated or key in self._read_back:
            return False
        self._read_back.add(key)
        return True

    def add(self, key: str, text: str, res: EdgeResult, disk: bool) -> None:
        """A result just simulated: kept in memory, and on disk when ``disk``."""
        self._simulated.add(key)
        self._remember(key, res)
        if disk:
            self._store(key, text, res)

    def path(self, key: str) -> Path | None:
        return None if self.folder is None else self.folder / key[:2] / f"{key}.npz"

    def _remember(self, key: str, res: EdgeResult) -> None:
        for a in (res.success, res.trajectories, res.lengths, res.outcome, res.end_states.states, res.end_states.xy):
            a.flags.writeable = False  # shared with the cache: read-only
        self._memo[key] = res
        while len(self._memo) > self.memo_size:
            self._memo.popitem(last=False)

    def _load(self, key: str, text: str) -> EdgeResult | None:
        path = self.path(key)
        if path is None or not path.is_file():  # a FIFO in its place is never opened: the read would wait forever
            return None
        try:
            with np.load(path, allow_pickle=False) as z:
                if str(z["key"]) != text:
                    raise ValueError("key mismatch")
                success = z["success"].astype(bool)
                n = len(success)
                end = StartStates(z["end_states"].astype(np.float64), z["end_xy"].astype(np.float64))
                res = EdgeResult(p=float(success.mean()) if n else 0.0, ci=wilson_ci(int(success.sum()), n), n=n,
                                 successes=int(success.sum()), success=success, trajectories=z["trajectories"],
                                 lengths=z["lengths"].astype(np.int64), end_states=end, steps=int(z["steps"]),
                                 cached=True, outcome=z["outcome"].astype(np.int8))
                if len(res.lengths) != n or len(res.trajectories) != n or len(end) != res.successes:
                    raise ValueError("inconsistent arrays")
                return res
        except Exception as e:  # corrupt, truncated, foreign: never crash, recompute
            log.warning("ignoring unreadable cache entry %s: %s: %s", path, type(e).__name__, e)
            return None

    def _store(self, key: str, text: str, res: EdgeResult) -> None:
        path = self.path(key)
        if path is None:
            return
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
            tmp.unlink(missing_ok=True)  # a killed run's, or a planted link: removed, never followed
            with open(tmp, "wb", opener=fresh_opener) as f:
                np.savez_compressed(f, key=np.array(text), success=res.success, trajectories=res.trajectories,
                                    lengths=res.lengths, end_states=res.end_states.states, end_xy=res.end_states.xy,
                                    steps=np.array(res.steps), outcome=res.outcome)
            os.replace(tmp, path)
        except OSError as e:
            log.warning("could not write cache entry %s: %s", path, e)
