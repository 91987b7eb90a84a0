"""Run long work in a child process that Ctrl-C and SIGTERM stop at once.

SuperLU's factorisation and ARPACK run in C for minutes without coming back to Python, and a
Python signal handler only runs when they do: a SIGTERM during a fine FEM solve used to wait
70-90 s. Rendering a report (matplotlib, VTK, WeasyPrint) is full of finalisers, and a
KeyboardInterrupt raised while one runs is swallowed ("Exception ignored in ..."), so the
render went on. `stoppable(fn, *args)` forks a child that calls fn and sends the result back
through a pipe, while the parent waits in a read, where signals are handled at once. When that
wait ends with an exception (KeyboardInterrupt from Ctrl-C, or from SIGTERM, which the command
lines turn into one), the child is killed with SIGKILL and reaped before the exception goes on,
so the work stops within milliseconds. The child also dies with its parent
(PR_SET_PDEATHSIG), so a kill -9 of the run leaves no orphan computing. fork shares the
parent's memory copy-on-write (nothing is copied or pickled on the way in); only the result (a
few MB of eigenvectors, or a pair of paths) and any exception are pickled back. Where fork is
unavailable the call runs in-process. Used by the FEM solve (fem_reference.model) and the
report (reports.build).
"""
from __future__ import annotations

import ctypes
import os
import pickle
import signal
from typing import Any, Callable

from .errors import ComputeError

_PR_SET_PDEATHSIG = 1


class WorkerDied(ComputeError):
    """The child process ended without a result (killed by a signal, e.g. out of memory)."""


def stoppable(fn: Callable[..., Any], *args, **kwargs) -> Any:
    """fn(*args, **kwargs), computed in a child process that a signal to this one stops."""
    if not hasattr(os, "fork"):
        return fn(*args, **kwargs)
    read_end, write_end = os.pipe()
    parent = os.getpid()
    pid = os.fork()
    if pid == 0:  # the child: compute, send, and leave without running the parent's cleanup
        status = 1
        try:
            os.close(read_end)
            die_with_parent(parent)
            signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C reaches the whole group:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)  # the parent decides, and kills us
            _send(write_end, fn, args, kwargs)
            status = 0
        finally:
            os._exit(status)
    os.close(write_end)
    try:
        data = _receive(read_end)
    except BaseException:
        os.kill(pid, signal.SIGKILL)
        raise
    finally:
        os.close(read_end)
        _, status = os.waitpid(pid, 0)
    if not data:
        how = (f"killed by signal {os.WTERMSIG(status)}" if os.WIFSIGNALED(status)
               else f"exit status {os.waitstatus_to_exitcode(status)}")
        raise WorkerDied(f"the solver process ended without a result ({how}; out of memory?)")
    ok, value = pickle.loads(data)
    if ok:
        return value
    raise value


def _send(fd: int, fn, args, kwargs) -> None:
    try:
        payload = pickle.dumps((True, fn(*args, **kwargs)), protocol=pickle.HIGHEST_PROTOCOL)
    except BaseException as exc:  # noqa: BLE001 - every failure goes back to the parent
        try:
            payload = pickle.dumps((False, exc), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:  # noqa: BLE001 - an exception that cannot be pickled
            payload = pickle.dumps((False, ComputeError(f"{type(exc).__name__}: {exc}")))
    with os.fdopen(fd, "wb") as pipe:
        pipe.write(payload)


def _receive(fd: int) -> bytes:
    chunks: list[bytes] = []
    while True:
        chunk = os.read(fd, 1 << 20)
        if not chunk:
            return b"".join(chunks)
        chunks.append(chunk)


def die_with_parent(parent: int) -> None:
    """Ask the kernel to SIGKILL this process when its parent dies (Linux): the stoppable
    child, and the workers of a pool it starts (as their initializer), so stopping a stoppable
    call stops everything it started."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent:  # the parent died before the request took effect
        os._exit(1)
