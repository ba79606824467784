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
* the run's own files (``RUN_FILES``) must each be a regular file or absent, before any work (a folder at
  ``result.json`` is refused then, not after the run); a link only where the file is replaced whole (the link
  is replaced, never written through), not where the run appends (``APPENDED``).  Temporary files a killed
  run left (``.NAME.PID.tmp``, in the folder and its cache) are removed once the lock is held.

Every file a command writes is opened without following a link (:func:`replacing`, :func:`open_append`; a table
that a command resumes row by row is held by it alone: :func:`appending_alone`), and an
output named by the user (``--out FILE``) is checked before any work by :func:`output_file`: a regular file or a
new path, in a folder this process can write, never a run folder's own file; writing into a run folder takes that
folder's lock, as a run does.
"""

from __future__ import annotations

import errno
import fcntl
import json
import os
import re
import stat
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

from .errors import RunFolderError, SpecrefineError
from .records import read_json, read_result  # noqa: F401 - read_result: its readers know it from here

LOCK, RECORD = ".lock", "run.json"
#: what a run writes into its folder (besides the cache): no other command may write over them
RUN_FILES = (LOCK, RECORD, "result.json", "policy.json", "steps.jsonl", "refined.png", "graph.png", "roadmap.png",
             "vlm_recording.jsonl")
FULL = (errno.ENOSPC, errno.EDQUOT)  # a write failed for want of room
APPENDED = ("vlm_recording.jsonl",)  # appended to as the run goes, not replaced whole
_LEFTOVER = re.compile(r"^\..+\.\d+\.tmp$")  # replacing()'s and the cache's temporary files: .NAME.PID.tmp


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
    _probe(path, f"{path}: cannot write in the output folder")
    return path


def writable_parent(path, what: str = "--out") -> Path:
    """``path`` as a file this process can write (:func:`output_file`), its folder made if missing."""
    ensure_dir(Path(path).parent)
    return output_file(path, what)


def _start_time(pid: int) -> str:
    """The process's start time in clock ticks since boot ('' where /proc has none): a pid reused later differs."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return ""
    return fields.rsplit(")", 1)[1].split()[19]


def live_holder(out) -> int | None:
    """The pid of the live process whose run holds ``out`` (its ``.lock`` names it), else None: no lock, a lock left
    by a dead process, or one that is not a regular file (read without following a link)."""
    try:
        fd = os.open(Path(out) / LOCK, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError:
        return None
    try:
        owner = os.pread(fd, 100, 0).decode(errors="replace") if stat.S_ISREG(os.fstat(fd).st_mode) else ""
    finally:
        os.close(fd)
    return int(owner.split()[0]) if owner.split() and _alive(owner) else None


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
        fd = _open_lock(out, lock)
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


def _open_lock(out: Path, lock: Path) -> int:
    """``out/.lock`` opened for writing the holder's pid into it: never through a link (a link to a file elsewhere
    would have that file overwritten), and only a regular file with no other name (a hard link)."""
    try:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC, 0o644)
    except OSError as exc:
        why = "a link: remove it" if exc.errno == errno.ELOOP else exc.strerror or exc
        raise RunFolderError(f"{out}: cannot open the folder's lock {LOCK} ({why})") from None
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode) or st.st_nlink > 1:
        os.close(fd)
        why = f"{file_kind(st.st_mode)}: remove it" if not stat.S_ISREG(st.st_mode) else "a file with other names " \
            "(a hard link): remove it"
        raise RunFolderError(f"{out}: cannot use the folder's lock {LOCK} ({why})")
    return fd


def file_kind(mode: int) -> str:
    """What a non-regular file is, in words."""
    return ("a link" if stat.S_ISLNK(mode) else "a folder" if stat.S_ISDIR(mode) else "a FIFO" if stat.S_ISFIFO(mode)
            else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else "a socket" if stat.S_ISSOCK(mode)
            else "not a regular file")


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
    the old file or the new one, never a half-written one.  A link at ``path`` is replaced, never written through;
    the temporary file is created afresh (``O_EXCL``), so that a link planted at its name is not followed either.
    A full disk is one line naming it (:func:`write_error`)."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    _replaceable(path)
    in_block = False
    try:
        tmp.unlink(missing_ok=True)  # a killed run's (same pid) or a planted one: removed, never followed
        with open(tmp, mode, opener=fresh_opener, **open_kw) as fh:
            in_block = True
            yield fh
            in_block = False
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError as exc:
        if in_block and exc.errno not in FULL:  # the block's own error (its other files), not this file's
            raise
        raise write_error(path, exc) from None
    finally:
        tmp.unlink(missing_ok=True)  # gone already after the rename


def _replaceable(path: Path) -> None:
    """A one-line RunFolderError unless ``path`` is a regular file, a link (replaced) or absent: a device such as
    /dev/null, a FIFO or a folder is never replaced by a file."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    except OSError as exc:
        raise write_error(path, exc) from None
    if not (stat.S_ISREG(mode) or stat.S_ISLNK(mode)):
        raise RunFolderError(f"{path}: {file_kind(mode)}: name a regular file or a new path")


def fresh_opener(file, flags: int) -> int:
    """``open``'s opener for a file that must not exist yet (no link followed, nothing overwritten)."""
    return os.open(file, flags | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o644)


def open_append(path, what: str = "file"):
    """``path`` opened to append text lines (created if missing): a regular file only, never through a link (rows
    would go to the file it points at) and never a FIFO (opening one blocks); else a one-line RunFolderError."""
    path = Path(path)
    try:
        fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC,
                     0o644)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise RunFolderError(f"{path}: cannot append to the {what} (a link: remove it or point --out "
                                 f"elsewhere)") from None
        if exc.errno in (errno.ENXIO, errno.EISDIR):  # a FIFO no one reads; a folder
            raise RunFolderError(f"{path}: cannot append to the {what} ({file_kind(os.lstat(path).st_mode)})") \
                from None
        raise write_error(path, exc, f"cannot append to the {what}") from None
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        raise RunFolderError(f"{path}: cannot append to the {what} ({file_kind(mode)})")
    os.set_blocking(fd, True)
    return os.fdopen(fd, "a", encoding="utf-8", newline="")


@contextmanager
def appending_alone(path, what: str = "table"):
    """``with appending_alone(path) as fh:``: ``path`` opened by :func:`open_append` and held by this process alone
    for the block (``flock`` on the file itself): a second command resuming the same table is refused with one
    line, instead of both appending the rows neither had when it began."""
    fh = open_append(path, what)
    try:
        try:
            fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise RunFolderError(f"{path}: another command is appending to this {what}: wait for it to finish or "
                                 f"name another file") from None
        except OSError as exc:  # a file system without locks
            raise write_error(path, exc, f"cannot lock the {what}") from None
        yield fh
    finally:
        fh.close()


def write_error(path, exc: OSError, doing: str = "cannot write") -> SpecrefineError:
    """A one-line error for a failed write: a full disk names the file system it is on."""
    if exc.errno in FULL:
        return SpecrefineError(f"{path}: the disk is full (no space left on the file system at "
                               f"{_mount_point(path)}): free some space or write elsewhere")
    return SpecrefineError(f"{path}: {doing} ({exc.strerror or exc})")


def _mount_point(path) -> str:
    where = Path(os.path.abspath(path)).parent
    while not os.path.ismount(where) and where != where.parent:
        where = where.parent
    return str(where)


def output_file(path, what: str = "--out") -> Path:
    """``path`` as a file a command will write (checked before any work): a regular file or a path not there yet,
    in an existing folder this process can write, and not one of a run folder's own files (``RUN_FILES``: the
    run's record would be lost); anything else (a device such as /dev/null, a folder, a link, a FIFO) is a
    one-line RunFolderError.  Writing it into a run folder must hold that folder's lock: :func:`writing_into`."""
    path = Path(path)
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as exc:
        raise RunFolderError(f"{what} {path}: cannot use it ({exc.strerror or exc})") from None
    if mode is not None and not stat.S_ISREG(mode):
        raise RunFolderError(f"{what} {path}: {file_kind(mode)}: name a regular file or a new path")
    folder = path.parent
    if not folder.is_dir():
        raise RunFolderError(f"{what} {path}: its folder {folder} does not exist")
    if path.name in RUN_FILES and is_run_folder(folder):
        raise RunFolderError(f"{what} {path}: the run's own {path.name} would be lost: name another file")
    _probe(folder, f"{what} {path}: cannot write in its folder")
    return path


def is_run_folder(folder) -> bool:
    """Whether ``folder`` holds a run (its record, result or lock)."""
    return any(os.path.lexists(Path(folder) / name) for name in (RECORD, "result.json", LOCK))


def _probe(folder: Path, message: str) -> None:
    """A one-line RunFolderError(``message``) unless this process can create a file in ``folder``."""
    probe = folder / f".write-test-{os.getpid()}"
    try:
        os.close(os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o644))
        probe.unlink()
    except OSError as exc:
        raise RunFolderError(f"{message} ({exc.strerror or exc})") from None


@contextmanager
def writing_into(path, what: str = "--out"):
    """``with writing_into(path) as path:``: ``path`` checked by :func:`output_file`, and when it lies in a run
    folder, that folder's lock held for the block (a run, or another command writing there, is refused)."""
    path = output_file(path, what)
    if not is_run_folder(path.parent):
        yield path
        return
    with locked(path.parent):
        yield path


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
def locked(out: Path):
    """``out``'s lock held for the block (another live holder: a one-line RunFolderError); what a killed holder
    left behind (``.NAME.PID.tmp`` files) is removed first: no one else can be writing them now."""
    fd = _lock(out)
    try:
        _remove_leftovers(out)
        yield out
    finally:
        _unlock(out, fd)


def _remove_leftovers(out: Path) -> None:
    for folder in (out, *(p for p in (out / "cache").glob("*") if p.is_dir() and not p.is_symlink())):
        with os.scandir(folder) as entries:
            for entry in entries:
                if _LEFTOVER.match(entry.name) and not entry.is_dir(follow_symlinks=False):
                    Path(entry.path).unlink(missing_ok=True)


def _check_run_files(out: Path) -> None:
    """Each of the run's own files a regular file or absent, before any work; a link only where the file is
    written whole (``os.replace`` replaces the link), not where it is appended to (``APPENDED``)."""
    for name in RUN_FILES[1:]:
        try:
            mode = os.lstat(out / name).st_mode
        except FileNotFoundError:
            continue
        if not (stat.S_ISREG(mode) or stat.S_ISLNK(mode) and name not in APPENDED):
            raise RunFolderError(f"{out / name}: {file_kind(mode)} where the run writes its {name}: remove it or "
                                 f"use another --out")


@contextmanager
def claim(out, args: dict):
    """Use ``out`` for the run described by ``args`` (JSON-able); see the module docstring."""
    out = ensure_dir(out)
    with locked(out):
        _check_record(out, args)
        _check_run_files(out)
        yield out


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
