"""Three cables through an up-bend: where the bundle's steady solve stalled, and why (it now relaxes the
bundle dynamically first where its one-iteration steps fail, exucable/solve/relax.py, and solves them).

The smallest case of the 100 m bundle route's failure: a 30° up-bend of 5 m radius between two 3 m
straights, three cables of 30 mm (1.41 kg/m, EJ 7.95 N m²) in a 100 mm duct (D/d 3.33), wall
friction μ 0.3, 300 N back tension, gravity, the mesh rule's elements (1 m), 8 check points per
element, steady mode, beside its neighbours: the same bend turned down and turned left, both
arrangements, with and without friction between the cables (``contact.cable_friction`` 0.3). Per case
it prints the status, the solve's CPU time and Newton iterations, the smallest residual the solver
recorded at full load (an inexact pseudo-time step records its spring's force only, so this is a
lower bound of the true residual there) against the stop tolerance, and the pull.

Then, for the up-bend (triangular, frictionless between the cables), at accepted states of the
steady solve at full load: the true residual, the eigenvalues of M⁻¹K nearest zero (K the
unregularised equilibrium's Jacobian, the eye's held coordinates removed; M the pseudo-time
spring's lumped masses; a negative one is an unstable mode) and where the softest mode lives, how
many cable-cable contacts switch on or off between successive accepted states (and the smallest
penetration among them: grazing contacts), and the cables' places across the duct in the bend. The
top cable's net lateral load there is printed too: T κ of its own tension (T_b/3 plus its weight
times the rise: it touches no wall) against its weight.

Every solve goes through the smooth contact onset continued from 0.5 mm to 0, as the bundle's steady
solve does (:mod:`exucable.solve.onset_continuation`); per case the layers' pulls, Newton iterations
and CPU follow the table, with the first layer ``--onset`` [m] (the solve's default) or, with
``--no-onset``, the law of one cable throughout (the stall).

    nice .venv/bin/python studies/bundle_upbend_study.py [--limit 60] [--quick] [--onset 5e-4 | --no-onset]
        [--start clearance | statics | statics_own | axis]

``--start``: the bundle's start (``build_bundle_model``'s ``start_path``; the default's when not given).

``--quick``: the up-bend and the down-bend only (triangular, frictionless between the cables), with a
5 s CPU limit, and the diagnosis of what the up-bend reached in it.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
import exudyn as exu

import exucable as xc
from exucable.model.bundle import build_bundle_model, bundle_cross_sections
from exucable.solve import steady as st
from exucable.solve.onset_continuation import OnsetSettings, extrapolate_to_zero

R_CABLE, R_DUCT, DENSITY, MU, BACK_N, G = 0.015, 0.05, 2000.0, 0.3, 300.0, 9.81
BEND_RADIUS, ANGLE, STRAIGHT = 5.0, 30.0, 3.0

CASES = [(bend, arrangement, cf) for cf in (0.0, 0.3) for bend in ("up", "down", "left")
         for arrangement in ("triangular", "cradled")]


def scenario(bend: str, arrangement: str, cable_friction: float, time_limit_s: float):
    route = (xc.Route(inner_radius=R_DUCT).straight(STRAIGHT).bend(ANGLE, radius=BEND_RADIUS, turn=bend)
             .straight(STRAIGHT))
    return xc.Scenario(route=route,
                       cable=xc.Cable(radius=R_CABLE, density=DENSITY, youngs_modulus=2e8, count=3,
                                      arrangement=arrangement),
                       contact=xc.Contact(friction=MU, check_points_per_element=8, cable_friction=cable_friction),
                       pull=xc.Pull(speed=0.1, back_tension=BACK_N), gravity=xc.Gravity(g=G),
                       solver=xc.Solver(mode="steady", steady_lead_out=0.0, steady_time_limit=time_limit_s))


class RecordingSolver(st.SteadySolver):
    """The steady solver, keeping every accepted state (load scale, true residual, coordinates)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.accepted_states = []

    def record(self, lam, residual):
        super().record(lam, residual)
        q, ae, _ = self.store.saved
        self.accepted_states.append((lam, residual, q.copy(), ae.copy()))


def run_case(bend, arrangement, cf, limit, onset=None, start=None):
    sc = scenario(bend, arrangement, cf, limit)
    model = build_bundle_model(sc) if start is None else build_bundle_model(sc, start_path=start)
    solver = RecordingSolver(model, st.SteadySettings.from_solver(sc.solver), onset=onset)
    c0 = time.process_time()
    out = solver.solve()
    cpu = time.process_time() - c0
    full = [r for lam, r, _, _ in solver.accepted_states if lam == 1.0]
    pull = float(np.sum(model.pull_shares_N())) if out.status == "ok" else float("nan")
    return model, solver, out, cpu, (min(full) if full else float("nan")), pull


def set_state(model, q, ae):
    sd = model.mbs.systemData
    for cfg in (exu.ConfigurationType.Initial, exu.ConfigurationType.Current):
        sd.SetODE2Coordinates(list(q), configuration=cfg)
        sd.SetAECoordinates(list(ae), configuration=cfg)


def residual_and_stiffness(model, solver, q, ae):
    """The true residual [N] (the eye's held coordinates left out) and K = -∂r/∂q, M at the state,
    with the held coordinates removed, and the free coordinates' indices."""
    set_state(model, q, ae)
    solver.spring.rate = 0.0
    settings = st.static_settings(tolerance=1.0, max_iterations=1)
    s = exu.MainSolverStatic()
    s.InitializeSolver(model.mbs, settings)
    s.ComputeNewtonResidual(model.mbs, settings)
    r = np.array(s.GetSystemResidual())
    s.ComputeNewtonJacobian(model.mbs, settings)
    J = np.asarray(s.GetSystemJacobian())
    idx = model.ode2_index
    held = np.concatenate([model.mbs.GetNodeODE2Index(c.nodes[-1]) + np.arange(3) for c in model.cables])
    free = np.setdiff1d(np.arange(len(idx)), np.searchsorted(idx, held))
    m = np.repeat(solver.spring.block_mass.reshape(-1), 3)[free]
    K = -J[np.ix_(idx, idx)][np.ix_(free, free)]
    res = r[idx][free]
    return float(np.linalg.norm(res)), K, m, free


def mode_place(model, vec, free):
    """(cable, arc length along the pull-oriented centreline [m], direction (x, y, z)) of a mode's largest motion."""
    full = np.zeros(len(model.ode2_index))
    full[free] = vec
    pos = full.reshape(model.n_cables, -1, 6)[:, :, :3]
    amp = np.linalg.norm(pos, axis=2)
    c, node = np.unravel_index(np.argmax(amp), amp.shape)
    return int(c), float(model.layout.cables[c].node_s_m[node]), pos[c, node] / amp[c, node]


def pair_set(model, q):
    qa = model.layout.coordinates.reshape(-1) + q[model.ode2_index]
    c = model.between.contacts(qa)
    return set(map(int, c["index"][:, 0])), c["penetration_m"]


def diagnose(model, solver, n_states: int):
    full = [s for s in solver.accepted_states if s[0] == 1.0]
    if not full:
        print("no accepted state at full load to diagnose")
        return
    best = int(np.argmin([s[1] for s in full]))
    picks = sorted(set(np.linspace(max(0, best - 2 * n_states), len(full) - 1, n_states).astype(int)) | {best})
    print("\n| accepted state (full load) | true residual [N] | eigenvalues of M⁻¹K nearest 0 [1/s²] "
          "| softest mode: cable, s [m], direction | pairs | switched on / off since the state before | smallest pair penetration [µm] |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for k in picks:
        _, _, q, ae = full[k]
        res, K, m, free = residual_and_stiffness(model, solver, q, ae)
        w, V = np.linalg.eig(K / m[:, None])
        order = np.argsort(np.abs(w.real))
        cable, s, d = mode_place(model, V[:, order[0]].real, free)
        now, pen = pair_set(model, q)
        before, _ = pair_set(model, full[k - 1][2]) if k > 0 else (now, None)
        negatives = int(np.count_nonzero(w.real < 0))
        print(f"| {k}{' (best)' if k == best else ''} | {res:.3g} | {', '.join(f'{x:.3g}' for x in w.real[order[:4]])} "
              f"({negatives} negative) | {cable + 1}, {s:.2f}, ({d[0]:+.2f}, {d[1]:+.2f}, {d[2]:+.2f}) | {len(now)} "
              f"| {len(now - before)} / {len(before - now)} | {1e6 * pen.min() if len(pen) else float('nan'):.3g} |")
    _, _, q, ae = full[best]
    set_state(model, q, ae)
    s_mid = STRAIGHT + 0.5 * math.radians(ANGLE) * BEND_RADIUS
    places = [STRAIGHT - 0.5, s_mid, STRAIGHT + math.radians(ANGLE) * BEND_RADIUS + 0.5]
    xs = 1e3 * bundle_cross_sections(model, places)
    print("\ncables across the duct at the best state, (horizontal, up) from the duct's axis [mm], looking along the pull:")
    for s, x in zip(places, xs):
        print(f"  s = {s:.2f} m: " + "  ".join(f"cable {i + 1} ({h:+.1f}, {v:+.1f})" for i, (h, v) in enumerate(x)))
    w = DENSITY * math.pi * R_CABLE ** 2 * G
    rise = BEND_RADIUS * (1.0 - math.cos(math.radians(ANGLE) / 2))
    T_top = BACK_N / 3 + w * rise
    print(f"top cable in the bend's middle: T κ = {T_top / BEND_RADIUS:.3g} N/m (T = {T_top:.4g} N: T_b/3 plus its "
          f"weight times the rise) against its weight {w:.3g} N/m: net {T_top / BEND_RADIUS - w:+.3g} N/m toward the "
          f"bend's centre")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--limit", type=float, default=60.0, help="each solve's CPU time limit [s]")
    p.add_argument("--states", type=int, default=6, help="accepted states to diagnose")
    p.add_argument("--quick", action="store_true", help="the up- and down-bend only, 5 s CPU each")
    p.add_argument("--onset", type=float, default=OnsetSettings().first_m, help="the first onset layer [m]")
    p.add_argument("--no-onset", action="store_true", help="the law of one cable throughout (no onset layer)")
    p.add_argument("--start", choices=("clearance", "statics", "statics_own", "axis"), help="the bundle's start (default: the model's)")
    args = p.parse_args(argv)
    onset = None if args.no_onset else OnsetSettings(first_m=args.onset)
    cases = CASES
    if args.quick:
        cases, args.limit, args.states = [("up", "triangular", 0.0), ("down", "triangular", 0.0)], 5.0, 3
    print(f"three cables, 30° bend of {BEND_RADIUS:g} m between {STRAIGHT:g} m straights, D/d {R_DUCT / R_CABLE:.3g}, "
          f"μ {MU}, back tension {BACK_N:g} N, gravity; CPU limit {args.limit:g} s per solve")
    print("\n| bend | arrangement | cable friction | status | solve CPU [s] | Newton its | smallest residual recorded at full load [N] "
          "| stop [N] | pull [N] |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    kept, layers = None, []
    for bend, arrangement, cf in cases:
        model, solver, out, cpu, smallest, pull = run_case(bend, arrangement, cf, args.limit, onset, args.start)
        print(f"| {bend} | {arrangement} | {cf:g} | {out.status} | {cpu:.2f} | {out.newton_iterations} | {smallest:.3g} "
              f"| {solver.tolerance_N:.3g} | {pull:.6g} |", flush=True)
        if out.onset_layer is not None:
            layers.append(((bend, arrangement, cf), out.onset_layer))
        if (bend, arrangement, cf) == ("up", "triangular", 0.0):
            kept = (model, solver)
    if layers:
        print("\nthe onset layer's continuation, per case: layer [µm]: pull [N] (Newton iterations, CPU [s]); "
              "F₀ extrapolated from the last two layers above 0")
        for (bend, arrangement, cf), o in layers:
            st_ = o["stages"]
            above = [x for x in st_ if x["converged"] and x["layer_m"] > 0.0]
            f0 = extrapolate_to_zero([x["layer_m"] for x in above], [x["pull_force_N"] for x in above])[0] if above else float("nan")
            print(f"  {bend} {arrangement} μ_c {cf:g}: " + ", ".join(
                f"{1e6 * x['layer_m']:.3g}: " + (f"{x['pull_force_N']:.6g}" if x["converged"] else "stalled")
                + f" ({x['newton_iterations']}, {x['cpu_s']:.2f})" for x in st_) + f"; F₀ from the layers above 0: {f0:.6g}")
    if kept is not None:
        diagnose(*kept, args.states)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
