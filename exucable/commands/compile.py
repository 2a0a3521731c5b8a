"""``exucable compile``: compile the contact kernels for this machine now, into numba's disk cache.

The first run after an install or an update of exucable compiles them anyway (once; later processes
load the machine code from numba's cache, see :mod:`exucable.contact.jitcache`); this command does it
up front by running a tiny built-in case in each solver mode, so that every kernel a run calls is
compiled with the argument types a run uses (no hand-kept list of signatures). Commands that run a
model say when a run is about to compile (:func:`announce_compiling`).
"""

from __future__ import annotations

import sys
import time

__all__ = ["add_arguments", "main", "announce_compiling"]

# what the first compile costs on a 2-core machine: 45 s quiet, 190 s with eight other jobs
COMPILE_ESTIMATE = "about a minute, a few on a busy machine"


def add_arguments(p) -> None:
    p.add_argument("--check", action="store_true",
                   help="only say whether the kernels are compiled (exit status 0 if so, 1 if not)")
    p.add_argument("-q", "--quiet", action="store_true", help="say nothing when the kernels are compiled")


def announce_compiling(stream=None) -> None:
    """Say on ``stream`` (stderr) that the coming run compiles the contact kernels, when it will."""
    from ..contact.jitcache import kernels_to_compile

    if kernels_to_compile():
        print(f"exucable: compiling the contact kernels for this machine ({COMPILE_ESTIMATE}, once after an "
              "install or an update; `exucable compile` does it ahead) ...", file=stream or sys.stderr, flush=True)


def _warm_up() -> None:
    """Run the coarse Example 2 over a few steps in dynamic mode and once in steady mode, and format a
    row of numbers: every kernel a run calls is compiled and cached."""
    from ..data import data_path
    from ..run import run_scenario
    from ..scenario.specs import load_scenario

    sc = load_scenario(data_path("scenarios", "fast", "paper_ex2_bend90.toml"))
    run_scenario(sc.replace(**{"solver.mode": "dynamic", "solver.end_time": 0.003}), plots=False)
    run_scenario(sc.replace(**{"solver.mode": "steady"}), plots=False)
    # the cable-cable kernel runs only with several cables: without this a first bundle run compiles
    # it inside its own time budget
    run_scenario(_tiny_bundle(), plots=False)
    # the result files' number formatter (runs without out_dir write nothing)
    import numpy as np

    from ..output.numbers_text import rows_text
    rows_text([np.zeros(1), np.arange(1)])


def _tiny_bundle():
    """Three cables in a 2 m straight duct, steady: the smallest run that calls the cable-cable kernel."""
    from ..api import Cable, Contact, Gravity, Pull, Route, Scenario, Solver

    route = Route(inner_radius=0.05).straight(2.0)
    return Scenario(route=route,
                    cable=Cable(radius=0.015, density=2000.0, youngs_modulus=2e8, count=3, arrangement="triangular"),
                    contact=Contact(friction=0.3, check_points_per_element=8),
                    pull=Pull(speed=0.1, back_tension=100.0), gravity=Gravity(g=9.81),
                    solver=Solver(mode="steady", steady_lead_out=0.0))


def main(args) -> int:
    from ..contact.jitcache import kernels_to_compile

    pending = kernels_to_compile()
    if pending == []:
        if not args.quiet:
            print("contact kernels compiled and cached for this machine")
        return 0
    if args.check:
        print("the contact kernels are not compiled for these sources and this machine: the next run "
              f"compiles them ({COMPILE_ESTIMATE}); `exucable compile` does it now")
        return 1
    print(f"compiling the contact kernels for this machine ({COMPILE_ESTIMATE}) ...", flush=True)
    t0 = time.perf_counter()
    _warm_up()
    left = kernels_to_compile()
    print(f"compiled in {time.perf_counter() - t0:.0f} s" + ("" if not left else
          f"; not cached (numba cannot write its cache, see the warning above): {', '.join(left)}"))
    return 0
