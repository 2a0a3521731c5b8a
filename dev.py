#!/usr/bin/env python3
"""exucable's quick start, for a fresh machine with only python3 on it.

    python3 dev.py main     # install (first time), then run the main job: validate the paper's examples
    python3 dev.py test     # install (first time), then run the whole test suite

Each command creates ./.venv and installs exucable with its test extras into it when needed
(again only when pyproject.toml changes), so both are idempotent. Extra arguments are passed on
(``python3 dev.py test -m slow``). Both also compile the contact kernels into numba's cache when the
sources changed (``exucable compile``: about a minute on a fresh machine, a few on a busy one), so that no test or run pays it. The main job validates the paper's examples at the paper's
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
    """Compile the contact kernels into numba's cache if they are not; a failure is not fatal (the
    first run that needs them compiles them)."""
    if subprocess.call([str(PY), "-m", "exucable", "compile", "--quiet"], cwd=ROOT) != 0:
        print("dev.py: continuing; the first run that needs the contact kernels compiles them", flush=True)


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
