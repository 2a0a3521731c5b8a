"""The cable mesh a route and cable need: element length and check points per element.

Pure arithmetic on the route (no Exudyn), so the rule can be stated, tested and printed before
anything runs. The rule (also in scenarios/README.md, "Mesh rule"):

* **Bends.** On a bend of radius R with clearance c = R_in − r, an element of length L_e spans a
  chord whose sagitta is L_e²/(8R). When the sagitta exceeds a few clearances, the element bridges
  the bend instead of lying along its wall and touches it only near its nodes (a row of spikes in
  the contact profile); on a 100 m route (R 3 m, c 2 mm) the pulling force was
  16 % high at 110 elements (sagitta 17 c) and 0.5 % at 440 (sagitta 1.1 c), while at c = 8.4 mm
  110, 220 and 440 elements agreed (sagitta ≤ 4 c). The rule keeps the sagitta ≤ 2 c,
  L_e ≤ √(16 R c), and the turning per element ≤ 0.2 rad (a cubic element departs from an arc
  of angle φ by about Rφ⁴/384), on the tightest curved piece.
* **Straight routes** get at least ``MIN_ELEMENTS`` elements (a cubic element is exactly straight)
  and ``MIN_CHECK_POINTS`` per element.
* **Check points.** Bending stiffness concentrates the contact load at a bend's ends over the
  bending length λ = √(EJ/T) (the decay length of a tensioned beam on a wall); the check points
  are spaced at most λ/4 so that this load is sampled by several points, with at least
  ``MIN_CHECK_POINTS`` and at most ``MAX_CHECK_POINTS`` per element. T is the largest rope
  tension on the route (the shortest λ).

A mesh given by the scenario (``cable.elements`` or ``cable.element_length``) is used as given
when it is no coarser than the rule; coarser by up to the refusal limit it runs with a warning in
the summary; beyond (sagitta > 16 c or turning > 0.5 rad per element) it is refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import ModelError

__all__ = ["MeshPlan", "plan_mesh", "rule_element_length_m", "bending_length_m",
           "MAX_SAGITTA_CLEARANCES", "REFUSE_SAGITTA_CLEARANCES", "MAX_TURN_RAD", "REFUSE_TURN_RAD",
           "MAX_MODEL_CHECK_POINTS", "STEADY_REFINE"]

MAX_SAGITTA_CLEARANCES = 2.0       # rule: chord sagitta ≤ 2 clearances
MAX_TURN_RAD = 0.2                 # rule: turning per element
REFUSE_SAGITTA_CLEARANCES = 16.0   # refused beyond (17 c gave +16 % on a 100 m route)
REFUSE_TURN_RAD = 0.5              # refused beyond (cubic misfit Rφ⁴/384 ≈ 0.16 mm per metre of radius)
MIN_ELEMENTS = 10
#: Steady mode solves on the rule's mesh refined this many times (a given mesh as given) and the
#: rule's own mesh gives its error bar (exucable.solve.error_bar): the rule's mesh was up to 0.13 %
#: off on a down-bend with gravity, its halving within 0.01 % (benchmarks/steady_error_bar.py).
STEADY_REFINE = 2.0
CHECK_POINTS_PER_BENDING_LENGTH = 4
MIN_CHECK_POINTS = 8
MAX_CHECK_POINTS = 200
# elements × check points per element of one model: ~1 kB each (README "Performance"), ~2 GB
MAX_MODEL_CHECK_POINTS = 2_000_000


def bending_length_m(bending_stiffness_N_m2: float, tension_N: float) -> float:
    """λ = √(EJ/T) [m]: length over which a tensioned beam's contact load decays at a bend end."""
    return math.sqrt(bending_stiffness_N_m2 / max(tension_N, 1e-12))


def _curved_radii_m(centreline) -> list[float]:
    return [p.radius_of_curvature_m for p in centreline.pieces if p.is_curved]


def _max_length_m(radius_m: float, clearance_m: float, sagitta_clearances: float, turn_rad: float) -> float:
    """Longest element whose chord sagitta L²/(8R) ≤ k·c and whose turning L/R ≤ φ."""
    return min(math.sqrt(8.0 * radius_m * sagitta_clearances * clearance_m), turn_rad * radius_m)


def rule_element_length_m(centreline, clearance_m: float, cable_length_m: float) -> float:
    """The rule's element length [m] on ``centreline`` (see the module docstring)."""
    lengths = [cable_length_m / MIN_ELEMENTS]
    lengths += [_max_length_m(R, clearance_m, MAX_SAGITTA_CLEARANCES, MAX_TURN_RAD) for R in _curved_radii_m(centreline)]
    return min(lengths)


@dataclass(frozen=True)
class MeshPlan:
    """The mesh a run uses and why.

    Attributes
    ----------
    elements : int
        Number of cable elements.
    element_length_m : float
        Unstretched element length [m].
    check_points_per_element : int
    rule_element_length_m : float
        Element length the rule asks for [m].
    rule_check_points_per_element : int
    bending_length_m : float
        λ = √(EJ/T_max) [m].
    source : str
        ``"rule"``, ``"cable.elements"`` or ``"cable.element_length"``.
    warnings : list of str
        Why a given mesh is coarser than the rule (empty when it is not).
    """

    elements: int
    element_length_m: float
    check_points_per_element: int
    rule_element_length_m: float
    rule_check_points_per_element: int
    bending_length_m: float
    source: str
    warnings: list = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"elements": self.elements, "element_length_m": self.element_length_m,
                "check_points_per_element": self.check_points_per_element,
                "rule_element_length_m": self.rule_element_length_m,
                "rule_check_points_per_element": self.rule_check_points_per_element,
                "bending_length_m": self.bending_length_m, "source": self.source,
                "warnings": list(self.warnings)}


def plan_mesh(centreline, clearance_m: float, cable_length_m: float, bending_stiffness_N_m2: float,
              max_tension_N: float, elements: int | None = None, element_length_m: float | None = None,
              check_points_per_element: int | None = None, refine: float = 1.0) -> MeshPlan:
    """Choose the cable mesh for a route (see the module docstring for the rule).

    Parameters
    ----------
    centreline : Centreline
        The conduit's centreline (``pieces`` with ``is_curved`` and ``radius_of_curvature_m``).
    clearance_m : float
        c = conduit inner radius − cable radius [m].
    cable_length_m : float
    bending_stiffness_N_m2 : float
        EJ [N m²].
    max_tension_N : float
        Largest tension expected on the route [N] (the rope solution's).
    elements, element_length_m : optional
        The scenario's override (``cable.elements`` / ``cable.element_length``), at most one.
    check_points_per_element : int, optional
        The scenario's ``contact.check_points_per_element``.
    refine : float
        Divide the rule's element length by this (``exucable converge``'s levels); an override
        is refined by the same factor.

    Raises
    ------
    ModelError
        A given mesh beyond the refusal limit, naming the key and the element count needed.
    """
    L = float(cable_length_m)
    rule_L = rule_element_length_m(centreline, clearance_m, L)
    lam = bending_length_m(bending_stiffness_N_m2, max_tension_N)
    if elements is not None:
        n0, source = int(elements), "cable.elements"
    elif element_length_m is not None:
        n0, source = max(1, int(math.ceil(L / element_length_m - 1e-9))), "cable.element_length"
    else:
        n0, source = max(1, int(math.ceil(L / rule_L - 1e-9))), "rule"
    n = int(math.ceil(n0 * refine - 1e-9))   # refine the count, so levels keep the exact ratio
    L_e = L / n
    key = "cable.element_length" if source == "cable.element_length" else "cable.elements"
    n_rule = int(math.ceil(L / rule_L - 1e-9))
    warnings = []
    for R in _curved_radii_m(centreline):
        limit = _max_length_m(R, clearance_m, REFUSE_SAGITTA_CLEARANCES, REFUSE_TURN_RAD)
        if L_e > limit * (1 + 1e-12):
            raise ModelError(key, f"elements of {L_e:.4g} m cannot follow the bend of radius {R:.4g} m with "
                             f"{1e3 * clearance_m:.3g} mm clearance: chord sagitta {1e3 * L_e**2 / (8 * R):.3g} mm "
                             f"(at most {REFUSE_SAGITTA_CLEARANCES:g} clearances) and turning "
                             f"{math.degrees(L_e / R):.1f} deg per element (at most {math.degrees(REFUSE_TURN_RAD):.1f}); "
                             f"use at least {int(math.ceil(L / limit))} elements, or omit {key} for the "
                             f"rule's {n_rule}")
    if source != "rule" and L_e > rule_L * (1 + 1e-9):
        warnings.append(f"{key}: elements of {L_e:.4g} m are coarser than the mesh rule's {rule_L:.4g} m "
                        f"({n_rule} elements); the pulling force may be off by more than 0.2 %")
    has_bends = bool(_curved_radii_m(centreline))
    rule_k = MIN_CHECK_POINTS
    if has_bends:      # no bend ends, no concentrated loads to sample on a straight route
        rule_k = int(min(MAX_CHECK_POINTS, max(MIN_CHECK_POINTS,
                                               math.ceil(CHECK_POINTS_PER_BENDING_LENGTH * L_e / lam - 1e-9))))
    if check_points_per_element is None:
        k = rule_k
    else:
        k = int(check_points_per_element)
        if has_bends and k < rule_k and L_e / k > lam / 2:
            warnings.append(f"contact.check_points_per_element: {k} points space {1e3 * L_e / k:.3g} mm apart, "
                            f"more than half the bending length √(EJ/T) = {1e3 * lam:.3g} mm over which bend-end "
                            f"loads concentrate (the rule gives {rule_k})")
    if n * k > MAX_MODEL_CHECK_POINTS:
        what = (f"{key} ({n} elements{f' after refining by {refine:g}' if refine != 1.0 else ''})"
                if source != "rule" else f"the mesh rule's {n} elements (clearance {clearance_m:.3g} m)")
        raise ModelError(key if source != "rule" else "cable.element_length",
                         f"{what} × {k} check points per element = {n * k} check points, more than "
                         f"{MAX_MODEL_CHECK_POINTS} (about 1 kB each: a bound that keeps the run's memory finite); "
                         "give fewer elements (cable.elements or a longer cable.element_length) or fewer "
                         "contact.check_points_per_element")
    return MeshPlan(elements=n, element_length_m=L_e, check_points_per_element=k, rule_element_length_m=rule_L,
                    rule_check_points_per_element=rule_k, bending_length_m=lam, source=source, warnings=warnings)
