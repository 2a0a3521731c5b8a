"""Which steady state does a pull of three cables reach? The dynamic bundle as the steady solve's judge.

The steady solve of a bundle has several stable answers on the up-bend study's cases
(``studies/bundle_upbend_study.py``), and its start picks one: the clearance start (the default) or the
cross-section's statics (``start_path="statics_own"``). Here the dynamic bundle
(:mod:`exucable.model.bundle_rig`, the time integration of the same cables, walls and contacts) pulls the
cables until the material in the bend has come through it, and its force and its cross-section in the
bend's middle are set beside the steady answers from both starts.

The geometry (each case's bend between a straight of ``before`` and one of ``after`` metres):

- the **dynamic pull** starts with a straight ``before + X`` m long before the bend (X the pulled
  distance, more than the bend's arc plus the straight before it, so that every material point in the
  bend at the end came through the bend during the pull from at least ``before`` metres ahead of it),
  the cables' trailing ends at the entry with T_b/3 each, their leading ends ``after`` m past the bend,
  and the duct continued X m beyond them (so the eye moves inside the duct, as the steady rig holds the
  ends in it: no free span hanging under gravity from a mouth). At the end of the pull the cables lie
  from ``before`` metres ahead of the bend to ``after + X`` past it;
- the **steady solves** are of that final geometry: the bend between ``before`` and ``after + X`` m,
  rig at the exit (``solver.steady_lead_out`` 0), from each start.

The dynamic pull starts from (``--from``): ``laid`` (the bundle's laid start, pre-tensioned, not solved:
the clearance path, the arrangement rolled toward the load), ``laid_axis`` and ``laid_statics_own`` (the
other start paths, laid), ``clearance`` or ``statics_own`` (the steady state of the start geometry solved
from that start, the material sliding along it at the pull speed,
:func:`exucable.model.bundle_rig.solved_bundle_layouts`; ``--nudge`` moves cable 3 of it sideways, to break
a symmetric state). As the straight before the bend shortens, the tension entering the bend falls by the
straight's friction; ``--hold-entry`` raises the back tension by it as the pull goes on (the steady solves
of the final geometry then carry the raised back tension).

Per dynamic run: the CPU, steps and Newton iterations; over the last ``--window`` metres pulled the eye's
force's mean, standard deviation and the drift between the halves' means, against the drift expected as
the straight's cable moves from before the bend to after it (``reference_drift_N_per_s``, the share
rope's with the calculators' weight correction); the force at the end from a line fitted over the
window; each cable's place across the duct in the bend's middle every tenth of the pull. The pull's
inertia: in steady sliding at speed V the curved cable's centripetal load m V² κ lowers its wall
force as a tension lower by m V² would, so the bundle's pull is lower by about
n m V² (e^{μ w_c θ} − 1) (the capstan on the bend, n cables of m kg/m, w_c the weight correction,
θ the bend's angle); ``--speeds`` runs more than one speed to measure it.

    nice .venv/bin/python studies/bundle_dynamic_judge.py [--cases up03 up0 left03 ind90]
        [--from laid laid_axis laid_statics_own clearance statics_own] [--pull X] [--speeds 1.0] [--window 1.0]
        [--limit 60] [--nudge 1] [--hold-entry] [--no-steady | --no-dynamic] [--save DIR]
    nice .venv/bin/python studies/bundle_dynamic_judge.py --quick

``--quick``: the up-bend with cable friction 0.3, pulled 0.2 m from the laid start, no steady solve
(a smoke run of the machinery, not a verdict).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bundle_upbend_study import (ANGLE, BACK_N, BEND_RADIUS, DENSITY, G, MU, R_CABLE, R_DUCT,  # noqa: E402
                                 STRAIGHT)


@dataclasses.dataclass(frozen=True)
class Case:
    """One bend of three cables (SI units: m, N, degrees for the bend's angle)."""

    name: str
    turn: str
    cable_friction: float
    angle_deg: float = ANGLE
    radius_m: float = BEND_RADIUS
    before_m: float = STRAIGHT
    after_m: float = STRAIGHT
    duct_radius_m: float = R_DUCT
    friction: float = MU
    back_tension_N: float = BACK_N

    @property
    def arc_m(self) -> float:
        return math.radians(self.angle_deg) * self.radius_m


CASES = {
    # the up-bend study's triangles where the starts disagree
    "up03": Case("up, μ_c 0.3", "up", 0.3),
    "up0": Case("up, μ_c 0", "up", 0.0),
    "left03": Case("left, μ_c 0.3", "left", 0.3),
    # the industry plan's kind: a free triangle at D/d 3.7, μ 0.5, no back tension, 90° of 3 m
    "ind90": Case("90° left R 3 m, D/d 3.7, μ 0.5", "left", 0.0, angle_deg=90.0, radius_m=3.0, before_m=3.0,
                  after_m=4.0, duct_radius_m=3.7 * R_CABLE, friction=0.5, back_tension_N=0.0),
}


def scenario(case: Case, before_m: float, after_m: float, speed_m_per_s: float, limit_s: float = 60.0):
    """The case's bundle (triangular, steady mode) between straights of ``before_m`` and ``after_m``."""
    import exucable as xc

    route = (xc.Route(inner_radius=case.duct_radius_m).straight(before_m)
             .bend(case.angle_deg, radius=case.radius_m, turn=case.turn).straight(after_m))
    return xc.Scenario(route=route,
                       cable=xc.Cable(radius=R_CABLE, density=DENSITY, youngs_modulus=2e8, count=3,
                                      arrangement="triangular"),
                       contact=xc.Contact(friction=case.friction, check_points_per_element=8,
                                          cable_friction=case.cable_friction),
                       pull=xc.Pull(speed=speed_m_per_s, back_tension=case.back_tension_N),
                       gravity=xc.Gravity(g=G),
                       solver=xc.Solver(mode="steady", steady_lead_out=0.0, steady_time_limit=limit_s))


def steady(sc, start: str):
    """Steady solve of ``sc`` from ``start``: (model, outcome, CPU s, pull [N])."""
    from exucable.model.bundle import build_bundle_model
    from exucable.solve.steady import SteadySettings, solve_steady

    c0 = time.process_time()
    model = build_bundle_model(sc, start_path=start)
    out = solve_steady(model, settings=SteadySettings.from_solver(sc.solver))
    cpu = time.process_time() - c0
    pull = float(np.sum(model.pull_shares_N())) if out.status == "ok" else float("nan")
    return model, out, cpu, pull


#: where the cross-sections are taken: the bend's middle, and past the bend's end by these [m]
AFTER_M = (0.5, 1.5, 3.0)


def places_m(case: Case, before_m: float) -> list:
    """The bend's middle and the places :data:`AFTER_M` past its end, along a route whose bend starts
    ``before_m`` from the entry [m]."""
    return [before_m + 0.5 * case.arc_m] + [before_m + case.arc_m + a for a in AFTER_M]


def section_text(xy) -> str:
    """Cables' (horizontal, up) places [m] as text in mm."""
    return "  ".join(f"{i + 1} ({1e3 * h:+.1f}, {1e3 * v:+.1f})" for i, (h, v) in enumerate(xy))


def inertia_share_N(case: Case, speed_m_per_s: float) -> float:
    """The pull's change from the sliding cables' centripetal inertia [N], n m V² (e^{μ w_c θ} − 1)
    (module notes), negative: the inertia lowers the wall force in the bend."""
    from exucable.quasistatic import engineering as eng

    m = DENSITY * math.pi * R_CABLE ** 2
    wc = eng.weight_correction_factor(3, "triangular", 2 * case.duct_radius_m, 2 * R_CABLE)
    return -3 * m * speed_m_per_s ** 2 * (math.exp(case.friction * wc * math.radians(case.angle_deg)) - 1.0)


def rope_pull_N(case: Case, before_m: float, after_m: float) -> float:
    """The calculators' pull [N] of the case's bend between ``before_m`` and ``after_m``: three times
    one cable's rope with friction μ w_c and back tension T_b/3 (:func:`exucable.quasistatic.rope.rope_pull_force_N`)."""
    from exucable.quasistatic import engineering as eng
    from exucable.quasistatic.rope import rope_pull_force_N

    sc = scenario(case, before_m, after_m, 1.0)
    wc = eng.weight_correction_factor(3, "triangular", 2 * case.duct_radius_m, 2 * R_CABLE)
    return 3 * rope_pull_force_N(sc.build_conduit().centreline, friction=case.friction * wc,
                                 weight_per_length_N_per_m=DENSITY * math.pi * R_CABLE ** 2 * G,
                                 trailing_tension_N=case.back_tension_N / 3)


#: the up-bend study's pull speed [m/s]: the steady tables' (the steady answer depends on it only through
#: the cable friction's regularisation, 1 % of it, against slips proportional to it)
STUDY_SPEED = 0.1

#: the unsolved laid starts: the start path each lays
LAID = {"laid": "clearance", "laid_statics_own": "statics_own", "laid_axis": "axis"}


def nudged(layout, nudge_m: float):
    """``layout`` with every node moved ``nudge_m`` [m] sideways (horizontal, square to the cable)."""
    side = np.cross([0.0, 0.0, 1.0], layout.slope)
    side /= np.linalg.norm(side, axis=1)[:, None]
    return dataclasses.replace(layout, position_m=layout.position_m + nudge_m * side)


def straight_friction_N_per_m(case: Case) -> float:
    """The bundle's friction per metre on a horizontal straight by the calculators' weight correction
    [N/m]: μ w_c · 3 w."""
    from exucable.quasistatic import engineering as eng

    wc = eng.weight_correction_factor(3, "triangular", 2 * case.duct_radius_m, 2 * R_CABLE)
    return case.friction * wc * 3 * DENSITY * math.pi * R_CABLE ** 2 * G


def dynamic_pull(case: Case, start: str, pull_m: float, speed_m_per_s: float, limit_s: float, samples: int = 10,
                 nudge_m: float = 0.0, hold_entry: bool = False):
    """Pull the case's bundle ``pull_m`` metres at ``speed_m_per_s`` from ``start`` (module notes).

    Returns a dict: ``time_s``, ``force_N`` (the eye's pull history), ``sections`` (pulled [m], the
    cables' places in the bend's middle [m]), ``cpu_s`` (build, start's solve and integration),
    ``outcome`` (the integration's), ``start_pull_N`` (the start's steady pull, NaN for ``laid``)."""
    from exucable.model.bundle import build_bundle_model, bundle_cross_sections
    from exucable.model.bundle_rig import build_bundle_dynamic_model, solved_bundle_layouts
    from exucable.solve.dynamic import simulate
    from exucable.solve.steady import SteadySettings, solve_steady

    c0 = time.process_time()
    before = case.before_m + pull_m
    sc = scenario(case, before, case.after_m, speed_m_per_s, limit_s)
    laid = start.startswith("laid")
    model = build_bundle_model(sc, start_path=LAID.get(start, start))
    layouts, start_pull = None, float("nan")
    if not laid:
        out = solve_steady(model, settings=SteadySettings.from_solver(sc.solver))
        if out.status != "ok":
            raise RuntimeError(f"the start's steady solve from {start!r} did not converge: {out.message}")
        start_pull = float(np.sum(model.pull_shares_N()))
        layouts = solved_bundle_layouts(model)
        if nudge_m:
            # a symmetric state stays symmetric in a symmetric run: the top cable moved aside breaks it
            layouts[2] = nudged(layouts[2], nudge_m)
    # the duct continued past the leading ends by the pull (and half a metre): the eye stays inside
    longer = scenario(case, before, case.after_m + pull_m + 0.5, speed_m_per_s, limit_s)
    start_model = dataclasses.replace(model, conduit=longer.build_conduit())
    end_time = pull_m / speed_m_per_s
    dyn_sc = sc.replace(**{"solver.mode": "dynamic", "solver.end_time": end_time,
                           "solver.output_interval": end_time / 400})
    dyn = build_bundle_dynamic_model(dyn_sc, start=start_model, layouts=layouts)
    s_mid = before + 0.5 * case.arc_m
    sections, every = [], pull_m / samples
    mbs = dyn.mbs

    def watch(mbs_, t):
        pulled = speed_m_per_s * t
        if pulled >= every * len(sections) - 1e-9:
            sections.append((pulled, bundle_cross_sections(dyn, [s_mid])[0]))
        return True

    trailing = [(i, np.array(mbs.GetLoadParameter(i, "loadVector"), dtype=float))
                for hd in dyn.handles for i in hd.end_loads["trailing"]] if hold_entry else []
    rate = straight_friction_N_per_m(case) * speed_m_per_s / 3 / max(case.back_tension_N / 3, 1e-12)

    def watch_and_hold(mbs_, t):
        # the back tension raised as the straight before the bend shortens: the bend's entry tension
        # stays the start's (set after each step: the next step's load, lagging by one step)
        for i, v0 in trailing:
            mbs_.SetLoadParameter(i, "loadVector", list(v0 * (1.0 + rate * t)))
        return watch(mbs_, t)

    mbs.SetPostStepUserFunction(watch_and_hold)
    outcome = simulate(dyn, steady_stop=False)
    cpu = time.process_time() - c0
    h = outcome.history
    return {"time_s": np.asarray(h.time_s), "force_N": np.asarray(h.pull_force_N), "sections": sections,
            "final_section": bundle_cross_sections(dyn, places_m(case, before))[0],
            "final_after": bundle_cross_sections(dyn, places_m(case, before))[1:], "cpu_s": cpu, "outcome": outcome,
            "start_pull_N": start_pull}


def window_stats(t, f, speed_m_per_s: float, window_m: float) -> dict:
    """The eye's force over the last ``window_m`` metres pulled: mean, standard deviation, the drift
    between the halves' means (per metre), the fitted line's value at the end and its standard error."""
    keep = t >= t[-1] - window_m / speed_m_per_s
    tt, ff = t[keep], f[keep]
    half = tt < 0.5 * (tt[0] + tt[-1])
    x = speed_m_per_s * (tt - tt[-1])
    A = np.column_stack([np.ones_like(x), x])
    coef, res, *_ = np.linalg.lstsq(A, ff, rcond=None)
    dof = max(1, ff.size - 2)
    sigma2 = float(np.sum((ff - A @ coef) ** 2)) / dof
    cov = sigma2 * np.linalg.inv(A.T @ A)
    return {"mean": float(ff.mean()), "std": float(ff.std()), "rows": int(ff.size),
            "halves_drift_N_per_m": float((ff[~half].mean() - ff[half].mean()) / (0.5 * window_m)),
            "end": float(coef[0]), "end_se": float(math.sqrt(cov[0, 0])), "slope_N_per_m": float(coef[1])}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cases", nargs="+", default=["up03"], choices=sorted(CASES))
    p.add_argument("--from", dest="starts", nargs="+", default=["laid", "clearance", "statics_own"],
                   choices=(*LAID, "clearance", "statics_own"), help="the dynamic pull's starts")
    p.add_argument("--pull", type=float, default=None, help="pulled distance X [m] (default: the bend's arc "
                   "plus the straight before it plus 1 m)")
    p.add_argument("--speeds", type=float, nargs="+", default=[1.0], help="pull speeds [m/s]")
    p.add_argument("--window", type=float, default=1.0, help="the last stretch pulled the force is judged on [m]")
    p.add_argument("--limit", type=float, default=60.0, help="each steady solve's CPU limit [s]")
    p.add_argument("--no-steady", action="store_true", help="the dynamic pulls only")
    p.add_argument("--no-dynamic", action="store_true", help="the steady solves only")
    p.add_argument("--hold-entry", action="store_true", help="raise the back tension by the straight's friction "
                   "μ w_c 3w per metre pulled, so that the bend's entry tension stays; the final geometry's steady "
                   "solves then carry T_b + μ w_c 3w X")
    p.add_argument("--nudge", type=float, default=0.0, help="the solved starts' cable 3 moved this far sideways [mm]")
    p.add_argument("--save", type=Path, help="a folder for each dynamic pull's force history and sections (.npz)")
    p.add_argument("--quick", action="store_true", help="the up-bend with μ_c 0.3 pulled 0.2 m from the laid start")
    args = p.parse_args(argv)
    if args.quick:
        args.cases, args.starts, args.pull, args.speeds, args.window, args.no_steady = ["up03"], ["laid"], 0.2, [1.0], 0.1, True
    for key in args.cases:
        case = CASES[key]
        X = args.pull if args.pull is not None else case.arc_m + case.before_m + 1.0
        print(f"\n## {case.name}: {case.angle_deg:g}° {case.turn} of R {case.radius_m:g} m, straights {case.before_m:g} / "
              f"{case.after_m:g} m, D/d {case.duct_radius_m / R_CABLE:.3g}, μ {case.friction:g}, back tension "
              f"{case.back_tension_N:g} N, pulled {X:g} m (arc + straight before {case.arc_m + case.before_m:.3g} m)")
        if not args.no_steady:
            print(f"\nsteady solves of the study's geometry and of the pull's final geometry, from each start, at the "
                  f"study's {STUDY_SPEED:g} m/s:\n")
            print("| geometry | start | status | CPU [s] | pull [N] | shares [N] | cables in the bend's middle (horizontal, up) [mm] | "
                  + " | ".join(f"{a:g} m past the bend [mm]" for a in AFTER_M) + " |")
            print("| --- | --- | --- | --- | --- | --- | --- |" + " --- |" * len(AFTER_M))
            final = case
            if args.hold_entry:
                final = dataclasses.replace(case, back_tension_N=case.back_tension_N + straight_friction_N_per_m(case) * X)
                print(f"(final geometry: back tension {final.back_tension_N:.2f} N, raised as the pull held the bend's entry)\n")
            for c_, after, label in ((case, case.after_m, "study"), (final, case.after_m + X, "final")):
                for start in ("clearance", "statics_own"):
                    from exucable.model.bundle import bundle_cross_sections
                    sc = scenario(c_, case.before_m, after, STUDY_SPEED, args.limit)
                    model, out, cpu, pull = steady(sc, start)
                    xy = bundle_cross_sections(model, places_m(case, case.before_m))
                    print(f"| {label} ({case.before_m:g} / {after:.3g} m) | {start} | {out.status} | {cpu:.2f} | {pull:.3f} | "
                          f"{' / '.join(f'{x:.2f}' for x in model.pull_shares_N())} | {section_text(xy[0])} | "
                          + " | ".join(section_text(x) for x in xy[1:]) + " |", flush=True)
        for V in [] if args.no_dynamic else args.speeds:
            print(f"\ndynamic pulls at {V:g} m/s" + (f", the solved starts' cable 3 moved {args.nudge:g} mm aside" if args.nudge else "") + f" (ε {100 * 0.01:g} % of it: {1e3 * 0.01 * V:g} mm/s), inertia's share "
                  f"n m V² (e^(μ w_c θ) − 1) = {inertia_share_N(case, V):+.3f} N; the last {args.window:g} m pulled:\n")
            w_ = args.window
            # held entry: only the straight after the bend lengthens
            drift = (rope_pull_N(case, case.before_m, case.after_m + X)
                     - rope_pull_N(case, case.before_m + (0.0 if args.hold_entry else w_), case.after_m + X - w_))
            print(f"expected drift (the rope's pull with μ w_c, straights {case.before_m + (0.0 if args.hold_entry else w_):g} / {case.after_m + X - w_:.3g} m → "
                  f"{case.before_m:g} / {case.after_m + X:.3g} m): {drift / w_:+.3f} N/m\n")
            print("| from | start's steady pull [N] | status | CPU [s] | steps | Newton its | mean [N] | std [N] | "
                  "drift between halves [N/m] | at the end, fitted [N] | cables in the bend's middle at the end [mm] |")
            print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
            runs = []
            for start in args.starts:
                try:
                    r = dynamic_pull(case, start, X, V, args.limit, nudge_m=1e-3 * args.nudge,
                                     hold_entry=args.hold_entry)
                except RuntimeError as exc:
                    print(f"| {start} | {exc} | | | | | | | | | |", flush=True)
                    continue
                o = r["outcome"]
                w = window_stats(r["time_s"], r["force_N"], V, args.window)
                runs.append((start, r))
                if args.save is not None:
                    args.save.mkdir(parents=True, exist_ok=True)
                    np.savez(args.save / f"{key}_{start}_{V:g}{'_nudge' if args.nudge else ''}.npz", time_s=r["time_s"], force_N=r["force_N"],
                             pulled_m=np.array([x for x, _ in r["sections"]]),
                             sections_m=np.array([xy for _, xy in r["sections"]]))
                print(f"| {start} | {r['start_pull_N']:.3f} | {o.status} | {r['cpu_s']:.1f} | {o.steps} | {o.newton_iterations} "
                      f"| {w['mean']:.3f} | {w['std']:.3f} | {w['halves_drift_N_per_m']:+.3f} "
                      f"| {w['end']:.3f} ± {w['end_se']:.3f} | {section_text(r['final_section'])} |", flush=True)
            print("\nat the pull's end, past the bend: " + ", ".join(f"{a:g}" for a in AFTER_M) + " m [mm]:")
            for start, r in runs:
                print(f"  {start}: " + " | ".join(section_text(x) for x in r["final_after"]))
            for start, r in runs:
                print(f"\n{start}: cables in the bend's middle as the pull goes on (pulled [m]: places [mm]):")
                for pulled, xy in r["sections"]:
                    print(f"  {pulled:5.2f}: {section_text(xy)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
