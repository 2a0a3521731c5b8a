"""The figures' helper process (exucable.output.figure_process): the same files as drawn here, a
fallback when it fails, and the rule for when it is used. Hand-made results: no solve."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from exucable.errors import OutputError
from exucable.output.figure_process import Figures
from exucable.output.results import FIGURE_FILES, RunResult, write_results

ROOT = Path(__file__).resolve().parents[1]
needs_fork = pytest.mark.skipif(not hasattr(os, "fork"), reason="the helper is forked")


def _result() -> RunResult:
    """A small result with every figure's data (the writer is under test, not the physics)."""
    t = np.linspace(0.0, 0.4, 41)
    x = np.linspace(0.0, 2.8, 81)
    s = np.linspace(0.0, 2.8, 600)
    pressure = np.where((s > 1.0) & (s < 1.8), 350.0, 0.0)
    summary = {"name": "hand-made", "mode": "dynamic", "status": "steady", "steady": True, "steady_from_s": 0.2,
               "pull_force_N": 205.5, "pull_force_uncertainty_N": 0.1, "rope_pull_force_N": 205.37,
               "rope_clearance_pull_force_N": 205.37, "pressure_window_m": 0.25}
    from exucable.post.pressure import BEND_COLUMNS
    bend = {c: 1.0 for c in BEND_COLUMNS}
    bend |= {"s_conduit_start_m": 1.0, "s_conduit_end_m": 1.785, "entry_point_load_N": 6.0,
            "exit_point_load_N": 15.3, "entry_s_conduit_m": 1.0, "exit_s_conduit_m": 1.785}
    return RunResult(summary=summary,
                     history={"time_s": t, "pull_force_N": 205.0 + t, "trailing_tension_N": np.full_like(t, 150.0),
                              "max_tension_N": 205.0 + t},
                     tension_profile={"x_m": x, "tension_N": 150.0 + 20.0 * x},
                     contact_profile={"s_conduit_m": s, "normal_force_per_length_N_per_m": pressure,
                                      "penetration_m": np.zeros_like(s)},
                     rope_profile={"s_conduit_m": x, "tension_N": 150.0 + 19.0 * x,
                                   "sidewall_pressure_N_per_m": np.zeros_like(x)},
                     extras={"x_m": x}, bends=[bend],
                     pressure_profile={"s_conduit_m": s, "windowed_pressure_N_per_m": pressure,
                                       "rope_windowed_pressure_N_per_m": 0.95 * pressure})


@needs_fork
def test_the_helpers_figures_are_those_drawn_here(tmp_path):
    """Byte for byte: the helper is a fork with the same matplotlib and settings."""
    with Figures(helper=True) as figures:
        assert figures.helper_running
        helper = write_results(tmp_path / "helper", _result(), plots=figures)
    here = write_results(tmp_path / "here", _result(), plots=True)
    assert [p.name for p in helper] == [p.name for p in here]
    for name in set(FIGURE_FILES) & {p.name for p in here}:
        assert (tmp_path / "helper" / name).read_bytes() == (tmp_path / "here" / name).read_bytes(), name
    assert not figures.helper_running and figures.helper_reason == ""
    assert {"warm_up_s", "draw_s"} <= set(figures.helper_cpu_s) and all(v > 0 for v in figures.helper_cpu_s.values())


def _children(pid: int) -> list[int]:
    """The ids of process ``pid``'s children (Linux's /proc; empty where there is none)."""
    try:
        return [int(c) for c in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    except OSError:
        return []


def _ended(pid: int) -> bool:
    """Whether process ``pid`` has ended (gone, or a zombie not yet reaped)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] in ("Z", "X")
    except OSError:
        return True


def _wait_for(condition, timeout_s: float = 60.0) -> bool:
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.05)
    return False


needs_proc_children = pytest.mark.skipif(not Path(f"/proc/{os.getpid()}/task/{os.getpid()}/children").exists(),
                                         reason="reads a process's children from Linux's /proc")


def _drawing_processes_forked(figures) -> tuple[int, list[int]]:
    """The helper's id and, once it has forked them after its warm-up, its two drawing processes'."""
    if len(os.sched_getaffinity(0)) < 2:
        pytest.skip("one core: the helper forks no drawing process")
    helper = figures._proc.pid
    assert _wait_for(lambda: len(_children(helper)) == 2), "no drawing processes forked"
    return helper, _children(helper)


@needs_fork
@needs_proc_children
def test_drawing_processes_forked_ahead_draw_the_same_files(tmp_path):
    """A helper given the results after its warm-up has forked a drawing process for each figure but
    its own, each with its frame built; they draw byte for byte what one process draws, report their
    frames' CPU beside the solve, and every process of the figures has ended when the run goes on."""
    from exucable.output import figure_process as fp

    with Figures(helper=True) as figures:
        helper, drawers = _drawing_processes_forked(figures)
        helper_paths = write_results(tmp_path / "helper", _result(), plots=figures)
    here = fp.draw_figures(tmp_path / "here", _result())
    assert [p.name for p in helper_paths if p.suffix == ".png"] == [p.name for p in here]
    for p in here:
        assert (tmp_path / "helper" / p.name).read_bytes() == p.read_bytes(), p.name
    assert figures.helper_cpu_s["forks_warm_up_s"] > 0 and figures.helper_cpu_s["longest_fork_draw_s"] > 0
    assert all(_ended(pid) for pid in [helper] + drawers)


@needs_fork
@needs_proc_children
def test_the_drawing_processes_of_a_helper_given_nothing_end_with_it():
    """A failed run kills its helper without results: the drawing processes it forked ahead, waiting
    for the results, end too."""
    with Figures(helper=True) as figures:
        _, drawers = _drawing_processes_forked(figures)
    assert _wait_for(lambda: all(_ended(pid) for pid in drawers), 10.0)


@needs_fork
@needs_proc_children
def test_the_helper_of_a_run_that_died_ends_by_itself(tmp_path):
    """The run killed before it sent its results: the helper (which held the run's end of their
    pipe too, and so waited for ever) ends."""
    script = textwrap.dedent("""
        import os, signal, time
        from exucable.output.figure_process import Figures
        figures = Figures(helper=True)
        print(figures._proc.pid, flush=True)
        time.sleep(0.2)
        os.kill(os.getpid(), signal.SIGKILL)
    """)
    with open(tmp_path / "out", "w") as out:         # a file: a helper left behind holds no pipe open
        subprocess.run([sys.executable, "-c", script], stdout=out, timeout=120, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    helper = int((tmp_path / "out").read_text().split()[0])
    ended = _wait_for(lambda: _ended(helper))
    if not ended:
        os.kill(helper, 9)                          # not left behind by a failing test
    assert ended, "the helper outlived its run"


@needs_fork
def test_a_dead_helper_costs_no_figure(tmp_path):
    """Killed before the results arrive: the figures are drawn here, and the reason is kept."""
    with Figures(helper=True) as figures:
        figures._proc.kill()
        figures._proc.join()
        paths = write_results(tmp_path, _result(), plots=figures)
    drawn = {"pull_force.png", "tension_profile.png", "pressure.png"}      # one cable: no cross sections
    assert {p.name for p in paths} >= drawn
    assert all((tmp_path / n).stat().st_size > 1000 for n in drawn)
    assert "helper" in figures.helper_reason


@needs_fork
def test_a_helper_that_cannot_write_reports_the_files_error(tmp_path, monkeypatch):
    """An OSError of the helper's write (a full disk) is raised here as the usual OutputError, after
    the data files and summary.json are in place."""
    def full(path, data):
        raise OSError(28, "No space left on device", str(path))

    monkeypatch.setattr("exucable.io.atomic_write_bytes", full)   # the fork inherits the patch
    with Figures(helper=True) as figures:
        with pytest.raises(OutputError, match="summary.json are written, but a figure is not.*No space left"):
            write_results(tmp_path, _result(), plots=figures)
    assert (tmp_path / "summary.json").exists()


def test_a_helper_that_stays_unused_is_stopped():
    with Figures(helper=hasattr(os, "fork")) as figures:
        proc = figures._proc
    assert not figures.helper_running
    assert proc is None or not proc.is_alive()


def test_the_helper_is_forked_only_from_a_fresh_process():
    """In a fresh process it is (exucable imported, neither Exudyn nor matplotlib yet); with matplotlib
    or Exudyn loaded, or another thread running, the figures are drawn here, and the reason says why."""
    script = textwrap.dedent("""
        import threading, time
        import exucable.run
        from exucable.output.figure_process import helper_allowed
        print(helper_allowed()[0])
        t = threading.Thread(target=time.sleep, args=(0.5,)); t.start()
        print(helper_allowed()); t.join()
        import matplotlib.figure
        print(helper_allowed())
    """)
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                       env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert p.returncode == 0, p.stderr
    first, thread, mpl = p.stdout.strip().splitlines()
    assert first == str(hasattr(os, "fork"))
    assert "thread" in thread and "False" in thread
    assert "matplotlib is loaded" in mpl


@needs_fork
def test_parallel_processes_draw_the_same_files(tmp_path):
    """draw_in_parallel (the helper's way) writes byte for byte what one process draws, listed in the
    same order."""
    from exucable.output import figure_process as fp

    one = fp.draw_figures(tmp_path / "one", _result())
    many = fp.draw_in_parallel(tmp_path / "many", _result())
    assert [p.name for p in many] == [p.name for p in one] == fp.figure_names(_result())
    for p in one:
        assert (tmp_path / "many" / p.name).read_bytes() == p.read_bytes(), p.name


@needs_fork
def test_each_figure_is_drawn_in_a_process_of_its_own(tmp_path, monkeypatch):
    """On two or more cores the figures are drawn at once: HELPER_DRAWS here, each other in a fork."""
    from exucable.output import figure_process as fp

    if len(os.sched_getaffinity(0)) < 2:
        pytest.skip("one core: the figures are drawn here, one after the other")
    here = os.getpid()
    for name, draw in list(fp._DRAW.items()):
        def noting_the_process(path, result, frame=None, draw=draw):
            draw(path, result, frame=frame)
            Path(f"{path}.pid").write_text(str(os.getpid()))
        monkeypatch.setitem(fp._DRAW, name, noting_the_process)
    cpu = {}
    paths = fp.draw_in_parallel(tmp_path, _result(), cpu)
    pids = {p.name: int(Path(f"{p}.pid").read_text()) for p in paths}
    assert len(pids) == 3 and len(set(pids.values())) == 3, pids
    assert pids[fp.HELPER_DRAWS] == here
    assert 0 < cpu["longest_fork_draw_s"] <= cpu["forks_draw_s"]


@needs_fork
def test_a_failing_drawing_process_costs_no_figure(tmp_path, monkeypatch):
    from exucable.output import figure_process as fp

    here, draw = os.getpid(), fp._DRAW["pull_force.png"]

    def fails_in_the_fork(path, result, frame=None):
        if os.getpid() != here:
            raise RuntimeError("drawing failed")
        draw(path, result, frame=frame)

    monkeypatch.setitem(fp._DRAW, "pull_force.png", fails_in_the_fork)
    paths = fp.draw_in_parallel(tmp_path, _result())
    assert all(p.stat().st_size > 1000 for p in paths) and "pull_force.png" in {p.name for p in paths}


@needs_fork
def test_a_helper_given_nothing_is_killed_at_once():
    """Bad input or a failed run is not held up by the helper's import of matplotlib."""
    with Figures(helper=True) as figures:
        proc = figures._proc
    assert proc.exitcode is not None and proc.exitcode != 0


@needs_fork
def _helper_used_by(call: str, tmp_path) -> subprocess.CompletedProcess:
    """Run ``call`` (Python source drawing a coarse run's figures into ``tmp_path``) in a fresh
    process that prints whether the figures' helper was running when the figures were written."""
    script = textwrap.dedent("""
        from exucable.output import figure_process as fp
        write = fp.Figures.write
        def spy(self, *a, **k):
            print("helper", self.helper_running, repr(self.helper_reason))
            return write(self, *a, **k)
        fp.Figures.write = spy
    """) + call
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300,
                       env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert "helper True ''" in p.stdout, p.stdout + p.stderr
    assert {"pull_force.png", "tension_profile.png", "pressure.png"} <= {f.name for f in tmp_path.iterdir()}
    return p


def test_exucable_run_draws_its_figures_in_the_helper(tmp_path):
    """The command forks the helper before anything loads Exudyn, so that the helper is used: a check
    before the solve that imports Exudyn must not silently keep it out. Coarse Example 2, steady mode."""
    p = _helper_used_by("from exucable.cli import main\n"
                        f"raise SystemExit(main(['run', 'fast/paper_ex2_bend90', '-q', '--mode', 'steady', "
                        f"'-o', r'{tmp_path}']))\n", tmp_path)
    assert p.returncode in (0, 1), p.stderr


def test_run_scenario_from_python_draws_its_figures_in_the_helper(tmp_path):
    """The Python entry point forks the helper before its pre-run checks import Exudyn, as the command
    does: a script calling ``run_scenario`` once gets its figures drawn beside the solve."""
    p = _helper_used_by("from exucable.run import run_scenario\n"
                        f"run_scenario('fast/paper_ex2_bend90', r'{tmp_path}', mode='steady')\n", tmp_path)
    assert p.returncode == 0, p.stderr


def test_a_long_title_is_wrapped_and_not_clipped():
    """The fixed layout: a title up to the overhang widens the margins; a longer one is wrapped, each
    line within the axes' width plus the overhang; the subplot area keeps its size [in]."""
    from exucable.plots.results import TITLE_OVERHANG_IN, _text_width_in, framed_figure

    fig, title = framed_figure((5.0, 3.0), "short: tension along the cable", 12)
    assert "\n" not in title
    w, h = fig.get_size_inches()
    sp = fig.subplotpars
    assert (sp.right - sp.left) * w == pytest.approx(5.0) and (sp.top - sp.bottom) * h == pytest.approx(3.0)
    long = "a-very-long-scenario-name-" * 6 + ": sidewall pressure (bends shaded; point loads at bend ends)"
    fig, title = framed_figure((5.0, 3.0), long, 12)
    lines = title.split("\n")
    assert len(lines) >= 2 and " ".join(lines).replace(" ", "") == long.replace(" ", "")
    assert all(_text_width_in(line, 12) <= 5.0 + TITLE_OVERHANG_IN for line in lines)
    w, _ = fig.get_size_inches()
    assert w >= max(_text_width_in(line, 12) for line in lines)          # within the figure
    unbroken = "a_name_with_no_spaces_or_hyphens_" * 5 + ": tension along the cable"
    lines = framed_figure((5.0, 3.0), unbroken, 12)[1].split("\n")
    assert 2 <= len(lines) <= 4 and all(_text_width_in(line, 12) <= 5.0 + TITLE_OVERHANG_IN for line in lines)


def test_a_dense_scatter_keeps_one_point_per_occupied_half_pixel():
    """Beyond `most` points, every half-pixel cell that had a point keeps exactly one of them (the
    figure lights the same pixels); up to `most`, the points are drawn as they are."""
    from exucable.plots.results import thinned_scatter

    rng = np.random.default_rng(1)
    x, y = np.sort(rng.uniform(0.0, 1e4, 200_000)), rng.normal(300.0, 5.0, 200_000)
    y[:10] = [-5.0, 900.0, np.nan, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]     # outside the y-range, not finite
    same = thinned_scatter(x[:1000], y[:1000], (0.0, 480.0), (744, 370), most=1000)
    assert np.array_equal(same[0], x[:1000]) and np.array_equal(same[1], y[:1000], equal_nan=True)
    tx, ty = thinned_scatter(x, y, (0.0, 480.0), (744, 370), most=1000)
    assert 1000 < tx.size < 0.5 * x.size and np.isin(tx, x).all()

    def cells(a, b):
        ok = np.isfinite(a) & np.isfinite(b)
        i = np.floor((a[ok] - x.min()) / (x.max() - x.min()) * 1488)
        j = np.clip(np.floor(b[ok] / 480.0 * 740), -1, 740)
        return set(zip(i.tolist(), j.tolist()))

    assert cells(tx, ty) == cells(x, y) and len(cells(tx, ty)) == tx.size


@pytest.mark.parametrize("ticks", [0, 2, 11, 30])
def test_a_figure_drawn_on_a_frame_built_ahead_is_the_same_file(tmp_path, ticks):
    """The helper builds each figure's frame (figure, axes, ticks) before the results exist; drawn on
    it, each file is byte for byte the one drawn on a new figure, whether fewer, as many or more
    ticks were made ahead than the axes draw (11: the most these figures draw)."""
    from exucable.output import figure_process as fp

    new = fp.draw_figures(tmp_path / "new", _result())
    frames = fp.build_frames(ticks)
    framed = fp.draw_figures(tmp_path / "framed", _result(), frames=frames)
    assert frames == {}                                      # each frame drawn on once
    assert [p.name for p in framed] == [p.name for p in new]
    for p in new:
        assert (tmp_path / "framed" / p.name).read_bytes() == p.read_bytes(), p.name


def test_the_figures_fast_png_encoding_keeps_every_pixel(tmp_path):
    """The figures are written at zlib level 1: decoded, the pixels are exactly those of Pillow's
    default encoding (PNG is lossless; this checks nothing else changed), and a file is at most a
    quarter larger (measured: 6-13 %)."""
    from matplotlib.image import imread

    from exucable.io import save_figure
    from exucable.plots import results as plots

    for name, figure in (("pull_force", plots.pull_force_figure), ("tension", plots.tension_profile_figure),
                         ("pressure", plots.pressure_figure)):
        fig = figure(_result())
        fast = save_figure(fig, tmp_path / f"{name}_fast.png", dpi=plots.SAVE_DPI, **plots.PNG_KWARGS)
        default = save_figure(fig, tmp_path / f"{name}_default.png", dpi=plots.SAVE_DPI)
        a, b = imread(fast), imread(default)
        assert a.shape == b.shape and np.array_equal(a, b), name
        assert default.stat().st_size < fast.stat().st_size <= 1.25 * default.stat().st_size, name


def test_frames_stop_being_built_once_the_results_arrive(tmp_path):
    """The helper builds frames only while it waits: once results are there, the figures left without
    a frame are drawn on new figures (the same files)."""
    from exucable.output import figure_process as fp

    arrived = iter([False, True, True])
    frames = fp.build_frames(until=lambda: next(arrived))
    assert list(frames) == ["pull_force.png"]
    new = fp.draw_figures(tmp_path / "new", _result())
    fp.draw_figures(tmp_path / "framed", _result(), frames=frames)
    for p in new:
        assert (tmp_path / "framed" / p.name).read_bytes() == p.read_bytes(), p.name
