"""What `exucable run` loads (issue 15, fixed cost): a run of a route of straights and horizontal
bends imports no scipy subpackage but scipy.linalg (which numba loads for its BLAS anyway), and with
plots=False neither matplotlib nor dask. Checked in a fresh interpreter, by module name, not by time."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_a_run_of_a_planar_route_imports_only_what_it_uses(tmp_path):
    text = (ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml").read_text()
    text = re.sub(r"(?m)^end_time = .*$", "end_time = 0.001", text)
    text = re.sub(r"(?m)^step = .*$", "step = 1.0e-3", text)
    scenario = tmp_path / "trivial.toml"
    scenario.write_text(text)
    code = (f"import sys, json\nfrom exucable.run import run_scenario\n"
            f"run_scenario({str(scenario)!r}, {str(tmp_path / 'out')!r}, plots=False)\n"
            "print(json.dumps(sorted(m for m in sys.modules if '.' not in m or m.startswith('scipy.'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    modules = set(json.loads(out.stdout.strip().splitlines()[-1]))
    scipy_parts = {m.split(".")[1] for m in modules if m.startswith("scipy.") and not m.split(".")[1].startswith("_")}
    assert scipy_parts <= {"linalg", "version"}, scipy_parts
    assert not modules & {"matplotlib", "dask", "distributed"}, modules & {"matplotlib", "dask", "distributed"}
    assert (tmp_path / "out" / "summary.json").exists()
