"""An output directory replaced whole: one run at a time, built beside it, swapped in at once.

    with staged_output(Path("out")) as stage:
        ...write every output into `stage`...
    # out/ is now exactly what was written into `stage`; on an exception it is untouched

- Lock: an exclusive `fcntl.flock` on `<parent>/.<name>.lock`, held for the life of the run.
  A second run on the same output directory says so in one line on stderr ("waiting for the
  run that is writing ... (pid N)") and waits; it then runs as usual (its solves come from
  the cache), so two `make` at once both end with exit 0 and out/ is the later one, whole.
  Waiting, not refusing, because `make report` started during `make` should report the new
  run, not fail. The kernel drops the lock when its process dies (kill -9 too), so a lock is
  never stale; its holder removes the lock file before releasing it, and a waiter that then
  finds the file gone (or replaced) locks the new one, so exactly one run holds a live lock.
- Staging: a fresh `<parent>/.<name>.staging-XXXXXXXX` per run, made under the lock. Staging
  folders found when the lock is taken belong to a run that died (kill -9, power loss): they
  are removed then. Nothing is ever staged inside out/.
- Swap: Linux `renameat2(RENAME_EXCHANGE)` exchanges the complete new tree and the old out/ in
  one atomic step (directories included), so no reader and no interruption can ever see a
  mix of two runs; the old tree, now at the staging path, is removed after. A first run (no
  out/ yet) is a plain rename. If the exchange fails (out/ immutable, read-only file system,
  ...) out/ is untouched and the error names it. Every file of the new tree is fsynced
  before the swap, so a power cut cannot leave empty files in a swapped-in tree.
  Fallback where renameat2 is missing (not Linux, glibc < 2.28) or the file system does not
  support the exchange (EINVAL): out/ is renamed aside, the new tree renamed in, the old one
  removed; between the two renames out/ is absent for an instant (still never a mix), and a
  run killed exactly there leaves the previous tree aside, put back by the next run.
- Safety: out/ must be a directory of its own. The current directory or one of its parents is
  refused, and an existing non-empty directory is replaced only if it holds an output of this
  pipeline (one of OUTPUT_MARKERS at its top: results.json, a report, a study's record), so a
  mistyped `--out` never deletes someone's files.
"""
from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import errno
import fcntl
import os
import secrets
import shutil
import signal
import sys
import threading
from pathlib import Path
from typing import Callable, Iterator

from common.errors import RpsError

# An existing directory holding one of these may be replaced (outputs of earlier runs): the
# record each command writes at the top of its output directory (tests/test_faults.py checks
# that every record staged by a command is here, so each command can run again into its own).
OUTPUT_MARKERS = ("results.json", "report.html", "bench.json", "design.json",
                  "correlation.json", "identification.json", "frf.json", "uncertainty.json",
                  "lobes.json", "verification.json")

_AT_FDCWD = -100
_RENAME_EXCHANGE = 2  # linux/fs.h
_UNSUPPORTED = (errno.ENOSYS, errno.EINVAL, errno.EOPNOTSUPP)


class OutputError(RpsError, OSError):
    """The output directory cannot be used or replaced (one-line message naming it)."""


def _renameat2_function():
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
        function = libc.renameat2
    except (OSError, AttributeError):
        return None
    function.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p,
                         ctypes.c_uint]
    function.restype = ctypes.c_int
    return function


_RENAMEAT2 = _renameat2_function()


def exchange(a: Path, b: Path) -> None:
    """Atomically exchange two existing directory entries (the one step that publishes a run).
    OSError(ENOSYS) where the system has no renameat2."""
    if _RENAMEAT2 is None:
        raise OSError(errno.ENOSYS, "renameat2 is not available")
    if _RENAMEAT2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) != 0:
        code = ctypes.get_errno()
        raise OSError(code, os.strerror(code))


def check_output_dir(out: str | os.PathLike, option: str = "--out") -> Path:
    """The absolute output directory, or OutputError if it must not be replaced whole
    (`option`: the command-line option that named it)."""
    text = str(out)
    path = Path(os.path.abspath(out))
    cwd = Path.cwd()
    if path == cwd or path in cwd.parents or path.parent == path:
        raise OutputError(f"{option} {text}: each run replaces the output directory whole, so it "
                          "cannot be the current directory or one of its parents; give a "
                          "directory of its own (e.g. out)")
    if path.is_symlink():
        raise OutputError(f"{option} {text}: is a symbolic link; give the directory itself")
    if path.exists() and not path.is_dir():
        raise OutputError(f"{option} {text}: exists and is not a directory")
    if path.is_dir():
        try:
            names = sorted(os.listdir(path))
        except OSError as exc:
            raise OutputError(f"{option} {text}: cannot be read ({exc.strerror})") from None
        if names and not any(n in names for n in OUTPUT_MARKERS):
            shown = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
            raise OutputError(f"{option} {text}: holds {shown} but none of "
                              f"{', '.join(OUTPUT_MARKERS)}: not an output directory of this "
                              "pipeline, and each run replaces it whole; choose another "
                              "directory")
    from .places import PlaceError, check_writable_dir
    try:  # the run is staged beside it, in its parent
        check_writable_dir(path.parent, option, typed=text)
    except PlaceError as exc:
        raise OutputError(str(exc)) from None
    return path


def lock_path(out: Path) -> Path:
    return out.parent / f".{out.name}.lock"


def staging_prefix(out: Path) -> str:
    return f".{out.name}.staging-"


def _aside_prefix(out: Path) -> str:
    return f".{out.name}.previous-"


@contextlib.contextmanager
def output_lock(out: Path, notify: Callable[[str], None] | None = None) -> Iterator[None]:
    """Hold the exclusive lock of `out` for the body; wait (saying so) while another run has
    it."""
    path = lock_path(out)
    notify = notify or (lambda text: print(text, file=sys.stderr, flush=True))
    waited = False
    while True:
        try:
            out.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
        except OSError as exc:
            raise OutputError(f"cannot lock {out}: {exc.strerror} ({path})") from None
        try:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                if not waited:  # said once, however many runs go first
                    holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "?"
                    notify(f"waiting for the run that is writing {out} (pid {holder}) to finish")
                    waited = True
                fcntl.flock(fd, fcntl.LOCK_EX)
            try:  # the run we waited for removed this file: lock the current one instead
                current = os.stat(path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                current = False
        except BaseException:
            os.close(fd)
            raise
        if current:
            break
        os.close(fd)
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        yield
    finally:
        with contextlib.suppress(OSError):
            os.unlink(path)
        os.close(fd)  # releases the lock


def remove_stale(out: Path) -> list[Path]:
    """Remove what dead runs left beside `out` (call with the lock held): staging folders and
    the legacy `out.partial`; a previous tree left aside by the fallback swap goes back first."""
    parent = out.parent
    if not parent.is_dir():
        return []
    aside = sorted((e for e in parent.iterdir() if e.name.startswith(_aside_prefix(out))),
                   key=lambda e: e.stat().st_mtime)
    if aside and not os.path.lexists(out):
        os.rename(aside.pop(), out)
    removed = []
    for entry in parent.iterdir():
        if entry.name.startswith((staging_prefix(out), _aside_prefix(out))) \
                or entry.name == f"{out.name}.partial":
            shutil.rmtree(entry, ignore_errors=True)
            removed.append(entry)
    return removed


def _carry(out: Path, stage: Path, keep: Callable[[str], bool]) -> None:
    """Copy the entries of the current out/ that `keep` accepts into `stage`."""
    if not out.is_dir():
        return
    for entry in sorted(out.iterdir()):
        if keep(entry.name):
            if entry.is_dir() and not entry.is_symlink():
                shutil.copytree(entry, stage / entry.name, symlinks=True)
            else:
                shutil.copy2(entry, stage / entry.name, follow_symlinks=False)


def swap_in(stage: Path, out: Path) -> None:
    """Make `stage` the new `out` in one step; afterwards `stage` holds the old tree (or is
    gone). Raises OutputError naming `out`, with out/ left as it was."""
    _fsync_tree(stage)
    try:
        if not os.path.lexists(out):
            os.rename(stage, out)
        else:
            try:
                exchange(stage, out)
            except OSError as exc:
                if exc.errno not in _UNSUPPORTED:
                    raise
                _swap_by_two_renames(stage, out)
        _fsync(out.parent)
    except OSError as exc:
        raise OutputError(f"cannot replace {out}: {exc.strerror or exc}; it was left as it "
                          "was") from None


def _swap_by_two_renames(stage: Path, out: Path) -> None:
    aside = out.with_name(_aside_prefix(out) + secrets.token_hex(4))
    os.rename(out, aside)
    try:
        os.rename(stage, out)
    except BaseException:
        os.rename(aside, out)
        raise
    os.rename(aside, stage)  # the old tree where the caller removes it


def _fsync(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_tree(root: Path) -> None:
    for folder, _, files in os.walk(root):
        for name in files:
            _fsync(Path(folder, name))
        _fsync(Path(folder))


def _new_directory(parent: Path, prefix: str) -> Path:
    """A fresh directory with an ordinary mode (0777 less the umask, not mkdtemp's 0700)."""
    while True:
        path = parent / (prefix + secrets.token_hex(4))
        try:
            path.mkdir()
            return path
        except FileExistsError:
            continue


@contextlib.contextmanager
def staged_output(out: str | os.PathLike, keep: Callable[[str], bool] | None = None,
                  notify: Callable[[str], None] | None = None) -> Iterator[Path]:
    """Lock `out`, yield a fresh staging directory beside it, swap it in whole on success.

    `keep` selects entries of the current out/ (by name) that are copied into the new tree
    first: a report rebuilt into an existing out/ keeps the run's other files. Without it
    nothing of the previous out/ survives. On any exception the staging directory is removed
    and out/ is left exactly as it was; an OSError about a file in the staging directory names
    the file's place in out/ instead. `notify` receives the one "waiting" line (default:
    stderr).
    """
    out = check_output_dir(out)
    with output_lock(out, notify), _stop_on_signals() as stop:
        remove_stale(out)
        out = check_output_dir(out)  # the run we waited for may have changed it
        try:
            stage = _new_directory(out.parent, staging_prefix(out))
        except OSError as exc:
            raise OutputError(f"cannot write beside {out}: {exc.strerror}") from None
        try:
            try:
                if keep is not None:
                    _carry(out, stage, keep)
                yield stage
            except OutputError:
                raise
            except OSError as exc:
                raise OutputError(_in_out(exc, stage, out)) from None
            with _signals_held():
                if stop:  # a stop whose KeyboardInterrupt a finaliser swallowed
                    raise KeyboardInterrupt
                swap_in(stage, out)
                stop.append("done")  # a signal arriving now finds the run complete
        finally:
            shutil.rmtree(stage, ignore_errors=True)


_STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def _stop_on_signals() -> Iterator[list]:
    """SIGINT and SIGTERM raise KeyboardInterrupt for the run and are remembered in the list
    yielded, so a stop cannot be lost: Python drops an exception raised inside a finaliser
    (a weakref callback during garbage collection), and the run must then not be swapped in.
    Once the swap is done ("done" in the list), a late signal is let go: the run is complete."""
    stop: list = []
    if threading.current_thread() is not threading.main_thread():
        yield stop
        return

    def on_signal(signum, frame):
        if "done" not in stop:
            stop.append(signum)
            raise KeyboardInterrupt

    previous = {s: signal.signal(s, on_signal) for s in _STOP_SIGNALS}
    try:
        yield stop
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM wait (blocked) while out/ is swapped: one step, never half-done."""
    held = signal.pthread_sigmask(signal.SIG_BLOCK, _STOP_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


def _in_out(exc: OSError, stage: Path, out: Path) -> str:
    """The error's message with the staging path shown as the path in out/ it stands for."""
    reason = exc.strerror or " ".join(str(exc).split())
    names = [Path(os.fsdecode(n)) for n in (exc.filename2, exc.filename) if n is not None]
    for path in names:  # a copy names its source first, its target second: the target counts
        if path.is_relative_to(stage):
            return f"cannot write {out / path.relative_to(stage)}: {reason}"
    if names:
        return f"cannot write {names[-1]}: {reason}"
    text = " ".join(str(exc).split()).replace(str(stage), str(out))
    if exc.errno is not None and exc.errno in (errno.ENOSPC, errno.EDQUOT, errno.EROFS,
                                               errno.EIO, errno.EFBIG):
        return f"cannot write {out}: {reason}"  # the OS did not say which file
    return text or type(exc).__name__
