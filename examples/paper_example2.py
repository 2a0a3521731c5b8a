"""Paper Example 2 (Yang et al. 2013, Sect. 3.2): a cable pulled through a 90° bend.

Two 1 m straights joined by a bend of radius 0.5 m, no gravity, μ = 0.2, back tension 150 N;
the paper's 40 elements. The capstan law T1 = T2·e^(μθ) (Eq. 26) gives 205.37 N.
"""

import math

import exucable as xc


def main(end_time=1.0):
    route = xc.Route(inner_radius=3.5e-3).straight(1.0).bend(90, radius=0.5, turn="left").straight(1.0)
    sc = xc.Scenario(route=route,
                     cable=xc.Cable(radius=2.5e-3, density=1000.0, youngs_modulus=1e9, elements=40),
                     contact=xc.Contact(friction=0.2), pull=xc.Pull(speed=0.1, back_tension=150.0),
                     solver=xc.Solver(end_time=end_time))
    res = xc.run(sc)
    capstan = 150.0 * math.exp(0.2 * math.pi / 2)
    print(f"pulling force {res.pull_force_N:.2f} ± {res.pull_force_uncertainty_N:.2g} N, "
          f"capstan {capstan:.2f} N ({100 * (res.pull_force_N / capstan - 1):+.3f} %), status {res.status}")
    return res, capstan


if __name__ == "__main__":
    main()
