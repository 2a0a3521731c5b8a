"""What `exucable run` loads (issue 15, fixed cost): a run of a route of straights and horizontal
bends imports no scipy subpackage but scipy.linalg (which numba loads for its BLAS anyway), and with
plots=False neither matplotlib nor dask. Checked in a fresh interpreter, by module name, not by time."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import textwrap

import numpy as np
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def modules_after_a_trivial_run(tmp_path, **environment) -> set[str]:
    """Top-level modules and scipy's subpackages loaded by a fresh interpreter that ran the fast
    Example 2 over one 1 ms step (``environment``: variables to set, None to remove)."""
    text = (ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml").read_text()
    text = re.sub(r"(?m)^end_time = .*$", "end_time = 0.001", text)
    text = re.sub(r"(?m)^step = .*$", "step = 1.0e-3", text)
    tmp_path.mkdir(parents=True, exist_ok=True)
    scenario = tmp_path / "trivial.toml"
    scenario.write_text(text)
    code = (f"import sys, json\nfrom exucable.run import run_scenario\n"
            f"run_scenario({str(scenario)!r}, {str(tmp_path / 'out')!r}, plots=False)\n"
            "print(json.dumps(sorted(m for m in sys.modules if '.' not in m or m.startswith('scipy.'))))")
    env = dict(os.environ)
    for name, value in environment.items():
        if value is None:
            env.pop(name, None)
        else:
            env[name] = value
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=600,
                         env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    assert (tmp_path / "out" / "summary.json").exists()
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


def test_a_run_of_a_planar_route_imports_only_what_it_uses(tmp_path):
    modules = modules_after_a_trivial_run(tmp_path)
    scipy_parts = {m.split(".")[1] for m in modules if m.startswith("scipy.") and not m.split(".")[1].startswith("_")}
    assert scipy_parts <= {"linalg", "version"}, scipy_parts
    assert not modules & {"matplotlib", "dask", "distributed"}, modules & {"matplotlib", "dask", "distributed"}


def test_the_rope_of_a_route_with_tilted_bends_imports_no_ode_integrator():
    """Bends out of the horizontal with weight (every long route with slopes) are integrated by
    Chebyshev collocation with numpy, not scipy.integrate, whose import (with scipy.optimize and
    scipy.special) is 0.2-0.5 s of a run; solve_ivp stays for pieces where the tension reaches zero."""
    code = textwrap.dedent("""
        import json, sys
        from exucable.geometry import Bend, Straight, centreline_from_path
        from exucable.quasistatic.rope import solve_rope
        route = centreline_from_path([0, 0, 0], [0.98, 0, 0.2], [Straight(50.0), Bend(15.0, 10.0, turn="up"),
                                     Straight(50.0), Bend(15.0, 10.0, turn="left"), Straight(50.0)])
        solve_rope(route, 0.2, 14.7, 500.0)
        print(json.dumps(sorted(m for m in sys.modules if m.startswith("scipy."))))
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    loaded = {m.split(".")[1] for m in json.loads(out.stdout.strip().splitlines()[-1])}
    assert not loaded & {"integrate", "optimize", "special"}, loaded


def test_a_kernel_says_whether_numba_has_it_cached(tmp_path):
    """``Kernel.is_cached`` (behind the first-run announcement and ``exucable compile --check``): False
    in an empty cache, True once a call compiled it there, and False again after a source changed."""
    code = textwrap.dedent("""
        import numpy as np
        from exucable.contact import jitcache, nearest
        k = nearest._nearest
        before = k.is_cached()
        nearest.NearestSample(np.random.default_rng(0).random((50, 3)))(np.zeros((2, 3)))
        after = k.is_cached()
        jitcache.sources_key = lambda sources=None: "changed"     # as after an edit of a kernel's source
        k._dispatcher = None
        print(before, after, k.is_cached())
    """)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300, env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["False", "True", "False"]


def test_the_compile_warm_up_runs_a_bundle_so_the_cable_cable_kernel_is_compiled_ahead():
    """``exucable compile`` runs a tiny three-cable case after the one-cable ones: the cable–cable
    kernel runs only with several cables, and a first bundle run would otherwise compile it inside
    its own time budget. The case must solve and carry its contact between cables; its weight
    correction lies between 1 (no contact between cables) and the rigid triangle's 1/√(1 − (d/(D−d))²)
    (D/d 3.33 here: 1.107; a 2 m straight measures less, its ends included), to 2 %."""
    from exucable.commands.compile import _tiny_bundle
    from exucable.run import run_scenario

    summary = run_scenario(_tiny_bundle(), plots=False).summary
    assert summary["status"] == "ok", summary["message"]
    bundle = summary["bundle"]
    assert bundle["count"] == 3
    d, D = 2 * 0.015, 2 * 0.05
    rigid = 1.0 / np.sqrt(1.0 - (d / (D - d)) ** 2)
    assert 1.0 < bundle["weight_correction_factor"] < rigid * 1.02


def _blas_threads() -> list[int]:
    from threadpoolctl import threadpool_info

    return [pool["num_threads"] for pool in threadpool_info() if pool["user_api"] == "blas"]


def test_a_run_solves_on_one_blas_thread_and_gives_the_former_limit_back(monkeypatch):
    """OpenBLAS's threads cost a 10 km run ~20 % of its CPU (exucable.run.one_blas_thread): the
    solve must see one thread, and the caller's own limit must be back afterwards."""
    import importlib

    from exucable.scenario.specs import load_scenario

    run_module = importlib.import_module("exucable.run")   # the package's ``run`` is the API function

    seen = []

    def fake_solve(*args):
        seen.append(_blas_threads())
        return "solved"

    monkeypatch.setattr(run_module, "_solve", fake_solve)
    before = _blas_threads()
    sc = load_scenario(Path(__file__).resolve().parents[1] / "scenarios" / "fast" / "paper_ex2_bend90.toml")
    assert run_module.run_scenario(sc) == "solved"
    assert seen and seen[0] and all(n == 1 for n in seen[0])
    assert _blas_threads() == before
