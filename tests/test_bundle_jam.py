"""The jam of three cables: the keystone statics (exucable/quasistatic/bundle_jam.py) and what the
steady sliding bundle does in the jam range (exucable/model/bundle.py), studies/bundle_jam_study.py.

The keystone's closed forms are checked against the vector balance of each circle (an independent
check of the algebra), the frictionless case against the triangle it must fall into, and the band
against NFPA 70 Ch. 9 Table 1 Note 2's 2.8-3.2 with the calculators' 5 % bend ovality. The simulated
case: three cradled cables at D/d = 2.9 (inside the NEC range) round a 90° bend with gravity slide
through it cradled, unflagged, with cable-cable forces the rigid cradle's, not a keystone's. The
simulated jam: the dynamic model with the pull standing still (pull.stop_time) and static friction on
the wall holds a keystone where the statics say μ_s suffices (status jam, its contact forces the
keystone's G/p), and drops one where the friction falls short into the triangle (no jam).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import exucable as xc
from exucable.errors import ModelError
from exucable.post.bundle import classify_cross_section, jam_band_warning
from exucable.quasistatic.bundle_jam import (frictionless_keystone_psi_rad, keystone, keystone_friction_needed,
                                             wedge_band_d_over_D)


@pytest.mark.parametrize("ratio", [2.6, 2.9, 2.99])
def test_keystone_forces_balance_each_circle(ratio):
    """Each circle's loads sum to zero in the cross-section (to 1e-12 of p): the load p down, the
    contact forces along the lines of centres, the wall's normal through the duct's axis and the
    friction along the wall, at angles across the whole spread range."""
    d, rho = 1.0, 0.5 * (ratio - 1.0)
    lo = math.asin(0.5 * d / rho)
    hi = min(math.pi / 2, math.asin(min(1.0, d / rho)))
    psi = np.linspace(lo, hi, 7)
    k = keystone(ratio, d, psi)
    for i in range(len(psi)):
        a, m, b = k.positions_m[i]
        G, N, F = k.contact_force_per_load[i], k.wall_force_per_load[i], k.wall_friction_per_load[i]
        assert np.linalg.norm(a - m) == pytest.approx(d, rel=1e-12)
        down = np.array([0.0, -1.0])
        on_m = down + G * (m - a) / d + G * (m - b) / d
        n_a = -a / np.linalg.norm(a)                   # the wall pushes toward the duct's axis
        up_wall = np.array([-math.cos(psi[i]), math.sin(psi[i])])
        on_a = down + G * (a - m) / d + N * n_a + F * up_wall
        np.testing.assert_allclose(on_m, 0.0, atol=1e-12)
        np.testing.assert_allclose(on_a, 0.0, atol=1e-12)


@pytest.mark.parametrize("ratio", [2.5, 2.8, 2.9, 2.95, 2.99])
def test_no_frictionless_keystone_below_three(ratio):
    """Without friction in the cross-section (steady sliding) no keystone stands for D/d < 3: the
    outer cables need F > 0 up the wall at every spread, so they slide down until they touch
    (the triangle)."""
    rho = 0.5 * (ratio - 1.0)
    psi = np.linspace(math.asin(0.5 / rho) + 1e-9, math.pi / 2, 2001)
    assert np.all(keystone(ratio, 1.0, psi).wall_friction_per_load > 0.0)


def test_keystone_across_the_duct_multiplies_the_load_toward_three():
    """Across the duct (ψ = 90°) G/p = d/(2√(d² − ρ²)) and μ needed 3√(d² − ρ²)/ρ: at D/d = 2.99
    G/p = 5.006 and the friction needed at 90° 0.301; the least friction over the across range
    (2ψ ≥ 150°) is at most the 90° value."""
    k = keystone(2.99, 1.0, math.pi / 2)
    rho = 0.995
    assert k.contact_force_per_load[0] == pytest.approx(1.0 / (2 * math.sqrt(1 - rho**2)), rel=1e-12)
    assert k.wall_friction_per_load[0] / k.wall_force_per_load[0] == pytest.approx(3 * math.sqrt(1 - rho**2) / rho,
                                                                                   rel=1e-12)
    assert keystone_friction_needed(2.99, 1.0) <= k.wall_friction_per_load[0] / k.wall_force_per_load[0]
    # just above D/d = 3 a frictionless keystone balances (unstable); beyond 3.07 none reaches across
    assert keystone_friction_needed(3.05, 1.0) < 1e-3
    assert keystone_friction_needed(3.1, 1.0) == math.inf
    ratios = [2.8, 2.9, 2.95, 2.98, 2.99]
    needed = [keystone_friction_needed(r, 1.0) for r in ratios]
    assert needed == sorted(needed, reverse=True)


def test_frictionless_keystone_only_above_three():
    """Above D/d = 3 a keystone balances without friction where sin²ψ = (9d²/ρ² − 1)/8 (F = 0 to
    1e-12 of p; at 3.05 ψ = 76.5°, G/p = 6.3); at and below 3 there is none."""
    for ratio in (3.02, 3.05, 3.1):
        psi = frictionless_keystone_psi_rad(ratio, 1.0)
        k = keystone(ratio, 1.0, psi)
        assert abs(k.wall_friction_per_load[0]) < 1e-12 and k.contact_force_per_load[0] > 4.0
    assert math.degrees(frictionless_keystone_psi_rad(3.05, 1.0)) == pytest.approx(76.536, abs=1e-3)
    assert frictionless_keystone_psi_rad(3.0, 1.0) is None and frictionless_keystone_psi_rad(2.9, 1.0) is None


def test_wedge_band_with_bend_ovality_is_the_nec_range():
    """μ_s 0.5 holds a keystone across the duct for D/d 2.967-3.071 in a round duct (the upper end
    1 + 2/sin 75°, where the outer cables can no longer both touch the middle one 150° apart); with
    the calculators' 5 % ovality of a bend either way the band is 2.83-3.22, NFPA 70's 2.8-3.2 to
    within 0.03 at either end."""
    lo, hi = wedge_band_d_over_D(0.5)
    assert keystone_friction_needed(lo, 1.0) == pytest.approx(0.5, abs=1e-3)
    assert hi == pytest.approx(1 + 2 / math.sin(math.radians(75.0)), rel=1e-12)
    lo5, hi5 = wedge_band_d_over_D(0.5, 0.05)
    assert lo5 == pytest.approx(lo / 1.05, rel=1e-12) and hi5 == pytest.approx(hi * 1.05, rel=1e-12)
    assert abs(lo5 - 2.8) < 0.03 and abs(hi5 - 3.2) < 0.03
    # more friction holds a wider band
    assert wedge_band_d_over_D(1.0)[0] < lo < wedge_band_d_over_D(0.3)[0]
    with pytest.raises(ModelError):
        wedge_band_d_over_D(-0.1)


def test_classifier_flags_the_keystone_across_and_not_the_triangle():
    """The keystone's own positions (D/d 2.95, ψ 85°, 90°) classify as side by side, wedged; the
    touching end of the family (the triangle) does not."""
    D, d = 2.95 * 0.03, 0.03
    for deg in (85.0, 90.0):
        pos = keystone(D, d, math.radians(deg)).positions_m[0]
        c = classify_cross_section(pos[[0, 1, 2]], D / 2, d / 2)
        assert c["arrangement"] == "side_by_side" and c["wedged"]
    rho = (D - d) / 2
    tri = keystone(D, d, math.asin(0.5 * d / rho) + 1e-9).positions_m[0]
    c = classify_cross_section(tri, D / 2, d / 2)
    assert c["arrangement"] == "triangular" and not c["wedged"]


@pytest.mark.parametrize("ratio, friction, bends, warned", [
    (2.9, 0.3, True, True), (2.9, 0.3, False, False), (3.0, 0.3, False, True), (3.2, 0.3, True, True),
    (3.3, 0.3, True, False), (2.75, 0.5, True, False), (2.9, 0.0, True, False)])
def test_jam_band_warning(ratio, friction, bends, warned):
    """The run's warning follows the keystone band: μ 0.3 holds one for D/d 2.989-3.071 in a round
    duct, 2.846-3.224 with a bend's 5 % ovality; no friction, no keystone."""
    text = jam_band_warning(3, ratio, friction, bends)
    assert (text is not None) == warned
    if warned:
        assert f"D/d = {ratio:.3g}" in text and "conduit.inner_radius" in text
    assert jam_band_warning(2, ratio, friction, bends) is None


D_CABLE, RADIUS, STRAIGHT = 0.03, 2.0, 0.5


def bend_scenario(ratio):
    """The study's case (studies/bundle_jam_study.py): a horizontal 90° bend of 2 m radius, gravity,
    wall μ 0.3, frictionless between the cables, 100 N per cable in, 16 elements."""
    route = (xc.Route(inner_radius=ratio * D_CABLE / 2).straight(STRAIGHT).bend(90, radius=RADIUS, turn="left")
             .straight(STRAIGHT))
    return xc.Scenario(route=route,
                       cable=xc.Cable(radius=D_CABLE / 2, density=2000.0, youngs_modulus=2e8, bending_stiffness=1.0,
                                      count=3, arrangement="cradled", elements=16),
                       contact=xc.Contact(friction=0.3, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=300.0), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", end_time=1.0, steady_lead_out=0.0))


def test_a_cradle_in_the_jam_range_slides_cradled_and_says_it_could_wedge():
    """D/d = 2.9, inside NFPA 70's 2.8-3.2: the steady bundle goes round the bend cradled, no cable
    lifted off the wall between the others, so no jam flag and status ok, but with the keystone
    band's warning. The middle cable's contact force per length over the bend's middle half is the
    rigid cradle's 2x·p = 1.053 p within 10 % (p = T κ n − w e_z⊥ per cable, T the share rope's),
    not the keystone's 1.60 p."""
    res = xc.run(bend_scenario(2.9))
    b = res.summary.bundle
    assert res.status == "ok" and b["jam"] is False
    bend = next(s for s in b["sections"] if s["kind"] == "bend")
    assert bend["arrangement"] == "cradled" and not bend["jam"]
    assert any("wedge side by side" in w for w in res.summary.warnings)
    model = res.model
    kernel = model.between
    q_all = np.concatenate([q.reshape(-1) for q in model.cable_coordinates()])
    c = kernel.contacts(q_all)
    cable, point = c["index"][:, 0] // kernel.n_points, c["index"][:, 0] % kernel.n_points
    line = (kernel.weight[point] * kernel.law.stiffness * c["penetration_m"] ** kernel.law.exponent
            / (kernel.element_length_m[point // kernel.n_k] / kernel.n_k))
    x_pts, _ = kernel.point_forces_N(q_all)
    s = np.array([np.interp(x_pts[j], model.layout.cables[i].node_x_m, model.layout.cables[i].node_s_m)
                  for i, j in zip(cable, point)])
    a, e = STRAIGHT + 0.25 * RADIUS * math.pi / 2, STRAIGHT + 0.75 * RADIUS * math.pi / 2
    mid = (s >= a) & (s <= e)
    centre = model.conduit.centreline
    T = np.interp(s[mid], model.rope.s_conduit_m, model.rope.tension_N)
    w = model.scenario.cable.mass_per_length_kg_per_m * 9.81
    p = np.hypot(T / RADIUS, w)          # a horizontal bend: T κ across, the weight down
    assert centre.length_m > e
    ratio = line[mid] / p
    assert np.max(ratio) == pytest.approx(2.0 / (2.9 - 1.0), rel=0.10)


def test_laid_as_the_keystone_the_steady_bundle_does_not_stay_wedged(monkeypatch):
    """Started in the jam itself (a 2 m horizontal straight with gravity, D/d 3.05, the cables laid as
    the keystone at its frictionless balance ψ = 76.5°, G = 6.3 w), the steady solve does not hold it
    (it is unstable, and sliding friction gives no hold across the duct): no plane side by side, no
    jam, status ok, the pull within 5 % of the calculators' cradle rather than the keystone's
    w_c = 2N/3w = 4.3. Where the middle cable ends is the path's choice between two steady states:
    through the contact onset layer (the bundle's steady solve) the outer cables close under it, a
    triangle in all 9 planes (+0.57 % on the formula); with the law of one cable throughout it
    dropped between them, cradled in 7 of 9 (+3.7 %; reference/README.md, "Through a smooth contact
    onset")."""
    import exucable.model.bundle as bundle_model

    def keystone_offsets(count, arrangement, inner_radius_m, cable_radius_m):
        D, d = 2.0 * inner_radius_m, 2.0 * cable_radius_m
        psi = frictionless_keystone_psi_rad(D, d)
        return keystone(D, d, math.pi / 2 if psi is None else psi).positions_m[0]

    monkeypatch.setattr(bundle_model, "arrangement_offsets", keystone_offsets)
    ratio = 3.05
    sc = bend_scenario(ratio).replace(**{"conduit.path": [{"straight": 2.0}]})
    res = xc.run(sc)
    b = res.summary.bundle
    assert res.status == "ok" and b["jam"] is False
    (straight,) = b["sections"]
    assert straight["arrangement"] in ("cradled", "triangular") and "side_by_side" not in straight["arrangements_seen"]
    formula = 3 * res.model.rope.pull_force_N
    assert res.pull_force_N == pytest.approx(formula, rel=0.05)


# -- a stopped pull: static friction across the duct holds the keystone (dynamic mode)

def test_stopping_pull_schedule():
    """The eye's schedule: the speed factor is the ramp up, down at the stop and up again after the
    hold; the distance is its integral (trapezoid on 20 001 points, to 1e-6 of the distance), and
    without a stop both are the plain ramp's."""
    from exucable.model.rig import pull_speed_factor, pulled_distance_m, ramped_displacement, smooth_ramp

    tau, stop, hold, V = 0.2, 0.5, 0.3, 0.1
    t = np.linspace(0.0, 1.5, 20001)
    f = np.array([pull_speed_factor(x, tau, stop, hold) for x in t])
    x = np.array([pulled_distance_m(x, V, tau, stop, hold) for x in t])
    assert f[t <= 0.0][0] == 0.0 and np.all(f[(t >= tau) & (t <= stop)] == 1.0)
    assert np.all(f[(t >= stop + tau) & (t <= stop + hold)] == 0.0) and np.all(f[t >= stop + hold + tau] == 1.0)
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(t))]) * V
    np.testing.assert_allclose(x, integral, atol=1e-6 * x[-1])
    # standing still from the start: no motion until the hold ends
    assert pulled_distance_m(0.3, V, tau, 0.0, 0.4) == 0.0 and pull_speed_factor(0.3, tau, 0.0, 0.4) == 0.0
    assert pulled_distance_m(0.7, V, 0.0, 0.0, None) == 0.0
    for y in (0.05, 0.3, 1.0):
        assert pull_speed_factor(y, tau) == smooth_ramp(y, tau)
        assert pulled_distance_m(y, V, tau) == ramped_displacement(y, V, tau)


def test_a_stopped_single_cable_eye_follows_the_schedule():
    """One cable on a 1 m straight with gravity, pulled at 0.1 m/s, stopping at 0.15 s for 0.15 s
    (ramps 0.05 s): at the end the leading node has moved along the exit tangent by the schedule's
    distance (to 1e-9 m: the drive's position constraint), and while the eye stands still the
    pull force, held by static friction, changes by less than 1 % of itself."""
    from exucable.model.rig import pulled_distance_m

    sc = xc.Scenario(route=xc.Route(inner_radius=3.5e-3).straight(1.0),
                     cable=xc.Cable(radius=2.5e-3, density=1000.0, youngs_modulus=1e9, elements=4),
                     contact=xc.Contact(friction=0.2, static_friction=0.3),
                     pull=xc.Pull(speed=0.1, back_tension=20.0, stop_time=0.15, hold_time=0.15, ramp_time=0.05),
                     gravity=xc.Gravity(g=9.81), solver=xc.Solver(mode="dynamic", end_time=0.4, steady_stop=False))
    res = xc.run(sc)
    model = res.model
    q, _ = model.coordinates()
    start = model.layout.coordinates
    moved = float((q[-1, :3] - start[-1, :3]) @ model.lead_drive.direction)
    assert moved == pytest.approx(pulled_distance_m(0.4, 0.1, 0.05, 0.15, 0.15), abs=1e-9)
    assert pulled_distance_m(0.4, 0.1, 0.05, 0.15, 0.15) == pytest.approx(0.1 * (0.4 - 0.025 - 0.15), rel=1e-12)
    t, F = np.asarray(res.history.time_s), np.asarray(res.history.pull_force_N)
    still = (t >= 0.22) & (t <= 0.30)
    assert np.ptp(F[still]) < 0.01 * np.mean(F[still])


@pytest.mark.parametrize("keys, key", [
    ({"pull.stop_time": None, "pull.hold_time": 0.2}, "pull.hold_time"),
    ({"pull.stop_time": 0.0, "solver.mode": "steady"}, "pull.stop_time"),
    ({"pull.stop_time": 0.0, "solver.mode": "dynamic", "solver.exit_span_damping": 10.0}, "pull.stop_time")])
def test_a_stop_the_model_cannot_run_is_refused_naming_the_key(keys, key):
    from exucable.errors import ScenarioError

    with pytest.raises(ScenarioError) as err:
        stopped_keystone(2.98, 0.5).replace(**keys)
    assert err.value.key == key


def stopped_keystone(ratio, static_friction, psi_deg=None):
    """Three cables laid as the keystone across a 2 m horizontal duct with gravity, the pull standing
    still from the start (``pull.stop_time = 0``) and the weight and the back tension ramped in over
    0.2 s (a load put on at once knocks the cables off the wall faster than the Stribeck velocity,
    and then only the kinetic μ 0.3 acts); 8 elements of 0.25 m, ε = 0.1 mm/s, 0.35 s."""
    return xc.Scenario(route=xc.Route(inner_radius=ratio * D_CABLE / 2).straight(2.0),
                       cable=xc.Cable(radius=D_CABLE / 2, density=2000.0, youngs_modulus=2e8, bending_stiffness=1.0,
                                      count=3, arrangement="cradled", elements=8),
                       contact=xc.Contact(friction=0.3, static_friction=static_friction, check_points_per_element=8,
                                          friction_regularisation_velocity=1e-4),
                       pull=xc.Pull(speed=0.1, back_tension=30.0, stop_time=0.0, ramp_time=0.2),
                       gravity=xc.Gravity(g=9.81), solver=xc.Solver(mode="dynamic", end_time=0.35))


def lay_keystone(monkeypatch, psi_deg):
    """Lay the cables as the keystone at the outer cables' angle ``psi_deg`` [deg] from the bottom,
    exactly: the start's 5 % gap (laid as larger circles) would lift the middle cable ~8 mm at D/d
    2.98 (the keystone's shape is steep near D/d 3) and it would fall onto the others."""
    import exucable.model.bundle as bundle_model

    def offsets(count, arrangement, inner_radius_m, cable_radius_m):
        return keystone(2.0 * inner_radius_m, D_CABLE, math.radians(psi_deg)).positions_m[0]

    monkeypatch.setattr(bundle_model, "arrangement_offsets", offsets)


def middle_cable_wedge_factor(res) -> float:
    """The middle cable's mean contact force per length with each outer one over its weight per
    length [-] in the duct's middle half, 0.5-1.5 m (a bending length √(EJ/T) ≈ 0.3 m and more away
    from the trailing end and from the eye, which holds the leading ends as laid)."""
    model = res.model
    kernel = model.between
    q_all = np.concatenate([q.reshape(-1) for q in model.cable_coordinates()])
    c = kernel.contacts(q_all)
    cable, point = c["index"][:, 0] // kernel.n_points, c["index"][:, 0] % kernel.n_points
    x_pts, _ = kernel.point_forces_N(q_all)
    s = np.array([np.interp(x_pts[j], model.layout.cables[i].node_x_m, model.layout.cables[i].node_s_m)
                  for i, j in zip(cable, point)])
    line = (kernel.weight[point] * kernel.law.stiffness * c["penetration_m"] ** kernel.law.exponent
            / (kernel.element_length_m[point // kernel.n_k] / kernel.n_k))
    w = model.scenario.cable.mass_per_length_kg_per_m * 9.81
    mid = (s >= 0.5) & (s <= 1.5) & ((cable == 1) | (c["index"][:, 1] // kernel.n_points == 1))
    return float(np.sum(line[mid]) / np.count_nonzero(mid) / w)


def test_a_stopped_keystone_in_the_band_stands_and_is_flagged_jam(monkeypatch):
    """D/d 2.98, μ_s 0.5, μ 0.3: the keystone needs a wall friction of 0.394 at ψ 86.5° (the least
    across the duct, :func:`keystone_friction_needed`), so static friction holds it and kinetic would
    not. Laid there with the pull standing still, it stands through the 0.35 s (the outer cables creep
    down the wall at about the regularisation speed, well under a millimetre): every plane reads side
    by side, the run's status is ``jam`` with the place, D/d and the fix. The middle cable's contact
    force per length is the keystone's G = p d/(2h) at the simulated outer cables' angle, within
    10 % (Hertz penetrations and the chord's sag move the contact by micrometres where h is 4.6 mm),
    far above the cradle's 2d/(D − d) = 1.01 and the brief's 1.6."""
    lay_keystone(monkeypatch, 86.5)
    res = xc.run(stopped_keystone(2.98, 0.5))
    b = res.summary.bundle
    assert res.status == "jam" and b["jam"] is True
    (straight,) = b["sections"]
    assert straight["arrangements_seen"] == {"side_by_side": 9}
    assert res.summary.message.startswith("jam: three cables wedged side by side across the duct at s = ")
    assert "D/d = 2.98" in res.summary.message and "conduit.inner_radius" in res.summary.message
    offs = np.array(b["cross_sections"][0]["offsets_m"])
    psi = math.atan2(-offs[0, 0], -offs[0, 1])
    assert 85.0 < math.degrees(psi) < 87.0
    G = keystone(2.98 * D_CABLE, D_CABLE, psi).contact_force_per_load[0]
    assert middle_cable_wedge_factor(res) == pytest.approx(G, rel=0.10)


def test_a_keystone_friction_cannot_hold_drops_to_the_triangle_unflagged(monkeypatch):
    """The jam's neighbour: at D/d 2.9 the keystone across the duct needs μ 0.765 (> μ_s 0.5). Laid
    the same way and held still, the outer cables slide down the wall until they touch and the middle
    one rests on them (triangular in every plane): no jam, and the run is not flagged ``jam`` (it ends
    ``not_steady``: the held force still settles after the collapse). The same keystone at D/d 2.98
    with μ 0.3 alone drops too (studies/bundle_jam_study.py, 12 cases against the statics)."""
    lay_keystone(monkeypatch, 75.0)
    res = xc.run(stopped_keystone(2.9, 0.5))
    b = res.summary.bundle
    assert b["jam"] is False and res.status != "jam"
    (straight,) = b["sections"]
    assert straight["arrangements_seen"] == {"triangular": 9}
