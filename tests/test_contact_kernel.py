"""Tests of the cable-conduit contact kernel (paper Sects. 2.4-2.5, Eqs. 2-8 and 14-23).

The references here are independent of the kernel: a plain per-point loop written from the
paper's equations, closed-form Hertz forces, and central finite differences. The test conduits
are built here from exact arcs and helices (the geometry package is developed separately).
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from exucable.contact import (
    ContactKernel,
    ContactLaw,
    assemble_blocks_dense,
    block_sparsity,
    check_points,
)
from exucable.contact.broadphase import (
    candidates_all_pairs,
    candidates_sweep,
    element_aabbs,
)
from exucable.geometry.segments import Segments

R_CONDUIT = 3.5e-3  # NOTES.md: conduit inner radius [m]
R_CABLE = 2.5e-3  # cable radius [m]
GAP = R_CONDUIT - R_CABLE

BACKENDS = ["numpy", "numba"]

# damping_onset_m=0: the paper's Eq. 18 as written, which the reference loops below implement
SLIDING = ContactLaw(stiffness=1e6, damping=1e3, exponent=1.5, friction=0.3, damping_onset_m=0.0)
STATIC = ContactLaw(stiffness=1e6, damping=50.0, exponent=1.5, friction=0.2, static_friction=0.35, damping_onset_m=0.0,
                    stribeck_velocity_m_per_s=0.05, regularisation_velocity_m_per_s=1e-3)
LINEAR = ContactLaw(stiffness=2e5, damping=0.0, exponent=1.0, friction=0.1, damping_onset_m=0.0)
GENERIC = ContactLaw(stiffness=5e6, damping=20.0, exponent=1.3, friction=0.25, damping_onset_m=0.0)


# ---------------------------------------------------------------------------------------------
# test conduits: exact centrelines (point, unit tangent at arc length s) and their polylines
# ---------------------------------------------------------------------------------------------

class Route:
    """A centreline c(s), its unit tangent, and a polyline with vertices on it."""

    def __init__(self, centre, tangent, s_vertices):
        self.centre = centre
        self.tangent = tangent
        self.s_vertices = np.asarray(s_vertices, dtype=float)
        self.segments = Segments(centre(self.s_vertices), self.s_vertices, R_CONDUIT)
        self.length = float(self.s_vertices[-1])


def straight_route(n_seg=6, length=1.2):
    """Oblique straight line split into ``n_seg`` collinear segments."""
    d = np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5])
    p0 = np.array([0.1, -0.2, 0.3])
    return Route(lambda s: p0 + np.multiply.outer(s, d),
                 lambda s: np.broadcast_to(d, np.shape(s) + (3,)).copy(),
                 np.linspace(0.0, length, n_seg + 1))


def bend_route(n_arc=24, radius=0.5, lead=0.3):
    """Straight, 90° arc of ``radius`` in ``n_arc`` segments, straight (in the xy plane)."""
    arc = radius * np.pi / 2

    def centre(s):
        s = np.atleast_1d(s).astype(float)
        out = np.empty(s.shape + (3,))
        for i, si in enumerate(s):
            if si <= lead:
                out[i] = [si - lead, 0.0, 0.0]
            elif si <= lead + arc:
                phi = (si - lead) / radius
                out[i] = [radius * np.sin(phi), radius * (1 - np.cos(phi)), 0.0]
            else:
                out[i] = [radius, radius + si - lead - arc, 0.0]
        return out

    def tangent(s):
        s = np.atleast_1d(s).astype(float)
        phi = np.clip((s - lead) / radius, 0.0, np.pi / 2)
        return np.stack([np.cos(phi), np.sin(phi), 0 * phi], axis=-1)

    s_v = np.concatenate([[0.0], lead + np.linspace(0.0, arc, n_arc + 1), [2 * lead + arc]])
    return Route(centre, tangent, s_v)


def helix_route(n_seg=60, radius=0.4, pitch=0.3, turns=1.25):
    """Helix about z of ``radius`` and ``pitch`` (rise per turn)."""
    c = pitch / (2 * np.pi)
    rho = np.hypot(radius, c)

    def centre(s):
        phi = np.asarray(s, dtype=float) / rho
        return np.stack([radius * np.cos(phi), radius * np.sin(phi), c * phi], axis=-1)

    def tangent(s):
        phi = np.asarray(s, dtype=float) / rho
        return np.stack([-radius * np.sin(phi), radius * np.cos(phi), c + 0 * phi], axis=-1) / rho

    return Route(centre, tangent, np.linspace(0.0, turns * 2 * np.pi * rho, n_seg + 1))


def kink_route(angle_deg=40.0, leg=0.5):
    """Two straight segments meeting at the origin, turning by ``angle_deg`` towards +y."""
    a = np.radians(angle_deg)
    d0 = np.array([1.0, 0.0, 0.0])
    d1 = np.array([np.cos(a), np.sin(a), 0.0])

    def centre(s):
        s = np.atleast_1d(s).astype(float)
        return np.where((s <= leg)[:, None], (s - leg)[:, None] * d0, (s - leg)[:, None] * d1)

    def tangent(s):
        s = np.atleast_1d(s).astype(float)
        return np.where((s <= leg)[:, None], d0, d1)

    return Route(centre, tangent, [0.0, leg, 2 * leg])


def perpendicular_unit(t, rng):
    """Random unit vectors perpendicular to the rows of ``t``."""
    x = rng.normal(size=t.shape)
    x -= np.sum(x * t, axis=1)[:, None] * t
    return x / np.linalg.norm(x, axis=1)[:, None]


def random_cable(route, n_el, rng, element_length=None, s0=0.05, pen=(-3e-4, 6e-4),
                 speed=0.1, noise=0.02, direction=None):
    """Cable state near the wall: nodes at the clearance plus a random penetration in ``pen``.

    Returns q, q_t and the element length [m]. ``direction`` (callable of the node index and
    tangent) fixes the offset direction; by default it is random, perpendicular to the tangent.
    """
    if element_length is None:
        element_length = (route.length - 2 * s0) / n_el
    s = s0 + element_length * np.arange(n_el + 1)
    c = route.centre(s)
    t = route.tangent(s)
    t = t / np.linalg.norm(t, axis=1)[:, None]
    off = perpendicular_unit(t, rng) if direction is None else direction(c, t)
    pos = c + off * (GAP + rng.uniform(*pen, size=(n_el + 1, 1)))
    slope = t + rng.normal(scale=1e-3, size=t.shape)
    vel = speed * t + rng.normal(scale=noise, size=t.shape)
    slope_rate = rng.normal(scale=2.5 * noise, size=t.shape)
    q = np.hstack([pos, slope]).reshape(-1)
    q_t = np.hstack([vel, slope_rate]).reshape(-1)
    return q, q_t, element_length


# ---------------------------------------------------------------------------------------------
# the paper's equations, one point at a time (the reference for the forces)
# ---------------------------------------------------------------------------------------------

def paper_loop_force(segments, q, q_t, element_length, law, n_points, rule, h_ref=1e-3):
    """Generalized contact force by a plain loop over elements, check points and segments."""
    if rule == "gauss":
        x, wq = np.polynomial.legendre.leggauss(n_points)
        xis, omegas = (x + 1) / 2, wq / 2
    else:
        xis = (np.arange(n_points) + 0.5) / n_points
        omegas = np.full(n_points, 1.0 / n_points)
    verts = segments.vertices_m
    n_el = len(q) // 6 - 1
    lengths = np.broadcast_to(element_length, (n_el,))
    force = np.zeros_like(q)
    n_contact = 0
    for e in range(n_el):
        qe, qte = q[6 * e:6 * e + 12], q_t[6 * e:6 * e + 12]
        L = lengths[e]
        for xi, omega in zip(xis, omegas):
            n1 = 1 - 3 * xi**2 + 2 * xi**3
            n2 = L * (xi - 2 * xi**2 + xi**3)
            n3 = 3 * xi**2 - 2 * xi**3
            n4 = L * (-xi**2 + xi**3)
            S = np.hstack([n1 * np.eye(3), n2 * np.eye(3), n3 * np.eye(3), n4 * np.eye(3)])
            P = S @ qe  # Eq. 2
            v = S @ qte  # Eq. 8
            best_d, best_pc = np.inf, None
            for i in range(len(verts) - 1):  # closest point on the polyline
                A, B = verts[i], verts[i + 1]
                a = (B - A) / np.linalg.norm(B - A)
                t = np.clip(np.dot(P - A, a), 0.0, np.linalg.norm(B - A))
                pc = A + t * a
                d = np.linalg.norm(P - pc)
                if d < best_d:
                    best_d, best_pc = d, pc
            delta = best_d - (R_CONDUIT - R_CABLE)  # Eq. 14
            if delta <= 0:
                continue
            n_contact += 1
            n = (P - best_pc) / best_d  # Eq. 15
            vn = np.dot(n, v)  # Eq. 16
            vt = v - vn * n  # Eq. 17
            w = L * omega / h_ref
            fn = w * max(0.0, law.stiffness * delta**law.exponent + law.damping * vn)  # Eq. 18
            mu = law.friction
            if law.static_friction is not None:
                mu += (law.static_friction - law.friction) * np.exp(
                    -(np.linalg.norm(vt) / law.stribeck_velocity_m_per_s) ** 2)
            ft = mu * fn  # Eq. 19
            tau = vt / np.sqrt(np.dot(vt, vt) + law.regularisation_velocity_m_per_s**2)  # Eq. 20
            F = -fn * n - ft * tau  # Eqs. 21-23
            force[6 * e:6 * e + 12] += S.T @ F
    return force, n_contact


def relative_error(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


# ---------------------------------------------------------------------------------------------
# forces against the paper's equations
# ---------------------------------------------------------------------------------------------

ROUTES = {"straight": straight_route, "bend": bend_route, "helix": helix_route}


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("route_name", list(ROUTES))
@pytest.mark.parametrize("law", [SLIDING, STATIC, LINEAR, GENERIC],
                         ids=["hertz-sliding", "stribeck", "linear", "pow-1.3"])
def test_forces_match_paper_loop(backend, route_name, law):
    route = ROUTES[route_name]()
    rng = np.random.default_rng([list(ROUTES).index(route_name), int(100 * law.exponent)])
    n_el, n_points = 6, 9
    q, q_t, L = random_cable(route, n_el, rng)
    rule = "gauss" if law.exponent != 1.0 else "uniform"
    kernel = ContactKernel(route.segments, L, R_CABLE, law, n_points, rule=rule,
                           n_elements=n_el, backend=backend)
    res = kernel.evaluate(q, q_t)
    ref, n_ref = paper_loop_force(route.segments, q, q_t, L, law, n_points, rule)
    # the configuration must exercise both branches of the contact test
    assert 0 < n_ref < n_el * n_points
    assert res.n_in_contact == n_ref
    # 1e-12 relative: both sides compute the same quantities with different operation order;
    # the largest rounding is in d - (R - r) with |P| ~ 1 m and δ ~ 1e-4 m (2e-16/1e-4 ~ 2e-12
    # per point at worst, averaging down over the summed points).
    assert relative_error(res.generalized_force, ref) < 1e-12


@pytest.mark.parametrize("backend", BACKENDS)
def test_unequal_element_lengths(backend):
    route = bend_route()
    rng = np.random.default_rng(99)
    lengths = np.array([0.08, 0.2, 0.13, 0.31, 0.1])
    s = 0.05 + np.concatenate([[0.0], np.cumsum(lengths)])
    t = route.tangent(s)
    pos = route.centre(s) + perpendicular_unit(t, rng) * (GAP + rng.uniform(-2e-4, 5e-4, (6, 1)))
    q = np.hstack([pos, t]).reshape(-1)
    q_t = np.hstack([0.1 * t + rng.normal(scale=0.02, size=t.shape),
                     rng.normal(scale=0.05, size=t.shape)]).reshape(-1)
    k = ContactKernel(route.segments, lengths, R_CABLE, SLIDING, 7, backend=backend)
    ref, n_ref = paper_loop_force(route.segments, q, q_t, lengths, SLIDING, 7, "gauss")
    res = k.evaluate(q, q_t)
    assert 0 < n_ref < 35 and res.n_in_contact == n_ref
    assert relative_error(res.generalized_force, ref) < 1e-12  # as in the test above


# ---------------------------------------------------------------------------------------------
# broad phase
# ---------------------------------------------------------------------------------------------

def test_sweep_equals_all_pairs_on_random_boxes():
    rng = np.random.default_rng(7)
    for trial in range(60):
        ne, ns = rng.integers(1, 40), rng.integers(1, 60)
        c = rng.uniform(0, 10, (ne, 3))
        elo, ehi = c - rng.uniform(0, 2, (ne, 3)), c + rng.uniform(0, 2, (ne, 3))
        c = rng.uniform(0, 10, (ns, 3))
        slo, shi = c - rng.uniform(0, 2, (ns, 3)), c + rng.uniform(0, 2, (ns, 3))
        if trial % 3 == 0:  # boxes that only touch: closed intervals count as overlapping
            k = min(ne, ns)
            elo[:k] = slo[:k]
            ehi[:k] = np.maximum(ehi[:k], elo[:k])
            ehi[0] = np.maximum(elo[0], slo[-1])
        ref = candidates_all_pairs(elo, ehi, slo, shi)
        for axis in (None, 0, 1, 2):
            got = candidates_sweep(elo, ehi, slo, shi, axis=axis)
            assert np.array_equal(got[0], ref[0]) and np.array_equal(got[1], ref[1])


def test_element_box_contains_the_curve():
    rng = np.random.default_rng(3)
    q, _, L = random_cable(bend_route(), 5, rng)
    lo, hi = element_aabbs(q, np.full(5, L), 0.0)
    xi = np.linspace(0, 1, 201)
    for e in range(5):
        qe = q[6 * e:6 * e + 12].reshape(4, 3)
        n = np.stack([1 - 3 * xi**2 + 2 * xi**3, L * (xi - 2 * xi**2 + xi**3),
                      3 * xi**2 - 2 * xi**3, L * (xi**3 - xi**2)], axis=1)
        p = n @ qe
        assert np.all(p >= lo[e] - 1e-15) and np.all(p <= hi[e] + 1e-15)


@pytest.mark.parametrize("backend", BACKENDS)
def test_broad_phase_gives_the_brute_force_result(backend):
    route = bend_route(n_arc=24)
    rng = np.random.default_rng(11)
    n_el = 5
    centre_of_bend = np.array([0.0, 0.5, 0.0])

    def inward(c, t):  # towards the bend centre: points on the bend's inside
        x = centre_of_bend - c
        x -= np.sum(x * t, axis=1)[:, None] * t
        return x / np.linalg.norm(x, axis=1)[:, None]

    # elements of 0.2 m against arc segments of 0.033 m: each element spans several segments
    q, q_t, L = random_cable(route, n_el, rng, element_length=0.2, s0=0.25, direction=inward,
                             pen=(-1e-4, 5e-4))
    aabb = ContactKernel(route.segments, L, R_CABLE, SLIDING, 16, n_elements=n_el,
                         backend=backend)
    brute = ContactKernel(route.segments, L, R_CABLE, SLIDING, 16, n_elements=n_el,
                          broad_phase="none", backend=backend)
    off, _ = aabb.candidates(q)
    assert np.diff(off).max() >= 5 and np.diff(off).max() < route.segments.count
    st = aabb.points(q, q_t)
    assert st.in_contact.sum() >= 30  # about half the points, on the inside of the bend
    # precondition of the equivalence: every check point within R of the polyline
    assert np.nanmax(st.penetration_m) < R_CABLE
    a = aabb.evaluate(q, q_t, jacobian=True)
    b = brute.evaluate(q, q_t, jacobian=True)
    # same nearest segment, same arithmetic: equal up to 1e-14 relative (in practice bitwise)
    assert relative_error(a.generalized_force, b.generalized_force) <= 1e-14
    assert relative_error(a.jac_q_blocks, b.jac_q_blocks) <= 1e-14
    assert relative_error(a.jac_qt_blocks, b.jac_qt_blocks) <= 1e-14
    assert a.n_in_contact == b.n_in_contact


def test_point_outside_the_conduit_feels_no_force():
    """Documented limit: a cable that has left the conduit finds no candidate segment."""
    route = straight_route()
    q = np.zeros(12)
    q[0:3] = [0.3, 0.3, 0.3]  # 0.3 m off the axis line, which starts at (0.1, -0.2, 0.3)
    q[3:6] = [1.0, 0.0, 0.0]
    q[6:9] = [0.4, 0.3, 0.3]
    q[9:12] = [1.0, 0.0, 0.0]
    for backend in BACKENDS:
        k = ContactKernel(route.segments, 0.1, R_CABLE, SLIDING, 4, n_elements=1,
                          backend=backend)
        res = k.evaluate(q, np.zeros(12), jacobian=True)
        assert res.n_in_contact == 0 and not res.generalized_force.any()
    st = k.points(q, np.zeros(12))
    assert np.all(st.segment == -1) and np.all(np.isnan(st.penetration_m))


@pytest.mark.parametrize("backend", BACKENDS)
def test_conduit_ends_are_open(backend):
    """A cable pulled out of the conduit (or still to enter it) touches nothing beyond the end
    planes, however far it sits from the axis line's continuation; with ``open_ends=False`` the
    end vertex acts as a wall (the paper's closed polyline), and the points inside the conduit
    feel the same force either way (1e-12)."""
    route = straight_route(n_seg=3, length=1.2)
    d = route.tangent(np.array([0.0]))[0]
    side = perpendicular_unit(d[None, :], np.random.default_rng(1))[0]
    p_end = route.centre(np.array([route.length]))[0]
    # one element straddling the exit: first node inside at the wall, second 5 cm beyond the end
    q = np.zeros(12)
    q[0:3] = p_end - 0.05 * d + (GAP + 2e-4) * side
    q[3:6] = d
    q[6:9] = p_end + 0.05 * d + (GAP + 2e-4) * side
    q[9:12] = d
    q_t = np.concatenate([0.1 * d, np.zeros(3), 0.1 * d, np.zeros(3)])
    open_k = ContactKernel(route.segments, 0.1, R_CABLE, SLIDING, 40, n_elements=1, backend=backend)
    closed_k = ContactKernel(route.segments, 0.1, R_CABLE, SLIDING, 40, n_elements=1, backend=backend,
                             open_ends=False)
    st_open = open_k.points(q, q_t)
    st_closed = closed_k.points(q, q_t)
    s_along = (st_open.position_m - route.centre(np.array([0.0]))[0]) @ d
    inside = s_along < route.length
    assert inside.any() and (~inside).any()
    assert np.all(st_open.in_contact[inside]) and not np.any(st_open.in_contact[~inside])
    assert np.all(st_closed.in_contact)   # the closed end vertex is a wall
    np.testing.assert_allclose(st_open.normal_force_N[inside], st_closed.normal_force_N[inside], rtol=1e-12)
    assert open_k.evaluate(q, q_t).n_in_contact == inside.sum()



@pytest.mark.parametrize("backend", BACKENDS)
def test_point_segments_are_the_point_states_segments(backend):
    """point_segments (the compiled backend: its contact search alone) gives the nearest segment
    of points(): on a bend, and across an open end where points beyond it have none (-1)."""
    rng = np.random.default_rng(3)
    route = bend_route()
    q, q_t, L = random_cable(route, 4, rng)
    route_end = straight_route(n_seg=3, length=1.2)
    d = route_end.tangent(np.array([0.0]))[0]
    p_end = route_end.centre(np.array([route_end.length]))[0]
    # two elements: one across the exit, one wholly beyond it (no segment near: -1)
    q_out = np.concatenate([p_end - 0.1 * d, d, p_end + 0.1 * d, d, p_end + 0.3 * d, d])
    for segs, qq, n_el, length in ((route.segments, q, 4, L), (route_end.segments, q_out, 2, 0.2)):
        fresh = ContactKernel(segs, length, R_CABLE, SLIDING, 40, n_elements=n_el,
                              backend=backend)
        seg = fresh.point_segments(qq)
        state = ContactKernel(segs, length, R_CABLE, SLIDING, 40, n_elements=n_el,
                              backend=backend).points(qq, np.zeros_like(qq)).segment
        np.testing.assert_array_equal(seg, state)
    assert (seg < 0).any() and (seg >= 0).any()

# ---------------------------------------------------------------------------------------------
# Jacobians against central finite differences
# ---------------------------------------------------------------------------------------------

H_Q = 1e-8  # step in positions [m] and slopes [-]
H_QT = 1e-7  # step in velocities [m/s] and slope rates [1/s]
# Tolerance on max|J - J_fd| / max|J|: the truncation error of central differences is
# ~ (h/δ_min)² relative for the δ^1.5 law, ≤ 2.5e-7 with δ_min ≥ 2e-5 m asserted below, and
# (h/ε)² = 1e-8 for the friction regularisation; rounding adds ~ eps·|Q|/h ≈ 1e-11 relative.
FD_TOL = 1e-6


def finite_difference_jacobians(kernel, q, q_t):
    n = len(q)
    jq = np.zeros((n, n))
    jqt = np.zeros((n, n))
    for i in range(n):
        dq = np.zeros(n)
        dq[i] = H_Q
        jq[:, i] = (kernel.evaluate(q + dq, q_t).generalized_force
                    - kernel.evaluate(q - dq, q_t).generalized_force) / (2 * H_Q)
        dq[i] = H_QT
        jqt[:, i] = (kernel.evaluate(q, q_t + dq).generalized_force
                     - kernel.evaluate(q, q_t - dq).generalized_force) / (2 * H_QT)
    return jq, jqt


def assert_smooth_configuration(kernel, q, q_t):
    """No check point within reach of a switch (contact on/off, force clip) for the FD steps."""
    st = kernel.points(q, q_t)
    delta = st.penetration_m
    assert np.all(np.abs(delta) > 2e-5)
    assert st.in_contact.sum() >= 5
    law = kernel.law
    c = st.in_contact
    vn = np.sum(st.normal[c] * st.velocity_m_per_s[c], axis=1)
    elastic = law.stiffness * delta[c] ** law.exponent
    raw = elastic + law.damping * vn  # Eq. 18 before the clip at 0
    assert np.all(np.abs(raw) > 1e-3 * (elastic + law.damping * np.abs(vn)))
    return st


def fd_case(name):
    rng = np.random.default_rng({"sliding": 21, "static": 23, "vertex": 23}[name])
    if name == "vertex":
        # A short straight element across the outer side of a 40° kink, 1.4 mm from the vertex:
        # points within ±ρ tan 20° = ±0.51 mm of the bisector see the vertex (projection clamped
        # on both segments), the others a segment interior; all have δ >= 0.4 mm.
        route = kink_route(40.0)
        half = np.radians(20.0)
        along = np.array([np.cos(half), np.sin(half), 0.0])  # bisector direction
        outward = np.array([np.sin(half), -np.cos(half), 0.0])  # away from the turn
        L = 2e-3
        base = (GAP + 4e-4) * outward
        pos = np.stack([base - 0.5 * L * along, base + 0.5 * L * along])
        vel = 0.1 * along + rng.normal(scale=0.02, size=(2, 3))
        q = np.hstack([pos, np.tile(along, (2, 1))]).reshape(-1)
        q_t = np.hstack([vel, rng.normal(scale=0.05, size=(2, 3))]).reshape(-1)
        return route, SLIDING, q, q_t, L, 1, 7
    route = helix_route() if name == "sliding" else bend_route()
    law = SLIDING if name == "sliding" else STATIC
    speed, noise = (0.1, 0.02) if name == "sliding" else (0.03, 0.01)  # near v_s = 0.05 m/s
    q, q_t, L = random_cable(route, 3, rng, element_length=0.15, s0=0.3, pen=(1e-4, 6e-4),
                             speed=speed, noise=noise)
    return route, law, q, q_t, L, 3, 5


@pytest.mark.parametrize("name", ["sliding", "static", "vertex"])
def test_jacobians_match_finite_differences(name):
    route, law, q, q_t, L, n_el, n_points = fd_case(name)
    ref = ContactKernel(route.segments, L, R_CABLE, law, n_points, n_elements=n_el,
                        backend="numpy")
    st = assert_smooth_configuration(ref, q, q_t)
    if name == "vertex":  # some points in contact are clamped to the kink's vertex
        at_vertex = np.isclose(st.s_conduit_m, route.s_vertices[1], rtol=0, atol=1e-15)
        assert np.count_nonzero(at_vertex & st.in_contact) >= 3
    if name == "static":  # sliding speeds where the Stribeck term has a slope
        v = st.sliding_velocity_m_per_s[st.in_contact]
        assert np.any((v > 0.01) & (v < 0.1))
    jq_fd, jqt_fd = finite_difference_jacobians(ref, q, q_t)
    for backend in BACKENDS:
        k = ContactKernel(route.segments, L, R_CABLE, law, n_points, n_elements=n_el,
                          backend=backend)
        res = k.evaluate(q, q_t, jacobian=True)
        jq = assemble_blocks_dense(res.jac_q_blocks)
        jqt = assemble_blocks_dense(res.jac_qt_blocks)
        assert relative_error(jq, jq_fd) < FD_TOL, backend
        assert relative_error(jqt, jqt_fd) < FD_TOL, backend


def test_jacobian_without_friction_normal_coupling_is_wrong():
    """The ∂f_n/∂q term inside the friction force is significant (Newton cycles without it)."""
    route, law, q, q_t, L, _, _ = fd_case("sliding")
    k = ContactKernel(route.segments, L, R_CABLE, law, 5, n_elements=3, backend="numpy")
    no_friction = ContactKernel(route.segments, L, R_CABLE,
                                ContactLaw(law.stiffness, law.damping, law.exponent, 0.0, damping_onset_m=0.0), 5,
                                n_elements=3, backend="numpy")
    jq = assemble_blocks_dense(k.evaluate(q, q_t, jacobian=True).jac_q_blocks)
    jq0 = assemble_blocks_dense(no_friction.evaluate(q, q_t, jacobian=True).jac_q_blocks)
    # friction adds at least 1 % of the normal stiffness to the Jacobian (μ = 0.3 couples it)
    assert np.max(np.abs(jq - jq0)) > 0.01 * np.max(np.abs(jq0))


# ---------------------------------------------------------------------------------------------
# closed forms
# ---------------------------------------------------------------------------------------------

def one_point_case(delta0, vel):
    """One element along x at distance R - r + δ0 from a straight conduit on the x axis."""
    seg = Segments(np.array([[-1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]), np.array([0.0, 3.0]),
                   R_CONDUIT)
    L = 0.4
    y = GAP + delta0
    q = np.array([0, y, 0, 1, 0, 0, L, y, 0, 1, 0, 0], dtype=float)
    q_t = np.concatenate([vel, [0, 0, 0], vel, [0, 0, 0]]).astype(float)
    return seg, L, q, q_t


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("damping, vel", [(0.0, [0.0, 0.0, 0.0]), (1e3, [0.0, 2e-3, 0.0]),
                                          (1e3, [0.05, -1e-3, 0.0])])
def test_single_point_hertz_force(backend, damping, vel):
    delta0 = 2e-4
    seg, L, q, q_t = one_point_case(delta0, np.array(vel))
    law = ContactLaw(stiffness=1e6, damping=damping, exponent=1.5, friction=0.3, damping_onset_m=0.0)
    h_ref = 1e-3
    k = ContactKernel(seg, L, R_CABLE, law, 1, reference_spacing_m=h_ref, n_elements=1,
                      backend=backend)
    res = k.evaluate(q, q_t)
    w = L * 1.0 / h_ref  # one Gauss point: ξ = 1/2, ω = 1
    fn = w * (1e6 * delta0**1.5 + damping * vel[1])  # Eq. 18 with δ̇ = v_y
    eps = law.regularisation_velocity_m_per_s
    fx = -0.3 * fn * vel[0] / np.hypot(vel[0], eps)  # regularised Coulomb friction along x
    # S(1/2) = [1/2 I, L/8 I, 1/2 I, -L/8 I]
    expected = np.concatenate([0.5 * np.array([fx, -fn, 0]), L / 8 * np.array([fx, -fn, 0]),
                               0.5 * np.array([fx, -fn, 0]), -L / 8 * np.array([fx, -fn, 0])])
    # a handful of roundings on O(1) numbers
    np.testing.assert_allclose(res.generalized_force, expected, rtol=1e-13, atol=1e-13 * fn)
    assert res.n_in_contact == 1
    st = k.points(q, q_t)
    np.testing.assert_allclose(st.penetration_m, [delta0], rtol=1e-10)
    np.testing.assert_allclose(st.normal_force_N, [fn], rtol=1e-12)
    np.testing.assert_allclose(st.normal_force_per_length_N_per_m, [fn / L], rtol=1e-12)
    np.testing.assert_allclose(st.s_conduit_m, [1.0 + L / 2], rtol=1e-14)
    np.testing.assert_allclose(st.sliding_velocity_m_per_s, [abs(vel[0])], atol=1e-15)
    np.testing.assert_allclose(st.friction_force_N, [abs(fx)], rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("backend", BACKENDS)
def test_total_force_independent_of_number_of_check_points(backend):
    """w = L ω / h_ref: a uniformly pressed element carries (L/h_ref) K δ^e whatever n."""
    seg, L, q, q_t = one_point_case(3e-4, np.zeros(3))
    totals = []
    for n in (1, 7, 40):
        k = ContactKernel(seg, L, R_CABLE, SLIDING, n, n_elements=1, backend=backend)
        totals.append(k.evaluate(q, q_t).generalized_force[[1, 7]].sum())
    expected = -(L / 1e-3) * 1e6 * (3e-4) ** 1.5  # N1 + N3 = 1 along the element
    np.testing.assert_allclose(totals, expected, rtol=1e-12)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("route_name", list(ROUTES))
def test_cable_on_centreline_has_no_contact(backend, route_name):
    # polylines fine enough that their chords stay well inside the clearance (sagitta < 0.3 mm)
    route = {"straight": straight_route(), "bend": bend_route(n_arc=48),
             "helix": helix_route(n_seg=120)}[route_name]
    n_el = 20
    L = (route.length - 0.2) / n_el
    s = 0.1 + L * np.arange(n_el + 1)
    q = np.hstack([route.centre(s), route.tangent(s)]).reshape(-1)
    q_t = np.hstack([0.1 * route.tangent(s), np.zeros((n_el + 1, 3))]).reshape(-1)
    k = ContactKernel(route.segments, L, R_CABLE, SLIDING, 20, n_elements=n_el, backend=backend)
    res = k.evaluate(q, q_t, jacobian=True)
    assert res.n_in_contact == 0
    assert not res.generalized_force.any()
    assert not res.jac_q_blocks.any() and not res.jac_qt_blocks.any()
    assert res.max_penetration_m < 0


# ---------------------------------------------------------------------------------------------
# bookkeeping
# ---------------------------------------------------------------------------------------------

def test_block_sparsity_matches_dense_assembly():
    from scipy.sparse import coo_matrix

    rng = np.random.default_rng(5)
    blocks = rng.normal(size=(4, 12, 12))
    rows, cols = block_sparsity(4)
    n = 6 * 5
    sparse = coo_matrix((blocks.reshape(-1), (rows, cols)), shape=(n, n)).toarray()
    np.testing.assert_array_equal(sparse, assemble_blocks_dense(blocks))


@pytest.mark.parametrize("rule", ["gauss", "uniform"])
def test_check_points(rule):
    xi, w = check_points(5, rule)
    assert np.all((xi > 0) & (xi < 1)) and np.all(np.diff(xi) > 0)
    np.testing.assert_allclose(w.sum(), 1.0, rtol=1e-15)
    if rule == "gauss":  # exact for polynomials up to degree 2n - 1 = 9 on [0, 1]
        np.testing.assert_allclose(np.sum(w * xi**9), 0.1, rtol=1e-14)
    else:
        np.testing.assert_allclose(xi, (np.arange(5) + 0.5) / 5, rtol=1e-15)


def test_invalid_inputs_are_rejected():
    with pytest.raises(ValueError):
        ContactLaw(1e6, 1e3, 0.5, 0.3)  # exponent < 1
    with pytest.raises(ValueError):
        ContactLaw(1e6, 1e3, 1.5, 0.3, static_friction=0.2)  # μ_s < μ_k
    with pytest.raises(ValueError):
        check_points(3, "simpson")
    route = straight_route()
    with pytest.raises(ValueError):
        ContactKernel(route.segments, 0.1, R_CONDUIT, SLIDING, 4, n_elements=2)  # r = R
    with pytest.raises(ValueError):
        ContactKernel(route.segments, 0.1, R_CABLE, SLIDING, 4)  # no element count


def test_numba_cache_and_first_call_in_fresh_process():
    """The compiled kernel is cached on disk and a new process imports and runs it."""
    from exucable.contact import fast

    assert type(fast._contact_kernel.dispatcher._cache).__name__ != "NullCache"
    code = textwrap.dedent("""
        import numpy as np
        from exucable.contact import ContactKernel, ContactLaw
        from exucable.geometry.segments import Segments
        seg = Segments(np.array([[0.0, 0, 0], [1.0, 0, 0]]), np.array([0.0, 1.0]), 3.5e-3)
        k = ContactKernel(seg, 0.5, 2.5e-3, ContactLaw(1e6, 1e3, 1.5, 0.3, damping_onset_m=0.0), 8, n_elements=1,
                          backend="numba")
        q = np.array([0.1, 1.2e-3, 0, 1, 0, 0, 0.6, 1.2e-3, 0, 1, 0, 0])
        r = k.evaluate(q, np.zeros(12), jacobian=True)
        print(r.n_in_contact, r.generalized_force[1] < 0)
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["8", "True"]


def test_kernel_imports_and_runs_when_no_cache_directory_is_writable():
    """Numba finds no writable cache directory (simulated by offering it only a locator that
    never applies: IPython's): exucable warns once per compiled module, with the fix, instead of
    failing, and compiles in memory (checked on the broad phase, which compiles in a second; the
    kernel's own compilation takes tens of seconds and is the same code path)."""
    code = textwrap.dedent("""
        import warnings
        warnings.simplefilter("always")
        with warnings.catch_warnings(record=True) as caught:
            from exucable.contact import broadphase, fast
            fast._contact_kernel.dispatcher, fast._points_kernel.dispatcher, broadphase._element_boxes.dispatcher
        print(type(fast._contact_kernel.dispatcher._cache).__name__,
              len([w for w in caught if "NUMBA_CACHE_DIR" in str(w.message)]))
        import numpy as np
        lo, hi = np.empty((1, 3)), np.empty((1, 3))
        broadphase._element_boxes(np.array([0.0, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0]), np.array([1.0]),
                                  0.01, lo, hi)
        print(type(broadphase._element_boxes.dispatcher._cache).__name__, np.allclose(lo[0], [-0.01] * 3))
    """)
    env = dict(os.environ, NUMBA_CACHE_LOCATOR_CLASSES="IPythonCacheLocator")
    env.pop("NUMBA_CACHE_DIR", None)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, env=env)
    assert out.returncode == 0, out.stderr
    # one warning from the broad phase's module, one from the kernel's
    assert out.stdout.split() == ["NullCache", "2", "NullCache", "True"]
