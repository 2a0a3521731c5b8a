"""Shared helpers for the tests: scenarios built from dicts (the TOML contract), and the test tiers.

Tiers: ``python3 dev.py test`` runs everything but ``slow`` (full-fidelity runs); ``-m quick`` the
quick tier for the edit–test loop: every test outside :data:`HEAVY_MODULES`, the modules whose tests
run whole simulations, sweeps, installs or subprocesses (measured with ``pytest --durations=0``)."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
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


def upbend_bundle_scenario():
    """Three cables (triangular) through 2 m straight, a 30° up-bend of 5 m radius and 1 m straight, steady
    mode, 8 check points per element: a small bundle whose residual and stiffness tests compare with Exudyn's."""
    import exucable as xc

    route = xc.Route(inner_radius=0.05).straight(2.0).bend(30, radius=5.0, turn="up").straight(1.0)
    return xc.Scenario(route=route, cable=xc.Cable(radius=0.015, density=2000.0, youngs_modulus=2e8, count=3,
                                                   arrangement="triangular"),
                       contact=xc.Contact(friction=0.3, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=300.0), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", steady_lead_out=0.0))


def exudyn_static_residual_jacobian(model):
    """Exudyn's static solver's residual and Newton Jacobian at ``model``'s current state (one Newton
    setup, plain settings), on the cables' coordinates (``model.ode2_index``): (q, r, J), q the
    cables' displacement coordinates."""
    import exudyn as exu
    from exucable.solve import steady as st

    mbs = model.mbs
    idx = model.ode2_index
    q_all = np.array(mbs.systemData.GetODE2Coordinates())
    settings = st.static_settings(tolerance=1.0, max_iterations=1)
    s = exu.MainSolverStatic()
    s.InitializeSolver(mbs, settings)
    s.ComputeNewtonResidual(mbs, settings)
    r = np.array(s.GetSystemResidual())[:q_all.size][idx]
    s.ComputeNewtonJacobian(mbs, settings)
    return q_all[idx], r, np.asarray(s.GetSystemJacobian())[np.ix_(idx, idx)]
