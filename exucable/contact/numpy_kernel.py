"""The numpy contact kernel: the tested definition of the contact force (paper Eqs. 2-8, 14-23).

Vectorised over check points and written to read like the equations; :mod:`exucable.contact.fast`
computes the same numbers compiled and is tested against this one. :class:`ReferenceKernel` is
one of the two backends behind :class:`exucable.contact.ContactKernel` (``backend="numpy"``); the
equations are listed in :mod:`exucable.contact.kernel`.
"""

from __future__ import annotations

import numpy as np

from .broadphase import candidates_all_pairs, candidates_all_segments, element_aabbs
from .law import ContactLaw, damping_ramp, friction_coefficient, onset_blend
from .smooth import refine_closest_points

__all__ = ["ReferenceKernel"]


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


def _point_law(p_res, v, axis_inside, w, law: ContactLaw, gap, jacobian, held_onset=None):
    """Force law on flat arrays of points (Eqs. 14-23) and its derivatives ∂F/∂P, ∂F/∂v.

    ``p_res`` = P - Pc (NaN rows for points without a segment); ``axis_inside`` = segment axis
    where the projection is inside the segment, 0 where it is clamped to a vertex;
    ``held_onset`` (optional, one per point): the damping onset g, held, instead of g(δ).
    The law acts on the blended penetration φ = φ_s(δ) of the law's onset layer s
    (:func:`~exucable.contact.law.onset_blend`; δ itself for s = 0), a point touching for δ > -s.
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
    layer = law.onset_layer_m
    touch = np.nonzero(delta > -layer)[0]  # NaN compares False: no segment, no contact
    pos = d > 0.0
    out["normal"][pos] = p_res[pos] / d[pos, None]
    if touch.size == 0:
        return out
    dt = d[touch]
    n = p_res[touch] / dt[:, None]  # Eq. 15
    vt_ = v[touch]
    vn = np.sum(n * vt_, axis=1)  # Eq. 16
    dl, dphi = onset_blend(delta[touch], layer)
    if held_onset is None:
        ramp, dramp = damping_ramp(law, dl)
        dramp = dramp * dphi
    else:
        ramp, dramp = held_onset[touch], np.zeros_like(dl)
    raw = law.stiffness * dl**law.exponent + law.damping * ramp * vn  # Eq. 18 (with the onset)
    act = raw > 0.0
    idx = touch[act]
    n, vt_, vn, dl, dt, raw = n[act], vt_[act], vn[act], dl[act], dt[act], raw[act]
    ramp, dramp, dphi = ramp[act], dramp[act], dphi[act]
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
    df_dp = wt[:, None] * ((law.stiffness * law.exponent * dl ** (law.exponent - 1.0) * dphi
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


class ReferenceKernel:
    """numpy backend of a :class:`~exucable.contact.ContactKernel`: the same three calls as
    :class:`~exucable.contact.fast.FastKernel` (candidates, evaluate, point_state).

    Parameters
    ----------
    kernel : ContactKernel
        The facade whose geometry (segments, element lengths, check points, wall) and law it uses.
    """

    def __init__(self, kernel):
        self.k = kernel

    def candidates(self, q):
        """Candidate segments of each element (CSR offsets, indices): every element box tested
        against every segment box (the compiled backend sorts and sweeps; same lists)."""
        k = self.k
        if k.broad_phase == "none":
            return candidates_all_segments(k.n_elements, k._seg_start.shape[0])
        elo, ehi = element_aabbs(q, k.element_length_m, k.cable_radius_m)
        return candidates_all_pairs(elo, ehi, k._seg_lo, k._seg_hi)

    def point_state(self, q, q_t):
        """Per check point: nearest segment (-1: none), P, v, residual P - Pc (NaN without a
        segment), weighted normal force w·f_n [N], sliding speed |v_τ| and friction force [N]
        (0 without force)."""
        st = self._state(q, q_t, jacobian=False)
        law = st["law"]
        return {"segment": st["segment"], "position_m": st["p"], "velocity_m_per_s": st["v"],
                "residual_m": st["residual"], "normal_force_N": law["f"],
                "sliding_velocity_m_per_s": law["slip"], "friction_force_N": law["friction"]}

    #: True when the check points' velocities are a function of q (see :meth:`_velocity_map`)
    velocity_from_coordinates = False

    def _velocity_map(self, shape, q, q_t):
        """(shape table, coordinates) whose product gives the check points' velocities:
        v = S(ξ) q̇ (Eq. 8). A subclass may derive v from q instead (steady sliding)."""
        return shape, q_t

    def _state(self, q, q_t, jacobian, held_onset=None):
        k = self.k
        n_el, n_k = k.n_elements, k.n_check_points
        shape = np.broadcast_to(k._nh, (n_el, n_k, 4)).copy()
        shape[:, :, 1] *= k.element_length_m[:, None]
        shape[:, :, 3] *= k.element_length_m[:, None]
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
            s, te, re, ins = _nearest(p[e], cand, k._seg_start, k._seg_end,
                                      k._seg_axis, k._seg_length, *k._open)
            segment[e], t[e], residual[e] = s, te, re
            axis_inside[e] = np.where(ins[:, None], k._seg_axis[s], 0.0)
        phi = None
        if k.wall is not None:
            # beyond an open end the residual is zero: leave those points alone
            seg_flat = segment.reshape(-1).copy()
            seg_flat[~np.any(residual.reshape(-1, 3) != 0.0, axis=1)] = -1
            mask, r_s, ax_s, phi = refine_closest_points(p.reshape(-1, 3), seg_flat, t.reshape(-1),
                                                         k._seg_length, k.wall)
            res_flat = residual.reshape(-1, 3)
            ax_flat = axis_inside.reshape(-1, 3)
            res_flat[mask] = r_s[mask]
            ax_flat[mask] = ax_s[mask]
            phi = np.where(mask, phi, np.nan)
        w = (k.element_length_m[:, None] * k.omega[None, :]) / k.reference_spacing_m
        law = _point_law(residual.reshape(-1, 3), v.reshape(-1, 3), axis_inside.reshape(-1, 3),
                         w.reshape(-1), k.law, k.gap_m, jacobian,
                         None if held_onset is None else np.asarray(held_onset, dtype=float).reshape(-1))
        return {"p": p.reshape(-1, 3), "v": v.reshape(-1, 3), "segment": segment.reshape(-1),
                "t": t.reshape(-1), "shape": shape, "rate_shape": rate_shape, "law": law, "phi": phi,
                "residual": residual.reshape(-1, 3)}

    def evaluate(self, q, q_t, jacobian, held_onset=None):
        """Return (Q, ∂Q/∂q blocks or None, ∂Q/∂q̇ blocks or None, n_in_contact, max δ [m],
        δ [m] per point (n_el, n_k), 0 out of contact); ``held_onset`` as FastKernel.evaluate."""
        k = self.k
        st = self._state(q, q_t, jacobian, held_onset)
        n_el, n_k = k.n_elements, k.n_check_points
        shape = st["shape"]
        law = st["law"]
        force_e = np.einsum("ekA,eki->eAi", shape, law["force"].reshape(n_el, n_k, 3))
        force = np.zeros(k.n_coordinates)
        nodes = force.reshape(-1, 6)
        nodes[:-1] += force_e[:, 0:2].reshape(n_el, 6)
        nodes[1:] += force_e[:, 2:4].reshape(n_el, 6)
        delta = law["delta"]
        layer = k.law.onset_layer_m
        with np.errstate(invalid="ignore"):
            n_contact = int(np.count_nonzero(delta > -layer))
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
        with np.errstate(invalid="ignore"):
            # the blended penetration φ_s(δ) the law acted on (δ itself for s = 0)
            penetration = np.where(delta > -layer, onset_blend(delta, layer)[0], 0.0).reshape(n_el, n_k)
        return force, jq, jqt, n_contact, max_pen, penetration
