"""The error bar of a steady solve: a second, cheaper solve on a coarser mesh.

A steady solve has no time scatter; what bounds its error is the discretisation (element length
and check-point spacing) and the solve's stop tolerance. The mesh part is measured, not assumed
from the mesh rule: the same scenario is solved again on a mesh ``COARSE_RATIO`` times coarser
(fewer elements, the same check points per element, so both spacings grow alike, as in
``exucable converge``), and with the solved mesh h and the coarse one H = r·h

    u_mesh = |F_h − F_H| / (r^p − 1) + ``RESOLUTION_FLOOR`` · |F_h|,   p = ``ASSUMED_ORDER``,

Richardson's error estimate of F_h for an assumed order p, plus a floor for the wiggle that the
check points' places along the bends leave once the sequence has converged (two meshes can agree
by chance closer than either is to the limit). The solve's part is its stop residual:
``steady_residual`` (:class:`exucable.solve.steady.SteadySettings`) × the rope's largest tension
bounds the unbalanced force left, which moves the pulling force by at most that much. The parts
are added (not in quadrature: they may push the same way).

Measured (``benchmarks/steady_error_bar.py``, against the value on meshes 4 and 8 times finer): the
rule's mesh is not yet in the asymptotic range on every route (a 60° down-bend with gravity: +0.13 %
at the rule's 11 elements, −0.009 % at 22, < 0.001 % beyond; coarser than the rule the sequence
jumps by 2 %), so a coarse solve below the rule's mesh says little. Steady mode therefore solves on
the rule's mesh refined ``exucable.scenario.mesh.STEADY_REFINE`` times and takes the rule's own mesh
as the coarse one: there |F_h − F_H| bounded the error of F_h on every case measured, by factors of
2 to 20, except where the two agreed by chance to 5e-6 (a 90° bend: error 6e-5 of the force, within
the floor).

The wall's part (:func:`wall_compliance_N`): the Hertz wall lets the cable sink δ into it, and where a
stiff cable is forced round a bend with little room to cut it the pull comes out below the rigid
wall's. ``studies/wall_compliance_study.py`` (reference/README.md, "The wall's compliance") measured
that a compliant wall acts as a rigid one with the clearance c + δ, and that the bend-end share of
the pull, F − F_rope, scales as c^(-1/2) (the wall forces bending the cable to the bend's radius R
over the length l ~ √(R c) the clearance leaves, ~ EJ/(R l)); so the rigid-wall pull is about
F_rope + (F − F_rope)·√(1 + δ/c), with δ the deepest penetration of the converged state and F_rope the
rope with clearance, and u_wall = ``WALL_FACTOR`` · |F − F_rope|·(√(1 + δ/c) − 1). It is a bound: where
the cable has room to cut the bend, F − F_rope does not depend on c at all. The pulling force
reported stays the simulated one; the bar covers the rigid wall's.

Several cables (:func:`bundle_error_bar`): the same parts, each from what a bundle's solve has. The
solve's part is the stop tolerance (:func:`exucable.solve.steady.stop_tolerance_N`) carried to the eye:
an unbalanced force f left anywhere on the cables raises the tension behind it by f, and a tension
increment grows through the bends at most by the capstan factor e^(w μ Θ) (Θ the route's turning
angle, w the bundle's weight correction factor, the larger of the calculators' and the one that
emerged), so u_solve = tol · e^(w μ Θ) (:func:`bundle_solve_part_N`). The onset layer's part
(:func:`onset_layer_part_N`): the contact law is continued from a smooth onset layer s down to 0
(:mod:`exucable.solve.onset_continuation`); Richardson's step (p = 1) on the two thinnest layers above 0
gives F₀, and |F − F₀| bounds what the layers leave: the answer's own error where the continuation
stopped at a finite layer, and where it reached s = 0 the disagreement between the two ways to s → 0
(reference/README.md, "Through a smooth contact onset": 0.004 to 0.028 N on the up-bend study). The
mesh part is a second bundle solve on a mesh ``COARSE_RATIO`` times coarser, with the assumed order
``BUNDLE_ASSUMED_ORDER`` (0.5: bundles converge slower than one cable on the rule's mesh), from the start that gave
the answer (``bundle_starts``: another start may land on another steady state), made only where the
solve's CPU budget has room for it (as much CPU time left as the fine solve took,
:data:`BUNDLE_COARSE_COST`); otherwise the bar is the solve's parts only and its method says that
the mesh part was not measured, and why. A bundle has several stable steady states in places (the
up-bend's triangle: 466.6 and 468.455 N, both with every eigenvalue positive); the bar covers the
one found, not the distance to another. The wall's compliance part is one cable's only.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

__all__ = ["SteadyErrorBar", "steady_error_bar", "combine", "wall_compliance_N", "with_wall_compliance",
           "bundle_error_bar", "bundle_solve_part_N", "onset_layer_part_N", "coarse_solve_skipped",
           "COARSE_RATIO", "ASSUMED_ORDER", "RESOLUTION_FLOOR", "WALL_WARNING", "WALL_FACTOR", "BUNDLE_COARSE_COST",
           "BUNDLE_ASSUMED_ORDER"]

#: The coarse mesh has this many times fewer elements than the solved one.
COARSE_RATIO = 2.0

#: Order of convergence assumed for the error estimate: the lowest plausible one, so the estimate
#: is |F_h − F_H| itself (benchmarks/steady_error_bar.py: the error of F_h was below it on every case
#: measured but one within the floor).
ASSUMED_ORDER = 1.0

#: Relative floor of the mesh part [-]: the largest change seen on meshes finer than the solved one
#: once the sequence had converged, 6e-5 of the force (a 90° bend, benchmarks/steady_error_bar.py),
#: rounded up.
RESOLUTION_FLOOR = 1e-4

#: The wall's part above this fraction of the force: the run warns, naming ``contact.stiffness``
#: (the stiff cable at 0.5 mm clearance: 0.6 % at K 1e8, where the pull is 0.55 % below the rigid wall's).
WALL_WARNING = 0.005

#: The wall's part is the law's estimate times this: the study's runs inside the penetration limit
#: fell short of the rigid wall by 0.82 to 1.45 times the estimate (stiff cable, c 0.25-2 mm, K 1e6-1e9).
WALL_FACTOR = 1.5

#: Order of convergence assumed for a bundle's mesh part (u_mesh = |F_h − F_H| / (2^p − 1), 2.41 times
#: the difference): on the up-bend study's down-bend cradle the pulls on 5, 10, 20, 40 elements per cable
#: (409.009, 410.040, 410.882, 411.387 N) converge at an observed order of 0.3 to 0.7, and one cable's
#: p = 1 left the error of the 10 elements' pull against the 40 elements', 1.35 N, outside its bar of
#: 1.10 N (reference/README.md, "A bundle's error bar").
BUNDLE_ASSUMED_ORDER = 0.5

#: A bundle's coarse solve is made where the CPU time left of the budget is at least this times the
#: fine solve's (the start that gave the answer). Half the unknowns, but not half the cost: the coarse
#: solve took 0.84 times the fine one's CPU on the 100 m cradle (its dynamic relaxation's steps do not
#: halve) and 0.31 to 2.1 times on the up-bend study's cases (reference/README.md, "A bundle's error
#: bar"); it may use no more than the time left, so the budget holds whatever it costs.
BUNDLE_COARSE_COST = 1.0


@dataclass(frozen=True)
class SteadyErrorBar:
    """The uncertainty of a steady solve's result.

    Attributes
    ----------
    uncertainty_N : float or None
        u_mesh + u_solve (+ u_wall once added, :func:`with_wall_compliance`) [N]; None when the
        coarse solve could not be made.
    mesh_N : float or None
        u_mesh [N].
    solve_N : float
        u_solve [N].
    coarse_value_N : float or None
        The coarse mesh's value [N].
    coarse_elements : int or None
        Its element count.
    method : str
        How it was made, in words (the summary's ``pull_force_uncertainty_method``).
    wall_time_s : float
        The coarse solve's wall time, model build included [s].
    wall_N : float or None
        u_wall, the wall's compliance (:func:`wall_compliance_N`) [N]; None until added.
    layer_N : float or None
        Several cables: u_layer, the contact onset layer's part (:func:`onset_layer_part_N`) [N].
    cpu_time_s : float or None
        Several cables: the coarse solve's CPU time, its build included [s] (None: not made).
    """

    uncertainty_N: float | None
    mesh_N: float | None
    solve_N: float
    coarse_value_N: float | None
    coarse_elements: int | None
    method: str
    wall_time_s: float
    wall_N: float | None = None
    layer_N: float | None = None
    cpu_time_s: float | None = None

    def to_dict(self) -> dict:
        out = {"uncertainty_N": self.uncertainty_N, "mesh_N": self.mesh_N, "solve_N": self.solve_N,
               "wall_N": self.wall_N,
               "coarse_value_N": self.coarse_value_N, "coarse_elements": self.coarse_elements,
               "method": self.method, "wall_time_s": self.wall_time_s}
        if self.layer_N is not None:     # several cables' parts (one cable's keys unchanged)
            out.update(layer_N=self.layer_N, cpu_time_s=self.cpu_time_s)
        return out


def combine(value_N: float, coarse_N: float, elements: int, coarse_elements: int, solve_N: float,
            order: float = ASSUMED_ORDER) -> tuple[float, float]:
    """u_mesh = |F_h − F_H| / (r^p − 1) + floor·|F_h| with r = elements / coarse_elements, and
    u_mesh + u_solve [N]."""
    r = elements / coarse_elements
    mesh = abs(value_N - coarse_N) / (r**order - 1.0) + RESOLUTION_FLOOR * abs(value_N)
    return mesh, mesh + solve_N


def wall_compliance_N(value_N: float, rope_N: float, max_penetration_m: float, clearance_m: float) -> float:
    """u_wall = ``WALL_FACTOR`` · |F − F_rope|·(√(1 + δ/c) − 1) [N]: how much higher the pull can be
    against a rigid wall.

    Parameters
    ----------
    value_N : float
        The simulated force F [N].
    rope_N : float
        The rope's (with clearance, where there is one) value of the same force [N].
    max_penetration_m : float
        The deepest penetration δ of the converged state [m].
    clearance_m : float
        c = R_in − r [m].
    """
    if not (clearance_m > 0.0 and math.isfinite(value_N) and math.isfinite(rope_N)):
        return 0.0
    x = max(float(max_penetration_m), 0.0) / clearance_m
    return WALL_FACTOR * abs(value_N - rope_N) * (math.sqrt(1.0 + x) - 1.0)


def with_wall_compliance(bar: SteadyErrorBar, value_N: float, rope_N: float, max_penetration_m: float,
                         clearance_m: float) -> SteadyErrorBar:
    """``bar`` with the wall's part u_wall (:func:`wall_compliance_N`) added to its uncertainty and method."""
    if bar.uncertainty_N is None:
        return bar
    wall = wall_compliance_N(value_N, rope_N, max_penetration_m, clearance_m)
    method = (f"{bar.method}; plus the wall's compliance {WALL_FACTOR:g} x |F - F_rope| x (sqrt(1 + d/c) - 1) with the deepest "
              f"penetration d = {1e3 * max_penetration_m:.3g} mm, clearance c = {1e3 * clearance_m:.3g} mm "
              f"(a compliant wall acts as a rigid one with the clearance c + d)")
    return dataclasses.replace(bar, uncertainty_N=bar.uncertainty_N + wall, wall_N=wall, method=method)


def steady_error_bar(scenario, model, value_N: float, quantity: str, coarse=None,
                     refine: float = 1.0, coarse_outcome=None) -> SteadyErrorBar:
    """Solve ``scenario`` again on a mesh ``COARSE_RATIO`` times coarser than ``model``'s and state
    the uncertainty of ``value_N`` (the solved model's ``quantity``: ``"pull_force_N"`` or
    ``"trailing_tension_N"``) [N].

    ``coarse``: that coarser model, already built (steady mode on the mesh rule builds the rule's
    mesh first); otherwise it is built here at ``refine`` / ``COARSE_RATIO`` (``refine``: the solved
    model's) with the solved model's check points per element. ``coarse_outcome``: ``coarse``'s steady
    solve, already made (steady mode solves the coarse mesh first and starts the solved mesh from
    its state, :func:`exucable.solve.start.nested_start`), its state still the model's; otherwise
    it is solved here from the rope start.

    Never raises for a coarse mesh the rule refuses or a coarse solve that fails: the result then
    has ``uncertainty_N = None`` and the method says why.
    """
    from ..errors import ModelError
    from ..model.build import build_model
    from .steady import SteadySettings, solve_steady, steady_forces

    t0 = time.perf_counter()
    T_max = model.rope.max_tension_N if getattr(model, "rope", None) is not None else abs(value_N)
    settings = SteadySettings.from_solver(scenario.solver)   # the solved model's stop rule, so both stop alike
    stop = settings.steady_residual   # the coarse solve's stop residual [-]
    solve_N = stop * T_max
    n = model.mesh.elements
    k = model.mesh.check_points_per_element
    head = f"second steady solve on a mesh {COARSE_RATIO:g}x coarser"
    if coarse is None:
        try:
            coarse = build_model(scenario, refine=refine / COARSE_RATIO, check_points_per_element=k,
                                 references=getattr(model, "start", None))
        except ModelError as exc:
            return SteadyErrorBar(None, None, solve_N, None, None, f"{head} not possible: {exc}",
                                  time.perf_counter() - t0)
    m = coarse.mesh.elements
    if m >= n:
        return SteadyErrorBar(None, None, solve_N, None, m, f"{head} not possible: {n} elements cannot be coarsened",
                              time.perf_counter() - t0)
    if coarse_outcome is None:
        out = solve_steady(coarse, settings=settings)
    else:
        out = coarse_outcome
        t0 -= out.wall_time_s   # the bar's cost includes its solve, made before this call
    if out.status == "failed":
        return SteadyErrorBar(None, None, solve_N, None, m, f"{head} failed ({out.message})", time.perf_counter() - t0)
    pull, trail, _ = steady_forces(coarse)
    coarse_N = trail if quantity == "trailing_tension_N" else pull
    mesh_N, total = combine(value_N, coarse_N, n, m, solve_N)
    r = n / m
    method = (f"{head} ({m} elements x {coarse.mesh.check_points_per_element} check points against {n} x {k}): "
              f"mesh = |F - F_coarse| / "
              f"(r^p - 1) with r = {r:.4g} and an assumed order p = {ASSUMED_ORDER:g} "
              f"(Richardson's error estimate) + {RESOLUTION_FLOOR:g} x |F|; plus the steady solve's stop residual "
              f"{stop:g} x the rope's largest tension; added")
    if not math.isfinite(total):
        return SteadyErrorBar(None, None, solve_N, coarse_N, m, f"{head}: not finite", time.perf_counter() - t0)
    return SteadyErrorBar(total, mesh_N, solve_N, coarse_N, m, method, time.perf_counter() - t0)


def bundle_solve_part_N(model, settings, weight_correction: float | None = None) -> tuple[float, float]:
    """u_solve of several cables' steady solve: the stop tolerance × e^(w μ Θ) [N], and that
    capstan factor [-] (module notes).

    An unbalanced force f left at a station raises the tension behind it by at most f; through the
    bends a tension increment grows at most as the capstan's dT/dθ = w μ T, so by e^(w μ Θ) with Θ
    the route's whole turning angle, μ the wall's friction and w the largest of the calculators'
    weight correction factor, ``weight_correction`` (the one that emerged, where known) and 1 (the
    cables' wedging raises the wall's normal force by w).

    Parameters
    ----------
    model : exucable.model.bundle.BundleModel
        The solved bundle.
    settings : exucable.solve.steady.SteadySettings
        The solve's settings (``steady_residual``).
    """
    from ..quasistatic import engineering as eng
    from .steady import stop_tolerance_N

    sc = model.scenario
    D, d = 2.0 * sc.conduit.inner_radius_m, 2.0 * sc.cable.radius_m
    w = max(1.0, float(eng.weight_correction_factor(model.n_cables, model.arrangement, D, d)),
            float(weight_correction or 0.0))
    gain = math.exp(w * float(sc.contact.friction) * model.conduit.centreline.turning_angle_rad)
    return stop_tolerance_N(model, settings) * gain, gain


def onset_layer_part_N(onset: dict | None) -> float:
    """u_layer: what the contact onset layer's continuation leaves in the answer [N] (module notes).

    ``onset``: the continuation's summary (:meth:`exucable.solve.onset_continuation.OnsetContinuation.summary`).
    At a finite layer, the answer's distance from Richardson's s → 0 extrapolation (inf where only one
    layer solved); at s = 0, the solved answer's distance from the extrapolation of the two thinnest
    layers above 0 (0 where fewer than two solved). None of a summary: 0 (no layer, the law itself).
    """
    from .onset_continuation import extrapolate_to_zero

    if not onset:
        return 0.0
    if onset["layer_m"] > 0.0:
        err = onset["layer_error_N"]
        return float("inf") if err is None else float(err)
    done = [st for st in onset["stages"] if st["converged"] and st["pull_force_N"] is not None]
    finite = [st for st in done if st["layer_m"] > 0.0][-2:]
    if len(finite) < 2 or done[-1]["layer_m"] != 0.0:
        return 0.0
    f0, _ = extrapolate_to_zero([st["layer_m"] for st in finite], [st["pull_force_N"] for st in finite])
    return abs(float(done[-1]["pull_force_N"]) - f0)


def coarse_solve_skipped(error_bar: bool, cpu_left_s: float, fine_cpu_s: float) -> str | None:
    """Why a bundle's coarse solve is not made (None: it is): not asked for, or the CPU budget left,
    ``cpu_left_s`` [s], is below ``BUNDLE_COARSE_COST`` × the fine solve's ``fine_cpu_s`` [s]."""
    if not error_bar:
        return "not asked for (error_bar=False)"
    need = BUNDLE_COARSE_COST * fine_cpu_s
    if cpu_left_s < need:
        return (f"{max(cpu_left_s, 0.0):.3g} s CPU left of the steady budget (solver.steady_time_limit), a coarse "
                f"solve takes about {need:.3g} s ({BUNDLE_COARSE_COST:g} x the fine solve's {fine_cpu_s:.3g} s)")
    return None


def bundle_error_bar(scenario, model, value_N: float, onset: dict | None, settings, start: str,
                     refine: float = 1.0, cpu_left_s: float | None = None, skip: str | None = None,
                     weight_correction: float | None = None) -> SteadyErrorBar:
    """The uncertainty of several cables' steady pull ``value_N`` [N] (module notes): u_solve + u_layer,
    plus u_mesh from a second solve on a mesh ``COARSE_RATIO`` coarser unless ``skip`` says why not.

    Parameters
    ----------
    scenario : exucable.scenario.Scenario
        The bundle's scenario.
    model : exucable.model.bundle.BundleModel
        The solved bundle (its mesh, stop tolerance and arrangement).
    value_N : float
        Its pulling force [N].
    onset : dict or None
        The solve's onset layer summary (``SolveOutcome.onset_layer``).
    settings : exucable.solve.steady.SteadySettings
        The fine solve's settings; the coarse solve keeps them but for the start and the CPU limit.
    start : str
        The start that gave the answer (``bundle_starts``' entry): the coarse solve's only start.
    refine : float
        The fine model's ``refine``; the coarse one is built at ``refine / COARSE_RATIO``.
    cpu_left_s : float, optional
        The coarse solve's CPU limit [s] (what is left of the budget); default the fine solve's
        ``settings.time_limit_s``.
    skip : str, optional
        Why the coarse solve is not made (:func:`coarse_solve_skipped`).
    weight_correction : float, optional
        The weight correction factor that emerged [-] (:func:`bundle_solve_part_N`).

    Never raises for a coarse mesh the rule refuses or a coarse solve that fails: the bar is then
    the solve's parts, and the method says the mesh part was not measured and why.
    """
    from dataclasses import replace

    from ..errors import ModelError
    from ..model.bundle import build_bundle_model
    from .bundle_starts import solve_bundle_starts

    t0, c0 = time.perf_counter(), time.process_time()
    solve_N, gain = bundle_solve_part_N(model, settings, weight_correction)
    layer_N = onset_layer_part_N(onset)
    parts = solve_N + layer_N
    solve_text = (f"the steady solve's stop residual {settings.steady_residual:g} x the rope's largest tension x the "
                  f"capstan factor e^(w mu Theta) = {gain:.3g} = {solve_N:.2g} N; the contact onset layer's "
                  f"|F - F0| (Richardson on the two thinnest layers) = {layer_N:.2g} N")
    n = model.mesh.elements
    head = f"second bundle steady solve on a mesh {COARSE_RATIO:g}x coarser from the start \"{start}\""

    def parts_only(why: str, m=None, coarse_N=None) -> SteadyErrorBar:
        return SteadyErrorBar(parts, None, solve_N, coarse_N, m,
                              f"solve parts only, mesh part not measured ({why}): {solve_text}; added; "
                              "the bar covers the steady state found (a bundle may have several)",
                              time.perf_counter() - t0, layer_N=layer_N,
                              cpu_time_s=None if m is None else time.process_time() - c0)

    if skip is not None:
        return parts_only(skip)
    try:
        coarse = build_bundle_model(scenario, refine=refine / COARSE_RATIO, start_path=start)
    except ModelError as exc:
        return parts_only(f"{head} not possible: {exc}")
    m = coarse.mesh.elements
    if m >= n:
        return parts_only(f"{head} not possible: {n} elements cannot be coarsened")
    # the solver's settings refuse an unlimited time, so no limit given means the fine solve's own
    limit_s = settings.time_limit_s if cpu_left_s is None else cpu_left_s
    left = limit_s - (time.process_time() - c0)
    if left <= 0.0:
        return parts_only(f"{head}: no CPU time left after its build", m)
    out = solve_bundle_starts(scenario, coarse, refine=refine / COARSE_RATIO,
                              settings=replace(settings, bundle_starts=(start,), time_limit_s=left)).outcome
    if out.status == "failed":
        return parts_only(f"{head} failed: {out.message}", m)
    coarse_N = float(np.sum(coarse.pull_shares_N()))
    mesh_N, total = combine(value_N, coarse_N, n, m, parts, order=BUNDLE_ASSUMED_ORDER)
    method = (f"{head} ({m} elements per cable against {n}): mesh = |F - F_coarse| / (r^p - 1) with r = {n / m:.4g} "
              f"and an assumed order p = {BUNDLE_ASSUMED_ORDER:g} (Richardson's error estimate) + {RESOLUTION_FLOOR:g} x |F|; "
              f"plus {solve_text}; added; the bar covers the steady state found (a bundle may have several)")
    if not math.isfinite(total):
        return parts_only(f"{head}: not finite", m, coarse_N)
    return SteadyErrorBar(total, mesh_N, solve_N, coarse_N, m, method, time.perf_counter() - t0,
                          layer_N=layer_N, cpu_time_s=time.process_time() - c0)
