"""Shared helpers for the tests: scenarios built from dicts (the TOML contract), and the test tiers.

Tiers: ``python3 dev.py test`` runs everything but ``slow`` (full-fidelity runs); ``-m quick`` the
quick tier for the edit–test loop: every test outside :data:`HEAVY_MODULES`, the modules whose tests
run whole simulations, sweeps, installs or subprocesses (measured with ``pytest --durations=0``)."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest

from exucable.scenario.specs import parse_scenario

ROOT = Path(__file__).resolve().parents[1]

# test modules left out of the quick tier: each runs whole simulations, sweeps, an install or numba in
# fresh processes, and took 15 s or more of a full run (pytest --durations=0)
HEAVY_MODULES = frozenset({
    "test_api", "test_beam_conduit", "test_benchmarks", "test_bundle_bends", "test_bundle_upbend", "test_bundle_dynamic", "test_bundle_jam",
    "test_examples", "test_fixed_cost", "test_installed", "test_plan_multibody",
    "test_run", "test_steady_start", "test_stiff_bend", "test_sweep", "test_validate",
})


def pytest_collection_modifyitems(config, items):
    quick = pytest.mark.quick
    for item in items:
        if item.get_closest_marker("slow") is None and Path(str(item.fspath)).stem not in HEAVY_MODULES:
            item.add_marker(quick)


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
