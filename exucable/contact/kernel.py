"""Cable-conduit contact kernel (paper Sects. 2.4-2.5): narrow phase, force law, Jacobians.

This module holds the public :class:`ContactKernel`, a facade over two backends chosen by ONE
switch (its ``backend`` argument) for every call: forces, Jacobians, candidate lists and the
per-point profiles of :meth:`ContactKernel.points` alike. :mod:`exucable.contact.numpy_kernel` is the
numpy backend, the tested definition; :mod:`exucable.contact.fast` the compiled one (the default),
tested against it.

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

import importlib.util
from dataclasses import dataclass

import numpy as np

from ..geometry.segments import Segments
from ..scenario.fields import default_of
from .checkpoints import check_points, hermite_unit
from .law import ContactLaw, damping_onset
from .smooth import SmoothWall, closest_point_angles

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
    penetration_m : ndarray, shape (n_el, n_check_points), or None
        Every check point's penetration δ [m], 0 out of contact (None from the steady kernel).
    """

    generalized_force: np.ndarray
    jac_q_blocks: np.ndarray | None
    jac_qt_blocks: np.ndarray | None
    n_in_contact: int
    max_penetration_m: float = -np.inf
    penetration_m: np.ndarray | None = None


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
                 law: ContactLaw, check_points_per_element: int = default_of("contact.check_points_per_element"),
                 rule: str = default_of("contact.check_point_rule"),
                 reference_spacing_m: float = default_of("contact.reference_spacing"),
                 broad_phase: str = default_of("contact.broad_phase"),
                 backend: str = "auto", n_elements: int | None = None, open_ends: bool = True,
                 surface: str | None = None, centreline=None):
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
        if surface is None:
            # the scenario's default "smooth" needs the centreline; without one, the segments
            surface = default_of("contact.surface") if centreline is not None else "segments"
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
            # found, not imported: numba is imported by the first kernel call (.jitcache)
            backend = "numba" if importlib.util.find_spec("numba") is not None else "numpy"
        self.backend = backend
        # the one switch: every call below goes to this object
        if backend == "numba":
            from .fast import FastKernel

            self._impl = FastKernel(self._seg_start, self._seg_end, self._seg_axis,
                                    self._seg_length, self._seg_lo, self._seg_hi, length,
                                    self._nh, self.omega, law, self.gap_m, radius,
                                    self.reference_spacing_m, broad_phase, self.open_ends,
                                    self.wall)
        else:
            from .numpy_kernel import ReferenceKernel   # the numpy backend only: not imported by compiled runs
            self._impl = ReferenceKernel(self)
        self._last_point_state = None   # (q, q_t, state) of the last per-point pass
        self._last_points = None        # (that state, points() of it)

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
        sorts and sweeps. Both give the same lists.
        """
        off, idx = self._impl.candidates(self._check(q, "q"))
        return off.copy(), idx.copy()

    # -- evaluation ----------------------------------------------------------------------------
    def evaluate(self, q, q_t, jacobian: bool = False, held_onset=None) -> ContactResult:
        """Generalized contact force on the cable and optionally its Jacobian blocks.

        Parameters
        ----------
        q : array_like, shape (n_coordinates,)
            Cable coordinates [m, -].
        q_t : array_like, shape (n_coordinates,)
            Their time derivatives [m/s, 1/s].
        jacobian : bool
            Also return ∂Q/∂q and ∂Q/∂q̇ as element blocks.
        held_onset : array_like, shape (n_elements, n_check_points), optional
            The damping onset g [-] of every check point, held at these values instead of
            g(δ) of this state: f_n = max(0, K δ^e + C g δ̇), with no ∂g/∂δ term in the Jacobian.
            The dynamic solve passes g(δ) of the step's start (:meth:`damping_onset`), which
            makes the law linear in δ̇ within a step (see :class:`~exucable.contact.law.ContactLaw`).

        Returns
        -------
        ContactResult
        """
        q = self._check(q, "q")
        q_t = self._check(q_t, "q_t")
        if held_onset is None:
            return ContactResult(*self._impl.evaluate(q, q_t, jacobian))
        held = np.asarray(held_onset, dtype=float)
        if held.shape != (self.n_elements, self.n_check_points):
            raise ValueError(f"held_onset has shape {held.shape}, expected "
                             f"{(self.n_elements, self.n_check_points)}")
        return ContactResult(*self._impl.evaluate(q, q_t, jacobian, held))

    def law_statement(self) -> dict:
        """The contact force as this kernel evaluates it, in words and values (for ``problem.json``):
        ``sliding_velocity`` (what v is), ``normal_law`` with its ``damping`` rule, and
        ``friction_law``, the friction force as a function of the tangential velocity v_τ with
        ``regularisation_velocity_m_per_s`` the ε it uses [m/s]."""
        law = self.law
        return {
            "sliding_velocity": "v = N1 dr_i/dt + N2 dr'_i/dt + N3 dr_j/dt + N4 dr'_j/dt at the check point "
                                "(the nodal rates)",
            "normal_law": "f_n = contact_weight * max(0, K * delta**e + C * g * delta_dot), delta_dot = n . v "
                          "(paper Eq. 18)",
            "damping": "g = min(delta/delta_d, 1) (1 when delta_d = 0), held within a time step at its value "
                       "in the step's start state (Exudyn's generalized-alpha step)",
            "friction_law": "F_t = -mu(|v_t|) * f_n * v_t / sqrt(|v_t|**2 + eps**2), v_t = v - (n . v) n, "
                            "mu(s) = mu_k + (mu_s - mu_k) * exp(-s**2 / v_s**2) (mu_s null: mu_k) "
                            "(paper Eqs. 19-23)",
            "regularisation_velocity_m_per_s": law.regularisation_velocity_m_per_s,
            "force_on_cable": "F = -f_n n + F_t at the check point; generalized force sum_k S(xi_k)^T F_k",
        }

    def damping_onset(self, penetration_m) -> np.ndarray:
        """The damping onset g(δ) [-] of penetrations δ [m] (e.g. ContactResult.penetration_m):
        min(δ/δ_d, 1) in contact, 0 out of contact (1 everywhere for the paper's δ_d = 0)."""
        return damping_onset(self.law, penetration_m)

    def points(self, q, q_t) -> CheckPointState:
        """Per check point state for post-processing, from the kernel's backend.

        Penetration, normal and the conduit arc length of Pc are derived here from each point's
        nearest segment and residual P - Pc, the same numbers for both backends: in numpy
        (:meth:`_profiles_numpy`, the definition) or, with the compiled backend, in one compiled
        pass (:func:`exucable.contact.profiles.point_profiles`, the same bits at about an eighth
        of the cost).
        """
        st = self._point_state(self._check(q, "q"), self._check(q_t, "q_t"))
        last = self._last_points
        if last is not None and last[0] is st:
            # the same point state (the same q, and q_t where the backend reads it): the same
            # profiles. A steady state's post-processing asks three times (the contact profile, the
            # trust check, the snapshot): 17 ms each at 10 km
            return last[1]
        seg = st["segment"]
        p = st["position_m"]
        residual = st["residual_m"]
        if self.backend == "numba":
            from .profiles import point_profiles

            delta, normal, s_conduit = point_profiles(p, seg, residual, self.gap_m, self.segments, self.wall)
        else:
            delta, normal, s_conduit = self._profiles_numpy(p, seg, residual)
        normal_force = st["normal_force_N"]
        share = (self.element_length_m[:, None] * self.omega[None, :]).reshape(-1)
        out = CheckPointState(
            element=np.repeat(np.arange(self.n_elements), self.n_check_points),
            xi=np.tile(self.xi, self.n_elements),
            segment=seg,
            position_m=p,
            velocity_m_per_s=st["velocity_m_per_s"],
            normal=normal,
            s_conduit_m=s_conduit,
            penetration_m=delta,
            normal_force_N=normal_force,
            normal_force_per_length_N_per_m=normal_force / share,
            sliding_velocity_m_per_s=st["sliding_velocity_m_per_s"],
            friction_force_N=st["friction_force_N"],
            in_contact=delta > 0.0,
        )
        for derived in (out.element, out.xi, delta, normal, s_conduit, out.normal_force_per_length_N_per_m,
                        out.in_contact):
            derived.setflags(write=False)   # shared by every caller at this state
        self._last_points = (st, out)
        return out

    def _profiles_numpy(self, p, seg, residual):
        """Penetration δ [m], normal n [-] and conduit arc length of Pc [m] of every check point
        from its nearest segment ``seg`` and residual P - Pc (numpy; see :meth:`points`)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            d = np.sqrt(np.sum(residual * residual, axis=1))
            delta = d - self.gap_m  # Eq. 14 (NaN without a segment)
            normal = np.where((d > 0.0)[:, None], residual / d[:, None], np.nan)  # Eq. 15
        return delta, normal, self._arc_length(p, seg, residual)

    def point_segments(self, q) -> np.ndarray:
        """Each check point's nearest conduit segment (-1: none within R: outside the conduit),
        element-major: :meth:`points`' ``segment`` without the profiles' post-processing."""
        q = self._check(q, "q")
        last = self._last_point_state
        if last is not None and np.array_equal(last[0], q):
            return last[2]["segment"]      # the segments depend on q alone
        search = getattr(self._impl, "nearest_segments", None)
        if search is not None:
            # the compiled backend's contact search alone: the same segments as its point state
            # (tests/test_contact_kernel.py) at a tenth of the cost (Ex. 4: 0.5 vs 7 ms)
            return search(q).reshape(-1)
        return self._point_state(q, np.zeros_like(q))["segment"]

    def _point_state(self, q, q_t) -> dict:
        """The backend's per-point state, reused when asked again at the same state (the steady
        solve's last check and the profiles after it ask at the same q; a backend that takes
        the velocity from q, ``velocity_from_coordinates``, ignores q_t)."""
        last = self._last_point_state
        rates_matter = not getattr(self._impl, "velocity_from_coordinates", False)
        if (last is not None and np.array_equal(last[0], q)
                and (not rates_matter or np.array_equal(last[1], q_t))):
            return last[2]
        st = self._impl.point_state(q, q_t)
        self._last_point_state = (q.copy(), q_t.copy(), st)
        return st

    def _arc_length(self, p, seg, residual) -> np.ndarray:
        """Centreline arc length of each point's closest point Pc [m] (NaN without a segment):
        linear along the segment between its vertices' arc lengths, or on the smooth wall the
        exact arc length of Pc on its bend or helix."""
        has = seg >= 0
        sh = seg[has]
        d = p[has] - self._seg_start[sh]
        a = self._seg_axis[sh]
        t = np.full(seg.shape, np.nan)
        t[has] = np.clip(d[:, 0] * a[:, 0] + d[:, 1] * a[:, 1] + d[:, 2] * a[:, 2], 0.0, self._seg_length[sh])
        s_vertex = self.segments.s_vertex_m
        s_conduit = np.full(seg.shape, np.nan)
        s_conduit[has] = s_vertex[sh] + t[has] / self._seg_length[sh] * (s_vertex[sh + 1] - s_vertex[sh])
        if self.wall is not None:
            # beyond an open end the residual is zero: those points keep the segment's value
            refine = np.where(np.any(residual != 0.0, axis=1), seg, -1)
            mask, phi = closest_point_angles(p, residual, refine, t, self._seg_length, self.wall)
            sm = mask & np.isfinite(phi)
            piece = self.wall.seg_piece[seg[sm]]
            s_conduit[sm] = self.wall.s_piece_start_m[piece] + phi[sm] * self.wall.piece_speed_m_per_rad[piece]
        return s_conduit

    def _check(self, x, name):
        x = np.ascontiguousarray(x, dtype=float)
        if x.shape != (self.n_coordinates,):
            raise ValueError(f"{name} must have shape ({self.n_coordinates},), got {x.shape}")
        return x
