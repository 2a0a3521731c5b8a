"""The one table of scenario keys: TOML key, dataclass attribute, unit, default, check, rule.

Every key of a scenario is one :class:`Field` row in :data:`FIELDS`. The row drives

- the TOML parser and the Python constructors (:mod:`exucable.scenario.specs`): type, bounds,
  default, the dotted key and unit in every error message;
- ``to_dict`` of each spec dataclass (the TOML name of each attribute);
- the key tables of ``scenarios/README.md``: :func:`markdown_table` renders them and a test
  checks the README against it (``python -m exucable.commands.key_tables`` rewrites them).

To add a key: add a row here, the attribute to the section's dataclass, and rerun
``python -m exucable.commands.key_tables`` to update the README. Cross-field rules (e.g.
``static_friction >= friction``) live in the dataclass's ``_check`` method; keys whose value is
not a scalar (the conduit route) are ``kind="custom"`` and parsed by hand.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["REQUIRED", "Field", "FIELDS", "SECTIONS", "fields_of", "default_of", "markdown_table", "format_default",
           "readme_with_tables", "range_text"]


class _Required:
    """Sentinel: the key has no default."""

    def __repr__(self) -> str:
        return "REQUIRED"


REQUIRED: Any = _Required()

#: Sections in file order; "" is the top level.
SECTIONS = ("", "cable", "conduit", "contact", "pull", "gravity", "solver", "output", "limits", "display")

#: Heading of each section's key table in scenarios/README.md.
SECTION_HEADINGS = {
    "": "## Top level",
    "cable": "## `[cable]` (paper Sect. 2.2)",
    "conduit": "## `[conduit]` (paper Sect. 2.3)",
    "contact": "## `[contact]` (optional; paper Sect. 2.4–2.5, Eqs. 17–23)",
    "pull": "## `[pull]` (paper Sect. 2.1, Eq. 1)",
    "gravity": "## `[gravity]` (optional; absent = no gravity)",
    "solver": "## `[solver]`",
    "output": "## `[output]` (optional; snapshots, see docs/results-format.md)",
    "limits": "## `[limits]` (optional; checked by `exucable plan`)",
    "display": "## `[display]` (optional; units of bare numbers and printed tables)",
}


@dataclass(frozen=True)
class Field:
    """One scenario key.

    Attributes
    ----------
    key : str
        Dotted TOML key, e.g. ``"pull.speed"`` (top-level keys have no dot).
    attr : str
        Attribute of the section's dataclass, with its unit, e.g. ``"speed_m_per_s"``.
    kind : str
        ``"float"``, ``"int"``, ``"bool"``, ``"str"``, ``"strings"`` (an array of non-empty strings),
        ``"choice"``, ``"vector3"`` or ``"custom"``
        (parsed by hand; only documented here).
    unit : str
        Unit as written in error messages (ASCII, e.g. ``"kg/m^3"``); ``""`` for none.
    default : Any
        The default value, ``None`` (absent: the key is optional and has no value), or
        :data:`REQUIRED`. A *derived* default (``derived=True``) is ``None`` here and computed
        by the dataclass from other values.
    rule : str
        The README's "rule" column (Markdown).
    default_doc : str
        The README's "default" column when the default is not a plain value ("" = render
        :attr:`default`).
    unit_doc : str
        The README's unit when it differs from :attr:`unit` (e.g. ``"kg/m³"``).
    gt, ge, lt, le : float or None
        Bounds checked for numbers.
    choices : tuple of str
        Allowed strings for ``kind="choice"``.
    ours : bool
        The key is not in the paper (marked *ours* in the README).
    derived : bool
        The default is computed from other values (so ``Scenario.replace`` re-derives it).
    nonzero : bool
        For ``vector3``: refuse [0, 0, 0].
    why : str
        Why the outer bounds are where they are (a plausibility range, or what keeps the run finite):
        said in the error message and the README's rule.
    max_abs : float or None
        For ``vector3``: largest magnitude of a component.
    """

    key: str
    attr: str
    kind: str
    unit: str = ""
    default: Any = REQUIRED
    rule: str = ""
    default_doc: str = ""
    unit_doc: str | None = None
    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None
    choices: tuple[str, ...] = ()
    ours: bool = False
    derived: bool = False
    nonzero: bool = False
    why: str = ""
    max_abs: float | None = None

    @property
    def section(self) -> str:
        """The table the key is in (``""`` for the top level)."""
        return self.key.rpartition(".")[0]

    @property
    def name(self) -> str:
        """The key inside its table."""
        return self.key.rpartition(".")[2]

    @property
    def bounds(self) -> dict:
        """The non-None bounds as keyword arguments."""
        return {k: v for k, v in (("gt", self.gt), ("ge", self.ge), ("lt", self.lt), ("le", self.le))
                if v is not None}

    @property
    def readme_unit(self) -> str:
        return self.unit if self.unit_doc is None else self.unit_doc


F = Field
# Kelvin-Voigt retardation time [s]: damps the element-scale axial modes of the paper's
# cables (omega ~ 1e3..1e4 rad/s -> damping ratio tau*omega/2 ~ 0.5..5) while the
# steady-state damping force tau*EA*d(eps)/dt stays negligible (material strain rate is tiny).
_DAMPING_TIME_S = 1.0e-3

FIELDS: tuple[Field, ...] = (
    # ---- top level
    F("name", "name", "str", default=None, derived=True, default_doc="file stem", rule="non-empty string"),
    F("description", "description", "str", default="", rule="string"),
    # ---- cable (paper Sect. 2.2)
    F("cable.radius", "radius_m", "float", "m", gt=0.0, ge=1.0e-5, rule="> 0", le=1.0, why="a cable from 20 µm to 2 m across"),
    F("cable.density", "density_kg_per_m3", "float", "kg/m^3", None, unit_doc="kg/m³", gt=0.0, ge=1.0, default_doc="—",
      rule="> 0; give exactly one of `density`, `mass_per_length`", le=1.0e5, why="foam to four times osmium's density"),
    F("cable.mass_per_length", "mass_per_length_kg_per_m", "float", "kg/m", None, gt=0.0, ge=1.0e-7, default_doc="—",
      rule="> 0", le=1.0e4, why="a cable's mass per length, a glass fibre to the heaviest submarine cable"),
    F("cable.youngs_modulus", "youngs_modulus_Pa", "float", "Pa", gt=0.0, ge=1.0e5, rule="> 0", le=1.0e13, why="the range of cable materials, soft rubber to beyond diamond; a value like 1000 is usually MPa written as Pa (1000 MPa = 1e9 Pa)"),
    F("cable.bending_stiffness", "bending_stiffness_given_N_m2", "float", "N m^2", None, unit_doc="N m²", gt=0.0, ge=1.0e-12,
      ours=True, default_doc="E π r⁴/4",
      rule="> 0: EJ of a stranded or layered cable, apart from `youngs_modulus` (which still gives EA)", le=1.0e9, why="a glass fibre to a stiff steel pipe"),
    F("cable.elements", "elements", "int", "", None, ge=1, derived=True,
      default_doc="the mesh rule",
      rule="integer ≥ 1, an override of the mesh rule (below: chord sagitta ≤ 2 clearances and ≤ 0.2 rad "
           "per element on the tightest bend, at least 10); not with `element_length`; refused when the "
           "sagitta exceeds 16 clearances or an element turns more than 0.5 rad", le=20000, why="keeps the model's memory below a few GB (1 m elements on a 20 km cable)"),
    F("cable.element_length", "element_length_m", "float", "m", None, gt=0.0, ge=1.0e-4, ours=True, default_doc="—",
      rule="> 0: elements of about this length instead of the mesh rule's; not with `elements`", le=1.0e4, why="elements from 0.1 mm to 10 km"),
    F("cable.length", "length_m", "float", "m", None, gt=0.0, ge=1.0e-3, default_doc="conduit centreline length",
      rule="> 0 and ≤ the conduit centreline length", le=1.0e5, why="a cable from 1 mm to 100 km long"),
    F("cable.damping_time", "damping_time_s", "float", "s", _DAMPING_TIME_S, ge=0.0, ours=True,
      rule="≥ 0; Kelvin–Voigt τ: axial damping τ·EA [N s], bending damping τ·EJ [N m² s]", le=10.0, why="Kelvin–Voigt τ far beyond any cable's (ms)"),
    F("cable.integration", "integration", "choice", "", "lobatto", choices=("lobatto", "reduced", "full"),
      ours=True,
      rule="Exudyn's quadrature of the element forces: `\"lobatto\"`, `\"reduced\"`, `\"full\"` "
           "(useReducedOrderIntegration 2, 1, 0); full quadrature lets coarse elements on curves carry a "
           "saw-tooth of axial force"),
    # ---- conduit (paper Sect. 2.3)
    F("cable.count", "count", "int", "", 1, ge=1, le=4, ours=True,
      rule="integer 1…4: identical cables of this kind in the duct; they must fit the duct. `exucable plan` uses "
           "the calculators' formulas; `exucable run` simulates one ANCF cable each, in either solver mode "
           "(`\"dynamic\"`: the cables' leading ends driven together at the eye, each trailing end with its share "
           "of `pull.back_tension`; docs/results-format.md, \"Several cables\")"),
    F("cable.arrangement", "arrangement", "choice", "", "auto",
      choices=("auto", "single", "triangular", "cradled", "diamond"), ours=True,
      rule="`single` (1), `triangular` (2, 3), `cradled` (3, 4), `diamond` (4); `auto`: 3 cables triangular for "
           "D/d < 2.5 else cradled, 4 diamond for D/d < 3.0 else cradled (Cableizer CR_pull)"),
    F("cable.positions", "positions_m", "custom", "m", None, ours=True,
      default_doc="the arrangement's rigid circles at rest",
      rule="array of `cable.count` pairs [horizontal, up] [m]: the cables' axes in the duct's cross-section, from "
           "its axis (horizontal to the right looking along the pull, up against gravity), where the simulation "
           "lays them at the start instead of `cable.arrangement`'s rest (turned with the load into bends as an "
           "arrangement is) and where the pulling eye holds their leading ends; inside the duct and apart (each "
           "at most `conduit.inner_radius` − `cable.radius` from the axis, any two at least 2 `cable.radius` "
           "apart, to 1e-3 `cable.radius` for digits typed). The calculators' formula values stay "
           "`cable.arrangement`'s, and `exucable plan` keeps the lay (no fallback to the rule's arrangement)"),
    F("cable.weight_correction_in_bends", "weight_correction_in_bends", "bool", "", True, ours=True,
      rule="`exucable plan`, several cables: `true` (IEEE 1185, AEIC CG5, Polywater): the weight correction factor "
           "w_c multiplies the friction in bends too, T_out = T_in e^(w_c μ θ); `false`: on straights only, "
           "T_out = T_in e^(μ θ) in bends (SEC TES-P-104.05's worked example)"),
    F("conduit.inner_radius", "inner_radius_m", "float", "m", gt=0.0, ge=1.0e-5, rule="> `cable.radius`", le=1.0, why="a duct from 20 µm to 2 m across"),
    F("conduit.start", "start_m", "vector3", "m", (0.0, 0.0, 0.0), rule="3 numbers; path routes only", max_abs=1.0e8, why="coordinates within 1e8 m (a survey's UTM coordinates fit)"),
    F("conduit.heading", "heading", "vector3", "", (1.0, 0.0, 0.0), nonzero=True,
      rule="3 numbers, nonzero; path routes only", max_abs=1.0e6, why="components within 1e6 (only the direction counts)"),
    F("conduit.max_segment_angle", "max_segment_angle_deg", "float", "deg", 1.0, gt=0.0, ge=1.0e-3, le=45.0,
      rule="0 < a ≤ 45: turning per straight segment on curved parts", why="at least 0.001° per segment keeps the segment count finite"),
    F("conduit.segments_per_bend", "segments_per_bend", "int", "", None, ge=1, default_doc="—",
      rule="integer ≥ 1 segments per bend/helix/fillet; not with `max_segment_angle`", le=10000, why="keeps the run's size finite"),
    F("conduit.path", "path", "custom", "", None, default_doc="—",
      rule="array of pieces (below); exactly one of `path`, `points`, `points_csv`"),
    F("conduit.points", "points_m", "custom", "m", None, default_doc="—",
      rule="array of ≥ 2 points `[x, y, z]` (survey polyline; interior vertices filleted)"),
    F("conduit.points_csv", "points_csv", "custom", "", None, default_doc="—",
      rule="CSV file relative to the scenario file; header `x,y,z` or `x,y,z,bend_radius`"),
    F("conduit.bend_radius", "bend_radius_m", "custom", "m", None, default_doc="CSV column",
      rule="one number or one per interior vertex, each > `inner_radius`; required with `points`, and with "
           "`points_csv` unless the CSV has a `bend_radius` column (the scenario's value wins)"),
    # ---- contact (paper Sect. 2.4-2.5, Eqs. 17-23)
    F("contact.stiffness", "stiffness", "float", "N/m^exponent", 1.0e6, gt=0.0, rule="> 0", le=1.0e15, why="far stiffer than any wall; beyond it Newton's steps lose precision"),
    F("contact.damping", "damping", "float", "N s/m", 1.0e3, ge=0.0, rule="≥ 0", le=1.0e12, why="far beyond any wall's damping"),
    F("contact.exponent", "exponent", "float", "", 1.5, ge=1.0, rule="≥ 1", le=5.0, why="Hertz exponents are 1 to 2.5"),
    F("contact.friction", "friction", "float", "", 0.0, ge=0.0, rule="≥ 0 (kinetic μ)", le=5.0, why="cable–duct friction is 0.1 to 1; e^(μθ) must stay finite"),
    F("contact.cable_friction", "cable_friction", "float", "", 0.0, ge=0.0, ours=True,
      rule="≥ 0: kinetic μ between the cables of a bundle (`cable.count` > 1); 0 (default): frictionless, the "
           "calculators' rigid-circle statics. Their normal law is the wall's (`contact.stiffness`, `exponent`; "
           "in the dynamic mode also `damping` with its `damping_onset`)", le=5.0, why="cable–cable friction is below 1"),
    F("contact.static_friction", "static_friction", "float", "", None, ge=0.0, ours=True, default_doc="none",
      rule="≥ `friction`", le=5.0, why="cable–duct friction is 0.1 to 1"),
    F("contact.stribeck_velocity", "stribeck_velocity_m_per_s", "float", "m/s", 0.01, gt=0.0, ge=1.0e-6, ours=True,
      rule="> 0", le=100.0, why="1/v_s² must stay finite"),
    F("contact.friction_regularisation_velocity", "friction_regularisation_velocity_m_per_s", "float", "m/s",
      None, gt=0.0, ge=1.0e-9, ours=True, derived=True, default_doc="1 % of `pull.speed`",
      rule="> 0: dynamic mode's friction direction v_τ/√(|v_τ|² + ε²); at 1 % of the pull speed the friction at "
           "that speed is 99.995 % developed whatever the speed (a fixed 1 mm/s gave −4.5 % on Example 2 at "
           "1 mm/s, studies/slow_pull.py); a run where it develops less than 1 − 1e-4 of μ is flagged "
           "`friction_underdeveloped`. Steady mode slides at the pull speed and uses fully developed friction",
      le=10.0, why="1/ε must stay finite"),
    F("contact.check_points_per_element", "check_points_per_element", "int", "", None, ge=1,
      default_doc="the mesh rule",
      rule="integer ≥ 1; default: spaced at most λ/4, λ = √(EJ/T_max) the bending length over which bend-end "
           "loads concentrate, 8–200 per element (8 on routes without bends)", le=1000, why="keeps the run's size finite (the mesh rule uses at most 200)"),
    F("contact.check_point_rule", "check_point_rule", "choice", "", "gauss", choices=("gauss", "uniform"),
      ours=True, rule="`\"gauss\"` or `\"uniform\"`"),
    F("contact.reference_spacing", "reference_spacing_m", "float", "m", 1.0e-3, gt=0.0, ge=1.0e-6, ours=True,
      rule="> 0; each check point's force is scaled by its share of the element length / this", le=1.0e3, why="a weight scale from 1 µm to 1 km"),
    F("contact.broad_phase", "broad_phase", "choice", "", "aabb", choices=("aabb", "none"),
      rule="`\"aabb\"` or `\"none\"`"),
    F("contact.damping_onset", "damping_onset_m", "float", "m", 5.0e-5, ge=0.0, ours=True,
      rule="≥ 0: penetration over which the damping term grows from 0, f_n = Kδ^e + C·min(δ/δ_d, 1)·δ̇; 0 is "
           "the paper's Eq. 18, whose damping force jumps to C·δ̇ at first touch (each touch then cuts the "
           "step: Example 4 took 7745 steps per 0.03 s with 0, 90 with 1e-5); 5e-5 halves Newton's "
           "iterations against 1e-5, results within their uncertainty (docs/performance.md); in dynamic "
           "runs min(δ/δ_d, 1) is held within a time step at the step's start value (exucable/contact/law.py)", le=1.0, why="a penetration scale below 1 m"),
    F("contact.surface", "surface", "choice", "", "smooth", choices=("smooth", "segments"), ours=True,
      rule="`\"smooth\"`: closest points on the exact bends/helices (the segments still do the search); "
           "`\"segments\"`: on the straight segments, as the paper (Sect. 2.3)"),
    # ---- pull (paper Sect. 2.1, Eq. 1)
    F("pull.speed", "speed_m_per_s", "float", "m/s", gt=0.0, ge=1.0e-6, rule="> 0", le=100.0, why="pull speeds from 1 µm/s to 100 m/s (real rigs: below 1 m/s)"),
    F("pull.direction", "direction", "choice", "", "forward", choices=("forward", "reverse"),
      rule="`\"forward\"` (out at the end of the route) or `\"reverse\"`"),
    F("pull.back_tension", "back_tension_N", "float", "N", 0.0, ge=0.0,
      rule="≥ 0, at the trailing end along the conduit tangent", le=1.0e8, why="up to 100 MN, beyond any cable's strength"),
    F("pull.force", "force_N", "float", "N", None, gt=0.0, default_doc="none",
      rule="> 0: prescribed pulling force (force-controlled pull, Example 3); not with a nonzero "
           "`back_tension`", le=1.0e8, why="up to 100 MN, beyond any cable's strength"),
    F("pull.ramp_time", "ramp_time_s", "float", "s", 0.0, ge=0.0, ours=True,
      rule="≥ 0: time over which speed/loads ramp up from the start state", le=1.0e6, why="keeps the run's size finite"),
    F("pull.stop_time", "stop_time_s", "float", "s", None, ge=0.0, ours=True, default_doc="none",
      rule="≥ 0, dynamic mode, velocity-controlled pull: the eye stops here (slowing over `ramp_time`) and stands "
           "still, so static friction (`contact.static_friction`) can hold the cables across the duct (a jam); 0: "
           "standing still from the start, the cables laid at rest", le=1.0e6, why="keeps the run's size finite"),
    F("pull.hold_time", "hold_time_s", "float", "s", None, gt=0.0, ours=True, default_doc="none",
      rule="> 0, with `stop_time`: the eye stands still this long, then pulls on (over `ramp_time`); none: still to "
           "the end", le=1.0e6, why="keeps the run's size finite"),
    F("pull.feed_from_reel", "feed_from_reel", "bool", "", False, ours=True,
      rule="`exucable plan`: also the pull-in history (tension at the rig vs pulled length), with `back_tension` "
           "as the reel's back tension"),
    # ---- gravity
    F("gravity.g", "g_m_per_s2", "float", "m/s^2", 9.81, unit_doc="m/s²", ge=0.0,
      rule="≥ 0, acting along −z (the paper's examples give 9.8, the industry files standard gravity 9.80665)",
      le=1000.0, why="up to 100 g"),
    # ---- solver
    F("solver.end_time", "end_time_s", "float", "s", None, gt=0.0, default_doc="required in dynamic mode",
      rule="> 0: simulated time of a dynamic run (an upper bound with `steady_stop`); steady mode does not use it",
      le=1.0e6, why="keeps the run's size finite"),
    F("solver.step", "step_s", "float", "s", 1.0e-2, gt=0.0,
      rule="> 0 (initial and maximum step; the adaptive controller cuts it where needed)", le=1.0e3, why="keeps the run's size finite"),
    F("solver.min_step", "min_step_s", "float", "s", None, gt=0.0, ge=1.0e-15, ours=True, derived=True,
      default_doc="min(1e-8, step)", rule="0 < min_step ≤ step", why="keeps the run's size finite"),
    F("solver.spectral_radius", "spectral_radius", "float", "", 0.5, ge=0.0, le=1.0, ours=True,
      rule="generalized-α ρ∞ in [0, 1]"),
    # 12 iterations and 1e-7: measured on Example 2, 735 -> 155 steps at the same pulling
    # force (within 0.02 %) as 8 and 1e-8 (exudyn-findings had 8 with a different start);
    # 1e-7 -> 1e-5: Exudyn resets the Lagrange multipliers to 0 at each step, so the
    # first residual is about the rig force and 1e-5 of it is a force balance to 1e-5 of the pull.
    # 12 -> 8 (with the damping onset held per step): a step still unconverged after 8
    # contracts linearly (0.3-0.5) or cycles; halving it costs fewer iterations (Ex. 4 288 its in
    # 71 steps -> 290 in 73, 4.06 -> 3.97 per step; 100 m route 685 -> 669; Ex. 1-3 unchanged)
    F("solver.newton_max_iterations", "newton_max_iterations", "int", "", 8, ge=1, ours=True,
      rule="integer ≥ 1: a step attempt not converged after this many Newton iterations is retried at half the step", le=100, why="Newton converges in a few iterations or not at all; more only burns time"),
    F("solver.newton_tolerance", "newton_tolerance", "float", "", 1.0e-5, gt=0.0, ge=1.0e-14, lt=1.0, ours=True,
      rule="0 < tol < 1: Newton's residual relative to its first one in the step, which the rig's "
           "reaction (≈ the pulling force) dominates; 1e-5 changes results by < 1e-5 against 1e-7", why="below 1e-14 round-off never lets Newton stop"),
    F("solver.startup_time", "startup_time_s", "float", "s", 0.05, ge=0.0, ours=True,
      rule="≥ 0: a mass-proportional damper toward the start's sliding velocities settles the pre-tensioned "
           "start and fades out over this time; the steady state is looked for after it", le=1.0e6, why="keeps the run's size finite"),
    F("solver.startup_damping", "startup_damping_1_per_s", "float", "1/s", 200.0, ge=0.0, ours=True,
      rule="≥ 0: its initial rate", le=1.0e6, why="a rate far beyond the cable's own (stiff damping stalls the steps)"),
    F("solver.exit_span_damping", "exit_span_damping_1_per_s", "float", "1/s", 0.0, ge=0.0, ours=True,
      rule="≥ 0: velocity-controlled dynamic runs: a mass-proportional damper toward the steady flow V·r'/|r'| on the "
           "cable past the conduit's exit (the span hanging from the mouth to the rig, which nothing else damps; it "
           "exerts no force on a steadily sliding cable); 0 switches it off. The industry scenarios use 10 "
           "(reference/README.md, \"Why the force wandered\")", le=1.0e6, why="a rate far beyond the cable's own (stiff damping stalls the steps)"),
    F("solver.output_interval", "output_interval_s", "float", "s", None, gt=0.0, ours=True, derived=True,
      default_doc="max(step, end_time/1000)", rule="> 0 (dynamic mode)", why="keeps the run's size finite; at most 1e6 outputs per run"),
    F("solver.steady_stop", "steady_stop", "bool", "", False, ours=True,
      rule="stop once the pulling force is steady"),
    F("solver.steady_window", "steady_window_s", "float", "s", 0.2, gt=0.0, ours=True, rule="> 0", le=1.0e6, why="keeps the run's size finite"),
    F("solver.steady_tolerance", "steady_tolerance", "float", "", 1.0e-3, gt=0.0, ours=True,
      rule="> 0, relative drift/scatter bound"),
    F("solver.pretension", "pretension", "bool", "", True, ours=True,
      rule="start from the rope solution's tension profile near contact equilibrium"),
    F("solver.mode", "mode", "choice", "", None, choices=("auto", "dynamic", "steady"), ours=True, derived=True,
      default_doc="`\"auto\"`",
      rule="`\"auto\"`: `\"steady\"`, unless the scenario asks for what only the time integration gives "
           "(`[output]` snapshots) or what steady mode cannot start without (`solver.pretension = false`): then "
           "`\"dynamic\"`; the summary's `mode` and `mode_rule` say which and why (README, \"Two solver modes\"). "
           "Why steady by default: a velocity-controlled pull's answer is its steady sliding state, which steady "
           "mode finds in seconds with an error bar (a second solve on a coarser mesh), where a dynamic run "
           "rings and drifts for seconds of simulated time before it is steady. "
           "`\"dynamic\"`: integrate the dynamics in time (paper Sect. 2.6); `\"steady\"`: one static solve "
           "of the steady sliding state (friction along the cable's tangent, no start-up, no time history; "
           "needs `solver.pretension = true`; on a route ending in a bend the start is laid out past the exit so that "
           "the rig sits 10 bending lengths √(EJ/T) beyond the bend, and `reference_pulled_out_m` says how far); "
           "the `solver` time keys are then unused, `solver.end_time` included"),
    F("solver.start_from", "start_from", "choice", "", "rope", choices=("rope", "steady"), ours=True,
      rule="dynamic mode, velocity-controlled pull: `\"rope\"` starts from the rope's tension on the rope-with-"
           "clearance path (`solver.pretension`); `\"steady\"` first solves the steady state (as `solver.mode = "
           "\"steady\"`, laid out by the same rule or `solver.steady_lead_out`) and starts the dynamic run in it, "
           "sliding: no start misfit to ring in the axial mode, no bending boundary layer at the rig to pull out of "
           "(reference/README.md, \"Why the force wandered\"); falls back to `\"rope\"` with a warning if that "
           "solve fails"),
    F("solver.steady_residual", "steady_residual", "float", "", 1.0e-6, gt=0.0, lt=1.0, ours=True,
      rule="0 < tol < 1; steady mode: the static solve stops once its equilibrium residual (N, the norm over "
           "every coordinate) is below this times the rope solution's largest tension; at 1e-6 Example 4's pulling "
           "force is 1e-9 from a 1000× tighter solve's (reference/README.md, \"Speed\"); a cross-check of the "
           "equilibrium itself wants it tighter"),
    F("solver.steady_time_limit", "steady_time_limit_s", "float", "s", 60.0, gt=0.0, ours=True,
      rule="> 0; steady mode: CPU seconds one static solve may take before it stops as failed, naming the load "
           "scale and residual it reached, the strain at the head and what to change (CPU time, not wall: the same "
           "on a loaded machine)", le=1.0e6, why="keeps the run's time finite"),
    F("solver.steady_lead_out", "steady_lead_out_m", "float", "m", None, ge=0.0, ours=True,
      default_doc="the rule in `solver.mode`",
      rule="≥ 0; steady mode and `solver.start_from = \"steady\"`: cable laid out past the conduit's exit at the start (the state a dynamic pull "
           "reaches after pulling that far: `exucable validate` sets it to the dynamic run's "
           "`reference_pulled_out_m` to compare both modes in the same state)", le=1.0e4, why="keeps the run's size finite"),
    F("solver.bundle_starts", "bundle_starts", "strings", "", ("clearance", "statics_own"),
      choices=("clearance", "statics_own", "statics", "axis"), ours=True,
      default_doc='`["clearance", "statics_own"]`',
      rule="steady mode, several cables: the starts tried in turn, each but the last given up where its dynamic "
           "relaxation stalls, the next solved in the CPU time left of `solver.steady_time_limit` (the summary's "
           "`bundle.start` says which gave the answer, `bundle.starts_tried` each one's CPU): `\"clearance\"`, the "
           "bundle's centroid on the rope-with-clearance path; `\"statics_own\"`, each cable where the statics of "
           "its cross-section puts it under its own start tension (`\"statics\"`: the cables' mean tension; "
           "`\"axis\"`: the arrangement about the duct's axis). Where there are several steady states the start "
           "chooses among them (reference/README.md, \"A start sequence\"); one start given alone is the only one tried"),
    F("solver.cable_element", "cable_element", "choice", "", "compiled", choices=("compiled", "exudyn"), ours=True,
      rule="steady mode (one cable or several): who assembles the ANCF cables' elastic forces and their Jacobian: `\"compiled\"`, "
           "exucable's compiled copy of Exudyn's `ObjectANCFCable` (`exucable/contact/ancf_cable.py`, equal to "
           "Exudyn's element to 1e-14) inside the contact's user function, with the weight as its consistent nodal "
           "load; `\"exudyn\"`, Exudyn's `ObjectANCFCable` objects, whose Jacobian Exudyn takes by automatic "
           "differentiation over positions and velocities. Exudyn keeps the nodes, end loads, rig, static solver and "
           "factorisation either way. The same pulling force to round-off (≤ 4e-13 on the shipped scenarios), one "
           "Newton iteration at 0.6-0.8 the CPU time (docs/decisions/0004-compiled-cable-element.md); the summary's "
           "`cable_element` says which ran. Dynamic mode and `add_cable_in_conduit` into your own "
           "system use Exudyn's element"),
    F("solver.static_solver", "static_solver", "choice", "", "exucable", choices=("exucable", "exudyn"), ours=True,
      rule="steady mode: who runs the static solves' Newton iterations: `\"exucable\"`, our own Newton loop on the "
           "assembled system (the rig's coordinates eliminated, a banded LU of the node-major chain, several "
           "cables' nodes interleaved; `exucable/solve/newton_system.py`), with Exudyn's stop test, so the iterates "
           "are Exudyn's to round-off; `\"exudyn\"`, Exudyn's static solver (sparse assembly from triplets, the "
           "rig's multipliers, Eigen's SparseLU). Ours needs `cable_element = \"compiled\"`; other models "
           "(Exudyn's element, items of a user's own) use Exudyn's, and the summary's "
           "`static_solver` says which ran (docs/decisions/0005-own-static-newton.md)"),
    # ---- output
    F("output.snapshots", "snapshots_s", "custom", "s", (), ours=True, default_doc="none",
      rule="array of times in [0, `solver.end_time`]: the whole state is written at each "
           "(interpolated between solver steps)"),
    F("output.snapshot_interval", "snapshot_interval_s", "float", "s", None, gt=0.0, ours=True,
      default_doc="none", rule="> 0: also a snapshot at every multiple of it up to `solver.end_time`", why="keeps the run's size finite; at most 10000 snapshots"),
    F("output.cross_sections", "cross_sections_m", "custom", "m", (), ours=True,
      default_doc="the middle of each straight and bend (at most 8)",
      rule="array of places s along the conduit [m], at most 8: several cables (`cable.count` > 1) are drawn "
           "across the duct there (`cross_sections.png`)"),
    # ---- limits (exucable plan)
    F("limits.max_tension", "max_tension_N", "float", "N", None, gt=0.0, ours=True, default_doc="none",
      rule="> 0: largest allowed pulling tension", le=1.0e9, why="up to 1 GN"),
    F("limits.grip_limit", "grip_limit_N", "float", "N", None, gt=0.0, ours=True, default_doc="none",
      rule="> 0: rating of the pulling eye or grip", le=1.0e9, why="up to 1 GN"),
    F("limits.conductor_material", "conductor_material", "choice", "", None, choices=("copper", "aluminium"),
      ours=True, default_doc="none",
      rule="with `conductor_area` and `conductors`: the conductors' tension limit"),
    F("limits.conductor_area", "conductor_area_m2", "float", "m^2", None, unit_doc="m²", gt=0.0, ours=True,
      default_doc="none", rule="> 0: cross-section of ONE conductor", le=1.0, why="up to 1 m²"),
    F("limits.conductors", "conductors", "int", "", None, ge=1, ours=True, default_doc="none",
      rule="integer ≥ 1: conductors sharing the pull (all cables)", le=1000, why="up to 1000 conductors"),
    F("limits.conductor_rule", "conductor_rule", "choice", "", None, choices=("iec", "us"), ours=True,
      default_doc="iec; us with imperial units",
      rule="`iec`: 50 N/mm² copper, 30 N/mm² aluminium; `us`: 0.008 / 0.006 lb/cmil, × 0.8 above 3 conductors"),
    F("limits.max_sidewall_pressure", "max_sidewall_pressure_N_per_m", "float", "N/m", None, gt=0.0, ours=True,
      default_doc="none", rule="> 0: largest SWBP on the most loaded cable", le=1.0e9, why="up to 1 GN/m"),
    F("limits.min_bend_radius_multiple", "min_bend_radius_multiple", "float", "", None, gt=0.0, ours=True,
      default_doc="none", rule="> 0: smallest bend centreline radius as a multiple of the cable diameter", le=1000.0, why="up to 1000 diameters"),
    F("limits.min_clearance", "min_clearance_m", "float", "m", None, gt=0.0, ours=True, default_doc="none",
      rule="> 0: smallest clearance between the uppermost cable and the duct", le=1.0, why="up to 1 m"),
    F("limits.max_fill", "max_fill_percent", "float", "%", None, gt=0.0, le=100.0, ours=True, default_doc="none",
      rule="0 < f ≤ 100: largest conduit fill, the cables' cross-sections n·d² over the duct's D², in percent "
           "(NEC Chapter 9 Table 1 allows 53 for one cable, 31 for two, 40 for three or more)"),
    # ---- display
    F("display.units", "units", "choice", "", "si", choices=("si", "imperial"), ours=True,
      rule="unit system of bare numbers in the file and of printed tables (see above); results files stay SI"),
    F("display.point_names", "point_names", "strings", "", None, ours=True, default_doc="A, B, C, …",
      rule="array of non-empty strings naming the route's points in route order: its start and the end of each "
           "piece (one more than the pieces); `exucable plan` names sections and bends by them (`\"B–C\"`)"),
)
del F


def default_of(key: str):
    """The default of ``key`` (e.g. ``"contact.damping_onset"``), so that building blocks below
    the scenario layer default to the validated values."""
    for f in FIELDS:
        if f.key == key:
            if f.default is REQUIRED:
                raise KeyError(f"{key} has no default")
            return f.default
    raise KeyError(key)


def fields_of(section: str) -> tuple[Field, ...]:
    """The rows of one table (``""`` for the top level), in file order."""
    return tuple(f for f in FIELDS if f.section == section)


def format_default(value) -> str:
    """A default as the README writes it: ``1e-3``, ``0.5``, ``"gauss"``, ``false``, ``[0, 0, 0]``."""
    if isinstance(value, bool):
        return f"`{str(value).lower()}`"
    if isinstance(value, str):
        return f'`"{value}"`'
    if isinstance(value, tuple):
        return "`[" + ", ".join(format_default(v).strip("`") for v in value) + "]`"
    if isinstance(value, float) and value != 0.0 and not (1e-2 <= abs(value) < 1e3):
        mantissa, exponent = f"{value:e}".split("e")
        mantissa = mantissa.rstrip("0").rstrip(".")
        return f"{mantissa}e{int(exponent)}"
    return f"{value:g}"


def _default_cell(f: Field) -> str:
    if f.default_doc:
        return f.default_doc
    if f.default is REQUIRED:
        return "required"
    if f.default is None:
        return "none"
    return format_default(f.default)


def range_text(f: Field) -> str:
    """The allowed range of a row as the README says it, e.g. ``1e-05 … 1 m``, ``> 0 and ≤ 1e+06 s``,
    ``|each| ≤ 1e+08 m``; ``""`` without bounds."""
    unit = f" {f.readme_unit}" if f.readme_unit else ""
    if f.max_abs is not None:
        return f"|each| ≤ {f.max_abs:g}{unit}"
    if f.ge is not None and f.le is not None:
        return f"{f.ge:g} … {f.le:g}{unit}"
    parts = [f"{op} {v:g}" for op, v in (("≥", f.ge), (">", f.gt), ("≤", f.le), ("<", f.lt)) if v is not None]
    return " and ".join(parts) + unit if parts else ""


def _rule_cell(f: Field) -> str:
    if not f.why:
        return f.rule
    bounds = range_text(f)
    return f"{f.rule}; range {bounds} ({f.why})" if bounds else f"{f.rule} ({f.why})"


def markdown_table(section: str) -> str:
    """The README key table of one section, rendered from :data:`FIELDS`."""
    lines = ["| key | unit | default | rule |", "| --- | --- | --- | --- |"]
    for f in fields_of(section):
        key = f"`{f.name}`" + (" (*ours*)" if f.ours else "")
        cells = (key, f.readme_unit, _default_cell(f), _rule_cell(f))
        lines.append("|" + "|".join(f" {c} " if c else " " for c in cells) + "|")
    return "\n".join(lines)


_TABLE = re.compile(r"\| key \| unit \| default \| rule \|\n(?:\|.*\|\n?)*")


def readme_with_tables(text: str) -> str:
    """``text`` (scenarios/README.md) with the key table under each section heading regenerated.

    Raises
    ------
    ValueError
        If a section's heading or key table is missing.
    """
    for section in SECTIONS:
        heading = SECTION_HEADINGS[section]
        at = text.find(heading + "\n")
        if at < 0:
            raise ValueError(f"scenarios/README.md has no heading {heading!r}")
        m = _TABLE.search(text, at)
        if m is None:
            raise ValueError(f"scenarios/README.md has no key table under {heading!r}")
        end_newline = "\n" if m.group(0).endswith("\n") else ""
        text = text[: m.start()] + markdown_table(section) + end_newline + text[m.end():]
    return text

