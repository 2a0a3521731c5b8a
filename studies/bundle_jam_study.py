"""Three cables through the jam range D/d 2.5-3.5: what the steady sliding model predicts, and why.

One 90° bend of 2 m radius between two 0.5 m straights, gravity on, wall friction μ 0.3, each cable
entering with 100 N (16 elements of 0.26 m, 8 check points each), in steady mode: cradled and
triangular starts, frictionless and μ_c 0.3 between the cables, a horizontal bend (``left``: the
bend's pull and the weight press the bundle into the inner wall's lower side) and a vertical
up-bend (``up``: the bend's pull, 50 N/m per cable, turns the cables' 13.9 N/m weight round, so the
bundle must cross the duct, the place a wedge would form); and, in a 2 m horizontal straight with
gravity, a start laid as the jam itself (the keystone of :mod:`exucable.quasistatic.bundle_jam`: at
D/d 2.9 across the duct, at 3.05 at its frictionless balance), to see whether the model holds it.
Per case, all measured in this one run:

- the status, the pull force F over the calculators' 3 × (one cable's rope with μ·w_c and T_b/3),
  each cable's share, wall normal force and force from the other cables (sums over check points);
- the arrangement found in each straight and bend (:mod:`exucable.post.bundle`) and the jam flag;
- the wedge factor: the largest cable-cable contact force per unit length over the lateral load per
  unit length on one cable there, in the bend's middle half (away from its ends and the eye),
  |T κ n − w e_z⊥| with T the share rope's tension: rigid circles
  give 2x = 2d/(D − d) between a cradle's side and middle, 1/√3 from a triangle's top, and
  d/(2h) in the keystone across the duct (:mod:`exucable.quasistatic.bundle_jam`), which grows
  without bound toward D/d = 3.

Then the jam itself, in the dynamic mode with the pull standing still (``pull.stop_time = 0``, the
weight and back tension ramped in over 0.2 s): three cables laid as the keystone across a 2 m
horizontal duct with gravity at the angle that needs the least wall friction
(:func:`~exucable.quasistatic.bundle_jam.least_friction_keystone`), with the kinetic μ 0.3 alone and
with a static μ_s 0.5 (Stribeck, v_s 1 cm/s; regularisation ε 0.1 mm/s): does it stand (the run's
status ``jam``) where the statics say the friction holds it, and drop into the triangle where not?
Per case the status, the arrangement, the outer cables' final angle and the middle cable's contact
force per length over its weight against the keystone's G/p at that angle. And one held keystone
pulled on again after 0.3 s (``pull.hold_time``): the restart force's peak against the pull once it
has dropped through.

Beside it, from the rigid-circle statics of the keystone (no Exudyn): the least wall friction that
holds a keystone across the duct, and the D/d band where a friction μ_s holds one, in a round duct
and with a bend's 5 % ovality.

    nice .venv/bin/python studies/bundle_jam_study.py [--ratios 2.6 2.9 3.1 3.4] [--up-ratios 2.9] [--keystone-ratios 2.9 3.05]
        [--stopped-ratios 2.9 2.95 2.97 2.98 2.99 3.05] [--restart-ratio 2.98]
        [--record reference/bundle_jam_study.json] [--figure reference/bundle_jam.png] [--from-json FILE]

The record and its reading: reference/README.md, "Three cables through the jam range".
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import time
from pathlib import Path

import numpy as np

import exucable as xc
from exucable.errors import ExucableError
from exucable.io import atomic_write_text, save_figure
import exucable.model.bundle as bundle_model
from exucable.model.bundle import build_bundle_model, bundle_report, bundle_sections
from exucable.quasistatic.bundle_jam import (frictionless_keystone_psi_rad, keystone, keystone_friction_needed,
                                             least_friction_keystone, wedge_band_d_over_D)
from exucable.solve.steady import solve_steady

D_CABLE, RADIUS, T0, STRAIGHT, MU, G = 0.03, 2.0, 100.0, 0.5, 0.3, 9.81
STRAIGHT_KEYSTONE = 2.0     # the straight the keystone start is tried in [m]


def middle_half_m(turn) -> tuple[float, float]:
    """Where the wedge factor is read [m]: the bend's (or the straight's) middle half, away from the
    bend's ends' bending boundary layers and the eye, where the cables' bending shear, not the lateral
    load, sets the contact forces."""
    if turn == "straight":
        return 0.25 * STRAIGHT_KEYSTONE, 0.75 * STRAIGHT_KEYSTONE
    return STRAIGHT + 0.25 * RADIUS * math.pi / 2, STRAIGHT + 0.75 * RADIUS * math.pi / 2


@contextlib.contextmanager
def keystone_start():
    """Lay the cables as the keystone (:mod:`exucable.quasistatic.bundle_jam`) instead of the named
    arrangement: at its frictionless balance where there is one (D/d > 3), else across the duct."""
    original = bundle_model.arrangement_offsets

    def offsets(count, arrangement, inner_radius_m, cable_radius_m):
        D, d = 2.0 * inner_radius_m, 2.0 * cable_radius_m
        psi = frictionless_keystone_psi_rad(D, d)
        return keystone(D, d, math.pi / 2 if psi is None else psi).positions_m[0]

    bundle_model.arrangement_offsets = offsets
    try:
        yield
    finally:
        bundle_model.arrangement_offsets = original


def scenario(arrangement, ratio, cable_friction, turn):
    if turn == "straight":
        route = xc.Route(inner_radius=ratio * D_CABLE / 2).straight(STRAIGHT_KEYSTONE)
    else:
        route = (xc.Route(inner_radius=ratio * D_CABLE / 2).straight(STRAIGHT).bend(90, radius=RADIUS, turn=turn)
                 .straight(STRAIGHT))
    return xc.Scenario(route=route,
                       cable=xc.Cable(radius=D_CABLE / 2, density=2000.0, youngs_modulus=2e8, bending_stiffness=1.0,
                                      count=3, arrangement=arrangement, elements=16),
                       contact=xc.Contact(friction=MU, cable_friction=cable_friction, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=3 * T0), gravity=xc.Gravity(g=G),
                       solver=xc.Solver(mode="steady", end_time=1.0, steady_lead_out=0.0))


def wedge_factor(model, turn) -> tuple[float, float]:
    """The largest cable-cable contact force per unit length over one cable's lateral load per unit
    length at that place [-] in the middle half (:func:`middle_half_m`), and the place along the conduit [m]."""
    kernel = model.between
    q_all = np.concatenate([q.reshape(-1) for q in model.cable_coordinates()])
    c = kernel.contacts(q_all)
    if len(c["penetration_m"]) == 0:
        return 0.0, float("nan")
    p_index = c["index"][:, 0]
    cable, point = p_index // kernel.n_points, p_index % kernel.n_points
    spacing = kernel.element_length_m[point // kernel.n_k] / kernel.n_k
    line_load = kernel.weight[point] * kernel.law.stiffness * c["penetration_m"] ** kernel.law.exponent / spacing
    x_pts, _ = kernel.point_forces_N(q_all)
    s = np.array([np.interp(x_pts[j], model.layout.cables[i].node_x_m, model.layout.cables[i].node_s_m)
                  for i, j in zip(cable, point)])
    centre = model.conduit.centreline
    s = np.clip(s, 0.0, centre.length_m)
    t = np.atleast_2d(centre.tangent(s))
    kn = np.atleast_2d(centre.curvature_vector(s))
    T = np.interp(s, model.rope.s_conduit_m, model.rope.tension_N)
    w = model.scenario.cable.mass_per_length_kg_per_m * G
    ez = np.array([0.0, 0.0, 1.0])
    lateral = np.linalg.norm(T[:, None] * kn - w * (ez[None, :] - (t @ ez)[:, None] * t), axis=1)
    ratio = line_load / np.maximum(lateral, 1e-9)
    a, b = middle_half_m(turn)
    ratio = np.where((s >= a) & (s <= b), ratio, 0.0)
    k = int(np.argmax(ratio))
    return float(ratio[k]), float(s[k])


def case_plan(args) -> list[tuple]:
    """(start, D/d, μ_c, bend) of each case: both starts through D/d in the horizontal bend; μ_c > 0
    at ``--friction-ratios``; the cradle in the up-bend; the keystone start in a straight."""
    out = [(a, r, 0.0, "left") for a in args.arrangements for r in args.ratios]
    out += [(a, r, mu, "left") for mu in args.cable_friction if mu > 0.0 for a in args.arrangements
            for r in args.friction_ratios]
    out += [("cradled", r, 0.0, "up") for r in args.up_ratios]
    out += [("keystone", r, 0.0, "straight") for r in args.keystone_ratios]
    return out


def one_case(arrangement, ratio, cable_friction, turn) -> dict:
    row = {"arrangement": arrangement, "ratio": ratio, "cable_friction": cable_friction, "turn": turn}
    try:
        if arrangement == "keystone":
            with keystone_start():
                model = build_bundle_model(scenario("cradled", ratio, cable_friction, turn))
        else:
            model = build_bundle_model(scenario(arrangement, ratio, cable_friction, turn))
    except ExucableError as exc:        # an arrangement that does not fit: say so, go on
        return dict(row, status="refused", message=str(exc))
    t0 = time.process_time()
    out = solve_steady(model)
    row.update(status=out.status, message=out.message, cpu_s=time.process_time() - t0)
    if out.status == "failed":
        return row
    rep = bundle_report(model)
    sec = bundle_sections(model)
    formula = model.n_cables * model.rope.pull_force_N
    wf, s_wf = wedge_factor(model, turn)
    row.update(pull_force_N=rep["pull_force_N"], formula_pull_force_N=formula,
               pull_vs_formula=rep["pull_force_N"] / formula,
               shares_N=[c["pull_share_N"] for c in rep["cables"]],
               wall_normal_force_N=[c["wall_normal_force_N"] for c in rep["cables"]],
               cable_contact_force_N=[c["cable_contact_force_N"] for c in rep["cables"]],
               sections=[{"kind": s["kind"], "arrangement": s["arrangement"], "seen": s["arrangements_seen"],
                          "jam": s["jam"]} for s in sec["sections"]],
               jam=sec["jam"], wedge_factor=wf, wedge_factor_s_m=s_wf)
    return row


STOPPED_LENGTH, STOP_RAMP, STOP_END, MU_S = 2.0, 0.2, 0.35, 0.5


@contextlib.contextmanager
def laid_keystone(psi_rad):
    """Lay the cables exactly as the keystone at the outer cables' angle ``psi_rad``: without the
    start's 5 % gap (laid as larger circles), which near D/d 3 lifts the middle cable millimetres
    off the others and drops it on them."""
    original = bundle_model.arrangement_offsets

    def offsets(count, arrangement, inner_radius_m, cable_radius_m):
        return keystone(2.0 * inner_radius_m, D_CABLE, psi_rad).positions_m[0]

    bundle_model.arrangement_offsets = offsets
    try:
        yield
    finally:
        bundle_model.arrangement_offsets = original


def stopped_scenario(ratio, static_friction, hold_s=None, end_s=STOP_END):
    """The keystone in a 2 m horizontal duct with gravity, the pull standing still from the start
    (pulling on after ``hold_s`` if given), loads ramped in over 0.2 s, 8 elements."""
    return xc.Scenario(route=xc.Route(inner_radius=ratio * D_CABLE / 2).straight(STOPPED_LENGTH),
                       cable=xc.Cable(radius=D_CABLE / 2, density=2000.0, youngs_modulus=2e8, bending_stiffness=1.0,
                                      count=3, arrangement="cradled", elements=8),
                       contact=xc.Contact(friction=MU, static_friction=static_friction, check_points_per_element=8,
                                          friction_regularisation_velocity=1e-4),
                       pull=xc.Pull(speed=0.1, back_tension=3 * T0 / 10, stop_time=0.0, hold_time=hold_s,
                                    ramp_time=STOP_RAMP),
                       gravity=xc.Gravity(g=G), solver=xc.Solver(mode="dynamic", end_time=end_s))


def middle_contact_factor(model) -> float:
    """The middle cable's mean contact force per length with the outer ones over its weight per length
    [-], in the duct's middle half (a bending length and more from either end)."""
    kernel = model.between
    q_all = np.concatenate([q.reshape(-1) for q in model.cable_coordinates()])
    c = kernel.contacts(q_all)
    if len(c["penetration_m"]) == 0:
        return 0.0
    cable, point = c["index"][:, 0] // kernel.n_points, c["index"][:, 0] % kernel.n_points
    x_pts, _ = kernel.point_forces_N(q_all)
    s = np.array([np.interp(x_pts[j], model.layout.cables[i].node_x_m, model.layout.cables[i].node_s_m)
                  for i, j in zip(cable, point)])
    line = (kernel.weight[point] * kernel.law.stiffness * c["penetration_m"] ** kernel.law.exponent
            / (kernel.element_length_m[point // kernel.n_k] / kernel.n_k))
    mid = ((s >= 0.25 * STOPPED_LENGTH) & (s <= 0.75 * STOPPED_LENGTH)
           & ((cable == 1) | (c["index"][:, 1] // kernel.n_points == 1)))
    w = model.scenario.cable.mass_per_length_kg_per_m * G
    return float(np.mean(line[mid]) / w) if mid.any() else 0.0


def stopped_case(ratio, static_friction, hold_s=None, end_s=STOP_END) -> dict:
    """One laid keystone held still (and pulled on after ``hold_s``): statics' verdict beside the run's."""
    psi, need = least_friction_keystone(ratio * D_CABLE, D_CABLE)
    if not math.isfinite(need):
        psi = frictionless_keystone_psi_rad(ratio * D_CABLE, D_CABLE)
    wall_mu = MU if static_friction is None else static_friction
    row = {"ratio": ratio, "static_friction": static_friction, "hold_s": hold_s, "psi_laid_deg": math.degrees(psi),
           "friction_needed": need, "statics_holds": bool(need <= wall_mu)}
    t0 = time.process_time()
    with laid_keystone(psi):
        res = xc.run(stopped_scenario(ratio, static_friction, hold_s, end_s))
    b = res.summary.bundle
    offs = np.array(b["cross_sections"][0]["offsets_m"]) if b["cross_sections"] else None
    psi_end = math.degrees(math.atan2(-offs[0, 0], -offs[0, 1])) if offs is not None else float("nan")
    G_statics = None
    if offs is not None and b["jam"]:
        G_statics = float(keystone(ratio * D_CABLE, D_CABLE, math.radians(psi_end)).contact_force_per_load[0])
    h = res.history
    t, F = np.asarray(h.time_s), np.asarray(h.pull_force_N)
    row.update(status=res.status, jam=b["jam"], cpu_s=time.process_time() - t0,
               arrangements_seen=b["sections"][0]["arrangements_seen"] if b["sections"] else {},
               psi_end_deg=psi_end, contact_factor=middle_contact_factor(res.model), keystone_G_per_p=G_statics,
               message=res.summary.message)
    if hold_s is not None:
        after = t >= hold_s
        last = t >= t[-1] - 0.1
        row.update(restart_peak_N=float(np.max(F[after])), restart_peak_s=float(t[after][np.argmax(F[after])]),
                   held_pull_N=float(F[np.searchsorted(t, hold_s) - 1]), final_pull_N=float(np.mean(F[last])))
    return row


def rigid_wedge_factors(ratio) -> dict:
    """The rigid circles' contact force over the lateral load [-]: cradle 2x, keystone across d/(2h)."""
    x = 1.0 / (ratio - 1.0)
    rho = 0.5 * (ratio - 1.0)
    out = {"cradled": 2.0 * x, "triangular_top": 1.0 / math.sqrt(3.0)}
    out["keystone_across"] = (keystone(ratio, 1.0, math.pi / 2).contact_force_per_load[0]
                              if (1 / math.sqrt(2) <= rho < 1.0) else None)
    return out


def statics_table(ratios) -> list[dict]:
    rows = []
    for r in ratios:
        rows.append({"ratio": r, "friction_needed_across": keystone_friction_needed(r, 1.0),
                     **rigid_wedge_factors(r)})
    return rows


def figure(record, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 4, figsize=(18, 4.4))
    styles = {("cradled", 0.0): ("o", "C0"), ("cradled", 0.3): ("o", "C1"),
              ("triangular", 0.0): ("s", "C2"), ("triangular", 0.3): ("s", "C3")}
    rows = [r for r in record["cases"] if r["status"] != "refused"]
    for (arr, mu_c), (marker, color) in styles.items():
        for turn, ls in (("left", "-"), ("up", ":")):
            sel = [r for r in rows if r["arrangement"] == arr and r["cable_friction"] == mu_c and r["turn"] == turn]
            ok = [r for r in sel if r["status"] != "failed"]
            label = f"{arr}, μ_c {mu_c:g}, {'horizontal' if turn == 'left' else 'up-bend'}"
            if ok:
                x = [r["ratio"] for r in ok]
                axes[0].plot(x, [r["pull_vs_formula"] for r in ok], ls=ls, marker=marker, color=color, label=label)
                axes[1].plot(x, [r["wedge_factor"] for r in ok], ls=ls, marker=marker, color=color, label=label)
            bad = [r for r in sel if r["status"] == "failed"]
            if bad:
                shift = 0.02 * (list(styles).index((arr, mu_c)) - 1.5)     # failures side by side, not on top
                axes[0].plot([r["ratio"] + shift for r in bad], [1.0] * len(bad), "x", color=color, ms=9,
                             label=f"{label}: failed to solve")
    keys = [r for r in rows if r["arrangement"] == "keystone" and r["status"] != "failed"]
    if keys:
        axes[1].plot([r["ratio"] for r in keys], [r["wedge_factor"] for r in keys], "k*", ms=10,
                     label="keystone start, straight: where the solve ends")
    grid = np.linspace(2.45, 3.55, 221)
    ks = [keystone(r, 1.0, math.pi / 2).contact_force_per_load[0] if 2.415 <= r < 3.0 else np.nan for r in grid]
    axes[1].plot(grid, ks, "k--", lw=1, label="keystone across the duct, d/(2h)")
    axes[1].plot(grid, 2.0 / (grid - 1.0), "k:", lw=1, label="cradle, 2x")
    axes[1].set_ylim(0, 9)
    need = [keystone_friction_needed(r, 1.0) for r in grid]
    axes[2].plot(grid, need, "k-", label="least wall friction holding a keystone across")
    for mu_s, c in ((0.3, "C0"), (0.5, "C1"), (1.0, "C2")):
        lo, hi = wedge_band_d_over_D(mu_s, 0.05)
        if lo is not None:
            axes[2].axvspan(lo, hi, color=c, alpha=0.12, label=f"μ_s {mu_s:g}, 5 % ovality: {lo:.2f}-{hi:.2f}")
    axes[2].axvspan(2.8, 3.2, fill=False, hatch="//", ec="0.5", label="NEC jam range 2.8-3.2")
    stopped = [r for r in record.get("stopped", []) if r.get("hold_s") is None]
    zoom = np.linspace(2.88, 3.08, 401)
    axes[3].plot(zoom, [keystone_friction_needed(r, 1.0) for r in zoom], "k-",
                 label="statics: least wall friction holding a keystone across")
    for held, marker, text in ((True, "*", "simulated, pull stopped: keystone stands (status jam)"),
                               (False, "x", "simulated, pull stopped: drops to the triangle (no jam)")):
        sel = [r for r in stopped if r["jam"] == held]
        if sel:
            axes[3].plot([r["ratio"] for r in sel], [MU if r["static_friction"] is None else r["static_friction"]
                                                     for r in sel], marker, color="C3" if held else "C0",
                         ms=12 if held else 9, ls="none", label=text)
    held = [r for r in stopped if r["jam"] and r["static_friction"] is not None]
    if held:
        axes[1].plot([r["ratio"] for r in held], [r["contact_factor"] for r in held], "*", color="C3", ms=10,
                     label="keystone held still (dynamic, μ_s 0.5): middle cable's contact / weight")
    axes[3].set_xlim(2.88, 3.08)
    axes[3].set_ylim(0, 1.0)
    axes[3].set_ylabel("wall friction coefficient [-] (μ 0.3, or μ_s 0.5)")
    axes[3].set_title("keystone laid, pull standing still:\nsimulated vs statics")
    axes[2].set_ylim(0, 1.5)
    axes[0].set_ylabel("bundle's pull / calculators' 3·rope(μ w_c) [-]")
    axes[0].set_title("pull out of a 90° bend, R 2 m, gravity")
    axes[1].set_ylabel("cable-cable force / lateral load, per length [-]")
    axes[1].set_title("wedge factor: simulated (largest) vs rigid circles")
    axes[2].set_ylabel("friction coefficient in the cross-section [-]")
    axes[2].set_title("keystone statics: when friction holds a wedge")
    for ax in axes:
        ax.set_xlabel("D/d [-]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=6, loc="upper left" if ax is axes[1] else "best")
    axes[0].axhline(1.0, color="k", lw=0.5)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)     # atomic: a reader never sees half a PNG


def print_record(record) -> None:
    print(f"{'start':10} {'μ_c':>4} {'bend':>5} {'D/d':>5} {'status':>7} {'F [N]':>8} {'F/formula':>9} "
          f"{'wedge':>6} {'CPU [s]':>7}  arrangement per section; shares [N]")
    for r in record["cases"]:
        head = f"{r['arrangement']:10} {r['cable_friction']:4.2g} {r['turn']:>5} {r['ratio']:5.2f} {r['status']:>7}"
        if r["status"] in ("failed", "refused"):
            print(head + "  " + r["message"][:150])
            continue
        arr = " / ".join(s["arrangement"] + ("(JAM)" if s["jam"] else "") for s in r["sections"])
        print(head + f" {r['pull_force_N']:8.2f} {r['pull_vs_formula']:9.4f} {r['wedge_factor']:6.3f} {r['cpu_s']:7.1f}  "
              f"{arr}; " + " ".join(f"{x:.1f}" for x in r["shares_N"]))
    if record.get("stopped"):
        print("\nkeystone laid, pull standing still (dynamic, 2 m straight, gravity): D/d, wall μ, friction the statics "
              "need, laid -> final angle, status, arrangement, middle cable's contact force / weight (keystone G/p)")
        for r in record["stopped"]:
            mu = MU if r["static_friction"] is None else r["static_friction"]
            kg = "-" if r["keystone_G_per_p"] is None else f"{r['keystone_G_per_p']:.3f}"
            line = (f"  {r['ratio']:5.2f}  μ {'' if r['static_friction'] is None else 's '}{mu:.2g}  needs {r['friction_needed']:.3f} "
                    f"({'holds' if r['statics_holds'] else 'drops'})  ψ {r['psi_laid_deg']:.1f} -> {r['psi_end_deg']:.1f}°  "
                    f"{r['status']:>10}  {'/'.join(r['arrangements_seen'])}  {r['contact_factor']:.3f} ({kg})  CPU {r['cpu_s']:.1f} s")
            if r.get("hold_s") is not None:
                line += (f"\n      pulled on after {r['hold_s']:g} s: held {r['held_pull_N']:.2f} N, restart peak "
                         f"{r['restart_peak_N']:.2f} N at {r['restart_peak_s']:.3f} s, then {r['final_pull_N']:.2f} N")
            print(line)
    print("\nrigid circles: D/d, least wall friction holding a keystone across the duct, wedge factors "
          "(cradle 2x, keystone across d/(2h))")
    for r in record["statics"]:
        ka = "-" if r["keystone_across"] is None else f"{r['keystone_across']:.3f}"
        print(f"  {r['ratio']:5.3f}  μ_needed {r['friction_needed_across']:.3f}  cradle {r['cradled']:.3f}  keystone {ka}")
    for b in record["bands"]:
        lo = "-" if b["round"][0] is None else f"{b['round'][0]:.3f}"
        lo5 = "-" if b["oval"][0] is None else f"{b['oval'][0]:.3f}"
        print(f"  keystone held by μ_s {b['friction']:g}: D/d {lo}-{b['round'][1]:.3f} round; "
              f"{lo5}-{b['oval'][1]:.3f} with 5 % ovality")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--ratios", type=float, nargs="+", default=[2.6, 2.9, 3.1, 3.4])
    p.add_argument("--arrangements", nargs="+", default=["cradled", "triangular"])
    p.add_argument("--cable-friction", type=float, nargs="+", default=[0.0, 0.3],
                   help="μ_c between the cables; those > 0 at --friction-ratios only")
    p.add_argument("--friction-ratios", type=float, nargs="*", default=[2.9])
    p.add_argument("--up-ratios", type=float, nargs="*", default=[2.9],
                   help="D/d of the cradled up-bend cases (a failing solve spends its minute of CPU)")
    p.add_argument("--keystone-ratios", type=float, nargs="*", default=[2.9, 3.05],
                   help="D/d of the keystone starts in a straight with gravity")
    p.add_argument("--stopped-ratios", type=float, nargs="*", default=[2.9, 2.95, 2.97, 2.98, 2.99, 3.05],
                   help="D/d of the keystones laid with the pull standing still (dynamic), μ 0.3 and μ_s 0.5 each")
    p.add_argument("--restart-ratio", type=float, nargs="*", default=[2.98],
                   help="D/d of a held keystone (μ_s 0.5) pulled on after 0.3 s")
    p.add_argument("--record", help="write the record here (JSON)")
    p.add_argument("--figure", help="write the figure here (PNG)")
    p.add_argument("--from-json", help="print (and draw) a stored record instead of running")
    p.add_argument("--quick", action="store_true", help="one case: cradled, D/d 2.9, frictionless, horizontal")
    args = p.parse_args(argv)
    if args.from_json:
        record = json.loads(Path(args.from_json).read_text())
    else:
        if args.quick:
            args.ratios, args.arrangements, args.cable_friction = [2.9], ["cradled"], [0.0]
            args.up_ratios, args.keystone_ratios = [], []
            args.stopped_ratios, args.restart_ratio = [2.98], []
        cases = []
        for arrangement, ratio, mu_c, turn in case_plan(args):
            cases.append(one_case(arrangement, ratio, mu_c, turn))
            print(f"  done: {arrangement} μ_c {mu_c:g} {turn} D/d {ratio:g}: {cases[-1]['status']}", flush=True)
        statics = statics_table([2.5, 2.6, 2.8, 2.9, 2.95, 2.97, 2.98, 2.99, 2.995])
        bands = [{"friction": mu, "round": list(wedge_band_d_over_D(mu)), "oval": list(wedge_band_d_over_D(mu, 0.05))}
                 for mu in (0.3, 0.5, 1.0)]
        stopped = []
        for ratio in args.stopped_ratios:
            for mu_s in ((MU_S,) if args.quick else (None, MU_S)):
                stopped.append(stopped_case(ratio, mu_s))
                print(f"  done: keystone held still, D/d {ratio:g}, μ_s {mu_s}: {stopped[-1]['status']}", flush=True)
        for ratio in args.restart_ratio:
            stopped.append(stopped_case(ratio, MU_S, hold_s=0.3, end_s=0.8))
            print(f"  done: keystone held 0.3 s and pulled on, D/d {ratio:g}: {stopped[-1]['status']}", flush=True)
        record = {"cases": cases, "statics": statics, "bands": bands, "stopped": stopped}
        if args.record:
            atomic_write_text(Path(args.record), json.dumps(record, indent=1) + "\n")
    print_record(record)
    if args.figure:
        figure(record, args.figure)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
