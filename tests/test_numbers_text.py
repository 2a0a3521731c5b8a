"""The compiled CSV number formatter writes exactly Python's characters: ``repr(float)`` and ``str(int)``.

The reference is Python itself (David Gay's shortest round-trip ``dtoa`` behind ``repr``), not our
output: every string is compared with ``repr`` of the same double, on random bit patterns (every
exponent, subnormals and NaN payloads included), both ends and the neighbours of every binade, powers
of ten, integers, round decimals and the layout's edges (1e-4 / 1e-5, 1e16 / 1e17).
"""

from __future__ import annotations

import numpy as np
import pytest

from exucable.io import csv_text, repr_rows
from exucable.output.numbers_text import COMPILED_FROM_VALUES, csv_rows, rows_text


def _doubles(seed: int, n: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    random_bits = rng.integers(0, 2**64, n, dtype=np.uint64, endpoint=False).view(np.float64)
    binades = np.ldexp(1.0, np.arange(-1074, 1024))
    edges = np.concatenate([binades, np.nextafter(binades, 0.0), np.nextafter(binades, np.inf),
                            np.nextafter(binades, -np.inf) * -1.0])
    decimals = rng.standard_normal(n) * 10.0 ** rng.integers(-9, 9, n)
    special = np.array([0.0, -0.0, np.nan, -np.nan, np.inf, -np.inf, 5e-324, -5e-324, 2.2250738585072014e-308,
                        2.225073858507201e-308, 1.7976931348623157e308, 0.1, 0.2, 0.3, 1e-4, 1e-5, 9.999999999999999e-5,
                        1e15, 1e16, 1e17, 9999999999999998.0, 123456789012345678.0, 9007199254740993.0, 1e22, 1e23,
                        0.5, 100.0, 1234.5, 5e-5, 1.23e-5])
    return np.concatenate([random_bits, edges, decimals, np.round(decimals, 3), 10.0 ** np.arange(-30.0, 31.0),
                           rng.integers(-10**6, 10**6, 2000).astype(float), special, -special])


@pytest.mark.parametrize("seed", [0, 1])
def test_doubles_are_written_as_repr_writes_them(seed):
    a = _doubles(seed, 100_000)
    got = rows_text([a]).split("\n")
    assert got[-1] == ""
    want = list(map(repr, a.tolist()))
    bad = [(w, g) for w, g in zip(want, got[:-1]) if w != g]
    assert len(got) - 1 == len(a) and bad == []


def test_integers_and_mixed_rows_as_csv_text_writes_them():
    rng = np.random.default_rng(2)
    n = 5000
    ints = np.concatenate([rng.integers(-2**63, 2**63 - 1, n - 4, dtype=np.int64, endpoint=True),
                           np.array([0, -1, 2**63 - 1, -2**63], dtype=np.int64)])
    columns = [np.arange(n), rng.standard_normal(n), ints, rng.integers(0, 3, n).astype(np.int32), np.full(n, np.nan)]
    assert rows_text(columns) == repr_rows(columns)
    assert rows_text(columns).splitlines()[0] == ",".join(
        str(c[0]) if np.issubdtype(c.dtype, np.integer) else repr(float(c[0])) for c in columns)


def test_csv_rows_chooses_a_path_not_a_result():
    rng = np.random.default_rng(3)
    small = {"x_m": rng.standard_normal(10), "element": np.arange(10)}
    large = {"x_m": rng.standard_normal(COMPILED_FROM_VALUES), "tension_N": rng.standard_normal(COMPILED_FROM_VALUES)}
    for data in (small, large, {"x_m": np.zeros(0)}):
        assert csv_text(list(data), data, rows=csv_rows) == csv_text(list(data), data)
    assert rows_text([np.zeros(0)]) == "" == repr_rows([np.zeros(0)])
