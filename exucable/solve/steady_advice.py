"""Why a steady solve that did not converge stopped, and what to change that would help.

A steady solve that fails names where it got to (the load scale λ reached, the residual against its
stop) and the strain the rope reference puts at the head (its largest tension over the cable's EA;
above a few per cent, check the modulus), and advises by cause: a solve that ran out of time while
still converging (or before anything converged) needs more time; one that stalled, a coarser mesh or
the dynamic run. Several cables that stall are sent to the dynamic run alone: their steady solve stalls
where the cables rearrange across the duct (three cables through an up-bend turn their triangle over:
a soft, at times unstable sideways mode and grazing contacts that switch), and there the mesh rule's
coarsest mesh stalled too (`studies/bundle_upbend_study.py`, reference/README.md), while the dynamic
pull follows the cables as they move (a short dynamic pull's state let the steady solve of that bend
converge: `studies/bundle_settle_start.py`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["head_strain", "failure_advice", "LARGE_STRAIN", "TIME_LIMIT_KEY"]

#: Axial strain at the head [-] above which the message asks to check the modulus: cables are not
#: pulled that hard in practice (manufacturers' pulling limits keep the conductors' strain well under 1 %).
LARGE_STRAIN = 0.02

#: The scenario key of the steady solve's time limit.
TIME_LIMIT_KEY = "solver.steady_time_limit"

_MESH_FIX = ('a coarser mesh (larger `cable.element_length`, or fewer `contact.check_points_per_element`) '
             'or the dynamic run (`solver.mode = "dynamic"` with a `solver.end_time`)')

_BUNDLE_FIX = ('the dynamic run (`solver.mode = "dynamic"` with a `solver.end_time`), which follows the cables '
               'as they rearrange across the duct (where several cables\' steady solve stalls, a coarser mesh '
               'has not helped)')


def _triangle_note(model) -> str:
    """For three cables laid triangular in a duct where the calculators take them cradled (D/d ≥
    2.5, :func:`exucable.quasistatic.engineering.auto_arrangement`), the arrangement that does solve
    and why the triangle may not; else "".

    Why: pressed onto a bend's wall by tensions far above their weight, the triangle's top cable
    sits on a crest of the other two (its stiffness with them held has negative eigenvalues) and
    falls into the cradle's place, climbing back on the straights; the steady solve follows that
    rearrangement on the 100 m route only from the cross-section's statics start (the default
    ``solver.bundle_starts``' second), and not on the industry plan from any start, where the
    cradled arrangement solves (reference/README.md, "The industry three-cable plan: the top cable
    falls off in the bends" and "A start sequence")."""
    from ..quasistatic.engineering import auto_arrangement

    sc = getattr(model, "scenario", None)
    if sc is None or getattr(model, "n_cables", 1) != 3 or getattr(model, "arrangement", "") != "triangular":
        return ""
    D, d = 2.0 * sc.conduit.inner_radius_m, 2.0 * sc.cable.radius_m
    if auto_arrangement(3, D, d) != "cradled":
        return ""
    return (f"; or `cable.arrangement = \"cradled\"` (the calculators' arrangement at D/d {D / d:.3g} ≥ 2.5): "
            "at this D/d a triangle's top cable falls off the other two in the bends, a rearrangement the "
            "steady solve does not always follow")


def head_strain(model) -> tuple[float, float, float]:
    """The rope reference's largest tension [N], the cable's axial stiffness EA [N] and their ratio,
    the axial strain at the head [-] (NaN without a rope reference)."""
    EA = float(model.scenario.cable.axial_stiffness_N)
    if model.rope is None or EA <= 0.0:
        return float("nan"), EA, float("nan")
    T = float(np.max(np.abs(model.rope.tension_N)))
    return T, EA, T / EA


def failure_advice(model, *, load_scale: float, residual_N: float, tolerance_N: float, timed_out: bool,
                   still_converging: bool, time_limit_s: float | None,
                   residual_load_scale: float | None = None) -> str:
    """The cause of a failed steady solve and what to change, in one sentence for its message.

    Parameters
    ----------
    model : Model
        The steady model (its scenario and rope reference).
    load_scale : float
        The load scale λ [-] of the last equilibrium reached (1: the full loads).
    residual_N, tolerance_N : float
        The smallest equilibrium residual reached at the next load scale and the stop [N].
    timed_out : bool
        Whether the solve stopped at its time limit (``time_limit_s`` CPU seconds).
    still_converging : bool
        Whether the residual was still falling when it stopped.
    residual_load_scale : float, optional
        The load scale λ [-] at which ``residual_N`` was reached, named where it is not the next one
        after ``load_scale`` would suggest (a solve that failed at the full loads before any ramp
        reached λ = 0 and its residual at λ = 1).
    """
    T, EA, strain = head_strain(model)
    reached = (f"residual {residual_N:.3g} N" if np.isfinite(residual_N) else "no pseudo-time step accepted")
    if np.isfinite(residual_N) and residual_load_scale is not None and residual_load_scale != load_scale:
        reached += f" at load scale {residual_load_scale:.3g}"
    where = (f"load scale reached {load_scale:.3g} of 1, {reached} (stop at {tolerance_N:.3g} N), "
             f"strain at the head {100 * strain:.3g} % (the rope's {T:.4g} N over EA {EA:.4g} N)")
    if np.isfinite(strain) and strain > LARGE_STRAIN:
        # reported, not blamed: soft cables at 4.7 % and 7.3 % strain at the head converge
        # (a 1 km route with ten 30° bends, a 100 m one with two); a strain like this is more often
        # a wrong modulus than a real pull
        where += (f"; a strain above {100 * LARGE_STRAIN:g} % is beyond cables' pulling limits: check "
                  "`cable.youngs_modulus`")
    fix = _BUNDLE_FIX if getattr(model, "n_cables", 1) > 1 else _MESH_FIX
    fix += _triangle_note(model)
    if timed_out and (still_converging or not np.isfinite(residual_N)):
        why = "the residual was still falling" if still_converging else "nothing had converged yet"
        return (f"{where}: {why} when the time limit of {time_limit_s:g} s CPU ran out; "
                f"fix: a larger `{TIME_LIMIT_KEY}`, or {fix}")
    return f"{where}; fix: {fix}"
