"""Speed of the contact kernel at the paper's Example 4 size (Sect. 3.4, Table 1).

100 cable elements × 800 check points against a 3D route of three straights and three bends, each
bend in 80 straight segments (243 segments). The cable lies on the centreline shifted towards the
wall by the clearance plus 0.1 mm, so nearly every check point is in contact and sliding at
0.1 m/s. Prints, all measured in this one run (median of repeats, one thread):

- kernel time per evaluation, forces only and forces + Jacobians, numba and numpy;
- check points per second;
- brute force (every segment for every point) / broad phase (AABB sort-and-sweep) time ratios,
  for the contact search alone (nearest segment of every check point) and for whole evaluations
  (which add the force law and the Jacobians, the same work either way).

Run: ``.venv/bin/python benchmarks/contact_kernel.py`` (about 15 s, plus compilation on first use);
``--quick``: 10 elements x 50 check points, 10 segments per bend, one repeat (a smoke run).
"""

from __future__ import annotations

import os

# one core, as the target states (the kernel is serial; this pins any BLAS/numba pools)
os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from exucable.contact import ContactKernel, ContactLaw  # noqa: E402
from exucable.geometry.segments import Segments  # noqa: E402

N_ELEMENTS = 100
CHECK_POINTS = 800
SEGMENTS_PER_BEND = 80
R_CONDUIT = 3.5e-3  # NOTES.md common parameters
R_CABLE = 2.5e-3


def route(segments_per_bend=SEGMENTS_PER_BEND):
    """Centreline of straight 6 m, 90° bend (+y), straight 5 m, 60° bend up, straight 4 m, 90° bend.

    Returns the polyline vertices (on the centreline), their arc lengths, a function giving
    centreline point, unit tangent and wall-side normal (bend: towards the bend centre; straight:
    downwards) at arc lengths s on the exact arcs, and the route length [m].
    """
    pieces = [("straight", 6.0, None), ("bend", 1.0, (np.pi / 2, [0, 1, 0])),
              ("straight", 5.0, None), ("bend", 1.2, (np.pi / 3, [0, 0, 1])),
              ("straight", 4.0, None), ("bend", 0.8, (np.pi / 2, [-1, 0, 0]))]
    p = np.zeros(3)
    t = np.array([1.0, 0.0, 0.0])
    s0 = 0.0
    table = []  # (s_start, length, kind, start point, tangent, bend dir, radius)
    verts, s_verts = [p.copy()], [0.0]
    for kind, size, bend in pieces:
        if kind == "straight":
            table.append((s0, size, kind, p.copy(), t.copy(), None, None))
            p = p + size * t
            s0 += size
            verts.append(p.copy())
            s_verts.append(s0)
        else:
            angle, towards = bend
            b = np.asarray(towards, float) - np.dot(towards, t) * t
            b /= np.linalg.norm(b)
            length = size * angle
            table.append((s0, length, kind, p.copy(), t.copy(), b, size))
            for phi in np.linspace(0.0, angle, segments_per_bend + 1)[1:]:
                verts.append(p + size * (1 - np.cos(phi)) * b + size * np.sin(phi) * t)
                s_verts.append(s0 + size * phi)
            p = verts[-1].copy()
            t = np.cos(angle) * t + np.sin(angle) * b
            s0 += length

    def at(s):
        pts, tans, nors = [], [], []
        for si in np.atleast_1d(s):
            for s_start, length, kind, p0, t0, b, rho in table:
                if si <= s_start + length + 1e-12:
                    break
            u = si - s_start
            if kind == "straight":
                # gravity side: -e_z without its tangential part (no straight here is vertical)
                down = np.array([0.0, 0.0, -1.0]) + t0[2] * t0
                down /= np.linalg.norm(down)
                pts.append(p0 + u * t0)
                tans.append(t0)
                nors.append(down)
            else:
                phi = u / rho
                pts.append(p0 + rho * (1 - np.cos(phi)) * b + rho * np.sin(phi) * t0)
                tans.append(np.cos(phi) * t0 + np.sin(phi) * b)
                nors.append(np.cos(phi) * b - np.sin(phi) * t0)  # towards the bend centre
        return np.array(pts), np.array(tans), np.array(nors)

    return np.array(verts), np.array(s_verts), at, s0


def cable_state(at, total_length, rng, n_elements=N_ELEMENTS):
    """Nodes shifted from the centreline to the wall side by the clearance + 0.1 mm, sliding."""
    gap = R_CONDUIT - R_CABLE
    length = total_length / n_elements
    s_nodes = np.linspace(0.0, total_length, n_elements + 1)
    pts, tans, nors = at(s_nodes)
    pos = pts + (gap + 1.0e-4) * nors
    q = np.hstack([pos, tans]).reshape(-1)
    vel = 0.1 * tans + rng.normal(scale=1e-3, size=tans.shape)
    q_t = np.hstack([vel, rng.normal(scale=1e-3, size=tans.shape)]).reshape(-1)
    return q, q_t, length


def median_time(fn, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true",
                    help="10 elements x 50 check points, 10 segments per bend, one repeat (a smoke run)")
    args = ap.parse_args(argv)
    n_elements, check_points, per_bend = (10, 50, 10) if args.quick else (N_ELEMENTS, CHECK_POINTS, SEGMENTS_PER_BEND)
    verts, s_verts, at, total = route(per_bend)
    segments = Segments(verts, s_verts, R_CONDUIT)
    rng = np.random.default_rng(4)
    q, q_t, length = cable_state(at, total, rng, n_elements)
    law = ContactLaw(stiffness=1e6, damping=1e3, exponent=1.5, friction=0.3, damping_onset_m=0.0)  # Eq. 18
    n_points = n_elements * check_points
    print(f"{'smoke-run' if args.quick else 'Example-4-size'} case: {n_elements} elements x {check_points} check points = {n_points} "
          f"points, {segments.count} segments, route {total:.2f} m")

    kernels = {}
    t0 = time.perf_counter()
    for backend in ("numba", "numpy"):
        for bp in ("aabb", "none"):
            kernels[backend, bp] = ContactKernel(segments, length, R_CABLE, law, check_points,
                                                 n_elements=n_elements, broad_phase=bp,
                                                 backend=backend)
    kernels["numba", "aabb"].evaluate(q, q_t, jacobian=True)  # compile or load the cache
    kernels["numba", "none"].evaluate(q, q_t, jacobian=True)
    print(f"set-up + first numba calls: {time.perf_counter() - t0:.2f} s")

    res = kernels["numba", "aabb"].evaluate(q, q_t, jacobian=True)
    ref = kernels["numpy", "aabb"].evaluate(q, q_t, jacobian=True)
    brute = kernels["numba", "none"].evaluate(q, q_t, jacobian=True)
    scale = np.abs(ref.generalized_force).max()
    print(f"points in contact: {res.n_in_contact} of {n_points}; "
          f"max |Q_numba - Q_numpy| / max|Q| = "
          f"{np.abs(res.generalized_force - ref.generalized_force).max() / scale:.1e}; "
          f"max |Q_aabb - Q_brute| = "
          f"{np.abs(res.generalized_force - brute.generalized_force).max():.1e} N")

    rows = []
    for backend, repeats in (("numba", 1 if args.quick else 30), ("numpy", 1 if args.quick else 3)):
        for jac in (False, True):
            for bp in ("aabb", "none"):
                if backend == "numpy" and bp == "none" and not jac:
                    continue
                k = kernels[backend, bp]
                reps = repeats if not (backend == "numpy" and bp == "none") else 1
                t = median_time(lambda k=k, jac=jac: k.evaluate(q, q_t, jacobian=jac), reps)
                rows.append((backend, bp, jac, t))
    print(f"{'backend':8s} {'broad phase':12s} {'output':20s} {'ms/eval':>9s} {'points/s':>10s}")
    timing = {}
    for backend, bp, jac, t in rows:
        timing[backend, bp, jac] = t
        what = "forces + Jacobians" if jac else "forces"
        print(f"{backend:8s} {bp:12s} {what:20s} {1e3 * t:9.2f} {n_points / t:10.3g}")
    fast_aabb, fast_none = kernels["numba", "aabb"]._impl, kernels["numba", "none"]._impl
    assert np.array_equal(fast_aabb.nearest_segments(q), fast_none.nearest_segments(q))
    reps = 1 if args.quick else 30
    t_sweep = median_time(lambda: fast_aabb.sweep.candidates(q), reps)
    t_search = median_time(lambda: fast_aabb.nearest_segments(q), reps)
    t_search_bf = median_time(lambda: fast_none.nearest_segments(q), 1 if args.quick else 10)
    off, _ = fast_aabb.candidates(q)
    counts = np.diff(off)
    print(f"candidate segments per element: mean {counts.mean():.2f}, max {counts.max()} "
          f"(of {segments.count})")
    print(f"broad phase alone (element boxes + sort-and-sweep): {1e3 * t_sweep:.3f} ms")
    print(f"contact search (nearest segment of every point): broad phase {1e3 * t_search:.3f} ms, "
          f"brute force {1e3 * t_search_bf:.3f} ms -> {t_search_bf / t_search:.1f}x")
    for jac in (False, True):
        ratio = timing["numba", "none", jac] / timing["numba", "aabb", jac]
        what = "forces + Jacobians" if jac else "forces"
        print(f"numba brute force / broad phase, {what}: {ratio:.1f}x")
    ratio = timing["numpy", "none", True] / timing["numpy", "aabb", True]
    print(f"numpy brute force / broad phase, forces + Jacobians: {ratio:.1f}x")
    print(f"numpy / numba (broad phase, forces + Jacobians): "
          f"{timing['numpy', 'aabb', True] / timing['numba', 'aabb', True]:.1f}x")


if __name__ == "__main__":
    main()
