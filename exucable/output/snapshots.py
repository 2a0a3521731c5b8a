"""Snapshots: the whole cable state at requested times (scenario ``[output] snapshots``).

The solver's adaptive steps do not land on the requested times. Each snapshot time t in a step
[t0, t1] gets its state by cubic Hermite interpolation in time of the nodal coordinates between
the two step ends, using the coordinates q and their rates q̇ at both ends (the solver's own
values):

    q(t) = h00 q0 + h10 Δt q̇0 + h01 q1 + h11 Δt q̇1,  s = (t − t0)/Δt,
    h00 = 2s³ − 3s² + 1, h10 = s³ − 2s² + s, h01 = −2s³ + 3s², h11 = s³ − s²,

and q̇(t) its time derivative (error O(Δt⁴) in q, O(Δt³) in q̇; exact when t is a step end).
Every quantity of the snapshot is then evaluated at that state: the tension N (paper Eq. 24) at
ξ = 0, ¼, ½, ¾, 1 of every element, from the equilibrium of the cable's loads at that state
(:func:`exucable.post.tension.equilibrium_tension`: the contact forces, weight and inertia, the
accelerations and the drives' reactions interpolated linearly between the step ends), the contact forces by the kernel (Eqs. 14-23), so a reader that evaluates the
contact law at the snapshot's nodal state gets the same forces to round-off. The pulling force (a
Lagrange multiplier, known only at step ends) is interpolated linearly.

A steady solve (``solver.mode = "steady"``) has no time: its one state is written as one snapshot
at ``time_s = 0`` (:meth:`SnapshotRecorder.record_steady_state`), whose ``vel_*`` columns are the
steady flow's material velocity V·r' of each node and whose ``slope_rate_*`` are ``nan`` (V·r''
jumps at a node); the contact forces are the steady kernel's (friction against V·r').

Files (long format: one row per time and element or node):

``snapshot_times.csv``    ``time_s,step_start_s,step_end_s,pull_force_N``
``snapshot_nodes.csv``    ``time_s,node,x_m,pos_*_m,slope_*,vel_*_m_per_s,slope_rate_*_1_per_s``
``snapshot_tension.csv``  ``time_s,element,xi,x_m,tension_N``
``snapshot_contact.csv``  ``time_s,element,x_mid_m,normal_force_N,friction_force_N,
                          normal_force_per_length_N_per_m,friction_force_per_length_N_per_m,
                          max_penetration_m,points_in_contact`` (sums over the element's check points of
                          the weighted normal force w·f_n and of the friction force's magnitude [N], the
                          same over the element's reference length [N/m] to compare different meshes;
                          the largest penetration δ of its check points, 0 without contact [m])
"""

from __future__ import annotations

import numpy as np

from .formats import SNAPSHOT_FILES
from ..post.tension import equilibrium_tension, tension_at

__all__ = ["SnapshotRecorder", "SNAPSHOT_FILES", "TENSION_XI", "hermite_in_time"]

#: Element coordinates at which the snapshot tension is written [-].
TENSION_XI = (0.0, 0.25, 0.5, 0.75, 1.0)



def hermite_in_time(t, t0, q0, v0, t1, q1, v1):
    """State (q, q̇) at time t ∈ [t0, t1] by cubic Hermite interpolation of the step ends."""
    h = t1 - t0
    if h <= 0.0:
        return q1.copy(), v1.copy()
    s = (t - t0) / h
    s2, s3 = s * s, s * s * s
    q = (2 * s3 - 3 * s2 + 1) * q0 + (s3 - 2 * s2 + s) * h * v0 + (-2 * s3 + 3 * s2) * q1 + (s3 - s2) * h * v1
    v = ((6 * s2 - 6 * s) / h * q0 + (3 * s2 - 4 * s + 1) * v0 + (-6 * s2 + 6 * s) / h * q1
         + (3 * s2 - 2 * s) * v1)
    return q, v


class SnapshotRecorder:
    """Collects snapshots during a run; fed by the solver's post-step hook.

    Parameters
    ----------
    model : exucable.model.build.Model
    times_s : sequence of float
        Snapshot times [s], sorted.
    """

    def __init__(self, model, times_s):
        self.model = model
        self.pending = [float(t) for t in sorted(times_s)]
        # per file and column, one array per snapshot, joined by tables()
        self.rows = {name: {c: [] for c in cols} for name, cols in SNAPSHOT_FILES.items()}
        q, v = model.coordinates()
        a = self._accelerations()
        r = model.drive_reactions_N()
        self._prev = (0.0, q, v, float("nan"), a, r)
        if self.pending and self.pending[0] <= 0.0:
            self._record(0.0, q, v, (0.0, 0.0), float("nan"), a, r)
            self.pending.pop(0)

    def _accelerations(self) -> np.ndarray:
        """The solver's nodal accelerations of the cable now, (n_el + 1, 6)."""
        m = self.model
        return np.asarray(m.mbs.systemData.GetODE2Coordinates_tt())[m.ode2_index].reshape(-1, 6)

    @property
    def recorded_s(self) -> list[float]:
        return [float(t) for part in self.rows["snapshot_times.csv"]["time_s"] for t in part]

    def step(self, t: float, pull_force_N: float) -> None:
        """Called at the end of every solver step (time t [s]) with the pulling force there [N]."""
        if not self.pending:
            return
        q, v = self.model.coordinates()
        a = self._accelerations()
        r = self.model.drive_reactions_N()
        t0, q0, v0, f0, a0, r0 = self._prev
        while self.pending and self.pending[0] <= t + 1e-12 * max(1.0, t):
            tk = self.pending.pop(0)
            qk, vk = hermite_in_time(min(tk, t), t0, q0, v0, t, q, v)
            frac = 1.0 if t <= t0 else (min(tk, t) - t0) / (t - t0)
            f = pull_force_N if frac == 1.0 else f0 + frac * (pull_force_N - f0)
            rk = {end: None if r[end] is None else r0[end] + frac * (r[end] - r0[end]) for end in r}
            self._record(tk, qk, vk, (t0, t), f, a0 + frac * (a - a0), rk)
        self._prev = (t, q, v, pull_force_N, a, r)

    def record_steady_state(self, pull_force_N: float) -> None:
        """Record the model's current state as the steady state: one snapshot at time 0 [s] with
        the steady flow's nodal velocities V·r' [m/s] and the pulling force ``pull_force_N`` [N]."""
        q, _ = self.model.coordinates()
        v = np.full_like(q, np.nan)
        v[:, :3] = self.model.scenario.pull.speed_m_per_s * q[:, 3:]
        self._record(0.0, q, v, (0.0, 0.0), pull_force_N)

    def _append(self, name, **columns):
        n = max(np.size(v) for v in columns.values())
        for c, v in columns.items():
            self.rows[name][c].append(np.array(np.broadcast_to(np.asarray(v), (n,))))   # a copy: v may be a view of the state

    def _record(self, t, q, v, step, pull_force_N, a=None, reactions=None):
        """One snapshot of state (t, q, v); ``a`` the nodal accelerations (None: a static state) and
        ``reactions`` the drives' forces at t (:meth:`Model.drive_reactions_N`; None: the model's now)."""
        m = self.model
        lay = m.layout
        Le = np.asarray(lay.element_length_m, dtype=float)
        n_el = len(Le)
        self._append("snapshot_times.csv", time_s=t, step_start_s=step[0], step_end_s=step[1],
                     pull_force_N=pull_force_N)
        nodes = {"time_s": t, "node": np.arange(n_el + 1), "x_m": lay.node_x_m}
        for k, c in enumerate("xyz"):
            nodes[f"pos_{c}_m"] = q[:, k]
            nodes[f"slope_{c}"] = q[:, 3 + k]
            nodes[f"vel_{c}_m_per_s"] = v[:, k]
            nodes[f"slope_rate_{c}_1_per_s"] = v[:, 3 + k]
        self._append("snapshot_nodes.csv", **nodes)
        xi = np.asarray(TENSION_XI)
        x = (lay.node_x_m[:-1, None] + xi[None, :] * Le[:, None]).ravel()
        loads = m.loads(state=(t, q, v, a, m.drive_reactions_N() if reactions is None else reactions))
        if loads.trailing_force_N is None and loads.leading_force_N is None:
            N = tension_at(q, Le, m.axial_stiffness_N, x)     # both ends held by reactions
        else:
            N = equilibrium_tension(q, Le, loads, x)
        self._append("snapshot_tension.csv", time_s=t, element=np.repeat(np.arange(n_el), len(xi)),
                     xi=np.tile(xi, n_el), x_m=x, tension_N=N)
        if m.kernel is None:
            return
        # the steady kernel takes its velocities from q; nan rates must not reach the dynamic one
        pts = m.kernel.points(q.reshape(-1), np.nan_to_num(v).reshape(-1))
        e = pts.element
        pen = np.nan_to_num(np.asarray(pts.penetration_m, dtype=float), nan=-np.inf)
        k = len(e) // n_el if n_el else 0
        if k and len(e) == k * n_el:
            max_pen = pen.reshape(n_el, k).max(axis=1)    # the kernel's points: element-major, k each
        else:
            max_pen = np.full(n_el, -np.inf)
            np.maximum.at(max_pen, e, pen)
        normal = np.bincount(e, pts.normal_force_N, n_el)
        friction = np.bincount(e, pts.friction_force_N, n_el)
        self._append("snapshot_contact.csv", time_s=t, element=np.arange(n_el),
                     x_mid_m=lay.node_x_m[:-1] + 0.5 * Le, normal_force_N=normal, friction_force_N=friction,
                     normal_force_per_length_N_per_m=normal / Le, friction_force_per_length_N_per_m=friction / Le,
                     max_penetration_m=np.maximum(max_pen, 0.0),
                     points_in_contact=np.bincount(e, pts.in_contact.astype(float), n_el).astype(int))

    def tables(self) -> dict[str, dict]:
        """file name -> {column: array}; integer columns stay integer."""
        return {name: {c: np.concatenate(parts) if parts else np.asarray([]) for c, parts in cols.items()}
                for name, cols in self.rows.items()}
