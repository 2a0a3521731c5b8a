"""A run's figures drawn by a helper process forked before the solve.

Importing matplotlib costs about as much CPU as drawing a run's three figures (``benchmarks/
figure_cost.py``); in a fresh process both came after the solve and nearly doubled a short run. The
helper is forked when the run starts, imports matplotlib and loads its fonts while this process builds
and solves the model, then waits. Once the results are post-processed they are sent to it through a
pipe; it draws and writes the figures (atomically, :func:`exucable.io.save_figure`) while this process
writes the data files and ``summary.json``; :meth:`Figures.write` returns once every figure is on disk.

Deterministic: the helper is a fork of this process (the same matplotlib settings) and draws with the
same functions, so its files are byte for byte those drawn here. Whatever goes wrong in the helper (it
died, timed out or raised) the figures are drawn here instead; an :class:`OSError` of the helper's
write (a full disk) is raised here as it would have been.

The helper is used only where forking is safe and pays: a POSIX system with the ``fork`` start method,
one Python thread, not a daemonic process (a sweep's case process), no Exudyn loaded yet (a process
that may have run a model is never forked) and matplotlib not yet loaded (with it loaded, drawing here
costs no import). Otherwise the figures are drawn in this process, as before.
"""

from __future__ import annotations

import dataclasses
import multiprocessing
import sys
import threading
from pathlib import Path

from ..plots.bundle import plot_cross_sections
from ..plots.results import plot_pressure, plot_pull_force, plot_tension_profile

__all__ = ["Figures", "draw_figures", "helper_allowed", "HELPER_TIMEOUT_S"]

#: Seconds to wait for the helper's figures before drawing them here instead. Drawing a 10 km run's
#: three figures takes a few seconds; a helper taking this long is stuck (or the machine is).
HELPER_TIMEOUT_S = 120.0


def helper_allowed() -> tuple[bool, str]:
    """Whether this process may fork a figure helper now, and why not."""
    if "fork" not in multiprocessing.get_all_start_methods():
        return False, "no fork start method on this system"
    if threading.active_count() != 1:
        return False, "more than one thread in this process"
    if multiprocessing.current_process().daemon:
        return False, "a daemonic process (a sweep's case) cannot have children"
    if "exudyn" in sys.modules:
        return False, "Exudyn is loaded (a process that may have run a model is not forked)"
    if "matplotlib.figure" in sys.modules:
        return False, "matplotlib is loaded already (drawing here costs no import)"
    return True, ""


def _warm_up() -> None:
    """Import matplotlib and load the font and text caches, so that the first figure drawn costs
    no more than the next one."""
    import io

    from ..io import new_figure

    fig = new_figure(figsize=(2.0, 1.5))
    ax = fig.subplots()
    ax.plot([0.0, 1.0], [0.0, 1.0], ".-", label="a")
    ax.set_title("warm-up")
    ax.set_xlabel("x [m]")
    ax.legend(fontsize=7)
    fig.savefig(io.BytesIO(), format="png", dpi=40)


def _serve(conn) -> None:
    """The helper: warm up, wait for ``(out_dir, result)`` (or None: nothing to draw), draw, reply
    ``("ok", paths)``, ``("oserror", errno, strerror, filename)`` or ``("failed", reason)``."""
    try:
        _warm_up()
        msg = conn.recv()
        if msg is None:
            return
        out, result = msg
        reply = ("ok", [str(p) for p in draw_figures(Path(out), result)])
    except EOFError:
        return                                  # the run is gone or ended without figures
    except OSError as exc:
        reply = ("oserror", exc.errno, exc.strerror, exc.filename)
    except BaseException as exc:  # reported, and the run draws the figures itself
        reply = ("failed", f"{type(exc).__name__}: {exc}")
    try:
        conn.send(reply)
    except OSError:
        pass
    finally:
        conn.close()


def draw_figures(out: Path, result) -> list[Path]:
    """Draw the run's figures into ``out`` (each written atomically); returns their paths. Called
    after the numbers are computed: a failure to draw must not hold back (or lose) a result."""
    plot_pull_force(out / "pull_force.png", result)
    written = [out / "pull_force.png"]
    if result.tension_profile is not None:
        plot_tension_profile(out / "tension_profile.png", result)
        written.append(out / "tension_profile.png")
    if result.pressure_profile is not None:
        plot_pressure(out / "pressure.png", result)
        written.append(out / "pressure.png")
    if result.cross_sections:
        x = result.cross_sections
        plot_cross_sections(out / "cross_sections.png", x["panels"], x["inner_radius_m"], x["cable_radius_m"],
                            title=result.summary.get("name", ""))
        written.append(out / "cross_sections.png")
    return written


class Figures:
    """The figures of one run, drawn by a helper process when :func:`helper_allowed` (or ``helper``
    says so), else here. Use as a context manager around the solve, so the helper never outlives it.

    Parameters
    ----------
    helper : bool, optional
        True: fork a helper if the system can fork at all; False: draw here; None (default): fork
        where :func:`helper_allowed`.
    """

    def __init__(self, helper: bool | None = None):
        self._proc = self._conn = None
        self.helper_reason = ""          # why the figures were drawn here, if they were
        if helper is None:
            helper, self.helper_reason = helper_allowed()
        elif helper and "fork" not in multiprocessing.get_all_start_methods():
            helper, self.helper_reason = False, "no fork start method on this system"
        if helper:
            ctx = multiprocessing.get_context("fork")
            self._conn, child = ctx.Pipe(duplex=True)
            self._proc = ctx.Process(target=_serve, args=(child,), daemon=True, name="exucable-figures")
            self._proc.start()
            child.close()

    @property
    def helper_running(self) -> bool:
        """Whether a helper process is waiting for this run's results."""
        return self._proc is not None

    def __enter__(self) -> "Figures":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def write(self, out_dir, result, while_drawing=None) -> list[Path]:
        """Draw ``result``'s figures into ``out_dir``; returns their paths.

        ``while_drawing``: a callable run here while the helper draws (the data files); its value is
        ignored and its exceptions propagate after the helper is stopped. Without a helper it runs
        first, then the figures are drawn here.
        """
        out = Path(out_dir)
        if self._proc is None:
            if while_drawing is not None:
                while_drawing()
            return draw_figures(out, result)
        reply = None
        try:
            # the solved model stays here: it is not data, and it cannot cross a pipe
            self._conn.send((str(out), dataclasses.replace(result, model=None)))
            sent = True
        except (OSError, ValueError):
            sent = False
        try:
            if while_drawing is not None:
                while_drawing()
            if sent and self._conn.poll(HELPER_TIMEOUT_S):
                reply = self._conn.recv()
        except (EOFError, OSError):
            reply = None
        finally:
            self.close()
        if reply is not None and reply[0] == "ok":
            return [Path(p) for p in reply[1]]
        if reply is not None and reply[0] == "oserror":
            raise OSError(reply[1], reply[2], reply[3])
        self.helper_reason = ("the helper failed: " + reply[1]) if reply else "the helper gave no figures"
        return draw_figures(out, result)

    def close(self) -> None:
        """Stop the helper (if any): told to end, then killed if it does not within a second."""
        if self._proc is None:
            return
        try:
            self._conn.send(None)
        except (OSError, ValueError):
            pass
        self._conn.close()
        self._proc.join(timeout=1.0)
        if self._proc.is_alive():
            self._proc.kill()
            self._proc.join()
        self._proc = self._conn = None
