"""The smooth wall (contact.surface = "smooth"): exact closest points on bends and helices."""

from __future__ import annotations

import numpy as np
import pytest

from exucable.contact import ContactKernel, ContactLaw, assemble_blocks_dense
from exucable.geometry import Bend, Conduit, Helix, Straight, centreline_from_path

R_CABLE, R_CONDUIT = 0.0025, 0.0035
GAP = R_CONDUIT - R_CABLE
LAW = ContactLaw(stiffness=1e6, damping=1e3, exponent=1.5, friction=0.2, damping_onset_m=0.0)  # Eq. 18


def conduit(kind, segments_per_bend=12):
    items = {"bend": [Straight(0.3), Bend(90, 0.5, "left"), Straight(0.3)],
             "helix": [Helix(1.25, 0.4, 0.3)],
             "sbend": [Straight(0.2), Bend(60, 0.4, "left"), Bend(45, 0.6, "up"), Straight(0.2)]}[kind]
    c = centreline_from_path([0, 0, 0], [1, 0, 0], items)
    return Conduit.build(R_CONDUIT, c, segments_per_bend=segments_per_bend)


def cable_on_offset_curve(cond, s_nodes, offset_dir, distance, speed=0.1, rng=None, noise=0.0):
    """Nodes on the curve C(s) + distance·u(s) with slopes along the centreline tangent."""
    c = cond.centreline
    t = c.tangent(s_nodes)
    u = offset_dir(s_nodes, t)
    pos = c.point(s_nodes) + distance * u
    vel = speed * t
    if rng is not None:
        vel = vel + rng.normal(scale=noise, size=vel.shape)
    q = np.hstack([pos, t]).reshape(-1)
    q_t = np.hstack([vel, np.zeros_like(t) if rng is None else rng.normal(scale=2 * noise, size=t.shape)]).reshape(-1)
    return q, q_t


def fd_jacobians(kernel, q, q_t, h_q=1e-8, h_v=1e-7):
    """∂Q/∂q and ∂Q/∂q̇ by central differences (steps [m, -] and [m/s, 1/s])."""
    n = q.size
    jq = np.zeros((n, n))
    jqt = np.zeros((n, n))
    for i in range(n):
        d = np.zeros(n)
        d[i] = h_q
        jq[:, i] = (kernel.evaluate(q + d, q_t).generalized_force - kernel.evaluate(q - d, q_t).generalized_force) / (2 * h_q)
        d[i] = h_v
        jqt[:, i] = (kernel.evaluate(q, q_t + d).generalized_force - kernel.evaluate(q, q_t - d).generalized_force) / (2 * h_v)
    return jq, jqt


def towards_centre(cond):
    def f(s, t):
        kn = cond.centreline.curvature_vector(s)
        n = np.linalg.norm(kn, axis=1, keepdims=True)
        return kn / n
    return f


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_points_at_a_known_distance_from_a_bend_get_exactly_that_penetration(backend):
    """Check points on a curve at distance GAP + δ0 from the bend's axis: the smooth wall gives
    δ = δ0 at every point (up to the Hermite interpolation of the cable between nodes, ~1e-8 m
    here), while the chords of the paper's wall give δ0 less up to the sagitta ρ(1-cos(Δθ/2))."""
    cond = conduit("bend", segments_per_bend=12)
    s_bend = 0.3 + 0.5 * np.pi / 2 * np.array([0.1, 0.9])
    s_nodes = np.linspace(*s_bend, 33)
    delta0 = 3e-4
    q, q_t = cable_on_offset_curve(cond, s_nodes, towards_centre(cond), GAP + delta0)
    L = np.diff(s_nodes) * (1 - (GAP + delta0) / 0.5)  # arc lengths of the offset curve (unit slopes)
    smooth = ContactKernel(cond.segments, L, R_CABLE, LAW, 16, backend=backend, surface="smooth",
                           centreline=cond.centreline)
    st = smooth.points(q, q_t)
    # the cable's axis radius is R_b - GAP - δ0; Hermite cubics with unit slopes on an arc of
    # 0.039 rad per element stay within ~1e-8 m of it (error ~ R φ⁴/100)
    np.testing.assert_allclose(st.penetration_m, delta0, atol=2e-8)
    segs = ContactKernel(cond.segments, L, R_CABLE, LAW, 16, backend=backend)
    sag = 0.5 * (1 - np.cos(np.radians(90 / 12) / 2))
    dev = segs.points(q, q_t).penetration_m - delta0
    # the chords lie between the arc and its centre: toward the centre they cut the penetration by
    # up to the sagitta
    assert dev.min() < -0.5 * sag and dev.max() < 1e-8 and dev.min() > -sag - 1e-8


@pytest.mark.parametrize("kind", ["bend", "helix", "sbend"])
def test_numba_equals_numpy_on_the_smooth_wall(kind):
    """Same forces and Jacobians from both backends (1e-11 relative: coordinates of order 1 m,
    penetrations of 1e-4 m, and a few Newton steps on the helix)."""
    cond = conduit(kind)
    rng = np.random.default_rng(3)
    L_total = cond.centreline.length_m
    s_nodes = np.linspace(0.1, L_total - 0.1, 7)
    def sideways(s, t):  # a fixed oblique direction across the tangent: inner, outer and side walls
        v = np.cross(t, [0.3, 0.2, 1.0])
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    q, q_t = cable_on_offset_curve(cond, s_nodes, sideways, GAP + 3e-4, rng=rng, noise=0.02)
    L = np.full(6, (s_nodes[-1] - s_nodes[0]) / 6)
    res = {}
    for backend in ("numpy", "numba"):
        k = ContactKernel(cond.segments, L, R_CABLE, LAW, 20, backend=backend, surface="smooth",
                          centreline=cond.centreline)
        res[backend] = k.evaluate(q, q_t, jacobian=True)
    a, b = res["numpy"], res["numba"]
    assert a.n_in_contact == b.n_in_contact > 10
    scale = np.abs(a.generalized_force).max()
    assert np.abs(a.generalized_force - b.generalized_force).max() <= 1e-11 * scale
    for ja, jb in ((a.jac_q_blocks, b.jac_q_blocks), (a.jac_qt_blocks, b.jac_qt_blocks)):
        assert np.abs(ja - jb).max() <= 1e-10 * np.abs(ja).max()


@pytest.mark.parametrize("kind", ["bend", "helix"])
def test_smooth_wall_jacobians_match_finite_differences(kind):
    """∂Q/∂q (including ∂(P − Pc)/∂P = I − T Tᵀ/(1 − r·κ) on the curve) and ∂Q/∂q̇ against central
    differences: steps 1e-8 / 1e-7, tolerance 1e-6 of max|J| (truncation (h/δ)² ≤ 1e-6 with
    δ ≥ 1e-4 m here; rounding ~1e-10)."""
    cond = conduit(kind, segments_per_bend=10)
    rng = np.random.default_rng(5)
    s0 = 0.35 if kind == "bend" else 0.5
    s_nodes = np.linspace(s0, s0 + 0.3, 3)
    q, q_t = cable_on_offset_curve(cond, s_nodes, towards_centre(cond), GAP + 3e-4, rng=rng, noise=0.02)
    L = np.diff(s_nodes)
    k = ContactKernel(cond.segments, L, R_CABLE, LAW, 6, backend="numpy", surface="smooth",
                      centreline=cond.centreline)
    st = k.points(q, q_t)
    assert st.in_contact.all() and np.all(st.penetration_m > 1e-4)
    res = k.evaluate(q, q_t, jacobian=True)
    jq_fd, jqt_fd = fd_jacobians(k, q, q_t)
    jq = assemble_blocks_dense(res.jac_q_blocks)
    jqt = assemble_blocks_dense(res.jac_qt_blocks)
    assert np.abs(jq - jq_fd).max() < 1e-6 * np.abs(jq).max()
    assert np.abs(jqt - jqt_fd).max() < 1e-6 * np.abs(jqt).max()


def test_smooth_wall_reports_exact_arc_length():
    """points().s_conduit_m is the centreline arc length of the exact closest point (1e-9 m)."""
    cond = conduit("bend", segments_per_bend=8)
    s_nodes = np.linspace(0.4, 0.9, 3)
    q, q_t = cable_on_offset_curve(cond, s_nodes, towards_centre(cond), GAP + 2e-4)
    k = ContactKernel(cond.segments, np.diff(s_nodes), R_CABLE, LAW, 5, backend="numpy", surface="smooth",
                      centreline=cond.centreline)
    st = k.points(q, q_t)
    # the closest point of P = C(s) + d·n(s) on the arc is C(s): compare with a dense search
    dense = np.linspace(0.3, 1.1, 200001)
    pts = cond.centreline.point(dense)
    for p, s in zip(st.position_m, st.s_conduit_m):
        assert abs(dense[np.argmin(np.sum((pts - p) ** 2, axis=1))] - s) < 1e-5


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_open_ends_do_not_hide_contact_behind_the_start_plane(backend):
    """A U-turn route whose return leg runs behind the first segment's start plane: points there
    are far from the open end and must still touch the wall, with or without the broad phase
    (regression: the open-end test was once made per candidate segment, so the brute-force search
    dropped them)."""
    c = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(1.0), Bend(180, 0.3, "left"), Straight(1.6)])
    cond = Conduit.build(R_CONDUIT, c, segments_per_bend=20)
    s_nodes = np.linspace(c.length_m - 1.2, c.length_m - 0.1, 6)   # on the return leg, x < 0 partly
    q, q_t = cable_on_offset_curve(cond, s_nodes, lambda s, t: np.tile([0.0, 0.0, -1.0], (len(s), 1)),
                                   GAP + 2e-4)
    L = np.diff(s_nodes)
    res = {}
    for bp in ("aabb", "none"):
        k = ContactKernel(cond.segments, L, R_CABLE, LAW, 8, backend=backend, broad_phase=bp,
                          surface="smooth", centreline=c)
        res[bp] = k.evaluate(q, q_t)
        assert res[bp].n_in_contact == 5 * 8
    np.testing.assert_array_equal(res["aabb"].generalized_force, res["none"].generalized_force)


ONSET = ContactLaw(stiffness=1e6, damping=1e3, exponent=1.5, friction=0.2, damping_onset_m=5e-4)


def onset_case():
    """Two elements in a bend, 3e-4 m into the wall (inside ONSET's 5e-4 m ramp), sliding with
    noise: (q, q_t, kernels by backend, the generator for more noise)."""
    cond = conduit("bend", segments_per_bend=10)
    rng = np.random.default_rng(7)
    s_nodes = np.linspace(0.35, 0.65, 3)
    q, q_t = cable_on_offset_curve(cond, s_nodes, towards_centre(cond), GAP + 3e-4, rng=rng, noise=0.02)
    L = np.diff(s_nodes)
    ks = {b: ContactKernel(cond.segments, L, R_CABLE, ONSET, 6, backend=b, surface="smooth",
                           centreline=cond.centreline) for b in ("numpy", "numba")}
    return q, q_t, ks, rng


def test_damping_onset_jacobians_and_backends_agree():
    """With a damping onset (f_n = K δ^e + C min(δ/δ_d, 1) δ̇; penetrations 3e-4 m inside the
    5e-4 m ramp) both backends agree (1e-11) and the Jacobians match central differences (same
    steps and 1e-6 bound as above)."""
    q, q_t, ks, rng = onset_case()
    a, b = (ks[x].evaluate(q, q_t, jacobian=True) for x in ("numpy", "numba"))
    assert np.abs(a.generalized_force - b.generalized_force).max() <= 1e-11 * np.abs(a.generalized_force).max()
    assert np.abs(a.jac_q_blocks - b.jac_q_blocks).max() <= 1e-10 * np.abs(a.jac_q_blocks).max()
    k = ks["numpy"]
    jq_fd, jqt_fd = fd_jacobians(k, q, q_t)
    assert np.abs(assemble_blocks_dense(a.jac_q_blocks) - jq_fd).max() < 1e-6 * np.abs(jq_fd).max()
    assert np.abs(assemble_blocks_dense(a.jac_qt_blocks) - jqt_fd).max() < 1e-6 * np.abs(jqt_fd).max()
    # and the force is continuous at first touch: the damping term vanishes with δ
    st = k.points(q, q_t)
    assert np.all(st.penetration_m < ONSET.damping_onset_m)


def test_held_damping_onset():
    """The dynamic solve holds the onset g within a step (ContactLaw's notes). Held at g(δ) of the
    same state the force is the same (1e-12); held at other values both backends agree and the
    Jacobians are those of f_n = K δ^e + C g δ̇ with g fixed (central differences, 1e-6), which
    differ from the live onset's by its ∂g/∂δ term."""
    q, q_t, ks, rng = onset_case()
    for k in ks.values():
        live = k.evaluate(q, q_t, jacobian=True)
        assert live.penetration_m.shape == (2, 6) and np.all(live.penetration_m > 0.0)
        np.testing.assert_allclose(live.penetration_m.reshape(-1), k.points(q, q_t).penetration_m, rtol=1e-12)
        g = k.damping_onset(live.penetration_m)
        np.testing.assert_allclose(g, live.penetration_m / ONSET.damping_onset_m, rtol=1e-12)
        same = k.evaluate(q, q_t, jacobian=True, held_onset=g)
        np.testing.assert_allclose(same.generalized_force, live.generalized_force, rtol=0,
                                   atol=1e-12 * np.abs(live.generalized_force).max())
        assert np.abs(same.jac_q_blocks - live.jac_q_blocks).max() > 1e-3 * np.abs(live.jac_q_blocks).max()
    held = rng.uniform(0.2, 1.0, size=(2, 6))
    a, b = (ks[x].evaluate(q, q_t, jacobian=True, held_onset=held) for x in ("numpy", "numba"))
    assert np.abs(a.generalized_force - b.generalized_force).max() <= 1e-11 * np.abs(a.generalized_force).max()
    assert np.abs(a.jac_q_blocks - b.jac_q_blocks).max() <= 1e-10 * np.abs(a.jac_q_blocks).max()
    assert np.abs(a.jac_qt_blocks - b.jac_qt_blocks).max() <= 1e-10 * np.abs(a.jac_qt_blocks).max()

    class Held:  # the numpy kernel with the onset held, for the differences
        def evaluate(self, q, q_t, jacobian=False):
            return ks["numpy"].evaluate(q, q_t, jacobian, held_onset=held)

    jq_fd, jqt_fd = fd_jacobians(Held(), q, q_t)
    assert np.abs(assemble_blocks_dense(a.jac_q_blocks) - jq_fd).max() < 1e-6 * np.abs(jq_fd).max()
    assert np.abs(assemble_blocks_dense(a.jac_qt_blocks) - jqt_fd).max() < 1e-6 * np.abs(jqt_fd).max()
    with pytest.raises(ValueError, match="held_onset has shape"):
        ks["numba"].evaluate(q, q_t, held_onset=np.ones(12))


def test_damping_onset_values():
    """g(δ) = min(δ/δ_d, 1) in contact, 0 out of it; 1 for the paper's law (δ_d = 0)."""
    from exucable.contact.law import damping_onset
    d = np.array([-1e-4, 0.0, 1e-4, 5e-4, 2e-3])
    np.testing.assert_allclose(damping_onset(ONSET, d), [0.0, 0.0, 0.2, 1.0, 1.0])
    np.testing.assert_array_equal(damping_onset(LAW, d), np.ones(5))


def cable_partly_in_contact(cond, seed=5):
    """(q, q̇, element lengths) of a cable along the conduit from a fifth of its length to 3 %
    past its open end, at a distance from the axis that varies along it (in contact with δ up to
    0.4 mm, and free), offset in random directions across the tangent."""
    length = cond.centreline.length_m
    s_nodes = np.linspace(0.2 * length, 1.03 * length, 21)  # the last node 3 % past the open end
    rng = np.random.default_rng(seed)
    distance = GAP + rng.uniform(-3e-4, 4e-4, size=(s_nodes.size, 1))
    c = cond.centreline
    inside = np.minimum(s_nodes, length)
    t = c.tangent(inside)
    e1 = np.cross(t, [0.3, 0.2, 1.0])
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(t, e1)
    angle = rng.uniform(0.0, 2.0 * np.pi, size=(s_nodes.size, 1))
    u = np.cos(angle) * e1 + np.sin(angle) * e2
    pos = c.point(inside) + distance * u + np.maximum(s_nodes - length, 0.0)[:, None] * t
    q = np.hstack([pos, t]).reshape(-1)
    q_t = np.hstack([0.1 * t + rng.normal(scale=0.02, size=t.shape),
                     rng.normal(scale=0.05, size=t.shape)]).reshape(-1)
    return q, q_t, np.linalg.norm(np.diff(pos, axis=0), axis=1)


@pytest.mark.parametrize("surface", ["segments", "smooth"])
@pytest.mark.parametrize("kind", ["bend", "helix", "sbend"])
def test_profiles_of_both_backends_agree(kind, surface):
    """ContactKernel.points() goes to the kernel's backend like every other call: the compiled
    profiles (segment, penetration, normal, arc length, forces, slip) equal the numpy reference's,
    on a cable partly in contact, partly free, with its lead pulled out past the conduit's end."""
    cond = conduit(kind)
    length = cond.centreline.length_m
    q, q_t, L = cable_partly_in_contact(cond)
    kw = dict(n_elements=L.size, surface=surface, centreline=cond.centreline)
    ref = ContactKernel(cond.segments, L, R_CABLE, LAW, 24, backend="numpy", **kw).points(q, q_t)
    fast = ContactKernel(cond.segments, L, R_CABLE, LAW, 24, backend="numba", **kw).points(q, q_t)
    assert ref.in_contact.sum() > 20 and (~ref.in_contact).sum() > 20
    assert ((ref.s_conduit_m >= length - 1e-12) | (ref.segment < 0)).any()  # the lead is out
    np.testing.assert_array_equal(fast.segment, ref.segment)
    np.testing.assert_array_equal(fast.in_contact, ref.in_contact)
    # same arithmetic up to the compiled kernel's reassociation: the residual P - Pc (mm) is a
    # difference of positions of metres, rounded at ~1e-15 m, which is 1e-12 of a millimetre;
    # normals, penetrations and forces inherit that: 1e-10 of each quantity's scale
    for name, scale in (("position_m", 1.0), ("velocity_m_per_s", 1.0), ("normal", 1.0),
                        ("s_conduit_m", length), ("penetration_m", GAP),
                        ("normal_force_N", np.max(ref.normal_force_N)),
                        ("normal_force_per_length_N_per_m", np.max(ref.normal_force_per_length_N_per_m)),
                        ("sliding_velocity_m_per_s", 0.1), ("friction_force_N", np.max(ref.friction_force_N))):
        a, b = getattr(fast, name), getattr(ref, name)
        assert np.array_equal(np.isnan(a), np.isnan(b)), name
        assert np.nanmax(np.abs(a - b)) <= 1e-10 * scale, name


@pytest.mark.parametrize("surface", ["segments", "smooth"])
@pytest.mark.parametrize("kind", ["bend", "helix", "sbend"])
def test_compiled_profiles_are_the_numpy_definitions_bits(kind, surface):
    """From one point state, the compiled profiles (exucable.contact.profiles) give exactly the
    numpy definition's penetration, normal and arc length (the same operations in the same order;
    the result files must not change by an ulp), for points in contact, free, past the open end
    and outside every segment."""
    from exucable.contact.profiles import point_profiles

    cond = conduit(kind)
    q, q_t, L = cable_partly_in_contact(cond, seed=11)
    k = ContactKernel(cond.segments, L, R_CABLE, LAW, 24, backend="numba", n_elements=L.size,
                      surface=surface, centreline=cond.centreline)
    st = k._point_state(q, q_t)
    p, seg, residual = st["position_m"], st["segment"].copy(), st["residual_m"].copy()
    seg[:5], residual[:5] = -1, np.nan                  # as the kernel reports points outside
    beyond = np.all(residual == 0.0, axis=1)            # past the open end: Pc = P
    assert beyond.any() and (seg >= 0).sum() > 100
    ref = k._profiles_numpy(p, seg, residual)
    got = point_profiles(p, seg, residual, k.gap_m, k.segments, k.wall)
    for name, a, b in zip(("penetration_m", "normal", "s_conduit_m"), got, ref):
        np.testing.assert_array_equal(a, b, err_msg=name)


@pytest.mark.parametrize("kind", ["bend", "helix", "sbend"])
def test_closest_point_angles_from_the_residual_match_newtons(kind):
    """The profiles' arc length takes Pc's helix angle from the residual the kernel found (a polar
    angle, no iteration): the same angle as refine_closest_points' Newton iteration (~1e-12 rad),
    on the pieces and past their ends (clamped), for points anywhere in the conduit."""
    from exucable.contact.smooth import SmoothWall, closest_point_angles, refine_closest_points

    cond = conduit(kind, segments_per_bend=12)
    seg = cond.segments
    wall = SmoothWall(cond.centreline, seg)
    rng = np.random.default_rng(7)
    s = rng.uniform(0.0, cond.centreline.length_m, 400)
    p = cond.centreline.point(s) + rng.uniform(-GAP, GAP, (s.size, 3))
    d = p[:, None, :] - seg.start_m[None]
    t_all = np.clip(np.einsum("ijk,jk->ij", d, seg.axis), 0.0, seg.length_m)
    foot = seg.start_m[None] + t_all[..., None] * seg.axis[None]
    nearest = np.argmin(np.sum((p[:, None, :] - foot) ** 2, axis=2), axis=1)
    t = t_all[np.arange(s.size), nearest]
    mask, residual, _, phi = refine_closest_points(p, nearest, t, seg.length_m, wall)
    assert mask.sum() > 100
    mask2, phi2 = closest_point_angles(p, residual, nearest, t, seg.length_m, wall)
    np.testing.assert_array_equal(mask2, mask)
    np.testing.assert_allclose(phi2[mask], phi[mask], rtol=0.0, atol=1e-11)


def test_segment_sectors_are_the_segments_angular_sides():
    """The compiled bend refinement skips the angle test for a point strictly inside its segment's
    sector: the table holds (cos, sin) of each segment's end angles, and zero sides (no point is
    ever inside) for a segment spanning π/2 or more."""
    from exucable.contact.kernel_parts import segment_sectors

    phi = np.array([[0.0, 0.1], [0.1, 0.2], [0.0, 2.0], [0.0, 0.0]])
    table = segment_sectors(phi)
    np.testing.assert_array_equal(table[:, :2], phi)
    np.testing.assert_allclose(table[0, 2:], [1.0, 0.0, np.cos(0.1), np.sin(0.1)], rtol=0, atol=1e-16)
    np.testing.assert_allclose(table[1, 2:], [np.cos(0.1), np.sin(0.1), np.cos(0.2), np.sin(0.2)], rtol=0, atol=1e-16)
    np.testing.assert_array_equal(table[2, 2:], 0.0)


def test_bend_ends_and_segment_joints_agree_with_numpy():
    """Check points densely across a bend's start and end and the joints between its chords
    (inside their nearest segment's sector, on its sides, and past the bend's ends): the compiled
    penetration, normal and arc length equal the numpy reference's (1e-12, round-off of metre
    positions)."""
    cond = conduit("bend", segments_per_bend=12)
    c = cond.centreline
    for s0 in (0.3, 0.3 + 0.5 * np.pi / 2):  # the bend's start and end
        s_nodes = np.linspace(s0 - 0.15, s0 + 0.15, 5)  # chords of 0.065 m
        # offset in the bend's plane, toward its centre: in contact with the inner wall
        q, q_t = cable_on_offset_curve(cond, s_nodes, lambda s, t: np.cross([0.0, 0.0, 1.0], t), GAP + 2e-4)
        L = np.diff(s_nodes)
        kw = dict(surface="smooth", centreline=c)
        ref = ContactKernel(cond.segments, L, R_CABLE, LAW, 400, backend="numpy", **kw).points(q, q_t)
        fast = ContactKernel(cond.segments, L, R_CABLE, LAW, 400, backend="numba", **kw).points(q, q_t)
        np.testing.assert_array_equal(fast.segment, ref.segment)
        assert len(np.unique(ref.segment)) >= 3  # a straight and at least two chords of the bend
        assert ref.in_contact.all()
        for name in ("penetration_m", "normal", "s_conduit_m"):
            assert np.abs(getattr(fast, name) - getattr(ref, name)).max() <= 1e-12, name
