"""An independent reader of an ``exucable export``: the discrete problem of Yang et al. (2013) from the
exported files alone, with plain numpy (no exucable import).

This is the pattern a solver author follows: load the discrete problem (``problem.json`` and the CSV
tables, see ``docs/results-format.md``), rebuild a state (the initial one from ``nodes_initial.csv``,
or a snapshot's from ``snapshot_nodes.csv``), evaluate one's own forces there and compare them with
exucable's: the contact forces per element (``snapshot_contact.csv``, Eqs. 14-23) and, for a steady
solve, the whole static equilibrium — elastic forces of the ANCF cable with Exudyn's quadrature,
contact with friction against the steady flow V·r', gravity's consistent load, back tension —
whose residual must vanish everywhere but at the rig's held node, where it is the rig's reaction,
the pulling force along the exit tangent.

Usage (a steady solve; its state is the one snapshot, time 0)::

    exucable export scenarios/fast/paper_ex2_bend90.toml out/ex2 --mode steady
    exucable run scenarios/fast/paper_ex2_bend90.toml --mode steady --out out/ex2 --no-plots
    python examples/crosscheck_reader.py out/ex2

prints the largest difference of the per-element normal and friction forces between this reader and
exucable at the first snapshot, relative to the largest force, and for a steady solve the
equilibrium residual relative to the pulling force and the rig's reaction against the pulling force.
A dynamic run needs ``[output] snapshots`` in its scenario for the contact check (and has no
static equilibrium to check).
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np


def read_table(path) -> dict[str, np.ndarray]:
    """A CSV with a header row as {column: float array} ('#' lines skipped)."""
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#")) if r]
    header = rows[0]
    body = np.array([[float(x) for x in r] for r in rows[1:]], dtype=float).reshape(-1, len(header))
    return {h: body[:, i] for i, h in enumerate(header)}


def load_export(directory) -> dict:
    """problem.json and every CSV of an export directory."""
    d = Path(directory)
    out = {"problem": json.loads((d / "problem.json").read_text())}
    for name in ("nodes_initial", "elements", "check_points", "conduit_segments", "conduit_pieces"):
        out[name] = read_table(d / f"{name}.csv")
    return out


def node_state(table, rows=None) -> tuple[np.ndarray, np.ndarray]:
    """(q, q̇), each shape (n_nodes, 6) = [r, r'] and [ṙ, ṙ'], from a nodes table (optionally some rows)."""
    sel = slice(None) if rows is None else rows
    q = np.stack([table[c][sel] for c in ("pos_x_m", "pos_y_m", "pos_z_m", "slope_x", "slope_y", "slope_z")], 1)
    v = np.stack([table[c][sel] for c in ("vel_x_m_per_s", "vel_y_m_per_s", "vel_z_m_per_s",
                                          "slope_rate_x_1_per_s", "slope_rate_y_1_per_s",
                                          "slope_rate_z_1_per_s")], 1)
    return q, v


def hermite(xi, length_m):
    """Cubic Hermite values [N1, N2, N3, N4] (paper Eqs. 4-6), shape (m, 4)."""
    x = np.asarray(xi, dtype=float)
    L = np.asarray(length_m, dtype=float)
    return np.stack([1 - 3 * x**2 + 2 * x**3, L * (x - 2 * x**2 + x**3), 3 * x**2 - 2 * x**3, L * (x**3 - x**2)], 1)


def _xyz(table, prefix, unit=""):
    return np.stack([table[f"{prefix}_{c}{unit}"] for c in "xyz"], 1)


def hermite_x(xi, length_m):
    """dN/dx of the Hermite functions (x the material coordinate, x = ξ L_e), shape (m, 4)."""
    x = np.asarray(xi, dtype=float)
    L = np.asarray(length_m, dtype=float)
    return np.stack([(-6 * x + 6 * x**2) / L, 1 - 4 * x + 3 * x**2, (6 * x - 6 * x**2) / L, 3 * x**2 - 2 * x], 1)


def hermite_xx(xi, length_m):
    """d²N/dx² of the Hermite functions, shape (m, 4)."""
    x = np.asarray(xi, dtype=float)
    L = np.asarray(length_m, dtype=float)
    return np.stack([(-6 + 12 * x) / L**2, (-4 + 6 * x) / L, (6 - 12 * x) / L**2, (6 * x - 2) / L], 1)


def _interpolate(S, q, ni, nj):
    """Σ_a S_a q_a at points: S (m, 4), q (n_nodes, 6), element node indices ni, nj (m,) → (m, 3)."""
    return S[:, 0, None] * q[ni, :3] + S[:, 1, None] * q[ni, 3:] + S[:, 2, None] * q[nj, :3] + S[:, 3, None] * q[nj, 3:]


def _scatter(Q, S, F, ni, nj):
    """Add the point forces F (m, 3) as Σ Sᵀ F into Q (n_nodes, 6)."""
    for col, node in ((0, ni), (2, nj)):
        np.add.at(Q, (node, slice(0, 3)), S[:, col, None] * F)
        np.add.at(Q, (node, slice(3, 6)), S[:, col + 1, None] * F)


def elastic_forces(ex, q) -> np.ndarray:
    """Exudyn's ANCF cable elastic forces Q_el(q), shape (n_nodes, 6), as ``problem.json``'s
    ``equations`` state them: the axial term EA(|r'| − 1) and the bending term EJ κ·∂κ/∂q with
    κ = r'×r''/|r'|², each with its own quadrature (points ξ_g and weights w_g, times L_e)."""
    pr, el = ex["problem"], ex["elements"]
    EA, EJ = pr["cable"]["axial_stiffness_N"], pr["cable"]["bending_stiffness_N_m2"]
    Q = np.zeros((q.shape[0], 6))
    n_el = len(el["element"])
    for term in ("axial", "bending"):
        rule = pr["equations"][term]
        xi, w = np.asarray(rule["xi"]), np.asarray(rule["weight"])
        e = np.repeat(np.arange(n_el), xi.size)
        L = el["reference_length_m"][e]
        ni, nj = el["node_i"].astype(int)[e], el["node_j"].astype(int)[e]
        xg, wL = np.tile(xi, n_el), np.tile(w, n_el) * L
        Sx = hermite_x(xg, L)
        r1 = _interpolate(Sx, q, ni, nj)
        if term == "axial":
            norm = np.linalg.norm(r1, axis=1)
            _scatter(Q, Sx, (wL * EA * (norm - 1.0) / norm)[:, None] * r1, ni, nj)
            continue
        Sxx = hermite_xx(xg, L)
        r2 = _interpolate(Sxx, q, ni, nj)
        g = np.sum(r1 * r1, axis=1)[:, None]
        f = np.cross(r1, r2)
        kappa = f / g
        # δκ = δf/g − f δg/g², δf = δr'×r'' + r'×δr'', δg = 2 r'·δr': κ·δκ per unit δr' and δr''
        along_r1 = np.cross(r2, kappa) / g - 2.0 * np.sum(kappa * f, axis=1)[:, None] / g**2 * r1
        along_r2 = np.cross(kappa, r1) / g
        _scatter(Q, Sx, (wL * EJ)[:, None] * along_r1, ni, nj)
        _scatter(Q, Sxx, (wL * EJ)[:, None] * along_r2, ni, nj)
    return Q


def gravity_forces(ex) -> np.ndarray:
    """The consistent load of gravity, ρA L_e [g/2, L_e g/12, g/2, −L_e g/12] per element, shape (n_nodes, 6)."""
    pr, el = ex["problem"], ex["elements"]
    g = np.asarray(pr["gravity_m_per_s2"], dtype=float) * pr["cable"]["mass_per_length_kg_per_m"]
    Q = np.zeros((len(el["element"]) + 1, 6))
    for e, L in enumerate(el["reference_length_m"]):
        i, j = int(el["node_i"][e]), int(el["node_j"][e])
        Q[i, :3] += g * L / 2
        Q[i, 3:] += g * L * L / 12
        Q[j, :3] += g * L / 2
        Q[j, 3:] -= g * L * L / 12
    return Q


def closest_residual(P, ex) -> np.ndarray:
    """P − Pc for every point of P (m, 3): nearest segment (brute force, first minimum), no contact
    past the open ends, then on a curved piece the exact closest point on the bend/helix
    (Newton to convergence), continued along the piece's end tangent beyond its ends."""
    seg, pieces = ex["conduit_segments"], ex["conduit_pieces"]
    A, B = _xyz(seg, "start", "_m"), _xyz(seg, "end", "_m")
    length = np.linalg.norm(B - A, axis=1)
    axis = (B - A) / length[:, None]
    d = P[:, None, :] - A[None, :, :]
    t = np.einsum("mnk,nk->mn", d, axis)
    low, high = t <= 0.0, t >= length[None, :]
    res = np.where(low[..., None], d, np.where(high[..., None], P[:, None, :] - B[None], d - t[..., None] * axis))
    j = np.argmin(np.sum(res * res, axis=2), axis=1)
    m = np.arange(P.shape[0])
    r = res[m, j]
    n_seg = len(length)
    beyond = ((j == 0) & low[m, j]) | ((j == n_seg - 1) & high[m, j])
    r[beyond] = 0.0                          # outside the conduit: no contact
    piece = seg["piece"].astype(int)[j]
    curved = (pieces["curved"][piece] == 1) & ~beyond
    for i in np.nonzero(curved)[0]:
        k = piece[i]
        c = np.array([pieces[f"centre_{x}_m"][k] for x in "xyz"])
        e1 = np.array([pieces[f"e1_{x}"][k] for x in "xyz"])
        e2 = np.array([pieces[f"e2_{x}"][k] for x in "xyz"])
        ax = np.array([pieces[f"axis_{x}"][k] for x in "xyz"])
        a, h, Phi = pieces["coil_radius_m"][k], pieces["rise_m_per_rad"][k], pieces["phi_rad"][k]
        speed = np.hypot(a, h)
        s0 = pieces["s_start_pull_m"][k]
        tj = np.clip(t[i, j[i]], 0.0, length[j[i]])
        s_est = seg["s_start_pull_m"][j[i]] + tj / length[j[i]] * (seg["s_end_pull_m"][j[i]] - seg["s_start_pull_m"][j[i]])
        phi = (s_est - s0) / speed
        x = P[i] - c
        x1, x2, xk = x @ e1, x @ e2, x @ ax
        for _ in range(50):   # minimise |P − C(φ)|², C(φ) = c + a(cos φ e1 + sin φ e2) + h φ k
            g = -(a * (-np.sin(phi) * x1 + np.cos(phi) * x2) + h * (xk - h * phi))
            dg = a * (np.cos(phi) * x1 + np.sin(phi) * x2) + h * h
            step = g / dg
            phi -= step
            if abs(step) < 1e-15:
                break
        pc = np.clip(phi, 0.0, Phi)
        C = c + a * (np.cos(pc) * e1 + np.sin(pc) * e2) + h * pc * ax
        T = (a * (-np.sin(pc) * e1 + np.cos(pc) * e2) + h * ax) / speed
        ri = P[i] - C
        if not 0.0 <= phi <= Phi:
            ri = ri - (ri @ T) * T
        r[i] = ri
    return r


def contact_forces(ex, q, v=None) -> dict:
    """Eqs. 14-23 at every exported check point for nodal state (q, q̇) of shape (n_nodes, 6).

    The check point's velocity is the nodal rates' interpolation (dynamic mode) or, for a steady
    solve (``problem["mode"] == "steady"``), the steady flow's V·∂r/∂x (``v`` unused).
    Returns per check point the weighted normal force f [N] and friction force magnitude [N],
    the penetration δ [m], and the generalized force Q = Σ Sᵀ F, shape (n_nodes·6,).
    """
    pr = ex["problem"]
    law = pr["contact"]
    cp, el = ex["check_points"], ex["elements"]
    e = cp["element"].astype(int)
    Le = el["reference_length_m"][e]
    S = hermite(cp["xi"], Le)                                         # (m, 4)
    ni, nj = el["node_i"].astype(int)[e], el["node_j"].astype(int)[e]
    P = _interpolate(S, q, ni, nj)
    if pr.get("mode") == "steady":
        V = pr["rig"]["speed_m_per_s"] * _interpolate(hermite_x(cp["xi"], Le), q, ni, nj)
    else:
        V = _interpolate(S, v, ni, nj)
    r = closest_residual(P, ex)
    dist = np.linalg.norm(r, axis=1)
    delta = dist - law["gap_m"]                                      # Eq. 14
    touch = delta > 0.0
    n = np.zeros_like(r)
    n[touch] = r[touch] / dist[touch, None]                          # Eq. 15
    vn = np.sum(n * V, axis=1)                                       # Eq. 16
    onset = law["damping_onset_m"]
    ramp = np.minimum(delta / onset, 1.0) if onset > 0 else np.ones_like(delta)
    raw = law["stiffness_N_per_m_e"] * np.where(touch, delta, 0.0) ** law["exponent"] + law["damping_N_s_per_m"] * ramp * vn
    act = touch & (raw > 0.0)
    f = np.where(act, cp["contact_weight"] * raw, 0.0)               # Eq. 18, weighted
    tau = V - vn[:, None] * n                                        # Eq. 17
    g = np.sum(tau * tau, axis=1)
    mu = np.full_like(g, law["friction"])
    if law["static_friction"] is not None:
        mu = mu + (law["static_friction"] - law["friction"]) * np.exp(-g / law["stribeck_velocity_m_per_s"] ** 2)
    sr = np.sqrt(g + law["regularisation_velocity_m_per_s"] ** 2)
    F = -f[:, None] * n - (mu * f / sr)[:, None] * tau               # Eqs. 19-23
    Q = np.zeros((q.shape[0], 6))
    _scatter(Q, S, F, ni, nj)
    return {"element": e, "normal_force_N": f, "friction_force_N": mu * f * np.sqrt(g) / sr,
            "penetration_m": delta, "generalized_force": Q.reshape(-1)}


def per_element(ex, forces) -> dict[str, np.ndarray]:
    """Sums of the check points' normal and friction force magnitudes per element [N]."""
    n_el = len(ex["elements"]["element"])
    e = forces["element"]
    return {"normal_force_N": np.bincount(e, forces["normal_force_N"], n_el),
            "friction_force_N": np.bincount(e, forces["friction_force_N"], n_el)}


def steady_equilibrium(ex, q) -> dict:
    """The static equilibrium of a steady solve at nodal coordinates q (n_nodes, 6): the residual
    R = Q_contact + Q_gravity + Q_end − Q_elastic, zero at equilibrium but on the held node's
    positions, where −R is the rig's force on the cable.

    Returns ``residual`` (n_nodes, 6) with the held node's positions zeroed [N, N·m],
    ``rig_force_N`` (3,) and ``pull_force_N``, the rig's force along the exit tangent [N].
    A velocity-controlled pull (the rig holds the leading node; back tension at the trailing one).
    """
    pr = ex["problem"]
    rig = pr["rig"]
    if pr.get("mode") != "steady" or rig["controlled"] != "speed":
        raise ValueError("steady_equilibrium: needs the export of a velocity-controlled steady solve "
                         "(problem.json mode = 'steady', rig.controlled = 'speed')")
    R = gravity_forces(ex) - elastic_forces(ex, q)
    if pr["contact"] is not None:
        R += contact_forces(ex, q)["generalized_force"].reshape(-1, 6)
    R[0, :3] -= rig["back_tension_N"] * np.asarray(rig["entry_tangent"])
    held = int(rig["held_node"])
    rig_force = -R[held, :3].copy()
    R[held, :3] = 0.0
    return {"residual": R, "rig_force_N": rig_force,
            "pull_force_N": float(rig_force @ np.asarray(rig["exit_tangent"]))}


def snapshot_state(directory, time_s=None) -> tuple[float, np.ndarray, np.ndarray]:
    """(time, q, q̇) of a snapshot in ``directory`` (the first one by default)."""
    path = Path(directory) / "snapshot_nodes.csv"
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no snapshot; a steady run always writes its state, a dynamic one "
                                "needs [output] snapshots in its scenario")
    nodes = read_table(path)
    t = nodes["time_s"].min() if time_s is None else time_s
    rows = np.nonzero(nodes["time_s"] == t)[0]
    rows = rows[np.argsort(nodes["node"][rows])]
    q, v = node_state(nodes, rows)
    return float(t), q, v


def steady_check(directory) -> dict[str, float]:
    """The steady state of ``directory`` (an export and a steady run's results in one directory)
    against this reader's equilibrium: the largest residual entry and the rig's force along the
    exit tangent against exucable's pulling force, both relative to that force."""
    d = Path(directory)
    ex = load_export(d)
    _, q, _ = snapshot_state(d)
    eq = steady_equilibrium(ex, q)
    pull = float(read_table(d / "snapshot_times.csv")["pull_force_N"][0])
    return {"pull_force_N": pull, "reader_pull_force_N": eq["pull_force_N"],
            "residual": float(np.max(np.abs(eq["residual"]))) / abs(pull),
            "rig_force": abs(eq["pull_force_N"] - pull) / abs(pull)}


def first_snapshot_check(directory) -> dict[str, float]:
    """Largest |reader − exucable| of the per-element forces at the first snapshot, relative to the
    largest force of that kind."""
    d = Path(directory)
    ex = load_export(d)
    t0, q, v = snapshot_state(d)
    contact = read_table(d / "snapshot_contact.csv")
    mine = per_element(ex, contact_forces(ex, q, v))
    sel = np.nonzero(contact["time_s"] == t0)[0]
    sel = sel[np.argsort(contact["element"][sel])]
    out = {"time_s": float(t0)}
    for key in ("normal_force_N", "friction_force_N"):
        theirs = contact[key][sel]
        out[key] = float(np.max(np.abs(mine[key] - theirs)) / max(np.max(np.abs(theirs)), 1e-300))
    return out


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    if not (Path(sys.argv[1]) / "snapshot_nodes.csv").is_file():
        sys.exit(f"{sys.argv[1]}: no snapshot_nodes.csv; run the scenario with [output] snapshots into the "
                 "export's directory (usage above)")
    res = first_snapshot_check(sys.argv[1])
    print(f"first snapshot t = {res['time_s']:.12g} s: max relative difference of the per-element "
          f"normal forces {res['normal_force_N']:.2e}, friction forces {res['friction_force_N']:.2e}")
    if load_export(sys.argv[1])["problem"].get("mode") == "steady":
        eq = steady_check(sys.argv[1])
        print(f"steady equilibrium: largest residual {eq['residual']:.2e} of the pulling force "
              f"{eq['pull_force_N']:.6g} N; the rig's force along the exit tangent {eq['reader_pull_force_N']:.6g} N "
              f"(relative difference {eq['rig_force']:.2e})")
