"""A one-line progress bar for a sweep on stderr: cases done / failed / remaining."""

from __future__ import annotations

import sys
import time

__all__ = ["SweepProgress"]


class SweepProgress:
    """Progress of a sweep, redrawn in place (``\\r``) on a terminal.

    Parameters
    ----------
    name : str
        Sweep name shown in front of the bar.
    total : int
        Number of cases in the sweep.
    enabled : bool
        Draw at all (the caller passes ``not quiet``); nothing is drawn unless ``stream`` is a tty.
    stream : file, optional
        Default ``sys.stderr``.
    """

    WIDTH = 24

    def __init__(self, name: str, total: int, enabled: bool = True, stream=None):
        self.stream = stream if stream is not None else sys.stderr
        isatty = getattr(self.stream, "isatty", lambda: False)
        self.enabled = bool(enabled) and isatty()
        self.name = name
        self.total = total
        self.done = self.failed = self.running = 0
        self.t0 = time.monotonic()
        self._drawn = False
        self._width = 0

    def update(self, done: int, failed: int, running: int = 0) -> None:
        """Redraw with ``done`` finished cases (of which ``failed`` failed) and ``running`` in flight."""
        self.done, self.failed, self.running = done, failed, running
        if not self.enabled:
            return
        frac = done / self.total if self.total else 1.0
        fill = int(round(frac * self.WIDTH))
        elapsed = int(time.monotonic() - self.t0)
        line = (f"\r{self.name} [{'#' * fill}{'-' * (self.WIDTH - fill)}] {done}/{self.total} done, "
                f"{failed} failed, {self.total - done} remaining ({running} running) "
                f"{elapsed // 60}:{elapsed % 60:02d}")
        # pad to the previous length so that a shorter line leaves no tail behind
        self.stream.write(line.ljust(self._width))
        self._width = len(line)
        self.stream.flush()
        self._drawn = True

    def close(self) -> None:
        """End the line."""
        if self.enabled and self._drawn:
            self.stream.write("\n")
            self.stream.flush()
            self._drawn = False
