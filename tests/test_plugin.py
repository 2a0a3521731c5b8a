"""The plugin face: a cable in a conduit added to the user's own Exudyn system."""

from __future__ import annotations

import math

import numpy as np
import pytest

import exucable as xc


def ex2(end_time=0.2):
    route = xc.Route(inner_radius=3.5e-3).straight(1.0).bend(90, radius=0.5, turn="left").straight(1.0)
    return xc.Scenario(route=route, cable=xc.Cable(radius=2.5e-3, density=1000.0, youngs_modulus=1e9),
                       contact=xc.Contact(friction=0.2), pull=xc.Pull(speed=0.1, back_tension=150.0),
                       solver=xc.Solver(mode="dynamic", end_time=end_time))


def test_initial_layout_needs_no_exudyn_and_is_pretensioned():
    sc = ex2()
    start = xc.initial_layout(sc)
    assert start.cable.n_elements == sc.cable.elements
    # the rope's trailing tension is the back tension, its pull the capstan (paper Eq. 26)
    assert start.rope.trailing_tension_N == pytest.approx(150.0)
    assert start.rope.pull_force_N == pytest.approx(150.0 * math.exp(0.2 * math.pi / 2), rel=1e-3)
    np.testing.assert_allclose(start.exit_tangent, [0.0, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(start.cable.velocity_m_per_s[-1], [0.0, 0.1, 0.0], atol=1e-6)


def test_add_to_user_system_without_assembling_or_taking_the_post_step():
    import exudyn as exu
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    h = xc.add_cable_in_conduit(mbs, ex2())
    assert not mbs.GetPostStepUserFunction()
    assert not mbs.systemIsConsistent          # not assembled: the user adds more, then assembles
    assert len(h.nodes) == ex2().cable.elements + 1 and h.kernel is not None and h.coupling is not None
    s = h.recommended_settings()
    assert s.timeIntegration.endTime == 0.2 and s.timeIntegration.newton.useModifiedNewton is False
    # parts instead of a scenario
    h2 = xc.add_cable_in_conduit(mbs, route=xc.Route(inner_radius=3.5e-3).straight(1.0),
                                 cable=xc.Cable(radius=2.5e-3, density=1000.0, youngs_modulus=1e9),
                                 pull=xc.Pull(speed=0.1))
    assert h2.scenario.solver.end_time_s == 1.0


def test_leading_end_joined_to_a_user_vehicle_pulls_the_capstan():
    """A user's point mass driven at the pull speed, joined to the cable's leading end by a
    spherical joint: the tension at the leading end is the capstan value, as with the rig."""
    import exudyn as exu
    from exudyn.itemInterface import (CoordinateConstraint, MarkerNodeCoordinate, MarkerNodePosition,
                                      MassPoint, NodePoint, NodePointGround)
    sc = ex2(end_time=0.25)
    start = xc.initial_layout(sc)
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    v = sc.pull.speed_m_per_s * start.exit_tangent
    vehicle = mbs.AddNode(NodePoint(referenceCoordinates=list(start.leading_position_m), initialVelocities=list(v)))
    mbs.AddObject(MassPoint(nodeNumber=vehicle, mass=5.0))
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    for k in range(3):
        m = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=vehicle, coordinate=k))
        mbs.AddObject(CoordinateConstraint(markerNumbers=[ground, m],
                                           offsetUserFunction=lambda mbs, t, i, o, vk=v[k]: vk * t,
                                           offsetUserFunction_t=lambda mbs, t, i, o, vk=v[k]: vk))
    hitch = mbs.AddMarker(MarkerNodePosition(nodeNumber=vehicle))
    h = xc.add_cable_in_conduit(mbs, sc, leading=xc.JoinToMarker(hitch), start=start)
    calls = []

    def users_post_step(mbs, t):
        calls.append(t)
        return h.recorder(mbs, t)

    mbs.SetPostStepUserFunction(users_post_step)
    mbs.Assemble()
    mbs.SolveDynamic(h.recommended_settings())
    F = np.asarray(h.recorder.history.pull_force_N)
    t = np.asarray(h.recorder.history.time_s)
    capstan = 150.0 * math.exp(0.2 * math.pi / 2)
    assert calls and t[-1] == pytest.approx(0.25)
    # leading-end tension EA·ε in the second half; 0.5 %: the default mesh, against the closed form
    assert abs(np.mean(F[t >= 0.125]) / capstan - 1) < 5e-3


def test_simulate_keeps_and_calls_the_users_post_step_function():
    from exucable.model.build import build_model
    from exucable.solve.dynamic import simulate
    model = build_model(ex2(end_time=0.03))
    calls = []

    def mine(mbs, t):
        calls.append(t)
        return True

    model.mbs.SetPostStepUserFunction(mine)
    out = simulate(model)
    assert out.status == "ok" and calls and calls[-1] == pytest.approx(0.03)
    assert model.mbs.GetPostStepUserFunction()["function"] is mine


def test_initial_layout_runs_with_exudyn_blocked():
    import subprocess
    import sys
    import textwrap
    code = textwrap.dedent("""
        import sys
        class Block:
            def find_spec(self, name, path=None, target=None):
                if name == "exudyn" or name.startswith("exudyn."):
                    raise ImportError("exudyn is blocked in this test")
        sys.meta_path.insert(0, Block())
        import exucable as xc
        route = xc.Route(inner_radius=3.5e-3).straight(1.0).bend(90, radius=0.5, turn="left").straight(1.0)
        sc = xc.Scenario(route=route, cable=xc.Cable(radius=2.5e-3, density=1000.0, youngs_modulus=1e9),
                         pull=xc.Pull(speed=0.1, back_tension=150.0), solver=xc.Solver(end_time=0.1))
        start = xc.initial_layout(sc)
        assert start.cable.n_elements == sc.cable.elements and "exudyn" not in sys.modules
    """)
    subprocess.run([sys.executable, "-c", code], check=True)
