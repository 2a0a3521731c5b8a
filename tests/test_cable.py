"""The cable on Exudyn without contact: rig, back tension, gravity, N = EA·ε (paper Eq. 24)."""

from __future__ import annotations

import numpy as np
import pytest
import exudyn as exu

from exucable.model.build import build_model
from exucable.model.cable import CableProperties, add_cable, add_gravity
from exucable.solve.dynamic import simulate
from exucable.post.tension import tension_at, tension_profile

from conftest import make_scenario

EA = 1.0e9 * np.pi * 0.0025**2


def test_straight_free_cable_carries_back_tension_everywhere():
    """N = T everywhere and the rig's force = T once steady.

    No gravity, straight conduit: the cable never touches the wall, and at constant speed its
    axial force is uniform. The pre-stretched start is exact for this case and the integrator
    keeps it to Newton's tolerance, so 1e-6 relative is a generous bound (we see ~1e-10).
    """
    T = 150.0
    sc = make_scenario(pull={"speed": 0.1, "back_tension": T}, solver={"end_time": 0.2, "step": 0.02})
    model = build_model(sc, with_contact=False)
    out = simulate(model)
    assert out.status == "ok", out.message
    q, _ = model.coordinates()
    x, N = tension_profile(q, model.layout.element_length_m, EA)
    np.testing.assert_allclose(N, T, rtol=1e-6)
    np.testing.assert_allclose(out.history.pull_force_N[-1], T, rtol=1e-6)
    # the rig moved the leading end by v·t along the conduit
    assert q[-1, 0] - model.layout.position_m[-1, 0] == pytest.approx(0.1 * out.end_time_s, rel=1e-9)


def test_unstressed_start_reaches_back_tension_with_ramp():
    """Without the pre-tensioned start (cable at rest, loads ramped over 0.05 s), the tension
    still settles to T: the start is a convenience, not a change of the answer. Axial damping
    (τ = 1 ms) removes the ramp's waves; 1e-4 relative after 0.3 s."""
    T = 50.0
    sc = make_scenario(pull={"speed": 0.1, "back_tension": T, "ramp_time": 0.05},
                       solver={"end_time": 0.3, "step": 0.005, "pretension": False})
    model = build_model(sc, with_contact=False)
    out = simulate(model)
    assert out.status == "ok", out.message
    q, _ = model.coordinates()
    _, N = tension_profile(q, model.layout.element_length_m, EA)
    np.testing.assert_allclose(N, T, rtol=1e-4)


def test_vertical_cable_hanging_from_rig():
    """N(x) = ρAg·x along a cable hanging from the rig (x from the free end).

    The cable rises along a vertical conduit at constant speed: no acceleration, no wall contact,
    so the tension is its own weight below x. Cubic Hermite elements represent the linear strain
    exactly; the start (interpolated rope profile, ~3e-5 off) settles within 0.6 s, after which
    1e-6 of the top tension bounds Newton's tolerance (we see ~2e-10).
    """
    g = 9.8
    sc = make_scenario(conduit={"inner_radius": 0.0035, "heading": [0.0, 0.0, 1.0], "path": [{"straight": 5.0}]},
                       cable=dict(radius=0.0025, density=1000.0, youngs_modulus=1.0e9, elements=8),
                       gravity={"g": g}, solver={"end_time": 0.6, "step": 0.02})
    model = build_model(sc, with_contact=False)
    out = simulate(model)
    assert out.status == "ok", out.message
    q, _ = model.coordinates()
    w = 1000.0 * np.pi * 0.0025**2 * g
    x = np.linspace(0.0, 5.0, 41)
    N = tension_at(q, model.layout.element_length_m, EA, x)
    np.testing.assert_allclose(N, w * x, rtol=0, atol=1e-6 * w * 5.0)
    assert out.history.pull_force_N[-1] == pytest.approx(w * 5.0, rel=1e-6)


def test_tension_postprocessor_matches_exudyn_force_local():
    """Our N = EA(|r'| - 1) equals EA times Exudyn's StrainLocal output of the element, on a
    curved, moving cable (1e-9 relative: both evaluate the same polynomial). Exudyn's ForceLocal
    adds the axial damping force D·ε̇, which is why the post-processor uses the strain."""
    sc = make_scenario(pull={"speed": 0.1, "back_tension": 80.0},
                       conduit={"inner_radius": 0.0035, "path": [{"straight": 0.5}, {"bend": 90, "radius": 0.5, "turn": "left"}]},
                       solver={"end_time": 0.02, "step": 0.01})
    model = build_model(sc, with_contact=False)
    simulate(model)
    q, _ = model.coordinates()
    Le = model.layout.element_length_m
    for e in (0, 3, 7):
        for xi in (0.0, 0.3, 0.9):
            ours = tension_at(q, Le, EA, [Le[:e].sum() + xi * Le[e]])[0]
            theirs = EA * model.mbs.GetObjectOutputBody(model.cable.elements[e], exu.OutputVariableType.StrainLocal,
                                                        localPosition=[xi * Le[e], 0.0, 0.0])
            assert ours == pytest.approx(theirs, rel=1e-9, abs=1e-9)


def test_exudyn_ancf_cable_mini_example_through_our_builder():
    """Exudyn's own ObjectANCFCable mini example (TestModels/MiniExamples/ObjectANCFCable.py):
    a 2 m cantilever of 32 elements under gravity, static; its test suite pins the tip's
    x-displacement at -0.5013058140308919. Built with exucable's add_cable/add_gravity, the same
    number to 1e-10 relative (the reference's own reproducibility across versions is ~1e-12)."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    n = 32
    L = 2.0
    x = np.linspace(0.0, L, n + 1)
    coords = np.zeros((n + 1, 6))
    coords[:, 0] = x
    coords[:, 3] = 1.0
    props = CableProperties(mass_per_length_kg_per_m=78.0, axial_stiffness_N=1.0e6,
                            bending_stiffness_N_m2=833.3333333333333, integration="full")  # as Exudyn's example
    cable = add_cable(mbs, coords, np.diff(x), props)
    add_gravity(mbs, cable, [0.0, -9.81, 0.0])
    from exudyn.itemInterface import CoordinateConstraint, MarkerNodeCoordinate, NodePointGround
    mg = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    for k, fixed in enumerate([1, 1, 1, 0, 1, 1]):
        if fixed:
            m = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=cable.nodes[0], coordinate=k))
            mbs.AddObject(CoordinateConstraint(markerNumbers=[mg, m]))
    mbs.Assemble()
    sim = exu.SimulationSettings()
    sim.show.computationTime = False
    sim.solution.file.write = False
    mbs.SolveStatic(sim)
    ux = mbs.GetNodeOutput(cable.nodes[-1], exu.OutputVariableType.Displacement)[0]
    assert ux == pytest.approx(-0.5013058140308919, rel=1e-10)


def test_internal_damping_does_not_change_steady_tension():
    """The paper's cable damping value is lost; ours (Kelvin-Voigt, τ = 1 ms) only damps
    transients: with τ = 0.25 ms and 4 ms the steady pulling force of the fast Example 2 agrees
    with τ = 1 ms to 0.05 % (its own scatter is ~0.03 %)."""
    from exucable.run import run_scenario
    from exucable.scenario.specs import load_scenario
    import dataclasses
    from conftest import ROOT
    base = load_scenario(ROOT / "scenarios/fast/paper_ex2_bend90.toml")
    forces = {}
    for tau in (0.25e-3, 1e-3, 4e-3):
        sc = dataclasses.replace(base, cable=dataclasses.replace(base.cable, damping_time_s=tau))
        forces[tau] = run_scenario(sc, None, quiet=True).summary["pull_force_N"]
    assert forces[0.25e-3] == pytest.approx(forces[1e-3], rel=5e-4)
    assert forces[4e-3] == pytest.approx(forces[1e-3], rel=5e-4)


def test_items_from_shortened_dicts_are_the_interface_classes_items():
    """add_cable and add_gravity pass Exudyn dicts without the class defaults (cable.item_dict); the
    items Exudyn makes of them are those of the full interface objects, entry for entry."""
    from exudyn.itemInterface import LoadMassProportional, MarkerBodyMass, NodePointSlope1, ObjectANCFCable
    from exucable.model.cable import INTEGRATION

    rng = np.random.default_rng(0)
    coords, vel, lengths = rng.standard_normal((4, 6)), rng.standard_normal((4, 6)), rng.uniform(0.5, 1.0, 3)
    p = CableProperties(mass_per_length_kg_per_m=0.3, axial_stiffness_N=1e5, bending_stiffness_N_m2=2e-3,
                        axial_damping_N_s=0.1, bending_damping_N_m2_s=0.0, integration="lobatto")
    ours = exu.SystemContainer().AddSystem()
    cable = add_cable(ours, coords, lengths, p, vel, draw_radius_m=0.01)
    add_gravity(ours, cable, [0.0, 0.0, -9.81])
    full = exu.SystemContainer().AddSystem()
    nodes = [full.AddNode(NodePointSlope1(referenceCoordinates=list(c), initialVelocities=list(v)))
             for c, v in zip(coords, vel)]
    for i, L in enumerate(lengths):
        e = full.AddObject(ObjectANCFCable(
            nodeNumbers=[nodes[i], nodes[i + 1]], length=L, massPerLength=0.3, axialStiffness=1e5,
            bendingStiffness=2e-3, axialDamping=0.1, bendingDamping=0.0,
            useReducedOrderIntegration=INTEGRATION["lobatto"],
            visualization={"show": True, "radius": 0.01, "color": [-1.0, -1.0, -1.0, -1.0]}))
        full.AddLoad(LoadMassProportional(markerNumber=full.AddMarker(MarkerBodyMass(bodyNumber=e)),
                                          loadVector=[0.0, 0.0, -9.81]))

    def plain(v):   # item indices (NodeIndex, ObjectIndex, ...) compare by identity: their numbers
        if isinstance(v, list):
            return [plain(x) for x in v]
        return int(v) if type(v).__name__.endswith("Index") else v

    def same(a, b):
        return a.keys() == b.keys() and all(np.array_equal(plain(a[k]), plain(b[k])) for k in a)

    for get, count in ((lambda m, i: m.GetNode(i), 4), (lambda m, i: m.GetObject(i), 3),
                       (lambda m, i: m.GetMarker(i), 3), (lambda m, i: m.GetLoad(i), 3)):
        for i in range(count):
            assert same(get(ours, i), get(full, i)), (get(ours, i), get(full, i))
