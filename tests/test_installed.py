"""exucable installed from its wheel (not editable) runs ``exucable validate --fast`` from another
directory: the scenarios and reference values travel as package data, nothing reads the checkout.

The wheel is built from a copy of the sources; it goes into a fresh virtual environment that sees
the test environment's packages (numpy, Exudyn, ...) through a path entry, so nothing is downloaded
or compiled but exucable itself.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SOURCES = ("pyproject.toml", "README.md", "LICENSE", "exucable", "reference", "scenarios")


def _run(cmd, cwd, timeout=300):
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    p = subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert p.returncode == 0, f"{' '.join(map(str, cmd))} failed ({p.returncode}):\n{p.stdout}\n{p.stderr}"
    return p.stdout


def test_wheel_installed_elsewhere_validates(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    for name in SOURCES:
        path = ROOT / name
        if path.is_dir():
            shutil.copytree(path, src / name, symlinks=True, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(path, src / name)
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "--wheel-dir", tmp_path / "wheel", src],
         cwd=tmp_path)
    (wheel,) = (tmp_path / "wheel").glob("exucable-*.whl")

    env_dir = tmp_path / "env"
    venv.create(env_dir, with_pip=False)
    bin_dir = env_dir / ("Scripts" if os.name == "nt" else "bin")
    python = bin_dir / ("python.exe" if os.name == "nt" else "python")
    site = Path(_run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], cwd=tmp_path).strip())
    # the test environment's packages, as a plain path entry: its .pth files (our editable install's
    # finder among them) are not run, so `import exucable` can only find the wheel's copy
    (site / "test_environment.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    _run([sys.executable, "-m", "pip", "--python", python, "install", "--no-deps", "--no-index", "--quiet", wheel],
         cwd=tmp_path)

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    where = _run([python, "-c", "import exucable; print(exucable.__file__)"], cwd=elsewhere).strip()
    assert Path(where).resolve().is_relative_to(site.resolve()), where

    out = _run([bin_dir / "exucable", "validate", "--fast", "--quiet", "--out", "validation"], cwd=elsewhere,
               timeout=600)
    assert "checks passed" in out
    assert (elsewhere / "validation" / "validation.csv").is_file()
    assert (elsewhere / "validation" / "fig12_coils.png").is_file()
    assert not list(elsewhere.glob("*.toml")) and not (elsewhere / "scenarios").exists()
    # the README's commands, as written, from outside the repository: shipped scenarios by name or by
    # their scenarios/... path
    assert "industry/commscope_conquest_run_a_h" in _run([bin_dir / "exucable", "scenarios"], cwd=elsewhere)
    _run([bin_dir / "exucable", "route", "scenarios/paper_ex4_spatial.toml", "-o", "route.png"], cwd=elsewhere)
    _run([bin_dir / "exucable", "plan", "industry/commscope_conquest_run_a_h", "--out", "plan"], cwd=elsewhere)
    assert (elsewhere / "route.png").is_file() and (elsewhere / "plan" / "report.html").is_file()
