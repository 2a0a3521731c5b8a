"""Pulling force against pull speed: is the friction fully developed at slow pulls?

Runs the coarse Example 2 (90° bend, μ 0.2, back tension 150 N; capstan T1 = 150 e^(0.2 π/2) =
205.37 N, paper Eq. 26) at pull speeds over five decades, in steady mode and in dynamic mode,
the latter with the scenario's friction regularisation velocity ε (default 1 % of the pull speed;
``--fixed E`` also with ε = E m/s whatever the speed, the former default being 1e-3) and with
``--relative F`` also with ε = F·V. Prints per case
the pulling force, its error against the capstan value, the status, the friction factor
V/√(V² + ε²) and the wall time, all measured in this one run.

    nice .venv/bin/python studies/slow_pull.py [--speeds 1e-4 1e-3 1e-2 1e-1 1] [--relative 0.01]
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import exucable as xc
from exucable.scenario.specs import load_scenario

ROOT = Path(__file__).resolve().parents[1]
CAPSTAN_N = 150.0 * math.exp(0.2 * math.pi / 2.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speeds", type=float, nargs="+", default=[1e-4, 1e-3, 1e-2, 1e-1, 1.0])
    ap.add_argument("--relative", type=float, default=None,
                    help="also dynamic runs with contact.friction_regularisation_velocity = this × pull speed")
    ap.add_argument("--fixed", type=float, default=None,
                    help="also dynamic runs with contact.friction_regularisation_velocity = this [m/s] at every speed")
    ap.add_argument("--modes", nargs="+", default=["steady", "dynamic"])
    ap.add_argument("--quick", action="store_true", help="two speeds, steady mode only (a smoke run)")
    args = ap.parse_args()
    if args.quick:      # the smoke run: two speeds in steady mode
        args.speeds, args.modes = [1e-3, 1e-1], ["steady"]
    base = load_scenario(ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml")
    print(f"coarse Example 2, capstan {CAPSTAN_N:.4f} N")
    print(f"{'mode':8} {'eps':>9} {'V [m/s]':>9} {'force [N]':>10} {'error':>9} {'factor':>9} {'status':>10} "
          f"{'Newton':>7} {'wall [s]':>8}")
    for mode in args.modes:
        # (label, ε as a function of V or None for the scenario's default)
        variants = [("default", None)]
        if mode == "dynamic" and args.relative is not None:
            variants.append((f"{args.relative:g}V", lambda v: args.relative * v))
        if mode == "dynamic" and args.fixed is not None:
            variants.append((f"{args.fixed:g}", lambda v: args.fixed))
        for label, eps_of in variants:
            for v in args.speeds:
                changes = {"pull.speed": v, "solver.mode": mode}
                if eps_of is not None:
                    changes["contact.friction_regularisation_velocity"] = eps_of(v)
                sc = base.replace(**changes)
                eps = sc.contact.friction_regularisation_velocity_m_per_s     # the default is derived from V
                t0 = time.perf_counter()
                res = xc.run(sc)
                wall = time.perf_counter() - t0
                f = res.pull_force_N
                factor = 1.0 if mode == "steady" else v / math.hypot(v, eps)
                shown = "steady" if mode == "steady" else (f"{eps:.1e}" if eps_of is None else label)
                print(f"{mode:8} {shown:>9} {v:9.1e} {f:10.4f} {100 * (f / CAPSTAN_N - 1):+8.3f}% {factor:9.6f} "
                      f"{res.status:>10} {res.summary['newton_iterations']:7d} {wall:8.2f}", flush=True)

if __name__ == "__main__":
    main()
