"""Three cables pulled together through one duct, simulated (``cable.count = 3``, steady mode).

Three 30 mm cables cradled in the bottom of a 99 mm duct (D/d = 3.3), a horizontal straight,
μ = 0.3 at the wall and frictionless between the cables, back tension 30 N for the bundle. The
straight's weight correction factor emerges from the cables pressing on each other and on the
wall; the rigid-circle statics the calculators use give 1 + (4/3)(d/(D − d))² = 1.2520.
"""

import exucable as xc


def main(length_m=20.0, elements=40, out_dir=None):
    d, D = 0.03, 0.099
    route = xc.Route(inner_radius=D / 2).straight(length_m)
    sc = xc.Scenario(route=route,
                     cable=xc.Cable(radius=d / 2, density=2000.0, youngs_modulus=2e8, elements=elements,
                                    count=3, arrangement="cradled"),
                     contact=xc.Contact(friction=0.3, cable_friction=0.0, check_points_per_element=8),
                     pull=xc.Pull(speed=0.1, back_tension=30.0), gravity=xc.Gravity(g=9.81),
                     solver=xc.Solver(mode="steady", steady_lead_out=0.0))
    res = xc.run(sc, out_dir=out_dir)
    b = res.summary["bundle"]
    (straight,) = b["straights"]
    u = res.summary.get("pull_force_uncertainty_N")
    bar = f" ± {u:.2g} N" if u is not None else ""
    print(f"pulling force {res.pull_force_N:.2f} N{bar}, status {res.status}; weight correction factor of the "
          f"straight {straight['weight_correction_factor']:.4f} (the calculators' {b['formula_weight_correction_factor']:.4f})")
    print(f"arrangement found: {b['sections'][0]['arrangement']}, jam: {b['jam']}; pull shares "
          + ", ".join(f"{100 * c['pull_share']:.1f} %" for c in b["cables"]))
    return res


if __name__ == "__main__":
    main()
