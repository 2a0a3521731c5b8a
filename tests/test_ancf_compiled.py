"""The compiled ANCF cable element (exucable/contact/ancf_cable.py) against Exudyn's ObjectANCFCable.

Exudyn's element is the reference: its residual and its system Jacobian at random deformed states
of a few elements (stretched, compressed, curved out of plane, unequal lengths), for every
``cable.integration``. Tolerances: 1e-10 relative to the largest entry — both sides evaluate the
same formula in double precision (Exudyn's Jacobian by automatic differentiation, ours by hand), so
only round-off separates them (measured ≤ 7e-15). The numpy reference and the compiled kernel
agree to 1e-13 (measured 2e-15); the Jacobian agrees with central differences of the force to 1e-6 (the step's
truncation and cancellation error, measured ~2e-9).
"""

from __future__ import annotations

import numpy as np
import pytest

exu = pytest.importorskip("exudyn")
from exudyn.itemInterface import NodePointSlope1, ObjectANCFCable  # noqa: E402

from exucable.contact.ancf_cable import (AncfCableForces, INTEGRATIONS, elastic_forces,  # noqa: E402
                                         elastic_forces_numpy)
from exucable.model.cable import INTEGRATION  # noqa: E402

EA, EJ = 2.0e5, 3.5


def _states(seed: int, n_el: int = 3):
    """Element lengths [m] and absolute nodal coordinates of a deformed cable: a helix-like curve
    with random stretch, slopes off the tangent and out of plane."""
    rng = np.random.default_rng(seed)
    L = 0.3 + rng.random(n_el)
    s = np.concatenate([[0.0], np.cumsum(L)])
    R = 1.5
    q = np.zeros((n_el + 1, 6))
    q[:, 0], q[:, 1], q[:, 2] = R * np.sin(s / R), R * (1 - np.cos(s / R)), 0.1 * s
    q[:, 3], q[:, 4], q[:, 5] = np.cos(s / R), np.sin(s / R), 0.1
    q[:, 3:] *= (1.0 + 0.05 * rng.standard_normal(n_el + 1))[:, None]     # stretch and compression
    q += 0.03 * rng.standard_normal(q.shape)
    return L, q


def _exudyn_lhs_and_jacobian(L, q, integration):
    """Exudyn's elastic LHS (minus its ODE2 right-hand side) and its dense ∂LHS/∂q at state q."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    nodes = [mbs.AddNode(NodePointSlope1(referenceCoordinates=list(c))) for c in q]
    for i, length in enumerate(L):
        mbs.AddObject(ObjectANCFCable(nodeNumbers=[nodes[i], nodes[i + 1]], length=float(length), massPerLength=1.0,
                                      axialStiffness=EA, bendingStiffness=EJ,
                                      useReducedOrderIntegration=INTEGRATION[integration]))
    mbs.Assemble()
    s = exu.SimulationSettings()
    s.solution.file.write = False   # no solution/ file in the working directory
    s.linearSolver.solverType = exu.LinearSolverType.EXUdense
    s.staticSolver.verboseMode = 0
    solver = exu.MainSolverStatic()
    solver.InitializeSolver(mbs, s)
    solver.ComputeODE2RHS(mbs)
    rhs = np.array(solver.GetSystemResidual())
    solver.ComputeJacobianODE2RHS(mbs, 1.0, 0.0, 1.0)
    jac_rhs = np.array(solver.GetSystemJacobian())
    return -rhs, -jac_rhs


def _assemble(blocks):
    n_el = blocks.shape[0]
    K = np.zeros((6 * (n_el + 1), 6 * (n_el + 1)))
    for e in range(n_el):
        K[6 * e:6 * e + 12, 6 * e:6 * e + 12] += blocks[e]
    return K


def _rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.mark.parametrize("integration", INTEGRATIONS)
@pytest.mark.parametrize("seed", [0, 1])
def test_compiled_element_equals_exudyns(integration, seed):
    L, q = _states(seed)
    lhs_exu, jac_exu = _exudyn_lhs_and_jacobian(L, q, integration)
    lhs, blocks = elastic_forces(q, L, EA, EJ, integration)
    assert _rel(lhs, lhs_exu) < 1e-10
    assert _rel(_assemble(blocks), jac_exu) < 1e-10
    # the state is neither straight nor unstretched: both terms are exercised
    assert np.max(np.abs(lhs_exu)) > 1.0


@pytest.mark.parametrize("integration", INTEGRATIONS)
def test_numpy_reference_equals_compiled_kernel(integration):
    L, q = _states(7, n_el=5)
    f_np, k_np = elastic_forces_numpy(q, L, EA, EJ, integration)
    f_nb, k_nb = elastic_forces(q, L, EA, EJ, integration)
    assert _rel(f_nb, f_np) < 1e-13
    assert _rel(k_nb, k_np) < 1e-13
    f_only, none = elastic_forces(q, L, EA, EJ, integration, jacobian=False)
    assert none is None and np.array_equal(f_only, f_nb)


@pytest.mark.parametrize("integration", INTEGRATIONS)
def test_jacobian_is_the_derivative_of_the_force(integration):
    L, q = _states(3)
    _, blocks = elastic_forces(q, L, EA, EJ, integration)
    K = _assemble(blocks)
    x = q.reshape(-1)
    h = 1e-7
    fd = np.empty_like(K)
    for j in range(x.size):
        d = np.zeros(x.size)
        d[j] = h
        fd[:, j] = (elastic_forces(x + d, L, EA, EJ, integration, jacobian=False)[0]
                    - elastic_forces(x - d, L, EA, EJ, integration, jacobian=False)[0]) / (2 * h)
    assert _rel(K, fd) < 1e-6


def test_weight_is_exudyns_mass_proportional_load():
    """The weight AncfCableForces adds equals Exudyn's LoadMassProportional on the same elements."""
    from exudyn.itemInterface import LoadMassProportional, MarkerBodyMass

    L, q = _states(5)
    rho_a, g = 1.7, np.array([0.0, 0.0, -9.81])
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    nodes = [mbs.AddNode(NodePointSlope1(referenceCoordinates=list(c))) for c in q]
    for i, length in enumerate(L):
        e = mbs.AddObject(ObjectANCFCable(nodeNumbers=[nodes[i], nodes[i + 1]], length=float(length),
                                          massPerLength=rho_a, axialStiffness=EA, bendingStiffness=EJ))
        mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(MarkerBodyMass(bodyNumber=e)), loadVector=list(g)))
    mbs.Assemble()
    s = exu.SimulationSettings()
    s.solution.file.write = False   # no solution/ file in the working directory
    s.staticSolver.verboseMode = 0
    solver = exu.MainSolverStatic()
    solver.InitializeSolver(mbs, s)
    solver.ComputeODE2RHS(mbs)
    rhs_exu = np.array(solver.GetSystemResidual())
    forces = AncfCableForces(L, EA, EJ, "full", rho_a, g)
    rhs, _ = forces.evaluate(q, jacobian=False)
    assert _rel(rhs + forces.weight(), rhs_exu) < 1e-10
    assert np.array_equal(rhs, -elastic_forces(q, L, EA, EJ, "full", jacobian=False)[0])
    forces.gravity_scale = 0.5
    assert np.array_equal(forces.weight(), 0.5 * forces.weight_N)
    forces.gravity_scale = 0.0
    assert forces.weight() is None


def test_bad_integration_is_refused():
    with pytest.raises(ValueError, match="integration must be one of"):
        AncfCableForces([1.0], EA, EJ, "simpson")


# ---- the steady model with the compiled element (solver.cable_element = "compiled")

def _fast(name, element):
    from exucable.data import data_path
    from exucable.scenario.specs import load_scenario

    sc = load_scenario(data_path("scenarios", "fast", f"{name}.toml"))
    return sc.replace(**{"solver.mode": "steady", "solver.cable_element": element})


def _system_rhs_and_jacobian(model, gravity_scale: float):
    """The assembled system's ODE2 right-hand side and its dense Jacobian at the model's start, at
    a gravity scale (the steady solve's load continuation)."""
    model.load_scale.apply(model.mbs, gravity=gravity_scale, end_force=1.0)
    s = exu.SimulationSettings()
    s.solution.file.write = False   # no solution/ file in the working directory
    s.linearSolver.solverType = exu.LinearSolverType.EXUdense
    s.staticSolver.verboseMode = 0
    solver = exu.MainSolverStatic()
    solver.InitializeSolver(model.mbs, s)
    solver.ComputeODE2RHS(model.mbs)
    rhs = np.array(solver.GetSystemResidual())[:solver.GetODE2size()]
    solver.ComputeJacobianODE2RHS(model.mbs, 1.0, 0.0, 1.0)
    n = solver.GetODE2size()
    return rhs, np.array(solver.GetSystemJacobian())[:n, :n]


def test_the_compiled_model_assembles_what_exudyns_elements_do():
    """Example 1 (incline, gravity, contact) at its start: the whole system's residual and Jacobian
    with the compiled element and its weight equal those with Exudyn's elements and
    LoadMassProportional, at full and at half gravity (measured 3e-16; bound 1e-10 relative)."""
    from exucable.model.build import build_model

    exu_model = build_model(_fast("paper_ex1_incline", "exudyn"))
    own = build_model(_fast("paper_ex1_incline", "compiled"))
    assert len(exu_model.cable.elements) == exu_model.cable.n_elements > 0
    assert own.cable.elements == () and own.cable.n_elements == exu_model.cable.n_elements
    assert own.gravity_loads == () and own.cable_forces is not None
    assert np.array_equal(own.ode2_index, exu_model.ode2_index)
    for scale in (1.0, 0.5):
        r_exu, j_exu = _system_rhs_and_jacobian(exu_model, scale)
        r_own, j_own = _system_rhs_and_jacobian(own, scale)
        assert _rel(r_own, r_exu) < 1e-10
        assert _rel(j_own, j_exu) < 1e-10
        # the post-processor's line load (the weight) follows the scale too
        assert np.allclose(own.loads().line_load_N_per_m, exu_model.loads().line_load_N_per_m, rtol=1e-14, atol=0)


@pytest.mark.parametrize("name", ["paper_ex1_incline", "paper_ex2_bend90"])
def test_the_pulling_force_does_not_depend_on_who_assembles_the_cable(name, monkeypatch):
    """The steady pulling force with the compiled element equals Exudyn's element's to 1e-8 relative
    (measured 1.0e-13 and 6e-15, the same Newton iterations). Not bit for bit: the same equations,
    summed in another order (element forces and weight in one vector, the stiffness into the contact's
    triplets), so the iterates differ by round-off, and the solve stops at a residual, not at the exact
    root. Exudyn's element runs on Exudyn's static solver, which rejects a spiking step at once, so
    both run with ``max_backtracks = 0`` (the shortened steps are ours alone: tests/test_own_newton.py)."""
    from dataclasses import replace

    from exucable.run import run_scenario
    from exucable.solve.steady import SteadySettings

    base = SteadySettings.from_solver
    monkeypatch.setattr(SteadySettings, "from_solver",
                        classmethod(lambda cls, solver: replace(base(solver), max_backtracks=0)))
    a = run_scenario(_fast(name, "exudyn"), None, plots=False).summary
    b = run_scenario(_fast(name, "compiled"), None, plots=False).summary
    assert a["status"] == b["status"] == "ok"
    assert abs(b["pull_force_N"] / a["pull_force_N"] - 1) < 1e-8
    assert b["newton_iterations"] == a["newton_iterations"]
    # the summary says which element assembled the cable
    assert (a["cable_element"], b["cable_element"]) == ("exudyn", "compiled")


def test_compiled_is_the_steady_default_and_dynamic_mode_keeps_exudyns_element():
    from exucable.data import data_path
    from exucable.model.build import build_model
    from exucable.scenario.specs import load_scenario

    given = load_scenario(data_path("scenarios", "fast", "paper_ex2_bend90.toml"))
    assert given.solver.cable_element == "compiled"
    dynamic = build_model(given.replace(**{"solver.mode": "dynamic"}))
    assert dynamic.cable_forces is None and len(dynamic.cable.elements) == dynamic.cable.n_elements
    steady = build_model(given.replace(**{"solver.mode": "steady"}))
    assert steady.cable_forces is not None and steady.cable.elements == ()
    # the plugin face: a user's own system gets Exudyn's elements unless asked otherwise
    from exucable.model.build import add_cable_in_conduit

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    h = add_cable_in_conduit(mbs, given.replace(**{"solver.mode": "steady"}))
    assert h.cable_forces is None and len(h.cable.elements) == h.cable.n_elements
