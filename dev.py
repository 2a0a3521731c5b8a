#!/usr/bin/env python3
"""exucable's quick start, for a fresh machine with only python3 on it.

    python3 dev.py main     # install (first time), then run the main job: validate the paper's examples
    python3 dev.py test     # install (first time), then run the whole test suite

Each command creates ./.venv and installs exucable with its test extras into it when needed
(again only when pyproject.toml changes), so both are idempotent. Extra arguments are passed on
(``python3 dev.py test -m slow``). Both also compile the contact kernels ahead of time when the
sources changed (``exucable compile``: about half a minute, a minute on a fresh machine where numba
compiles them first), so that runs skip numba's start-up; without a C compiler, runs use numba's
JIT kernels and this only prints why. The main job validates the paper's examples at the paper's
fidelity (about 90 s); ``python3 dev.py main --fast`` runs the coarse variants (about 15 s).
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parent
VENV = ROOT / ".venv"
BIN = VENV / ("Scripts" if os.name == "nt" else "bin")
PY = BIN / ("python.exe" if os.name == "nt" else "python")
STAMP = VENV / ".exucable-install-stamp"


def ensure_environment() -> None:
    digest = hashlib.sha256((ROOT / "pyproject.toml").read_bytes()).hexdigest()
    if PY.exists() and STAMP.exists() and STAMP.read_text().strip() == digest:
        return
    if not PY.exists():
        print(f"dev.py: creating {VENV}", flush=True)
        venv.create(VENV, with_pip=True)
    print("dev.py: installing exucable and its dependencies into .venv", flush=True)
    subprocess.check_call([str(PY), "-m", "pip", "install", "--quiet", "--upgrade", "pip"])
    subprocess.check_call([str(PY), "-m", "pip", "install", "--quiet", "-e", f"{ROOT}[test,dask]"])
    STAMP.write_text(digest + "\n")


def ensure_compiled_kernels() -> None:
    """Build the ahead-of-time kernels if they are missing or stale; a failure is not fatal."""
    if subprocess.call([str(PY), "-m", "exucable", "compile", "--quiet"], cwd=ROOT) != 0:
        print("dev.py: continuing without the compiled kernels (runs use numba's JIT kernels)", flush=True)


def main(argv: list[str]) -> int:
    if not argv or argv[0] not in ("main", "test"):
        print(__doc__)
        return 2
    ensure_environment()
    ensure_compiled_kernels()
    cmd, rest = argv[0], argv[1:]
    if cmd == "test":
        return subprocess.call([str(PY), "-m", "pytest", *rest], cwd=ROOT)
    # the main job validates both solver modes and tables their difference (README, "Two solver modes")
    return subprocess.call([str(PY), "-m", "exucable", "validate", *rest], cwd=ROOT)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
