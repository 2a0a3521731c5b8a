"""Contact between cables pulled together through one conduit: Hertz normal force, Coulomb friction.

The law is the cable-conduit one (paper Eqs. 18-20, :class:`~exucable.contact.ContactLaw`) with the
conduit's wall replaced by another cable's axis:

- every cable carries check points at ξ_k = (k + ½)/n_k of each element (equal weights); the
  check points of one cable, in order, make a polyline that stands for its axis (chord error
  L_k²κ/8, sub-micron at the spacings used);
- a check point P of cable a meets cable b (a < b) at the closest point C = (1 - t) B0 + t B1 of
  the nearest segment [B0, B1] of b's polyline (t clamped to [0, 1]); d = |P - C|,
  δ = 2r - d (two cables of radius r), n = (P - C)/d;
- f_n = w K φ^e with w = (the point's share of the element length)/h_ref, as at the wall, and
  φ = φ_s(δ) the penetration blended over the law's onset layer s (δ itself for s = 0, the points
  touching for δ > -s; :func:`~exucable.contact.law.onset_blend`); the
  normal force on P is +f_n n, on B0 and B1 -(1 - t) f_n n and -t f_n n (action and reaction);
- friction -μ_c f_n v_τ/√(|v_τ|² + ε²) on the relative velocity v = U_P - (1 - t) U0 - t U1,
  v_τ = (I - n nᵀ) v, with the cables' own coefficient μ_c (``contact.cable_friction``), shared
  likewise.

- the normal law's damping, as at the wall (Eq. 18 with the onset of ``contact.damping_onset``):
  f_n = w max(0, K δ^e + C g(δ) δ̇), δ̇ = -n·v, g = min(δ/δ_d, 1) of the current δ (not held within
  a step as at the wall: its derivative is in the Jacobian). Without it a cable dropped onto
  another bounces on the elastic Hertz law for seconds (a dynamic run's top cable of a trefoil:
  the pull swung ±40 % after 2 s); in steady sliding, where all cables flow at the pull speed,
  the model passes C = 0.

The points' velocities: in steady sliding U = V ∂r/∂x (the material flows along a fixed shape);
in a dynamic run U = S q̇, the nodal rates mapped to the point, and ∂Q/∂q̇ = Sᵀ (∂F/∂U) S.

Broad phase: the cables are meshed alike and laid side by side, so the check point at index p of
one cable lies beside the points near index p of the others. Only the segments within ``window``
indices of p are searched, linear in the route length. The compiled search goes by blocks of
G = g² segments, each in a bounding ball and split into g sub-blocks of g segments in balls of their
own (g ≈ (2·window/3)^⅓): a block or sub-block whose ball lies farther from P than a segment already
found (the previous point's nearest segment and its neighbours, the first candidates, not evaluated
again) or than the onset layer's edge gap + s (no contact beyond it) is skipped, so it finds the full
scan's segment wherever there is a contact (the same one, ties included: the segments left are scanned
in index order, and one equal to a candidate wins if its index is lower) in about
3·(2·window/3)^⅓ tests instead of 2·window (at 69 check points per element, window 209: a pass 26 →
3.4 ms with one level of blocks; on the 100 m three-cable route, 60 check points, window 182: 5.2 →
2.4 ms with two, the same contacts bit for bit).
A closest segment at the window's edge (not at a cable's end) is counted (``at_window_edge``), so
that a run whose cables slid apart along the route by more than the window says so.

Jacobians are exact for the chosen segment and clamping (the force is piecewise smooth): with
x = (P, B0, B1), ∂d/∂x = Aᵀn, A = [I, -(1 - t) I, -t I], and ∂²d/∂x² = Aᵀ(I - nnᵀ)R/d + [0; n; -n]
∂t/∂x, R = ∂r/∂x, r = P - C. :func:`pair_contacts_reference` is the numpy definition;
:func:`_pair_contacts` the compiled loop (tested equal, ``tests/test_cable_pairs.py``), its Jacobian
entry by entry into scratch arrays (the reference's ~57 small arrays per contact, allocated in a
compiled loop, were two thirds of a pass). On the cables' coordinates the Jacobian is Sᵀ J S (S the
Hermite map from coordinates to check points): the numpy path multiplies sparse matrices, the compiled
one sums each contact's blocks into 6 × 6 node blocks (:func:`_add_blocks`), a third of the pair
coupling's time before (the 100 m route with three cables: 40 of 100 ms per Newton iteration).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .checkpoints import hermite_unit
from .jitcache import njit
from .law import ContactLaw, onset_blend
from .steady import hermite_unit_derivative

__all__ = ["CableContactKernel", "CableContactResult", "pair_contacts_reference", "cable_check_points"]

_JIT = dict(fastmath=False, nogil=True, error_model="numpy")


def cable_check_points(n: int) -> np.ndarray:
    """ξ_k = (k + ½)/n [-]: equally spaced check points of one element (weights 1/n)."""
    return (np.arange(n) + 0.5) / n


@dataclass
class CableContactResult:
    """Output of :meth:`CableContactKernel.evaluate`.

    Attributes
    ----------
    generalized_force : ndarray (n_coordinates,)
        Contact forces between the cables on all cables' coordinates [N, N·m].
    jacobian : scipy.sparse.csr_matrix or None
        ∂Q/∂q [N/m, ...], the velocity's dependence on q (steady sliding) included.
    n_in_contact : int
        Check points in contact with another cable.
    max_penetration_m : float
        Largest δ [m] (-inf without contact).
    at_window_edge : int
        Contacts whose nearest segment lies at the broad phase's window edge.
    jacobian_t : scipy.sparse.csr_matrix or None
        ∂Q/∂q̇ [N·s/m, ...] of a dynamic evaluation (velocities from the nodal rates); None in
        steady sliding, whose velocities follow from q.
    """

    generalized_force: np.ndarray
    jacobian: object
    n_in_contact: int
    max_penetration_m: float
    at_window_edge: int
    jacobian_t: object = None


def _segment_search(P, X, first, last):
    """Nearest segment of the polyline X[first..last] to P: (j, t, squared distance)."""
    best_j, best_t, best_d2 = -1, 0.0, np.inf
    for j in range(first, last):
        e = X[j + 1] - X[j]
        a = P - X[j]
        c = e @ e
        t = 0.0 if c <= 0.0 else min(1.0, max(0.0, (a @ e) / c))
        r = a - t * e
        d2 = r @ r
        if d2 < best_d2:
            best_j, best_t, best_d2 = j, t, d2
    return best_j, best_t, best_d2


def pair_contacts_reference(X, U, n_cables, n_points, window, gap, weight, law: ContactLaw,
                            jacobian=True):
    """All cable-cable contacts, plain numpy (the tested definition).

    Parameters
    ----------
    X, U : ndarray (n_cables·n_points, 3)
        Check point positions [m] and velocities [m/s], cable by cable, each in order along it.
    n_cables, n_points : int
    window : int
        Broad phase half-width in check point indices.
    gap : float
        Sum of the two cables' radii [m].
    weight : ndarray (n_points,)
        w of each check point [-].
    law : ContactLaw
        ``stiffness``, ``exponent``, ``friction`` (the cables' μ_c), ``regularisation_velocity_m_per_s``,
        ``damping`` C, ``damping_onset_m`` δ_d and ``onset_layer_m`` s.

    Returns
    -------
    dict of arrays: ``index`` (m, 3) global point indices (P, B0, B1), ``t`` (m,), ``penetration_m``
    (m,), ``force`` (m, 9) on (P, B0, B1) [N], ``jac_x`` and ``jac_u`` (m, 9, 9) [N/m, N·s/m],
    ``edge`` (m,) bool.
    """
    X = np.asarray(X, dtype=float)
    U = np.asarray(U, dtype=float)
    K, ex, mu = law.stiffness, law.exponent, law.friction
    C, dd = law.damping, law.damping_onset_m
    layer = law.onset_layer_m
    eps2 = law.regularisation_velocity_m_per_s ** 2
    I3 = np.eye(3)
    rows = {k: [] for k in ("index", "t", "penetration_m", "force", "jac_x", "jac_u", "edge")}
    for a in range(n_cables):
        for b in range(a + 1, n_cables):
            Xb = X[b * n_points:(b + 1) * n_points]
            for p in range(n_points):
                i = a * n_points + p
                first = max(0, p - window)
                last = min(n_points - 1, p + window)
                j, t, d2 = _segment_search(X[i], Xb, first, last)
                if j < 0:
                    continue
                d = np.sqrt(d2)
                delta = gap - d
                if not delta > -layer or d <= 0.0:
                    continue
                phi, dphi = (float(x) for x in onset_blend(delta, layer))
                B0, B1 = Xb[j], Xb[j + 1]
                P = X[i]
                e = B1 - B0
                c = e @ e
                r = P - B0 - t * e
                n = r / d
                clamped = t <= 0.0 or t >= 1.0
                A = np.hstack([I3, -(1.0 - t) * I3, -t * I3])                  # (3, 9)
                if clamped:
                    dt = np.zeros(9)
                else:
                    a_vec = P - B0
                    dt = np.concatenate([e / c, -e / c - (a_vec - 2.0 * t * e) / c, (a_vec - 2.0 * t * e) / c])
                dr = np.hstack([I3, -I3, np.zeros((3, 3))]) - t * np.hstack([np.zeros((3, 3)), -I3, I3]) \
                    - np.outer(e, dt)                                            # ∂r/∂x (3, 9)
                Pn = I3 - np.outer(n, n)
                dn = Pn @ dr / d                                                  # ∂n/∂x (3, 9)
                g = A.T @ n                                                       # ∂d/∂x
                w = weight[p]
                f = w * K * phi ** ex
                df = -w * K * ex * phi ** (ex - 1.0) * dphi * g                   # ∂f/∂x
                swap = np.concatenate([np.zeros(3), n, -n])                       # ∂(Aᵀn)/∂t
                H = A.T @ dn + np.outer(swap, dt)                                 # ∂²d/∂x²
                u = np.concatenate([U[i], U[b * n_points + j], U[b * n_points + j + 1]])
                v = A @ u
                dfu = np.zeros(9)                                                 # ∂f/∂u
                if C > 0.0:
                    rate = -(n @ v)                                               # δ̇
                    on, don = (1.0, 0.0) if dd <= 0.0 else ((phi / dd, dphi / dd) if phi < dd else (1.0, 0.0))
                    f = f + w * C * on * rate
                    if not f > 0.0:
                        continue                                                  # the damping lets go
                    drate = -(v @ dn + n @ np.outer(u[3:6] - u[6:9], dt))         # ∂δ̇/∂x
                    df = df + w * C * (-don * rate * g + on * drate)
                    dfu = -w * C * on * g
                vt = Pn @ v
                h = 1.0 / np.sqrt(vt @ vt + eps2)
                Ff = -mu * f * h * vt
                force = f * g + A.T @ Ff
                rows["index"].append([i, b * n_points + j, b * n_points + j + 1])
                rows["t"].append(t)
                rows["penetration_m"].append(delta)
                rows["force"].append(force)
                rows["edge"].append((j == first and first > 0) or (j == last - 1 and last < n_points - 1))
                if jacobian:
                    M = h * I3 - h ** 3 * np.outer(vt, vt)                        # ∂(h v_τ)/∂v_τ
                    dv_dx = np.outer(u[3:6] - u[6:9], dt)                          # ∂v/∂x via t
                    dvt_dx = Pn @ dv_dx - (np.outer(n, v) + (n @ v) * I3) @ dn
                    dFf_dx = -mu * np.outer(h * vt, df) - mu * f * M @ dvt_dx
                    jx = np.outer(g, df) + f * H + A.T @ dFf_dx + np.outer(np.concatenate([np.zeros(3), Ff, -Ff]), dt)
                    ju = np.outer(g, dfu) + A.T @ (-mu * np.outer(h * vt, dfu) - mu * f * M @ Pn @ A)
                    rows["jac_x"].append(jx)
                    rows["jac_u"].append(ju)
    m = len(rows["t"])
    return {
        "index": np.asarray(rows["index"], dtype=np.int64).reshape(m, 3),
        "t": np.asarray(rows["t"], dtype=float),
        "penetration_m": np.asarray(rows["penetration_m"], dtype=float),
        "force": np.asarray(rows["force"], dtype=float).reshape(m, 9),
        "jac_x": np.asarray(rows["jac_x"], dtype=float).reshape(m if jacobian else 0, 9, 9),
        "jac_u": np.asarray(rows["jac_u"], dtype=float).reshape(m if jacobian else 0, 9, 9),
        "edge": np.asarray(rows["edge"], dtype=bool),
    }


@njit(**_JIT)
def _segment_distance2(X, j, px, py, pz):
    """(t, squared distance) of P = (px, py, pz) to the segment [X[j], X[j + 1]] (t clamped to [0, 1])."""
    ex_ = X[j + 1, 0] - X[j, 0]
    ey_ = X[j + 1, 1] - X[j, 1]
    ez_ = X[j + 1, 2] - X[j, 2]
    ax = px - X[j, 0]
    ay = py - X[j, 1]
    az = pz - X[j, 2]
    c = ex_ * ex_ + ey_ * ey_ + ez_ * ez_
    t = 0.0
    if c > 0.0:
        t = min(1.0, max(0.0, (ax * ex_ + ay * ey_ + az * ez_) / c))
    rx = ax - t * ex_
    ry = ay - t * ey_
    rz = az - t * ez_
    return t, rx * rx + ry * ry + rz * rz


@njit(**_JIT)
def _hermite_points(q, n_cables, n_el, n_k, coef, out):
    """S q without the sparse matrix: out[c·n_points + p, i] = Σ_a coef[p, a] q[slot a of point p's
    element, i] of cable c, summed in S's stored order (a = 0..3 after 0.0, as scipy's CSR product
    does: the same bits)."""
    n_points = n_el * n_k
    n1 = 6 * (n_el + 1)
    for c in range(n_cables):
        for e in range(n_el):
            b = c * n1 + 6 * e
            for k in range(n_k):
                p = e * n_k + k
                row = c * n_points + p
                for i in range(3):
                    s = 0.0
                    s += coef[p, 0] * q[b + i]
                    s += coef[p, 1] * q[b + 3 + i]
                    s += coef[p, 2] * q[b + 6 + i]
                    s += coef[p, 3] * q[b + 9 + i]
                    out[row, i] = s


@njit(**_JIT)
def _hermite_transpose(f, n_cables, n_el, n_k, coef, out):
    """Sᵀ f without the sparse matrix (f: 3 per point, all cables): each coordinate of node n sums its
    points in increasing order (element n - 1's, then element n's), as Sᵀ's stored rows do."""
    n_points = n_el * n_k
    n1 = 6 * (n_el + 1)
    for c in range(n_cables):
        for node in range(n_el + 1):
            for slot in range(2):
                # the three components side by side (contiguous in f), each summed in that order
                s0 = 0.0
                s1 = 0.0
                s2 = 0.0
                if node >= 1:
                    for k in range(n_k):
                        p = (node - 1) * n_k + k
                        cf = coef[p, 2 + slot]
                        base = 3 * (c * n_points + p)
                        s0 += cf * f[base]
                        s1 += cf * f[base + 1]
                        s2 += cf * f[base + 2]
                if node < n_el:
                    for k in range(n_k):
                        p = node * n_k + k
                        cf = coef[p, slot]
                        base = 3 * (c * n_points + p)
                        s0 += cf * f[base]
                        s1 += cf * f[base + 1]
                        s2 += cf * f[base + 2]
                o = c * n1 + 6 * node + 3 * slot
                out[o] = s0
                out[o + 1] = s1
                out[o + 2] = s2


@njit(**_JIT)
def _beyond(centre, radius, px, py, pz, reach):
    """Whether the ball (``centre``, ``radius``) lies farther than ``reach`` from P (squared distances)."""
    dx = px - centre[0]
    dy = py - centre[1]
    dz = pz - centre[2]
    lim = reach + radius
    return dx * dx + dy * dy + dz * dz > lim * lim


@njit(**_JIT)
def _point_forces(index, force, m, out):
    """Each check point's force (3 per point, all cables) summed from the contacts' ``force`` (m, 9)
    on their points ``index`` (m, 3), in the contacts' order: numpy's ``bincount`` of the same
    entries, bit for bit, without its index and weight arrays."""
    for c in range(m):
        for al in range(3):
            base = 3 * index[c, al]
            for k in range(3):
                out[base + k] += force[c, 3 * al + k]


@njit(**_JIT)
def _balls(X, ob, n_seg, size, n_blocks, cen, rad):
    """Bounding balls (centre ``cen`` (n_blocks, 3), radius ``rad``) of the polyline X[ob..]'s blocks
    of ``size`` consecutive segments (each ball holds its segments' end points, so the segments)."""
    for k in range(n_blocks):
        j0 = k * size
        j1 = min(j0 + size, n_seg)
        for v in range(j0, j1 + 1):
            for l in range(3):
                cen[k, l] += X[ob + v, l]
        for l in range(3):
            cen[k, l] /= j1 - j0 + 1
        r2 = 0.0
        for v in range(j0, j1 + 1):
            dx = X[ob + v, 0] - cen[k, 0]
            dy = X[ob + v, 1] - cen[k, 1]
            dz = X[ob + v, 2] - cen[k, 2]
            r2 = max(r2, dx * dx + dy * dy + dz * dz)
        rad[k] = np.sqrt(r2)


@njit(**_JIT)
def _pair_contacts(X, U, n_cables, n_points, window, gap, weight, K, ex, mu, eps2, C, dd, jacobian,
                   index, tpar, pen, force, jac_x, jac_u, edge, layer):
    """Compiled :func:`pair_contacts_reference`; fills the output arrays, returns the contact count."""
    m = 0
    # the search's blocks, on two levels: G = g² consecutive segments of a polyline inside a bounding
    # ball (centre, radius), each split into g sub-blocks of g segments in balls of their own; a
    # (sub-)block whose ball is farther from P than a segment already found cannot hold the nearest
    # one and is skipped, so the result is the full window scan's, at a fraction of its cost
    g = max(2, int(((2.0 * window + 1.0) / 3.0) ** (1.0 / 3.0) + 0.5))
    G = g * g
    n_seg = n_points - 1
    nb = max(1, (n_seg + G - 1) // G)
    ns = max(1, (n_seg + g - 1) // g)
    cen = np.zeros((n_cables, nb, 3))
    rad = np.zeros((n_cables, nb))
    scen = np.zeros((n_cables, ns, 3))
    srad = np.zeros((n_cables, ns))
    for b in range(n_cables):
        ob = b * n_points
        _balls(X, ob, n_seg, G, nb, cen[b], rad[b])
        _balls(X, ob, n_seg, g, ns, scen[b], srad[b])
    dr, dn, dvt, dFf = np.empty((3, 9)), np.empty((3, 9)), np.empty((3, 9)), np.empty((3, 9))
    df, dfu, M, MPn = np.empty(9), np.empty(9), np.empty((3, 3)), np.empty((3, 3))
    e, av, n, v, vt, Ff = np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    dt, g9, u = np.empty(9), np.empty(9), np.empty(9)
    for a in range(n_cables):
        for b in range(a + 1, n_cables):
            ob = b * n_points
            previous = -1
            for p in range(n_points):
                i = a * n_points + p
                first = max(0, p - window)
                last = min(n_points - 1, p + window)
                if last <= first:
                    continue
                px, py, pz = X[i, 0], X[i, 1], X[i, 2]
                # an upper bound on the nearest distance: the last point's nearest segment and its
                # neighbours (or p's own index), kept as the first candidates (not evaluated again);
                # no farther than the layer's edge gap + s, beyond which a point has no contact
                guess = previous if first <= previous < last else min(max(p, first), last - 1)
                g0 = max(first, guess - 1)
                g1 = min(last, guess + 2)
                best_j, best_t, best_d2 = -1, 0.0, np.inf
                for j in range(g0, g1):
                    t, d2 = _segment_distance2(X, ob + j, px, py, pz)
                    if d2 < best_d2:
                        best_j, best_t, best_d2 = j, t, d2
                reach = min(np.sqrt(best_d2), gap + layer) + 1e-9
                for k in range(first // G, (last - 1) // G + 1):
                    if _beyond(cen[b, k], rad[b, k], px, py, pz, reach):
                        continue
                    for sk in range(k * g, min(k * g + g, ns)):
                        j0 = max(first, sk * g)
                        j1 = min(last, sk * g + g)
                        if j0 >= j1 or _beyond(scen[b, sk], srad[b, sk], px, py, pz, reach):
                            continue
                        for j in range(j0, j1):
                            if g0 <= j < g1:
                                continue
                            t, d2 = _segment_distance2(X, ob + j, px, py, pz)
                            # the lowest index among equals, as the scan in index order finds it
                            if d2 < best_d2 or (d2 == best_d2 and j < best_j):
                                best_j, best_t, best_d2 = j, t, d2
                if best_j < 0:
                    continue
                previous = best_j
                d = np.sqrt(best_d2)
                delta = gap - d
                if not delta > -layer or d <= 0.0:
                    continue
                # φ_s(δ), dφ_s/dδ (law.onset_blend)
                phi, dphi = delta, 1.0
                if layer > 0.0:
                    if delta < layer:
                        y = delta + layer
                        phi, dphi = y * y / (4.0 * layer), y / (2.0 * layer)
                j = best_j
                t = best_t
                for k in range(3):
                    e[k] = X[ob + j + 1, k] - X[ob + j, k]
                    av[k] = X[i, k] - X[ob + j, k]
                    n[k] = (av[k] - t * e[k]) / d
                c = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
                for k in range(9):
                    dt[k] = 0.0
                if 0.0 < t < 1.0:
                    for k in range(3):
                        q = (av[k] - 2.0 * t * e[k]) / c
                        dt[k] = e[k] / c
                        dt[3 + k] = -e[k] / c - q
                        dt[6 + k] = q
                for k in range(3):
                    g9[k] = n[k]
                    g9[3 + k] = -(1.0 - t) * n[k]
                    g9[6 + k] = -t * n[k]
                w = weight[p]
                f = w * K * phi ** ex
                for k in range(3):
                    u[k] = U[i, k]
                    u[3 + k] = U[ob + j, k]
                    u[6 + k] = U[ob + j + 1, k]
                for k in range(3):
                    v[k] = u[k] - (1.0 - t) * u[3 + k] - t * u[6 + k]
                vn = n[0] * v[0] + n[1] * v[1] + n[2] * v[2]
                on, don = 1.0, 0.0
                if C > 0.0:
                    if dd > 0.0 and phi < dd:
                        on, don = phi / dd, dphi / dd
                    f = f + w * C * on * (-vn)
                    if not f > 0.0:
                        continue
                for k in range(3):
                    vt[k] = v[k] - vn * n[k]
                h = 1.0 / np.sqrt(vt[0] * vt[0] + vt[1] * vt[1] + vt[2] * vt[2] + eps2)
                for k in range(3):
                    Ff[k] = -mu * f * h * vt[k]
                for k in range(9):
                    force[m, k] = f * g9[k]
                for k in range(3):
                    force[m, k] += Ff[k]
                    force[m, 3 + k] -= (1.0 - t) * Ff[k]
                    force[m, 6 + k] -= t * Ff[k]
                index[m, 0] = i
                index[m, 1] = ob + j
                index[m, 2] = ob + j + 1
                tpar[m] = t
                pen[m] = delta
                edge[m] = (j == first and first > 0) or (j == last - 1 and last < n_points - 1)
                if jacobian:
                    # the formulas of pair_contacts_reference entry by entry into scratch arrays
                    # allocated once per call (a 3 × 9 or 9 × 9 product per line there)
                    a0, a1, a2 = 1.0, -(1.0 - t), -t
                    # ∂r/∂x = [I, -(1 - t) I, -t I] - e ⊗ ∂t/∂x and ∂n/∂x = (I - n nᵀ) ∂r/∂x / d
                    for l in range(9):
                        for k in range(3):
                            dr[k, l] = -e[k] * dt[l]
                    for k in range(3):
                        dr[k, k] += a0
                        dr[k, 3 + k] += a1
                        dr[k, 6 + k] += a2
                    for l in range(9):
                        s_n = n[0] * dr[0, l] + n[1] * dr[1, l] + n[2] * dr[2, l]
                        for k in range(3):
                            dn[k, l] = (dr[k, l] - n[k] * s_n) / d
                    coef = -w * K * ex * phi ** (ex - 1.0) * dphi
                    ud0, ud1, ud2 = u[3] - u[6], u[4] - u[7], u[5] - u[8]      # U0 - U1
                    for l in range(9):
                        df[l] = coef * g9[l]
                        dfu[l] = 0.0
                    if C > 0.0:
                        n_ud = n[0] * ud0 + n[1] * ud1 + n[2] * ud2
                        for l in range(9):
                            drate = -(v[0] * dn[0, l] + v[1] * dn[1, l] + v[2] * dn[2, l] + n_ud * dt[l])
                            df[l] += w * C * (-don * (-vn) * g9[l] + on * drate)
                            dfu[l] = -w * C * on * g9[l]
                    # M = ∂(h v_τ)/∂v_τ; ∂v_τ/∂x = (I - n nᵀ)(U0 - U1) ⊗ ∂t/∂x - (n vᵀ + (n·v) I) ∂n/∂x
                    for k in range(3):
                        for j in range(3):
                            M[k, j] = -h * h * h * vt[k] * vt[j]
                        M[k, k] += h
                    n_ud = n[0] * ud0 + n[1] * ud1 + n[2] * ud2
                    pud0, pud1, pud2 = ud0 - n[0] * n_ud, ud1 - n[1] * n_ud, ud2 - n[2] * n_ud
                    for l in range(9):
                        s_v = v[0] * dn[0, l] + v[1] * dn[1, l] + v[2] * dn[2, l]
                        dvt[0, l] = pud0 * dt[l] - n[0] * s_v - vn * dn[0, l]
                        dvt[1, l] = pud1 * dt[l] - n[1] * s_v - vn * dn[1, l]
                        dvt[2, l] = pud2 * dt[l] - n[2] * s_v - vn * dn[2, l]
                    # ∂F_f/∂x = -μ (h v_τ) ⊗ ∂f/∂x - μ f M ∂v_τ/∂x
                    for l in range(9):
                        for k in range(3):
                            dFf[k, l] = -mu * (h * vt[k]) * df[l] - mu * f * (
                                M[k, 0] * dvt[0, l] + M[k, 1] * dvt[1, l] + M[k, 2] * dvt[2, l])
                    # M (I - n nᵀ), for ∂Q/∂u
                    for k in range(3):
                        Mn = M[k, 0] * n[0] + M[k, 1] * n[1] + M[k, 2] * n[2]
                        for j in range(3):
                            MPn[k, j] = M[k, j] - Mn * n[j]
                    # jac_x = g ⊗ ∂f/∂x + f (Aᵀ ∂n/∂x + [0; n; -n] ⊗ ∂t/∂x) + Aᵀ ∂F_f/∂x + [0; F_f; -F_f] ⊗ ∂t/∂x
                    # jac_u = g ⊗ ∂f/∂u + Aᵀ (-μ (h v_τ) ⊗ ∂f/∂u - μ f M (I - n nᵀ) A)
                    for blk in range(3):
                        ab = a0 if blk == 0 else (a1 if blk == 1 else a2)
                        for k in range(3):
                            r_ = 3 * blk + k
                            sw = 0.0 if blk == 0 else (n[k] if blk == 1 else -n[k])
                            fs = 0.0 if blk == 0 else (Ff[k] if blk == 1 else -Ff[k])
                            for l in range(9):
                                jac_x[m, r_, l] = (g9[r_] * df[l] + f * (ab * dn[k, l] + sw * dt[l])
                                                   + ab * dFf[k, l] + fs * dt[l])
                            for blk2 in range(3):
                                ac = a0 if blk2 == 0 else (a1 if blk2 == 1 else a2)
                                for j in range(3):
                                    l = 3 * blk2 + j
                                    jac_u[m, r_, l] = g9[r_] * dfu[l] + ab * (-mu * (h * vt[k]) * dfu[l]
                                                                            - mu * f * (MPn[k, j] * ac))
                m += 1
    return m


@njit(**_JIT)
def _add_blocks(index, jac, m, n_points, n_k, n_nodes, row_coef, col_coef, scale, W, acc, used):
    """Adds Sᵀ J S of the contacts' 9 × 9 blocks ``jac[:m]`` to the node blocks ``acc``.

    A point p of a cable lies on element e = p // n_k; its position is Σ_a coef[p, a] times slot a
    of that element's coordinates (a = 0, 2: the nodes' positions, 1, 3: their slopes), so the
    contact's block of points (α, β) adds coef_row[p_α, a] coef_col[p_β, b] ``scale`` times it to
    the 3 × 3 part of the 6 × 6 block of the nodes (of slots a and b). Node blocks are stored as
    ``acc[row node, column cable, column node - row node's index + W]`` (node indices within each
    cable), ``used`` marks them.
    """
    cab = np.empty(3, dtype=np.int64)
    pt = np.empty(3, dtype=np.int64)
    el = np.empty(3, dtype=np.int64)
    for c in range(m):
        # each point's cable, its index on it and its element once per contact: the integer
        # divisions were the pass's largest cost when done in the column loop (72 per contact)
        for al in range(3):
            ga = index[c, al]
            cab[al] = ga // n_points
            pt[al] = ga - cab[al] * n_points
            el[al] = pt[al] // n_k
        for al in range(3):
            cab_a = cab[al]
            pa = pt[al]
            ea = el[al]
            for a in range(4):
                ca = row_coef[pa, a]
                if ca == 0.0:
                    continue
                na = ea + a // 2
                rs = 3 * (a % 2)
                rnode = cab_a * n_nodes + na
                for be in range(3):
                    cab_b = cab[be]
                    pb = pt[be]
                    eb = el[be]
                    for b in range(4):
                        cb = col_coef[pb, b]
                        if cb == 0.0:
                            continue
                        off = eb + b // 2 - na + W
                        if off < 0 or off > 2 * W:
                            raise ValueError("cable-cable contact beyond the Jacobian's node window")
                        cs = 3 * (b % 2)
                        f = ca * cb * scale
                        used[rnode, cab_b, off] = True
                        for i in range(3):
                            for j in range(3):
                                acc[rnode, cab_b, off, rs + i, cs + j] += f * jac[c, 3 * al + i, 3 * be + j]


@njit(**_JIT)
def _emit_blocks(acc, used, n_nodes, W, rows, cols, vals):
    """The used node blocks of ``acc`` (:func:`_add_blocks`) as triplets (their zeros left out),
    zeroing them for the next pass; returns the count."""
    k = 0
    n_rows, n_cab, n_off = used.shape
    for rn in range(n_rows):
        local = rn % n_nodes
        for cb in range(n_cab):
            for off in range(n_off):
                if not used[rn, cb, off]:
                    continue
                used[rn, cb, off] = False
                cn = cb * n_nodes + local + off - W
                for i in range(6):
                    for j in range(6):
                        x = acc[rn, cb, off, i, j]
                        if x != 0.0:
                            rows[k] = 6 * rn + i
                            cols[k] = 6 * cn + j
                            vals[k] = x
                            k += 1
                        acc[rn, cb, off, i, j] = 0.0
    return k


class CableContactKernel:
    """Contact forces between ``n_cables`` equally meshed cables and their exact Jacobian.

    Parameters
    ----------
    n_cables : int
    element_length_m : array_like (n_el,)
        Material element lengths L_e [m], the same for every cable.
    cable_radius_m : float
        r [m]; two cables touch at axis distance 2r.
    law : ContactLaw
        Stiffness K [N/m^e] per reference spacing, exponent e, the cables' friction μ_c and the
        regularisation velocity ε [m/s].
    check_points_per_element : int
    reference_spacing_m : float
        h_ref [m] (``contact.reference_spacing``): w = (L_e/n_k)/h_ref, as at the wall.
    speed_m_per_s : float
        Pull speed V [m/s]: in steady sliding a point moves with U = V ∂r/∂x.
    window : int, optional
        Broad phase half-width in check points (default: n_k + 2, i.e. a little more than one
        element either side).
    backend : {"numba", "numpy"}
    """

    def __init__(self, n_cables, element_length_m, cable_radius_m, law: ContactLaw,
                 check_points_per_element: int, reference_spacing_m: float, speed_m_per_s: float,
                 window: int | None = None, backend: str = "numba"):
        from scipy import sparse

        if backend not in ("numba", "numpy"):
            raise ValueError(f"backend must be 'numba' or 'numpy', got {backend!r}")
        self.n_cables = int(n_cables)
        self.element_length_m = np.asarray(element_length_m, dtype=float)
        self.n_el = len(self.element_length_m)
        self.n_k = int(check_points_per_element)
        self.radius_m = float(cable_radius_m)
        self.base_law = law
        self.law = law
        self.speed_m_per_s = float(speed_m_per_s)
        self.window = int(self.n_k + 2 if window is None else window)
        self.backend = backend
        self.n_points = self.n_el * self.n_k
        self.n_coordinates_per_cable = 6 * (self.n_el + 1)
        self.n_coordinates = self.n_cables * self.n_coordinates_per_cable
        xi = cable_check_points(self.n_k)
        self.weight = np.repeat(self.element_length_m / self.n_k / reference_spacing_m, self.n_k)
        # S: point positions from one cable's coordinates; S': L·∂r/∂x there, divided by L_e below
        N = hermite_unit(xi)                                 # (n_k, 4)
        dN = hermite_unit_derivative(xi)
        rows, cols, vals, dvals = [], [], [], []
        for e in range(self.n_el):
            Le = self.element_length_m[e]
            for k in range(self.n_k):
                p = e * self.n_k + k
                for a in range(4):
                    node = e + a // 2
                    slope = a % 2 == 1
                    scale = Le if slope else 1.0
                    for i in range(3):
                        rows.append(3 * p + i)
                        cols.append(6 * node + (3 if slope else 0) + i)
                        vals.append(N[k, a] * scale)
                        dvals.append(dN[k, a] * scale / Le)
        # the same maps per point and slot (n_points, 4), for the compiled assembly (_add_blocks)
        slot = np.where(np.arange(4) % 2 == 1, 1.0, 0.0)[None, :]
        Le_p = np.repeat(self.element_length_m, self.n_k)[:, None]
        scale_p = 1.0 + slot * (Le_p - 1.0)
        self._coef = np.ascontiguousarray(np.tile(N, (self.n_el, 1)) * scale_p)
        self._coef_d = np.ascontiguousarray(np.tile(dN, (self.n_el, 1)) * scale_p / Le_p)
        self._acc = None
        one = sparse.csr_matrix((vals, (rows, cols)), shape=(3 * self.n_points, self.n_coordinates_per_cable))
        done = sparse.csr_matrix((dvals, (rows, cols)), shape=one.shape)
        # S's and S''s values per point and slot, in their stored order (for _hermite_points)
        self._s_coef = np.ascontiguousarray(one.data.reshape(self.n_points, 3, 4)[:, 0, :])
        self._ds_coef = np.ascontiguousarray(done.data.reshape(self.n_points, 3, 4)[:, 0, :])
        self.S = sparse.block_diag([one] * self.n_cables, format="csr")
        self.dS = sparse.block_diag([done] * self.n_cables, format="csr")
        self.St = self.S.T.tocsr()
        m = self.n_points * self.n_cables * (self.n_cables - 1) // 2
        self._buffers = (np.zeros((m, 3), dtype=np.int64), np.zeros(m), np.zeros(m), np.zeros((m, 9)),
                         np.zeros((m, 9, 9)), np.zeros((m, 9, 9)), np.zeros(m, dtype=np.bool_))

    def set_friction_scale(self, scale: float) -> None:
        """Scale μ_c by ``scale`` [-] (the steady solve's continuation parameter)."""
        from dataclasses import replace
        self.law = replace(self.base_law, friction=scale * self.base_law.friction)

    def set_onset_layer(self, layer_m: float) -> None:
        """The contact onset's layer s [m] (:func:`~exucable.contact.law.onset_blend`; 0: the law
        without one), kept by :meth:`set_friction_scale`."""
        from dataclasses import replace
        layer = float(layer_m)
        if not 0.0 <= layer < self.radius_m:
            raise ValueError(f"onset layer {layer!r} m must be in [0, the cable radius {self.radius_m:g} m)")
        self.base_law = replace(self.base_law, onset_layer_m=layer)
        self.law = replace(self.law, onset_layer_m=layer)

    def points(self, q, q_t=None):
        """Check point positions [m] and velocities [m/s], each (n_cables·n_points, 3): the
        steady-sliding V ∂r/∂x, or with the nodal rates ``q_t`` (a dynamic state) S q̇."""
        q = np.asarray(q, dtype=float).reshape(-1)
        if q_t is not None:
            return self._map(self._s_coef, q), self._map(self._s_coef, np.asarray(q_t, dtype=float).reshape(-1))
        return self._map(self._s_coef, q), self.speed_m_per_s * self._map(self._ds_coef, q)

    def _map(self, coef, q) -> np.ndarray:
        """S q (or S' q) as (n_cables·n_points, 3), compiled (the sparse product's bits, 8x faster)."""
        out = np.empty((self.n_cables * self.n_points, 3))
        _hermite_points(np.ascontiguousarray(q, dtype=float), self.n_cables, self.n_el, self.n_k, coef, out)
        return out

    def contacts(self, q, jacobian: bool = False, q_t=None, copy: bool = True) -> dict:
        """Every contact at absolute coordinates ``q`` (see :func:`pair_contacts_reference`), the
        points' velocities from the rates ``q_t`` when given (:meth:`points`). ``copy=False``:
        the compiled backend's arrays are views of its buffers, overwritten by the next call."""
        X, U = self.points(q, q_t)
        law = self.law
        if self.backend == "numpy":
            return pair_contacts_reference(X, U, self.n_cables, self.n_points, self.window, 2.0 * self.radius_m,
                                           self.weight, law, jacobian)
        index, t, pen, force, jx, ju, edge = self._buffers
        m = _pair_contacts(X, U, self.n_cables, self.n_points, self.window, 2.0 * self.radius_m, self.weight,
                           float(law.stiffness), float(law.exponent), float(law.friction),
                           float(law.regularisation_velocity_m_per_s) ** 2, float(law.damping),
                           float(law.damping_onset_m), bool(jacobian),
                           index, t, pen, force, jx, ju, edge, float(law.onset_layer_m))
        keep = (lambda a: a[:m].copy()) if copy else (lambda a: a[:m])
        out = {"index": keep(index), "t": keep(t), "penetration_m": keep(pen), "force": keep(force), "edge": keep(edge)}
        out["jac_x"] = keep(jx) if jacobian else np.zeros((0, 9, 9))
        out["jac_u"] = keep(ju) if jacobian else np.zeros((0, 9, 9))
        return out

    def _assemble(self, parts, index):
        """Σ scale · Sᵀ J C over ``parts`` (J (m, 9, 9), the column map C's per-point coefficients
        ``_coef`` for S or ``_coef_d`` for S' (steady sliding's velocity), scale) as a CSR matrix on
        all cables' coordinates (:func:`_add_blocks`)."""
        from scipy import sparse

        n_nodes = self.n_el + 1
        W = (self.window + 1) // self.n_k + 3      # node offsets a contact's blocks can span
        if self._acc is None:
            self._acc = (np.zeros((self.n_cables * n_nodes, self.n_cables, 2 * W + 1, 6, 6)),
                         np.zeros((self.n_cables * n_nodes, self.n_cables, 2 * W + 1), dtype=np.bool_))
        acc, used = self._acc
        m = len(index)
        for jac, col, scale in parts:
            _add_blocks(index, jac, m, self.n_points, self.n_k, n_nodes, self._coef, col, float(scale), W, acc, used)
        size = 36 * int(np.count_nonzero(used))
        rows, cols, vals = np.empty(size, dtype=np.int64), np.empty(size, dtype=np.int64), np.empty(size)
        k = _emit_blocks(acc, used, n_nodes, W, rows, cols, vals)
        n = self.n_coordinates
        return sparse.csr_matrix((vals[:k], (rows[:k], cols[:k])), shape=(n, n))

    def point_forces_N(self, q, q_t=None) -> tuple[np.ndarray, np.ndarray]:
        """Each cable's contact load from the other cables, check point by check point.

        The force of a contact on its point P and, as reaction, on the two check points B0, B1 of the
        other cable's polyline (shares 1 - t, t) is summed per check point, so that
        Σ_k S(ξ_k)ᵀ F_k is :meth:`evaluate`'s generalized force exactly: the loads a cable's
        equilibrium (:func:`exucable.post.tension.equilibrium_tension`) needs from the others.

        Returns
        -------
        x_m : ndarray (n_points,)
            The check points' material coordinates from each cable's trailing end [m] (the same on
            every cable).
        force_N : ndarray (n_cables, n_points, 3)
            The force on each cable's check points [N].
        """
        c = self.contacts(q, q_t=q_t)
        f = np.zeros((self.n_cables * self.n_points, 3))
        np.add.at(f, c["index"].reshape(-1), c["force"].reshape(-1, 3))
        x_nodes = np.concatenate([[0.0], np.cumsum(self.element_length_m)])
        p = np.arange(self.n_points)
        e = p // self.n_k
        x = x_nodes[e] + cable_check_points(self.n_k)[p % self.n_k] * self.element_length_m[e]
        return x, f.reshape(self.n_cables, self.n_points, 3)

    def evaluate(self, q, jacobian: bool = True, q_t=None) -> CableContactResult:
        """Generalized contact force on all cables and (optionally) its exact Jacobian ∂Q/∂q; with
        the nodal rates ``q_t`` (a dynamic state) the points move with S q̇ and the Jacobian comes
        as ∂Q/∂q and ∂Q/∂q̇ (``jacobian_t``)."""
        from scipy import sparse

        c = self.contacts(q, jacobian, q_t, copy=False)
        n3 = 3 * self.n_points * self.n_cables
        f_pts = np.zeros(n3)
        _point_forces(c["index"], c["force"], len(c["index"]), f_pts)
        Q = np.empty(self.n_coordinates)
        _hermite_transpose(f_pts, self.n_cables, self.n_el, self.n_k, self._s_coef, Q)       # Sᵀ f
        J = J_t = None
        if jacobian and self.backend == "numba":
            # Sᵀ J S summed into node blocks in one compiled pass (the same sums as the sparse
            # products below, in another order: round-off only)
            # without friction and damping between the cables ∂Q/∂u is zero entry by entry (its
            # terms are multiples of μ_c and C), so its sweep would add zeros only (half the cost)
            moving = self.law.friction != 0.0 or self.law.damping != 0.0
            J = self._assemble([(c["jac_x"], self._coef, 1.0)] + (
                [(c["jac_u"], self._coef_d, self.speed_m_per_s)] if q_t is None and moving else []), c["index"])
            if q_t is not None:
                J_t = self._assemble([(c["jac_u"], self._coef, 1.0)], c["index"])
        elif jacobian:
            dof = (3 * c["index"][:, :, None] + np.arange(3)[None, None, :]).reshape(-1, 9)   # (m, 9)
            r = np.broadcast_to(dof[:, :, None], (len(dof), 9, 9)).reshape(-1)
            k = np.broadcast_to(dof[:, None, :], (len(dof), 9, 9)).reshape(-1)
            Jx = sparse.csr_matrix((c["jac_x"].reshape(-1), (r, k)), shape=(n3, n3))
            Ju = sparse.csr_matrix((c["jac_u"].reshape(-1), (r, k)), shape=(n3, n3))
            if q_t is None:
                J = (self.St @ (Jx @ self.S) + self.speed_m_per_s * (self.St @ (Ju @ self.dS))).tocsr()
            else:
                J, J_t = (self.St @ (Jx @ self.S)).tocsr(), (self.St @ (Ju @ self.S)).tocsr()
        pen = c["penetration_m"]
        return CableContactResult(Q, J, int(len(pen)), float(pen.max()) if len(pen) else -np.inf,
                                  int(np.count_nonzero(c["edge"])), J_t)

