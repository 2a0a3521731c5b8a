"""The tension profile against the physical tensions and under refinement, on the industry routes and
study routes like issue 23's (steady mode).

For each route: the pulling force, the physical band [smallest, largest] tension — the smaller of the back
tension and the rope reference's smallest tension, the larger of the pulling force (in dynamic mode also
the rig's force in the final state, which the profile belongs to) and the rope's largest —
then the range of N = EA·ε of the ANCF elements at 4 stations per element (the profile before: paper Eq. 24
read off the strain) and of the profile written now (the equilibrium of the cable's loads,
``exucable.post.tension.equilibrium_tension``), each as its excursion beyond the band in % of the pull (0 =
inside; the target is ≤ 1 %), and the largest change of each profile when the elements are halved
(``--refine`` levels, % of the pull, compared at the coarser stations).

The change on halving is given as its largest value (dominated by a friction step that moves with the
check points near a bend end) and its root mean square along the cable.

Run: ``nice .venv/bin/python studies/tension_profile.py [--only NAME] [--refine 1 2] [--mode steady|dynamic]``
(dynamic: each route with ``solver.start_from = "steady"`` and ``solver.steady_stop``).
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

import numpy as np

from exucable.post.tension import tension_profile
from exucable.run import run_scenario
from exucable.scenario.specs import load_scenario, parse_scenario

ROOT = Path(__file__).resolve().parent.parent
INDUSTRY = [("commscope_conquest_run_a_h", "forward"), ("commscope_conquest_run_a_h", "reverse"),
            ("commscope_conquest_500ft_bend90", "forward"), ("gera_wire_pulling_example", "forward"),
            ("machinecalcs_two_bends", "forward")]


def study_routes():
    """Routes of issue 23's kind: an 18 mm cable (E 1 GPa solid section unless EJ given) in steady mode."""
    def cable(r=0.009, mpl=0.6, ej=None):
        c = {"radius": r, "mass_per_length": mpl, "youngs_modulus": 1e9}
        if ej is not None:
            c["bending_stiffness"] = ej
        return c
    yield "down-bend 60° R 5 m, 1 kg/m, c 10 mm, gravity", {
        "cable": cable(0.009, 1.0), "conduit": {"inner_radius": 0.019, "path": [
            {"straight": 10.0}, {"bend": 60.0, "radius": 5.0, "turn": "down"}, {"straight": 10.0}]},
        "contact": {"friction": 0.35}, "pull": {"speed": 0.5, "back_tension": 50.0}, "gravity": {"g": 9.80665}}
    yield "S-bend, c 8.4 mm, no gravity", {
        "cable": cable(), "conduit": {"inner_radius": 0.0174, "path": [
            {"straight": 5.0}, {"bend": 45.0, "radius": 2.0, "turn": "left"}, {"straight": 2.0},
            {"bend": 45.0, "radius": 2.0, "turn": "right"}, {"straight": 5.0}]},
        "contact": {"friction": 0.4}, "pull": {"speed": 0.5, "back_tension": 100.0}}
    yield "single bend 3 m, back tension 100 N, gravity", {
        "cable": cable(), "conduit": {"inner_radius": 0.017, "path": [
            {"straight": 10.0}, {"bend": 90.0, "radius": 3.0, "turn": "left"}, {"straight": 10.0}]},
        "contact": {"friction": 0.35}, "pull": {"speed": 0.5, "back_tension": 100.0}, "gravity": {"g": 9.80665}}
    yield "100 m, four bends, c 2 mm, gravity", {
        "cable": cable(), "conduit": {"inner_radius": 0.011, "path": [
            {"straight": 20.0}, {"bend": 30.0, "radius": 3.0, "turn": "left"}, {"straight": 20.0},
            {"bend": 20.0, "radius": 4.0, "turn": "up"}, {"straight": 15.0}, {"bend": 20.0, "radius": 4.0, "turn": "down"},
            {"straight": 15.0}, {"bend": 45.0, "radius": 3.0, "turn": "right"}, {"straight": 20.0}]},
        "contact": {"friction": 0.35}, "pull": {"speed": 0.5, "back_tension": 50.0}, "gravity": {"g": 9.80665}}


def excursion(N, lo, hi, pull):
    """How far N leaves [lo, hi], in % of the pull (0 inside)."""
    return 100.0 * max(0.0, lo - float(np.min(N)), float(np.max(N)) - hi) / pull


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", action="append", help="routes whose name contains this (repeatable)")
    ap.add_argument("--refine", type=float, nargs="+", default=[1.0, 2.0], help="mesh refinements (default 1 2)")
    ap.add_argument("--mode", choices=("steady", "dynamic"), default="steady", help="solver mode (default steady)")
    ap.add_argument("--quick", action="store_true", help="the first route on one mesh (a smoke run)")
    args = ap.parse_args()
    if args.quick:      # the smoke run: one route, one mesh
        args.refine = [1.0]
    cases = [(f"{n} {d}", dataclasses.replace(
        sc := load_scenario(ROOT / "scenarios" / "industry" / f"{n}.toml"),
        pull=dataclasses.replace(sc.pull, direction=d))) for n, d in INDUSTRY]
    cases += [(name, parse_scenario({"name": "study", **data, "solver": {"mode": "steady", "end_time": 1.0}}, ROOT, default_name="study"))
              for name, data in study_routes()]
    if args.only:
        cases = [c for c in cases if any(o in c[0] for o in args.only)]
    if args.quick:
        cases = cases[-1:]      # the last study route (the shortest to solve)
    if args.mode == "dynamic":
        cases = [(n, sc.replace(**{"solver.start_from": "steady", "solver.steady_stop": True})) for n, sc in cases]
    print("| route | refine | elements | pull [N] | band [N] | EA·ε range [N] | beyond band [% pull] "
          "| profile range [N] | beyond band [% pull] | change on halving, max (rms): EA·ε, profile [% pull] | wall [s] |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for name, sc in cases:
        before = None
        for refine in args.refine:
            t0 = time.perf_counter()
            r = run_scenario(sc, None, quiet=True, plots=False, mode=args.mode, refine=refine)
            wall = time.perf_counter() - t0
            m, s = r.model, r.summary
            pull = s["pull_force_N"]
            q, _ = m.coordinates()
            x, strain_N = tension_profile(q, m.layout.element_length_m, m.axial_stiffness_N)
            N = r.tension_profile["tension_N"]
            rope = m.rope.tension_N
            hi = max(pull, float(np.max(rope)))
            if args.mode == "dynamic":
                hi = max(hi, m.pull_force_N(float(m.mbs.systemData.GetTime())))
            lo = min(m.back_tension_N, float(np.min(rope)))
            change = ""
            if before is not None:
                xb, eb, nb = before
                de, dn = np.interp(xb, x, strain_N) - eb, np.interp(xb, x, N) - nb
                change = (f"{100 * np.max(np.abs(de)) / pull:.2f} ({100 * np.sqrt(np.mean(de**2)) / pull:.3f}), "
                          f"{100 * np.max(np.abs(dn)) / pull:.2f} ({100 * np.sqrt(np.mean(dn**2)) / pull:.3f})")
            before = (x, strain_N, N)
            print(f"| {name} | {refine:g} | {len(m.layout.element_length_m)} | {pull:.2f} | {lo:.1f}…{hi:.1f} "
                  f"| {strain_N.min():.1f}…{strain_N.max():.1f} | {excursion(strain_N, lo, hi, pull):.2f} "
                  f"| {N.min():.1f}…{N.max():.1f} | {excursion(N, lo, hi, pull):.2f} | {change} | {wall:.1f} |", flush=True)


if __name__ == "__main__":
    main()
