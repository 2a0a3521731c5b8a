"""Ahead-of-time compiled kernels (issue 15, fixed cost): the same numbers as numba's JIT, bit for
bit; a run that loads them imports no numba; a stale, missing, unloadable or unwritable module
falls back to the JIT path.

The module is built once per session (fixture ``aot_module`` in conftest.py) if ``python3 dev.py``
(or ``exucable compile``) has not built it yet; without a C compiler the tests that need it are
skipped. That a run with it imports no numba: tests/test_fixed_cost.py.
"""

from __future__ import annotations

import shutil
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from exucable.contact import ContactKernel, ContactLaw, aot, aot_build
from exucable.contact.jitcache import Kernel
from exucable.contact.nearest import NearestSample
from exucable.contact.steady import SteadySlidingKernel
from exucable.geometry import Bend, Conduit, Straight, centreline_from_path

R_CABLE, R_CONDUIT = 0.0025, 0.0035
LAW = ContactLaw(stiffness=1e6, damping=1e3, exponent=1.5, friction=0.3, static_friction=0.4,
                 stribeck_velocity_m_per_s=0.2, damping_onset_m=1e-4)


@pytest.fixture
def mode(monkeypatch):
    """``mode("jit")`` / ``mode("aot")``: route every kernel call to one path. In "aot" mode the JIT
    dispatcher raises, so a result proves the compiled module served every call."""
    def select(name):
        aot.reset()
        if name == "jit":
            monkeypatch.setenv(aot.MODE_VARIABLE, "jit")
            monkeypatch.setattr(Kernel, "dispatcher", _ORIGINAL_DISPATCHER)
        else:
            monkeypatch.delenv(aot.MODE_VARIABLE, raising=False)
            monkeypatch.setattr(Kernel, "dispatcher", property(_no_jit))
    yield select
    aot.reset()


_ORIGINAL_DISPATCHER = Kernel.dispatcher


def _no_jit(kernel):
    raise AssertionError(f"{kernel.name} went to the JIT dispatcher")


def bend_conduit():
    c = centreline_from_path([0, 0, 0], [1, 0, 0],
                             [Straight(0.3), Bend(90, 0.5, "left"), Bend(45, 0.6, "up"), Straight(0.3)])
    return Conduit.build(R_CONDUIT, c, segments_per_bend=12)


def cable(cond, seed):
    """Five nodes near the inner wall of the bends, the last two on the axis (out of contact)."""
    rng = np.random.default_rng(seed)
    c = cond.centreline
    s = np.linspace(0.35, 0.95, 5)
    u = c.curvature_vector(s)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    pos = c.point(s) + (R_CONDUIT - R_CABLE + 3e-4) * u
    pos[3:] = c.point(s[3:])
    slope = 1.002 * c.tangent(s) + rng.normal(scale=2e-3, size=(5, 3))
    q = np.hstack([pos, slope]).reshape(-1)
    return q, np.diff(s), rng.normal(scale=0.05, size=q.size)


def everything(cond, q, length, q_t):
    """Every kernel a run calls, on both walls and both modes: results as a flat list of arrays."""
    out = []
    for surface in ("segments", "smooth"):
        dyn = ContactKernel(cond.segments, length, R_CABLE, LAW, 7, backend="numba", surface=surface,
                            centreline=cond.centreline)
        search = dyn.point_segments(q)                     # before points(), which it would reuse
        r = dyn.evaluate(q, q_t, jacobian=True)
        held = dyn.evaluate(q, q_t, jacobian=True, held_onset=np.full((4, 7), 0.5))
        p = dyn.points(q, q_t)
        steady = SteadySlidingKernel(cond.segments, length, R_CABLE, LAW, 7, backend="numba", surface=surface,
                                     centreline=cond.centreline, speed_m_per_s=0.1)
        s = steady.evaluate(q, q_t, jacobian=True)
        sp = steady.points(q, q_t)
        out += [r.generalized_force, r.jac_q_blocks, r.jac_qt_blocks, held.generalized_force, held.jac_qt_blocks,
                s.generalized_force, s.jac_q_blocks, p.segment, p.normal_force_N, p.friction_force_N,
                p.position_m, sp.normal_force_N, sp.friction_force_N, search]
    out.append(NearestSample(cond.centreline.point(np.linspace(0.0, 1.4, 200)))(q.reshape(-1, 6)[:, :3]))
    return out


def test_compiled_kernels_equal_the_jit_kernels_bit_for_bit(aot_module, mode):
    cond = bend_conduit()
    q, length, q_t = cable(cond, 4)
    mode("aot")
    ahead = everything(cond, q, length, q_t)
    mode("jit")
    jit = everything(cond, q, length, q_t)
    assert np.count_nonzero(ahead[0]) > 0                      # there is contact to compare
    for k, (a, b) in enumerate(zip(ahead, jit)):
        assert a.dtype == b.dtype and np.array_equal(a, b, equal_nan=True), k
    # and the table of argument types is complete: the JIT path compiled no other signature
    from numba.core import types
    for name, tokens in aot.KERNELS.items():
        module, function = name.split(".")
        kernel = getattr(sys.modules[f"exucable.contact.{module}"], function)
        assert kernel.dispatcher.signatures == [aot_build.numba_argtypes(tokens, types)], name


def test_other_argument_types_go_to_the_jit_path(aot_module, mode):
    mode("aot")
    compiled = aot.exported("nearest._nearest")
    points, samples = np.zeros((2, 3)), np.ones((4, 3))
    start, centre, radius, out = np.array([0, 4]), np.array([1]), np.zeros(1), np.empty(2, dtype=np.int64)
    assert compiled.accepts((points, samples, start, centre, radius, out))
    for bad in (points.T, points.astype(np.float32), points[:, :2], points.reshape(-1), list(points)):
        assert not compiled.accepts((bad, samples, start, centre, radius, out))
    assert not compiled.accepts((points, samples, start, centre, 1, out))
    frozen = samples.copy()
    frozen.flags.writeable = False
    assert not compiled.accepts((points, frozen, start, centre, radius, out))


def test_the_key_follows_the_kernel_sources(tmp_path):
    copy = tmp_path / "contact"
    shutil.copytree(Path(aot.__file__).parent, copy, ignore=shutil.ignore_patterns("__pycache__"))
    assert aot.key(copy) == aot.key()
    fast = copy / "fast.py"
    fast.write_text(fast.read_text().replace('"reassoc"}', '"reassoc", "afn"}', 1))
    assert aot.key(copy) != aot.key()


def test_a_stale_module_is_not_used(aot_module, mode, monkeypatch):
    mode("aot")
    assert aot.exported("fast._contact_kernel") is not None
    monkeypatch.setattr(aot, "key", lambda sources=None: "0" * 24)   # the sources changed since the build
    aot.reset()
    assert aot.find() is None and aot.exported("fast._contact_kernel") is None


def test_an_unloadable_module_warns_once_and_is_not_used(monkeypatch, tmp_path):
    import numba  # noqa: F401  (numba reads NUMBA_CACHE_DIR once, at import: keep it away from tmp_path)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv(aot.MODE_VARIABLE, raising=False)
    (tmp_path / "exucable").mkdir()
    (tmp_path / "exucable" / aot.filename(aot.key())).write_bytes(b"not a shared object")
    aot.reset()
    try:
        with pytest.warns(RuntimeWarning, match="cannot be loaded"):
            assert aot.exported("fast._contact_kernel") is None
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert aot.exported("fast._search_kernel") is None
    finally:
        aot.reset()


def test_without_a_writable_directory_compile_fails_clearly_and_runs_use_the_jit_path(monkeypatch, tmp_path):
    """Every place under a regular file: nothing can be written (a read-only install, as root can
    not make one here). Building fails with a message naming NUMBA_CACHE_DIR; kernels use the JIT."""
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setattr(aot, "directories", lambda: [blocker / "a", blocker / "b"])
    monkeypatch.delenv(aot.MODE_VARIABLE, raising=False)
    aot.reset()
    try:
        with pytest.raises(aot_build.CompilerUnavailable, match="NUMBA_CACHE_DIR"):
            aot_build.build()
        assert aot.find() is None and aot.exported("nearest._nearest") is None
        assert NearestSample(np.eye(3))(np.array([[0.9, 0.0, 0.1]]))[0] == 0
    finally:
        aot.reset()


def test_the_compile_command_says_whether_the_module_is_up_to_date(aot_module, monkeypatch, capsys):
    from exucable.cli import main

    assert main(["compile", "--check"]) == 0
    assert str(aot_module) in capsys.readouterr().out
    monkeypatch.setattr(aot, "key", lambda sources=None: "0" * 24)       # as after an edit of a kernel
    assert main(["compile", "--check"]) == 1
    assert "exucable compile" in capsys.readouterr().out
    aot.reset()


def test_jit_machine_code_that_inlined_changed_sources_is_compiled_again(tmp_path, monkeypatch):
    """Numba's disk cache keys a function on its own file only: machine code that inlined another
    file's helper would load unchanged after that helper changed. A marker of the kernel sources'
    hash beside the cache empties the index when the sources changed (a cache hit only while they
    have not)."""
    import importlib.util

    from numba import njit as numba_njit
    from numba.core.types import float64

    from exucable.contact import jitcache
    from exucable.contact.jitcache import forget_stale_machine_code

    source = tmp_path / "tiny_kernel.py"
    source.write_text("def twice(x):\n    return 2.0 * x\n")
    spec = importlib.util.spec_from_file_location("tiny_kernel", source)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)

    def fresh_dispatcher():
        d = numba_njit(cache=True)(module.twice)
        assert d(1.5) == 3.0
        return d

    first = fresh_dispatcher()                       # compiled and saved; no marker yet
    assert forget_stale_machine_code(first, "tiny.twice")          # so it is taken as stale
    assert fresh_dispatcher().stats.cache_hits.get((float64,), 0) == 0
    assert not forget_stale_machine_code(fresh_dispatcher(), "tiny.twice")   # marker current: kept
    assert fresh_dispatcher().stats.cache_hits.get((float64,), 0) == 1
    monkeypatch.setattr(jitcache, "sources_key", lambda: "other sources")    # a helper file changed
    assert forget_stale_machine_code(fresh_dispatcher(), "tiny.twice")
    assert fresh_dispatcher().stats.cache_hits.get((float64,), 0) == 0


@pytest.mark.parametrize("forced", [False, True])
def test_a_run_on_jit_kernels_says_how_to_build_the_compiled_ones(tmp_path, monkeypatch, capsys, forced):
    """`exucable run` without an ahead-of-time module (numba's start-up paid) says so and names
    `exucable compile`; not when the JIT kernels were asked for (EXUCABLE_KERNELS=jit)."""
    import numba  # noqa: F401 - the JIT path has imported it in such a run

    from exucable.cli import main as cli_main

    monkeypatch.setattr(aot, "find", lambda: None)
    if forced:
        monkeypatch.setenv(aot.MODE_VARIABLE, "jit")
    else:
        monkeypatch.delenv(aot.MODE_VARIABLE, raising=False)
    aot.reset()
    try:
        toml = Path(__file__).parent / "data" / "sweep" / "tiny_bend.toml"
        assert cli_main(["run", str(toml), "--out", str(tmp_path / "out"), "--no-plots"]) == 0
    finally:
        aot.reset()
    assert ("`exucable compile`" in capsys.readouterr().out) is not forced
