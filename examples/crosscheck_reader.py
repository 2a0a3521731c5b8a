"""An independent reader of an ``exucable export``: the contact law of Yang et al. (2013), Eqs. 14-23,
from the exported files alone, with plain numpy (no exucable import).

This is the pattern a solver author follows: load the discrete problem (``problem.json`` and the CSV
tables, see ``docs/results-format.md``), rebuild the state (the initial one from
``nodes_initial.csv``, or a snapshot's from ``snapshot_nodes.csv``), evaluate one's own contact
forces and compare them with exucable's (``snapshot_contact.csv``).

Usage::

    cp scenarios/fast/paper_ex2_bend90.toml ex2.toml
    printf '[output]\nsnapshots = [0.2]\n' >> ex2.toml     # the state to compare at
    exucable export ex2.toml out/ex2-export
    exucable run ex2.toml --out out/ex2-export
    python examples/crosscheck_reader.py out/ex2-export

prints, for the first snapshot, the largest difference of the per-element normal and friction
forces [N] between this reader and exucable, relative to the largest force.
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


def contact_forces(ex, q, v) -> dict:
    """Eqs. 14-23 at every exported check point for nodal state (q, q̇) of shape (n_nodes, 6).

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
    P = S[:, 0, None] * q[ni, :3] + S[:, 1, None] * q[ni, 3:] + S[:, 2, None] * q[nj, :3] + S[:, 3, None] * q[nj, 3:]
    V = S[:, 0, None] * v[ni, :3] + S[:, 1, None] * v[ni, 3:] + S[:, 2, None] * v[nj, :3] + S[:, 3, None] * v[nj, 3:]
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
    for col, node in ((0, ni), (2, nj)):
        np.add.at(Q, (node, slice(0, 3)), S[:, col, None] * F)
        np.add.at(Q, (node, slice(3, 6)), S[:, col + 1, None] * F)
    return {"element": e, "normal_force_N": f, "friction_force_N": mu * f * np.sqrt(g) / sr,
            "penetration_m": delta, "generalized_force": Q.reshape(-1)}


def per_element(ex, forces) -> dict[str, np.ndarray]:
    """Sums of the check points' normal and friction force magnitudes per element [N]."""
    n_el = len(ex["elements"]["element"])
    e = forces["element"]
    return {"normal_force_N": np.bincount(e, forces["normal_force_N"], n_el),
            "friction_force_N": np.bincount(e, forces["friction_force_N"], n_el)}


def first_snapshot_check(directory) -> dict[str, float]:
    """Largest |reader − exucable| of the per-element forces at the first snapshot, relative to the
    largest force of that kind."""
    d = Path(directory)
    ex = load_export(d)
    nodes = read_table(d / "snapshot_nodes.csv")
    contact = read_table(d / "snapshot_contact.csv")
    t0 = nodes["time_s"].min()
    rows = np.nonzero(nodes["time_s"] == t0)[0]
    rows = rows[np.argsort(nodes["node"][rows])]
    q, v = node_state(nodes, rows)
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
