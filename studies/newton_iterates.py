"""How far each Newton iterate of a step is from the step's converged state, check point by check
point: where Newton overshoots, by how much, and how fast it comes back.

Runs a scenario from its start to ``--to``, records the state at every contact force call after
``--from`` and, for every step with at least ``--min-iterates`` iterates, prints per iterate: the
largest node position and velocity error against the step's last iterate (and where), the check
points touching, the sum of normal forces, the range of penetration errors δ - δ_final, the normal
force error (total, and the element with most) and the points whose damping clip is on.

    nice .venv/bin/python studies/newton_iterates.py scenarios/paper_ex4_spatial.toml --from 0.07 --to 0.108
    nice .venv/bin/python studies/newton_iterates.py --quick   # smoke run: the fast Example 2 over its first 3 ms

``--no-hold`` sets :data:`exucable.solve.dynamic.HOLD_ONSET` (a module setting; ``simulate`` takes no
settings object) for this run and restores it after.

Linear convergence shows as a penetration error shrinking by a constant factor per iterate
(1/2: Newton on a quadratic, e.g. a damping force ∝ δ·δ̇; 1/3: on δ^1.5 from above).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

import exucable.solve.dynamic as solve  # noqa: E402
from contact_flips import record_force_calls  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenario", nargs="?", help="scenario file (required unless --quick)")
    ap.add_argument("--from", dest="t_from", type=float, default=0.07, help="first time recorded [s]")
    ap.add_argument("--to", dest="t_to", type=float, default=0.108, help="end time of the run [s]")
    ap.add_argument("--min-iterates", type=int, default=5)
    ap.add_argument("--no-hold", action="store_true", help="damping onset g(δ) of every iterate (solve.HOLD_ONSET)")
    ap.add_argument("--quick", action="store_true",
                    help="smoke run: scenarios/fast/paper_ex2_bend90.toml from 0 to 3 ms, steps of >= 2 iterates")
    args = ap.parse_args(argv)
    if args.quick:
        args.scenario = args.scenario or str(ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml")
        args.t_from, args.t_to, args.min_iterates = 0.0, 0.003, 2
    if not args.scenario:
        ap.error("scenario: give a scenario file (or --quick)")
    hold = solve.HOLD_ONSET
    solve.HOLD_ONSET = not args.no_hold
    try:
        model, calls = record_force_calls(args.scenario, args.t_from, args.t_to)
    finally:
        solve.HOLD_ONSET = hold
    impl = model.coupling.kernel._impl
    n_k = impl.nh.shape[0]
    steps = {}
    for t, q, v in calls:
        steps.setdefault(t, []).append((q, v))

    def penetration(state):
        d = np.linalg.norm(state["residual_m"], axis=1) - impl.gap
        return np.nan_to_num(d, nan=-1.0)

    print(f"# {Path(args.scenario).name}: {len(calls)} force calls in [{args.t_from}, {args.t_to}] s, "
          f"{sum(len(v) >= args.min_iterates for v in steps.values())} steps of >= {args.min_iterates} iterates\n")
    for t, its in steps.items():
        if len(its) < args.min_iterates:
            continue
        print(f"t = {t:.5f} s: {len(its)} iterates")
        qf, vf = its[-1]
        sf = impl.point_state(qf, vf)
        df, ff = penetration(sf), sf["normal_force_N"]
        for k, (q, v) in enumerate(its):
            s = impl.point_state(q, v)
            d, f = penetration(s), s["normal_force_N"]
            pos = np.linalg.norm(np.abs(q - qf).reshape(-1, 6)[:, :3], axis=1)
            vel = np.linalg.norm(np.abs(v - vf).reshape(-1, 6)[:, :3], axis=1)
            el = np.abs(f - ff).reshape(-1, n_k).sum(axis=1)
            e = int(np.argmax(el))
            print(f"  {k:2d}: |Δr| {pos.max():.2e} m at node {int(np.argmax(pos))}, |Δv| {vel.max():.2e} m/s "
                  f"at node {int(np.argmax(vel))}; touching {int((d > 0).sum())} (final {int((df > 0).sum())}); "
                  f"Σf {f.sum():.4g} N (final {ff.sum():.4g}); δ - δ_final in [{1e6 * (d - df).min():.2f}, "
                  f"{1e6 * (d - df).max():.2f}] µm; |f - f_final| {np.abs(f - ff).sum():.3g} N, most in "
                  f"element {e} ({el[e]:.3g} N); clipped {int(((d > 0) & (f <= 0)).sum())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
