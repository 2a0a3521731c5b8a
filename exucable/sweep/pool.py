"""The local pool: every case in a fresh process, at most ``workers`` at a time.

Each case runs in its own :class:`multiprocessing.Process` of a ``forkserver`` (or ``spawn``)
context and sends its record back through a pipe. The parent waits on the processes' sentinels
and pipes together, so it knows *which* case's process died and how (exit code or signal).

Why not :class:`concurrent.futures.ProcessPoolExecutor` (``max_tasks_per_child=1``), which was
the first design: on CPython 3.11, a worker process started by ``submit()`` is not among the
processes the pool's manager thread watches until that thread next wakes up, so a worker killed
mid-case (SIGKILL, OOM killer, a crash in native code) could leave the pool waiting forever; this
was reproduced by ``tests/test_sweep.py::test_dead_worker_is_rerun_then_recorded``. And a broken
executor fails every case in flight without saying which one killed it.

A case whose process dies without a record is started once more (a stray kill or an out-of-memory
kill need not repeat); if it dies again it is recorded as failed with the exit code or signal.

A case process dies with the sweep (:func:`_die_with_sweep`): killed, even by SIGKILL, the sweep
leaves no case computing on as an orphan, whose files a re-run would otherwise race.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys
import threading
import time
import traceback
from collections import deque
from multiprocessing.connection import wait

from ..io import pid_alive

__all__ = ["run_local", "MAX_ATTEMPTS"]

# Starts of one case whose process dies without sending a record, before it is recorded failed.
MAX_ATTEMPTS = 2


#: Seconds between two looks of a case process at whether its sweep is still alive.
WATCH_INTERVAL_S = 0.5
_PR_SET_PDEATHSIG = 1       # linux/prctl.h


def _die_with_sweep(sweep_pid: int) -> None:
    """Make this case process die when the sweep process ``sweep_pid`` does.

    On Linux the kernel sends SIGKILL when the parent dies (``prctl(PR_SET_PDEATHSIG)``); the
    parent of a ``forkserver`` child is the fork server, which exits as soon as the sweep is gone.
    A watch thread covers the rest (``spawn``, other systems, a sweep that died before the
    ``prctl``): it kills this process once the sweep's pid is gone or this process was re-parented.
    """
    if sys.platform.startswith("linux"):
        try:
            ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):
            pass                                # no libc prctl here: the watch thread alone
    parent = os.getppid()

    def orphaned() -> bool:
        return os.getppid() != parent or not pid_alive(sweep_pid)

    def watch() -> None:
        while not orphaned():
            time.sleep(WATCH_INTERVAL_S)
        os.kill(os.getpid(), signal.SIGKILL)

    if orphaned():
        os.kill(os.getpid(), signal.SIGKILL)
    threading.Thread(target=watch, name="exucable-watch-sweep", daemon=True).start()


def _child(task: dict, runner, conn, sweep_pid: int | None = None) -> None:
    """Process target: run one case, send ``("ok", record)`` or ``("error", message, traceback)``."""
    from .worker import run_case

    if sweep_pid is not None:
        _die_with_sweep(sweep_pid)
    try:
        msg = ("ok", run_case(task, runner))
    except BaseException as exc:  # the harness failed (disk full, bad runner): report, don't hang
        msg = ("error", f"{type(exc).__name__}: {exc}", traceback.format_exc())
    try:
        conn.send(msg)
    except OSError:
        pass              # the sweep is gone (a broken pipe): the case directory is installed anyway
    finally:
        conn.close()


def _death(exitcode) -> str:
    if exitcode is not None and exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = "unknown signal"
        return f"killed by signal {-exitcode} ({name})"
    return f"exited with code {exitcode} before sending its result"


class _Running:
    __slots__ = ("proc", "conn", "task", "message")

    def __init__(self, proc, conn, task):
        self.proc, self.conn, self.task, self.message = proc, conn, task, None


def run_local(tasks, workers: int, runner, ctx, on_record, on_running, on_failure) -> None:
    """Run ``tasks`` with at most ``workers`` case processes at a time.

    Parameters
    ----------
    tasks : list of dict
        Task dicts (see :mod:`exucable.sweep.worker`).
    workers : int
        Largest number of case processes alive at once.
    runner : callable or None
        Passed to :func:`~exucable.sweep.worker.run_case`.
    ctx : multiprocessing context
        ``forkserver`` or ``spawn`` (see :func:`~exucable.sweep.execute.worker_context`).
    on_record : callable(case_id, record)
        Called in this process for every case that ended with a record.
    on_running : callable(n)
        Called with the number of case processes alive.
    on_failure : callable(task, message, detail) -> record
        Records a case that ended without a record (its process died twice, or the harness
        failed); the returned record is passed to ``on_record``.
    """
    queue = deque(tasks)
    attempts: dict[str, int] = {}
    running: list[_Running] = []
    try:
        while queue or running:
            while queue and len(running) < workers:
                task = queue.popleft()
                attempts[task["case"]] = attempts.get(task["case"], 0) + 1
                r, w = ctx.Pipe(duplex=False)
                proc = ctx.Process(target=_child, args=(task, runner, w, os.getpid()), daemon=True,
                                   name=f"exucable-case-{task['case']}")
                proc.start()
                w.close()   # the child holds the write end; EOF here once it is gone
                running.append(_Running(proc, r, task))
            on_running(len(running))
            # pipes too, not only sentinels: a record larger than the pipe buffer blocks its
            # sender until read, and the process could not exit before that
            waitables = [x.conn for x in running if x.message is None] + [x.proc.sentinel for x in running]
            ready = set(wait(waitables))
            for x in list(running):
                if x.message is None and x.conn in ready:
                    try:
                        x.message = x.conn.recv()
                    except (EOFError, OSError):
                        x.message = ("dead",)
                if x.proc.sentinel not in ready:
                    continue
                if x.message is None:          # exited: drain what it may have sent last
                    try:
                        x.message = x.conn.recv() if x.conn.poll() else ("dead",)
                    except (EOFError, OSError):
                        x.message = ("dead",)
                x.proc.join()
                x.conn.close()
                running.remove(x)
                cid = x.task["case"]
                kind = x.message[0]
                if kind == "ok":
                    on_record(cid, x.message[1])
                elif kind == "error":
                    on_record(cid, on_failure(x.task, x.message[1], x.message[2]))
                elif attempts[cid] < MAX_ATTEMPTS:
                    queue.appendleft(x.task)  # died without a record: once more
                else:
                    on_record(cid, on_failure(
                        x.task, f"the case's process died {attempts[cid]} times; last: "
                                f"{_death(x.proc.exitcode)} (killed, out of memory, or a crash in native code)",
                        ""))
    except BaseException:
        for x in running:   # interrupted: stop the cases now (their temporary dirs are cleaned next run)
            x.proc.kill()
        for x in running:
            x.proc.join(timeout=5)
        raise
    finally:
        on_running(0)
