"""solver.start_from = "steady": the dynamic run starts in the steady solve's state (issue 10 item 3).

A short Gera-like route (the wander's worst case: a stiff cable, EJ = 103 N m², in a 0.6 m bend at
the exit, gravity): from the rope start the pulling force falls for the whole run as the rig pulls
the cable out of the bend's bending boundary layer, with the axial mode ringing on top; from the
steady start, laid out past the bend, it stays where it started. The comparison is with the steady
mode solved independently at the same extent (the dynamic run's ``reference_pulled_out_m``).
Coarse and short (seconds); the full routes are ``studies/industry_dynamic.py``.
"""

from __future__ import annotations

import numpy as np

import exucable as xc


def _scenario(start):
    route = xc.Route(inner_radius=0.0508).straight(10.0).bend(90, radius=0.6096, turn="left")
    return xc.Scenario(route=route,
                       cable=xc.Cable(radius=0.01905, mass_per_length=2.2322, youngs_modulus=1e9),
                       contact=xc.Contact(friction=0.3), pull=xc.Pull(speed=0.3048, back_tension=500.0),
                       gravity=xc.Gravity(g=9.80665),
                       solver=xc.Solver(mode="dynamic", end_time=0.4, step=1e-2, start_from=start))


def test_steady_start_is_steady_and_agrees_with_steady_mode():
    res = xc.run(_scenario("steady"))
    s = res.summary
    assert s["start"]["kind"] == "steady"
    assert s["start"]["lead_out_m"] > 0.0          # laid out past the bend's boundary layer
    t, f = res.history.time_s, res.history.pull_force_N
    late = t >= 0.1
    # the whole run after the start-up stays within 0.2 % of its mean (issue 10's scatter bound) ...
    assert np.std(f[late]) / np.mean(f[late]) < 2e-3
    # ... and starts at the steady solve's force
    assert abs(f[late][0] / s["start"]["steady_pull_force_N"] - 1) < 2e-3
    steady = xc.run(_scenario("rope").replace(**{"solver.mode": "steady",
                                                 "solver.steady_lead_out": s["reference_pulled_out_m"]}))
    assert abs(steady.pull_force_N / res.pull_force_N - 1) < 2e-3


def test_rope_start_wanders_on_the_same_route():
    """The case the steady start removes (so the test above is not passing by chance): from the
    rope start the force moves by more than 1 % after the start-up."""
    res = xc.run(_scenario("rope"))
    t, f = res.history.time_s, res.history.pull_force_N
    late = f[t >= 0.1]
    assert (late.max() - late.min()) / np.mean(late) > 1e-2


def test_exit_span_damper_is_zero_on_the_steady_flow_and_damps_departures():
    """solver.exit_span_damping: no force inside the conduit, none on a cable sliding along its own
    path at the rig speed past the exit, -c·m·δv on a departure δv from that flow."""
    from exucable.model.startup import ExitSpanDamper

    # three nodes: one inside (behind the exit at x = 0), one half a ramp past it, one a full ramp past
    pos = np.array([[-1.0, 0.0, 0.0], [0.25, 0.0, 0.0], [2.0, 0.0, -0.1]])
    slope = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.995, 0.0, -0.0998]])
    ref = np.hstack([pos, slope]).reshape(-1)
    mass = np.array([0.5, 1.0, 2.0])
    d = ExitSpanDamper(mass, ref, rate_1_per_s=10.0, speed_m_per_s=0.3, exit_point_m=[0, 0, 0],
                       exit_tangent=[1, 0, 0], ramp_length_m=0.5)
    q = np.zeros(18)
    flow = np.zeros((3, 6))
    flow[:, :3] = 0.3 * slope / np.linalg.norm(slope, axis=1)[:, None]
    assert np.allclose(d.force(1.0, q, flow.reshape(-1)), 0.0)
    moved = flow.copy()
    moved[:, 2] += 0.01                                  # every node 1 cm/s upwards
    f = d.force(1.0, q, moved.reshape(-1)).reshape(3, 6)
    assert f[0, 2] == 0.0                                # inside: none
    assert np.isclose(f[1, 2], -10.0 * 0.5 * 1.0 * 0.01)  # half-way up the ramp (smoothstep(1/2) = 1/2)
    assert np.isclose(f[2, 2], -10.0 * 2.0 * 0.01)       # fully on
    assert np.allclose(f[:, 3:], 0.0)                    # slopes are not damped
