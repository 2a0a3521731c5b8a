"""The numbers the README and examples/README.md print are what the code they show prints now
(docs/printed_numbers.py runs that code; `--write` refreshes the documents)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _printed_numbers():
    spec = importlib.util.spec_from_file_location("printed_numbers", ROOT / "docs" / "printed_numbers.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_printed_numbers_are_current():
    module = _printed_numbers()
    assert module.stale() == [], "run: .venv/bin/python docs/printed_numbers.py --write"


def test_a_stale_number_is_caught():
    module = _printed_numbers()
    assert module._same('# 205.37 N, 0.09 N, "ok"', '# 205.38 N, 0.09 N, "ok"')      # one unit of rounding
    assert not module._same('# 205.30 N, 0.18 N, "ok"', '# 205.37 N, 0.09 N, "ok"')
    assert not module._same("(−0.011 %)", "(+0.003 %)")
