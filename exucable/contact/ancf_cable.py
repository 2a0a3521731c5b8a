"""The elastic forces of Exudyn's 3D ANCF cable element and their exact Jacobian, compiled.

The steady solve may assemble the cable itself (``[solver] cable_element = "compiled"``) instead
of adding Exudyn ``ObjectANCFCable`` objects: Exudyn differentiates its element by automatic
differentiation over positions *and* velocities, even in a static solve, which was about half of a
Newton iteration on long routes (``benchmarks/newton_floor.py``). The formulation here is the one of
Exudyn's ``CObjectANCFCable::ComputeODE2LHStemplate`` (Exudyn 1.x, ``main/src/Objects/
CObjectANCFCable.cpp``), as :mod:`exucable.model.cable` configures it: absolute strain and curvature
(``strainIsRelativeToReference = 0``, no reference axial strain), no internal damping (steady mode
drops it), and per element of length L, coordinates q = [r_i, r'_i, r_j, r'_j] (paper Eqs. 2-13):

- axial strain ε = |r'| − 1, virtual work EA·ε·δε, by Gauss order 9 (5 points; ``full``), order 7
  (4 points; ``reduced``) or Lobatto order 3 (3 points: ends and middle; ``lobatto``);
- curvature vector κ = (r' × r'') / |r'|² (Exudyn's material measure), virtual work EJ·κ·δκ, by
  Gauss order 5 (3 points; ``full``) or order 3 (2 points; ``reduced``, ``lobatto``);

with r' = S'(x) q, r'' = S''(x) q and Exudyn's cubic Hermite shape functions. The generalized
force is the left-hand side Q_e(q) = ∂U/∂q of the strain energy U = ½∫(EA ε² + EJ |κ|²) dx; its
Jacobian ∂Q_e/∂q (the element's tangent stiffness) is derived by hand:

- axial, at a point: EA·S'ᵀ [φ I + r' r'ᵀ / |r'|³] S', φ = (|r'| − 1) / |r'|;
- bending, with z = (r', r'') and B = [S'; S''] (6 × 12): EJ·Bᵀ (AᵀA + H) B, A = ∂κ/∂z and
  H = Σ_k κ_k ∂²κ_k/∂z² (below, ``_bending_point``).

:func:`elastic_forces_numpy` is the reference, written with numpy; :func:`elastic_forces` runs the
compiled kernel. ``tests/test_ancf_compiled.py`` checks both against Exudyn's element (its
residual and its system Jacobian) and the Jacobian against finite differences of the force.
"""

from __future__ import annotations

import functools

import numpy as np

from .jitcache import njit

__all__ = ["AncfCableForces", "elastic_forces", "elastic_forces_numpy", "quadrature", "INTEGRATIONS"]

INTEGRATIONS = ("full", "reduced", "lobatto")


def quadrature(integration: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Exudyn's rules of the axial and the bending term for ``cable.integration``: points ξ ∈ [0, 1]
    and weights summing to 1 (times L) as ``(axial_xi, axial_w, bending_xi, bending_w)``."""
    if integration not in INTEGRATIONS:
        raise ValueError(f"integration must be one of {INTEGRATIONS}, got {integration!r}")
    return tuple(a.copy() for a in _quadrature(integration))


@functools.lru_cache(maxsize=None)
def _quadrature(integration: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`quadrature`'s rules, computed once each (numpy's ``leggauss`` takes an eigensolve:
    0.2 ms a call, a tenth of a wall pass of 100 elements)."""
    n_axial, n_bending = {"full": (5, 3), "reduced": (4, 2), "lobatto": (0, 2)}[integration]
    if n_axial:
        x, w = np.polynomial.legendre.leggauss(n_axial)
    else:
        x, w = np.array([-1.0, 0.0, 1.0]), np.array([1.0, 4.0, 1.0]) / 3.0
    xb, wb = np.polynomial.legendre.leggauss(n_bending)
    return 0.5 * (x + 1.0), 0.5 * w, 0.5 * (xb + 1.0), 0.5 * wb


def _shape_x(x, L):
    """dS/dx of Exudyn's shape functions [N1, N2, N3, N4] at x [m] (arrays broadcast)."""
    return np.stack([-6.0 * x / L**2 + 6.0 * x**2 / L**3, 1.0 - 4.0 * x / L + 3.0 * x**2 / L**2,
                     6.0 * x / L**2 - 6.0 * x**2 / L**3, -2.0 * x / L + 3.0 * x**2 / L**2], axis=-1)


def _shape_xx(x, L):
    """d²S/dx² of the shape functions at x [m]."""
    return np.stack([12.0 * x / L**3 - 6.0 / L**2, 6.0 * x / L**2 - 4.0 / L,
                     6.0 / L**2 - 12.0 * x / L**3, 6.0 * x / L**2 - 2.0 / L], axis=-1)


def _skew(v):
    """[v]× for vectors v (..., 3): [v]× u = v × u."""
    z = np.zeros(v.shape[:-1])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], -1), np.stack([v[..., 2], z, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], z], -1)], -2)


def elastic_forces_numpy(q, lengths_m, axial_stiffness_N: float, bending_stiffness_N_m2: float,
                         integration: str, jacobian: bool = True):
    """The cable's elastic generalized forces and element tangent stiffnesses, with numpy.

    Parameters
    ----------
    q : array_like (n_el + 1, 6) or (6 (n_el + 1),)
        Absolute nodal coordinates [r, r'] [m, -].
    lengths_m : array_like (n_el,)
        Element lengths L [m].
    axial_stiffness_N, bending_stiffness_N_m2 : float
        EA [N] and EJ [N m²].
    integration : {"full", "reduced", "lobatto"}
        Exudyn's ``useReducedOrderIntegration`` 0, 1, 2 (:func:`quadrature`).
    jacobian : bool
        Also the blocks ∂Q_e/∂q.

    Returns
    -------
    force : ndarray (6 (n_el + 1),)
        Q_e [N, N m], the left-hand side (the force the cable's elasticity needs from its loads).
    blocks : ndarray (n_el, 12, 12) or None
        ∂Q_e/∂q per element [N/m, N], on [r_i, r'_i, r_j, r'_j].
    """
    L = np.asarray(lengths_m, dtype=float)
    n_el = L.size
    qe = np.asarray(q, dtype=float).reshape(-1, 6)
    qe = np.concatenate([qe[:-1], qe[1:]], axis=1).reshape(n_el, 4, 3)
    F = np.zeros((n_el, 4, 3))
    K = np.zeros((n_el, 4, 3, 4, 3)) if jacobian else None
    ax_xi, ax_w, b_xi, b_w = quadrature(integration)
    eye = np.eye(3)
    for xi, w in zip(ax_xi, ax_w):
        Sx = _shape_x(xi * L, L)
        rx = np.einsum("ej,eja->ea", Sx, qe)
        n = np.linalg.norm(rx, axis=1)
        c = w * L * axial_stiffness_N
        phi = (n - 1.0) / n
        F += (c * phi)[:, None, None] * Sx[:, :, None] * rx[:, None, :]
        if jacobian:
            M = phi[:, None, None] * eye + rx[:, :, None] * rx[:, None, :] / n[:, None, None] ** 3
            K += np.einsum("e,ej,ek,eab->ejakb", c, Sx, Sx, M)
    for xi, w in zip(b_xi, b_w):
        Sx, Sxx = _shape_x(xi * L, L), _shape_xx(xi * L, L)
        rx = np.einsum("ej,eja->ea", Sx, qe)
        rxx = np.einsum("ej,eja->ea", Sxx, qe)
        g = np.sum(rx * rx, axis=1)
        f = np.cross(rx, rxx)
        kappa = f / g[:, None]
        # A = dκ/dz, z = (r', r''): 3 × 6
        A = np.concatenate([-_skew(rxx) / g[:, None, None] - 2.0 * f[:, :, None] * rx[:, None, :] / g[:, None, None] ** 2,
                            _skew(rx) / g[:, None, None]], axis=2)
        c = w * L * bending_stiffness_N_m2
        dz = np.einsum("eka,ek->ea", A, kappa)              # Aᵀ κ (6)
        S = np.stack([Sx, Sxx], axis=1)                      # (n_el, 2, 4): z-part p, shape j
        F += c[:, None, None] * np.einsum("epj,epa->eja", S, dz.reshape(n_el, 2, 3))
        if jacobian:
            m = kappa
            h = np.sum(m * f, axis=1)
            a = np.cross(rxx, m)
            b = np.cross(m, rx)
            g1, g2, g3 = g[:, None, None], g[:, None, None] ** 2, g[:, None, None] ** 3
            H = np.zeros((n_el, 6, 6))
            H[:, :3, :3] = (-2.0 * (a[:, :, None] * rx[:, None, :] + rx[:, :, None] * a[:, None, :]) / g2
                            + 8.0 * h[:, None, None] * rx[:, :, None] * rx[:, None, :] / g3
                            - 2.0 * h[:, None, None] * eye / g2)
            H[:, :3, 3:] = -_skew(m) / g1 - 2.0 * rx[:, :, None] * b[:, None, :] / g2
            H[:, 3:, :3] = np.swapaxes(H[:, :3, 3:], 1, 2)
            Hz = np.einsum("eka,ekb->eab", A, A) + H
            K += np.einsum("e,epj,eqk,epaqb->ejakb", c, S, S, Hz.reshape(n_el, 2, 3, 2, 3))
    force = np.zeros((n_el + 1, 6))
    Fe = F.reshape(n_el, 12)
    force[:-1] += Fe[:, :6]
    force[1:] += Fe[:, 6:]
    return force.reshape(-1), (K.reshape(n_el, 12, 12) if jacobian else None)


@njit(nogil=True)
def _elastic_kernel(q, L_all, EA, EI, ax_xi, ax_w, b_xi, b_w, jacobian, force, blocks):
    """Compiled :func:`elastic_forces_numpy`: ``force`` (n, zeroed) gets Q_e, ``blocks``
    (n_el, 12, 12) the element stiffnesses when ``jacobian``."""
    n_el = L_all.size
    qe = np.empty(12)
    Sx = np.empty(4)
    Sxx = np.empty(4)
    Fe = np.empty(12)
    rx = np.empty(3)
    rxx = np.empty(3)
    M = np.empty((3, 3))
    A = np.empty((3, 6))
    Hz = np.empty((6, 6))
    for e in range(n_el):
        L = L_all[e]
        for i in range(12):
            qe[i] = q[6 * e + i]
            Fe[i] = 0.0
        if jacobian:
            for i in range(12):
                for k in range(12):
                    blocks[e, i, k] = 0.0
        # axial strain
        for p in range(ax_xi.size):
            x = ax_xi[p] * L
            Sx[0] = -6.0 * x / L**2 + 6.0 * x**2 / L**3
            Sx[1] = 1.0 - 4.0 * x / L + 3.0 * x**2 / L**2
            Sx[2] = 6.0 * x / L**2 - 6.0 * x**2 / L**3
            Sx[3] = -2.0 * x / L + 3.0 * x**2 / L**2
            for a in range(3):
                rx[a] = Sx[0] * qe[a] + Sx[1] * qe[3 + a] + Sx[2] * qe[6 + a] + Sx[3] * qe[9 + a]
            n = np.sqrt(rx[0] * rx[0] + rx[1] * rx[1] + rx[2] * rx[2])
            c = ax_w[p] * L * EA
            phi = (n - 1.0) / n
            for j in range(4):
                for a in range(3):
                    Fe[3 * j + a] += c * phi * Sx[j] * rx[a]
            if jacobian:
                n3 = n * n * n
                for a in range(3):
                    for b in range(3):
                        M[a, b] = rx[a] * rx[b] / n3
                    M[a, a] += phi
                for j in range(4):
                    for k in range(4):
                        s = c * Sx[j] * Sx[k]
                        for a in range(3):
                            for b in range(3):
                                blocks[e, 3 * j + a, 3 * k + b] += s * M[a, b]
        # curvature
        for p in range(b_xi.size):
            x = b_xi[p] * L
            Sx[0] = -6.0 * x / L**2 + 6.0 * x**2 / L**3
            Sx[1] = 1.0 - 4.0 * x / L + 3.0 * x**2 / L**2
            Sx[2] = 6.0 * x / L**2 - 6.0 * x**2 / L**3
            Sx[3] = -2.0 * x / L + 3.0 * x**2 / L**2
            Sxx[0] = 12.0 * x / L**3 - 6.0 / L**2
            Sxx[1] = 6.0 * x / L**2 - 4.0 / L
            Sxx[2] = 6.0 / L**2 - 12.0 * x / L**3
            Sxx[3] = 6.0 * x / L**2 - 2.0 / L
            for a in range(3):
                rx[a] = Sx[0] * qe[a] + Sx[1] * qe[3 + a] + Sx[2] * qe[6 + a] + Sx[3] * qe[9 + a]
                rxx[a] = Sxx[0] * qe[a] + Sxx[1] * qe[3 + a] + Sxx[2] * qe[6 + a] + Sxx[3] * qe[9 + a]
            g = rx[0] * rx[0] + rx[1] * rx[1] + rx[2] * rx[2]
            f0 = rx[1] * rxx[2] - rx[2] * rxx[1]
            f1 = rx[2] * rxx[0] - rx[0] * rxx[2]
            f2 = rx[0] * rxx[1] - rx[1] * rxx[0]
            k0, k1, k2 = f0 / g, f1 / g, f2 / g
            g2 = g * g
            # A = dκ/dz: -[r'']×/g - 2 f r'ᵀ/g² | [r']×/g
            A[0, 0] = 0.0
            A[0, 1] = rxx[2] / g
            A[0, 2] = -rxx[1] / g
            A[1, 0] = -rxx[2] / g
            A[1, 1] = 0.0
            A[1, 2] = rxx[0] / g
            A[2, 0] = rxx[1] / g
            A[2, 1] = -rxx[0] / g
            A[2, 2] = 0.0
            for b in range(3):
                A[0, b] -= 2.0 * f0 * rx[b] / g2
                A[1, b] -= 2.0 * f1 * rx[b] / g2
                A[2, b] -= 2.0 * f2 * rx[b] / g2
            A[0, 3] = 0.0
            A[0, 4] = -rx[2] / g
            A[0, 5] = rx[1] / g
            A[1, 3] = rx[2] / g
            A[1, 4] = 0.0
            A[1, 5] = -rx[0] / g
            A[2, 3] = -rx[1] / g
            A[2, 4] = rx[0] / g
            A[2, 5] = 0.0
            c = b_w[p] * L * EI
            for j in range(4):
                for a in range(3):
                    Fe[3 * j + a] += c * (Sx[j] * (A[0, a] * k0 + A[1, a] * k1 + A[2, a] * k2)
                                          + Sxx[j] * (A[0, 3 + a] * k0 + A[1, 3 + a] * k1 + A[2, 3 + a] * k2))
            if jacobian:
                h = k0 * f0 + k1 * f1 + k2 * f2
                # a = r'' × κ, b = κ × r'
                a0 = rxx[1] * k2 - rxx[2] * k1
                a1 = rxx[2] * k0 - rxx[0] * k2
                a2 = rxx[0] * k1 - rxx[1] * k0
                b0 = k1 * rx[2] - k2 * rx[1]
                b1 = k2 * rx[0] - k0 * rx[2]
                b2 = k0 * rx[1] - k1 * rx[0]
                av = (a0, a1, a2)
                bv = (b0, b1, b2)
                g3 = g2 * g
                for u in range(6):
                    for v in range(6):
                        Hz[u, v] = A[0, u] * A[0, v] + A[1, u] * A[1, v] + A[2, u] * A[2, v]
                for u in range(3):
                    for v in range(3):
                        Hz[u, v] += (-2.0 * (av[u] * rx[v] + rx[u] * av[v]) / g2
                                     + 8.0 * h * rx[u] * rx[v] / g3)
                        Hz[u, 3 + v] += -2.0 * rx[u] * bv[v] / g2
                        Hz[3 + v, u] += -2.0 * rx[u] * bv[v] / g2
                    Hz[u, u] -= 2.0 * h / g2
                # -[κ]×/g in the (r', r'') block, its transpose in (r'', r')
                Hz[0, 4] += k2 / g
                Hz[0, 5] -= k1 / g
                Hz[1, 3] -= k2 / g
                Hz[1, 5] += k0 / g
                Hz[2, 3] += k1 / g
                Hz[2, 4] -= k0 / g
                Hz[4, 0] += k2 / g
                Hz[5, 0] -= k1 / g
                Hz[3, 1] -= k2 / g
                Hz[5, 1] += k0 / g
                Hz[3, 2] += k1 / g
                Hz[4, 2] -= k0 / g
                for j in range(4):
                    for k in range(4):
                        sxx = c * Sx[j] * Sx[k]
                        sxy = c * Sx[j] * Sxx[k]
                        syx = c * Sxx[j] * Sx[k]
                        syy = c * Sxx[j] * Sxx[k]
                        for a in range(3):
                            for b in range(3):
                                blocks[e, 3 * j + a, 3 * k + b] += (sxx * Hz[a, b] + sxy * Hz[a, 3 + b]
                                                                    + syx * Hz[3 + a, b] + syy * Hz[3 + a, 3 + b])
        for i in range(12):
            force[6 * e + i] += Fe[i]


def elastic_forces(q, lengths_m, axial_stiffness_N: float, bending_stiffness_N_m2: float, integration: str,
                   jacobian: bool = True):
    """:func:`elastic_forces_numpy`, compiled (same arguments and results)."""
    L = np.ascontiguousarray(lengths_m, dtype=float)
    qf = np.ascontiguousarray(np.asarray(q, dtype=float).reshape(-1))
    if qf.size != 6 * (L.size + 1):
        raise ValueError(f"q has {qf.size} coordinates, {6 * (L.size + 1)} expected for {L.size} elements")
    ax_xi, ax_w, b_xi, b_w = quadrature(integration)
    force = np.zeros(qf.size)
    blocks = np.empty((L.size if jacobian else 0, 12, 12))
    _elastic_kernel(qf, L, float(axial_stiffness_N), float(bending_stiffness_N_m2), ax_xi, ax_w, b_xi, b_w,
                    bool(jacobian), force, blocks)
    return force, (blocks if jacobian else None)


class AncfCableForces:
    """The cable's elastic forces and its weight as one generalized force, for a user function.

    Parameters
    ----------
    lengths_m : array_like (n_el,)
        Element lengths [m].
    axial_stiffness_N, bending_stiffness_N_m2 : float
        EA [N], EJ [N m²].
    integration : str
        ``cable.integration`` (:func:`quadrature`).
    mass_per_length_kg_per_m : float
        ρA [kg/m], for the weight.
    gravity_m_per_s2 : array_like (3,)
        Gravitational acceleration vector [m/s²] (zeros: none).

    Attributes
    ----------
    gravity_scale : float
        Factor [-] on the weight (the steady solve's load continuation).
    backend : {"numba", "numpy"}
        Which implementation :meth:`evaluate` runs.
    """

    def __init__(self, lengths_m, axial_stiffness_N: float, bending_stiffness_N_m2: float, integration: str,
                 mass_per_length_kg_per_m: float = 0.0, gravity_m_per_s2=(0.0, 0.0, 0.0)):
        self.lengths_m = np.ascontiguousarray(lengths_m, dtype=float)
        self.axial_stiffness_N = float(axial_stiffness_N)
        self.bending_stiffness_N_m2 = float(bending_stiffness_N_m2)
        self.integration = integration
        quadrature(integration)
        self.gravity_m_per_s2 = np.asarray(gravity_m_per_s2, dtype=float).reshape(3)
        self.gravity_scale = 1.0
        self.backend = "numba"
        # the consistent load of ρA·g on each element, ∫ρA Sᵀ g dx = ρA L [g/2, L g/12, g/2, -L g/12]
        # (what Exudyn's LoadMassProportional applies, by an exact Gauss rule)
        L = self.lengths_m
        rg = float(mass_per_length_kg_per_m) * self.gravity_m_per_s2
        weight = np.zeros((L.size + 1, 6))
        weight[:-1, :3] += (0.5 * L)[:, None] * rg
        weight[:-1, 3:] += (L * L / 12.0)[:, None] * rg
        weight[1:, :3] += (0.5 * L)[:, None] * rg
        weight[1:, 3:] -= (L * L / 12.0)[:, None] * rg
        self.weight_N = weight.reshape(-1)

    @property
    def n_elements(self) -> int:
        return self.lengths_m.size

    def evaluate(self, q, jacobian: bool = True):
        """Right-hand-side elastic force ``−Q_e(q)`` [N, N m] at absolute coordinates q, and the
        blocks ∂Q_e/∂q (n_el, 12, 12) of its left-hand-side derivative (None unless asked). The
        weight is apart (:meth:`weight`): it changes with :attr:`gravity_scale`, not with q."""
        run = elastic_forces if self.backend == "numba" else elastic_forces_numpy
        lhs, blocks = run(q, self.lengths_m, self.axial_stiffness_N, self.bending_stiffness_N_m2, self.integration,
                          jacobian)
        return -lhs, blocks

    def weight(self) -> np.ndarray | None:
        """The weight's generalized force ``gravity_scale·Q_g`` [N, N m] (None when it is zero)."""
        if self.gravity_scale == 0.0 or not self.weight_N.any():
            return None
        return self.gravity_scale * self.weight_N
