"""Bending stiffness at a bend, predicted and measured.

exucable's pulling force against the rope with clearance (the EJ → 0 limit, `exucable.quasistatic.clearance`)
on single bends, sweeping the bending length √(EJ/T_in)/R (T_in the rope's tension entering the
bend), set beside the stiff-bend model `exucable.quasistatic.stiff_bend.stiff_bend` (the elastica landing on the
bend's wall with a point load and its friction; derivation in reference/README.md). Also the bend-end
point loads of `exucable.post.pressure` against the model's T sin ψ_e and their places.

Each exucable run is a steady-mode solve (`solver.mode = "steady"`: no start-up vibration, no
scatter), with elements of at most λ/3 and check points at most λ/8 apart. The cases are those of
`rope_difference_study.py` (`tight`: R 0.5 m, 15 mm clearance, 18 mm cable, μ 0.5, 100 N back
tension; `hbend`, `upbend`, `downbend`); the model's exit is held on the rope's line where the
rig holds the cable's head, the exit straight's length beyond the bend. With gravity the estimate
also gets the gravity term of the beam-in-conduit model (`exucable.quasistatic.beam`): the stiff cable
crossing the floor's trough to a horizontal bend's inner wall, or held by its weight on a
down-bend's floor, which the in-plane stiff bend lacks.

    nice .venv/bin/python studies/bending_stiffness_study.py --json reference/bending_stiffness_study.json \\
        --figure reference/bending_stiffness.png                            # ~10 min on 2 loaded cores
    nice .venv/bin/python studies/bending_stiffness_study.py --case tight --ej 1.0 --refine
    nice .venv/bin/python studies/bending_stiffness_study.py --quick    # smoke run: one row, tight, EJ 4
    nice .venv/bin/python studies/bending_stiffness_study.py --from-json reference/bending_stiffness_study.json
    nice .venv/bin/python studies/bending_stiffness_study.py --from-json reference/bending_stiffness_study.json \\
        --gravity-terms --figure reference/bending_stiffness.png        # add the beam model's gravity terms

Prints a Markdown table.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from rope_difference_study import CASES, G, add_case_arguments, scenario_dict  # noqa: E402

# (case, gravity, clearance [m], EJ [N m²]); tight: EJ = 25 (λ_in/R)² at T_in = 100 N
SWEEP = [
    ("tight", False, 0.015, 0.0225), ("tight", False, 0.015, 0.09), ("tight", False, 0.015, 0.25),
    ("tight", False, 0.015, 0.5625), ("tight", False, 0.015, 1.0), ("tight", False, 0.015, 1.5625),
    ("tight", False, 0.015, 2.25), ("tight", False, 0.015, 4.0),
    ("hbend", False, 0.0084, 0.79), ("hbend", False, 0.0084, 7.9),
    ("tight", True, 0.015, 0.0225), ("tight", True, 0.015, 0.25), ("tight", True, 0.015, 1.0),
    ("tight", True, 0.015, 2.25),
    ("hbend", True, 0.0084, 0.079), ("hbend", True, 0.0084, 0.79), ("hbend", True, 0.0084, 7.9),
    ("upbend", True, 0.01, 0.079), ("upbend", True, 0.01, 0.79), ("upbend", True, 0.01, 7.9),
    ("upbend", True, 0.01, 25.0),
    ("downbend", True, 0.01, 0.079), ("downbend", True, 0.01, 0.79), ("downbend", True, 0.01, 7.9),
    ("downbend", True, 0.01, 25.0),
]


def bend_geometry(case: str) -> dict:
    """The case's bend: angle θ [rad], R [m], straights before/after [m], entry tension of the rope [N]."""
    c = CASES[case]
    i = next(k for k, p in enumerate(c["path"]) if "bend" in p)
    bend = c["path"][i]
    before, after = c["path"][i - 1]["straight"], c["path"][i + 1]["straight"]
    return {"theta_rad": math.radians(bend["bend"]), "R_m": bend["radius"], "before_m": before, "after_m": after}


def model_estimate(case: str, clearance_m: float, ej: float, tension_in_N: float, gravity: bool,
                   pull_force_N: float):
    """The estimate of exucable − rope with clearance [relative] and the stiff-bend model.

    The stiff-bend model (exit held at the rig, the exit straight's end) for the bend; on a
    vertical up-bend with gravity also the free spans' term (`free_span_stiffness_N`) at the
    entry (grown by e^{μθ}) and at the exit (at the tension leaving the bend: the pull less the
    exit straight's rope load).
    """
    from exucable.quasistatic.stiff_bend import free_span_stiffness_N, stiff_bend
    c = CASES[case]
    g = bend_geometry(case)
    mu, rho = c["friction"], g["R_m"] - clearance_m
    m = stiff_bend(tension_in_N, mu, g["theta_rad"], rho, ej, exit_held_m=g["after_m"])
    extra_N = 0.0
    if gravity and case == "upbend":
        w = c["mass_kg_per_m"] * G
        theta = g["theta_rad"]
        t_out = pull_force_N - w * (math.sin(theta) + mu * math.cos(theta)) * g["after_m"]
        extra_N = (free_span_stiffness_N(ej, mu, rho, clearance_m, w, tension_in_N) * math.exp(mu * theta)
                   + free_span_stiffness_N(ej, mu, rho, clearance_m, w * math.cos(theta), t_out))
    return m.vs_rope + extra_N / pull_force_N, m


def gravity_term(case: str, clearance_m: float, ej: float) -> float:
    """What gravity changes in the stiff cable's pull against the flexible one [relative], by the
    beam-in-conduit model (`exucable.quasistatic.beam.gravity_change_of_stiffness`: on a horizontal bend
    the 3D chain crossing the floor's trough to the inner wall; on a vertical bend the planar chain
    with its weight in the bend plane, held on a down-bend's floor, in free spans on an up-bend).
    Nodes λ/8 apart, 5–10 mm (finer, the 3D chain's Newton stalls at λ = h on the floor's contact
    kinks; the rows with λ < 4 cm, coarser than λ/8, have gravity terms of a few 0.001 percentage
    point)."""
    from exucable.quasistatic.beam import BeamConduitError, gravity_change_of_stiffness
    c = CASES[case]
    g = bend_geometry(case)
    w = c["mass_kg_per_m"] * G
    t_in = c["back_tension_N"] + c["friction"] * w * g["before_m"]
    h = min(0.01, max(0.005, math.sqrt(ej / t_in) / 8.0))
    try:
        return gravity_change_of_stiffness(c["path"], clearance_m, c["friction"], w, ej, c["back_tension_N"], h)
    except BeamConduitError:
        # the 3D chain's Newton can stall on the floor's contact kinks at a fine spacing: once at 2h
        return gravity_change_of_stiffness(c["path"], clearance_m, c["friction"], w, ej, c["back_tension_N"], 2 * h)


def add_gravity_terms(rows) -> None:
    """Add the beam model's gravity term and the estimate with it to each gravity row (in place):
    ``gravity_term_pct`` and ``gravity_estimate_pct`` = the stiff bend (held exit) + that term."""
    done = {}
    for r in rows:
        if not r["gravity"]:
            continue
        key = (r["case"], r["clearance_m"], r["EJ_N_m2"])
        if key not in done:
            done[key] = 100.0 * gravity_term(*key)
        g = bend_geometry(r["case"])
        c = CASES[r["case"]]
        t_in = c["back_tension_N"] + c["friction"] * c["mass_kg_per_m"] * G * g["before_m"]
        stiff, _ = model_estimate(r["case"], r["clearance_m"], r["EJ_N_m2"], t_in, False, r["rope_clearance_N"])
        r["gravity_term_pct"] = done[key]
        r["gravity_estimate_pct"] = 100.0 * stiff + done[key]
        r.pop("duct_estimate_pct", None)       # the retired linearised model's column


def run_one(case: str, gravity: bool, clearance_m: float, ej: float, refine: float = 1.0) -> dict:
    """One steady-mode run and the model's estimate; a row of the table."""
    from exucable.run import run_scenario
    from exucable.scenario.specs import parse_scenario

    c = CASES[case]
    g = bend_geometry(case)
    w = c["mass_kg_per_m"] * G if gravity else 0.0
    # the rope's tension entering the bend: back tension plus the entry straight's friction/lift
    # (the vertical cases' entry straight is level)
    t_in = c["back_tension_N"] + c["friction"] * w * g["before_m"]
    lam = math.sqrt(ej / t_in)
    # λ/3 resolves the lift-off; no finer than 25 mm (the smallest EJ are baselines: their point
    # loads are then not resolved, their pulling force is)
    element_length = max(min(0.1, lam / 3.0), 0.025) / refine
    check_spacing = min(0.005, lam / 8.0) / refine
    d = scenario_dict(case, clearance_m, ej, gravity, element_length, check_spacing, 1.0)
    d["solver"]["mode"] = "steady"
    sc = parse_scenario(d, ROOT, default_name=d["name"])
    t0 = time.perf_counter()
    res = run_scenario(sc, None, quiet=True, plots=False)
    wall = time.perf_counter() - t0
    s = res.summary
    F, clear = s["pull_force_N"], s["rope_clearance_pull_force_N"]
    estimate, m = model_estimate(case, clearance_m, ej, t_in, gravity, clear)
    b = s["bends"][0]
    rho = g["R_m"] - clearance_m
    s0 = g["before_m"]
    s1 = s0 + g["theta_rad"] * g["R_m"]
    row = {"case": case, "gravity": gravity, "clearance_m": clearance_m, "EJ_N_m2": ej, "refine": refine,
            "lambda_in_over_R": lam / g["R_m"], "offset_over_2c": max(m.entry_offset_m, m.exit_offset_m) / (2 * clearance_m),
            "model_fits": m.fits(clearance_m), "elements": sc.cable.elements,
            "check_points_per_element": sc.contact.check_points_per_element, "status": s["status"],
            "pull_force_N": F, "rope_clearance_N": clear, "rope_N": s["rope_pull_force_N"],
            "vs_rope_clearance_pct": 100 * (F / clear - 1), "model_pct": 100 * estimate,
            "entry_point_load_N": b["entry_point_load_N"], "model_entry_point_load_N": m.entry_point_load_N,
            "exit_point_load_N": b["exit_point_load_N"], "model_exit_point_load_N": m.exit_point_load_N,
            # the places as distances into the bend along the conduit's centreline [m]
            "entry_edge_m": b["entry_s_conduit_m"] - s0, "model_entry_edge_m": m.entry_edge_m * g["R_m"] / rho,
            "exit_edge_m": s1 - b["exit_s_conduit_m"], "model_exit_edge_m": m.exit_edge_m * g["R_m"] / rho,
            "wall_s": wall}
    add_gravity_terms([row])
    return row


HEADER = ("| case | gravity | c [mm] | EJ [N m²] | √(EJ/T_in)/R | lift-off / 2c | mesh | exucable [N] | "
          "rope with clearance [N] | exucable − it | model | model + beam gravity term | entry P [N] (model) | exit P [N] (model) | "
          "entry edge [mm] (model) | wall [s] |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")


def print_row(r: dict) -> None:
    fit = "" if r["model_fits"] else " (model invalid)"
    print(f"| {r['case']} | {'yes' if r['gravity'] else 'no'} | {r['clearance_m'] * 1e3:g} | {r['EJ_N_m2']:g} | "
          f"{r['lambda_in_over_R']:.3g} | {r['offset_over_2c']:.2f} | {r['elements']}×{r['check_points_per_element']} | "
          f"{r['pull_force_N']:.3f} | {r['rope_clearance_N']:.3f} | {r['vs_rope_clearance_pct']:+.3f} % | "
          f"{r['model_pct']:+.3f} %{fit} | {_with_gravity(r)} | "
          f"{r['entry_point_load_N']:.2f} ({r['model_entry_point_load_N']:.2f}) | "
          f"{r['exit_point_load_N']:.2f} ({r['model_exit_point_load_N']:.2f}) | "
          f"{1e3 * r['entry_edge_m']:.0f} ({1e3 * r['model_entry_edge_m']:.0f}) | {r['wall_s']:.0f} |", flush=True)


def by_case(rows) -> list[list[dict]]:
    """The rows grouped per case (case, gravity, clearance, EJ) in the sweep's order, each group by mesh
    (the study's mesh first, then the refined one)."""
    keys = []
    for r in rows:
        k = (r["case"], r["gravity"], r["clearance_m"], r["EJ_N_m2"])
        if k not in keys:
            keys.append(k)
    return [sorted((r for r in rows if (r["case"], r["gravity"], r["clearance_m"], r["EJ_N_m2"]) == k),
                   key=lambda r: r["refine"]) for k in keys]


def mesh_table(rows) -> str:
    """The mesh check of every case: the study's mesh against the refined one (pulling force of
    each, their difference, bound 0.2 %) and the wall time of each solve."""
    out = ["| case | gravity | c [mm] | EJ [N m²] | meshes (elements × check points) | pulling force per mesh [N] | "
           "study mesh vs refined | wall per mesh [s] |", "|---|---|---|---|---|---|---|---|"]
    for rs in by_case(rows):
        r0, r1 = rs[0], rs[-1]
        meshes = " / ".join(f"{r['elements']}×{r['check_points_per_element']}" for r in rs)
        forces = " / ".join(f"{r['pull_force_N']:.3f}" for r in rs)
        walls = " / ".join(f"{r['wall_s']:.1f}" for r in rs)
        diff = "–" if len(rs) < 2 else f"{100 * (r0['pull_force_N'] / r1['pull_force_N'] - 1):+.4f} %"
        out.append(f"| {r0['case']} | {'yes' if r0['gravity'] else 'no'} | {r0['clearance_m'] * 1e3:g} | "
                   f"{r0['EJ_N_m2']:g} | {meshes} | {forces} | {diff} | {walls} |")
    return "\n".join(out)


def _with_gravity(r: dict) -> str:
    """The estimate with the beam model's gravity term, or "–" (no gravity: the stiff bend alone)."""
    return f"{r['gravity_estimate_pct']:+.3f} %" if "gravity_estimate_pct" in r else "–"


def readme_table(rows) -> str:
    """One line per case: both meshes' values side by side (reference/README.md)."""
    out = ["| case | gravity | c [mm] | EJ [N m²] | λ_in/R | lift-off/2c | meshes | exucable − rope with clearance | "
           "estimate | estimate + beam gravity term | entry P [N] (model) | exit P [N] (model) | "
           "entry place [mm into the bend] (model) |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for rs in by_case(rows):
        r0 = rs[0]
        k = (r0["case"], r0["gravity"], r0["clearance_m"], r0["EJ_N_m2"])
        both = lambda f: " / ".join(f(r) for r in rs)  # noqa: E731
        est = f"{r0['model_pct']:+.3f} %" + ("" if r0["model_fits"] else " (invalid: lift-off > 2c)")
        out.append(f"| {k[0]} | {'yes' if k[1] else 'no'} | {k[2] * 1e3:g} | {k[3]:g} | {r0['lambda_in_over_R']:.3g} | "
                   f"{r0['offset_over_2c']:.2f} | {both(lambda r: str(r['elements']))} | "
                   f"{both(lambda r: format(r['vs_rope_clearance_pct'], '+.3f'))} % | {est} | {_with_gravity(r0)} | "
                   f"{both(lambda r: format(r['entry_point_load_N'], '.2f'))} ({r0['model_entry_point_load_N']:.2f}) | "
                   f"{both(lambda r: format(r['exit_point_load_N'], '.2f'))} ({r0['model_exit_point_load_N']:.2f}) | "
                   f"{both(lambda r: format(1e3 * r['entry_edge_m'], '.0f'))} ({1e3 * r0['model_entry_edge_m']:.0f}) |")
    return "\n".join(out)


def plot(rows, path) -> None:
    """Measured exucable − rope with clearance against the model, and the point loads against T sin ψ_e."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
    styles = {("tight", False): ("o", "C0"), ("hbend", False): ("D", "C4"), ("tight", True): ("s", "C1"),
              ("hbend", True): ("P", "C5"), ("upbend", True): ("^", "C2"), ("downbend", True): ("v", "C3")}
    for (case, grav), (marker, colour) in styles.items():
        sel = sorted((r for r in rows if r["case"] == case and r["gravity"] == grav and r["refine"] == 1.0),
                     key=lambda r: r["lambda_in_over_R"])
        if not sel:
            continue
        x = [r["lambda_in_over_R"] for r in sel]
        label = f"{case}{' + gravity' if grav else ''}"
        axes[0].plot(x, [r["vs_rope_clearance_pct"] for r in sel], marker=marker, color=colour, ls="none",
                     ms=7, label=f"exucable, {label}")
        valid = [r for r in sel if r["model_fits"]]       # the model's assumptions hold (lift-off ≤ 2c)
        axes[0].plot([r["lambda_in_over_R"] for r in valid], [r["model_pct"] for r in valid], color=colour, ls=":",
                     label=f"estimate, {label}")
        grav = [r for r in valid if "gravity_estimate_pct" in r]   # with the beam model's gravity term
        if grav:
            axes[0].plot([r["lambda_in_over_R"] for r in grav], [r["gravity_estimate_pct"] for r in grav],
                         color=colour, ls="--", label=f"estimate + beam gravity term, {label}")
        for key, fill in (("entry", True), ("exit", False)):
            axes[1].plot([r[f"model_{key}_point_load_N"] for r in sel], [r[f"{key}_point_load_N"] for r in sel],
                         marker=marker, color=colour, ls="none", mfc=colour if fill else "none",
                         label=f"{label}, {key}")
    top = max(max(r["model_exit_point_load_N"], r["exit_point_load_N"]) for r in rows)
    axes[1].plot([0, top], [0, top], "k-", lw=0.7, label="equal")
    axes[1].plot([0, top], [0, 1.1 * top], "k:", lw=0.5)
    axes[1].plot([0, top], [0, 0.9 * top], "k:", lw=0.5, label="±10 %")
    axes[0].set_xlabel("bending length √(EJ/T_in) / R")
    axes[0].set_ylabel("exucable − rope with clearance [%]")
    axes[0].set_title("pulling force: steady solves (points), estimate where valid (lines)")
    axes[1].set_xlabel("model T sin ψ_e [N]")
    axes[1].set_ylabel("exucable's bend-end point load [N]")
    axes[1].set_title("point loads (filled: entry, open: exit)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    axes[0].axhline(0.0, color="k", lw=0.5)
    fig.tight_layout()
    from exucable.io import save_figure

    save_figure(fig, path, dpi=110)     # atomic: a reader never sees half a PNG


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_case_arguments(p)           # --clearance defaults to the sweep's for the case
    p.add_argument("--gravity", action="store_true")
    p.add_argument("--mass", type=float, help="the case's cable mass per length [kg/m] (default: the case's)")
    p.add_argument("--refine", action="store_true", help="also run each row at half the element length")
    p.add_argument("--cases", help="only these cases of the sweep (comma-separated)")
    p.add_argument("--json", help="write the rows to this JSON file (rewritten after each row)")
    p.add_argument("--from-json", help="print (and plot) the rows of this JSON file instead of running")
    p.add_argument("--figure", help="plot the rows to this PNG")
    p.add_argument("--gravity-terms", action="store_true",
                   help="with --from-json: (re)compute the beam model's gravity term of every gravity row and "
                        "rewrite the JSON (no exucable runs)")
    p.add_argument("--mesh-report", action="store_true",
                   help="with --from-json: the mesh check of every case (pulling force and wall time per mesh)")
    p.add_argument("--quick", action="store_true",
                   help="smoke run: one row of the sweep (tight, no gravity, EJ 4 N m², the coarsest mesh)")
    a = p.parse_args(argv)
    if a.quick and not a.from_json:
        a.case, a.gravity, a.ej = "tight", False, 4.0
    if a.mass is not None and a.case:
        CASES[a.case]["mass_kg_per_m"] = a.mass
    if a.from_json:
        rows = json.loads(Path(a.from_json).read_text())
        if a.gravity_terms:
            add_gravity_terms(rows)
            tmp = Path(a.from_json + ".tmp")
            tmp.write_text(json.dumps(rows, indent=1))
            tmp.replace(a.from_json)
        print(mesh_table(rows) if a.mesh_report else readme_table(rows))
    else:
        if a.case:
            c = a.clearance if a.clearance is not None else next(x[2] for x in SWEEP if x[0] == a.case)
            plan = [(a.case, a.gravity, c, a.ej)]
        else:
            plan = [x for x in SWEEP if not a.cases or x[0] in a.cases.split(",")]
        print(HEADER)
        rows = []
        for case, grav, c, ej in plan:
            for refine in ((1.0, 2.0) if a.refine else (1.0,)):
                r = run_one(case, grav, c, ej, refine)
                rows.append(r)
                print_row(r)
                if a.json:
                    tmp = Path(a.json + ".tmp")
                    tmp.write_text(json.dumps(rows, indent=1))
                    tmp.replace(a.json)
    if a.figure:
        plot(rows, a.figure)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
