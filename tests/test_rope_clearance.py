"""The rope with clearance against the closed forms that still hold when the cable may leave the wall.

Tolerances: the chain's discretisation error is O(h²) (h the node spacing); at the spacings used here it is
below 1e-5 relative on a bend, so 2e-5 catches any modelling error (a mis-signed friction or a weight
counted twice moves the answer by percents) without resting on rounding. On straights the solution is exact
to rounding (1e-9).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exucable.quasistatic import closed_forms as cf
from exucable.errors import ModelError
from exucable.geometry import Bend, Straight, centreline_from_path
from exucable.quasistatic.rope import solve_rope
from exucable.quasistatic.clearance import solve_rope_with_clearance

W = 0.21 * 9.81  # the 18 mm fibre cable, 0.21 kg/m [N/m]


def route(*items, heading=(1.0, 0.0, 0.0)):
    return centreline_from_path([0.0, 0.0, 0.0], heading, list(items))


@pytest.mark.parametrize("clearance_m", [0.002, 0.0084, 0.02])
def test_bend_without_gravity_is_the_capstan_at_any_clearance(clearance_m):
    # Without weight the cable wraps the inner wall and turns through the bend's angle wherever it lies:
    # T_out = T_in e^{μθ} (paper Eq. 26), whatever the clearance.
    centre = route(Straight(2.0), Bend(90.0, 3.0), Straight(2.0))
    sol = solve_rope_with_clearance(centre, clearance_m, 0.5, 0.0, 100.0, node_spacing_m=0.01)
    assert sol.pull_force_N == pytest.approx(cf.capstan_out_N(100.0, 0.5, math.pi / 2), rel=2e-5)
    # it lies on the inner wall through the bend, pressing T/(R − c) per length of cable, which is
    # T/R per length of conduit (the cable's arc is (R − c)/R as long as the centreline's)
    body = (sol.s_conduit_m > 2.3) & (sol.s_conduit_m < 2.0 + 3.0 * math.pi / 2 - 0.3)
    assert np.all(sol.in_contact[body])
    inner = np.array([-1.0, 1.0, 0.0]) / math.sqrt(2)  # toward the bend's centre at mid-bend
    mid = np.argmin(abs(sol.s_conduit_m - (2.0 + 3.0 * math.pi / 4)))
    assert sol.offset_m[mid] @ inner == pytest.approx(clearance_m, rel=1e-5)
    np.testing.assert_allclose(sol.sidewall_pressure_N_per_m[body],
                               sol.tension_N[body] / 3.0, rtol=1e-4)


@pytest.mark.parametrize("theta_deg", [0.0, 20.0])
def test_straight_with_gravity_lies_on_the_floor(theta_deg):
    # On a straight the cable rests on the lower wall: T = T_b + w(μ cos θ + sin θ)L (paper Eq. 25; μwL flat).
    theta = math.radians(theta_deg)
    centre = route(Straight(30.0), heading=(math.cos(theta), 0.0, math.sin(theta)))
    sol = solve_rope_with_clearance(centre, 0.01, 0.5, W, 10.0)
    assert sol.pull_force_N == pytest.approx(10.0 + cf.incline_tension_N(30.0, W, 0.5, theta), rel=1e-9)
    assert np.all(sol.in_contact)
    np.testing.assert_allclose(sol.offset_m @ [-math.sin(theta), 0.0, math.cos(theta)], -0.01, rtol=1e-6)


def test_frictionless_pull_lifts_the_weight_through_its_free_spans():
    # μ = 0: the only work is lifting the cable, so T_lead − T_trail = w (z_lead − z_trail) exactly, with the
    # ends where the clearance puts them (on the floor of the entry, the inner (upper) wall of the exit).
    centre = route(Straight(5.0), Bend(60.0, 5.0, turn="up"), Straight(3.0))
    sol = solve_rope_with_clearance(centre, 0.01, 0.0, 9.81, 200.0, node_spacing_m=0.01)
    rise = sol.position_m[-1, 2] - sol.position_m[0, 2]
    # 1e-6: the weight is lumped at the nodes (an O(h²) error on the curved spans)
    assert sol.pull_force_N == pytest.approx(200.0 + 9.81 * rise, rel=1e-6)
    assert sol.free_spans_m(), "the cable crosses the clearance from the floor to the bend's inner wall"


def test_up_bend_free_span_lowers_the_pull_and_vanishes_with_the_clearance():
    # The vertical up-bend (60°, R 5 m, 1 kg/m, μ 0.3, 200 N): the cable leaves the floor before the
    # bend and hangs in a free span to its upper wall, so the weight of the span is carried by the bend's
    # wall, where it partly cancels the pressure T/R (the rope counts both): the pull is lower than the
    # centreline rope's, and the difference shrinks as the clearance closes, as the square root of it: the
    # free span that crosses the clearance c under tension T is a parabola of length √(2cT/w).
    centre = route(Straight(5.0), Bend(60.0, 5.0, turn="up"), Straight(3.0))
    rope = solve_rope(centre, 0.3, 9.81, 200.0).pull_force_N
    diffs = [solve_rope_with_clearance(centre, c, 0.3, 9.81, 200.0).pull_force_N / rope - 1
             for c in (0.01, 0.001, 0.0001)]
    assert diffs[0] < diffs[1] < diffs[2] < 0.0
    assert 7.0 < diffs[0] / diffs[2] < 13.0  # √100 = 10


def test_converges_with_the_node_spacing():
    centre = route(Straight(5.0), Bend(60.0, 5.0, turn="up"), Straight(3.0))
    f = [solve_rope_with_clearance(centre, 0.01, 0.3, 9.81, 200.0, node_spacing_m=h).pull_force_N
         for h in (0.04, 0.02, 0.01)]
    assert abs(f[2] - f[1]) < 0.5 * abs(f[1] - f[0]) + 1e-9 * f[2]
    assert abs(f[2] / f[1] - 1) < 2e-4


def test_reverse_pull_is_the_reversed_route():
    centre = route(Straight(3.0), Bend(45.0, 4.0, turn="up"), Straight(2.0))
    rev = solve_rope_with_clearance(centre, 0.01, 0.3, 9.81, 50.0, direction="reverse")
    fwd = solve_rope_with_clearance(centre.reversed(), 0.01, 0.3, 9.81, 50.0)
    assert rev.pull_force_N == pytest.approx(fwd.pull_force_N, rel=1e-9)
    np.testing.assert_allclose(rev.s_conduit_m, centre.length_m - fwd.s_conduit_m, atol=1e-12)


@pytest.mark.parametrize("kwargs, key", [(dict(clearance_m=0.0), "clearance_m"), (dict(friction=-0.1), "friction"),
                                         (dict(direction="up"), "direction"),
                                         (dict(cable_length_m=99.0), "cable_length_m")])
def test_bad_arguments_name_the_argument(kwargs, key):
    args = dict(centreline=route(Straight(5.0)), clearance_m=0.01, friction=0.3)
    args.update(kwargs)
    with pytest.raises(ModelError) as err:
        solve_rope_with_clearance(**args)
    assert err.value.key == key


def _sequential_frames(tangents):
    """The node-by-node parallel transport (n_i ∝ (I − a_i a_iᵀ) n_{i−1}) that ``_frames`` vectorises."""
    n1 = np.cross([0.0, 0.0, 1.0], tangents[0])
    n1 /= np.linalg.norm(n1)
    out = np.empty((len(tangents), 3, 2))
    for i, a in enumerate(tangents):
        n1 = n1 - (n1 @ a) * a
        n1 /= np.linalg.norm(n1)
        out[i, :, 0], out[i, :, 1] = n1, np.cross(a, n1)
    return out


def _sequential_march(chain, d, trailing_N):
    """Node i's 2 × 2 balance (along a_i, along d̂_i on the wall) solved one node after the other, from the
    trailing end: the definition that ``_Chain.march`` solves as one affine recurrence."""
    x = chain.positions(d)
    t, ell = chain.segments(x)
    r = np.linalg.norm(d, axis=1)
    half = np.zeros(chain.n)
    half[:-1] += 0.5 * ell
    half[1:] += 0.5 * ell
    W = -chain.w * half[:, None] * np.array([0.0, 0.0, 1.0])
    T, rho, carried = np.empty(chain.n - 1), np.zeros(chain.n), trailing_N * chain.a[0]
    for i in range(chain.n):
        out = t[i] if i < chain.n - 1 else chain.a[-1]
        tau = t[0] if i == 0 else t[-1] if i == chain.n - 1 else (t[i - 1] + t[i]) / np.linalg.norm(t[i - 1] + t[i])
        b, a = carried - W[i], chain.a[i]
        Ti = (b @ a) / (out @ a)
        if r[i] > chain.c:
            e = chain.B[i] @ d[i] / r[i]
            Tc, rc = np.linalg.solve([[out @ a, -chain.mu * (tau @ a)], [out @ e, -(1.0 + chain.mu * (tau @ e))]],
                                     [b @ a, b @ e])
            if rc > 0.0:
                Ti, rho[i] = Tc, rc
        if i < chain.n - 1:
            T[i], carried = Ti, Ti * t[i]
        else:
            pull = Ti
    return T, rho, pull


def test_vectorised_frames_and_march_equal_the_node_loops():
    # The frames (a doubling scan of projections) and the tension march (an affine recurrence whose wall/free
    # choice is iterated to consistency) are the node-by-node loops, vectorised: equal to rounding (1e-12) on a
    # spatial route whose cable touches and leaves the wall, from a tension guess far off (1 N: too low for the
    # up-bend's tension to hold the cable on its upper wall against its weight, so the first choice is wrong).
    from exucable.quasistatic.clearance import _Chain, _frames

    centre = route(Straight(3.0), Bend(40.0, 2.0, turn="up"), Straight(2.0), Bend(70.0, 3.0), Straight(2.0))
    s = np.linspace(0.0, centre.length_m, 801)
    a = np.asarray(centre.tangent(s), dtype=float)
    frames = _frames(a)
    np.testing.assert_allclose(frames, _sequential_frames(a), atol=1e-12)
    sol = solve_rope_with_clearance(centre, 0.01, 0.4, W, 80.0, node_spacing_m=centre.length_m / 800)
    assert 0 < np.count_nonzero(sol.in_contact) < len(s), "the case must have free spans and wall contact"
    chain = _Chain(np.asarray(centre.point(s), dtype=float), a, frames, 0.01, W, 0.4, 1.0)
    d = np.einsum("ijk,ij->ik", frames, sol.offset_m)
    T, rho, _, _, pull = chain.march(d, 80.0, np.full(len(s) - 1, 1.0))
    T_ref, rho_ref, pull_ref = _sequential_march(chain, d, 80.0)
    np.testing.assert_allclose(T, T_ref, rtol=1e-12)
    np.testing.assert_allclose(rho, rho_ref, rtol=1e-9, atol=1e-12 * pull_ref)
    assert pull == pytest.approx(pull_ref, rel=1e-12)


def test_nested_iteration_from_a_coarser_chain_gives_the_same_solution(monkeypatch):
    # Long chains start from the solution on a chain 4 times coarser (1 km: 50 000 nodes, 5x faster). Forced
    # here on a short route (1200 nodes, coarsened to 300): the same fixed point as the direct solve, to 2e-6 (5e-7 seen)
    # (each is converged to rtol 1e-10 but the wall is a penalty of finite stiffness, so the two stop at
    # nearby points), with its free spans where the direct solve has them.
    import exucable.quasistatic.clearance as rc

    centre = route(Straight(3.0), Bend(40.0, 2.0, turn="up"), Straight(2.0), Bend(70.0, 3.0), Straight(2.0))
    h = centre.length_m / 1200
    direct = solve_rope_with_clearance(centre, 0.01, 0.4, W, 80.0, node_spacing_m=h, _coarsen_above=10**9)
    monkeypatch.setattr(rc, "_COARSEN_REQUESTED_ABOVE", 1000)
    nested = solve_rope_with_clearance(centre, 0.01, 0.4, W, 80.0, node_spacing_m=h)
    assert nested.pull_force_N == pytest.approx(direct.pull_force_N, rel=2e-6)
    np.testing.assert_allclose(nested.tension_N, direct.tension_N, rtol=2e-6)
    np.testing.assert_allclose(nested.offset_m, direct.offset_m, atol=1e-4 * 0.01)
    assert np.count_nonzero(nested.in_contact != direct.in_contact) <= 2
    assert nested.residual_N < 1e-5 * nested.pull_force_N


def _long_route(length_m, bend_radius_m, angle_deg=15.0, spacing_m=350.0):
    """Straights and bends turning left, up, right, down in turn (the straights after a vertical
    bend slope), as in benchmarks/long_routes.py."""
    turns = ["left", "up", "right", "down"]
    items = [Straight(spacing_m / 2)]
    for i in range(max(1, int(round(length_m / spacing_m)))):
        items += [Bend(angle_deg, bend_radius_m, turn=turns[i % 4]), Straight(spacing_m / 2)]
    return route(*items)


def test_long_routes_grade_the_chain_away_from_the_bends():
    from exucable.quasistatic.clearance import _FAR_SPACING_M, _GRADING, default_node_spacing_m, graded_node_grid_m

    short = _long_route(350.0, 3.0)        # ≤ 400 m: the uniform chain, as it always was
    s = graded_node_grid_m(short, 0.0, short.length_m, 0.008)
    seg = np.diff(s)
    assert np.ptp(seg) < 1e-9 * seg[0] and default_node_spacing_m(short, 0.008) * (1 - 1e-3) < seg[0] <= default_node_spacing_m(short, 0.008)
    # ... and solves the same chain as one asked for with that spacing, bit for bit
    default = solve_rope_with_clearance(short, 0.008, 0.5, W, 100.0)
    asked = solve_rope_with_clearance(short, 0.008, 0.5, W, 100.0,
                                      node_spacing_m=default_node_spacing_m(short, 0.008))
    assert default.pull_force_N == asked.pull_force_N
    np.testing.assert_array_equal(default.offset_m, asked.offset_m)
    np.testing.assert_array_equal(default.sidewall_pressure_N_per_m, asked.sidewall_pressure_N_per_m)
    centre = _long_route(3000.0, 3.0)
    h_bend = default_node_spacing_m(centre, 0.008)
    s = graded_node_grid_m(centre, 10.0, centre.length_m, 0.008)
    seg = np.diff(s)
    assert s[0] == 10.0 and s[-1] == centre.length_m
    mid = 0.5 * (s[1:] + s[:-1])
    on_bend = np.zeros(mid.shape, bool)
    for a, b in centre.curved_ranges_m():
        on_bend |= (mid > a) & (mid < b)
    # (a segment reaching past a bend's end may be up to one grading step longer)
    assert on_bend.any() and np.all(seg[on_bend] <= h_bend * (1 + _GRADING))
    assert np.median(seg[on_bend]) <= h_bend
    assert seg.max() == pytest.approx(_FAR_SPACING_M, rel=0.01)
    # neighbours differ by about the grading over one segment (the count is integrated on samples half
    # the bends' spacing apart: 5.3 % seen)
    assert np.all(np.abs(np.diff(seg)) <= _GRADING * seg[:-1] * 1.1)
    assert len(s) < 0.15 * centre.length_m / h_bend


@pytest.mark.parametrize("radius_m, fine_m", [(10.0, 0.02), (3.0, 0.01)])
def test_graded_chain_gives_the_uniform_fine_chains_pull(radius_m, fine_m):
    # 1 km routes, a 30 mm cable (1.5 kg/m, 15 mm clearance, μ 0.2, 500 N) on 10 m bends and an 18 mm one
    # (0.21 kg/m, 8 mm, μ 0.5, 100 N) on 3 m bends, against a uniform chain 2.5 and 3 times finer on the
    # bends and 25-50 times on the straights (-2.2e-6 and -6.8e-6 seen): within a fifth of the 1e-4
    # relative floor of a steady run's error bar, the finest this reference is compared at. (Measured
    # on 10 km, benchmarks/long_routes.py --clearance-spacing: -8.6e-6 against a 2 cm chain.)
    centre = _long_route(1000.0, radius_m)
    args = (0.015, 0.2, 1.5 * 9.81, 500.0) if radius_m == 10.0 else (0.008, 0.5, W, 100.0)
    graded = solve_rope_with_clearance(centre, *args)
    fine = solve_rope_with_clearance(centre, *args, node_spacing_m=fine_m)
    assert len(graded.s_conduit_m) < 0.1 * len(fine.s_conduit_m)
    assert graded.pull_force_N == pytest.approx(fine.pull_force_N, rel=2e-5)
    assert graded.residual_N < 1e-5 * graded.pull_force_N
    # the pressure is per length of conduit a node stands for, on a graded chain too: its integral is the
    # wall's total reaction
    share = np.gradient(graded.s_conduit_m)
    share[[0, -1]] *= 0.5
    assert np.sum(graded.sidewall_pressure_N_per_m * share) == pytest.approx(np.sum(graded.contact_force_N), rel=1e-9)
