"""Following a growing log: re-read it when it changes, refit, until the pull ends or the log goes quiet."""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterator

from exucable.errors import LogError
from exucable.fit.log import PullLog, read_pull_log

__all__ = ["WatchUpdate", "watch_log"]


@dataclass
class WatchUpdate:
    """One re-read of the log: the log and the fit, or the error that kept it from fitting yet.

    ``stop`` says why the watch ends after this update (``"ended"``: the log says the pull ended or the
    head reached the route's end; ``"timeout"``: no change for the timeout), else None.
    """

    log: PullLog | None
    fit: object | None
    error: LogError | None
    stop: str | None = None


def watch_log(path, fit: Callable[[PullLog], object], *, poll_s: float = 2.0, timeout_s: float = 600.0,
              route_length_m: float | None = None, sleep: Callable[[float], None] = time.sleep,
              clock: Callable[[], float] = time.monotonic, **read_kwargs) -> Iterator[WatchUpdate]:
    """Yield an update each time the log at ``path`` changes (size or modification time).

    Parameters
    ----------
    path : path-like
        The log being written.
    fit : callable
        ``fit(log)`` → the fit (:func:`exucable.fit.friction.fit_friction` bound to a scenario).
    poll_s : float
        Seconds between looks at the file.
    timeout_s : float
        Stop when the file has not changed for this long [s].
    route_length_m : float, optional
        Stop once the log's pulled length reaches it (the head is out).
    sleep, clock : callable
        For tests: how to wait and what time it is.
    **read_kwargs
        Passed to :func:`exucable.fit.log.read_pull_log` (columns, units, tare, ...); a line still
        being written (no newline yet) is left for the next read.

    Yields
    ------
    WatchUpdate
        The last one has ``stop`` set. Ctrl-C (KeyboardInterrupt) propagates from the wait.
    """
    if not (poll_s > 0):
        raise LogError("--poll", f"must be > 0 (s), got {poll_s}")
    if not (timeout_s > 0):
        raise LogError("--timeout", f"must be > 0 (s), got {timeout_s}")
    path = Path(path)
    seen = None
    last_change = clock()
    while True:
        try:
            st = os.stat(path)
            stamp = (st.st_size, st.st_mtime_ns)
        except FileNotFoundError:
            stamp = None
        if stamp is not None and stamp != seen:
            seen = stamp
            last_change = clock()
            try:
                log = read_pull_log(path, complete_only=True, **read_kwargs)
            except LogError as exc:
                yield WatchUpdate(None, None, exc)
                continue
            try:
                result = fit(log)
                error = None
            except LogError as exc:
                result, error = None, exc
            done = log.ended or (route_length_m is not None
                                 and float(log.pulled_length_m.max()) >= route_length_m * (1 - 1e-6))
            yield WatchUpdate(log, result, error, "ended" if done else None)
            if done:
                return
            continue
        if clock() - last_change >= timeout_s:
            yield WatchUpdate(None, None, None, "timeout")
            return
        sleep(poll_s)
