"""The triangle's 100 m route from each bundle start with each relaxation mass, one solve per fresh process.

Three cables (``--arrangement``, triangular by default) through benchmarks/bundle_route.py's route,
steady mode, the solve as on main (one-iteration steps, the dynamic relaxation handed over early,
the onset layers' descent) under the CPU limit ``--limit`` [s] (``solver.steady_time_limit``), for
every pair of a start and a mass:

- start ``clearance`` (the default: the centroid on the rope-with-clearance path, the arrangement
  rolled toward the wall the path bears on), ``noroll`` (the same path, the arrangement not rolled:
  a probe, ``exucable.model.bundle._turn_toward`` replaced by zero in this process only) and
  ``statics_own`` (the cross-section's statics with each cable's own start tension;
  ``build_bundle_model(start_path=...)``);
- masses ``diagonal`` (the default) or ``frame`` (``SteadySettings.bundle_relax_masses``).

Prints per pair: status, the solve's CPU [s], the whole process's CPU (build included, getrusage),
the relaxation's steps and smallest residual [N], the smallest true residual the solve reached [N],
Newton iterations and the pull force [N] where it solved. The machine is shared: compare CPU.

    nice .venv/bin/python studies/bundle_start_masses.py [--limit 55] [--starts clearance,noroll,statics_own]
        [--masses diagonal,frame] [--arrangement triangular] [--scenario FILE] [--reverse]
    nice .venv/bin/python studies/bundle_start_masses.py --quick   # two cables, the 34 m route, 3 s
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import resource
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _handover():
    spec = importlib.util.spec_from_file_location("bundle_relax_handover", ROOT / "studies" / "bundle_relax_handover.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def run_variant(start: str, masses: str, limit_s: float, arrangement: str, quick: bool,
                scenario: str | None = None, reverse: bool = False) -> dict:
    """One pair in this process: the row's fields (``scenario``: a scenario file instead of the 100 m route,
    ``reverse``: pulled the other way)."""
    from exucable.model import bundle as bm
    from exucable.solve import steady as st
    from exucable.solve.onset_continuation import OnsetSettings

    if scenario is not None:
        from exucable.scenario.specs import load_scenario

        sc = load_scenario(scenario).replace(**{"solver.mode": "steady", "cable.arrangement": arrangement})
    else:
        sc = _handover().route_scenario("triangular", 2, 12.0) if quick else _handover().route_scenario(arrangement)
    if reverse:
        sc = sc.replace(**{"pull.direction": "reverse"})
    if start == "noroll":          # the probe: the arrangement laid unrolled along the clearance path
        bm._turn_toward = lambda centreline, s, *a, **k: np.zeros_like(np.asarray(s, dtype=float))
    model = bm.build_bundle_model(sc, start_path="clearance" if start == "noroll" else start)
    settings = replace(st.SteadySettings(time_limit_s=limit_s), bundle_relax_masses=masses)
    solver = st.SteadySolver(model, settings, onset=OnsetSettings())
    c0 = time.process_time()
    out = solver.solve()
    cpu = time.process_time() - c0
    ru = resource.getrusage(resource.RUSAGE_SELF)
    rel = solver.relaxation
    return {"start": start, "masses": masses, "status": out.status, "solve_cpu": cpu,
            "process_cpu": ru.ru_utime + ru.ru_stime, "its": out.newton_iterations,
            "relax_steps": getattr(rel, "steps", 0), "relax_residual": getattr(rel, "residual_N", None),
            "best": float(solver.best[0]),
            "pull": float(model.pull_shares_N().sum()) if out.status == "ok" else None,
            "message": out.message, "sections": _arrangements(model) if out.status == "ok" else None}


def _arrangements(model) -> str:
    """The arrangement found per straight and bend of a solved state, with each label's station count."""
    from exucable.model.bundle import bundle_report, bundle_sections

    rows = bundle_sections(model)["sections"]
    report = bundle_report(model)
    shares = 100.0 * model.pull_shares_N() / model.pull_shares_N().sum()
    return ("; ".join(f"{r['kind']} {r['section']}: {r['arrangement']} {r['arrangements_seen']}" for r in rows)
            + f"; weight correction {report['weight_correction_factor']:.4g}; pull shares "
            + " / ".join(f"{x:.1f}" for x in shares) + " %")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--limit", type=float, default=55.0, help="the solve's CPU limit [s]")
    p.add_argument("--starts", default="clearance,noroll,statics_own")
    p.add_argument("--masses", default="diagonal,frame")
    p.add_argument("--arrangement", default="triangular")
    p.add_argument("--scenario", help="a scenario file instead of the 100 m route (e.g. the industry plan's)")
    p.add_argument("--reverse", action="store_true", help="pull the other way (pull.direction = reverse)")
    p.add_argument("--variant", help="START:MASSES, run in this process (JSON on stdout)")
    p.add_argument("--quick", action="store_true", help="two cables through the 34 m route, 3 s, one pair (a smoke run)")
    args = p.parse_args(argv)
    if args.quick:
        args.limit, args.starts, args.masses = 3.0, "noroll", "frame"
    if args.variant:
        start, masses = args.variant.split(":")
        print(json.dumps(run_variant(start, masses, args.limit, args.arrangement, args.quick, args.scenario,
                                     args.reverse)))
        return 0
    print(f"{args.scenario or 'the 100 m route'}{' reversed' if args.reverse else ''}: "
          f"{args.arrangement}, solve CPU limit {args.limit:g} s, one fresh process per row")
    print("| start | masses | status | solve CPU [s] | process CPU [s] | relaxation steps | its residual [N] "
          "| smallest residual [N] | Newton its | pull [N] |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for start in args.starts.split(","):
        for masses in args.masses.split(","):
            cmd = [sys.executable, __file__, "--variant", f"{start}:{masses}", "--limit", str(args.limit),
                   "--arrangement", args.arrangement] + (["--quick"] if args.quick else [])
            cmd += (["--scenario", args.scenario] if args.scenario else []) + (["--reverse"] if args.reverse else [])
            proc = subprocess.run(cmd, capture_output=True, text=True)
            if proc.returncode:
                print(f"| {start} | {masses} | error | {proc.stderr.strip().splitlines()[-1:]} |", flush=True)
                continue
            r = json.loads(proc.stdout.strip().splitlines()[-1])
            rr = "-" if r["relax_residual"] is None else f"{r['relax_residual']:.3g}"
            pull = "n/a" if r["pull"] is None else f"{r['pull']:.6g}"
            print(f"| {start} | {masses} | {r['status']} | {r['solve_cpu']:.1f} | {r['process_cpu']:.1f} | "
                  f"{r['relax_steps']} | {rr} | {r['best']:.3g} | {r['its']} | {pull} |", flush=True)
            if r["status"] != "ok":
                print(f"    ({r['message'][:400]})", flush=True)
            else:
                print(f"    ({r['sections']})", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
