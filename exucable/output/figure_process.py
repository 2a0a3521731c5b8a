"""A run's figures drawn by a helper process forked before the solve.

Importing matplotlib costs about as much CPU as drawing a run's three figures (``benchmarks/
figure_cost.py``); in a fresh process both came after the solve and nearly doubled a short run. The
helper is forked when the run starts (``exucable run`` forks it first thing, before anything loads
Exudyn or numba), imports matplotlib and loads its fonts while this process imports, builds and solves
the model, then forks a drawing process for each figure but its own (:data:`HELPER_DRAWS`); each of
them builds its figure's frame (its figure, axes and ticks: what does not depend on the results,
about a fifth of a figure's drawing, :func:`build_frames`) and waits. Once the results are
post-processed they are sent to the helper through a pipe, and by it to the drawing processes; each
draws and writes its figure (atomically, :func:`exucable.io.save_figure`) at once
(:func:`draw_in_parallel`), while this process writes the data files and ``summary.json``;
:meth:`Figures.write` returns once every figure is on disk. Forked before the results arrive, the
drawing processes' fork and their first writes to the pages they share with the helper (copied on
write) are paid beside the solve, not after it. A helper given nothing to draw (bad input, an
error) is killed at once, and its drawing processes end with it; :class:`Figures` is a context
manager, so an error or Ctrl-C stops it, and a helper whose run died (killed) ends on its own.

Deterministic: the helper is a fork of this process (the same matplotlib settings) and draws with the
same functions, so its files are byte for byte those drawn here (a figure drawn on a frame built ahead
is the same file as one drawn on a new figure). Whatever goes wrong in the helper (it died, timed out
or raised) the figures are drawn here instead; an :class:`OSError` of the helper's write (a full disk)
is raised here as it would have been.

The helper is used only where forking is safe and pays: a POSIX system with the ``fork`` start method,
one Python thread, not a daemonic process (a sweep's case process), no Exudyn loaded yet (a process
that may have run a model is never forked) and matplotlib not yet loaded (with it loaded, drawing here
costs no import). Otherwise the figures are drawn in this process, as before.
"""

from __future__ import annotations

import dataclasses
import gc
import multiprocessing
import os
import pickle
import select
import sys
import threading
import time
from pathlib import Path

from ..plots.bundle import plot_cross_sections
from ..plots.results import FRAMES, plot_pressure, plot_pull_force, plot_tension_profile

__all__ = ["Figures", "draw_figures", "draw_in_parallel", "figure_names", "helper_allowed", "build_frames",
           "HELPER_TIMEOUT_S", "HELPER_DRAWS", "FRAME_TICKS"]

#: Seconds to wait for the helper's figures before drawing them here instead. Drawing a 10 km run's
#: three figures takes a few seconds; a helper taking this long is stuck (or the machine is).
HELPER_TIMEOUT_S = 120.0
#: Major ticks made ahead on each axis of a frame: the most these figures drew on a short run's
#: axes (more are made when drawn if needed; those not needed are not drawn).
FRAME_TICKS = 11


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


def build_frames(ticks: int = FRAME_TICKS, until=None, names=None) -> dict:
    """Each figure's frame (:data:`exucable.plots.results.FRAMES`: figure, axes, ``ticks`` major
    ticks on each axis), built before the results exist; each is drawn on once. ``until``: a
    callable checked before each frame; once it is true no more are built (the results arrived: a
    figure without a frame is drawn on a new one, the same file, rather than wait). ``names``: only
    these figures' frames (default: all)."""
    frames = {}
    for name, frame in FRAMES.items():
        if names is not None and name not in names:
            continue
        if until is not None and until():
            break
        frames[name] = frame(ticks)
    return frames


def _cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def _serve(conn, main_end=None) -> None:
    """The helper: warm up, fork the drawing processes (:class:`_Drawer`), build its own figure's
    frame, wait for ``(out_dir, result)`` (or None: nothing to draw), draw, reply ``("ok", paths,
    cpu)`` (``cpu``: :attr:`Figures.helper_cpu_s`), ``("oserror", errno, strerror, filename)`` or
    ``("failed", reason)``. ``main_end``: the run's end of the pipe, closed here at once (a fork
    holds it too): otherwise the helper of a run that died would wait for it for ever."""
    if main_end is not None:
        main_end.close()
    drawers = {}
    try:
        # matplotlib's import makes some 10^5 objects, freeing next to none: the collector's passes
        # over them and over the run's objects (whose pages each pass copies here) are a tenth of
        # the warm-up's CPU (benchmarks/figure_cost.py)
        gc.disable()
        try:
            _warm_up()
        finally:
            gc.enable()
        # matplotlib's objects, loaded now, stay: the collector need not walk them again while the
        # figures are drawn, nor write to their pages in the drawing processes (each write copies a page)
        gc.freeze()
        if _cores() > 1 and not conn.poll():
            drawers = _start_drawers([name for name in FRAMES if name != HELPER_DRAWS], [conn.fileno()])
        frames = build_frames(until=conn.poll, names=[HELPER_DRAWS] if drawers else None)
        cpu = {"warm_up_s": time.process_time()}        # a fork's CPU time starts at zero
        message = conn.recv_bytes()
        msg = pickle.loads(message)
        if msg is None:
            return
        out, result = msg
        c0 = time.process_time()
        paths = draw_in_parallel(Path(out), result, cpu, frames, drawers, message)
        cpu["draw_s"] = time.process_time() - c0
        reply = ("ok", [str(p) for p in paths], cpu)
    except EOFError:
        return                                  # the run is gone or ended without figures
    except BaseException as exc:  # reported, and the run draws the figures itself
        reply = _outcome(exc)
    finally:
        for drawer in drawers.values():         # those not given the results: told to end, reaped
            drawer.stop()
    try:
        conn.send(reply)
    except OSError:
        pass
    finally:
        conn.close()


def _cross_sections(path, result, frame=None) -> None:
    x = result.cross_sections
    plot_cross_sections(path, x["panels"], x["inner_radius_m"], x["cable_radius_m"], title=result.summary.get("name", ""))


def figure_names(result) -> list[str]:
    """The file names of ``result``'s figures, in the order they are drawn and listed."""
    return [name for name, has, _ in _FIGURES if has(result)]


#: (file name, whether ``result`` has it, drawing function(path, result, frame=None))
_FIGURES = (("pull_force.png", lambda r: True, plot_pull_force),
            ("tension_profile.png", lambda r: r.tension_profile is not None, plot_tension_profile),
            ("pressure.png", lambda r: r.pressure_profile is not None, plot_pressure),
            ("cross_sections.png", lambda r: bool(r.cross_sections), _cross_sections))
_DRAW = {name: draw for name, _, draw in _FIGURES}

#: The figure the helper draws itself, each other one in a fork of its own at the same time: the
#: cheapest (~0.1 s CPU against 0.15-0.2 s for the others, ``benchmarks/figure_cost.py``), since the
#: helper also collects the forks' replies.
HELPER_DRAWS = "tension_profile.png"


def draw_figures(out: Path, result, names=None, frames: dict | None = None) -> list[Path]:
    """Draw the run's figures into ``out`` (each written atomically); returns their paths. Called
    after the numbers are computed: a failure to draw must not hold back (or lose) a result.
    ``names``: only these of :func:`figure_names` (default: all). ``frames``: figures' frames built
    ahead (:func:`build_frames`), each taken out of the dict as it is drawn on; the others are drawn
    on new figures."""
    written = []
    for name in figure_names(result):
        if names is None or name in names:
            frame = frames.pop(name, None) if frames else None
            _DRAW[name](out / name, result, frame=frame)
            written.append(out / name)
    return written


def _outcome(exc: BaseException) -> tuple:
    """A drawing exception as a picklable reply."""
    if isinstance(exc, OSError):
        return ("oserror", exc.errno, exc.strerror, exc.filename)
    return ("failed", f"{type(exc).__name__}: {exc}")


def _raise(reply: tuple) -> None:
    if reply[0] == "oserror":
        raise OSError(reply[1], reply[2], reply[3])
    raise RuntimeError(reply[1])


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:                                     # a pipe, not a file: written in pieces
        view = view[os.write(fd, view):]


def _read_all(fd: int) -> bytes:
    """Everything written into the pipe ``fd`` until its writers closed it (b"" if none was)."""
    with os.fdopen(fd, "rb") as f:
        return f.read()


def _draw_and_report(write_end: int, out: Path, result, name: str, frames: dict | None) -> None:
    """In a drawing process: draw figure ``name``, write ``("ok", the drawing's CPU time [s], the
    CPU time before it [s])`` or the exception's :func:`_outcome` into the pipe ``write_end`` and
    close it."""
    c0 = time.process_time()
    try:
        draw_figures(out, result, [name], frames)
        reply = ("ok", time.process_time() - c0, c0)
    except BaseException as exc:  # reported; the forking process draws what is missing
        reply = _outcome(exc)
    _write_all(write_end, pickle.dumps(reply))
    os.close(write_end)


def _fork() -> int | None:
    try:
        return os.fork()
    except OSError:                                 # no process to spare: not a file's error, draw here
        return None


def _drawn_in_a_fork(out: Path, result, name: str, frames: dict | None) -> tuple[int, int] | None:
    """Fork a process that draws figure ``name`` and reports through a pipe; returns (pid, the
    pipe's read end), or None if no process could be forked."""
    read_end, write_end = os.pipe()
    pid = _fork()
    if pid is None:
        os.close(read_end)
        os.close(write_end)
        return None
    if pid == 0:                                    # the fork: draw, report, leave at once
        code = 1
        try:
            os.close(read_end)
            _draw_and_report(write_end, out, result, name, frames)
            code = 0
        finally:
            os._exit(code)                          # no cleanup of the parent's state in the fork
    os.close(write_end)
    return pid, read_end


class _Drawer:
    """A process forked by the helper before the results exist, to draw one figure: it builds that
    figure's frame, then waits for the pickled ``(out_dir, result)`` on a pipe (:meth:`start`) and
    draws and reports as :func:`_drawn_in_a_fork`'s processes do; the pipe closed with nothing
    written (:meth:`stop`), it ends. ``inherited``: the forking process's descriptors it must not
    hold (the helper's pipe to the run, the other drawers' pipes: a pipe held open by a process
    that does not use it never reports its end)."""

    def __init__(self, name: str, inherited: list[int]):
        self.name = name
        self.pid = None
        results_r, self._results_w = os.pipe()
        self._reply_r, reply_w = os.pipe()
        pid = _fork()
        if pid == 0:
            code = 1
            try:
                for fd in (*inherited, self._results_w, self._reply_r):
                    os.close(fd)
                arrived = lambda: bool(select.select([results_r], [], [], 0)[0])  # noqa: E731
                frames = build_frames(until=arrived, names=[name])
                message = _read_all(results_r)
                if message:
                    out, result = pickle.loads(message)
                    _draw_and_report(reply_w, Path(out), result, name, frames)
                else:
                    os.close(reply_w)
                code = 0
            finally:
                os._exit(code)
        os.close(results_r)
        os.close(reply_w)
        if pid is None:
            os.close(self._results_w)
            os.close(self._reply_r)
        self.pid = pid

    def fds(self) -> list[int]:
        """The helper's ends of this drawer's pipes."""
        return [self._results_w, self._reply_r] if self.pid else []

    def start(self, message: bytes) -> tuple[int, int] | None:
        """Send the pickled ``(out_dir, result)``; returns (pid, the reply pipe's read end), as
        :func:`_drawn_in_a_fork`, or None if the drawer is gone (its figure is drawn elsewhere)."""
        try:
            _write_all(self._results_w, message)
        except OSError:                             # it died (a broken pipe): reaped, and drawn elsewhere
            self.stop()
            return None
        os.close(self._results_w)
        (pid, self.pid), reply_r = (self.pid, None), self._reply_r
        self._results_w = self._reply_r = -1        # the caller's now
        return pid, reply_r

    def release(self) -> None:
        """Tell a drawer not given the results to end (its pipes closed); :meth:`stop` reaps it."""
        for fd in (self._results_w, self._reply_r):
            try:
                os.close(fd)
            except OSError:                         # closed already
                pass
        self._results_w = self._reply_r = -1

    def stop(self) -> None:
        """End a drawer that was not given the results and reap it."""
        if not self.pid:
            return
        self.release()
        os.waitpid(self.pid, 0)
        self.pid = None


def _start_drawers(names, inherited: list[int]) -> dict:
    """A :class:`_Drawer` for each of ``names`` that could be forked, by name."""
    drawers = {}
    for name in names:
        drawer = _Drawer(name, inherited + [fd for d in drawers.values() for fd in d.fds()])
        if drawer.pid:
            drawers[name] = drawer
    return drawers


def draw_in_parallel(out: Path, result, cpu: dict | None = None, frames: dict | None = None,
                     drawers: dict | None = None, message: bytes | None = None) -> list[Path]:
    """Draw the figures in processes of their own at once: each in a fork of this process but
    :data:`HELPER_DRAWS` (or, without it, the last), which is drawn here meanwhile; returns their
    paths in :func:`figure_names`' order. Drawing is CPU-bound and single-threaded, so on n free
    cores the figures take about the longer of the costliest figure and the total over n (on two
    cores, one fork drawing two figures took the time of both). The forks report through pipes;
    whatever a fork did not draw (it failed or died) is drawn here, and an :class:`OSError` of its
    write is raised here. ``cpu``: a dict given the forks' CPU times [s], ``forks_draw_s`` (total),
    ``longest_fork_draw_s`` and, of drawers forked ahead, ``forks_warm_up_s`` (their frames, before
    the results). ``frames``: as :func:`draw_figures`'; a fork draws on its copy of its figure's
    frame, and a figure drawn again here (its fork failed) on a new figure. ``drawers``: processes
    forked ahead (:class:`_Drawer`) by figure name, each given ``message`` (the pickled ``(str(out),
    result)``; pickled here if None) instead of a new fork; those used are taken out of the dict."""
    names = figure_names(result)
    if len(names) < 2 or _cores() < 2:
        return draw_figures(out, result, frames=frames)
    mine = HELPER_DRAWS if HELPER_DRAWS in names else names[-1]
    forks = {}
    for name in names:
        if name == mine:
            continue
        if drawers and name in drawers:
            if message is None:
                message = pickle.dumps((str(out), result))
            forked = drawers.pop(name).start(message)
        else:
            forked = _drawn_in_a_fork(out, result, name, frames)
        if forked is not None:
            forks[name] = forked
            if frames:
                frames.pop(name, None)          # drawn on in the fork; if that fails, here on a new figure
    for drawer in (drawers or {}).values():     # a figure this result does not have: ends now, reaped later
        drawer.release()
    replies = {}
    try:
        draw_figures(out, result, [n for n in names if n not in forks], frames)
    finally:
        for name, (pid, read_end) in forks.items():
            data = _read_all(read_end)
            os.waitpid(pid, 0)
            replies[name] = pickle.loads(data) if data else ("failed", "the drawing process died")
    for reply in replies.values():
        if reply[0] == "oserror":
            _raise(reply)
    draw_figures(out, result, [n for n, reply in replies.items() if reply[0] != "ok"])
    drawn = [reply for reply in replies.values() if reply[0] == "ok"]
    if cpu is not None and drawn:
        cpu["forks_draw_s"], cpu["longest_fork_draw_s"] = sum(r[1] for r in drawn), max(r[1] for r in drawn)
        cpu["forks_warm_up_s"] = sum(r[2] for r in drawn)
    return [out / n for n in names]


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
        self._sent = False               # whether the helper was given results to draw
        self.helper_reason = ""          # why the figures were drawn here, if they were
        #: the helper's CPU times [s] once it drew: ``warm_up_s`` (matplotlib's import, warm-up and its
        #: frame, beside the solve), ``draw_s`` (its drawing after the results arrived) and, where forks
        #: drew the other figures at the same time, ``forks_draw_s`` (their total),
        #: ``longest_fork_draw_s`` and ``forks_warm_up_s`` (the frames of those forked before the
        #: results, beside the solve); empty otherwise
        self.helper_cpu_s: dict[str, float] = {}
        if helper is None:
            helper, self.helper_reason = helper_allowed()
        elif helper and "fork" not in multiprocessing.get_all_start_methods():
            helper, self.helper_reason = False, "no fork start method on this system"
        if helper:
            ctx = multiprocessing.get_context("fork")
            self._conn, child = ctx.Pipe(duplex=True)
            self._proc = ctx.Process(target=_serve, args=(child, self._conn), daemon=True, name="exucable-figures")
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
            sent = self._sent = True
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
            self.helper_cpu_s = reply[2]
            return [Path(p) for p in reply[1]]
        if reply is not None and reply[0] == "oserror":
            _raise(reply)
        self.helper_reason = ("the helper failed: " + reply[1]) if reply else "the helper gave no figures"
        return draw_figures(out, result)

    def close(self) -> None:
        """Stop the helper (if any): killed at once if it was given nothing to draw (it has written
        nothing: a failed run or bad input is not held up by matplotlib's import), else told to end
        and killed if it does not within a second."""
        if self._proc is None:
            return
        if not self._sent:
            self._proc.kill()
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
