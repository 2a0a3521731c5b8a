"""What Example 4's difference from the rope solution is made of.

The rope (no bending stiffness) is Example 4's only reference. This study varies the mesh
(elements, check points) and the bending stiffness EJ (through Young's modulus: EJ/EA = r²/4
stays, and the rope does not depend on EA) and prints the pulling force against the rope's.
A second table isolates one horizontal 90° bend with gravity (R = 1 m, μ = 0.3, T2 = 20 N) and
varies the clearance R − r and EJ: a difference that stays as EJ falls but vanishes with the
clearance is the cable's path through the clearance (free spans from wall to wall that the rope,
glued to the centreline, does not have), not its stiffness.

    .venv/bin/python studies/ex4_study.py          # ~4 min on 2 cores
    .venv/bin/python studies/ex4_study.py --quick  # smoke run: the fast Example 4 once, one coarse bend run
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from run_examples import run  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true",
                    help="smoke run: the fast Example 4 on its own mesh, and one bend run at 20 elements x 20 points")
    args = ap.parse_args(argv)
    path = ROOT / "scenarios" / ("fast" if args.quick else "") / "paper_ex4_spatial.toml"
    from exucable.scenario.specs import load_scenario
    from exucable.quasistatic.rope import solve_rope
    sc = load_scenario(path)
    w = sc.cable.mass_per_length_kg_per_m * sc.gravity.g_m_per_s2
    rope = solve_rope(sc.build_conduit().centreline, sc.contact.friction, w,
                      trailing_tension_N=sc.pull.back_tension_N).pull_force_N
    print(f"rope solution: {rope:.4f} N\n")
    print("| elements | check points | E [Pa] | EJ [N m²] | pulling force [N] | vs rope |")
    print("|---|---|---|---|---|---|")
    cases = [(50, 400, 1e9), (100, 800, 1e9), (200, 400, 1e9), (100, 800, 1e8)]
    if args.quick:
        cases = [(sc.cable.elements, sc.contact.check_points_per_element, 1e9)]
    for n, cp, E in cases:
        r = run(path, {"cable.elements": n, "contact.check_points_per_element": cp, "cable.youngs_modulus": E})
        EJ = E * 3.141592653589793 * sc.cable.radius_m ** 4 / 4
        F = r["pull_force_N"]
        print(f"| {n} | {cp} | {E:.0e} | {EJ:.3g} | {F:.4f} | {100 * (F / rope - 1):+.3f} % |", flush=True)
    bend_study(args.quick)


BEND = """
name = "bend-with-gravity"
[cable]
radius = 0.0025
density = 1000.0
youngs_modulus = 1.0e9
elements = 60
[conduit]
inner_radius = 0.0035
segments_per_bend = 60
path = [ { straight = 1.0 }, { bend = 90.0, radius = 1.0, turn = "left" }, { straight = 1.0 } ]
[contact]
friction = 0.3
check_points_per_element = 100
[pull]
speed = 0.1
back_tension = 20.0
[gravity]
g = 9.8
[solver]
end_time = 0.6
step = 1.0e-2
steady_stop = true
"""


def bend_study(quick: bool = False):
    """The single bend's table; ``quick``: one run (3.5 mm, E 1e9 Pa) at 20 elements x 20 check points."""
    import tempfile
    from exucable.scenario.specs import load_scenario
    from exucable.quasistatic.rope import solve_rope
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "bend.toml"
        path.write_text(BEND)
        sc = load_scenario(path)
        w = sc.cable.mass_per_length_kg_per_m * sc.gravity.g_m_per_s2
        rope = solve_rope(sc.build_conduit().centreline, 0.3, w, trailing_tension_N=20.0).pull_force_N
        print(f"\nOne horizontal 90° bend with gravity; rope: {rope:.4f} N\n")
        print("| clearance R − r [mm] | E [Pa] | pulling force [N] | vs rope |\n|---|---|---|---|")
        coarse = {"cable.elements": 20, "contact.check_points_per_element": 20} if quick else {}
        for R in ((0.0035,) if quick else (0.0035, 0.0026)):
            for E in ((1e9,) if quick else (1e9, 1e8, 1e7)):
                r = run(path, {"conduit.inner_radius": R, "cable.youngs_modulus": E, **coarse})
                F = r["pull_force_N"]
                print(f"| {1e3 * (R - 0.0025):.1f} | {E:.0e} | {F:.4f} | {100 * (F / rope - 1):+.3f} % |", flush=True)


if __name__ == "__main__":
    main()
