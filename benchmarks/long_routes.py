"""Cost of a steady run against route length, stage by stage: 1, 2, 5, 10 km.

Realistic long routes: a 30 mm power cable (1.5 kg/m, EA = 14 MN) in a 60 mm duct, gravity,
μ = 0.2, 500 N back tension, a 15° bend (radius 10 m) every ~350 m, alternating left/up/right/down so
that the straights between the vertical bends slope; the mesh and the check points are the
scenario's default rules (:func:`route_data`).

Each length runs in its own process (so that its peak memory is its own): the process imports
exucable, parses the scenario, builds the models (the rule's coarse mesh for the error bar and the
solved mesh, the start layout and both rope references included), solves steady, solves the error
bar's coarse mesh, post-processes (tension profile, check-point loads, pressure, bends, trust),
writes the result files and draws the three figures, each stage timed on its own (wall and CPU
time). The parent times the whole child process (interpreter start to exit, wall and CPU; the
child ends as `exucable run` does, with exucable.cli.end_process where the tree has it). Printed
per length: elements, check points, Newton iterations of the solve and of the error bar's, the CPU
time of the whole process and of each stage with its share (on a shared, loaded machine the CPU
times are the ones to compare), the build's parts (the rope references, the start layout's fine grid
and fit, its contact offsets, Exudyn's cable items, the contact coupling), the solve's CPU time per
Newton iteration, peak memory (ru_maxrss) and the pulling force against the rope with clearance;
the share of everything outside the two steady solves (CPU time: the import, the interpreter's
start and exit, the scenario's parsing, the build, post-processing and writing), and beside it the
share the long-routes issue names, "the build, the references (rope, rope with clearance) and
post-processing": (build + post + write) / whole process, CPU time, where the build includes the
rope references solved in it (any reference solved after the solves is in post), so nothing is
counted twice, and the import, the parsing and the interpreter's start and exit are left out; then
the exponent p of a least-squares fit CPU time ∝ L^p (whole process, the solves, the rest, the
issue's part), measured in this one run, and a table of the stages per length.

``--profile`` runs the longest route once more under cProfile (in this process, after a short
warm-up) and prints Exudyn's own timers of its static solver per Newton iteration (system
Jacobian, factorisation, residual) and the functions with the most own and cumulative time (the
contact kernel, our coupling's and the pseudo-time spring's user functions, the build's parts).

``--newton-parts`` times each part of one Newton iteration of the longest route on its own (CPU
time): the residual, the ODE2 Jacobian with and without the loads' Jacobian, our contact
coupling's user functions within them, and one whole one-iteration static solve.

``--before TREE`` runs each length first with the exucable package of the source tree TREE (e.g.
``git archive <commit> | tar -x -C TREE``; copy ``exucable/contact/__pycache__`` into it with the
sources' time stamps, ``touch -r``, or its kernels compile in its first child), then with the installed
one, and prints the CPU time after/before of the whole process, the solves and the rest, and the
pulling force's change: a pass's effect measured in one run.

``--compare-static-solver`` runs each length with ``[solver] static_solver = "exudyn"`` and then
``"exucable"`` (processes of their own, one after the other: CPU ratios, pulling forces, Newton counts),
then times one Newton iteration of each (Exudyn's static solver, ours with the banded LU and with
SuperLU) interleaved in this process from the same state, and our iteration by part.

Run: ``nice .venv/bin/python benchmarks/long_routes.py [--lengths 1000 2000 5000 10000] [--profile] [--newton-parts] [--clearance-spacing] [--before TREE] [--compare-cold] [--compare-static-solver]``;
``--clearance-spacing`` solves the longest route's rope with clearance on uniform chains of 2, 5 and 10 cm node
spacing and on the default chain (graded away from the bends), with the pulling force's change against the 2 cm
chain and the CPU time of each.
``--compare-cold`` runs each length a second time with the solved mesh started from the rope start
instead of the error bar's coarse solve (steady mode's nested start), in a process of its own right
after, and prints the two side by side (Newton iterations, CPU of the solves and of the whole process,
the pulling forces' difference).
``--quick`` is a smoke run (a 200 m and a 400 m route).
"""

from __future__ import annotations

import argparse
import json
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CABLE_RADIUS_M = 0.015
MASS_PER_LENGTH_KG_PER_M = 1.5
AXIAL_STIFFNESS_N = 14.0e6
DUCT_INNER_RADIUS_M = 0.030
BEND_SPACING_M = 350.0
BEND_ANGLE_DEG = 15.0
BEND_RADIUS_M = 10.0


def route_path(length_m: float, bend_angle_deg: float = BEND_ANGLE_DEG, bend_spacing_m: float = BEND_SPACING_M,
               turns: tuple = ("left", "up", "right", "down")) -> list[dict]:
    """Straights and bends of ``bend_angle_deg`` [°] (radius 10 m) adding up to ``length_m`` [m], one
    bend per ~``bend_spacing_m`` [m] (at least one), turning as ``turns`` in turn (by default left,
    up, right, down: the straights after an up or down bend slope)."""
    import math

    n_bends = max(1, int(round(length_m / bend_spacing_m)))
    arc = math.radians(bend_angle_deg) * BEND_RADIUS_M
    straight = (length_m - n_bends * arc) / (n_bends + 1)
    path = [{"straight": straight}]
    for i in range(n_bends):
        path.append({"bend": bend_angle_deg, "radius": BEND_RADIUS_M, "turn": turns[i % len(turns)]})
        path.append({"straight": straight})
    return path


def route_data(length_m: float, cable_element: str | None = None, static_solver: str | None = None,
               friction: float = 0.2, back_tension_N: float = 500.0, **route) -> dict:
    """The scenario (as a TOML-like dict) of a route of ``length_m`` [m], steady mode;
    ``cable_element``, ``static_solver``: those ``[solver]`` keys (None: the default); ``friction`` [-]
    and ``back_tension_N`` [N]: the pull's; ``route``: :func:`route_path`'s bend keywords."""
    import math

    area = math.pi * CABLE_RADIUS_M ** 2
    solver = {"mode": "steady", "end_time": 1.0}   # end_time: required, unused by a steady solve
    if cable_element is not None:
        solver["cable_element"] = cable_element
    if static_solver is not None:
        solver["static_solver"] = static_solver
    return {
        "name": f"long-route-{length_m:g}m",
        "cable": {"radius": CABLE_RADIUS_M, "mass_per_length": MASS_PER_LENGTH_KG_PER_M,
                  "youngs_modulus": AXIAL_STIFFNESS_N / area},
        "conduit": {"inner_radius": DUCT_INNER_RADIUS_M, "path": route_path(length_m, **route)},
        "contact": {"friction": friction},
        "pull": {"speed": 0.1, "back_tension": back_tension_N},
        "gravity": {"g": 9.81},
        "solver": solver,
    }


class _Clock:
    """Wall [s] and this process's CPU time [s] of each stage (CPU time: robust on a loaded machine)."""

    def __init__(self):
        self.wall, self.cpu = {}, {}
        self._t = (time.perf_counter(), time.process_time())

    def lap(self, name: str) -> None:
        now = (time.perf_counter(), time.process_time())
        self.wall[name], self.cpu[name] = now[0] - self._t[0], now[1] - self._t[1]
        self._t = now


class _Timed:
    """Wall and CPU time [s] summed over the calls of the functions it wraps, per stage name,
    and the outcomes of the steady solves by stage."""

    def __init__(self):
        self.wall, self.cpu, self.solves = {}, {}, {}
        self._inside = set()

    def wrap(self, module, name: str, stage):
        """Replace ``module.name`` by a timed copy; ``stage(call_number, kwargs)`` names the stage of a call."""
        f = getattr(module, name)
        calls = [0]

        def timed(*args, **kwargs):
            key = stage(calls[0], kwargs)
            calls[0] += 1
            if key in self._inside:     # a call within a timed call of the same stage: counted there
                return f(*args, **kwargs)
            self._inside.add(key)
            w, c = time.perf_counter(), time.process_time()
            try:
                out = f(*args, **kwargs)
            finally:
                self._inside.discard(key)
            self.wall[key] = self.wall.get(key, 0.0) + time.perf_counter() - w
            self.cpu[key] = self.cpu.get(key, 0.0) + time.process_time() - c
            if name == "solve_steady":
                self.solves[key] = out
            return out

        setattr(module, name, timed)


def one_case(length_m: float, figures: bool = True, cold: bool = False, cable_element: str | None = None,
             static_solver: str | None = None) -> dict:
    """Every stage of one steady run of ``length_m`` [m] in this process (the JSON a child prints).

    Stages: import, parse, build (every model built, the rope references included), of it the
    references (the centreline rope's solves and the rope with clearance), solve (the steady
    solve), error bar (the second steady solve on the coarse mesh), post (the rest of
    ``run_scenario``: tension profile, check-point loads, pressure, bends, trust), write (CSV and
    JSON), figures; wall and CPU time of each. ``cold``: the solved mesh from the rope start, not
    from the error bar's coarse solve (``--compare-cold``)."""
    clock = _Clock()
    from exucable.output.results import write_results
    from exucable.plots.results import plot_pressure, plot_pull_force, plot_tension_profile
    from exucable.run import run_scenario
    from exucable.scenario.specs import parse_scenario
    import exucable.model.build as build
    import exucable.model.coupling as coupling
    import exucable.model.layout as layout
    import exucable.quasistatic.clearance as clearance
    import exucable.quasistatic.rope as rope
    import exucable.solve.start as start
    import exucable.solve.steady as steady
    if cold:
        start.nested_start = lambda fine, coarse: None     # run.py imports it at call time
    clock.lap("import_s")
    sc = parse_scenario(route_data(length_m, cable_element, static_solver), ROOT, default_name="route")
    clock.lap("parse_s")
    # run_scenario and the error bar import these at call time: the timed copies are the ones called
    timed = _Timed()
    timed.wrap(build, "build_model", lambda i, kw: "build_s")
    # run.py's main solve is the one with a progress bar; the error bar's coarse solve has none
    timed.wrap(steady, "solve_steady", lambda i, kw: "solve_s" if "progress" in kw else "error_bar_s")
    for module, name in ((rope, "solve_rope"), (rope, "rope_pull_force_N"), (rope, "solve_rope_for_pull_force"),
                         (clearance, "solve_rope_with_clearance")):
        timed.wrap(module, name, lambda i, kw: "references_s")
    # the build's other parts (BUILD_PARTS), each looked up at call time by its caller
    for (module, name), key in zip(((layout, "lay_cable"), (layout, "contact_offsets"), (build, "add_cable"),
                                    (coupling, "ContactCoupling")), BUILD_PARTS):
        timed.wrap(module, name, lambda i, kw, key=key: key)
    res = run_scenario(sc, None, plots=False)
    clock.lap("run_s")
    s = res.summary
    wall = {k: clock.wall[k] for k in ("import_s", "parse_s")}
    cpu = {k: clock.cpu[k] for k in ("import_s", "parse_s")}
    for k in ("build_s", "references_s", "solve_s", "error_bar_s") + BUILD_PARTS:
        wall[k], cpu[k] = timed.wall.get(k, 0.0), timed.cpu.get(k, 0.0)
    wall["post_s"] = clock.wall["run_s"] - wall["build_s"] - wall["solve_s"] - wall["error_bar_s"]
    cpu["post_s"] = clock.cpu["run_s"] - cpu["build_s"] - cpu["solve_s"] - cpu["error_bar_s"]

    out = Path(tempfile.mkdtemp(prefix="exucable-long-routes-"))
    try:
        clock.lap("rest")
        write_results(out, res, plots=False)
        clock.lap("write_s")
        if figures:
            plot_pull_force(out / "pull_force.png", res)
            plot_tension_profile(out / "tension_profile.png", res)
            if res.pressure_profile is not None:
                plot_pressure(out / "pressure.png", res)
        clock.lap("figures_s")
    finally:
        shutil.rmtree(out, ignore_errors=True)
    for k in ("write_s", "figures_s"):
        wall[k], cpu[k] = clock.wall[k], clock.cpu[k]
    bar = timed.solves.get("error_bar_s")
    return {"length_m": length_m, "status": s["status"], "message": s["message"],
            # the solved mesh's (steady mode refines the rule's; the error bar solves the rule's)
            "elements": s["mesh"]["elements"],
            "check_points": s["mesh"]["elements"] * s["mesh"]["check_points_per_element"],
            "newton_iterations": s["newton_iterations"], "steps": s["steps"],
            "error_bar_newton_iterations": bar.newton_iterations if bar is not None else 0,
            "started_from": timed.solves["solve_s"].started_from if "solve_s" in timed.solves else "-",
            "kernel_s": s["kernel_time_s"], "pull_force_N": s["pull_force_N"],
            "rope_clearance_pull_force_N": s["rope_clearance_pull_force_N"],
            "rope_pull_force_N": s["rope_pull_force_N"],
            "cpu_s": cpu, "peak_rss_MB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, **wall}


def in_child(length_m: float, figures: bool, cold: bool = False, tree: str | None = None,
             cable_element: str | None = None, static_solver: str | None = None) -> dict:
    """:func:`one_case` in a fresh process; adds the whole process's wall time ``process_s``.
    ``cold``: the solved mesh from the rope start (``--compare-cold``); ``tree``: an exucable source tree
    whose package the child imports instead of the installed one."""
    import os

    cmd = ([sys.executable, __file__, "--case", f"{length_m:g}"] + ([] if figures else ["--no-figures"])
           + (["--cold"] if cold else []) + (["--cable-element", cable_element] if cable_element else [])
           + (["--static-solver", static_solver] if static_solver else []))
    env = None
    if tree is not None:
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(tree).resolve())]
                                                          + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    t0 = time.perf_counter()
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(cmd, capture_output=True, text=True, check=False, env=env)
    wall = time.perf_counter() - t0
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stderr[-2000:]}")
    return dict(json.loads(done.stdout.strip().splitlines()[-1]), process_s=wall, process_cpu_s=cpu)


STAGES = ("import_s", "parse_s", "build_s", "solve_s", "error_bar_s", "post_s", "write_s", "figures_s")
#: the build's parts timed besides the rope references: the start layout's fine grid and fit
#: (lay_cable), the start's contact offsets, Exudyn's cable items (add_cable), the contact coupling
BUILD_PARTS = ("layout_s", "offsets_s", "items_s", "coupling_s")
BUILD_PART_NAMES = ("start layout (lay_cable)", "its contact offsets", "Exudyn's cable items", "contact coupling")


def issue_part_s(r: dict) -> float:
    """The long-routes issue's part of a run [s CPU]: the build (the rope references solved in it
    included) + post-processing + writing; the two solves, the import, the parsing and the
    interpreter's start and exit left out."""
    cpu = r["cpu_s"]
    return cpu["build_s"] + cpu["post_s"] + cpu["write_s"]


def report(r: dict) -> str:
    cpu, whole = r["cpu_s"], r["process_cpu_s"]
    stages = "  ".join(f"{k[:-2].replace('_', ' ')} {cpu[k]:6.2f} ({100 * cpu[k] / whole:3.0f} %)" for k in STAGES)
    n = max(r["newton_iterations"], 1)
    F, Fc = r["pull_force_N"], r["rope_clearance_pull_force_N"]
    vs = f"{100 * (F / Fc - 1):+.2f} %" if F is not None and Fc else "-"
    rest = whole - cpu["solve_s"] - cpu["error_bar_s"]
    return (f"{r['length_m'] / 1000:5.1f} km {r['status']:6s} whole process CPU {whole:6.2f} s (wall {r['process_s']:6.2f} s)  "
            f"outside the two solves {rest:6.2f} s = {100 * rest / whole:3.0f} %  "
            f"build (references) + post + write {issue_part_s(r):6.2f} s = {100 * issue_part_s(r) / whole:3.0f} %  "
            f"elements {r['elements']:5d}  check points {r['check_points']:7d}  Newton {r['newton_iterations']:4d} "
            f"({r['steps']} pseudo-time steps, from the {r['started_from']}; error bar's coarse solve "
            f"{r['error_bar_newton_iterations']})  "
            f"peak RSS {r['peak_rss_MB']:5.0f} MB\n"
            f"{'':9s}CPU per stage [s]: {stages}  (outside them: interpreter start and exit "
            f"{whole - sum(cpu[k] for k in STAGES):5.2f}); of the build, the rope references {cpu['references_s']:6.2f}, "
            + ", ".join(f"{n} {cpu.get(k, 0.0):5.2f}" for n, k in zip(BUILD_PART_NAMES, BUILD_PARTS)) + "\n"
            f"{'':9s}solve's CPU per Newton iteration {1e3 * cpu['solve_s'] / n:6.1f} ms (wall {1e3 * r['solve_s'] / n:6.1f} ms), "
            f"of which contact kernel (wall) {1e3 * r['kernel_s'] / n:6.1f} ms;  "
            f"F {'-' if F is None else f'{F:.1f}'} N, vs rope with clearance {vs}"
            + (f"\n{'':9s}{r['message']}" if r["message"] else ""))


def stage_table(runs, before=None) -> str:
    """Markdown table of the runs (one per length; ``before``: the ``--before`` tree's runs of the same
    lengths, shown as before / after), CPU times [s]."""
    lines = ["| route | whole process | the two solves | outside them (share) | the issue's part: build (rope "
             "references) + post + write (share of the whole process) | build (rope references) | post | write |",
             "|---|---|---|---|---|---|---|---|"]
    pairs = zip(before, runs) if before else ((None, r) for r in runs)
    for b, r in pairs:
        def cell(f, digits=2):
            return (f"{f(b):.{digits}f} / " if b is not None else "") + f"{f(r):.{digits}f}"

        def share(f):
            return (f"{100 * f(b) / b['process_cpu_s']:.0f} → " if b is not None else "") + \
                   f"{100 * f(r) / r['process_cpu_s']:.0f} %"

        solves = lambda x: x["cpu_s"]["solve_s"] + x["cpu_s"]["error_bar_s"]
        outside = lambda x: x["process_cpu_s"] - solves(x)
        lines.append(f"| {r['length_m'] / 1000:g} km | {cell(lambda x: x['process_cpu_s'])} | {cell(solves)} | "
                     f"{cell(outside)} ({share(outside)}) | {cell(issue_part_s)} ({share(issue_part_s)}) | "
                     f"{cell(lambda x: x['cpu_s']['build_s'])} ({cell(lambda x: x['cpu_s']['references_s'])}) | "
                     f"{cell(lambda x: x['cpu_s']['post_s'])} | {cell(lambda x: x['cpu_s']['write_s'])} |")
    return "\n".join(lines)


def cold_table(pairs) -> str:
    """Markdown table of ``--compare-cold``: each length's run with the solved mesh started from the
    coarse solve (nested) and from the rope start (cold), in processes run one after the other."""
    lines = ["| route | Newton, solve (nested / cold) / error bar | solve CPU [s] nested / cold | "
             "solve + error bar CPU [s] nested / cold (ratio) | whole process CPU [s] nested / cold (ratio) | "
             "F nested − cold [N] |", "|---|---|---|---|---|---|"]
    for r, c in pairs:
        both = lambda x: x["cpu_s"]["solve_s"] + x["cpu_s"]["error_bar_s"]
        dF = (r["pull_force_N"] - c["pull_force_N"]) if r["pull_force_N"] is not None and c["pull_force_N"] is not None else float("nan")
        lines.append(f"| {r['length_m'] / 1000:g} km | {r['newton_iterations']} / {c['newton_iterations']} / "
                     f"{r['error_bar_newton_iterations']} | {r['cpu_s']['solve_s']:.2f} / {c['cpu_s']['solve_s']:.2f} | "
                     f"{both(r):.2f} / {both(c):.2f} ({both(r) / both(c):.2f}) | "
                     f"{r['process_cpu_s']:.2f} / {c['process_cpu_s']:.2f} ({r['process_cpu_s'] / c['process_cpu_s']:.2f}) | "
                     f"{dF:+.2g} |")
    return "\n".join(lines)


def compare(b: dict, a: dict) -> str:
    """One line: CPU time after/before of the whole process, the two solves and everything else, and
    the pulling force's and the rope with clearance's relative change (both runs of one length)."""
    def parts(r):
        cpu, whole = r["cpu_s"], r["process_cpu_s"]
        solves = cpu["solve_s"] + cpu["error_bar_s"]
        return ((whole, solves, whole - solves, issue_part_s(r), cpu["build_s"], cpu["references_s"])
                + tuple(cpu.get(k, 0.0) for k in BUILD_PARTS) + (cpu["post_s"] + cpu["write_s"], cpu["post_s"],
                                                                 cpu["write_s"]))

    names = (("whole", "solves", "outside the solves", "build + post + write", "build", "rope references")
             + BUILD_PART_NAMES + ("post + write", "post", "write"))
    ratios = "  ".join(f"{n} {x:.2f} -> {y:.2f} s ({y / x if x else float('nan'):.2f})"
                       for n, x, y in zip(names, parts(b), parts(a)))

    def rel(key):
        x, y = b[key], a[key]
        return "-" if x is None or y is None else f"{y / x - 1:+.1e}"
    same = "bit for bit" if b["pull_force_N"] == a["pull_force_N"] else "NOT bit for bit"
    return (f"{'':9s}CPU after/before: {ratios}; change of the pulling force {rel('pull_force_N')}, "
            f"of the rope with clearance's {rel('rope_clearance_pull_force_N')}; Newton "
            f"{b['newton_iterations']}/{b['error_bar_newton_iterations']} -> {a['newton_iterations']}/{a['error_bar_newton_iterations']}"
            f"\n{'':9s}pulling force {b['pull_force_N']!r} -> {a['pull_force_N']!r} N ({same})")


def per_iteration(b: dict, a: dict, names=("exudyn", "compiled")) -> str:
    """One line: CPU per Newton iteration of both steady solves, run b (exudyn's element) and run a
    (the compiled one), or as ``names`` say."""
    def each(r):
        n = r["newton_iterations"] + r["error_bar_newton_iterations"]
        return 1e3 * (r["cpu_s"]["solve_s"] + r["cpu_s"]["error_bar_s"]) / max(n, 1), n
    (x, nx), (y, ny) = each(b), each(a)
    return (f"{'':9s}CPU per Newton iteration (solve and error bar): {names[0]} {x:.1f} ms ({nx} iterations), "
            f"{names[1]} {y:.1f} ms ({ny}), ratio {y / x:.2f}")


def static_solver_iteration(length_m: float, reps: int = 5) -> None:
    """CPU time of one one-iteration pseudo-time step (one Newton iteration: two residuals, one
    Jacobian, one factorisation) on the solved mesh of the route of ``length_m`` [m], by Exudyn's
    static solver and by ours with LAPACK's banded LU and with SuperLU, interleaved in this process
    from the same state (median of ``reps``), with the states' difference; then our iteration's CPU
    time by part (the forces: kernel, cable, spring; assembly; factorisation and solve; the rest)."""
    import types

    import numpy as np

    import exucable.model.coupling as coupling
    import exucable.solve.steady as steady
    from exucable.model.build import build_model
    from exucable.scenario.specs import parse_scenario
    from exucable.solve.newton_system import ExudynStatic, OwnStaticNewton

    # the coupling's own timers (kernel, cable) then count this process's CPU time, not wall
    coupling.time = types.SimpleNamespace(perf_counter=time.process_time)
    sc = parse_scenario(route_data(length_m), ROOT, default_name="route")
    first = build_model(sc)
    model = build_model(sc, refine=2.0, check_points_per_element=first.mesh.check_points_per_element,
                        references=first.start)
    solver = steady.SteadySolver(model)
    backends = {"exudyn": ExudynStatic(model.mbs, steady.static_settings),
                "ours, banded LU": OwnStaticNewton(model, solver.spring, linear_solver="banded"),
                "ours, SuperLU": OwnStaticNewton(model, solver.spring, linear_solver="splu")}
    times = {k: [] for k in backends}
    kernel = {k: 0.0 for k in backends}
    cable = {k: 0.0 for k in backends}
    states = {}
    c = model.coupling
    solver.pseudo_step(solver.c0, solver.one_iteration_settings)     # warm-up (kernels loaded)
    for _ in range(reps):
        for name, backend in backends.items():
            solver.static = backend
            solver.store.restore_as_initial()
            solver.spring.anchor_at(steady._cable_part(model, solver.store.saved[0]))
            solver.spring.rate = solver.c0
            model.coupling.forget_evaluation()       # every backend pays its kernel passes
            t, k0, c0 = time.process_time(), c.kernel_time_s, c.cable_time_s
            solver.one_solve(solver.one_iteration_settings)
            times[name].append(time.process_time() - t)
            kernel[name] += c.kernel_time_s - k0
            cable[name] += c.cable_time_s - c0
            states[name] = np.array(model.mbs.systemData.GetODE2Coordinates())
    base = float(np.median(times["exudyn"]))
    step = np.linalg.norm(states["exudyn"] - solver.store.saved[0])
    print(f"one Newton iteration (a one-iteration pseudo-time step), {length_m / 1000:g} km, "
          f"{model.mesh.elements} elements, {states['exudyn'].size} coordinates; CPU, median of {reps}, interleaved:")
    for name in backends:
        m = float(np.median(times[name]))
        diff = np.linalg.norm(states[name] - states["exudyn"]) / step
        print(f"  {name:16s} {1e3 * m:8.1f} ms  ratio to Exudyn's {m / base:5.2f}  step vs Exudyn's {diff:.1e}")
    print(f"  (each iteration here makes two kernel passes: the start's pass is not reused, as it is in a solve)")
    for name in backends:
        line = f"  {name}, by part per iteration [ms]: contact kernel {1e3 * kernel[name] / reps:.1f}, cable element {1e3 * cable[name] / reps:.1f}"
        if name != "exudyn":
            parts = dict(backends[name].time_parts_s)
            parts["forces"] -= kernel[name] + cable[name]      # what is left of the forces: sums, spring, blocks
            line += ", " + ", ".join(f"{'other forces' if k == 'forces' else k} {1e3 * v / reps:.1f}" for k, v in parts.items())
        else:
            line += f", the rest (Exudyn: handover, assembly, SparseLU) {1e3 * (np.sum(times[name]) - kernel[name] - cable[name]) / reps:.1f}"
        print(line)


def profile(length_m: float, top: int = 25, static_solver: str | None = None) -> None:
    """cProfile of one steady run of ``length_m`` [m] (after a short warm-up in this process);
    ``static_solver``: ``[solver] static_solver`` (Exudyn's timers are printed when its solver runs)."""
    import contextlib
    import cProfile
    import io
    import pstats

    from exucable.run import run_scenario
    from exucable.scenario.specs import parse_scenario

    import exudyn as exu

    import exucable.solve.steady as steady

    run_scenario(parse_scenario(route_data(200.0), ROOT, default_name="route"), None, plots=False)
    sc = parse_scenario(route_data(length_m, static_solver=static_solver), ROOT, default_name="route")
    # Exudyn's own timers of its static solver, summed over the solves (they run only when asked
    # for by show.computationTime, which also prints them: the output is captured and dropped)
    parts = ("jacobianODE2", "factorization", "ODE2RHS", "newtonIncrement", "total")
    timers = dict.fromkeys(parts, 0.0)
    base_solver, base_settings = exu.MainSolverStatic, steady.quiet_sparse

    class TimedSolver(base_solver):
        def SolveSystem(self, mbs, settings):
            ok = super().SolveSystem(mbs, settings)
            for k in parts:
                timers[k] += getattr(self.timer, k)
            return ok

    def timed_settings(settings):
        settings = base_settings(settings)
        settings.show.computationTime = True
        return settings

    exu.MainSolverStatic, steady.quiet_sparse = TimedSolver, timed_settings
    pr = cProfile.Profile()
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            pr.enable()
            res = run_scenario(sc, None, plots=False)
            pr.disable()
    finally:
        exu.MainSolverStatic, steady.quiet_sparse = base_solver, base_settings
    s = res.summary
    n = max(s["newton_iterations"], 1)
    if timers["total"] == 0.0:
        print(f"Exudyn's static solver did not run (static_solver = {s['static_solver']!r}; "
              f"--static-solver exudyn for its timers)")
    else:
        print(f"Exudyn's static solver per Newton iteration (its timers, wall): total {1e3 * timers['total'] / n:.1f} ms = "
              + ", ".join(f"{k} {1e3 * timers[k] / n:.1f} ms ({100 * timers[k] / max(timers['total'], 1e-12):.0f} %)"
                          for k in parts[:-1])
              + f"; of the system Jacobian, our contact coupling's and pseudo-time spring's user functions and the "
                f"contact kernel are in the cProfile below")
    buf = io.StringIO()
    st = pstats.Stats(pr, stream=buf)
    st.sort_stats("tottime").print_stats(top)
    print(f"cProfile of {length_m / 1000:g} km: build {s['build_time_s']:.2f} s, solve {s['wall_time_s']:.2f} s, "
          f"Newton {s['newton_iterations']}, kernel {s['kernel_time_s']:.2f} s")
    print(buf.getvalue())
    buf = io.StringIO()
    pstats.Stats(pr, stream=buf).sort_stats("cumulative").print_stats(top)
    print(buf.getvalue())


def newton_parts(length_m: float, reps: int = 5) -> None:
    """CPU time of each part of one Newton iteration of the steady solve on the solved mesh of the
    route of ``length_m`` [m], each part called ``reps`` times on its own through Exudyn's solver
    methods (after one warm-up residual): the residual (the ANCF elements inside Exudyn, our contact
    coupling's user function with the kernel, the pseudo-time spring's), the ODE2 Jacobian (the
    ANCF elements' by automatic differentiation inside Exudyn, the two user functions' sparse
    blocks) with and without the loads' Jacobian, and one whole one-iteration static solve (adds
    the sparse matrix's assembly, its LU factorisation and a second residual)."""
    import types

    import numpy as np
    import exudyn as exu

    import exucable.model.coupling as coupling
    import exucable.solve.steady as steady
    from exucable.model.build import build_model
    from exucable.scenario.specs import parse_scenario

    # the coupling's own timers then count this process's CPU time, not wall
    coupling.time = types.SimpleNamespace(perf_counter=time.process_time)
    sc = parse_scenario(route_data(length_m), ROOT, default_name="route")
    first = build_model(sc)
    model = build_model(sc, refine=2.0, check_points_per_element=first.mesh.check_points_per_element,
                        references=first.start)
    mbs = model.mbs
    spring = steady.PseudoTimeSpring(model)
    spring.rate = steady.initial_spring_rate(model)
    n = mbs.systemData.ODE2Size()
    print(f"one Newton iteration's parts, {length_m / 1000:g} km: {model.mesh.elements} elements x "
          f"{model.mesh.check_points_per_element} check points, {n} coordinates; CPU time per call, "
          f"mean of {reps}:")
    q0 = np.array(mbs.systemData.GetODE2Coordinates())
    rng = np.random.default_rng(0)

    def moved():   # new coordinates each call, so that the coupling's reuse of a kernel pass does not hide it
        mbs.systemData.SetODE2Coordinates(list(q0 + 1e-12 * rng.random(n)))

    def timed(name, f, count=reps):
        c = model.coupling
        t, u, k = time.process_time(), c.user_time_s, c.kernel_time_s
        for _ in range(count):
            f()
        dt, du, dk = [(x1 - x0) / count for x0, x1 in ((t, time.process_time()), (u, c.user_time_s), (k, c.kernel_time_s))]
        print(f"  {name:58s} {1e3 * dt:8.2f} ms  (contact coupling's user functions {1e3 * du:7.2f}, of it the kernel "
              f"{1e3 * dk:7.2f}; the rest {1e3 * (dt - du):7.2f})", flush=True)
        return dt

    solver = exu.MainSolverStatic()
    settings = steady.static_settings()
    solver.InitializeSolver(mbs, settings)
    moved()
    solver.ComputeODE2RHS(mbs)                  # warm-up: the kernel's first call loads it from numba's cache
    timed("residual (ODE2 RHS) at new coordinates", lambda: (moved(), solver.ComputeODE2RHS(mbs)))
    jac = timed("ODE2 Jacobian, no loads' Jacobian (the settings)", lambda: solver.ComputeJacobianODE2RHS(mbs, -1.0, 0.0, 0.0, 0))
    timed("ODE2 Jacobian with the loads' Jacobian (Exudyn's default)", lambda: solver.ComputeJacobianODE2RHS(mbs, -1.0, 0.0, 0.0, 1))
    one = steady.static_settings(tolerance=1.0, max_iterations=1)
    whole = timed("one whole static solve of one Newton iteration", lambda: (moved(), exu.MainSolverStatic().SolveSystem(mbs, one)))
    print(f"  the Jacobian is {100 * jac / whole:.0f} % of the whole iteration")


def clearance_spacing(length_m: float, spacings_m=(0.02, 0.05, 0.10, None)) -> None:
    """The rope with clearance of the route of ``length_m`` [m] at uniform node spacings
    ``spacings_m`` (None: the default chain, graded away from the bends on routes over 400 m), with
    its pulling force against the first (finest) and the CPU time of each solve."""
    from exucable.quasistatic.clearance import default_node_spacing_m, solve_rope_with_clearance
    from exucable.scenario.specs import parse_scenario

    centre = parse_scenario(route_data(length_m), ROOT, default_name="route").build_conduit().centreline
    clearance = DUCT_INNER_RADIUS_M - CABLE_RADIUS_M
    first = None
    for h in spacings_m:
        t0 = time.process_time()
        r = solve_rope_with_clearance(centre, clearance, 0.2, MASS_PER_LENGTH_KG_PER_M * 9.81, 500.0,
                                      node_spacing_m=h)
        cpu = time.process_time() - t0
        first = first if first is not None else r.pull_force_N
        what = (f"uniform spacing {100 * h:5.1f} cm" if h is not None else
                f"the default chain ({100 * default_node_spacing_m(centre, clearance):.1f} cm on the bends, graded)")
        print(f"rope with clearance, {length_m / 1000:g} km, {what}, {len(r.s_conduit_m)} nodes: pulling force "
              f"{r.pull_force_N:.4f} N ({r.pull_force_N / first - 1:+.1e} relative), CPU {cpu:.2f} s", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lengths", type=float, nargs="+", default=[1000.0, 2000.0, 5000.0, 10000.0])
    ap.add_argument("--quick", action="store_true", help="smoke run: 200 m and 400 m")
    ap.add_argument("--profile", action="store_true", help="also cProfile the longest route")
    ap.add_argument("--clearance-spacing", action="store_true",
                    help="also the longest route's rope with clearance at uniform 2, 5, 10 cm and on the default (graded) chain")
    ap.add_argument("--newton-parts", action="store_true",
                    help="also the CPU time of each part of one Newton iteration on the longest route")
    ap.add_argument("--no-figures", action="store_true", help="skip the figures stage")
    ap.add_argument("--compare-cold", action="store_true",
                    help="also run each length with the solved mesh from the rope start (not from the error "
                         "bar's coarse solve) in a process of its own, and print the two side by side")
    ap.add_argument("--cold", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--before", metavar="TREE",
                    help="an exucable source tree to compare with (e.g. `git archive <commit> | tar -x -C TREE`): "
                         "each length runs with it and then with the installed package, interleaved")
    ap.add_argument("--cable-element", choices=("exudyn", "compiled"),
                    help="[solver] cable_element of the runs (default: the scenario default)")
    ap.add_argument("--compare-elements", action="store_true",
                    help="each length with cable_element = \"exudyn\" and then \"compiled\", in processes of their "
                         "own one after the other, and their CPU ratios and pulling forces side by side")
    ap.add_argument("--static-solver", choices=("exucable", "exudyn"),
                    help="[solver] static_solver of the runs (default: the scenario default)")
    ap.add_argument("--compare-static-solver", action="store_true",
                    help="each length with static_solver = \"exudyn\" and then \"exucable\", in processes of "
                         "their own one after the other (CPU ratios, pulling forces), and one Newton iteration "
                         "of each, interleaved in this process")
    ap.add_argument("--case", metavar="LENGTH_M", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.case:
        print(json.dumps(one_case(float(args.case), figures=not args.no_figures, cold=args.cold,
                                  cable_element=args.cable_element, static_solver=args.static_solver)))
        # the child ends as `exucable run` does (exucable.cli.end_process: no interpreter
        # finalisation); a tree from before that (--before) ends with the interpreter's exit
        try:
            from exucable.cli import end_process
        except ImportError:
            return
        end_process(0)
    lengths = [200.0, 400.0] if args.quick else sorted(args.lengths)
    rows, pairs, runs, befores = [], [], [], []
    for L in lengths:
        if args.compare_static_solver:
            b = in_child(L, figures=not args.no_figures, static_solver="exudyn")
            print("exudyn:   " + report(b), flush=True)
            r = in_child(L, figures=not args.no_figures, static_solver="exucable")
            print("exucable: " + report(r), flush=True)
            print(compare(b, r).replace("after/before", "exucable/exudyn"), flush=True)
            print(per_iteration(b, r, names=("exudyn", "exucable")), flush=True)
            static_solver_iteration(L, reps=3 if args.quick else 5)
        elif args.compare_elements:
            b = in_child(L, figures=not args.no_figures, cable_element="exudyn")
            print("exudyn:   " + report(b), flush=True)
            r = in_child(L, figures=not args.no_figures, cable_element="compiled")
            print("compiled: " + report(r), flush=True)
            print(compare(b, r).replace("after/before", "compiled/exudyn"), flush=True)
            print(per_iteration(b, r), flush=True)
        else:
            if args.before:
                b = in_child(L, figures=not args.no_figures, tree=args.before, cable_element=args.cable_element)
                print("before: " + report(b), flush=True)
            r = in_child(L, figures=not args.no_figures, cable_element=args.cable_element,
                         static_solver=args.static_solver)
            print(("after:  " if args.before else "") + report(r), flush=True)
            if args.before:
                print(compare(b, r), flush=True)
                befores.append(b)
        runs.append(r)
        if args.compare_cold:
            c = in_child(L, figures=not args.no_figures, cold=True)
            print(report(c), flush=True)
            pairs.append((r, c))
        if r["status"] != "failed":
            solves = r["cpu_s"]["solve_s"] + r["cpu_s"]["error_bar_s"]
            rows.append((L, r["process_cpu_s"], solves, r["process_cpu_s"] - solves, r["process_s"], issue_part_s(r)))
    if len(rows) >= 2:
        import numpy as np

        L, cpu, solve, rest, w, issue = np.array(rows).T
        fit = lambda y: np.polyfit(np.log(L), np.log(y), 1)[0]
        print(f"CPU time: whole process ∝ L^{fit(cpu):.2f}, the two steady solves ∝ L^{fit(solve):.2f}, everything "
              f"but the solves ∝ L^{fit(rest):.2f}, build (references) + post + write ∝ L^{fit(issue):.2f}; whole "
              f"process wall ∝ L^{fit(w):.2f}; over {', '.join(f'{x:g}' for x in L)} m (least squares on log-log)")
        print(f"share of everything but the solve at {L[-1]:g} m (CPU time): {100 * rest[-1] / cpu[-1]:.0f} %; "
              f"the issue's share, (build with its references + post + write) / whole process: "
              f"{100 * issue[-1] / cpu[-1]:.0f} %")
    if runs:
        print(stage_table(runs, befores if len(befores) == len(runs) else None))
    if pairs:
        print(cold_table(pairs))
    if args.clearance_spacing:
        clearance_spacing(lengths[-1])
    if args.newton_parts:
        newton_parts(lengths[-1])
    if args.profile:
        profile(lengths[-1], static_solver=args.static_solver)


if __name__ == "__main__":
    main()
