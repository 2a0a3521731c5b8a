"""Which contact non-smoothness do Newton's iterates cross?, measured in one run.

Runs a scenario from its start to ``--to`` and records the state at every contact force call
after ``--from``; between consecutive Newton iterates of the same step it counts the check points
that
- enter or leave contact (δ crossing 0: the law K δ^e is C¹ there for e > 1),
- switch the normal force's clip max(0, K δ^e + C g(δ) δ̇) (touching, but the damping would pull:
  a kink in the residual, the derivative jumps by C g(δ) in δ̇),
- cross the damping onset's corner δ = δ_d (g = min(δ/δ_d, 1): a kink),
- change their nearest conduit segment while touching.

    nice .venv/bin/python studies/contact_flips.py scenarios/paper_ex4_spatial.toml --from 0.0022 --to 0.0045
    nice .venv/bin/python studies/contact_flips.py --quick    # smoke run: the fast Example 2 over its first 3 ms

The force calls are recorded by wrapping ``ContactCoupling._force`` for the one run and restoring it
after (the coupling offers no hook for an observer).

Prints one row per Newton iterate (first row of a step: -1, nothing to compare with) and the
medians over all iterates compared.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import exucable.model.coupling as coupling  # noqa: E402
import exucable.solve.dynamic as solve  # noqa: E402
from exucable.model.build import build_model  # noqa: E402
from exucable.scenario.specs import load_scenario  # noqa: E402


def record_force_calls(scenario_path, t_from: float, t_to: float):
    """Run the scenario to ``t_to`` [s]; return (model, [(t, absolute q, q̇) of every contact
    force call at t >= ``t_from``])."""
    sc = load_scenario(scenario_path)
    sc = dataclasses.replace(sc, solver=dataclasses.replace(sc.solver, end_time_s=t_to, steady_stop=False))
    calls = []
    force = coupling.ContactCoupling._force

    def recording_force(self, mbs, t, item, q, q_t):
        if t >= t_from:
            calls.append((t, np.array(q) + self.q_ref, np.array(q_t)))
        return force(self, mbs, t, item, q, q_t)

    coupling.ContactCoupling._force = recording_force
    try:
        model = build_model(sc)
        solve.simulate(model)
    finally:
        coupling.ContactCoupling._force = force
    return model, calls


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenario", nargs="?", help="scenario file (required unless --quick)")
    ap.add_argument("--from", dest="t_from", type=float, default=0.0022, help="first time recorded [s]")
    ap.add_argument("--to", dest="t_to", type=float, default=0.0045, help="end time of the run [s]")
    ap.add_argument("--quick", action="store_true",
                    help="smoke run: scenarios/fast/paper_ex2_bend90.toml from 0 to 3 ms")
    args = ap.parse_args(argv)
    if args.quick:
        args.scenario = args.scenario or str(ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml")
        args.t_from, args.t_to = 0.0, 0.003
    if not args.scenario:
        ap.error("scenario: give a scenario file (or --quick)")
    model, calls = record_force_calls(args.scenario, args.t_from, args.t_to)
    impl = model.coupling.kernel._impl
    onset = impl.law.damping_onset_m

    def state(q, v):
        s = impl.point_state(q, v)
        d = np.linalg.norm(s["residual_m"], axis=1) - impl.gap
        d = np.where(np.isnan(d), -1.0, d)
        touch = d > 0.0
        return {"touch": touch, "clip": touch & ~(s["normal_force_N"] > 0.0),
                "corner": d > onset, "segment": s["segment"]}

    print(f"# {Path(args.scenario).name}, {len(calls)} force calls in [{args.t_from}, {args.t_to}] s\n")
    print("| t [s] | touching | contact in/out | damping clip on/off | onset corner crossed | segment switched |")
    print("|---|---|---|---|---|---|")
    prev, rows = None, []
    for t, q, v in calls:
        st = state(q, v)
        if prev is not None and prev[0] == t:
            p = prev[1]
            n = np.array([(st["touch"] != p["touch"]).sum(), (st["clip"] != p["clip"]).sum(),
                          (st["corner"] != p["corner"]).sum(),
                          ((st["segment"] != p["segment"]) & st["touch"]).sum()])
            rows.append(n)
            print(f"| {t:.5f} | {st['touch'].sum()} | " + " | ".join(str(x) for x in n) + " |")
        else:
            print(f"| {t:.5f} | {st['touch'].sum()} | -1 | -1 | -1 | -1 |")
        prev = (t, st)
    if rows:  # rejected attempts (iterates running away) would swamp a total: medians
        print("| median | | " + " | ".join(f"{x:g}" for x in np.median(rows, axis=0)) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
