"""Scenarios: one problem definition, validated wherever it is made (TOML file or Python).

A scenario describes one pulling simulation: the cable (paper Sect. 2.2), the conduit
route (Sect. 2.3), the cable–conduit contact law (Sect. 2.4, Eqs. 17–23), the pulling
rig (Sect. 2.1, Eq. 1), gravity and the time integration settings. SI units throughout,
angles in degrees.

Every key, its unit, default and check is one row of
:data:`exucable.scenario.fields.FIELDS`; that table drives the TOML parser, the checks the
dataclasses run when built in Python, their ``to_dict`` and the key tables of
``scenarios/README.md``. So ``PullSpec(speed_m_per_s=-0.1)``, ``PullSpec.from_keys(speed=-0.1)``
and ``speed = -0.1`` in a file all raise the same
``ScenarioError: pull.speed: must be > 0 (m/s), got -0.1``.

Every problem with the input (unknown key, missing key, wrong type, non-physical value,
a route that cannot be built) raises ONE :class:`~exucable.errors.ScenarioError` whose
``key`` is the full dotted key, e.g. ``"conduit.path[2].radius"``, and whose message
says what is allowed and what was given.
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
import math
import numbers
import tomllib
from dataclasses import InitVar, dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import exucable.quasistatic.engineering as _eng
import exucable.geometry as _geo
from exucable.errors import GeometryError, ScenarioError
from exucable.scenario.fields import FIELDS, REQUIRED, Field, fields_of

__all__ = [
    "CableSpec",
    "ConduitSpec",
    "ContactSpec",
    "PullSpec",
    "GravitySpec",
    "OutputSpec",
    "resolve_mode",
    "SolverSpec",
    "LimitsSpec",
    "DisplaySpec",
    "Scenario",
    "load_scenario",
    "parse_scenario",
    "default_elements",
    "FIELD_BY_KEY",
    "coerce_value",
    "quantities_to_si",
    "parse_conduit",
    "conduit_from_spec",
]

_DEFAULT_MIN_STEP_S = 1.0e-8
# default friction regularisation velocity as a fraction of the pull speed: the regularised friction
# then develops 1/√(1 + 1e-4) = 99.995 % of μ at the pull speed, whatever the speed
REGULARISATION_FRACTION_OF_SPEED = 0.01

# Sizes that keep a run finite (time and memory), checked before anything is allocated. A run's
# memory grows with its check points (~1 kB each, README "Performance": 153 MB for 136 000) and
# elements; the conduit's segments and pieces are searched at every Newton iteration.
_SIZE_WHY = "a bound that keeps the run's time and memory finite"
MAX_LENGTH_M = 1.0e5          # a route piece, bend radius or helix pitch up to 100 km
MIN_PIECE_M = 1.0e-6          # a straight shorter than 1 µm is no piece of a conduit
_PIECE_WHY = "route pieces from 1 µm to 100 km"
MAX_HELIX_TURNS = 1000.0
# a curve turning less than 1e-6° is no bend: its segments would be shorter than round-off
MIN_TURN_DEG = 1.0e-6
_TURN_WHY = f"a curve turns at least {MIN_TURN_DEG:g}° (shorter segments are lost in round-off) and a helix at most {MAX_HELIX_TURNS:g} turns"
MAX_PIECES = 10_000           # path pieces
MAX_POINTS = 100_000          # survey points
MAX_SEGMENTS = 200_000        # straight contact segments of the conduit
MAX_OUTPUTS = 1_000_000       # stored output states: solver.end_time / solver.output_interval
MAX_SNAPSHOTS = 10_000        # snapshot files
# e^(μθ) up to e^50 ≈ 5e21: tension ratios beyond any real pull; the rope's exponentials stay finite
MAX_FRICTION_TURNING = 50.0

FIELD_BY_KEY: dict[str, Field] = {f.key: f for f in FIELDS}


def _default(key: str):
    """The dataclass default of a table row: its plain default, else None."""
    d = FIELD_BY_KEY[key].default
    return None if d is REQUIRED else d


def _what(f: Field) -> str:
    """What a missing key needs, as the message says it."""
    return {
        "float": f"a number{_unit(f.unit)}",
        "int": "an integer",
        "bool": "true or false",
        "str": "a string",
    }.get(f.kind, "a value")


def coerce_value(f: Field, value):
    """Check ``value`` against its table row and return it in canonical form (float, tuple)."""
    key = f.key
    if f.kind == "float":
        v = _as_float(key, value, f.unit)
        _check_range(key, v, f.unit, why=f.why, **f.bounds)
        return v
    if f.kind == "int":
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise ScenarioError(key, f"must be an integer, got {_describe(value)}")
        v = int(value)
        _check_range(key, v, "", why=f.why, **f.bounds)
        return v
    if f.kind == "bool":
        if not isinstance(value, bool):
            raise ScenarioError(key, f"must be true or false, got {_describe(value)}")
        return value
    if f.kind == "str":
        if not isinstance(value, str):
            raise ScenarioError(key, f"must be a string, got {_describe(value)}")
        return value
    if f.kind == "choice":
        if not isinstance(value, str) or value not in f.choices:
            allowed = ", ".join(f'"{c}"' for c in f.choices)
            raise ScenarioError(key, f"must be one of {allowed}, got {_describe(value)}")
        return value
    if f.kind == "strings":
        if isinstance(value, str) or not isinstance(value, (list, tuple)):
            raise ScenarioError(key, f"must be an array of strings, e.g. [\"A\", \"B\"], got {_describe(value)}")
        if f.choices and not value:
            raise ScenarioError(key, f"must name at least one of {', '.join(repr(c) for c in f.choices)}")
        for i, item in enumerate(value):
            if not isinstance(item, str) or not item.strip():
                raise ScenarioError(f"{key}[{i}]", f"must be a non-empty string, got {_describe(item)}")
            if f.choices and item not in f.choices:
                allowed = ", ".join(f'"{c}"' for c in f.choices)
                raise ScenarioError(f"{key}[{i}]", f"must be one of {allowed}, got {_describe(item)}")
        return tuple(value)
    if f.kind == "vector3":
        return _vector3(key, value, f.unit, nonzero=f.nonzero, max_abs=f.max_abs, why=f.why)
    return value  # "custom": checked by the section's own code


def _parse_positions(raw, count: int) -> tuple:
    """``cable.positions`` as ``count`` pairs of finite floats [m] (the fit is the scenario's check)."""
    if count < 2:
        raise ScenarioError("cable.positions", f"places several cables; cable.count is {count}: remove it or set "
                                               "cable.count to 2…4")
    if not isinstance(raw, (list, tuple)) or len(raw) != count:
        raise ScenarioError("cable.positions", f"must be an array of cable.count = {count} pairs [horizontal, up] [m], "
                                               f"one per cable, got {_describe(raw)}")
    pairs = []
    for i, pair in enumerate(raw):
        key = f"cable.positions[{i}]"
        if not isinstance(pair, (list, tuple)) or len(pair) != 2:
            raise ScenarioError(key, f"must be a pair [horizontal, up] [m] from the duct's axis, got {_describe(pair)}")
        pairs.append((_as_float(key, pair[0], "m"), _as_float(key, pair[1], "m")))
    return tuple(pairs)


#: Overlap allowed in ``cable.positions`` [fraction of cable.radius]: positions typed to a few digits
#: (a triangle's 0.031069 for 0.0310689…) overlap by a fraction of a micrometre; the Hertz law takes an
#: overlap of this size (15 µm at r = 15 mm, of the order of a solved contact's few µm) as a small force.
POSITIONS_OVERLAP = 1e-3


def _check_positions_fit(positions_m, inner_radius_m: float, cable_radius_m: float) -> None:
    """Refuse ``cable.positions`` that put a cable into the duct's wall or two cables into each other
    by more than ``POSITIONS_OVERLAP`` × the cable radius (touching is allowed, as in the
    arrangements' rigid circles)."""
    room = inner_radius_m - cable_radius_m
    slack = POSITIONS_OVERLAP * cable_radius_m
    for i, (h, v) in enumerate(positions_m):
        if math.hypot(h, v) > room + slack:
            on_wall = room / math.hypot(h, v)
            raise ScenarioError(f"cable.positions[{i}]", f"[{h!r}, {v!r}] m is {math.hypot(h, v):.6g} m from the duct's axis: "
                                f"the cable would cut into the wall; at most conduit.inner_radius − cable.radius = "
                                f"{room:.6g} m (at the wall in that direction: [{h * on_wall:.6g}, {v * on_wall:.6g}])")
    for i in range(len(positions_m)):
        for j in range(i + 1, len(positions_m)):
            gap = math.dist(positions_m[i], positions_m[j])
            if gap < 2.0 * cable_radius_m - slack:
                raise ScenarioError(f"cable.positions[{j}]", f"is {gap:.6g} m from cable.positions[{i}]: the cables "
                                    f"would overlap; place them at least 2 cable.radius = {2.0 * cable_radius_m:.6g} m apart")


def _toml_value(value):
    """A dataclass value in TOML form (tuples as lists)."""
    if isinstance(value, tuple):
        return [_toml_value(v) for v in value]
    return value


class _Spec:
    """Validation, ``to_dict``, ``from_keys`` and ``replace`` of one section, from :data:`FIELDS`.

    Subclasses are frozen dataclasses whose attributes are the ``attr`` of the section's rows
    (plus derived ones) and set ``_SECTION``. ``__post_init__`` checks every value against
    its row (type, bounds, choices; required ones present), fills plain defaults, then runs
    the subclass's ``_check`` for cross-field rules and derived defaults.
    """

    _SECTION: ClassVar[str] = ""
    #: Attributes ``to_dict`` leaves out (derived from another key that is echoed).
    _NOT_ECHOED: ClassVar[frozenset[str]] = frozenset()
    #: Attributes with a default that are None when another key replaces them.
    _NONE_MEANS_NOT_USED: ClassVar[frozenset[str]] = frozenset()

    def __post_init__(self):
        derived = set()
        for f in fields_of(self._SECTION):
            if f.kind == "custom":
                continue
            value = getattr(self, f.attr)
            if value is None:
                if f.default is REQUIRED:
                    raise ScenarioError(f.key, f"required key is missing: give {_what(f)}")
                if f.derived:
                    derived.add(f.attr)
                elif f.default is not None and f.attr not in self._NONE_MEANS_NOT_USED:
                    # a file cannot say None: leaving the key out gives its default
                    raise ScenarioError(f.key, f"must be {_what(f)}, got None; leave the key out for its default "
                                               f"{f.default!r}")
                continue
            object.__setattr__(self, f.attr, coerce_value(f, value))
        # Not a dataclass field: no part in equality, hashing or repr.
        object.__setattr__(self, "_derived", frozenset(derived))
        self._check()

    def _check(self) -> None:
        """Cross-field rules and derived defaults (override)."""

    @property
    def derived_keys(self) -> frozenset[str]:
        """TOML names of the keys whose value was derived from others (not given)."""
        by_attr = {f.attr: f.name for f in fields_of(self._SECTION)}
        return frozenset(by_attr[a] for a in self.__dict__.get("_derived", ()))

    def to_dict(self) -> dict:
        """The table in TOML key names, defaults filled in (absent optional keys left out)."""
        d: dict[str, Any] = {}
        for f in fields_of(self._SECTION):
            value = getattr(self, f.attr)
            if value is not None and f.attr not in self._NOT_ECHOED:
                d[f.name] = _toml_value(value)
        return d

    @classmethod
    def from_keys(cls, **keys):
        """Build the section from TOML key names, e.g. ``PullSpec.from_keys(speed=0.1)``.

        Raises
        ------
        ScenarioError
            Unknown key (with a close match suggested) or any invalid value, naming the dotted key.
        """
        return _PARSERS[cls._SECTION](keys)

    def replace(self, **keys):
        """A copy with some keys changed, given by TOML name (``friction=0.3``); validated.

        Derived defaults (e.g. ``solver.output_interval``) are derived again from the new values.
        """
        d = self.to_dict()
        for name in self.derived_keys:
            d.pop(name, None)
        d.update(keys)
        return self.from_keys(**d)

    with_ = replace


# --------------------------------------------------------------------------------------
# Dataclasses
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CableSpec(_Spec):
    """The cable (paper Sect. 2.2, Eqs. 2–10).

    Attributes
    ----------
    radius_m : float
        Cable radius r [m].
    mass_per_length_kg_per_m : float
        Mass per unit length ρA [kg/m] (from ``density`` when that was given).
    density_kg_per_m3 : float or None
        Density ρ [kg/m³] if given, else None (``mass_per_length`` was given).
    youngs_modulus_Pa : float
        Young's modulus E [Pa].
    elements : int or None
        Number of cable finite elements; None until a :class:`Scenario` applies the mesh rule
        (:func:`default_elements`, :mod:`exucable.scenario.mesh`) or ``element_length_m``.
    element_length_m : float or None
        Element length [m] asked for instead of the mesh rule; not with ``elements``.
    length_m : float or None
        Cable length [m]; None means the conduit's centreline length.
    damping_time_s : float
        Kelvin–Voigt retardation time τ [s]; internal damping = τ × stiffness.
    integration : str
        Exudyn's quadrature of the element's internal forces: ``"lobatto"`` (default),
        ``"reduced"`` or ``"full"`` (useReducedOrderIntegration 2, 1, 0).
    bending_stiffness_given_N_m2 : float or None
        EJ [N m²] if given (stranded cables: not E π r⁴/4), else None.
    count : int
        Identical cables of this kind in the duct (1…4; ``exucable plan`` only).
    arrangement : str
        ``"auto"`` or their arrangement in the duct (:data:`exucable.quasistatic.engineering.ARRANGEMENTS`).
    weight_correction_in_bends : bool
        ``exucable plan``: apply the weight correction factor to the friction in bends too (default) or
        on straights only.
    positions_m : tuple of (float, float) or None
        Several cables: their axes at the start, (horizontal, up) from the duct's axis [m], one pair per
        cable (``cable.positions``); None lays them in ``arrangement``'s rest. Inside the duct and apart
        (checked by the scenario).
    """

    _SECTION: ClassVar[str] = "cable"

    radius_m: float = _default("cable.radius")
    mass_per_length_kg_per_m: float | None = _default("cable.mass_per_length")
    density_kg_per_m3: float | None = _default("cable.density")
    youngs_modulus_Pa: float = _default("cable.youngs_modulus")
    elements: int | None = _default("cable.elements")
    element_length_m: float | None = _default("cable.element_length")
    length_m: float | None = _default("cable.length")
    damping_time_s: float = _default("cable.damping_time")
    integration: str = _default("cable.integration")
    bending_stiffness_given_N_m2: float | None = _default("cable.bending_stiffness")
    count: int = _default("cable.count")
    arrangement: str = _default("cable.arrangement")
    weight_correction_in_bends: bool = _default("cable.weight_correction_in_bends")
    positions_m: tuple | None = None

    def _check(self) -> None:
        if self.positions_m is not None:
            object.__setattr__(self, "positions_m", _parse_positions(self.positions_m, self.count))
        if self.elements is not None and self.element_length_m is not None:
            raise ScenarioError("cable.element_length", "give either elements or element_length, not both "
                                "(or neither: the mesh rule then chooses, see scenarios/README.md)")
        if self.arrangement != "auto":
            _eng.check_arrangement(self.count, self.arrangement)
        if self.density_kg_per_m3 is None and self.mass_per_length_kg_per_m is None:
            raise ScenarioError("cable.density", "required: give density (kg/m^3) or mass_per_length (kg/m)")
        if self.density_kg_per_m3 is not None:
            from_density = self.density_kg_per_m3 * self.area_m2
            given = self.mass_per_length_kg_per_m
            if given is not None and not math.isclose(given, from_density, rel_tol=1e-12):
                raise ScenarioError("cable.mass_per_length", "give either density or mass_per_length, not both")
            row = FIELD_BY_KEY["cable.mass_per_length"]
            if not row.ge <= from_density <= row.le:
                raise ScenarioError("cable.density", f"gives a mass per length ρ·π r² = {from_density!r} kg/m with "
                                                     f"cable.radius {self.radius_m!r} m, outside {row.ge:g} … "
                                                     f"{row.le:g} kg/m ({row.why})")
            object.__setattr__(self, "mass_per_length_kg_per_m", from_density)

    @property
    def _NOT_ECHOED(self) -> frozenset[str]:  # type: ignore[override]
        # mass_per_length follows from density when that was given, elements from element_length
        out = {"mass_per_length_kg_per_m"} if self.density_kg_per_m3 is not None else set()
        if self.element_length_m is not None:
            out.add("elements")
        return frozenset(out)

    @property
    def area_m2(self) -> float:
        """Cross-section area A = π r² [m²]."""
        return math.pi * self.radius_m**2

    @property
    def axial_stiffness_N(self) -> float:
        """Axial stiffness EA [N]."""
        return self.youngs_modulus_Pa * self.area_m2

    @property
    def bending_stiffness_N_m2(self) -> float:
        """Bending stiffness EJ [N m²]: as given, else E π r⁴ / 4 (solid circular section)."""
        if self.bending_stiffness_given_N_m2 is not None:
            return self.bending_stiffness_given_N_m2
        return self.youngs_modulus_Pa * math.pi * self.radius_m**4 / 4.0

    @property
    def axial_damping_N_s(self) -> float:
        """Axial damping τ·EA [N s] (force per unit axial strain rate)."""
        return self.damping_time_s * self.axial_stiffness_N

    @property
    def bending_damping_N_m2_s(self) -> float:
        """Bending damping τ·EJ [N m² s] (moment per unit curvature rate)."""
        return self.damping_time_s * self.bending_stiffness_N_m2


@dataclass(frozen=True)
class ConduitSpec(_Spec):
    """The conduit route (paper Sect. 2.3): a path of primitives or survey points.

    Build it with :class:`exucable.Route` in Python or the ``[conduit]`` table of a file.

    Attributes
    ----------
    inner_radius_m : float
        Conduit inner radius R [m].
    start_m : tuple of 3 float
        Start point of the centreline [m] (survey routes: the first point).
    heading : tuple of 3 float
        Initial direction of the centreline, not necessarily unit length (survey routes: the
        first leg, points[1] − points[0]).
    max_segment_angle_deg : float or None
        Largest turning angle of one straight segment on curved parts [deg], or None when
        ``segments_per_bend`` is given.
    segments_per_bend : int or None
        Straight segments per curved piece (bend, helix, fillet), or None.
    path : tuple of geometry items or None
        ``Straight``/``Bend``/``Helix`` items of :mod:`exucable.geometry`, or None for a survey route.
    points_m : tuple of (x, y, z) tuples or None
        Survey points [m] (given inline or read from ``points_csv``), or None for a path route.
    bend_radius_m : float, tuple of float, or None
        Fillet radius at the interior survey vertices [m]: one value for all or one per vertex;
        None for a path route.
    points_csv : str or None
        Absolute path of the survey CSV the points were read from, or None.
    """

    _SECTION: ClassVar[str] = "conduit"
    _NONE_MEANS_NOT_USED: ClassVar[frozenset[str]] = frozenset({"max_segment_angle_deg"})   # segments_per_bend given

    inner_radius_m: float = _default("conduit.inner_radius")
    start_m: tuple[float, float, float] = _default("conduit.start")
    heading: tuple[float, float, float] = _default("conduit.heading")
    max_segment_angle_deg: float | None = None
    segments_per_bend: int | None = _default("conduit.segments_per_bend")
    path: tuple[_geo.Straight | _geo.Bend | _geo.Helix, ...] | None = None
    points_m: tuple[tuple[float, float, float], ...] | None = None
    bend_radius_m: float | tuple[float, ...] | None = None
    points_csv: str | None = None

    def __post_init__(self):
        # max_segment_angle defaults to 1 deg only when segments_per_bend is not given.
        if self.segments_per_bend is not None:
            if self.max_segment_angle_deg is not None:
                raise ScenarioError(
                    "conduit.segments_per_bend", "give either max_segment_angle or segments_per_bend, not both"
                )
            super().__post_init__()
            object.__setattr__(self, "max_segment_angle_deg", None)
            return
        if self.max_segment_angle_deg is None:
            object.__setattr__(self, "max_segment_angle_deg", FIELD_BY_KEY["conduit.max_segment_angle"].default)
        super().__post_init__()

    def _check(self) -> None:
        if self.path is None and self.points_m is None:
            raise ScenarioError("conduit.path", "required: give path (a list of pieces), points or points_csv")
        if self.path is not None and self.points_m is not None:
            raise ScenarioError("conduit.points", "give only one of path, points, points_csv; got path and points")

    def to_dict(self) -> dict:
        """The ``[conduit]`` table in TOML key names, defaults filled in."""
        d: dict[str, Any] = {"inner_radius": self.inner_radius_m}
        if self.path is not None:
            d["start"] = list(self.start_m)
            d["heading"] = list(self.heading)
        if self.segments_per_bend is not None:
            d["segments_per_bend"] = self.segments_per_bend
        else:
            d["max_segment_angle"] = self.max_segment_angle_deg
        if self.path is not None:
            d["path"] = [_path_item_to_dict(item) for item in self.path]
        elif self.points_csv is not None:
            d["points_csv"] = self.points_csv
        else:
            d["points"] = [list(p) for p in self.points_m]
        if self.bend_radius_m is not None:
            d["bend_radius"] = (
                list(self.bend_radius_m) if isinstance(self.bend_radius_m, tuple) else self.bend_radius_m
            )
        return d

    @classmethod
    def from_keys(cls, **keys):
        """Build from TOML key names (``points_csv`` relative to the working directory)."""
        return parse_conduit(keys, Path("."))


@dataclass(frozen=True)
class ContactSpec(_Spec):
    """Cable–conduit contact law (paper Sect. 2.4, Eqs. 17–23).

    Attributes
    ----------
    stiffness : float
        Hertz contact stiffness K_n [N/m^exponent].
    damping : float
        Contact damping C_n [N s/m].
    exponent : float
        Hertz exponent e [-].
    friction : float
        Kinetic (Coulomb) friction coefficient μ [-].
    cable_friction : float
        Kinetic friction coefficient between the cables of a bundle μ_c [-] (``cable.count`` > 1).
    static_friction : float or None
        Static friction coefficient μ_s ≥ μ [-], or None for no static peak.
    stribeck_velocity_m_per_s : float
        Decay velocity of the static-to-kinetic transition [m/s].
    friction_regularisation_velocity_m_per_s : float or None
        Sliding speed below which friction is regularised (linear in velocity) [m/s]; None until a
        :class:`Scenario` sets :data:`REGULARISATION_FRACTION_OF_SPEED` of its pull speed.
    check_points_per_element : int or None
        Contact check points per cable element; None: the mesh rule's (:mod:`exucable.scenario.mesh`).
    check_point_rule : str
        ``"gauss"`` or ``"uniform"`` placement of check points along an element.
    reference_spacing_m : float
        Each check point's force is scaled by (its share of the element length) / this [m].
    broad_phase : str
        ``"aabb"`` (paper Sect. 2.5) or ``"none"``.
    damping_onset_m : float
        Penetration over which the contact damping grows from zero [m] (default 1e-5; 0: the
        paper's Eq. 18, whose damping force jumps to C δ̇ at first touch).
    surface : str
        ``"smooth"``: closest points on the exact bends and helices (default);
        ``"segments"``: on the straight segments, as the paper (see exucable.contact.smooth).
    """

    _SECTION: ClassVar[str] = "contact"

    stiffness: float = _default("contact.stiffness")
    damping: float = _default("contact.damping")
    exponent: float = _default("contact.exponent")
    friction: float = _default("contact.friction")
    cable_friction: float = _default("contact.cable_friction")
    static_friction: float | None = _default("contact.static_friction")
    stribeck_velocity_m_per_s: float = _default("contact.stribeck_velocity")
    friction_regularisation_velocity_m_per_s: float = _default("contact.friction_regularisation_velocity")
    check_points_per_element: int | None = _default("contact.check_points_per_element")
    check_point_rule: str = _default("contact.check_point_rule")
    reference_spacing_m: float = _default("contact.reference_spacing")
    broad_phase: str = _default("contact.broad_phase")
    surface: str = _default("contact.surface")
    damping_onset_m: float = _default("contact.damping_onset")

    def _check(self) -> None:
        if self.static_friction is not None and self.static_friction < self.friction:
            raise ScenarioError(
                "contact.static_friction",
                f"must be >= the kinetic friction {self.friction!r} (contact.friction), got {self.static_friction!r}",
            )


@dataclass(frozen=True)
class PullSpec(_Spec):
    """The pulling rig (paper Sect. 2.1, Eq. 1) and the far-end load.

    Attributes
    ----------
    speed_m_per_s : float
        Pulling speed [m/s].
    direction : str
        ``"forward"`` (toward the end of the route) or ``"reverse"``.
    back_tension_N : float
        Tension applied at the trailing end, along the conduit tangent [N].
    force_N : float or None
        Prescribed pulling force at the pulled end [N] (force-controlled pull), or None.
    ramp_time_s : float
        Time over which speed and loads ramp up from the start state [s].
    stop_time_s : float or None
        Time at which the eye stops (dynamic mode) [s], or None (never).
    hold_time_s : float or None
        How long it then stands still before pulling on [s], or None (to the end).
    feed_from_reel : bool
        ``exucable plan``: also compute the pull-in history.
    """

    _SECTION: ClassVar[str] = "pull"

    speed_m_per_s: float = _default("pull.speed")
    direction: str = _default("pull.direction")
    back_tension_N: float = _default("pull.back_tension")
    force_N: float | None = _default("pull.force")
    ramp_time_s: float = _default("pull.ramp_time")
    stop_time_s: float | None = _default("pull.stop_time")
    hold_time_s: float | None = _default("pull.hold_time")
    feed_from_reel: bool = _default("pull.feed_from_reel")

    def _check(self) -> None:
        if self.hold_time_s is not None and self.stop_time_s is None:
            raise ScenarioError("pull.hold_time", "holds a stopped pull: give pull.stop_time too, or remove it")
        if self.stop_time_s is not None and self.force_N is not None:
            raise ScenarioError("pull.stop_time", "stops the speed rig; a force-controlled pull (pull.force) has none: "
                                                  "remove one of them")
        if self.force_N is not None and self.back_tension_N != 0.0:
            raise ScenarioError(
                "pull.force",
                f"a prescribed pulling force cannot be combined with a nonzero pull.back_tension "
                f"({self.back_tension_N!r} N); give one of them",
            )


@dataclass(frozen=True)
class GravitySpec(_Spec):
    """Gravity along −z.

    Attributes
    ----------
    g_m_per_s2 : float
        Gravitational acceleration [m/s²].
    """

    _SECTION: ClassVar[str] = "gravity"

    g_m_per_s2: float = _default("gravity.g")


#: Most places of ``output.cross_sections``: the panels of one figure.
MAX_CROSS_SECTIONS = 8


@dataclass(frozen=True)
class OutputSpec(_Spec):
    """What is written besides the histories and final profiles.

    Attributes
    ----------
    snapshots_s : tuple of float
        Times at which the whole state is written (snapshot files) [s], sorted, each >= 0 (and
        <= ``solver.end_time``, checked by the scenario).
    snapshot_interval_s : float or None
        Also a snapshot every this many seconds, at k·interval, k = 1, 2, … [s].
    cross_sections_m : tuple of float
        Places s along the conduit where several cables are drawn across the duct [m], sorted,
        each >= 0 (and <= the conduit's length, checked by the scenario); empty: the middle of
        each straight and bend.
    """

    _SECTION: ClassVar[str] = "output"

    snapshots_s: tuple = ()
    snapshot_interval_s: float | None = None
    cross_sections_m: tuple = ()

    def _check(self) -> None:
        raw = self.snapshots_s
        if not isinstance(raw, (list, tuple)):
            raise ScenarioError("output.snapshots", f"must be an array of times [s], got {_describe(raw)}")
        if len(raw) > MAX_SNAPSHOTS:
            raise ScenarioError("output.snapshots", f"must have at most {MAX_SNAPSHOTS} times, got {len(raw)} ({_SIZE_WHY})")
        times = []
        for i, value in enumerate(raw):
            key = f"output.snapshots[{i}]"
            v = _as_float(key, value, "s")
            _check_range(key, v, "s", ge=0.0)
            times.append(v)
        object.__setattr__(self, "snapshots_s", tuple(sorted(set(times))))
        raw = self.cross_sections_m
        if not isinstance(raw, (list, tuple)):
            raise ScenarioError("output.cross_sections", f"must be an array of places s along the conduit [m], got "
                                                         f"{_describe(raw)}")
        if len(raw) > MAX_CROSS_SECTIONS:
            raise ScenarioError("output.cross_sections", f"must have at most {MAX_CROSS_SECTIONS} places (one "
                                                         f"figure's panels), got {len(raw)}")
        places = []
        for i, value in enumerate(raw):
            key = f"output.cross_sections[{i}]"
            v = _as_float(key, value, "m")
            _check_range(key, v, "m", ge=0.0)
            places.append(v)
        object.__setattr__(self, "cross_sections_m", tuple(sorted(set(places))))

    def times_s(self, end_time_s: float) -> tuple:
        """All snapshot times up to ``end_time_s`` [s], sorted, duplicates merged."""
        times = set(self.snapshots_s)
        if self.snapshot_interval_s is not None:
            n = int(math.floor(end_time_s / self.snapshot_interval_s * (1 + 1e-12)))
            times.update(k * self.snapshot_interval_s for k in range(1, n + 1))
        return tuple(sorted(t for t in times if t <= end_time_s))


@dataclass(frozen=True)
class SolverSpec(_Spec):
    """Time integration settings.

    Attributes
    ----------
    end_time_s : float or None
        Simulated end time [s]; required in dynamic mode, unused in steady mode.
    step_s : float
        Initial and maximum time step [s].
    min_step_s : float
        Smallest step the adaptive controller may take [s] (default min(1e-8 s, step)).
    spectral_radius : float
        Generalized-α ρ∞ [-] in [0, 1].
    newton_max_iterations : int
        Newton iterations per step before the step is cut.
    newton_tolerance : float
        Relative tolerance of Newton's residual [-].
    startup_time_s : float
        Duration of the start-up damper that settles the pre-tensioned start [s] (0: none).
    startup_damping_1_per_s : float
        Its initial rate c0 [1/s] (mass-proportional).
    exit_span_damping_1_per_s : float
        Rate [1/s] of the damper toward the steady flow on the cable past the conduit's exit
        (:class:`exucable.model.startup.ExitSpanDamper`); 0: none.
    output_interval_s : float
        Interval between stored output states [s] (default max(step, end_time/1000)).
    steady_stop : bool
        Stop once the pulling force is steady.
    steady_window_s : float
        Length of the window in which steadiness is judged [s].
    steady_tolerance : float
        Relative drift/scatter bound of the pulling force in that window [-].
    pretension : bool
        Start from the rope solution's tension profile near contact equilibrium.
    mode : {"auto", "dynamic", "steady"}
        ``"dynamic"``: integrate the paper's dynamics in time; ``"steady"``: solve the steady
        sliding state in one static solve (:mod:`exucable.solve.steady`); ``"auto"`` (the default)
        is resolved by the :class:`Scenario` (:func:`resolve_mode`), which holds the spec with
        the mode it chose.
    start_from : {"rope", "steady"}
        Dynamic mode: start from the rope's tension (``"rope"``) or from the steady solve's state
        (``"steady"``, :func:`exucable.solve.start.steady_start`).
    steady_residual : float
        Steady mode: equilibrium residual at which the static solve stops, relative to the rope
        solution's largest tension [-].
    steady_lead_out_m : float or None
        Steady mode: cable laid out past the conduit's exit at the start [m] (None: the rule of
        :func:`exucable.model.layout.steady_lead_out_m`, 10 bending lengths past the last bend).
    steady_time_limit_s : float
        Steady mode: CPU time one static solve may take before it stops as failed [s].    cable_element : {"exudyn", "compiled"}
        Steady mode: Exudyn's ``ObjectANCFCable`` or exucable's compiled copy of it
        (:mod:`exucable.contact.ancf_cable`) assembles the cable's elastic forces.
    static_solver : {"exucable", "exudyn"}
        Steady mode: who runs the static solves' Newton iterations: our own loop on the assembled
        system where the model allows it (:mod:`exucable.solve.newton_system`), or Exudyn's
        static solver.
    bundle_starts : tuple of str
        Steady mode, several cables: the starts tried in turn (:mod:`exucable.solve.bundle_starts`).
    """

    _SECTION: ClassVar[str] = "solver"

    end_time_s: float = _default("solver.end_time")
    step_s: float = _default("solver.step")
    min_step_s: float = _default("solver.min_step")
    spectral_radius: float = _default("solver.spectral_radius")
    newton_max_iterations: int = _default("solver.newton_max_iterations")
    newton_tolerance: float = _default("solver.newton_tolerance")
    startup_time_s: float = _default("solver.startup_time")
    startup_damping_1_per_s: float = _default("solver.startup_damping")
    exit_span_damping_1_per_s: float = _default("solver.exit_span_damping")
    output_interval_s: float = _default("solver.output_interval")
    steady_stop: bool = _default("solver.steady_stop")
    steady_window_s: float = _default("solver.steady_window")
    steady_tolerance: float = _default("solver.steady_tolerance")
    pretension: bool = _default("solver.pretension")
    mode: str = _default("solver.mode")
    steady_lead_out_m: float | None = _default("solver.steady_lead_out")
    steady_residual: float = _default("solver.steady_residual")
    steady_time_limit_s: float = _default("solver.steady_time_limit")
    start_from: str = _default("solver.start_from")
    cable_element: str = _default("solver.cable_element")
    static_solver: str = _default("solver.static_solver")
    bundle_starts: tuple = _default("solver.bundle_starts")

    @property
    def mode_rule(self) -> str:
        """Why :attr:`mode` is what it is: given, or what ``"auto"`` chose (:func:`resolve_mode`)."""
        return self.__dict__.get("_mode_rule", "given (solver.mode)" if self.mode != "auto" else "auto: not yet resolved")

    def _check(self) -> None:
        if self.mode in (None, "auto"):
            # resolved by the Scenario, which knows the pull and the outputs asked for
            object.__setattr__(self, "mode", "auto")
            object.__setattr__(self, "_derived", self._derived | {"mode"})
        if self.mode == "steady" and not self.pretension:
            raise ScenarioError("solver.pretension", 'solver.mode = "steady" starts from the rope solution '
                                "near the steady state; set it to true (or use the dynamic mode)")
        if self.min_step_s is None:
            object.__setattr__(self, "min_step_s", min(_DEFAULT_MIN_STEP_S, self.step_s))
        elif self.min_step_s > self.step_s:
            raise ScenarioError("solver.min_step", f"must be <= solver.step ({self.step_s!r} s), got {self.min_step_s!r}")
        if self.output_interval_s is None:
            object.__setattr__(self, "output_interval_s",
                               self.step_s if self.end_time_s is None else max(self.step_s, self.end_time_s / 1000.0))


@dataclass(frozen=True)
class LimitsSpec(_Spec):
    """The cable's installation limits, checked by ``exucable plan`` (all optional; SI).

    Attributes
    ----------
    max_tension_N, grip_limit_N : float or None
        Largest pulling tension given directly; rating of the pulling eye or grip [N].
    conductor_material : str or None
        ``"copper"`` or ``"aluminium"``; with ``conductor_area_m2`` and ``conductors`` gives the
        conductors' tension limit (:func:`exucable.quasistatic.engineering.max_tension_from_conductors_N`).
    conductor_area_m2 : float or None
        Cross-section of one conductor [m²].
    conductors : int or None
        Conductors sharing the pull.
    conductor_rule : str or None
        ``"iec"`` or ``"us"``; None: ``"us"`` with imperial display units, else ``"iec"``.
    max_sidewall_pressure_N_per_m : float or None
        Largest sidewall bearing pressure [N/m].
    min_bend_radius_multiple : float or None
        Smallest bend radius as a multiple of the cable diameter [-].
    min_clearance_m : float or None
        Smallest clearance between the uppermost cable and the duct [m].
    max_fill_percent : float or None
        Largest conduit fill n·d²/D² [%].
    """

    _SECTION: ClassVar[str] = "limits"

    max_tension_N: float | None = _default("limits.max_tension")
    grip_limit_N: float | None = _default("limits.grip_limit")
    conductor_material: str | None = _default("limits.conductor_material")
    conductor_area_m2: float | None = _default("limits.conductor_area")
    conductors: int | None = _default("limits.conductors")
    conductor_rule: str | None = _default("limits.conductor_rule")
    max_sidewall_pressure_N_per_m: float | None = _default("limits.max_sidewall_pressure")
    min_bend_radius_multiple: float | None = _default("limits.min_bend_radius_multiple")
    min_clearance_m: float | None = _default("limits.min_clearance")
    max_fill_percent: float | None = _default("limits.max_fill")

    def _check(self) -> None:
        group = ("conductor_material", "conductor_area_m2", "conductors")
        given = [a for a in group if getattr(self, a) is not None]
        if given and len(given) < 3:
            missing = next(a for a in group if getattr(self, a) is None)
            name = {"conductor_material": "conductor_material", "conductor_area_m2": "conductor_area",
                    "conductors": "conductors"}[missing]
            raise ScenarioError(f"limits.{name}", "the conductor limit needs conductor_material, conductor_area and "
                                                  "conductors together")
        if self.conductor_rule is not None and not given:
            raise ScenarioError("limits.conductor_rule", "given without conductor_material, conductor_area and "
                                                         "conductors")


@dataclass(frozen=True)
class DisplaySpec(_Spec):
    """How numbers are read and shown.

    Attributes
    ----------
    units : str
        ``"si"`` or ``"imperial"``: unit system of bare numbers in the file (converted to SI when it
        is read) and of printed tables. Results files stay SI.
    point_names : tuple of str or None
        Names of the route's points in route order (its start, then the end of each piece), or None
        for the default A, B, C, … (``exucable plan`` checks the count against the route).
    """

    _SECTION: ClassVar[str] = "display"

    units: str = _default("display.units")
    point_names: tuple[str, ...] | None = _default("display.point_names")


def _curved_turning_deg(conduit: ConduitSpec) -> list[float]:
    """Turning of each curved piece of a route before it is built [deg] (a helix: 360° a turn, an
    upper bound; a survey fillet: the angle between its legs)."""
    if conduit.path is not None:
        out = []
        for item in conduit.path:
            if isinstance(item, _geo.Bend):
                out.append(float(item.angle_deg))
            elif isinstance(item, _geo.Helix):
                out.append(360.0 * float(item.turns))
        return out
    # a survey fillet turns by the angle between its two legs
    legs = [tuple(b - a for a, b in zip(p, q)) for p, q in zip(conduit.points_m[:-1], conduit.points_m[1:])]
    out = []
    for u, v in zip(legs[:-1], legs[1:]):
        nu, nv = math.hypot(*u), math.hypot(*v)
        cos = sum(a * b for a, b in zip(u, v)) / (nu * nv) if nu > 0.0 and nv > 0.0 else 1.0
        out.append(math.degrees(math.acos(min(1.0, max(-1.0, cos)))))
    return out


def _check_sizes(sc: "Scenario") -> None:
    """Refuse a scenario whose derived sizes (segments, check points, outputs, snapshots) would not
    keep the run finite, before the conduit or the model is built."""
    cd = sc.conduit
    turning = _curved_turning_deg(cd)
    if cd.segments_per_bend is not None:
        n_seg, key = cd.segments_per_bend * len(turning), "conduit.segments_per_bend"
    else:
        n_seg = sum(math.ceil(t / cd.max_segment_angle_deg) for t in turning)
        key = "conduit.max_segment_angle"
    if n_seg > MAX_SEGMENTS:
        raise ScenarioError(key, f"gives about {n_seg} conduit segments on {len(turning)} curved pieces, more than "
                                 f"{MAX_SEGMENTS} ({_SIZE_WHY}); give a larger max_segment_angle or fewer segments_per_bend")
    c = sc.cable
    if c.elements is not None and sc.contact.check_points_per_element is not None:
        n_cp = c.elements * sc.contact.check_points_per_element
        from .mesh import MAX_MODEL_CHECK_POINTS
        if n_cp > MAX_MODEL_CHECK_POINTS:
            raise ScenarioError("contact.check_points_per_element",
                                f"{c.elements} elements × {sc.contact.check_points_per_element} check points = {n_cp}, "
                                f"more than {MAX_MODEL_CHECK_POINTS} ({_SIZE_WHY}); give fewer of either")
    sp = sc.solver
    if sp.end_time_s is None:       # steady mode needs no end time: no outputs or snapshots to count
        return
    if sp.end_time_s / sp.output_interval_s > MAX_OUTPUTS:
        raise ScenarioError("solver.output_interval", f"gives {sp.end_time_s / sp.output_interval_s:.3g} outputs over "
                                                      f"solver.end_time {sp.end_time_s:g} s, more than {MAX_OUTPUTS} "
                                                      f"({_SIZE_WHY}); give a longer interval")
    iv = sc.output.snapshot_interval_s
    if iv is not None and sp.end_time_s / iv > MAX_SNAPSHOTS:
        raise ScenarioError("output.snapshot_interval", f"gives {sp.end_time_s / iv:.3g} snapshots over solver.end_time "
                                                        f"{sp.end_time_s:g} s, more than {MAX_SNAPSHOTS} ({_SIZE_WHY}); "
                                                        "give a longer interval")


def _check_friction_turning(sc: "Scenario", conduit) -> None:
    """Refuse μ·θ (the route's total turning θ) beyond :data:`MAX_FRICTION_TURNING`: the capstan
    ratio e^(μθ) would exceed any real pull and overflow the rope's exponentials."""
    mu = max(sc.contact.friction, sc.contact.static_friction or 0.0)
    theta = float(sum(p.turning_angle_rad for p in conduit.centreline.pieces if p.is_curved))
    if mu * theta > MAX_FRICTION_TURNING:
        key = "contact.static_friction" if (sc.contact.static_friction or 0.0) > sc.contact.friction else "contact.friction"
        raise ScenarioError(key, f"μ {mu:g} × the route's total turning {theta:.4g} rad = {mu * theta:.4g}: the capstan "
                                 f"ratio e^(μθ) would exceed e^{MAX_FRICTION_TURNING:g} (no real pull; the tension "
                                 "overflows); check the friction and the route")


def resolve_mode(solver: SolverSpec, output: OutputSpec) -> tuple[str, str]:
    """The solver mode ``solver.mode = "auto"`` stands for, and why.

    Steady mode gives the steady sliding state's pulling force in one static solve, with its
    discretisation uncertainty, in a fraction of a dynamic run's time; it is the answer a route
    plan needs. The dynamic mode is chosen only when the scenario asks for what only the time
    integration gives (snapshots of the state at given times) or for a start steady mode cannot
    solve from (``solver.pretension = false``).

    Returns
    -------
    mode : {"steady", "dynamic"}
    rule : str
        One line for the summary's ``mode_rule``.
    """
    if solver.mode not in (None, "auto"):
        return solver.mode, "given (solver.mode)"
    if output.snapshots_s or output.snapshot_interval_s is not None:
        return "dynamic", "auto: [output] snapshots need the time integration"
    if not solver.pretension:
        return "dynamic", "auto: solver.pretension = false (steady mode starts from the rope solution)"
    return "steady", "auto: the steady sliding state in one static solve (set solver.mode = \"dynamic\" for the transient)"


def default_elements(centreline, clearance_m: float, cable_length_m: float,
                     element_length_m: float | None = None) -> int:
    """The default number of cable elements: the mesh rule's (:func:`exucable.scenario.mesh.rule_element_length_m`:
    chord sagitta ≤ 2 clearances and ≤ 0.2 rad per element on the tightest bend, at least 10), or
    ⌈L / element_length⌉ when an element length is asked for.

    Parameters
    ----------
    centreline : exucable.geometry.Centreline
        The route's centreline.
    clearance_m : float
        Conduit inner radius − cable radius [m].
    cable_length_m : float
        Cable length L [m].
    element_length_m : float, optional
        ``cable.element_length`` [m].
    """
    from .mesh import rule_element_length_m
    h = element_length_m if element_length_m is not None else rule_element_length_m(centreline, clearance_m, cable_length_m)
    return max(1, math.ceil(cable_length_m / h - 1e-9))


@dataclass(frozen=True)
class Scenario:
    """One validated pulling simulation.

    Built from a file (:func:`load_scenario`) or in Python, where every part not given has its
    default (``contact``: :class:`ContactSpec` defaults; ``gravity``: none)::

        Scenario(route=Route(inner_radius=3.5e-3).straight(1.0), cable=CableSpec.from_keys(...),
                 pull=PullSpec(speed_m_per_s=0.1), solver=SolverSpec(end_time_s=0.5))

    Attributes
    ----------
    name : str
        Scenario name (default: the file stem, or ``"scenario"``).
    description : str
        Free text.
    cable, conduit, contact, pull : CableSpec, ConduitSpec, ContactSpec, PullSpec
        ``cable.elements`` is filled in from :func:`default_elements` (the mesh rule) when not given.
    gravity : GravitySpec or None
        None: no gravity.
    solver : SolverSpec
    output : OutputSpec
        Snapshot times (default: none).
    limits : LimitsSpec
        Installation limits checked by ``exucable plan`` (default: none).
    display : DisplaySpec
        Unit system of the file's bare numbers and of printed tables (default: SI).
    source_path : Path or None
        File the scenario was read from (provenance only; not compared).
    route : exucable.Route, optional
        Init-only: the conduit as a route builder (instead of ``conduit``).
    """

    name: str | None = None
    description: str = ""
    cable: CableSpec | None = None
    conduit: ConduitSpec | None = None
    contact: ContactSpec = field(default_factory=ContactSpec)
    pull: PullSpec | None = None
    gravity: GravitySpec | None = None
    solver: SolverSpec = field(default_factory=SolverSpec)
    output: OutputSpec = field(default_factory=OutputSpec)
    limits: LimitsSpec = field(default_factory=LimitsSpec)
    display: DisplaySpec = field(default_factory=DisplaySpec)
    source_path: Path | None = field(default=None, compare=False)
    route: InitVar[Any] = None

    def __post_init__(self, route):
        if route is not None:
            if not hasattr(route, "to_spec"):
                raise ScenarioError("route", f"must be an exucable.Route (Route(inner_radius=...).straight(...)"
                                             f".bend(...)), got {_describe(route)}; survey points: "
                                             "Route.from_survey(points, bend_radius, inner_radius)")
            if self.conduit is not None:
                raise ScenarioError("conduit", "give either route or conduit, not both")
            object.__setattr__(self, "conduit", route.to_spec())
        if self.name is None:
            object.__setattr__(self, "name", "scenario")
        coerce_value(FIELD_BY_KEY["name"], self.name)
        if not self.name.strip():
            raise ScenarioError("name", "must be a non-empty string")
        coerce_value(FIELD_BY_KEY["description"], self.description)
        for part, cls, how in (
            ("cable", CableSpec, "exucable.Cable(...)"),
            ("conduit", ConduitSpec, "route=exucable.Route(...)"),
            ("contact", ContactSpec, "exucable.Contact(...)"),
            ("pull", PullSpec, "exucable.Pull(...)"),
        ):
            value = getattr(self, part)
            if value is None:
                raise ScenarioError(part, f"required: give the [{part}] table, or {part}={how} in Python")
            if not isinstance(value, cls):
                raise ScenarioError(part, f"must be a {cls.__name__} ({how}), got {_describe(value)}")
        if not isinstance(self.solver, SolverSpec):
            raise ScenarioError("solver", f"must be a SolverSpec (exucable.Solver(...)), got {_describe(self.solver)}")
        if not isinstance(self.output, OutputSpec):
            raise ScenarioError("output", f"must be an OutputSpec, got {_describe(self.output)}")
        if self.solver.mode == "auto":
            # a copy, not dataclasses.replace: that would re-check and read the mode as given
            solver = copy.copy(self.solver)
            mode, rule = resolve_mode(self.solver, self.output)
            object.__setattr__(solver, "mode", mode)
            object.__setattr__(solver, "_mode_rule", rule)
            object.__setattr__(self, "solver", solver)
        if self.pull.stop_time_s is not None and self.solver.mode == "steady":
            why = "" if "mode" not in self.solver.derived_keys else f" (solver.mode {self.solver.mode_rule})"
            raise ScenarioError("pull.stop_time", f"a pull that stops is a transient, steady mode has none{why}: set "
                                                  "solver.mode = \"dynamic\" or remove pull.stop_time")
        if self.pull.stop_time_s is not None and self.solver.exit_span_damping_1_per_s > 0.0:
            raise ScenarioError("pull.stop_time", "solver.exit_span_damping damps toward the flow at the pull speed, "
                                                  "which a stopped pull does not have: remove one of them")
        if self.solver.mode == "dynamic" and self.solver.end_time_s is None:
            why = "" if "mode" not in self.solver.derived_keys else f" (solver.mode {self.solver.mode_rule})"
            steady = ", or set solver.mode = \"steady\" (no end_time)" if self.solver.pretension else ""
            raise ScenarioError("solver.end_time", f"required in dynamic mode{why}: give the simulated time [s], "
                                                   f"e.g. end_time = 3.0 with steady_stop = true{steady}")
        far = [x for x in self.output.cross_sections_m if x > self.build_conduit().centreline.length_m * (1 + 1e-12)]
        if far:
            i = self.output.cross_sections_m.index(far[0])
            raise ScenarioError(f"output.cross_sections[{i}]", f"must be <= the conduit's length "
                                f"{self.build_conduit().centreline.length_m:.6g} m, got {far[0]!r}")
        late = [t for t in self.output.snapshots_s
                if self.solver.end_time_s is not None and t > self.solver.end_time_s]
        if late:
            i = self.output.snapshots_s.index(late[0])
            raise ScenarioError(f"output.snapshots[{i}]", f"must be <= solver.end_time = "
                                f"{self.solver.end_time_s!r} s, got {late[0]!r}")
        for part, cls in (("limits", LimitsSpec), ("display", DisplaySpec)):
            if not isinstance(getattr(self, part), cls):
                raise ScenarioError(part, f"must be a {cls.__name__}, got {_describe(getattr(self, part))}")
        if self.gravity is not None and not isinstance(self.gravity, GravitySpec):
            raise ScenarioError("gravity", f"must be a GravitySpec (exucable.Gravity(...)) or None, got "
                                           f"{_describe(self.gravity)}")
        if self.conduit.inner_radius_m <= self.cable.radius_m:
            raise ScenarioError(
                "conduit.inner_radius",
                f"must be > the cable radius {self.cable.radius_m!r} m (cable.radius), got {self.conduit.inner_radius_m!r}",
            )
        if self.cable.count > 1:
            _eng.check_fit(self.cable.count, 2.0 * self.conduit.inner_radius_m, 2.0 * self.cable.radius_m)
        if self.cable.positions_m is not None:
            _check_positions_fit(self.cable.positions_m, self.conduit.inner_radius_m, self.cable.radius_m)
        _check_sizes(self)
        conduit = self.build_conduit()  # route errors surface here, keyed
        _check_friction_turning(self, conduit)
        conduit_length_m = _conduit_length_m(conduit)
        # A relative tolerance absorbs float round-off when the length is written as the sum
        # of the route's pieces (e.g. ex1: 50 m cable in a 50 m conduit).
        shortest = FIELD_BY_KEY["cable.length"].ge
        if self.cable.length_m is None and conduit_length_m < shortest:
            raise ScenarioError("conduit.path", f"the route is {conduit_length_m:.3g} m long, and so the cable: at least "
                                                f"{shortest:g} m ({FIELD_BY_KEY['cable.length'].why})")
        if self.cable.length_m is not None and self.cable.length_m > conduit_length_m * (1.0 + 1e-9):
            raise ScenarioError(
                "cable.length",
                f"must be <= the conduit centreline length {conduit_length_m:.6g} m, got {self.cable.length_m!r}",
            )
        if self.contact.friction_regularisation_velocity_m_per_s is None:
            contact = copy.copy(self.contact)
            eps = REGULARISATION_FRACTION_OF_SPEED * self.pull.speed_m_per_s
            object.__setattr__(contact, "friction_regularisation_velocity_m_per_s", eps)
            object.__setattr__(contact, "_derived", contact.__dict__.get("_derived", frozenset())
                               | {"friction_regularisation_velocity_m_per_s"})
            object.__setattr__(self, "contact", contact)
        if self.cable.elements is None:
            n = default_elements(conduit.centreline, self.conduit.inner_radius_m - self.cable.radius_m,
                                 self.cable_length_m, self.cable.element_length_m)
            limit = FIELD_BY_KEY["cable.elements"].le
            if n > limit:
                key = "cable.element_length" if self.cable.element_length_m is not None else "conduit.inner_radius"
                raise ScenarioError(key, f"gives {n} cable elements (cable length {self.cable_length_m:.6g} m, clearance "
                                         f"{self.conduit.inner_radius_m - self.cable.radius_m:.3g} m under the mesh rule), "
                                         f"more than {limit} ({FIELD_BY_KEY['cable.elements'].why}); give a longer "
                                         "cable.element_length, fewer cable.elements, or a larger clearance")
            # a copy, not dataclasses.replace: that would re-check, and elements next to a given
            # element_length reads as both given
            cable = copy.copy(self.cable)
            object.__setattr__(cable, "elements", n)
            object.__setattr__(cable, "_derived", frozenset({"elements"}))
            object.__setattr__(self, "cable", cable)

    def build_conduit(self):
        """The conduit built from :attr:`conduit` (cached on this instance).

        Returns
        -------
        exucable.geometry.Conduit

        Raises
        ------
        ScenarioError
            If geometry cannot build the route; the key is prefixed with ``conduit.``.
        """
        cached = self.__dict__.get("_conduit")
        if cached is None:
            cached = conduit_from_spec(self.conduit)
            # Frozen dataclass: bypass __setattr__; the cache is not a field, so it takes
            # no part in equality, hashing or repr.
            object.__setattr__(self, "_conduit", cached)
        return cached

    def pulled_in(self, length_m: float, elements: int) -> "Scenario":
        """The pull with the cable's head ``length_m`` [m] into the conduit: the conduit as the pull
        meets it (reversed for ``pull.direction = "reverse"``) cut at the head
        (:meth:`exucable.geometry.Conduit.truncated`), pulled forward, the cable filling it on
        ``elements`` elements. A step of the multibody pull-in history (:mod:`exucable.solve.pull_in`): a
        scenario to build a model from, not to write back (its ``[conduit]`` table still names the whole route).

        Raises
        ------
        ScenarioError
            ``cable.length`` shorter than the route (the pull-in's cable is the length pulled in), or ``length_m``
            outside the route.
        """
        conduit = self.build_conduit()
        if self.cable.length_m is not None and self.cable.length_m < conduit.centreline.length_m * (1.0 - 1e-9):
            raise ScenarioError("cable.length", "a pull-in history fills the conduit up to the head; leave "
                                                "cable.length out (the route's length)")
        if self.pull.direction == "reverse":
            conduit = conduit.reversed()
        L = conduit.centreline.length_m
        if not (0.0 < float(length_m) <= L * (1.0 + 1e-9)):
            raise ScenarioError("pull_in", f"the head's pulled length must be in (0, {L:.6g}] m, got {length_m!r}")
        out = copy.copy(self)
        cable = copy.copy(self.cable)
        object.__setattr__(cable, "elements", int(elements))
        object.__setattr__(cable, "element_length_m", None)
        object.__setattr__(cable, "length_m", None)
        object.__setattr__(cable, "_derived", frozenset())
        object.__setattr__(out, "cable", cable)
        object.__setattr__(out, "pull", dataclasses.replace(self.pull, direction="forward"))
        # the built conduit is this scenario's own cut: build_conduit() returns it (its cache)
        object.__setattr__(out, "_conduit", conduit.truncated(min(float(length_m), L)))
        return out

    @property
    def cable_length_m(self) -> float:
        """Cable length [m]: ``cable.length`` or the conduit's centreline length."""
        if self.cable.length_m is not None:
            return self.cable.length_m
        return _conduit_length_m(self.build_conduit())

    def to_dict(self) -> dict:
        """The scenario in TOML key names with defaults filled in.

        ``parse_scenario(s.to_dict(), base_dir)`` returns a scenario equal to ``s``.
        """
        d: dict[str, Any] = {
            "name": self.name,
            "description": self.description,
            "cable": self.cable.to_dict(),
            "conduit": self.conduit.to_dict(),
            "contact": self.contact.to_dict(),
            "pull": self.pull.to_dict(),
        }
        if self.gravity is not None:
            d["gravity"] = self.gravity.to_dict()
        d["solver"] = self.solver.to_dict()
        d["output"] = self.output.to_dict()
        d["limits"] = self.limits.to_dict()
        if self.display.units != "si":
            # Bare numbers would be read back in the display system: echo the quantities with their SI unit.
            d = _quantities_as_si_strings(d)
        d["display"] = self.display.to_dict()
        return d

    def replace(self, **changes) -> "Scenario":
        """A copy with values changed by dotted key, validated like a file.

        Parameters
        ----------
        **changes
            Dotted keys as in ``scenarios/README.md`` and error messages:
            ``sc.replace(**{"contact.friction": 0.3, "conduit.path[1].radius": 0.8})``; a whole
            table may be given as a dict (``gravity={"g": 9.81}``) or ``None`` to remove an
            optional table (``gravity=None``). Derived defaults (``cable.elements``,
            ``contact.friction_regularisation_velocity``, ``solver.min_step``,
            ``solver.output_interval``) are derived again.

        Raises
        ------
        ScenarioError
            Naming the dotted key of the first bad value.
        """
        from .dotted import parse_key, set_value  # pure-dict helpers shared with sweeps

        # quantities as "<value> <SI unit>": read as the same numbers whatever display.units becomes
        # (bare numbers would be re-read in the new unit system)
        d = _quantities_as_si_strings(self.to_dict())
        for part in ("cable", "contact", "solver"):
            for name in getattr(self, part).derived_keys:
                d[part].pop(name, None)
        top_level = {"name", "description", "cable", "conduit", "contact", "pull", "gravity", "solver", "output",
                      "limits", "display"}
        for key, value in changes.items():
            tokens = parse_key(key, key)
            if len(tokens) == 1 and tokens[0] not in top_level:
                # a key inside a table given bare (friction=0.3): name the dotted key it means
                inside = [f.key for f in FIELDS if f.name == tokens[0]]
                hint = (f"did you mean {' or '.join(repr(k) for k in inside)}? Pass it as "
                        f"replace(**{{{inside[0]!r}: ...}})" if inside else
                        "give a dotted key such as 'contact.friction'")
                raise ScenarioError(key, f"not a top-level key; {hint}")
            if value is None and len(tokens) == 1 and tokens[0] in d:
                del d[tokens[0]]
                continue
            if hasattr(value, "to_dict"):
                value = value.to_dict()
            set_value(d, tokens, value, key)
        base_dir = self.source_path.parent if self.source_path is not None else Path(".")
        new = parse_scenario(d, base_dir, default_name=self.name)
        object.__setattr__(new, "source_path", self.source_path)
        return new

    with_ = replace


# --------------------------------------------------------------------------------------
# Public entry points
# --------------------------------------------------------------------------------------


def read_toml(path: Path, what: str = "scenario") -> dict:
    """Read a TOML file; every failure is a ScenarioError (key ``""``) naming the file."""
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except FileNotFoundError:
        hint = (" (or give a shipped scenario's name, e.g. paper_ex2_bend90; `exucable scenarios` lists them)"
                if what == "scenario" else "")
        raise ScenarioError("", f"{what} file not found: {path}{hint}") from None
    except IsADirectoryError:
        raise ScenarioError("", f"{what} path is a directory, not a file: {path}") from None
    except OSError as exc:
        raise ScenarioError("", f"cannot read {what} file {path}: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        # tomllib's message carries "(at line L, column C)"
        raise ScenarioError("", f"{path}: TOML syntax error: {exc}") from None
    except UnicodeDecodeError as exc:
        raise ScenarioError("", f"{path}: not UTF-8 text: {exc}") from None
    except RecursionError:
        raise ScenarioError("", f"{path}: nested too deeply to read (arrays or tables within each other "
                                "hundreds of levels deep)") from None


def load_scenario(path) -> Scenario:
    """Read and validate a scenario TOML file.

    Parameters
    ----------
    path : str or Path
        The scenario file, or a shipped scenario's name (``"paper_ex2_bend90"``,
        ``"fast/paper_ex2_bend90"``; :func:`exucable.data.resolve_scenario_path`). Relative paths
        inside it (``points_csv``) are resolved against its directory.

    Returns
    -------
    Scenario

    Raises
    ------
    ScenarioError
        Missing or unreadable file, TOML syntax error (key ``""``), or any invalid value.
    """
    from exucable.data import resolve_scenario_path

    path = resolve_scenario_path(path)
    data = read_toml(path, "scenario")
    scenario = parse_scenario(data, path.parent, default_name=path.stem)
    object.__setattr__(scenario, "source_path", path.resolve())
    return scenario


def parse_scenario(data: dict, base_dir: Path, default_name: str = "scenario") -> Scenario:
    """Validate a scenario given as a dict (as read from TOML) and build its conduit.

    Parameters
    ----------
    data : dict
        The scenario tables, in TOML key names.
    base_dir : Path
        Directory against which ``conduit.points_csv`` is resolved.
    default_name : str
        Name used when ``data`` has no ``name``.

    Returns
    -------
    Scenario
        With its conduit already built and cached (so route errors surface here).

    Raises
    ------
    ScenarioError
        The first problem found, naming its full dotted key.
    """
    top = _Table(data, "", {"name", "description", "cable", "conduit", "contact", "pull", "gravity", "solver",
                            "output", "limits", "display"})
    display = _parse_table("display", top.table("display", default={}), DisplaySpec)
    data = quantities_to_si(data, display.units)
    top = _Table(data, "", set(data))
    name = top.string("name", default=default_name)
    if not name.strip():
        raise ScenarioError("name", "must be a non-empty string")
    description = top.string("description", default="")

    cable = _parse_cable(top.table("cable"))
    conduit = parse_conduit(top.table("conduit"), Path(base_dir))
    contact = _parse_contact(top.table("contact", default={}))
    pull = _parse_pull(top.table("pull"))
    gravity_data = top.table("gravity", default=None)
    gravity = None if gravity_data is None else _parse_gravity(gravity_data)
    solver = _parse_solver(top.table("solver", default={}))
    output = _parse_output(top.table("output", default={}))
    limits = _parse_table("limits", top.table("limits", default={}), LimitsSpec)
    # Cross-section rules (inner radius > cable radius, cable length <= conduit length),
    # the route build and the default mesh are the Scenario's own checks.
    return Scenario(
        name=name,
        description=description,
        cable=cable,
        conduit=conduit,
        contact=contact,
        pull=pull,
        gravity=gravity,
        solver=solver,
        output=output,
        limits=limits,
        display=display,
    )


# Keys read as quantities: a bare number in the display unit system's unit (SI, or imperial: see
# scenarios/README.md) or a "value unit" string, converted to SI before the rows check them.
# (section, key) -> (dimension, cross-section length: inches rather than feet in imperial)
_QUANTITY_KEYS = {
    ("cable", "radius"): ("length", True),
    ("cable", "mass_per_length"): ("mass_per_length", False),
    ("cable", "length"): ("length", False),
    ("conduit", "inner_radius"): ("length", True),
    ("pull", "back_tension"): ("force", False),
    ("pull", "force"): ("force", False),
    ("pull", "speed"): ("speed", False),
    ("limits", "max_tension"): ("force", False),
    ("limits", "grip_limit"): ("force", False),
    ("limits", "conductor_area"): ("area", False),
    ("limits", "max_sidewall_pressure"): ("force_per_length", False),
    ("limits", "min_clearance"): ("length", True),
}
_PATH_QUANTITY_KEYS = {"straight": "length", "radius": "length", "pitch": "length"}


def quantities_to_si(data: dict, system: str) -> dict:
    """A copy of ``data`` with its quantity keys as SI numbers (:mod:`exucable.scenario.units`).

    In SI, bare numbers pass unchanged (only strings are converted), so SI files read as before.
    """
    from exucable.scenario.units import to_si

    def convert(key, value, dim, small):
        if system == "si" and (isinstance(value, bool) or not isinstance(value, (str, numbers.Real))):
            return value  # not a quantity: the row's own check words the error
        if isinstance(value, (str, numbers.Real)) and not isinstance(value, bool):
            return to_si(key, value, dim, system, small)
        return value

    out = dict(data)
    for (section, name), (dim, small) in _QUANTITY_KEYS.items():
        table = out.get(section)
        if isinstance(table, dict) and name in table:
            table = out[section] = dict(table)
            table[name] = convert(f"{section}.{name}", table[name], dim, small)
    conduit = out.get("conduit")
    if isinstance(conduit, dict) and isinstance(conduit.get("path"), list):
        path = []
        for i, item in enumerate(conduit["path"]):
            if isinstance(item, dict):
                item = dict(item)
                for name, dim in _PATH_QUANTITY_KEYS.items():
                    if name in item:
                        item[name] = convert(f"conduit.path[{i}].{name}", item[name], dim, False)
            path.append(item)
        out["conduit"] = dict(conduit, path=path)
    return out


_SI_UNIT = {"length": "m", "mass_per_length": "kg/m", "force": "N", "speed": "m/s", "area": "m2",
            "force_per_length": "N/m"}


def _quantities_as_si_strings(d: dict) -> dict:
    """The inverse of :func:`quantities_to_si` for an imperial scenario's echo: quantities as exact
    ``"<repr> <SI unit>"`` strings, so that reading the echo gives the same numbers."""
    def text(value, dim):
        return f"{float(value)!r} {_SI_UNIT[dim]}" if isinstance(value, (int, float)) and not isinstance(value, bool) else value

    out = dict(d)
    for (section, name), (dim, _) in _QUANTITY_KEYS.items():
        if isinstance(out.get(section), dict) and name in out[section]:
            out[section] = dict(out[section], **{name: text(out[section][name], dim)})
    conduit = out.get("conduit")
    if isinstance(conduit, dict) and isinstance(conduit.get("path"), list):
        out["conduit"] = dict(conduit, path=[
            {k: (text(v, _PATH_QUANTITY_KEYS[k]) if k in _PATH_QUANTITY_KEYS else v) for k, v in item.items()}
            for item in conduit["path"]])
    return out


# --------------------------------------------------------------------------------------
# Table reader: type and range checks with full dotted keys
# --------------------------------------------------------------------------------------


def _describe(value) -> str:
    """TOML-ish name of a value's type, for error messages."""
    if isinstance(value, bool):
        return f"a boolean ({str(value).lower()})"
    if isinstance(value, numbers.Integral):
        return f"an integer ({value})"
    if isinstance(value, numbers.Real):
        return f"a float ({float(value)!r})"
    if isinstance(value, str):
        return f"a string ({value!r})" if len(value) <= 80 else f"a string of {len(value)} characters ({value[:40]!r}...)"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, (list, tuple)):
        return f"an array of {len(value)} item(s)"
    return f"a {type(value).__name__}"


def _unit(unit: str) -> str:
    return f" ({unit})" if unit else ""


def _as_float(key: str, value, unit: str) -> float:
    """A finite float from an int or float (not a bool)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ScenarioError(key, f"must be a number{_unit(unit)}, got {_describe(value)}")
    try:
        v = float(value)
    except OverflowError:       # an integer of hundreds of digits
        raise ScenarioError(key, f"must be a finite number{_unit(unit)}, got an integer of {len(str(abs(value)))} "
                                 "digits") from None
    if not math.isfinite(v):
        raise ScenarioError(key, f"must be a finite number{_unit(unit)}, got {v}")
    return v


def _check_range(key: str, v, unit: str, gt=None, ge=None, lt=None, le=None, why: str = "") -> None:
    """Raise unless ``v`` satisfies every given bound. Without ``why`` the message lists them all;
    with ``why`` (a row with a plausibility range) it names the first bound broken, and for a
    nonzero one the reason for the range."""
    checks = (("> ", gt, lambda b: v > b), (">= ", ge, lambda b: v >= b), ("< ", lt, lambda b: v < b),
              ("<= ", le, lambda b: v <= b))
    broken = [(op, b) for op, b, ok in checks if b is not None and not ok(b)]
    if not broken:
        return
    got = repr(v) if not isinstance(v, int) or abs(v) < 10**30 else f"an integer of {len(str(abs(v)))} digits"
    if why:
        op, b = broken[0]
        raise ScenarioError(key, f"must be {op}{b:g}{_unit(unit)}, got {got}" + (f" ({why})" if b != 0 else ""))
    parts = [f"{op}{b:g}" for op, b, _ in checks if b is not None]
    raise ScenarioError(key, f"must be {' and '.join(parts)}{_unit(unit)}, got {got}")


def _vector3(key: str, value, unit: str, nonzero: bool = False, max_abs: float | None = None,
             why: str = "") -> tuple[float, float, float]:
    """Three finite numbers as a tuple, each of magnitude ≤ ``max_abs`` if given; ``nonzero``: the
    largest at least 1e-12 of ``max_abs`` (1e-12 without), so that its norm neither over- nor underflows."""
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        raise ScenarioError(key, f"must be an array of 3 numbers [x, y, z]{_unit(unit)}, got {_describe(value)}")
    out = []
    for j, c in enumerate(value):
        if isinstance(c, bool) or not isinstance(c, numbers.Real) or not math.isfinite(float(c)):
            raise ScenarioError(
                key, f"must be an array of 3 finite numbers{_unit(unit)}; item {j} is {_describe(c)}"
            )
        out.append(float(c))
    if nonzero and not any(out):
        raise ScenarioError(key, "must be a nonzero vector, got [0, 0, 0]")
    big = max(abs(c) for c in out)
    if max_abs is not None and big > max_abs:
        raise ScenarioError(key, f"each component must be within ±{max_abs:g}{_unit(unit)}, got {big!r}"
                                 + (f" ({why})" if why else ""))
    smallest = 1e-12 * (max_abs if max_abs is not None else 1.0)
    if nonzero and big < smallest:
        raise ScenarioError(key, f"must have a component of magnitude >= {smallest:g}{_unit(unit)}, got {out!r}")
    return (out[0], out[1], out[2])


class _Table:
    """One TOML table being validated; knows its dotted key and its allowed keys."""

    def __init__(self, data, key: str, allowed: set[str]):
        if not isinstance(data, dict):
            raise ScenarioError(key, f"must be a table, got {_describe(data)}")
        for k in data:
            if k not in allowed:
                hint = difflib.get_close_matches(str(k), sorted(allowed), n=1)
                where = f"[{key}]" if key else "the top level"
                msg = f"unknown key; allowed in {where}: {', '.join(sorted(allowed))}"
                if hint:
                    msg += f" (did you mean '{hint[0]}'?)"
                raise ScenarioError(self._join(key, str(k)), msg)
        self.data = data
        self.key = key

    @staticmethod
    def _join(prefix: str, name: str) -> str:
        return f"{prefix}.{name}" if prefix else name

    def k(self, name: str) -> str:
        """Full dotted key of ``name`` in this table."""
        return self._join(self.key, name)

    def has(self, name: str) -> bool:
        return name in self.data

    def _get(self, name: str, default, what: str = "a value"):
        if name in self.data:
            return self.data[name], True
        if default is REQUIRED:
            raise ScenarioError(self.k(name), f"required key is missing: give {what}")
        return default, False

    def number(self, name: str, unit: str, default=REQUIRED, why: str = "", **bounds) -> float | None:
        value, given = self._get(name, default, f"a number{_unit(unit)}")
        if not given and value is None:
            return None
        v = _as_float(self.k(name), value, unit)
        _check_range(self.k(name), v, unit, why=why, **bounds)
        return v

    def integer(self, name: str, default=REQUIRED, **bounds) -> int | None:
        value, given = self._get(name, default, "an integer")
        if not given and value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise ScenarioError(self.k(name), f"must be an integer, got {_describe(value)}")
        v = int(value)
        _check_range(self.k(name), v, "", **bounds)
        return v

    def boolean(self, name: str, default=REQUIRED) -> bool:
        value, _ = self._get(name, default, "true or false")
        if not isinstance(value, bool):
            raise ScenarioError(self.k(name), f"must be true or false, got {_describe(value)}")
        return value

    def string(self, name: str, default=REQUIRED) -> str:
        value, _ = self._get(name, default, "a string")
        if not isinstance(value, str):
            raise ScenarioError(self.k(name), f"must be a string, got {_describe(value)}")
        return value

    def choice(self, name: str, choices: tuple[str, ...], default=REQUIRED) -> str | None:
        value, given = self._get(name, default)
        if not given and value is None:
            return None
        allowed = ", ".join(f'"{c}"' for c in choices)
        if not isinstance(value, str) or value not in choices:
            raise ScenarioError(self.k(name), f"must be one of {allowed}, got {_describe(value)}")
        return value

    def vector3(self, name: str, unit: str, default=REQUIRED, nonzero: bool = False):
        value, given = self._get(name, default)
        if not given and value is None:
            return None
        return _vector3(self.k(name), value, unit, nonzero=nonzero)

    def table(self, name: str, default=REQUIRED):
        value, given = self._get(name, default, f"a table [{self.k(name)}]")
        if given and not isinstance(value, dict):
            raise ScenarioError(self.k(name), f"must be a table [{self.k(name)}], got {_describe(value)}")
        return value


# --------------------------------------------------------------------------------------
# Sections: the TOML front end of the dataclasses
# --------------------------------------------------------------------------------------


def _parse_table(section: str, data, cls):
    """A section whose keys are all scalar rows of FIELDS: unknown keys refused, the rest checked
    by the dataclass."""
    rows = fields_of(section)
    t = _Table(data, section, {f.name for f in rows})
    return cls(**{f.attr: t.data[f.name] for f in rows if f.name in t.data})


def _parse_cable(data) -> CableSpec:
    if isinstance(data, dict) and "density" in data and "mass_per_length" in data:
        _Table(data, "cable", {f.name for f in fields_of("cable")})  # unknown keys first
        raise ScenarioError("cable.mass_per_length", "give either density or mass_per_length, not both")
    return _parse_table("cable", data, CableSpec)


def _parse_contact(data) -> ContactSpec:
    return _parse_table("contact", data, ContactSpec)


def _parse_pull(data) -> PullSpec:
    return _parse_table("pull", data, PullSpec)


def _parse_gravity(data) -> GravitySpec:
    return _parse_table("gravity", data, GravitySpec)


def _parse_solver(data) -> SolverSpec:
    return _parse_table("solver", data, SolverSpec)


def _parse_output(data) -> OutputSpec:
    return _parse_table("output", data, OutputSpec)


_PATH_KINDS: dict[str, set[str]] = {
    "straight": {"straight"},
    "bend": {"bend", "radius", "turn", "axis"},
    "helix_turns": {"helix_turns", "radius", "pitch", "turn"},
}
_BEND_TURNS = ("left", "right", "up", "down")
_HELIX_TURNS = ("left", "right")


def parse_conduit(data, base_dir: Path) -> ConduitSpec:
    t = _Table(data, "conduit", {f.name for f in fields_of("conduit")})
    inner_radius = coerce_value(FIELD_BY_KEY["conduit.inner_radius"], t.data["inner_radius"]) if t.has(
        "inner_radius") else t.number("inner_radius", "m")
    if t.has("max_segment_angle") and t.has("segments_per_bend"):
        raise ScenarioError(
            "conduit.segments_per_bend", "give either max_segment_angle or segments_per_bend, not both"
        )

    # Exactly one route source.
    sources = [s for s in ("path", "points", "points_csv") if t.has(s)]
    if not sources:
        raise ScenarioError("conduit.path", "required: give path (a list of pieces), points or points_csv")
    if len(sources) > 1:
        raise ScenarioError(
            f"conduit.{sources[1]}", f"give only one of path, points, points_csv; got {' and '.join(sources)}"
        )

    route: dict[str, Any] = {}
    if t.has("path"):
        if t.has("bend_radius"):
            raise ScenarioError("conduit.bend_radius", "only used with points or points_csv, not with path")
        for name in ("start", "heading"):
            if t.has(name):
                route[f"{name}_m" if name == "start" else name] = t.data[name]
        route["path"] = _parse_path(t.data["path"], inner_radius)
    else:
        for path_key in ("start", "heading"):
            # Survey points fix the start and the initial direction themselves.
            if t.has(path_key):
                raise ScenarioError(f"conduit.{path_key}", "only used with path; survey points set the route")
        csv_radius = points_csv = None
        if t.has("points"):
            points = _parse_points("conduit.points", t.data["points"])
        else:
            points_csv, points, csv_radius = _read_points_csv(t.string("points_csv"), base_dir, inner_radius)
        if t.has("bend_radius"):
            # The scenario's value overrides a bend_radius column of the CSV.
            bend_radius = _parse_bend_radius(t.data["bend_radius"], len(points), inner_radius)
        elif csv_radius is not None:
            bend_radius = csv_radius
        else:
            raise ScenarioError(
                "conduit.bend_radius",
                "required with points/points_csv (m): one value or one per interior vertex"
                + (" (the CSV has no bend_radius column)" if points_csv is not None else ""),
            )
        # For the record: where the survey route starts and the direction of its first leg.
        route.update(
            start_m=points[0],
            heading=tuple(b - a for a, b in zip(points[0], points[1])),
            points_m=points,
            bend_radius_m=bend_radius,
            points_csv=points_csv,
        )

    return ConduitSpec(
        inner_radius_m=inner_radius,
        max_segment_angle_deg=t.data.get("max_segment_angle"),
        segments_per_bend=t.data.get("segments_per_bend"),
        **route,
    )


_PARSERS = {
    "cable": _parse_cable,
    "conduit": lambda data: parse_conduit(data, Path(".")),
    "contact": _parse_contact,
    "pull": _parse_pull,
    "gravity": _parse_gravity,
    "solver": _parse_solver,
    "output": _parse_output,
    "limits": lambda data: _parse_table("limits", data, LimitsSpec),
    "display": lambda data: _parse_table("display", data, DisplaySpec),
}


def _parse_path(value, inner_radius: float) -> tuple:
    key = "conduit.path"
    if not isinstance(value, (list, tuple)) or len(value) == 0:
        raise ScenarioError(
            key,
            "must be a non-empty array of pieces like { straight = 1.0 }, "
            "{ bend = 90.0, radius = 0.5, turn = \"left\" }, { helix_turns = 2.0, radius = 1.0, pitch = 0.05 }; "
            f"got {_describe(value)}",
        )
    if len(value) > MAX_PIECES:
        raise ScenarioError(key, f"must have at most {MAX_PIECES} pieces, got {len(value)} ({_SIZE_WHY})")
    items = []
    for i, raw in enumerate(value):
        ikey = f"{key}[{i}]"
        if not isinstance(raw, dict):
            raise ScenarioError(ikey, f"must be a table such as {{ straight = 1.0 }}, got {_describe(raw)}")
        kinds = [k for k in _PATH_KINDS if k in raw]
        if not kinds:
            raise ScenarioError(
                ikey, f"must contain exactly one of straight, bend, helix_turns; got keys {sorted(raw)}"
            )
        if len(kinds) > 1:
            raise ScenarioError(ikey, f"has both '{kinds[0]}' and '{kinds[1]}': one kind of piece per item")
        kind = kinds[0]
        t = _Table(raw, ikey, _PATH_KINDS[kind])
        try:
            if kind == "straight":
                item = _geo.Straight(t.number("straight", "m", gt=0.0, ge=MIN_PIECE_M, le=MAX_LENGTH_M, why=_PIECE_WHY))
            elif kind == "bend":
                angle = t.number("bend", "deg", gt=0.0, ge=MIN_TURN_DEG, lt=360.0, why=_TURN_WHY)
                radius = _curve_radius(t, inner_radius)
                if t.has("turn") and t.has("axis"):
                    raise ScenarioError(t.k("axis"), "give either turn or axis, not both")
                if not t.has("turn") and not t.has("axis"):
                    raise ScenarioError(
                        t.k("turn"), 'required: turn = "left"|"right"|"up"|"down", or axis = [x, y, z]'
                    )
                turn = t.choice("turn", _BEND_TURNS, default=None)
                axis = t.vector3("axis", "", default=None, nonzero=True)
                item = _geo.Bend(angle, radius, turn=turn, axis=axis)
            else:
                turns = t.number("helix_turns", "", gt=0.0, ge=MIN_TURN_DEG / 360.0, le=MAX_HELIX_TURNS, why=_TURN_WHY)
                radius = _curve_radius(t, inner_radius)
                # Negative pitch descends; zero pitch over more than one turn is refused by geometry.
                pitch = t.number("pitch", "m", ge=-MAX_LENGTH_M, le=MAX_LENGTH_M, why=_PIECE_WHY)
                turn = t.choice("turn", _HELIX_TURNS, default="left")
                item = _geo.Helix(turns, radius, pitch, turn=turn)
        except GeometryError as exc:
            raise _rekey(exc, ikey) from None
        items.append(item)
    return tuple(items)


def _curve_radius(t: _Table, inner_radius: float) -> float:
    """Centreline radius of a bend or helix: the conduit tube must not fold onto itself."""
    radius = t.number("radius", "m", gt=0.0, le=MAX_LENGTH_M, why=_PIECE_WHY)
    if radius <= inner_radius:
        raise ScenarioError(
            t.k("radius"), f"must be > the conduit inner radius {inner_radius!r} m, got {radius!r}"
        )
    return radius


def _parse_points(key: str, value) -> tuple[tuple[float, float, float], ...]:
    if not isinstance(value, (list, tuple)) or len(value) < 2:
        raise ScenarioError(key, f"must be an array of at least 2 points [[x, y, z], ...] (m), got {_describe(value)}")
    if len(value) > MAX_POINTS:
        raise ScenarioError(key, f"must have at most {MAX_POINTS} points, got {len(value)} ({_SIZE_WHY})")
    start = FIELD_BY_KEY["conduit.start"]
    return tuple(_vector3(f"{key}[{i}]", p, "m", max_abs=start.max_abs, why=start.why) for i, p in enumerate(value))


def _parse_bend_radius(value, n_points: int, inner_radius: float):
    key = "conduit.bend_radius"
    n_interior = max(n_points - 2, 0)

    def one(k, v):
        r = _as_float(k, v, "m")
        _check_range(k, r, "m", gt=0.0, le=MAX_LENGTH_M, why=_PIECE_WHY)
        if r <= inner_radius:
            raise ScenarioError(k, f"must be > the conduit inner radius {inner_radius!r} m, got {r!r}")
        return r

    if isinstance(value, (list, tuple)):
        if len(value) != n_interior:
            raise ScenarioError(
                key,
                f"must be one number or an array of {n_interior} (one per interior vertex) (m), "
                f"got {_describe(value)}",
            )
        return tuple(one(f"{key}[{i}]", v) for i, v in enumerate(value))
    return one(key, value)


def _read_points_csv(value: str, base_dir: Path, inner_radius: float):
    """Resolve and read a survey CSV.

    Returns
    -------
    (str, tuple of points, float tuple or None)
        Absolute path, the points [m], and the bend radii of the interior vertices [m]
        if the CSV has a ``bend_radius`` column.
    """
    key = "conduit.points_csv"
    if not value.strip():
        raise ScenarioError(key, "must be a file name (relative to the scenario file), got an empty string")
    path = (base_dir / value).resolve()
    if not path.is_file():
        raise ScenarioError(key, f"file not found: {path}")
    try:
        points, radii = _geo.read_survey_csv(path)
    except GeometryError as exc:
        # geometry keys are "points_csv" or "points_csv line k": keep the line in the message
        where = exc.key.removeprefix("points_csv").strip()
        raise ScenarioError(key, f"{path}{', ' + where if where else ''}: {exc.message}") from None
    pts = tuple((float(x), float(y), float(z)) for x, y, z in points)
    radius = None
    if radii is not None:
        # read_survey_csv gives one radius per row with NaN at the two ends (no fillet there).
        radius = tuple(float(r) for r in radii[1:-1])
        for j, r in enumerate(radius):
            if r <= inner_radius:
                raise ScenarioError(
                    key,
                    f"{path}: bend_radius on data row {j + 2} must be > the conduit inner radius "
                    f"{inner_radius!r} m, got {r!r}",
                )
    return str(path), pts, radius



# --------------------------------------------------------------------------------------
# Geometry glue
# --------------------------------------------------------------------------------------


def _rekey(exc: GeometryError, item_key: str | None = None) -> ScenarioError:
    """A GeometryError (keys relative to the conduit table) as a ScenarioError."""
    k = exc.key or ""
    # geometry names a helix's number of turns "helix"; the scenario key is "helix_turns"
    if k.endswith(".helix"):
        k += "_turns"
    if item_key is not None and not k.startswith(("path", "points")):
        full = f"{item_key}.{k}" if k else item_key
    else:
        full = f"conduit.{k}" if k else "conduit"
    return ScenarioError(full, exc.message)


def conduit_from_spec(spec: ConduitSpec):
    try:
        if spec.path is not None:
            centreline = _geo.centreline_from_path(spec.start_m, spec.heading, list(spec.path))
        else:
            centreline = _geo.centreline_from_survey(spec.points_m, spec.bend_radius_m)
        return _geo.Conduit.build(
            spec.inner_radius_m,
            centreline,
            max_segment_angle_deg=spec.max_segment_angle_deg,
            segments_per_bend=spec.segments_per_bend,
        )
    except GeometryError as exc:
        err = _rekey(exc)
        if spec.points_csv is not None and err.key.startswith("conduit.points"):
            # The user wrote no `points` key: point at the CSV and keep the row index.
            raise ScenarioError("conduit.points_csv", f"{spec.points_csv}: {exc.key}: {exc.message}") from None
        raise err from None


def _conduit_length_m(conduit) -> float:
    """Centreline length of a built conduit [m]."""
    return float(conduit.centreline.length_m)


def _path_item_to_dict(item) -> dict:
    """A geometry path item back in TOML form."""
    if isinstance(item, _geo.Straight):
        return {"straight": float(item.length_m)}
    if isinstance(item, _geo.Bend):
        d: dict[str, Any] = {"bend": float(item.angle_deg), "radius": float(item.radius_m)}
        if item.axis is not None:
            d["axis"] = [float(c) for c in item.axis]
        else:
            d["turn"] = item.turn
        return d
    if isinstance(item, _geo.Helix):
        return {
            "helix_turns": float(item.turns),
            "radius": float(item.radius_m),
            "pitch": float(item.pitch_m),
            "turn": item.turn,
        }
    raise TypeError(f"unknown conduit path item {item!r}")
