"""What `exucable run` loads (issue 15, fixed cost): a run of a route of straights and horizontal
bends imports no scipy subpackage but scipy.linalg (which numba loads for its BLAS anyway), with
plots=False neither matplotlib nor dask, and with the ahead-of-time kernels no numba. Checked in a fresh interpreter, by module name, not by time."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
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


def test_a_run_with_the_compiled_kernels_imports_no_numba(aot_module, tmp_path):
    """With the ahead-of-time kernels (tests/test_aot.py) a run never imports numba; forced to the
    JIT kernels it does (so the first check can fail)."""
    assert not modules_after_a_trivial_run(tmp_path / "aot", EXUCABLE_KERNELS=None) & {"numba", "llvmlite"}
    assert "numba" in modules_after_a_trivial_run(tmp_path / "jit", EXUCABLE_KERNELS="jit")
