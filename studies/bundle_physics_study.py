"""Three cables in one duct, what the calculators' formulas miss: cable–cable friction and vertical bends with gravity.

Two parts, steady mode, cable d = 30 mm, 2000 kg/m³ (w = 13.9 N/m per cable), E 2e8 Pa, EJ 1 N m², wall
friction μ 0.3, pull speed V 0.1 m/s; every figure measured in this one run.

**Cable–cable friction** (``contact.cable_friction`` μ_c 0 → 0.5), on (i) a horizontal 4 m straight with
gravity, back tension 30 N, and (ii) the 90° horizontal bend of 2 m radius of the bend study (no
gravity, each cable entering with 100 N). Per case the pull force, each cable's share and the straight's
weight correction factor, beside a small model: the rigid-circle statics of the cross-section
(exucable/quasistatic/bundle_bend.py; the same statics with the weight as the load on a straight) with the
contact law's regularised Coulomb friction at the cable–cable contacts. In steady sliding the cables slide
over each other only by the difference of their stretch: the kernel moves every cable's material at the
pull speed, U = V ∂r/∂x, so the relative slip of two touching cables is Δv = V (T_a − T_b)/EA and the
friction is μ_c F Δv/√(Δv² + ε²) (ε the regularisation velocity). The model integrates

    dT_i = μ N_i + Σ_j μ_c F_ij g(T_i − T_j),   g(ΔT) = (VΔT/EA)/√((VΔT/EA)² + ε²),

along the straight (per metre, N and F from the weight) or round the bend (per radian, N and F from
the tensions), from equal entry tensions. ``--coulomb`` also prints its Coulomb limit g = sign(ΔT).

**Vertical bends with gravity**: a 60° bend of 5 m radius turning up (the foot of a rise) or down (a
crest) between a 3 m and a 2 m straight, three cables (cradled D/d 3.3, triangular D/d 2.8), 200 N
back tension per cable (an up-bend's bundle lifted onto the upper wall) or 20 N (left on the bottom),
21 elements of 0.49 m with 8 check points each, a solve stopped after 20 s CPU, against the calculators' formula: each cable the rope equation with weight
(exucable/quasistatic/rope.py, the closed forms of exucable/quasistatic/closed_forms.py) at μ·w_c, times
three. A case that does not solve is printed with its status and message; two cables are run too, as
the fallback where three do not converge.

    nice .venv/bin/python studies/bundle_physics_study.py [--figure reference/bundle_physics.png] [--quick]

The record and its reading: reference/README.md, "Three cables: cable–cable friction and vertical bends".
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import exucable as xc
from exucable.errors import ExucableError
from exucable.io import save_figure
from exucable.model.bundle import build_bundle_model, bundle_report, bundle_sections
from exucable.quasistatic import engineering as eng
from exucable.solve.steady import solve_steady

D_CABLE, MU, EJ, SPEED = 0.03, 0.3, 1.0, 0.1
FRICTIONS = (0.0, 0.1, 0.3, 0.5)
#: CPU limit of one vertical-bend solve [s]: a case that stalls says so sooner than the default 60 s.
VERTICAL_CPU_LIMIT_S = 20.0


def _cable(arrangement, count=3, elements=None, **extra):
    c = dict(radius=D_CABLE / 2, density=2000.0, youngs_modulus=2e8, bending_stiffness=EJ, count=count,
             arrangement=arrangement, **extra)
    if elements is not None:
        c["elements"] = elements
    return xc.Cable(**c)


def straight_scenario(arrangement, ratio, cable_friction, coarse):
    return xc.Scenario(route=xc.Route(inner_radius=ratio * D_CABLE / 2).straight(4.0),
                       cable=_cable(arrangement, elements=8 if coarse else None),
                       contact=xc.Contact(friction=MU, cable_friction=cable_friction,
                                          check_points_per_element=8 if coarse else None),
                       pull=xc.Pull(speed=SPEED, back_tension=30.0), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", end_time=1.0, steady_lead_out=0.0))


def bend_scenario(arrangement, ratio, cable_friction, coarse):
    route = xc.Route(inner_radius=ratio * D_CABLE / 2).straight(0.5).bend(90, radius=2.0, turn="left").straight(0.5)
    return xc.Scenario(route=route, cable=_cable(arrangement, elements=16 if coarse else None),
                       contact=xc.Contact(friction=MU, cable_friction=cable_friction,
                                          check_points_per_element=16 if coarse else None),
                       pull=xc.Pull(speed=SPEED, back_tension=300.0),
                       solver=xc.Solver(mode="steady", end_time=1.0, steady_lead_out=0.0))


def vertical_scenario(turn, arrangement, ratio, count, back_per_cable=200.0):
    """A given mesh: 21 elements of 0.49 m (the rule's 11 about halved), 8 check points each."""
    route = (xc.Route(inner_radius=ratio * D_CABLE / 2).straight(3.0).bend(60, radius=5.0, turn=turn)
             .straight(2.0))
    return xc.Scenario(route=route, cable=_cable(arrangement, count=count, elements=21),
                       contact=xc.Contact(friction=MU, check_points_per_element=8),
                       pull=xc.Pull(speed=SPEED, back_tension=back_per_cable * count), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", end_time=1.0, steady_lead_out=0.0,
                                        steady_time_limit=VERTICAL_CPU_LIMIT_S))


def solve(sc):
    """(model or None, status, message, CPU [s])."""
    t0 = time.process_time()
    try:
        model = build_bundle_model(sc)
        out = solve_steady(model)
    except ExucableError as exc:
        return None, "refused", str(exc), time.process_time() - t0
    return model, out.status, out.message, time.process_time() - t0


# ---- the small model: rigid circles with the contact law's friction between the cables -----------------

def friction_model(place, arrangement, ratio, mu_c, *, w=0.0, T0=0.0, length=1.0, EA=1.0, V=SPEED, eps=1e-3,
                   coulomb=False):
    """Each cable's exit tension [N] of the rigid-circle cross-section with friction between the cables.

    ``place`` "straight": per metre over ``length`` [m], loads from the weight ``w`` [N/m] (cradled:
    N_side = w, F = 2xw side–middle, N_middle = (1 + 4x²)w; triangular: F = w/√3 top–bottom,
    N_bottom = 1.5w/√(1 − x²)); "bend": per radian over ``length`` [rad], the same with each cable's own
    tension as its load (bundle_bend.py's statics). x = d/(D − d). Entry tensions ``T0`` each.
    Returns the tensions in the order of exucable.model.bundle.arrangement_offsets.
    """
    x = 1.0 / (ratio - 1.0)
    c = math.sqrt(1.0 - x * x)

    def g(dT):
        if coulomb:
            return float(np.sign(dT))
        dv = V * dT / EA
        return dv / math.hypot(dv, eps)

    def rhs(_t, y):
        a, b = y      # cradled: (side, middle); triangular: (bottom, top)
        if arrangement == "cradled":
            load_s, load_m = (w, w) if place == "straight" else (a, b)
            F = 2.0 * x * load_s
            Ns, Nm = load_s, load_m + 4.0 * x * x * load_s
            f = mu_c * F * g(b - a)
            return [MU * Ns - f, MU * Nm + 2.0 * f]
        load_b, load_t = (w, w) if place == "straight" else (a, b)
        F = load_t / math.sqrt(3.0)
        Nb = (load_b + 0.5 * load_t) / c
        f = mu_c * F * g(a - b)
        return [MU * Nb + f, -2.0 * f]

    sol = solve_ivp(rhs, (0.0, length), [T0, T0], rtol=1e-10, atol=1e-10)
    a, b = sol.y[:, -1]
    return np.array([a, b, a]) if arrangement == "cradled" else np.array([a, a, b])


def friction_part(cases, coarse, coulomb):
    print("\n## Cable–cable friction\n")
    print("| place | arrangement | D/d | μ_c | status | pull [N] | Δpull vs μ_c 0 [N] | shares [N] | Δshares sim [N] "
          "| Δshares model [N] | w_c straight (formula) | CPU [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    for place, arrangement, ratio in cases:
        base = None
        for mu_c in FRICTIONS:
            sc = (straight_scenario if place == "straight" else bend_scenario)(arrangement, ratio, mu_c, coarse)
            model, status, msg, cpu = solve(sc)
            row = dict(place=place, arrangement=arrangement, ratio=ratio, mu_c=mu_c, status=status, cpu=cpu)
            rows.append(row)
            if status != "ok":
                print(f"| {place} | {arrangement} | {ratio:g} | {mu_c:g} | {status}: {msg} | | | | | | | {cpu:.1f} |",
                      flush=True)
                continue
            rep = bundle_report(model)
            shares = np.array([c["pull_share_N"] for c in rep["cables"]])
            ct, cb = sc.contact, sc.cable
            kw = dict(EA=cb.axial_stiffness_N, V=sc.pull.speed_m_per_s, eps=ct.friction_regularisation_velocity_m_per_s)
            if place == "straight":
                w = cb.mass_per_length_kg_per_m * 9.81
                # the middle half of the straight, where the rigid-circle statics hold (away from the ends)
                ref = friction_model(place, arrangement, ratio, mu_c, w=w, T0=10.0, length=4.0, **kw)
                ref0 = friction_model(place, arrangement, ratio, 0.0, w=w, T0=10.0, length=4.0, **kw)
                wc = rep["straights"][0]["weight_correction_factor"]
            else:
                ref = friction_model(place, arrangement, ratio, mu_c, T0=100.0, length=math.pi / 2, **kw)
                ref0 = friction_model(place, arrangement, ratio, 0.0, T0=100.0, length=math.pi / 2, **kw)
                wc = None
            row.update(pull=float(shares.sum()), shares=shares, model=ref, model0=ref0, wc=wc)
            if base is None and mu_c == 0.0:
                base = row
            d_sim = shares - base["shares"] if base else np.full(3, np.nan)
            d_mod = ref - ref0
            row.update(d_sim=d_sim, d_model=d_mod, d_pull=float(shares.sum() - base["pull"]) if base else np.nan)
            wc_txt = "" if wc is None else f"{wc:.5f} ({eng.weight_correction_factor(3, arrangement, ratio * D_CABLE, D_CABLE):.5f})"
            print(f"| {place} | {arrangement} | {ratio:g} | {mu_c:g} | ok | {shares.sum():.3f} | {row['d_pull']:+.3f} | "
                  + " ".join(f"{s:.2f}" for s in shares) + " | " + " ".join(f"{s:+.3f}" for s in d_sim) + " | "
                  + " ".join(f"{s:+.3f}" for s in d_mod) + f" | {wc_txt} | {cpu:.1f} |", flush=True)
            if coulomb:
                kwc = dict(kw, coulomb=True)
                lim = (friction_model(place, arrangement, ratio, mu_c, w=cb.mass_per_length_kg_per_m * 9.81, T0=10.0,
                                      length=4.0, **kwc) if place == "straight"
                       else friction_model(place, arrangement, ratio, mu_c, T0=100.0, length=math.pi / 2, **kwc))
                print(f"|  | Coulomb limit of the model | | {mu_c:g} | | {lim.sum() - ref0.sum():+.3f} (Δ total) | | | | "
                      + " ".join(f"{s:+.3f}" for s in lim - ref0) + " | | |")
    return rows


def vertical_part(cases):
    print("\n## Vertical bends with gravity\n")
    print("| bend | cables | arrangement | D/d | back tension per cable [N] | status | pull [N] | formula n·rope(μ w_c) [N] | sim/formula | "
          "rope alone n·rope(μ) [N] | shares [N] | arrangement in the bend | CPU [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    for turn, count, arrangement, ratio, back in cases:
        sc = vertical_scenario(turn, arrangement, ratio, count, back)
        model, status, msg, cpu = solve(sc)
        row = dict(turn=turn, count=count, arrangement=arrangement, ratio=ratio, back=back, status=status, cpu=cpu,
                   message=msg)
        rows.append(row)
        if model is None or status != "ok":
            print(f"| {turn} | {count} | {arrangement} | {ratio:g} | {back:g} | {status}: {msg} | | | | | | | {cpu:.1f} |",
                  flush=True)
            continue
        rep = bundle_report(model)
        shares = np.array([c["pull_share_N"] for c in rep["cables"]])
        formula = count * model.rope.pull_force_N
        alone = count * model.rope_alone.pull_force_N
        found = [s for s in bundle_sections(model)["sections"] if s.get("kind") == "bend"]
        where = ", ".join(str(s.get("arrangement")) for s in found) or "-"
        row.update(pull=float(shares.sum()), formula=formula, alone=alone, shares=shares, found=where)
        print(f"| {turn} | {count} | {arrangement} | {ratio:g} | {back:g} | ok | {shares.sum():.2f} | {formula:.2f} | "
              f"{shares.sum() / formula:.4f} | {alone:.2f} | " + " ".join(f"{s:.1f}" for s in shares)
              + f" | {where} | {cpu:.1f} |", flush=True)
    return rows


def figure(frows, vrows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(13, 4.2))
    ax = axes[0]
    for (place, arrangement), col in zip(sorted({(r["place"], r["arrangement"]) for r in frows}), ("C0", "C1", "C2", "C3")):
        sel = [r for r in frows if r["place"] == place and r["arrangement"] == arrangement and "d_sim" in r]
        if not sel:
            continue
        k = 1                                       # the middle (cradled) or a bottom (triangular) cable
        mu = [r["mu_c"] for r in sel]
        ax.plot(mu, [r["d_sim"][k] for r in sel], "o-", color=col, label=f"{place}, {arrangement}: simulated")
        ax.plot(mu, [r["d_model"][k] for r in sel], "x--", color=col, label="  rigid circles + regularised friction")
        ax.plot(mu, [r["d_pull"] for r in sel], "s:", color=col, ms=4, label="  bundle's pull (simulated)")
    ax.set_xlabel("cable–cable friction μ_c [-]")
    ax.set_ylabel("change from μ_c = 0 [N]")
    ax.set_title("pull share of the most loaded cable")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=6.5)
    ax = axes[1]
    ok = [r for r in vrows if r["status"] == "ok"]
    labels = [f"{r['turn']} {r['back']:g} N\n{r['count']} {r['arrangement'][:4]}." for r in ok]
    ax.bar(range(len(ok)), [r["pull"] / r["formula"] for r in ok], color=["C2" if r["turn"] == "up" else "C3" for r in ok])
    for i, r in enumerate(ok):
        ax.plot(i, r["alone"] / r["formula"], "k_", ms=18)
    ax.set_xticks(range(len(ok)), labels, fontsize=7)
    ax.set_ylim(0.85, 1.02)
    ax.axhline(1.0, color="k", lw=0.5)
    ax.set_ylabel("pull / formula n·rope(μ w_c) [-]  (—: cables alone)")
    ax.set_title("60° vertical bend, R 5 m, gravity (back tension per cable)")
    ax.grid(True, axis="y", alpha=0.3)
    failed = [r for r in vrows if r["status"] != "ok"]
    if failed:
        ax.text(1.02, 0.5, "not solved:\n" + "\n".join(f"{r['turn']} {r['back']:g} N, {r['count']} {r['arrangement']}: "
                                                      f"{r['status']}" for r in failed),
                transform=ax.transAxes, fontsize=7, va="center")
    fig.tight_layout()
    save_figure(fig, path, dpi=110)     # atomic: a reader never sees half a PNG


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--figure", help="write the figure here (PNG)")
    p.add_argument("--coarse", action="store_true", help="cable–cable friction on the unit tests' coarse meshes "
                   "instead of the mesh rule")
    p.add_argument("--json", help="write the rows here (the study's record)")
    p.add_argument("--from-json", help="draw --figure from a record written by --json instead of running")
    p.add_argument("--coulomb", action="store_true", help="also print the small model's Coulomb limit")
    p.add_argument("--part", choices=("friction", "vertical", "both"), default="both")
    p.add_argument("--quick", action="store_true", help="coarse, one friction case and one vertical bend (a smoke run)")
    args = p.parse_args(argv)
    fcases = [("straight", "cradled", 3.3), ("straight", "triangular", 2.8), ("bend", "cradled", 3.3),
              ("bend", "triangular", 2.8)]
    # 200 N per cable: T/R = 40 N/m against w = 13.9 N/m, the tension lifts an up-bend's bundle onto the
    # upper (inner) wall; 20 N: the weight keeps it on the bottom (outer) wall through the bend
    vcases = [("down", 3, "cradled", 3.3, 200.0), ("down", 3, "triangular", 2.8, 200.0),
              ("down", 2, "triangular", 3.3, 200.0), ("up", 3, "cradled", 3.3, 20.0),
              ("up", 3, "triangular", 2.8, 20.0), ("up", 2, "triangular", 3.3, 20.0),
              ("up", 3, "cradled", 3.3, 200.0), ("up", 2, "triangular", 3.3, 200.0)]
    global FRICTIONS
    if args.from_json:
        record = json.loads(Path(args.from_json).read_text())
        for r in record["friction"]:
            for k in ("d_sim", "d_model", "shares", "model", "model0"):
                if k in r:
                    r[k] = np.asarray(r[k])
        if args.figure:
            figure(record["friction"], record["vertical"], args.figure)
        return 0
    if args.quick:
        args.coarse, fcases, vcases, FRICTIONS = True, fcases[:1], vcases[:1], (0.0, 0.5)
    frows = friction_part(fcases, args.coarse, args.coulomb) if args.part in ("friction", "both") else []
    vrows = vertical_part(vcases) if args.part in ("vertical", "both") else []
    if args.json:
        from exucable.io import atomic_write_text

        def plain(v):
            return v.tolist() if isinstance(v, np.ndarray) else v
        atomic_write_text(args.json, json.dumps({"friction": [{k: plain(v) for k, v in r.items()} for r in frows],
                                                 "vertical": [{k: plain(v) for k, v in r.items()} for r in vrows]},
                                                indent=1) + "\n")
    if args.figure:
        figure(frows, vrows, args.figure)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
