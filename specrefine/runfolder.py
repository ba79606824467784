"""An output folder that cannot lie: one run's files only, one live run at a time.

``claim(out, args)`` (what ``refine_maze`` does before it writes anything):

* ``out`` must be a directory this process can write (created if missing); anything else (an existing
  file, ``/dev/null``, a path under a file, a folder it cannot write) is a one-line
  :class:`~specrefine.errors.RunFolderError`.
* ``out/.lock`` holds the pid (and start time) of the run using the folder; another live run's lock is
  refused, a lock left by a dead process (killed run) is taken over.
* ``out/run.json`` records the run's arguments (written by the caller with :func:`write_record` once they
  proved usable, so that a refused run leaves none).  A rerun with the same arguments resumes (its cache is
  reused); a rerun with OTHER arguments into a folder that holds another run is refused with one line
  naming what differs: nothing is overwritten or moved, the user picks another ``--out`` or removes the
  old folder.  A folder from before run.json existed is taken as it is and gets a run.json.
"""

from __future__ import annotations

import json
import os
from contextlib import contextmanager
from pathlib import Path

from .errors import RunFolderError

LOCK, RECORD = ".lock", "run.json"


def ensure_dir(path) -> Path:
    """``path`` as a directory this process can write in (created if missing), else a one-line error."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise RunFolderError(f"{path}: exists and is not a directory: use a folder for --out") from None
    except OSError as exc:
        raise RunFolderError(f"{path}: cannot create the output folder ({exc.strerror or exc})") from None
    if not path.is_dir():
        raise RunFolderError(f"{path}: exists and is not a directory: use a folder for --out")
    probe = path / f".write-test-{os.getpid()}"
    try:
        probe.touch()
        probe.unlink()
    except OSError as exc:
        raise RunFolderError(f"{path}: cannot write in the output folder ({exc.strerror or exc})") from None
    return path


def _start_time(pid: int) -> str:
    """The process's start time in clock ticks since boot ('' where /proc has none): a pid reused later differs."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return ""
    return stat.rsplit(")", 1)[1].split()[19]


def _alive(owner: str) -> bool:
    try:
        pid, _, started = owner.strip().partition(" ")
        pid = int(pid)
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's live process
        return True
    except (ValueError, OSError):  # an unreadable lock: nobody we can know of holds it
        return False
    return not started or not _start_time(pid) or _start_time(pid) == started


def _lock(out: Path) -> str:
    me = f"{os.getpid()} {_start_time(os.getpid())}".strip()
    lock = out / LOCK
    for _ in range(3):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            owner = lock.read_text(errors="replace") if lock.exists() else ""
            if owner.split()[:1] != [str(os.getpid())] and _alive(owner):
                raise RunFolderError(f"{out} is in use by another run (pid {owner.split()[0]}): wait for it to "
                                     f"finish or use another --out") from None
            lock.unlink(missing_ok=True)  # a dead run's lock (or our own): take it over
            continue
        with os.fdopen(fd, "w") as fh:
            fh.write(me + "\n")
        return me
    raise RunFolderError(f"{out}: cannot take the folder's lock {LOCK} (another run keeps taking it)")


def _unlock(out: Path, me: str) -> None:
    lock = out / LOCK
    try:
        if lock.read_text().strip() == me:
            lock.unlink()
    except OSError:
        pass


def _check_record(out: Path, args: dict) -> None:
    """Refuse ``out`` if its run.json records other arguments."""
    record = out / RECORD
    try:
        old = json.loads(record.read_text())
    except FileNotFoundError:
        old = None
    except (OSError, ValueError):
        old = []  # unreadable: refused below
    if old is not None and not isinstance(old, dict):
        raise RunFolderError(f"{record}: unreadable run record: remove it or use another --out")
    if old is not None:
        diff = [k for k in sorted(set(old) | set(args)) if old.get(k) != args.get(k)]
        if diff:
            what = ", ".join(f"{k} {old.get(k)!r} (now {args.get(k)!r})" for k in diff[:3])
            raise RunFolderError(f"{out} holds another run ({what}{', ...' if len(diff) > 3 else ''}): use "
                                 f"another --out, or remove the folder to start over")


def write_record(out: Path, args: dict) -> None:
    """``out/run.json``: the arguments of the run now using ``out`` (written atomically)."""
    record = out / RECORD
    tmp = record.with_name(RECORD + ".tmp")
    tmp.write_text(json.dumps(args, indent=1, sort_keys=True))
    os.replace(tmp, record)


@contextmanager
def claim(out, args: dict):
    """Use ``out`` for the run described by ``args`` (JSON-able); see the module docstring."""
    out = ensure_dir(out)
    me = _lock(out)
    try:
        _check_record(out, args)
        yield out
    finally:
        _unlock(out, me)
