"""An output folder that cannot lie: one run's files only, one live run at a time.

``claim(out, args)`` (what ``refine_maze`` does before it writes anything):

* ``out`` must be a directory this process can write (created if missing); anything else (an existing
  file, ``/dev/null``, a path under a file, a folder it cannot write) is a one-line
  :class:`~specrefine.core.errors.RunFolderError`.
* ``out/.lock`` is held with an OS file lock (``flock``) by the run using the folder, and names its pid (and
  start time); another live run's lock is refused, a lock left by a dead process (killed run) is free, since
  the kernel released it with the process.  Taking the lock is atomic: of runs started together, one holds it.
* ``out/run.json`` records the run's arguments (written by the caller with :func:`write_record` once they
  proved usable, so that a refused run leaves none).  A rerun with the same arguments resumes (its cache is
  reused); a rerun with OTHER arguments into a folder that holds another run is refused with one line
  naming what differs: nothing is overwritten or moved, the user picks another ``--out`` or removes the
  old folder.  A folder from before run.json existed is taken as it is and gets a run.json.
"""

from __future__ import annotations

import fcntl
import json
import os
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

from .errors import RunFolderError
from .records import read_json, read_result  # noqa: F401 - read_result: its readers know it from here

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


def writable_parent(path) -> Path:
    """``path`` as a file this process can create: its folder made (or a one-line error), ``path`` not a folder."""
    path = Path(path)
    ensure_dir(path.parent)
    if path.is_dir():
        raise RunFolderError(f"{path}: is a folder: name a file to write")
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


def _lock(out: Path) -> int:
    """An OS lock (``flock``) on ``out/.lock``, held through the returned descriptor for the run's life; the
    kernel releases it when the process ends, however it ends.  The file also names the holder (pid and start
    time) for the message a refused run prints."""
    lock = out / LOCK
    for _ in range(10):
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise RunFolderError(f"{out}: cannot open the folder's lock {LOCK} ({exc.strerror or exc})") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            owner = os.pread(fd, 100, 0).decode(errors="replace")
            os.close(fd)
            raise RunFolderError(f"{out} is in use by another run (pid {(owner.split() or ['?'])[0]}): wait for it "
                                 f"to finish or use another --out") from None
        if _same_file(fd, lock):
            owner = os.pread(fd, 100, 0).decode(errors="replace")
            if owner.split()[:1] not in ([], [str(os.getpid())]) and _alive(owner):  # a pid-file lock of an older
                os.close(fd)  # version of this package, whose run is still going
                raise RunFolderError(f"{out} is in use by another run (pid {owner.split()[0]}): wait for it to "
                                     f"finish or use another --out")
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()} {_start_time(os.getpid())}".strip().encode() + b"\n", 0)
            return fd
        os.close(fd)  # the holder we waited on removed the file as it let go: lock the file now at that path
    raise RunFolderError(f"{out}: cannot take the folder's lock {LOCK} (another run keeps taking it)")


def _same_file(fd: int, path: Path) -> bool:
    try:
        return os.path.samestat(os.fstat(fd), os.stat(path))
    except FileNotFoundError:
        return False


def _unlock(out: Path, fd: int) -> None:
    """Remove the lock file while still holding it (a run that opened it meanwhile sees it gone), then let go."""
    try:
        if _same_file(fd, out / LOCK):
            (out / LOCK).unlink()
    except OSError:
        pass
    finally:
        os.close(fd)


def _check_record(out: Path, args: dict) -> None:
    """Refuse ``out`` if its run.json records other arguments."""
    record = out / RECORD
    try:  # a FIFO, a folder or a device there is refused unopened
        old = read_json(record, "run record", RunFolderError) if record.exists() or record.is_symlink() else None
    except RunFolderError:
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
    write_atomic(out / RECORD, json.dumps(args, indent=1, sort_keys=True))


@contextmanager
def replacing(path, mode: str = "w", **open_kw):
    """A file to write ``path`` whole: a temporary file in the same folder, renamed onto ``path`` (``os.replace``)
    when the block ends without error and removed when it fails, so that a reader, or a kill at any moment, finds
    the old file or the new one, never a half-written one."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, mode, **open_kw) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)  # gone already after the rename


def write_atomic(path, data: str | bytes) -> None:
    """``path`` holds ``data`` (text as UTF-8), written whole (see :func:`replacing`)."""
    binary = isinstance(data, bytes)
    with replacing(path, "wb" if binary else "w", **({} if binary else {"encoding": "utf-8"})) as fh:
        fh.write(data)


def save_figure(fig, path, **savefig_kw) -> None:
    """A matplotlib figure saved whole to ``path`` (format from its suffix, PNG by default)."""
    path = Path(path)
    with replacing(path, "wb") as fh:
        fig.savefig(fh, format=path.suffix.lstrip(".") or "png", **savefig_kw)


@contextmanager
def claim(out, args: dict):
    """Use ``out`` for the run described by ``args`` (JSON-able); see the module docstring."""
    out = ensure_dir(out)
    fd = _lock(out)
    try:
        _check_record(out, args)
        yield out
    finally:
        _unlock(out, fd)


def recorded_maze(result_path, name: str, maze_dir=None):
    """The maze a finished run ran on, for commands that read the run (failures, calibrate): rebuilt from the grid
    its folder's run.json records (the maze file itself may be anywhere, or gone), else the maze ``name``:
    ``maze_dir/NAME.maze`` if ``maze_dir`` has it, else a shipped one (a bare result file has no run.json)."""
    from .mazes import parse_maze

    result_path = Path(result_path)
    record = result_path.with_name(RECORD) if result_path.name == "result.json" else None
    args = read_json(record, "run record", RunFolderError) if record is not None and record.is_file() else {}
    grid = args.get("maze_grid") if isinstance(args, dict) else None
    if isinstance(grid, list) and grid and all(isinstance(row, str) for row in grid):
        spec = args.get("maze_spec")
        text = "\n".join(grid) + (f"\n; spec: {spec}" if isinstance(spec, str) else "")
        maze = parse_maze(text, f"{record}: maze_grid")
        return replace(maze, name=str(args.get("maze", name)))
    if maze_dir is not None and (Path(maze_dir) / f"{name}.maze").is_file():
        return Path(maze_dir) / f"{name}.maze"
    return name
