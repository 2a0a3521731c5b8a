"""Cable-conduit contact kernel (paper Sects. 2.4-2.5): narrow phase, force law, Jacobians.

This module holds the public :class:`ContactKernel` and its pure-numpy reference implementation;
:mod:`exucable.contact.fast` is the compiled fast path (the default), tested against this one.

Per check point P at element coordinate ξ_k (weight ω_k) of element e:

- P = S(ξ) q_e, v = S(ξ) q̇_e (Eqs. 2, 8);
- Pc = closest point of P on the conduit polyline: the nearest candidate segment, projection
  parameter clamped to the segment (a point beyond a kink's outer side sees the vertex); ties
  go to the lower segment index;
- d = |P - Pc|, δ = d - (R - r) (Eq. 14), contact iff δ > 0; n = (P - Pc)/d (Eq. 15);
  v_n = n·v = δ̇ (Eq. 16, fixed conduit); v_τ = v - v_n n (Eq. 17);
- f_n = w·max(0, K δ^e + C δ̇) (Eq. 18) with w = L_e ω_k / h_ref, the point's share of the
  element length against the reference spacing h_ref, so that the total stiffness does not
  grow with the number of check points;
- F = -f_n n - μ(|v_τ|) f_n v_τ/√(|v_τ|² + ε²) (Eqs. 19-23, friction regularised);
- Q_e = Σ_k S(ξ_k)ᵀ F_k, ∂Q_e/∂q_e = Σ_k Sᵀ (∂F/∂P) S, ∂Q_e/∂q̇_e = Σ_k Sᵀ (∂F/∂v) S with the
  segment choice held fixed (the force is piecewise smooth).

Q is the force *on the cable* (a right-hand-side term of M q̈ = Q + ...); the Jacobians are its
derivatives, so for a stable contact ∂Q/∂q is negative semi-definite in the normal direction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.segments import Segments
from .broadphase import candidates_all_pairs, candidates_all_segments, element_aabbs
from .smooth import SmoothWall, refine_closest_points
from .checkpoints import check_points, hermite_unit
from .law import ContactLaw, damping_ramp, friction_coefficient

__all__ = [
    "ContactKernel",
    "ContactResult",
    "CheckPointState",
    "assemble_blocks_dense",
    "block_sparsity",
]

_BACKENDS = ("auto", "numpy", "numba")
_BROAD_PHASES = ("aabb", "none")


@dataclass
class ContactResult:
    """Output of :meth:`ContactKernel.evaluate`.

    Attributes
    ----------
    generalized_force : ndarray, shape (n_coordinates,)
        Generalized contact force Q on the cable [N for positions, N·m for slopes].
    jac_q_blocks : ndarray, shape (n_el, 12, 12), or None
        ∂Q_e/∂q_e per element [N/m, ...] (element ``e`` couples coordinates 6e ... 6e + 11);
        overlapping entries of neighbouring elements add (see :func:`block_sparsity`).
    jac_qt_blocks : ndarray, shape (n_el, 12, 12), or None
        ∂Q_e/∂q̇_e per element [N·s/m, ...].
    n_in_contact : int
        Number of check points with penetration δ > 0.
    max_penetration_m : float
        Largest δ over all check points that found a candidate segment [m] (-inf if none); a
        value approaching the cable radius means the cable is leaving the conduit.
    """

    generalized_force: np.ndarray
    jac_q_blocks: np.ndarray | None
    jac_qt_blocks: np.ndarray | None
    n_in_contact: int
    max_penetration_m: float = -np.inf


@dataclass
class CheckPointState:
    """Per check point state for post-processing (arrays of length n_el·n_k, element-major).

    Attributes
    ----------
    element : ndarray of int
        Element index of each point.
    xi : ndarray
        Element coordinate ξ [-].
    segment : ndarray of int
        Conduit segment holding the closest point Pc (-1: no candidate segment; the point is
        farther than R from the conduit axis, i.e. outside the conduit).
    position_m : ndarray, shape (n, 3)
        Check point position P [m].
    velocity_m_per_s : ndarray, shape (n, 3)
        Check point velocity v [m/s].
    normal : ndarray, shape (n, 3)
        Contact normal n, outward from the axis [-] (NaN where d = 0 or no segment).
    s_conduit_m : ndarray
        Centreline arc length of Pc [m], linear within a segment between ``s_vertex_m`` values
        (NaN without segment).
    penetration_m : ndarray
        δ = d - (R - r) [m]; <= 0 where there is no contact (NaN without segment).
    normal_force_N : ndarray
        Weighted normal force w·f_n [N] (0 without contact).
    normal_force_per_length_N_per_m : ndarray
        Normal force per cable length f_n/(L_e ω_k) [N/m], the sidewall bearing pressure.
    sliding_velocity_m_per_s : ndarray
        Tangential (sliding) speed |v_τ| [m/s] (0 without contact).
    friction_force_N : ndarray
        Magnitude of the regularised friction force μ w f_n |v_τ|/√(|v_τ|² + ε²) [N].
    in_contact : ndarray of bool
        δ > 0.
    """

    element: np.ndarray
    xi: np.ndarray
    segment: np.ndarray
    position_m: np.ndarray
    velocity_m_per_s: np.ndarray
    normal: np.ndarray
    s_conduit_m: np.ndarray
    penetration_m: np.ndarray
    normal_force_N: np.ndarray
    normal_force_per_length_N_per_m: np.ndarray
    sliding_velocity_m_per_s: np.ndarray
    friction_force_N: np.ndarray
    in_contact: np.ndarray


def block_sparsity(n_el: int) -> tuple[np.ndarray, np.ndarray]:
    """Global (row, column) indices of every entry of the element blocks.

    Parameters
    ----------
    n_el : int
        Number of elements.

    Returns
    -------
    rows, cols : ndarray of int64, shape (n_el·144,)
        In the order of ``blocks.reshape(-1)`` for blocks of shape (n_el, 12, 12); duplicated
        (row, col) pairs (coordinates shared by neighbouring elements) are to be summed, as
        ``scipy.sparse.coo_matrix`` does.
    """
    base = 6 * np.arange(n_el, dtype=np.int64)[:, None, None]
    local = np.arange(12, dtype=np.int64)
    rows = base + local[None, :, None] + 0 * local[None, None, :]
    cols = base + local[None, None, :] + 0 * local[None, :, None]
    return rows.reshape(-1), cols.reshape(-1)


def assemble_blocks_dense(blocks: np.ndarray) -> np.ndarray:
    """Sum element blocks (n_el, 12, 12) into the dense global matrix (n, n), n = 6 (n_el + 1)."""
    blocks = np.asarray(blocks, dtype=float)
    n_el = blocks.shape[0]
    n = 6 * (n_el + 1)
    out = np.zeros((n, n))
    for e in range(n_el):
        out[6 * e:6 * e + 12, 6 * e:6 * e + 12] += blocks[e]
    return out


# ---------------------------------------------------------------------------------------------
# numpy reference
# ---------------------------------------------------------------------------------------------

def _element_values(q: np.ndarray) -> np.ndarray:
    """Element coordinates as (n_el, 4, 3): r_i, r'_i, r_j, r'_j."""
    nodes = q.reshape(-1, 6)
    return np.stack([nodes[:-1, :3], nodes[:-1, 3:], nodes[1:, :3], nodes[1:, 3:]], axis=1)


def _nearest(p, cand, seg_start, seg_end, seg_axis, seg_length, open_first=-1, open_last=-1):
    """Closest point of each of the points ``p`` (m, 3) on the segments ``cand``.

    Returns (segment index, clamped projection parameter t [m], residual P - Pc, inside flag);
    the arithmetic mirrors the compiled kernel term by term so that both choose the same segment.
    """
    a = seg_axis[cand]
    start = seg_start[cand]
    end = seg_end[cand]
    dx = p[:, None, 0] - start[None, :, 0]
    dy = p[:, None, 1] - start[None, :, 1]
    dz = p[:, None, 2] - start[None, :, 2]
    t = dx * a[None, :, 0] + dy * a[None, :, 1] + dz * a[None, :, 2]
    length = seg_length[cand][None, :]
    low = t <= 0.0
    high = ~low & (t >= length)
    inside = ~low & ~high
    ex = np.where(low, dx, np.where(high, p[:, None, 0] - end[None, :, 0], dx - t * a[None, :, 0]))
    ey = np.where(low, dy, np.where(high, p[:, None, 1] - end[None, :, 1], dy - t * a[None, :, 1]))
    ez = np.where(low, dz, np.where(high, p[:, None, 2] - end[None, :, 2], dz - t * a[None, :, 2]))
    d2 = ex * ex + ey * ey + ez * ez
    j = np.argmin(d2, axis=1)  # first minimum: ties keep the lower segment index
    rows = np.arange(p.shape[0])
    residual = np.stack([ex[rows, j], ey[rows, j], ez[rows, j]], axis=1)
    # nearest to an open end's segment and past it: outside the conduit, no contact (residual 0,
    # as the compiled kernel). Decided on the nearest segment: a point far from the ends may well
    # lie behind the first segment's start plane.
    beyond = (low & (cand == open_first)[None, :]) | (high & (cand == open_last)[None, :])
    residual[beyond[rows, j]] = 0.0
    t_clamped = np.clip(t[rows, j], 0.0, length[0, j])
    return cand[j], t_clamped, residual, inside[rows, j]


def _point_law(p_res, v, axis_inside, w, law: ContactLaw, gap, jacobian):
    """Force law on flat arrays of points (Eqs. 14-23) and its derivatives ∂F/∂P, ∂F/∂v.

    ``p_res`` = P - Pc (NaN rows for points without a segment); ``axis_inside`` = segment axis
    where the projection is inside the segment, 0 where it is clamped to a vertex.
    """
    m = p_res.shape[0]
    out = {
        "delta": np.full(m, np.nan),
        "normal": np.full((m, 3), np.nan),
        "f": np.zeros(m),
        "f_unweighted": np.zeros(m),
        "slip": np.zeros(m),
        "friction": np.zeros(m),
        "force": np.zeros((m, 3)),
        "jp": np.zeros((m, 3, 3)) if jacobian else None,
        "jv": np.zeros((m, 3, 3)) if jacobian else None,
    }
    with np.errstate(invalid="ignore"):
        d = np.sqrt(np.sum(p_res * p_res, axis=1))
        delta = d - gap  # Eq. 14
    out["delta"] = delta
    touch = np.nonzero(delta > 0.0)[0]  # NaN compares False: no segment, no contact
    pos = d > 0.0
    out["normal"][pos] = p_res[pos] / d[pos, None]
    if touch.size == 0:
        return out
    dt = d[touch]
    n = p_res[touch] / dt[:, None]  # Eq. 15
    vt_ = v[touch]
    vn = np.sum(n * vt_, axis=1)  # Eq. 16
    dl = delta[touch]
    ramp, dramp = damping_ramp(law, dl)
    raw = law.stiffness * dl**law.exponent + law.damping * ramp * vn  # Eq. 18 (with the onset)
    act = raw > 0.0
    idx = touch[act]
    n, vt_, vn, dl, dt, raw = n[act], vt_[act], vn[act], dl[act], dt[act], raw[act]
    ramp, dramp = ramp[act], dramp[act]
    wt = w[idx]
    f = wt * raw
    tau = vt_ - vn[:, None] * n  # Eq. 17
    g = np.sum(tau * tau, axis=1)
    sr = np.sqrt(g + law.regularisation_velocity_m_per_s**2)
    mu, dmu_dg = friction_coefficient(law, g)
    h = mu * f / sr
    force = -f[:, None] * n - h[:, None] * tau  # Eqs. 19-23
    out["f"][idx] = f
    out["f_unweighted"][idx] = raw
    out["slip"][idx] = np.sqrt(g)
    out["friction"][idx] = h * np.sqrt(g)
    out["force"][idx] = force
    if not jacobian:
        return out
    eye = np.eye(3)
    a = axis_inside[idx]
    proj = eye - a[:, :, None] * a[:, None, :]  # Π
    nn = n[:, :, None] * n[:, None, :]
    mmat = (proj - nn) / dt[:, None, None]  # ∂n/∂P
    mv = np.einsum("kij,kj->ki", mmat, vt_)
    mt = np.einsum("kij,kj->ki", mmat, tau)
    df_dp = wt[:, None] * ((law.stiffness * law.exponent * dl ** (law.exponent - 1.0)
                            + law.damping * dramp * vn)[:, None] * n
                           + (law.damping * ramp)[:, None] * mv)
    df_dv = (wt * law.damping * ramp)[:, None] * n
    dtau_dp = -n[:, :, None] * mv[:, None, :] - vn[:, None, None] * mmat
    dtau_dv = eye - nn
    dg_dp = -2.0 * vn[:, None] * mt
    dg_dv = 2.0 * tau
    cg = f * (dmu_dg / sr - 0.5 * mu / sr**3)  # ∂h/∂g at fixed f
    u = n + (mu / sr)[:, None] * tau  # ∂h/∂f · τ + n
    outer = lambda x, y: x[:, :, None] * y[:, None, :]  # noqa: E731
    out["jp"][idx] = (-outer(u, df_dp) - f[:, None, None] * mmat
                      - outer(tau, cg[:, None] * dg_dp) - h[:, None, None] * dtau_dp)
    out["jv"][idx] = (-outer(u, df_dv) - outer(tau, cg[:, None] * dg_dv)
                      - h[:, None, None] * dtau_dv)
    return out


class ContactKernel:
    """Contact between an ANCF cable and a conduit made of straight hollow cylinders.

    Parameters
    ----------
    segments : Segments
        The conduit polyline and its inner radius R [m].
    element_length_m : float or array_like, shape (n_el,)
        Reference length L_e of each cable element [m]; a scalar needs ``n_elements``.
    cable_radius_m : float
        Cable radius r [m], 0 <= r < R.
    law : ContactLaw
        Normal force and friction law.
    check_points_per_element : int
        Check points per element (the paper uses 200-800).
    rule : {"gauss", "uniform"}
        Placement of the check points, see :func:`check_points`.
    reference_spacing_m : float
        h_ref [m]: a check point's force is scaled by w = L_e ω_k / h_ref (scenario key
        ``contact.reference_spacing``).
    broad_phase : {"aabb", "none"}
        ``"aabb"``: element and segment boxes, sort-and-sweep (Sect. 2.5); ``"none"``: every
        segment for every point (brute force, the paper's comparison). Identical results whenever
        each check point is within R of the polyline (see :mod:`exucable.contact.broadphase`).
    backend : {"auto", "numpy", "numba"}
        ``"numba"``: compiled kernel (``"auto"`` picks it when numba imports); ``"numpy"``: the
        vectorised reference.
    n_elements : int, optional
        Number of elements when ``element_length_m`` is a scalar.
    """

    def __init__(self, segments: Segments, element_length_m, cable_radius_m: float,
                 law: ContactLaw, check_points_per_element: int, rule: str = "gauss",
                 reference_spacing_m: float = 1e-3, broad_phase: str = "aabb",
                 backend: str = "auto", n_elements: int | None = None, open_ends: bool = True,
                 surface: str = "segments", centreline=None):
        length = np.asarray(element_length_m, dtype=float)
        if length.ndim == 0:
            if n_elements is None:
                raise ValueError("n_elements is required when element_length_m is a scalar")
            length = np.full(int(n_elements), float(length))
        elif n_elements is not None and int(n_elements) != length.shape[0]:
            raise ValueError("n_elements disagrees with the length of element_length_m")
        if length.ndim != 1 or length.size < 1 or np.any(~(length > 0.0)):
            raise ValueError("element_length_m must be positive, one value per element")
        radius = float(cable_radius_m)
        if not 0.0 <= radius < segments.inner_radius_m:
            raise ValueError(f"cable radius {radius} m must be in [0, R = "
                             f"{segments.inner_radius_m} m)")
        if not reference_spacing_m > 0.0:
            raise ValueError("reference_spacing_m must be > 0")
        if broad_phase not in _BROAD_PHASES:
            raise ValueError(f"broad_phase must be one of {_BROAD_PHASES}, got {broad_phase!r}")
        if backend not in _BACKENDS:
            raise ValueError(f"backend must be one of {_BACKENDS}, got {backend!r}")

        self.segments = segments
        self.law = law
        self.element_length_m = length
        self.cable_radius_m = radius
        self.gap_m = segments.inner_radius_m - radius
        self.reference_spacing_m = float(reference_spacing_m)
        self.broad_phase = broad_phase
        # The conduit's ends are open: a check point past the first segment's start or the last
        # segment's end is outside the conduit (the cable's lead pulled out, or still to enter).
        self.open_ends = bool(open_ends)
        # "segments": the paper's wall of straight hollow cylinders; "smooth": the same search,
        # then the closest point refined onto the exact bend/helix (exucable.contact.smooth)
        if surface not in ("segments", "smooth"):
            raise ValueError(f"surface must be 'segments' or 'smooth', got {surface!r}")
        if surface == "smooth" and centreline is None:
            raise ValueError("surface='smooth' needs the centreline the segments were cut from")
        self.surface = surface
        self.wall = SmoothWall(centreline, segments) if surface == "smooth" else None
        self._open = (0, segments.count - 1) if self.open_ends else (-1, -1)
        self.xi, self.omega = check_points(check_points_per_element, rule)
        self.rule = rule
        self._nh = hermite_unit(self.xi)
        self._seg_start = np.ascontiguousarray(segments.start_m)
        self._seg_end = np.ascontiguousarray(segments.end_m)
        self._seg_axis = np.ascontiguousarray(segments.axis)
        self._seg_length = np.ascontiguousarray(segments.length_m)
        self._seg_lo = np.ascontiguousarray(segments.aabb_min_m)
        self._seg_hi = np.ascontiguousarray(segments.aabb_max_m)

        if backend == "auto":
            try:
                import numba  # noqa: F401
                backend = "numba"
            except ImportError:  # pragma: no cover
                backend = "numpy"
        self.backend = backend
        self._fast = None
        if backend == "numba":
            from .fast import FastKernel

            self._fast = FastKernel(self._seg_start, self._seg_end, self._seg_axis,
                                    self._seg_length, self._seg_lo, self._seg_hi, length,
                                    self._nh, self.omega, law, self.gap_m, radius,
                                    self.reference_spacing_m, broad_phase, self.open_ends,
                                    self.wall)

    @property
    def n_elements(self) -> int:
        """Number of cable elements."""
        return self.element_length_m.shape[0]

    @property
    def n_coordinates(self) -> int:
        """Length 6 (n_el + 1) of the cable coordinate vector."""
        return 6 * (self.n_elements + 1)

    @property
    def n_check_points(self) -> int:
        """Check points per element."""
        return self.xi.shape[0]

    # -- broad phase ---------------------------------------------------------------------------
    def candidates(self, q) -> tuple[np.ndarray, np.ndarray]:
        """Candidate segments of each element (CSR offsets, indices; fresh arrays).

        The numpy backend tests every element box against every segment box; the numba backend
        uses sort-and-sweep. Both give the same lists.
        """
        q = self._check(q, "q")
        if self.broad_phase == "none":
            return candidates_all_segments(self.n_elements, self._seg_start.shape[0])
        if self._fast is not None:
            off, idx = self._fast.candidates(q)
            return off.copy(), idx.copy()
        elo, ehi = element_aabbs(q, self.element_length_m, self.cable_radius_m)
        return candidates_all_pairs(elo, ehi, self._seg_lo, self._seg_hi)

    # -- evaluation ----------------------------------------------------------------------------
    def evaluate(self, q, q_t, jacobian: bool = False) -> ContactResult:
        """Generalized contact force on the cable and optionally its Jacobian blocks.

        Parameters
        ----------
        q : array_like, shape (n_coordinates,)
            Cable coordinates [m, -].
        q_t : array_like, shape (n_coordinates,)
            Their time derivatives [m/s, 1/s].
        jacobian : bool
            Also return ∂Q/∂q and ∂Q/∂q̇ as element blocks.

        Returns
        -------
        ContactResult
        """
        q = self._check(q, "q")
        q_t = self._check(q_t, "q_t")
        if self._fast is not None:
            force, jq, jqt, n_contact, max_pen = self._fast.evaluate(q, q_t, jacobian)
            return ContactResult(force, jq, jqt, n_contact, max_pen)
        return self._evaluate_numpy(q, q_t, jacobian)

    def points(self, q, q_t) -> CheckPointState:
        """Per check point state for post-processing (numpy reference path)."""
        q = self._check(q, "q")
        q_t = self._check(q_t, "q_t")
        st = self._state_numpy(q, q_t, jacobian=False)
        seg = st["segment"]
        has = seg >= 0
        s_vertex = self.segments.s_vertex_m
        s_conduit = np.full(seg.shape, np.nan)
        sh = seg[has]
        frac = st["t"][has] / self._seg_length[sh]
        s_conduit[has] = s_vertex[sh] + frac * (s_vertex[sh + 1] - s_vertex[sh])
        if st["phi"] is not None:  # on the smooth wall: the exact arc length of Pc
            sm = np.isfinite(st["phi"])
            piece = self.wall.seg_piece[seg[sm]]
            s_conduit[sm] = self.wall.s_piece_start_m[piece] + st["phi"][sm] * self.wall.piece_speed_m_per_rad[piece]
        law = st["law"]
        share = (self.element_length_m[:, None] * self.omega[None, :]).reshape(-1)
        return CheckPointState(
            element=np.repeat(np.arange(self.n_elements), self.n_check_points),
            xi=np.tile(self.xi, self.n_elements),
            segment=seg,
            position_m=st["p"],
            velocity_m_per_s=st["v"],
            normal=law["normal"],
            s_conduit_m=s_conduit,
            penetration_m=law["delta"],
            normal_force_N=law["f"],
            normal_force_per_length_N_per_m=law["f"] / share,
            sliding_velocity_m_per_s=law["slip"],
            friction_force_N=law["friction"],
            in_contact=law["delta"] > 0.0,
        )

    def _check(self, x, name):
        x = np.ascontiguousarray(x, dtype=float)
        if x.shape != (self.n_coordinates,):
            raise ValueError(f"{name} must have shape ({self.n_coordinates},), got {x.shape}")
        return x

    #: True when the check points' velocities are a function of q (see :meth:`_velocity_map`)
    velocity_from_coordinates = False

    def _velocity_map(self, shape, q, q_t):
        """(shape table, coordinates) whose product gives the check points' velocities:
        v = S(ξ) q̇ (Eq. 8). Subclasses may derive v from q instead (steady sliding)."""
        return shape, q_t

    def _state_numpy(self, q, q_t, jacobian):
        n_el, n_k = self.n_elements, self.n_check_points
        shape = np.broadcast_to(self._nh, (n_el, n_k, 4)).copy()
        shape[:, :, 1] *= self.element_length_m[:, None]
        shape[:, :, 3] *= self.element_length_m[:, None]
        p = np.einsum("ekA,eAi->eki", shape, _element_values(q))  # Eq. 2
        rate_shape, rate_source = self._velocity_map(shape, q, q_t)
        v = np.einsum("ekA,eAi->eki", rate_shape, _element_values(rate_source))  # Eq. 8
        offsets, indices = self.candidates(q)
        segment = np.full((n_el, n_k), -1, dtype=np.int64)
        t = np.full((n_el, n_k), np.nan)
        residual = np.full((n_el, n_k, 3), np.nan)
        axis_inside = np.zeros((n_el, n_k, 3))
        for e in range(n_el):
            cand = indices[offsets[e]:offsets[e + 1]]
            if cand.size == 0:
                continue
            s, te, re, ins = _nearest(p[e], cand, self._seg_start, self._seg_end,
                                      self._seg_axis, self._seg_length, *self._open)
            segment[e], t[e], residual[e] = s, te, re
            axis_inside[e] = np.where(ins[:, None], self._seg_axis[s], 0.0)
        phi = None
        if self.wall is not None:
            # beyond an open end the residual is zero: leave those points alone
            seg_flat = segment.reshape(-1).copy()
            seg_flat[~np.any(residual.reshape(-1, 3) != 0.0, axis=1)] = -1
            mask, r_s, ax_s, phi = refine_closest_points(p.reshape(-1, 3), seg_flat, t.reshape(-1),
                                                         self._seg_length, self.wall)
            res_flat = residual.reshape(-1, 3)
            ax_flat = axis_inside.reshape(-1, 3)
            res_flat[mask] = r_s[mask]
            ax_flat[mask] = ax_s[mask]
            phi = np.where(mask, phi, np.nan)
        w = (self.element_length_m[:, None] * self.omega[None, :]) / self.reference_spacing_m
        law = _point_law(residual.reshape(-1, 3), v.reshape(-1, 3), axis_inside.reshape(-1, 3),
                         w.reshape(-1), self.law, self.gap_m, jacobian)
        return {"p": p.reshape(-1, 3), "v": v.reshape(-1, 3), "segment": segment.reshape(-1),
                "t": t.reshape(-1), "shape": shape, "rate_shape": rate_shape, "law": law, "phi": phi}

    def _evaluate_numpy(self, q, q_t, jacobian):
        st = self._state_numpy(q, q_t, jacobian)
        n_el, n_k = self.n_elements, self.n_check_points
        shape = st["shape"]
        law = st["law"]
        force_e = np.einsum("ekA,eki->eAi", shape, law["force"].reshape(n_el, n_k, 3))
        force = np.zeros(self.n_coordinates)
        nodes = force.reshape(-1, 6)
        nodes[:-1] += force_e[:, 0:2].reshape(n_el, 6)
        nodes[1:] += force_e[:, 2:4].reshape(n_el, 6)
        delta = law["delta"]
        with np.errstate(invalid="ignore"):
            n_contact = int(np.count_nonzero(delta > 0.0))
        finite = delta[np.isfinite(delta)]
        max_pen = float(finite.max()) if finite.size else -np.inf
        jq = jqt = None
        if jacobian:
            jp = law["jp"].reshape(n_el, n_k, 3, 3)
            jv = law["jv"].reshape(n_el, n_k, 3, 3)
            # (N Nᵀ) ⊗ J per point, summed over the element's points
            jq = np.einsum("ekA,ekB,ekij->eAiBj", shape, shape, jp).reshape(n_el, 12, 12)
            jv_blocks = np.einsum("ekA,ekB,ekij->eAiBj", shape, st["rate_shape"], jv).reshape(n_el, 12, 12)
            if self.velocity_from_coordinates:   # v depends on q, not on q̇
                jq += jv_blocks
                jqt = np.zeros_like(jq)
            else:
                jqt = jv_blocks
        return ContactResult(force, jq, jqt, n_contact, max_pen)
