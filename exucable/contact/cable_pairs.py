"""Contact between cables pulled together through one conduit: Hertz normal force, Coulomb friction.

The law is the cable-conduit one (paper Eqs. 18-20, :class:`~exucable.contact.ContactLaw`) with the
conduit's wall replaced by another cable's axis:

- every cable carries check points at ξ_k = (k + ½)/n_k of each element (equal weights); the
  check points of one cable, in order, make a polyline that stands for its axis (chord error
  L_k²κ/8, sub-micron at the spacings used);
- a check point P of cable a meets cable b (a < b) at the closest point C = (1 - t) B0 + t B1 of
  the nearest segment [B0, B1] of b's polyline (t clamped to [0, 1]); d = |P - C|,
  δ = 2r - d (two cables of radius r), n = (P - C)/d;
- f_n = w K δ^e with w = (the point's share of the element length)/h_ref, as at the wall; the
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
G ≈ √(2·window) segments, each in a bounding ball: a block whose ball lies farther from P than a
segment already found is skipped, so it finds the full scan's segment (the same one, ties included)
in about 2√(2·window) tests instead of 2·window (at 69 check points per element, window 209:
a pass 26 → 3.4 ms).
A closest segment at the window's edge (not at a cable's end) is counted (``at_window_edge``), so
that a run whose cables slid apart along the route by more than the window says so.

Jacobians are exact for the chosen segment and clamping (the force is piecewise smooth): with
x = (P, B0, B1), ∂d/∂x = Aᵀn, A = [I, -(1 - t) I, -t I], and ∂²d/∂x² = Aᵀ(I - nnᵀ)R/d + [0; n; -n]
∂t/∂x, R = ∂r/∂x, r = P - C. :func:`pair_contacts_reference` is the numpy definition;
:func:`_pair_contacts` the compiled loop (tested equal, ``tests/test_cable_pairs.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .checkpoints import hermite_unit
from .jitcache import njit
from .law import ContactLaw
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
        ``damping`` C and ``damping_onset_m`` δ_d.

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
                if not delta > 0.0 or d <= 0.0:
                    continue
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
                f = w * K * delta ** ex
                df = -w * K * ex * delta ** (ex - 1.0) * g                        # ∂f/∂x
                swap = np.concatenate([np.zeros(3), n, -n])                       # ∂(Aᵀn)/∂t
                H = A.T @ dn + np.outer(swap, dt)                                 # ∂²d/∂x²
                u = np.concatenate([U[i], U[b * n_points + j], U[b * n_points + j + 1]])
                v = A @ u
                dfu = np.zeros(9)                                                 # ∂f/∂u
                if C > 0.0:
                    rate = -(n @ v)                                               # δ̇
                    on, don = (1.0, 0.0) if dd <= 0.0 else ((delta / dd, 1.0 / dd) if delta < dd else (1.0, 0.0))
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
def _pair_contacts(X, U, n_cables, n_points, window, gap, weight, K, ex, mu, eps2, C, dd, jacobian,
                   index, tpar, pen, force, jac_x, jac_u, edge):
    """Compiled :func:`pair_contacts_reference`; fills the output arrays, returns the contact count."""
    m = 0
    # the search's blocks: G consecutive segments of a polyline inside a bounding ball (centre,
    # radius); a block whose ball is farther from P than a segment already found cannot hold the
    # nearest one and is skipped, so the result is the full window scan's, at a fraction of its cost
    G = max(4, int(np.sqrt(2.0 * window + 1.0)))
    n_seg = n_points - 1
    nb = max(1, (n_seg + G - 1) // G)
    cen = np.zeros((n_cables, nb, 3))
    rad = np.zeros((n_cables, nb))
    for b in range(n_cables):
        ob = b * n_points
        for k in range(nb):
            j0 = k * G
            j1 = min(j0 + G, n_seg)
            for v in range(j0, j1 + 1):
                for l in range(3):
                    cen[b, k, l] += X[ob + v, l]
            for l in range(3):
                cen[b, k, l] /= j1 - j0 + 1
            r2 = 0.0
            for v in range(j0, j1 + 1):
                dx = X[ob + v, 0] - cen[b, k, 0]
                dy = X[ob + v, 1] - cen[b, k, 1]
                dz = X[ob + v, 2] - cen[b, k, 2]
                r2 = max(r2, dx * dx + dy * dy + dz * dz)
            rad[b, k] = np.sqrt(r2)
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
                # an upper bound on the nearest distance: the block of the last point's nearest
                # segment (or of p's own index)
                guess = previous if first <= previous < last else min(max(p, first), last - 1)
                kg = guess // G
                ub = np.inf
                for j in range(max(first, kg * G), min(last, kg * G + G)):
                    d2 = _segment_distance2(X, ob + j, px, py, pz)[1]
                    if d2 < ub:
                        ub = d2
                reach = np.sqrt(ub) + 1e-9
                best_j, best_t, best_d2 = -1, 0.0, np.inf
                for k in range(first // G, (last - 1) // G + 1):
                    if k != kg:
                        dx = px - cen[b, k, 0]
                        dy = py - cen[b, k, 1]
                        dz = pz - cen[b, k, 2]
                        if np.sqrt(dx * dx + dy * dy + dz * dz) - rad[b, k] > reach:
                            continue
                    for j in range(max(first, k * G), min(last, k * G + G)):
                        t, d2 = _segment_distance2(X, ob + j, px, py, pz)
                        if d2 < best_d2:
                            best_j, best_t, best_d2 = j, t, d2
                if best_j < 0:
                    continue
                previous = best_j
                d = np.sqrt(best_d2)
                delta = gap - d
                if not delta > 0.0 or d <= 0.0:
                    continue
                j = best_j
                t = best_t
                e = X[ob + j + 1] - X[ob + j]
                c = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
                av = X[i] - X[ob + j]
                r = av - t * e
                n = r / d
                A = np.zeros((3, 9))
                for k in range(3):
                    A[k, k] = 1.0
                    A[k, 3 + k] = -(1.0 - t)
                    A[k, 6 + k] = -t
                dt = np.zeros(9)
                if 0.0 < t < 1.0:
                    for k in range(3):
                        q = (av[k] - 2.0 * t * e[k]) / c
                        dt[k] = e[k] / c
                        dt[3 + k] = -e[k] / c - q
                        dt[6 + k] = q
                g = np.zeros(9)
                for k in range(3):
                    g[k] = n[k]
                    g[3 + k] = -(1.0 - t) * n[k]
                    g[6 + k] = -t * n[k]
                w = weight[p]
                f = w * K * delta ** ex
                u = np.empty(9)
                for k in range(3):
                    u[k] = U[i, k]
                    u[3 + k] = U[ob + j, k]
                    u[6 + k] = U[ob + j + 1, k]
                v = np.zeros(3)
                for k in range(3):
                    v[k] = u[k] - (1.0 - t) * u[3 + k] - t * u[6 + k]
                vn = n[0] * v[0] + n[1] * v[1] + n[2] * v[2]
                on, don = 1.0, 0.0
                if C > 0.0:
                    if dd > 0.0 and delta < dd:
                        on, don = delta / dd, 1.0 / dd
                    f = f + w * C * on * (-vn)
                    if not f > 0.0:
                        continue
                vt = v - vn * n
                h = 1.0 / np.sqrt(vt[0] * vt[0] + vt[1] * vt[1] + vt[2] * vt[2] + eps2)
                Ff = -mu * f * h * vt
                for k in range(9):
                    force[m, k] = f * g[k]
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
                    # ∂r/∂x = [I, -I, 0] - t [0, -I, I] - e ⊗ ∂t/∂x
                    dr = np.zeros((3, 9))
                    for k in range(3):
                        dr[k, k] = 1.0
                        dr[k, 3 + k] = -1.0 + t
                        dr[k, 6 + k] = -t
                        for l in range(9):
                            dr[k, l] -= e[k] * dt[l]
                    Pn = np.eye(3) - np.outer(n, n)
                    dn = (Pn @ dr) / d
                    coef = -w * K * ex * delta ** (ex - 1.0)
                    df = coef * g
                    dfu = np.zeros(9)
                    if C > 0.0:
                        drate = -(v @ dn + n @ np.outer(u[3:6] - u[6:9], dt))
                        df = df + w * C * (-don * (-vn) * g + on * drate)
                        dfu = -w * C * on * g
                    swap = np.zeros(9)
                    for k in range(3):
                        swap[3 + k] = n[k]
                        swap[6 + k] = -n[k]
                    H = A.T @ dn + np.outer(swap, dt)
                    M = h * np.eye(3) - h * h * h * np.outer(vt, vt)
                    dv_dx = np.outer(u[3:6] - u[6:9], dt)
                    dvt_dx = Pn @ dv_dx - (np.outer(n, v) + vn * np.eye(3)) @ dn
                    dFf_dx = -mu * np.outer(h * vt, df) - mu * f * (M @ dvt_dx)
                    fswap = np.zeros(9)
                    for k in range(3):
                        fswap[3 + k] = Ff[k]
                        fswap[6 + k] = -Ff[k]
                    jac_x[m] = np.outer(g, df) + f * H + A.T @ dFf_dx + np.outer(fswap, dt)
                    jac_u[m] = np.outer(g, dfu) + A.T @ (-mu * np.outer(h * vt, dfu) - mu * f * (M @ (Pn @ A)))
                m += 1
    return m


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
        one = sparse.csr_matrix((vals, (rows, cols)), shape=(3 * self.n_points, self.n_coordinates_per_cable))
        done = sparse.csr_matrix((dvals, (rows, cols)), shape=one.shape)
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

    def points(self, q, q_t=None):
        """Check point positions [m] and velocities [m/s], each (n_cables·n_points, 3): the
        steady-sliding V ∂r/∂x, or with the nodal rates ``q_t`` (a dynamic state) S q̇."""
        q = np.asarray(q, dtype=float).reshape(-1)
        if q_t is not None:
            return (self.S @ q).reshape(-1, 3), (self.S @ np.asarray(q_t, dtype=float).reshape(-1)).reshape(-1, 3)
        return (self.S @ q).reshape(-1, 3), (self.speed_m_per_s * (self.dS @ q)).reshape(-1, 3)

    def contacts(self, q, jacobian: bool = False, q_t=None) -> dict:
        """Every contact at absolute coordinates ``q`` (see :func:`pair_contacts_reference`), the
        points' velocities from the rates ``q_t`` when given (:meth:`points`)."""
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
                           index, t, pen, force, jx, ju, edge)
        out = {"index": index[:m].copy(), "t": t[:m].copy(), "penetration_m": pen[:m].copy(),
               "force": force[:m].copy(), "edge": edge[:m].copy()}
        out["jac_x"] = jx[:m].copy() if jacobian else np.zeros((0, 9, 9))
        out["jac_u"] = ju[:m].copy() if jacobian else np.zeros((0, 9, 9))
        return out

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

        c = self.contacts(q, jacobian, q_t)
        n3 = 3 * self.n_points * self.n_cables
        dof = (3 * c["index"][:, :, None] + np.arange(3)[None, None, :]).reshape(-1, 9)   # (m, 9)
        f_pts = np.bincount(dof.reshape(-1), weights=c["force"].reshape(-1), minlength=n3)
        Q = self.St @ f_pts
        J = J_t = None
        if jacobian:
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

