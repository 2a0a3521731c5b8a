"""What separates exucable from the rope: bending stiffness and the clearance.

On single bends the pulling force of exucable is compared with two flexible references:
the centreline rope (``exucable.quasistatic.rope``: no bending stiffness, glued to the conduit's centreline)
and the rope with clearance (``exucable.quasistatic.clearance``: no bending stiffness, free to leave the
wall and hang in free spans across the clearance). The sweep varies the bending length
√(EJ/T) against the bend radius R (``cable.bending_stiffness``, at a fixed EA; the references do
not depend on it) and the clearance c against R, with and without gravity:

- ``hbend``: a horizontal 90° bend, R 3 m, between 2 m straights; an 18 mm fibre cable
  (0.21 kg/m, μ 0.5, 100 N back tension); without gravity and with it (then the cable rolls
  from the floor of the straights to the bend's inner side: a 3D path);
- ``upbend`` / ``downbend``: a 60° vertical bend, R 5 m, between a 5 m and a 3 m straight,
  a 1 kg/m cable (μ 0.3, 200 N back tension), gravity on.

Both references are evaluated for the cable's extent at the mean time of the averaging window
(``exucable.quasistatic.extent``: the cable leaves the conduit at the pull speed, so the length inside
shrinks and the part beyond the exit pulls along the exit line with its weight). Each exucable
run stops once steady (0.2 s window, 0.1 %); its scatter is the standard deviation there.

    nice .venv/bin/python studies/rope_difference_study.py            # the table (~15 min on 2 cores)
    nice .venv/bin/python studies/rope_difference_study.py --case upbend --clearance 0.01 --ej 7.9
    nice .venv/bin/python studies/rope_difference_study.py --figure reference/rope_difference.png
    nice .venv/bin/python studies/rope_difference_study.py --quick   # smoke run: the c → 0 table, one coarse row

Prints a Markdown table; ``--json FILE`` keeps the rows, ``--figure`` plots them.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

CABLE_RADIUS_M = 0.009
SPEED_M_PER_S = 0.2
# The fibre cable: EA = 1.3e5 N whatever EJ is (EJ is given on its own, as for a stranded
# cable; deriving it from E would make a low-EJ cable axially soft, and its axial mode, 4L/√(EA/ρA)
# ≈ 0.8 s with EJ = 0.079 N m² from E, then rang in the pulling force by ±0.5 %).
YOUNGS_MODULUS_PA = 5e8
G = 9.81

CASES = {
    "hbend": dict(path=[{"straight": 2.0}, {"bend": 90.0, "radius": 3.0, "turn": "left"}, {"straight": 2.0}],
                  mass_kg_per_m=0.21, friction=0.5, back_tension_N=100.0, radius_m=3.0),
    "upbend": dict(path=[{"straight": 5.0}, {"bend": 60.0, "radius": 5.0, "turn": "up"}, {"straight": 3.0}],
                   mass_kg_per_m=1.0, friction=0.3, back_tension_N=200.0, radius_m=5.0),
    "downbend": dict(path=[{"straight": 5.0}, {"bend": 60.0, "radius": 5.0, "turn": "down"}, {"straight": 3.0}],
                     mass_kg_per_m=1.0, friction=0.3, back_tension_N=200.0, radius_m=5.0),
    # a tight horizontal bend (R 0.5 m, about 28 cable diameters) where a bending length of up to
    # 0.3 R still lifts off less than the clearance: the bending-stiffness study's case
    "tight": dict(path=[{"straight": 2.0}, {"bend": 90.0, "radius": 0.5, "turn": "left"}, {"straight": 2.0}],
                  mass_kg_per_m=0.21, friction=0.5, back_tension_N=100.0, radius_m=0.5),
}


def scenario_dict(case: str, clearance_m: float, ej_N_m2: float, gravity: bool, element_length_m: float,
                  check_spacing_m: float, end_time_s: float) -> dict:
    c = CASES[case]
    r = CABLE_RADIUS_M
    area = math.pi * r * r
    length = sum(p.get("straight", 0.0) + math.radians(p.get("bend", 0.0)) * p.get("radius", 0.0) for p in c["path"])
    elements = int(math.ceil(length / element_length_m))
    d = {
        "name": f"{case}-c{clearance_m * 1e3:g}mm-EJ{ej_N_m2:g}{'-g' if gravity else ''}",
        "cable": {"radius": r, "density": c["mass_kg_per_m"] / area, "youngs_modulus": YOUNGS_MODULUS_PA,
                  "bending_stiffness": ej_N_m2, "elements": elements},
        "conduit": {"inner_radius": r + clearance_m, "path": c["path"]},
        "contact": {"friction": c["friction"],
                    "check_points_per_element": max(4, int(round(length / elements / check_spacing_m)))},
        "pull": {"speed": SPEED_M_PER_S, "back_tension": c["back_tension_N"]},
        "solver": {"end_time": end_time_s, "step": 1e-2, "steady_stop": True},
    }
    if gravity:
        d["gravity"] = {"g": G}
    return d


def run_one(case: str, clearance_m: float, ej_N_m2: float, gravity: bool, element_length_m: float = 0.1,
            check_spacing_m: float = 0.005, end_time_s: float = 1.0) -> dict:
    """One exucable run and both references at the cable's extent; a row of the table."""
    from exucable.model.build import pull_oriented_conduit
    from exucable.quasistatic.extent import pull_force_references_N
    from exucable.run import run_scenario
    from exucable.scenario.specs import parse_scenario

    data = scenario_dict(case, clearance_m, ej_N_m2, gravity, element_length_m, check_spacing_m, end_time_s)
    sc = parse_scenario(data, ROOT, default_name=data["name"])
    t0 = time.perf_counter()
    res = run_scenario(sc, None, quiet=True, plots=False, steady_stop=True)
    wall = time.perf_counter() - t0
    s, h = res.summary, res.history
    t = np.asarray(h["time_s"])
    from_s = s["steady_from_s"] if np.isfinite(s["steady_from_s"]) else t[0]
    window = t >= from_s
    t_mean = float(np.mean(t[window]))
    refs = pull_force_references_N(sc, pull_oriented_conduit(sc), SPEED_M_PER_S * t_mean)
    rope, clear = refs["rope_pull_force_N"], refs["rope_clearance_pull_force_N"]
    c = CASES[case]
    F = s["pull_force_N"]
    lam = math.sqrt(ej_N_m2 / rope)
    return {"case": case, "gravity": gravity, "clearance_m": clearance_m, "EJ_N_m2": ej_N_m2,
            "c_over_R": clearance_m / c["radius_m"], "bending_length_over_R": lam / c["radius_m"],
            "elements": sc.cable.elements, "check_points_per_element": sc.contact.check_points_per_element,
            "pull_force_N": F, "pull_force_std_N": s["pull_force_std_N"], "steady": s["steady"],
            "status": s["status"], "window_mean_time_s": t_mean, "rope_N": rope, "rope_clearance_N": clear,
            "vs_rope_pct": 100 * (F / rope - 1), "vs_rope_clearance_pct": 100 * (F / clear - 1),
            "clearance_rope_vs_rope_pct": 100 * (clear / rope - 1), "wall_s": wall,
            "free_span_estimate_pct": 100 * free_span_estimate_N(case, clearance_m, gravity) / rope}


def free_span_estimate_N(case: str, clearance_m: float, gravity: bool) -> float:
    """Estimated difference rope with clearance − centreline rope [N] from the free spans (reference/README.md).

    At each end of a bend the cable crosses the clearance in a free span of length a, whose weight
    its tension carries (a catenary) instead of the floor of the straight. Over a straight the
    centreline rope counts the floor's pressure w⊥ per length, the cable in its span nothing:

    - vertical up-bend (the bend's pressure T/R opposes the weight): the span runs from the floor to
      the bend's upper wall, a parabola of curvature w⊥/T landing tangentially on the arc:
      a = 2 √(c (T/w⊥ − R)), and the weight the span does not put on the floor is put against T/R in
      the bend, where the rope counted it with the opposite sign: ΔF = −2 μ w⊥ a;
    - horizontal bend (T/R horizontal, the weight vertical): the span rises c from the floor,
      a = √(2 c T / w), and its weight goes to the bend's wall, where it adds to T/R in quadrature
      (at second order): ΔF = −μ w a;
    - down-bend (T/R and the weight both press on the lower wall): no span, ΔF = 0.

    A saving at the bend's entry grows through the bend by the capstan factor e^{μθ}. Tensions are
    the centreline rope's at the bend's ends.
    """
    if not gravity:
        return 0.0
    c = CASES[case]
    mu, R, Tb, w = c["friction"], c["radius_m"], c["back_tension_N"], c["mass_kg_per_m"] * G
    bend = next(p for p in c["path"] if "bend" in p)
    theta = math.radians(bend["angle_deg"] if "angle_deg" in bend else bend["bend"])
    if case == "hbend":
        T_in = Tb + mu * w * c["path"][0]["straight"]
        T_out = T_in * math.cosh(mu * theta) + math.sinh(mu * theta) * math.hypot(T_in, w * R)
        span = lambda T: math.sqrt(2 * clearance_m * T / w)  # noqa: E731
        return -mu * w * (span(T_in) * math.exp(mu * theta) + span(T_out))
    if case == "upbend":
        T_in = Tb + mu * w * c["path"][0]["straight"]
        T_out = T_in * math.exp(mu * theta)  # the weight's share changes it by ~1 %: enough for an estimate
        w_out = w * math.cos(theta)
        return -2 * mu * (w * 2 * math.sqrt(clearance_m * (T_in / w - R)) * math.exp(mu * theta)
                          + w_out * 2 * math.sqrt(clearance_m * (T_out / w_out - R)))
    return 0.0


def clearance_limit(clearances_m=(1e-2, 1e-3, 1e-4, 1e-5)) -> list[dict]:
    """The rope with clearance against the centreline rope as c → 0 (no exucable run: seconds)."""
    from exucable.geometry import Bend, Straight, centreline_from_path
    from exucable.quasistatic.rope import solve_rope
    from exucable.quasistatic.clearance import solve_rope_with_clearance

    rows = []
    for case in ("hbend", "upbend"):
        c = CASES[case]
        items = [Straight(p["straight"]) if "straight" in p else Bend(p["bend"], p["radius"], turn=p["turn"])
                 for p in c["path"]]
        centre = centreline_from_path([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], items)
        w = c["mass_kg_per_m"] * G
        rope = solve_rope(centre, c["friction"], w, c["back_tension_N"]).pull_force_N
        for cl in clearances_m:
            clear = solve_rope_with_clearance(centre, cl, c["friction"], w, c["back_tension_N"]).pull_force_N
            rows.append({"case": case, "clearance_m": cl, "c_over_R": cl / c["radius_m"],
                         "clearance_rope_vs_rope_pct": 100 * (clear / rope - 1),
                         "free_span_estimate_pct": 100 * free_span_estimate_N(case, cl, True) / rope})
    return rows


def rereference(r: dict) -> dict:
    """Recompute a stored row's references (and differences) at its window's extent, without rerunning exucable."""
    from exucable.model.build import pull_oriented_conduit
    from exucable.quasistatic.extent import pull_force_references_N
    from exucable.scenario.specs import parse_scenario

    data = scenario_dict(r["case"], r["clearance_m"], r["EJ_N_m2"], r["gravity"], 0.1, 0.005, 1.0)
    data["cable"]["elements"] = r["elements"]
    sc = parse_scenario(data, ROOT, default_name=data["name"])
    refs = pull_force_references_N(sc, pull_oriented_conduit(sc), SPEED_M_PER_S * r["window_mean_time_s"])
    rope, clear, F = refs["rope_pull_force_N"], refs["rope_clearance_pull_force_N"], r["pull_force_N"]
    return dict(r, rope_N=rope, rope_clearance_N=clear, vs_rope_pct=100 * (F / rope - 1),
                vs_rope_clearance_pct=100 * (F / clear - 1), clearance_rope_vs_rope_pct=100 * (clear / rope - 1),
                free_span_estimate_pct=100 * free_span_estimate_N(r["case"], r["clearance_m"], r["gravity"]) / rope)


def print_row(r: dict) -> None:
    print(f"| {r['case']} | {'yes' if r['gravity'] else 'no'} | {r['clearance_m'] * 1e3:g} | {r['c_over_R']:.2g} | "
          f"{r['EJ_N_m2']:g} | {r['bending_length_over_R']:.3g} | {r['elements']}×{r['check_points_per_element']} | "
          f"{r['pull_force_N']:.3f} ± {r['pull_force_std_N']:.2g} | {r['rope_N']:.3f} | {r['rope_clearance_N']:.3f} | "
          f"{r['vs_rope_pct']:+.3f} % | {r['vs_rope_clearance_pct']:+.3f} % | {r['clearance_rope_vs_rope_pct']:+.3f} % | "
          f"{r['free_span_estimate_pct']:+.3f} % | "
          f"{r['wall_s']:.0f} |", flush=True)


HEADER = ("| case | gravity | c [mm] | c/R | EJ [N m²] | √(EJ/T)/R | mesh | exucable [N] | rope [N] | "
          "rope with clearance [N] | vs rope | vs rope with clearance | clearance rope vs rope | free-span estimate | "
          "wall [s] |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")

# (case, gravity, clearance [m], EJ [N m²]): each line of the sweep moves one parameter toward zero.
SWEEP = [
    ("hbend", False, 0.0084, 7.9), ("hbend", False, 0.0084, 0.79), ("hbend", False, 0.0084, 0.079),
    ("hbend", False, 0.002, 0.079), ("hbend", False, 0.0005, 0.079),
    ("hbend", True, 0.0084, 0.79), ("hbend", True, 0.0084, 0.079), ("hbend", True, 0.002, 0.079),
    ("upbend", True, 0.01, 7.9), ("upbend", True, 0.01, 0.79), ("upbend", True, 0.01, 0.079),
    ("upbend", True, 0.002, 0.079), ("upbend", True, 0.0005, 0.079),
    ("downbend", True, 0.01, 7.9), ("downbend", True, 0.01, 0.79), ("downbend", True, 0.01, 0.079),
    ("downbend", True, 0.002, 0.079),
]


def add_case_arguments(p) -> None:
    """``--case``, ``--clearance`` [m] and ``--ej`` [N m²]: one row instead of the sweep."""
    p.add_argument("--case", choices=sorted(CASES))
    p.add_argument("--clearance", type=float, help="clearance c [m]")
    p.add_argument("--ej", type=float, help="bending stiffness EJ [N m²]")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_case_arguments(p)
    p.add_argument("--no-gravity", action="store_true")
    p.add_argument("--element-length", type=float, default=0.1, help="[m]")
    p.add_argument("--check-spacing", type=float, default=0.005, help="[m]")
    p.add_argument("--json", help="write the rows to this JSON file")
    p.add_argument("--figure", help="plot the rows of --json (or of this run) to this PNG")
    p.add_argument("--from-json", help="read exucable's rows from this JSON file instead of running (the "
                   "references are recomputed)")
    p.add_argument("--mesh-check", help="steady solves of every case at the study's mesh and two refinements "
                   "(exucable converge's extrapolation); write the rows to this JSON file")
    p.add_argument("--clearance-limit", action="store_true",
                   help="only the rope with clearance against the centreline rope as c → 0 (seconds)")
    p.add_argument("--mesh-report", help="reprint the mesh check written by --mesh-check to this JSON file")
    p.add_argument("--quick", action="store_true",
                   help="smoke run: the c → 0 table and the sweep's first row (hbend, no gravity, c 8.4 mm, "
                        "EJ 7.9 N m²) on a coarse mesh (0.25 m elements, check points 20 mm apart)")
    a = p.parse_args(argv)
    if a.quick:
        a.case, a.no_gravity, a.clearance, a.ej = "hbend", True, 0.0084, 7.9
        a.element_length, a.check_spacing = 0.25, 0.02
    if a.mesh_report:
        print(MESH_HEADER)
        for row in json.loads(Path(a.mesh_report).read_text()):
            print(mesh_row_text(row))
        return 0
    limit = clearance_limit()
    print("| case (gravity) | c [m] | c/R | rope with clearance vs rope | free-span estimate |\n|---|---|---|---|---|")
    for r in limit:
        print(f"| {r['case']} | {r['clearance_m']:g} | {r['c_over_R']:.1e} | {r['clearance_rope_vs_rope_pct']:+.4f} % | "
              f"{r['free_span_estimate_pct']:+.4f} % |")
    print()
    if a.clearance_limit:
        return 0
    if a.mesh_check:
        mesh_check(a.mesh_check, a.element_length, a.check_spacing)
        return 0
    if a.from_json:
        rows = [rereference(r) for r in json.loads(Path(a.from_json).read_text())]
        print(HEADER)
        for r in rows:
            print_row(r)
    else:
        if a.case:
            plan = [(a.case, not a.no_gravity, a.clearance, a.ej)]
        else:
            plan = SWEEP
        print(HEADER)
        rows = []
        for case, grav, c, ej in plan:
            r = run_one(case, c, ej, grav, a.element_length, a.check_spacing)
            rows.append(r)
            print_row(r)
            if a.json:
                Path(a.json).write_text(json.dumps(rows, indent=1))
    if a.figure:
        plot(rows, limit, a.figure)
    return 0


MESH_HEADER = ("| case | gravity | c [mm] | EJ [N m²] | elements × check points | pulling force per level [N] | "
               "extrapolated [N] | study mesh vs extrapolated | observed order | wall per level [s] |\n"
               "|---|---|---|---|---|---|---|---|---|---|")


def mesh_row_text(row: dict) -> str:
    """One case of the mesh check as a table row (wall times to 0.1 s: most solves take about a second)."""
    ext = "n/a" if row["extrapolated_N"] is None else f"{row['extrapolated_N']:.3f} ± {row['error_N']:.2g}"
    dv = row["default_vs_extrapolated"]
    dv = f"{100 * dv:+.3f} %" if dv is not None else f"{100 * row['default_vs_finest']:+.3f} % (vs finest)"
    # no order where the three values are not monotone (the finest is then the estimate)
    order = "–" if row["order"] is None or math.isnan(row["order"]) else f"{row['order']:.2g}"
    return (f"| {row['case']} | {'yes' if row['gravity'] else 'no'} | {row['clearance_m'] * 1e3:g} | {row['EJ_N_m2']:g} | "
            f"{' / '.join(row['meshes'])} | {' / '.join(f'{v:.3f}' for v in row['values_N'])} | {ext} | {dv} | {order} | "
            f"{' / '.join(f'{w:.1f}' for w in row['wall_s'])} |")


def mesh_check(path: str, element_length_m: float, check_spacing_m: float) -> list[dict]:
    """The study's mesh against two refinements (halving the element length and the check-point
    spacing), each case solved in steady mode (no start-up, no scatter: the mesh alone)."""
    import tempfile

    from exucable.commands.converge import converge
    from exucable.scenario.specs import parse_scenario

    print(MESH_HEADER, flush=True)
    rows = []
    for case, grav, c, ej in SWEEP:
        data = scenario_dict(case, c, ej, grav, element_length_m, check_spacing_m, 1.0)
        sc = parse_scenario(data, ROOT, default_name=data["name"])
        with tempfile.TemporaryDirectory() as tmp:
            rep = converge(sc, tmp, levels=3, ratio=2.0, mode="steady")
        lv = rep["levels"]
        row = {"case": case, "gravity": grav, "clearance_m": c, "EJ_N_m2": ej,
               "meshes": [f"{r['elements']}×{r['check_points_per_element']}" for r in lv],
               "values_N": [r["value_N"] for r in lv], "statuses": [r["status"] for r in lv],
               "wall_s": [r["wall_time_s"] for r in lv], "extrapolated_N": rep["extrapolated_N"],
               "error_N": rep["error_N"], "order": rep["observed_order"], "method": rep["method"],
               "default_vs_extrapolated": rep.get("default_vs_extrapolated"),
               "default_vs_finest": lv[0]["value_N"] / lv[-1]["value_N"] - 1.0}
        rows.append(row)
        print(mesh_row_text(row), flush=True)
        tmp_json = Path(path + ".tmp")
        tmp_json.write_text(json.dumps(rows, indent=1))
        tmp_json.replace(path)
    return rows


def plot(rows, limit, path) -> None:
    """Three panels: EJ → 0 against the rope with clearance; c → 0 against the centreline rope
    (exucable, the rope with clearance and the free-span estimate)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
    styles = {("hbend", False): ("o", "C0"), ("hbend", True): ("s", "C1"), ("upbend", True): ("^", "C2"),
              ("downbend", True): ("v", "C3")}
    for (case, grav), (marker, colour) in styles.items():
        sel = [r for r in rows if r["case"] == case and r["gravity"] == grav]
        if not sel:
            continue
        label = f"{case}{' + gravity' if grav else ', no gravity'}"
        big_c = sorted((r for r in sel if r["clearance_m"] == max(x["clearance_m"] for x in sel)),
                       key=lambda r: r["bending_length_over_R"])
        axes[0].semilogx([r["bending_length_over_R"] for r in big_c], [r["vs_rope_clearance_pct"] for r in big_c],
                         marker=marker, color=colour, label=label)
        small_ej = sorted((r for r in sel if r["EJ_N_m2"] == min(x["EJ_N_m2"] for x in sel)),
                          key=lambda r: r["c_over_R"])
        axes[1].semilogx([r["c_over_R"] for r in small_ej], [r["vs_rope_pct"] for r in small_ej],
                         marker=marker, color=colour, ls="none", ms=8, label=f"exucable, {label}")
        lim = [r for r in limit if r["case"] == case] if grav else []
        if lim:
            axes[1].semilogx([r["c_over_R"] for r in lim], [r["clearance_rope_vs_rope_pct"] for r in lim],
                             color=colour, label=f"rope with clearance, {case}")
            axes[1].semilogx([r["c_over_R"] for r in lim], [r["free_span_estimate_pct"] for r in lim],
                             color=colour, ls=":", label=f"free-span estimate, {case}")
    axes[0].axhspan(-0.1, 0.1, color="0.9", label="±0.1 %")
    axes[0].set_xlabel("bending length √(EJ/T) / R")
    axes[0].set_ylabel("exucable − rope with clearance [%]")
    axes[0].set_title("EJ → 0 (largest clearance of each case)")
    axes[1].axhspan(-0.1, 0.1, color="0.9")
    axes[1].set_xlabel("clearance c / R")
    axes[1].set_ylabel("− centreline rope [%]")
    axes[1].set_title("c → 0 (smallest EJ): free spans, ∝ √c")
    from matplotlib.ticker import NullFormatter
    for ax in axes:
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.axhline(0.0, color="k", lw=0.5)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    raise SystemExit(main())
