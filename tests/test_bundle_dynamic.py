"""Several cables in one conduit in the dynamic mode (exucable/model/bundle_rig.py).

The cable-cable kernel with the points' velocities from the nodal rates and the normal law's damping
is checked against central differences of its own force (exact Jacobians ∂Q/∂q and ∂Q/∂q̇) and the
compiled loop against the numpy definition. The dynamic bundle's steady pulling force is checked
against the steady bundle solve (exucable/model/bundle.py, the same model without inertia) and its
straight's weight correction against the rigid-circle formulas (triangular 1/√(1 - x²), cradled
1 + (4/3)x², x = d/(D - d); exucable/quasistatic/engineering.py); tolerances from how steady the
dynamic run got (its pulling force's uncertainty, exucable/post/trust.py). Coarse meshes (8 elements
of 0.5 m on a 4 m straight, 16 round a bend).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import exucable as xc
from exucable.contact import ContactLaw
from exucable.contact.cable_pairs import CableContactKernel
from exucable.errors import ModelError
from exucable.post.tension import detect_steady_state
from exucable.post.trust import pull_force_uncertainty
from exucable.quasistatic import engineering as eng

D_CABLE = 0.03          # cable diameter [m]
MU = 0.3
BACK = 30.0             # the bundle's back tension [N]


def straight_duct(arrangement, ratio, mode, **solver):
    """A 4 m horizontal duct of inner diameter ratio·d with three cables (as tests/test_bundle.py)."""
    keys = dict(mode=mode, end_time=1.0, steady_lead_out=0.0)
    keys.update(solver)
    return xc.Scenario(route=xc.Route(inner_radius=ratio * D_CABLE / 2).straight(4.0),
                       cable=xc.Cable(radius=D_CABLE / 2, density=2000.0, youngs_modulus=2e8, count=3,
                                      arrangement=arrangement, elements=8),
                       contact=xc.Contact(friction=MU, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=BACK), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(**keys))


# -- the kernel's dynamic form

R = 2.5e-3
LAW = ContactLaw(stiffness=1e6, damping=50.0, exponent=1.5, friction=0.3, regularisation_velocity_m_per_s=1e-3,
                 damping_onset_m=2e-4)


def _trefoil(rng, n_el=2, Le=0.05):
    """Three cables pressed together by 0.1 mm, perturbed, with random nodal rates."""
    gap = 2 * R - 1e-4
    q = []
    for y, z in ((0.0, 0.0), (gap, 0.0), (gap / 2, gap * np.sqrt(3) / 2)):
        c = np.zeros((n_el + 1, 6))
        c[:, 0] = np.arange(n_el + 1) * Le + 1e-5 * rng.normal(size=n_el + 1)
        c[:, 1], c[:, 2], c[:, 3] = y, z, 1.0
        c[:, 1:3] += 1e-4 * rng.normal(size=(n_el + 1, 2))
        c[:, 4:6] += 0.02 * rng.normal(size=(n_el + 1, 2))
        q.append(c.reshape(-1))
    q = np.concatenate(q)
    q_t = 0.05 * rng.normal(size=q.size)
    q_t[0::6] += 0.1                    # all sliding along x at about the pull speed
    return q, q_t


def test_dynamic_pair_jacobians_match_central_differences():
    """∂Q/∂q and ∂Q/∂q̇ of the force with the points' velocities S q̇, friction and damping (with its
    onset ramp) on: exact against central differences (truncation ~h²|Q'''|, round-off ~1e-16|Q|/h,
    both below 1e-6 of the largest entry here). The compiled kernel; the numpy one is equal to it
    (next test)."""
    q, q_t = _trefoil(np.random.default_rng(3))
    k = CableContactKernel(3, np.full(2, 0.05), R, LAW, 4, 1e-3, 0.1, backend="numba")
    res = k.evaluate(q, q_t=q_t)
    assert res.n_in_contact > 0 and res.jacobian_t is not None
    for J, vary, h in ((res.jacobian.toarray(), "q", 1e-9), (res.jacobian_t.toarray(), "q_t", 1e-7)):
        fd = np.empty_like(J)
        for i in range(q.size):
            d = np.zeros_like(q)
            d[i] = h
            plus = k.evaluate(q + d, False, q_t) if vary == "q" else k.evaluate(q, False, q_t + d)
            minus = k.evaluate(q - d, False, q_t) if vary == "q" else k.evaluate(q, False, q_t - d)
            fd[:, i] = (plus.generalized_force - minus.generalized_force) / (2 * h)
        assert np.abs(J - fd).max() <= 1e-6 * np.abs(J).max(), vary


def test_dynamic_pair_kernel_compiled_equals_numpy():
    q, q_t = _trefoil(np.random.default_rng(4))
    a = CableContactKernel(3, np.full(2, 0.05), R, LAW, 4, 1e-3, 0.1, backend="numpy").evaluate(q, q_t=q_t)
    b = CableContactKernel(3, np.full(2, 0.05), R, LAW, 4, 1e-3, 0.1, backend="numba").evaluate(q, q_t=q_t)
    assert a.n_in_contact == b.n_in_contact > 0
    np.testing.assert_allclose(b.generalized_force, a.generalized_force, rtol=0,
                               atol=1e-11 * np.abs(a.generalized_force).max())
    for x, y in ((a.jacobian, b.jacobian), (a.jacobian_t, b.jacobian_t)):
        assert abs(x - y).max() <= 1e-11 * abs(x).max()


def test_damping_acts_on_the_approach_only_through_the_normal():
    """Two parallel cables approaching at δ̇ along their common normal: the normal force is
    w (K δ^e + C g δ̇) with g = δ/δ_d in the onset ramp; sliding along the axis adds nothing to it."""
    n_el, Le, delta = 4, 0.1, 1e-4
    a = np.zeros((n_el + 1, 6))
    a[:, 0], a[:, 3] = np.arange(n_el + 1) * Le, 1.0
    b = a.copy()
    b[:, 1] = 2 * R - delta
    q = np.concatenate([a.reshape(-1), b.reshape(-1)])
    q_t = np.zeros_like(q)
    q_t[0::6] = 0.1                                     # both sliding along x together
    q_t[6 * (n_el + 1) + 1::6] = -0.02                  # cable 2 approaching cable 1 along -y
    k = CableContactKernel(2, np.full(n_el, Le), R, LAW, 4, 1e-3, 0.1, backend="numba")
    c = k.contacts(q, q_t=q_t)
    w = Le / 4 / 1e-3
    expected = w * (LAW.stiffness * delta ** 1.5 + LAW.damping * (delta / LAW.damping_onset_m) * 0.02)
    np.testing.assert_allclose(c["force"][:, 1], -expected, rtol=1e-12)   # P on cable 1 pushed to -y
    np.testing.assert_allclose(c["force"][:, 0], 0.0, atol=1e-12 * expected)


# -- the dynamic bundle against the steady one and the formulas

def _window(history):
    """The dynamic run's own trust measures (exucable/post/trust.py, exucable/post/tension.py) on the
    pulling force as recorded: its steady window (solver.steady_window 0.2 s, drift and scatter
    within 1e-3) and that window's mean with its uncertainty (the per-period means' standard error
    and half the drift across the window). Taken without the references' expected drift: on these
    coarse meshes the force steps as a check point (6 cm apart) leaves the conduit instead of
    drifting as the rope's does (the summary's steadiness is judged against that drift)."""
    st = detect_steady_state(history.time_s, history.pull_force_N, 0.2, 1e-3)
    assert st.steady, "the dynamic run did not settle"
    est = pull_force_uncertainty(history.time_s, history.pull_force_N, st.from_s)
    assert np.isfinite(est.uncertainty_N)
    return est


def _agree(dynamic_N, u_N, steady_N):
    """Within three times the dynamic run's uncertainty plus 2e-3 of the force: what the two solves'
    different states of the exit leave (the dynamic run's cables pulled out by V·t, their last
    element across the exit; the steady solve laid out by that much; measured ≤ 6.4e-4 below)."""
    return abs(dynamic_N - steady_N) <= 3.0 * u_N + 2e-3 * steady_N


@pytest.mark.parametrize("arrangement, ratio", [("triangular", 2.4), ("cradled", 3.3)])
def test_straight_duct_from_the_steady_start_stays_steady(arrangement, ratio):
    """``solver.start_from = "steady"``: the dynamic model (inertia, the wall's dynamic kernel, the
    cables' velocities from the nodal rates) keeps the steady bundle's state: its pull within its own
    uncertainty of the steady solve's (measured 7e-5 relative), each straight's weight correction the
    rigid-circle value within 0.3 % (the steady solve: 0.2 %, tests/test_bundle.py; measured here
    −0.1 … +0.1 %)."""
    steady = xc.run(straight_duct(arrangement, ratio, "steady"))
    assert steady.status == "ok"
    dyn = xc.run(straight_duct(arrangement, ratio, "dynamic", start_from="steady", end_time=0.4))
    s = dyn.summary
    assert s["mode"] == "dynamic" and s["start"]["kind"] == "steady"
    est = _window(dyn.history)
    assert _agree(est.mean_N, est.uncertainty_N, steady.pull_force_N), (est, steady.pull_force_N)
    formula = eng.weight_correction_factor(3, arrangement, ratio * D_CABLE, D_CABLE)
    (straight,) = s["bundle"]["straights"]
    assert straight["weight_correction_factor"] == pytest.approx(formula, rel=3e-3)
    # the eye's pull is its cables' shares (the window's means)
    assert sum(c["pull_share_N"] for c in s["bundle"]["cables"]) == pytest.approx(s["pull_force_N"], rel=1e-9)


def test_rope_start_settles_in_the_steady_bundle(tmp_path):
    """From the rope start (laid 5 % of a radius apart and off the wall, as the steady model lays
    them) the cables drop into the cradle, swing and settle within about 1.3 s (the normal law's
    damping between them; without it the pull still swung ±40 % after 2 s). The settled pull is the
    steady solve's at the same extent (``solver.steady_lead_out`` = V times the window's mean time;
    measured −6e-4), the straight's weight correction the rigid-circle value within 0.3 % (measured
    +0.13 %); the files as for one cable plus the bundle's."""
    dyn = xc.run(straight_duct("cradled", 3.3, "dynamic", end_time=1.8), out_dir=tmp_path)
    est = _window(dyn.history)
    t_mean = 0.5 * (est.window_s[0] + est.window_s[1])
    steady = xc.run(straight_duct("cradled", 3.3, "steady", steady_lead_out=0.1 * t_mean))
    assert _agree(est.mean_N, est.uncertainty_N, steady.pull_force_N), (est, steady.pull_force_N)
    summary = json.loads((tmp_path / "summary.json").read_text())
    b = summary["bundle"]
    formula = eng.weight_correction_factor(3, "cradled", 3.3 * D_CABLE, D_CABLE)
    assert b["straights"][0]["weight_correction_factor"] == pytest.approx(formula, rel=3e-3)
    # the dynamic run's own trust keys, and the bundle's report
    for key in ("steady", "steady_from_s", "pull_force_uncertainty_N", "simulated_time_s", "flags"):
        assert key in summary
    assert summary["mode"] == "dynamic" and b["count"] == 3 and b["arrangement"] == "cradled"
    header = (tmp_path / "history.csv").read_text().splitlines()[0]
    assert header.split(",")[:4] == ["time_s", "pull_force_N", "trailing_tension_N", "max_tension_N"]
    assert (tmp_path / "cable_tensions.csv").read_text().splitlines()[0] == \
        "x_m,cable_1_tension_N,cable_2_tension_N,cable_3_tension_N"
    # the middle cable on the bottom, pressed by both others, pulls hardest
    shares = [c["pull_share_N"] for c in b["cables"]]
    assert shares[1] > shares[0] and shares[1] > shares[2]


def test_bend_agrees_with_the_steady_bundle():
    """A horizontal 90° bend of 2 m radius without gravity (tests/test_bundle_bends.py's, wall friction
    0.3, 16 elements), started steady: the dynamic run is steady by the summary's own detector (no
    gravity: no drift to expect) and its pull is the steady solve's within its uncertainty."""
    route = xc.Route(inner_radius=3.3 * D_CABLE / 2).straight(0.5).bend(90, radius=2.0, turn="left").straight(0.5)

    def bend(mode, **solver):
        return xc.Scenario(route=route,
                           cable=xc.Cable(radius=D_CABLE / 2, density=2000.0, youngs_modulus=2e8, bending_stiffness=1.0,
                                          count=3, arrangement="cradled", elements=16),
                           contact=xc.Contact(friction=MU, check_points_per_element=8),
                           pull=xc.Pull(speed=0.1, back_tension=300.0),
                           solver=xc.Solver(mode=mode, end_time=0.4, steady_lead_out=0.0, **solver))

    steady = xc.run(bend("steady"))
    assert steady.status == "ok"
    dyn = xc.run(bend("dynamic", start_from="steady"))
    s = dyn.summary
    assert s["steady"] and s["status"] in ("ok", "steady"), s["message"]
    assert _agree(s["pull_force_N"], s["pull_force_uncertainty_N"], steady.pull_force_N), \
        (s["pull_force_N"], s["pull_force_uncertainty_N"], steady.pull_force_N)


def test_snapshots_are_refused_naming_the_key():
    sc = straight_duct("cradled", 3.3, "dynamic").replace(**{"output.snapshots": [0.1]})
    with pytest.raises(ModelError) as err:
        xc.run(sc)
    assert "output.snapshots" in str(err.value)


def test_command_line_prints_the_dynamic_bundle(tmp_path):
    """`exucable run` on a scenario file with three cables in the dynamic mode (the bend without
    gravity, started steady): exit 0, the time integration's line and the shares printed."""
    import subprocess
    import sys

    path = tmp_path / "three.toml"
    path.write_text('name = "three"\n[cable]\nradius = 0.015\ndensity = 2000.0\nyoungs_modulus = 2e8\n'
                    'bending_stiffness = 1.0\ncount = 3\narrangement = "cradled"\nelements = 16\n'
                    '[conduit]\ninner_radius = 0.0495\npath = [{straight = 0.5}, {bend = 90.0, radius = 2.0, turn = "left"},'
                    ' {straight = 0.5}]\n[contact]\nfriction = 0.3\ncheck_points_per_element = 8\n'
                    '[pull]\nspeed = 0.1\nback_tension = 300.0\n'
                    '[solver]\nmode = "dynamic"\nstart_from = "steady"\nend_time = 0.3\nsteady_lead_out = 0.0\n')
    proc = subprocess.run([sys.executable, "-m", "exucable", "run", str(path), "--out", str(tmp_path / "out"),
                           "--no-plots"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "3 cables cradled" in proc.stdout and "time integration to t = 0.3 s, steady from" in proc.stdout
    assert proc.stdout.count("  cable ") == 3
