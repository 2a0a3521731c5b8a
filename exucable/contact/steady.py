"""Contact kernel of steady sliding: the friction direction from the cable's own tangent.

In a steady pull the cable's shape is fixed in space and its material flows along it toward the
leading end. A material point at element coordinate ξ then moves with

    v(ξ) = V ∂r/∂x = V S'(ξ) q_e,

V the pull speed [m/s] and x the material (unstretched) arc length, so v is a function of the
coordinates q, not of the nodal rates q̇ (which are zero in a static solve). Everything else is the
dynamic kernel's (paper Eqs. 14-23): the normal law with its damping on δ̇ = n·v, friction
-μ f_n v_τ/√(|v_τ|² + ε²) against the sliding direction. Its derivative with respect to q gains
the term of the velocity's dependence on the slopes,

    ∂Q_e/∂q_e = Σ_k S_kᵀ (∂F/∂P) S_k + Σ_k S_kᵀ (∂F/∂v) V S'_k,

which the compiled path sums in a polynomial basis: every product N_a N_b (degree 6 in ξ) and
N_a N'_b (degree 5, not symmetric in a, b) is a fixed combination of the seven Bernstein
polynomials of degree 6, so seven moments Σ_k B_m(ξ_k) J_k per column of the point Jacobians
replace the 10 + 16 product sums (:func:`block_coefficients`).

Friction is fully developed sliding friction: every point in contact slides at |v_τ| ≈ V > 0,
so the dynamic law's regularisation v_τ/√(|v_τ|² + ε²) (a smoothing of the stick/slip switch at
v_τ = 0, which steady sliding never reaches) would only scale μ by V/√(V² + ε²) and make the
pulling force depend on the pull speed (−8.8 % at V = ε). The steady kernel therefore uses
ε = :data:`STEADY_REGULARISATION_FRACTION` · V: the factor is 1 − 5e-13 at every speed, the
Jacobian formulas (in s = √(|v_τ|² + ε²)) stay exact, and a point whose v_τ vanished would still
get a finite (zero) friction force. A Stribeck law (``contact.static_friction``) stays a function
of the sliding speed |v_τ| ≈ V: it is a physical law the user chose, not a numerical device.

|∂r/∂x| = 1 + ε_axial: the material speed is taken as V (the pull speed) everywhere rather than
V (1 + ε_axial)/(1 + ε_lead); the difference (strain, < 1e-3 on the paper's examples) changes only
the Stribeck factor and the contact damping's share, whose entry and exit contributions cancel
along a contact zone.
"""

from __future__ import annotations

from dataclasses import replace
from math import comb

import numpy as np
from .jitcache import njit

from .checkpoints import hermite_unit
from .kernel import ContactKernel
from .numpy_kernel import ReferenceKernel
from .kernel_parts import (
    JIT_OPTIONS,
    PAIRS,
    J0,
    PX,
    PY,
    PZ,
    BEST,
    RX,
    RY,
    RZ,
    AX,
    AY,
    AZ,
    BEYOND,
    VX,
    VY,
    VZ,
    add_generalized_force,
    exponent_mode_of,
    friction,
    nearest_segments,
    normal_force,
    normals,
    point_jacobians,
    positions,
    refine_smooth,
)
from .smooth import NEWTON_ITERATIONS

__all__ = ["SteadySlidingKernel", "hermite_unit_derivative", "steady_sliding_law", "STEADY_REGULARISATION_FRACTION"]

#: Steady mode's friction regularisation velocity as a fraction of the pull speed [-]: the
#: regularisation factor 1/√(1 + 1e-12) = 1 − 5e-13 is fully developed sliding at any speed,
#: while ε > 0 keeps the force finite where v_τ = 0.
STEADY_REGULARISATION_FRACTION = 1.0e-6

# Degree of the polynomials in ξ whose sums over the check points make the Jacobian blocks:
# N_a N_b (6) and N_a N'_b (5); see block_coefficients
BLOCK_DEGREE = 6


def hermite_unit_derivative(xi) -> np.ndarray:
    """dN/dξ of the unit-length Hermite functions of :func:`hermite_unit`, shape (..., 4) [-]."""
    x = np.asarray(xi, dtype=float)
    x2 = x * x
    return np.stack([-6.0 * x + 6.0 * x2, 1.0 - 4.0 * x + 3.0 * x2, 6.0 * x - 6.0 * x2, 3.0 * x2 - 2.0 * x],
                    axis=-1)


class SteadySlidingKernel(ContactKernel):
    """:class:`~exucable.contact.ContactKernel` whose check points move as in steady sliding.

    Parameters are those of :class:`~exucable.contact.ContactKernel`, plus

    speed_m_per_s : float
        Pull speed V [m/s]; material flows toward the last node (the leading end).

    ``evaluate(q, q_t)`` and ``points(q, q_t)`` ignore ``q_t``; the ``jac_q_blocks`` are the full
    derivative (including the velocity's dependence on q) and the ``jac_qt_blocks`` are zero.
    """

    def __init__(self, segments, element_length_m, cable_radius_m, law, *args, speed_m_per_s: float, **kwargs):
        super().__init__(segments, element_length_m, cable_radius_m, steady_sliding_law(law, speed_m_per_s),
                         *args, **kwargs)
        self.speed_m_per_s = float(speed_m_per_s)
        self._dnh = hermite_unit_derivative(self.xi)
        self._base_law = self.law
        if self.backend == "numba":
            self._impl = _SteadyFast(self._impl, self.xi, self._dnh, self.speed_m_per_s)
        else:
            self._impl = _SteadyReference(self)

    def law_statement(self) -> dict:
        """:meth:`ContactKernel.law_statement` of steady sliding: v from the coordinates."""
        out = super().law_statement()
        out["sliding_velocity"] = ("v = V * dr/dx = (V / L_e) * (dN1/dxi r_i + dN2/dxi r'_i + dN3/dxi r_j + "
                                   "dN4/dxi r'_j) at the check point (N2, N4 with their L_e), V = "
                                   f"{self.speed_m_per_s!r} m/s the pull speed: the material flows along the "
                                   "fixed curve; not normalised by |r'|")
        out["damping"] = ("g = min(delta/delta_d, 1) (1 when delta_d = 0) at the current delta; delta_dot = n . v "
                          "with the steady v above (a point entering or leaving the wall moves through it)")
        return out

    def set_friction_scale(self, scale: float) -> None:
        """Scale μ_k and μ_s by ``scale`` [-] (a continuation parameter; 1 = the scenario's law)."""
        base = self._base_law
        law = replace(base, friction=scale * base.friction,
                      static_friction=None if base.static_friction is None else scale * base.static_friction)
        self._use(law)

    def set_onset_layer(self, layer_m: float) -> None:
        """The contact onset's layer s [m] (:func:`~exucable.contact.law.onset_blend`; 0: the law
        without one), kept by :meth:`set_friction_scale`; s must stay below the clearance R - r."""
        layer = float(layer_m)
        if not 0.0 <= layer < self.gap_m:
            raise ValueError(f"onset layer {layer!r} m must be in [0, the clearance R - r = {self.gap_m:g} m)")
        self._base_law = replace(self._base_law, onset_layer_m=layer)
        self._use(replace(self.law, onset_layer_m=layer))

    def _use(self, law) -> None:
        self.law = law
        self._last_point_state = None      # its forces were of the former law
        if isinstance(self._impl, _SteadyFast):
            self._impl.fast.law = law


def steady_sliding_law(law, speed_m_per_s: float):
    """``law`` with its friction fully developed at the sliding speed ``speed_m_per_s`` V [m/s].

    The regularisation velocity becomes :data:`STEADY_REGULARISATION_FRACTION` · V, so that
    μ v_τ/√(|v_τ|² + ε²) is μ v_τ/|v_τ| to 5e-13 wherever |v_τ| ≈ V (module docstring).

    Parameters
    ----------
    law : exucable.contact.ContactLaw
    speed_m_per_s : float
        Pull speed V > 0 [m/s].

    Returns
    -------
    exucable.contact.ContactLaw
    """
    if not speed_m_per_s > 0.0:
        raise ValueError(f"steady sliding needs a pull speed > 0 m/s, got {speed_m_per_s!r}")
    return replace(law, regularisation_velocity_m_per_s=STEADY_REGULARISATION_FRACTION * float(speed_m_per_s))


class _SteadyReference(ReferenceKernel):
    """numpy backend: v = V ∂r/∂x, its derivative folded into ∂Q/∂q."""

    velocity_from_coordinates = True

    def _velocity_map(self, shape, q, q_t):
        # V ∂r/∂x: positions' columns dN/dξ / L, slopes' columns dN/dξ (L N_unit differentiated)
        k = self.k
        L = k.element_length_m[:, None]
        d = np.broadcast_to(k._dnh, shape.shape).copy()
        d[:, :, 0] /= L
        d[:, :, 2] /= L
        return k.speed_m_per_s * d, q


def bernstein(xi, degree: int = BLOCK_DEGREE) -> np.ndarray:
    """Bernstein polynomials C(n, m) ξ^m (1 - ξ)^(n - m), m = 0..n, shape (..., n + 1) [-]."""
    x = np.asarray(xi, dtype=float)[..., None]
    m = np.arange(degree + 1)
    binomial = np.array([comb(degree, i) for i in m], dtype=float)
    return binomial * x**m * (1.0 - x) ** (degree - m)


def block_coefficients() -> np.ndarray:
    """Bernstein coefficients (degree 6) of the ten products N_a N_b (rows in the order of
    :data:`.kernel_parts.PAIRS`) and the sixteen N_a N'_b (row 10 + 4a + b), shape (26, 7) [-].

    Both are polynomials of degree ≤ 6 in ξ (N cubic, N' quadratic), so they are interpolated
    exactly (to round-off, ~1e-16) at seven Chebyshev nodes, where the Bernstein collocation
    matrix is well conditioned. Every N_a has Bernstein coefficients of one sign, hence so have
    the products N_a N_b: the sums over these coefficients cancel no more than the direct ones."""
    nodes = 0.5 - 0.5 * np.cos(np.pi * (2 * np.arange(BLOCK_DEGREE + 1) + 1) / (2 * BLOCK_DEGREE + 2))
    nh = hermite_unit(nodes)
    dnh = hermite_unit_derivative(nodes)
    products = [nh[:, a] * nh[:, b] for a, b in PAIRS] + [nh[:, a] * dnh[:, b] for a in range(4) for b in range(4)]
    return np.ascontiguousarray(np.linalg.solve(bernstein(nodes), np.stack(products, axis=1)).T)


@njit(inline="always", **JIT_OPTIONS)
def _jacobian_moments(tab, basis, mom):
    """mom[m, c] = Σ_k B_m(ξ_k) J_c(k) for the 18 columns of ∂F/∂P and ∂F/∂v (B: Bernstein,
    degree 6). Three columns per pass: each basis value loaded once serves three sums (the loop
    is bound by loads, not by arithmetic), 21 running sums held in registers."""
    n_k = basis.shape[1]
    b0, b1, b2, b3, b4, b5, b6 = basis[0], basis[1], basis[2], basis[3], basis[4], basis[5], basis[6]
    for col in range(0, 18, 3):
        ja = tab[J0 + col]
        jb = tab[J0 + col + 1]
        jc = tab[J0 + col + 2]
        a0 = a1 = a2 = a3 = a4 = a5 = a6 = 0.0
        c0 = c1 = c2 = c3 = c4 = c5 = c6 = 0.0
        d0 = d1 = d2 = d3 = d4 = d5 = d6 = 0.0
        for k in range(n_k):
            x = ja[k]
            y = jb[k]
            z = jc[k]
            a0, c0, d0 = _add_products(b0[k], x, y, z, a0, c0, d0)
            a1, c1, d1 = _add_products(b1[k], x, y, z, a1, c1, d1)
            a2, c2, d2 = _add_products(b2[k], x, y, z, a2, c2, d2)
            a3, c3, d3 = _add_products(b3[k], x, y, z, a3, c3, d3)
            a4, c4, d4 = _add_products(b4[k], x, y, z, a4, c4, d4)
            a5, c5, d5 = _add_products(b5[k], x, y, z, a5, c5, d5)
            a6, c6, d6 = _add_products(b6[k], x, y, z, a6, c6, d6)
        _store_moments(mom, col, a0, a1, a2, a3, a4, a5, a6)
        _store_moments(mom, col + 1, c0, c1, c2, c3, c4, c5, c6)
        _store_moments(mom, col + 2, d0, d1, d2, d3, d4, d5, d6)


@njit(inline="always", **JIT_OPTIONS)
def _add_products(v, x, y, z, sx, sy, sz):
    """(sx + v x, sy + v y, sz + v z): one basis value into three running sums."""
    return sx + v * x, sy + v * y, sz + v * z


@njit(inline="always", **JIT_OPTIONS)
def _store_moments(mom, col, s0, s1, s2, s3, s4, s5, s6):
    """The seven moments of column ``col``."""
    mom[0, col], mom[1, col], mom[2, col], mom[3, col] = s0, s1, s2, s3
    mom[4, col], mom[5, col], mom[6, col] = s4, s5, s6


@njit(inline="always", **JIT_OPTIONS)
def _steady_blocks(mom, coeff, pair_ab, le, speed, bq):
    """∂Q_e/∂q_e = Σ_k S_kᵀ (∂F/∂P)_k S_k + Σ_k S_kᵀ (∂F/∂v)_k V S'_k from the moments of
    :func:`_jacobian_moments`: Σ_k N_a N_b J = Σ_m c_abm mom_m (``coeff``: :func:`block_coefficients`)."""
    for p in range(10):
        a = pair_ab[p, 0]
        b = pair_ab[p, 1]
        scale = (le if (a == 1 or a == 3) else 1.0) * (le if (b == 1 or b == 3) else 1.0)
        for i in range(3):
            for j in range(3):
                c = 3 * i + j
                v = 0.0
                for m in range(BLOCK_DEGREE + 1):
                    v += coeff[p, m] * mom[m, c]
                v *= scale
                bq[3 * a + i, 3 * b + j] = v
                if a != b:  # (N Nᵀ) is symmetric: block (b, a) has the same 3×3
                    bq[3 * b + i, 3 * a + j] = v
    for a in range(4):
        row_scale = le if (a == 1 or a == 3) else 1.0     # S: slope functions carry L
        for b in range(4):
            col_scale = 1.0 if (b == 1 or b == 3) else 1.0 / le   # S' = dS/dx
            scale = speed * row_scale * col_scale
            p = 10 + 4 * a + b
            for i in range(3):
                for j in range(3):
                    c = 9 + 3 * i + j
                    v = 0.0
                    for m in range(BLOCK_DEGREE + 1):
                        v += coeff[p, m] * mom[m, c]
                    bq[3 * a + i, 3 * b + j] += scale * v


@njit(**JIT_OPTIONS)
def _steady_kernel(q, length, n1, n2, n3, n4, d1, d2, d3, d4, speed, basis, pair_ab, coeff,
                   omega, seg, off, cand, gap, stiffness, damping, exponent, exponent_mode, mu_k,
                   dmu, inv_vs2, eps2, inv_href, jacobian, force, jq, scratch, tab, sel, acc,
                   acc16, open_first, open_last, smooth, seg_piece, pieces, seg_phi, n_newton,
                   inv_onset, layer):
    """As :func:`exucable.contact.fast._contact_kernel`, with v = V S'(ξ) q_e.

    ``basis`` (7, n_k): Bernstein values B_m(ξ_k) (:func:`bernstein`); ``coeff`` (26, 7): the
    products' coefficients (:func:`block_coefficients`); ``acc`` (≥ 7, 18): the moments.
    ``scratch`` and ``acc16`` are not used (kept so that the call signature stays that of the former
    product sums)."""
    n_k = n1.shape[0]
    n_contact = 0
    max_d2 = -1.0
    for e in range(length.shape[0]):
        c0 = off[e]
        c1 = off[e + 1]
        if c0 == c1:
            continue
        le = length[e]
        b = 6 * e
        positions(q, b, le, n1, n2, n3, n4, tab[PX], tab[PY], tab[PZ])
        nearest_segments(tab[PX], tab[PY], tab[PZ], seg, cand, c0, c1, tab[BEST], sel,
                          tab[RX], tab[RY], tab[RZ], tab[AX], tab[AY], tab[AZ],
                          open_first, open_last, tab[BEYOND])
        if smooth:
            refine_smooth(tab[PX], tab[PY], tab[PZ], seg, sel, tab[BEST], tab[RX], tab[RY],
                           tab[RZ], tab[AX], tab[AY], tab[AZ], seg_piece, pieces, seg_phi,
                           n_newton)
        n_touch, max_d2 = normals(tab, n_k, gap, max_d2, layer)
        if n_touch == 0:
            continue
        n_contact += n_touch
        # v = V ∂r/∂x: positions with the derivative table gives L ∂r/∂x
        positions(q, b, le, d1, d2, d3, d4, tab[VX], tab[VY], tab[VZ])
        vs = speed / le
        vx = tab[VX]
        vy = tab[VY]
        vz = tab[VZ]
        for k in range(n_k):
            vx[k] *= vs
            vy[k] *= vs
            vz[k] *= vs
        normal_force(tab, omega, n_k, le * inv_href, stiffness, damping, exponent,
                      exponent_mode, inv_onset)
        friction(tab, n_k, mu_k, dmu, inv_vs2, eps2)
        add_generalized_force(tab, n1, n2, n3, n4, le, b, force)
        if not jacobian:
            continue
        point_jacobians(tab, n_k, stiffness, damping)
        _jacobian_moments(tab, basis, acc)
        _steady_blocks(acc, coeff, pair_ab, le, speed, jq[e])
    max_pen = np.sqrt(max_d2) - gap if max_d2 >= 0.0 else -np.inf
    return n_contact, max_pen


class _SteadyFast:
    """Compiled steady-sliding evaluation sharing a :class:`~exucable.contact.fast.FastKernel`'s
    tables, broad phase and work buffers."""

    velocity_from_coordinates = True    # v = V ∂r/∂x: q_t is ignored

    def __init__(self, fast, xi, dnh_unit, speed_m_per_s):
        self.fast = fast
        self.speed = float(speed_m_per_s)
        self._d = [np.ascontiguousarray(dnh_unit[:, i]) for i in range(4)]
        # the Jacobian blocks from seven moments per column instead of 10 + 16 products
        self.basis = np.ascontiguousarray(bernstein(xi).T)
        self.coeff = block_coefficients()
        self._unused_work = np.empty((0, 0))

    def candidates(self, q):
        return self.fast.candidates(q)

    def nearest_segments(self, q):
        """Contact search only: nearest segment per check point, shape (n_el, n_k) (-1: none)."""
        return self.fast.nearest_segments(q)

    def point_state(self, q, q_t):
        """Per check point state, compiled (tested against the numpy reference's); ``q_t`` is
        ignored: v = V ∂r/∂x."""
        return self.fast.point_state_with_rates(q, q, self._d, self.speed)

    def evaluate(self, q, q_t, jacobian):
        """As :meth:`FastKernel.evaluate`; ``q_t`` is ignored and the q̇-blocks are zero."""
        f = self.fast
        q = np.ascontiguousarray(q, dtype=float)
        off, cand = f.candidates(q)
        force = np.zeros(f.n_coordinates)
        jq = np.zeros((f.n_el, 12, 12)) if jacobian else f._empty_blocks
        law = f.law
        n1, n2, n3, n4 = f._n
        d1, d2, d3, d4 = self._d
        n_contact, max_pen = _steady_kernel(
            q, f.length, n1, n2, n3, n4, d1, d2, d3, d4, self.speed, self.basis, PAIRS, self.coeff,
            f.omega, f.seg, off, cand, f.gap, float(law.stiffness), float(law.damping),
            float(law.exponent), exponent_mode_of(law.exponent), float(law.friction),
            float(law.static_excess), 1.0 / law.stribeck_velocity_m_per_s**2,
            law.regularisation_velocity_m_per_s**2, f.inv_href, bool(jacobian), force, jq,
            self._unused_work, f._tab, f._sel, f._acc, self._unused_work, f.open_first, f.open_last,
            f.smooth, f.seg_piece, f.pieces, f.seg_phi, NEWTON_ITERATIONS,
            1.0 / law.damping_onset_m if law.damping_onset_m > 0.0 else 0.0, float(law.onset_layer_m))
        if not jacobian:
            return force, None, None, int(n_contact), float(max_pen)
        return force, jq, np.zeros_like(jq), int(n_contact), float(max_pen)
