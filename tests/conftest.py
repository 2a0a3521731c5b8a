"""Shared helpers for the tests: scenarios built from dicts (the TOML contract), the ahead-of-time
kernel module."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest

from exucable.scenario.specs import parse_scenario

ROOT = Path(__file__).resolve().parents[1]

PAPER_CABLE = {"radius": 0.0025, "density": 1000.0, "youngs_modulus": 1.0e9}


def make_scenario(**tables):
    """A scenario from TOML-like tables; unspecified tables get small, valid defaults."""
    data = {
        "name": tables.pop("name", "test"),
        "cable": dict(PAPER_CABLE, elements=10),
        "conduit": {"inner_radius": 0.0035, "path": [{"straight": 1.0}]},
        "pull": {"speed": 0.1},
        "solver": {"mode": "dynamic", "end_time": 0.2, "step": 0.01},
    }
    for k, v in tables.items():
        if isinstance(v, dict) and isinstance(data.get(k), dict):
            d = copy.deepcopy(data[k])
            d.update(v)
            data[k] = d
        else:
            data[k] = v
    return parse_scenario(data, ROOT, default_name="test")


@pytest.fixture
def scenario_factory():
    return make_scenario


@pytest.fixture(scope="session")
def aot_module():
    """The valid ahead-of-time kernel module for this checkout and machine (tests/test_aot.py), built
    here if ``python3 dev.py`` or ``exucable compile`` has not built it (about 10-40 s)."""
    from exucable.contact import aot, aot_build

    path = aot.find()
    if path is None:
        try:
            path, _ = aot_build.build()
        except aot_build.CompilerUnavailable as exc:     # a kernel that does not compile fails the test
            pytest.skip(f"cannot build the ahead-of-time kernels: {exc}")
    aot.reset()
    return path
