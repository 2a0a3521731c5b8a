"""Scenario files: TOML → validated, frozen dataclasses; every error names its key.

A scenario describes one pulling simulation: the cable (paper Sect. 2.2), the conduit
route (Sect. 2.3), the cable–conduit contact law (Sect. 2.4, Eqs. 17–23), the pulling
rig (Sect. 2.1, Eq. 1), gravity and the time integration settings. The keys, their
units and defaults are listed in ``scenarios/README.md``; SI units throughout, angles in
degrees.

Every problem with the input (unknown key, missing key, wrong type, non-physical value,
a route that cannot be built) raises ONE :class:`~exucable.errors.ScenarioError` whose
``key`` is the full dotted key, e.g. ``"conduit.path[2].radius"``, and whose message
says what is allowed and what was given.
"""

from __future__ import annotations

import difflib
import math
import numbers
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from exucable import geometry as _geo
from exucable.errors import GeometryError, ScenarioError

__all__ = [
    "CableSpec",
    "ConduitSpec",
    "ContactSpec",
    "PullSpec",
    "GravitySpec",
    "SolverSpec",
    "Scenario",
    "load_scenario",
    "parse_scenario",
]

# Defaults of optional keys (TOML key names). Values marked "ours" in the README are not
# in the paper; they are the project's choices.
_DEFAULT_MAX_SEGMENT_ANGLE_DEG = 1.0
# Kelvin-Voigt retardation time [s]: damps the element-scale axial modes of the paper's
# cables (omega ~ 1e3..1e4 rad/s -> damping ratio tau*omega/2 ~ 0.5..5) while the
# steady-state damping force tau*EA*d(eps)/dt stays negligible (material strain rate is tiny).
_DEFAULT_DAMPING_TIME_S = 1.0e-3
_DEFAULT_MIN_STEP_S = 1.0e-8

_REQUIRED = object()  # sentinel: the key has no default


# --------------------------------------------------------------------------------------
# Dataclasses
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CableSpec:
    """The cable (paper Sect. 2.2, Eqs. 2–10).

    Attributes
    ----------
    radius_m : float
        Cable radius r [m].
    mass_per_length_kg_per_m : float
        Mass per unit length ρA [kg/m] (from ``density`` when that was given).
    density_kg_per_m3 : float or None
        Density ρ [kg/m³] if the scenario gave it, else None (``mass_per_length`` was given).
    youngs_modulus_Pa : float
        Young's modulus E [Pa].
    elements : int
        Number of cable finite elements.
    length_m : float or None
        Cable length [m]; None means the conduit's centreline length.
    integration : str
        Exudyn's quadrature of the element's internal forces: ``"lobatto"`` (default),
        ``"reduced"`` or ``"full"`` (useReducedOrderIntegration 2, 1, 0).
    damping_time_s : float
        Kelvin–Voigt retardation time τ [s]; internal damping = τ × stiffness.
    """

    radius_m: float
    mass_per_length_kg_per_m: float
    density_kg_per_m3: float | None
    youngs_modulus_Pa: float
    elements: int
    length_m: float | None
    damping_time_s: float
    integration: str = "lobatto"

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
        """Bending stiffness EJ = E π r⁴ / 4 [N m²] (solid circular section)."""
        return self.youngs_modulus_Pa * math.pi * self.radius_m**4 / 4.0

    @property
    def axial_damping_N_s(self) -> float:
        """Axial damping τ·EA [N s] (force per unit axial strain rate)."""
        return self.damping_time_s * self.axial_stiffness_N

    @property
    def bending_damping_N_m2_s(self) -> float:
        """Bending damping τ·EJ [N m² s] (moment per unit curvature rate)."""
        return self.damping_time_s * self.bending_stiffness_N_m2

    def to_dict(self) -> dict:
        """The ``[cable]`` table in TOML key names, defaults filled in."""
        d: dict[str, Any] = {"radius": self.radius_m}
        if self.density_kg_per_m3 is not None:
            d["density"] = self.density_kg_per_m3
        else:
            d["mass_per_length"] = self.mass_per_length_kg_per_m
        d["youngs_modulus"] = self.youngs_modulus_Pa
        d["elements"] = self.elements
        if self.length_m is not None:
            d["length"] = self.length_m
        d["damping_time"] = self.damping_time_s
        d["integration"] = self.integration
        return d


@dataclass(frozen=True)
class ConduitSpec:
    """The conduit route (paper Sect. 2.3): a path of primitives or survey points.

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

    inner_radius_m: float
    start_m: tuple[float, float, float]
    heading: tuple[float, float, float]
    max_segment_angle_deg: float | None
    segments_per_bend: int | None
    path: tuple | None
    points_m: tuple[tuple[float, float, float], ...] | None
    bend_radius_m: float | tuple[float, ...] | None
    points_csv: str | None

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


@dataclass(frozen=True)
class ContactSpec:
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
    static_friction : float or None
        Static friction coefficient μ_s ≥ μ [-], or None for no static peak.
    stribeck_velocity_m_per_s : float
        Decay velocity of the static-to-kinetic transition [m/s].
    friction_regularisation_velocity_m_per_s : float
        Sliding speed below which friction is regularised (linear in velocity) [m/s].
    check_points_per_element : int
        Contact check points per cable element.
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

    stiffness: float
    damping: float
    exponent: float
    friction: float
    static_friction: float | None
    stribeck_velocity_m_per_s: float
    friction_regularisation_velocity_m_per_s: float
    check_points_per_element: int
    check_point_rule: str
    reference_spacing_m: float
    broad_phase: str
    surface: str = "smooth"
    damping_onset_m: float = 1.0e-5

    def to_dict(self) -> dict:
        """The ``[contact]`` table in TOML key names, defaults filled in."""
        d: dict[str, Any] = {
            "stiffness": self.stiffness,
            "damping": self.damping,
            "exponent": self.exponent,
            "friction": self.friction,
        }
        if self.static_friction is not None:
            d["static_friction"] = self.static_friction
        d.update(
            stribeck_velocity=self.stribeck_velocity_m_per_s,
            friction_regularisation_velocity=self.friction_regularisation_velocity_m_per_s,
            check_points_per_element=self.check_points_per_element,
            check_point_rule=self.check_point_rule,
            reference_spacing=self.reference_spacing_m,
            broad_phase=self.broad_phase,
            surface=self.surface,
            damping_onset=self.damping_onset_m,
        )
        return d


@dataclass(frozen=True)
class PullSpec:
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
    """

    speed_m_per_s: float
    direction: str
    back_tension_N: float
    force_N: float | None
    ramp_time_s: float

    def to_dict(self) -> dict:
        """The ``[pull]`` table in TOML key names, defaults filled in."""
        d: dict[str, Any] = {
            "speed": self.speed_m_per_s,
            "direction": self.direction,
            "back_tension": self.back_tension_N,
        }
        if self.force_N is not None:
            d["force"] = self.force_N
        d["ramp_time"] = self.ramp_time_s
        return d


@dataclass(frozen=True)
class GravitySpec:
    """Gravity along −z.

    Attributes
    ----------
    g_m_per_s2 : float
        Gravitational acceleration [m/s²].
    """

    g_m_per_s2: float

    def to_dict(self) -> dict:
        """The ``[gravity]`` table in TOML key names."""
        return {"g": self.g_m_per_s2}


@dataclass(frozen=True)
class SolverSpec:
    """Time integration settings.

    Attributes
    ----------
    end_time_s : float
        Simulated end time [s].
    step_s : float
        Initial and maximum time step [s].
    min_step_s : float
        Smallest step the adaptive controller may take [s].
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
    output_interval_s : float
        Interval between stored output states [s].
    steady_stop : bool
        Stop once the pulling force is steady.
    steady_window_s : float
        Length of the window in which steadiness is judged [s].
    steady_tolerance : float
        Relative drift/scatter bound of the pulling force in that window [-].
    pretension : bool
        Start from the rope solution's tension profile near contact equilibrium.
    mode : {"dynamic", "steady"}
        ``"dynamic"``: integrate the paper's dynamics in time; ``"steady"``: solve the steady
        sliding state in one static solve (:mod:`exucable.solve_steady`).
    """

    end_time_s: float
    step_s: float
    min_step_s: float
    spectral_radius: float
    newton_max_iterations: int
    output_interval_s: float
    steady_stop: bool
    steady_window_s: float
    steady_tolerance: float
    pretension: bool
    newton_tolerance: float = 1.0e-7
    startup_time_s: float = 0.05
    startup_damping_1_per_s: float = 200.0
    mode: str = "dynamic"

    def to_dict(self) -> dict:
        """The ``[solver]`` table in TOML key names, defaults filled in."""
        return {
            "end_time": self.end_time_s,
            "step": self.step_s,
            "min_step": self.min_step_s,
            "spectral_radius": self.spectral_radius,
            "newton_max_iterations": self.newton_max_iterations,
            "newton_tolerance": self.newton_tolerance,
            "startup_time": self.startup_time_s,
            "startup_damping": self.startup_damping_1_per_s,
            "output_interval": self.output_interval_s,
            "steady_stop": self.steady_stop,
            "steady_window": self.steady_window_s,
            "steady_tolerance": self.steady_tolerance,
            "pretension": self.pretension,
            "mode": self.mode,
        }


@dataclass(frozen=True)
class Scenario:
    """One validated pulling simulation.

    Attributes
    ----------
    name : str
        Scenario name (default: the file stem).
    description : str
        Free text.
    cable, conduit, contact, pull : CableSpec, ConduitSpec, ContactSpec, PullSpec
    gravity : GravitySpec or None
        None: no gravity.
    solver : SolverSpec
    source_path : Path or None
        File the scenario was read from (provenance only; not compared).
    """

    name: str
    description: str
    cable: CableSpec
    conduit: ConduitSpec
    contact: ContactSpec
    pull: PullSpec
    gravity: GravitySpec | None
    solver: SolverSpec
    source_path: Path | None = field(default=None, compare=False)

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
            cached = _build_conduit(self.conduit)
            # Frozen dataclass: bypass __setattr__; the cache is not a field, so it takes
            # no part in equality, hashing or repr.
            object.__setattr__(self, "_conduit", cached)
        return cached

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
        return d


# --------------------------------------------------------------------------------------
# Public entry points
# --------------------------------------------------------------------------------------


def read_toml(path: Path, what: str = "scenario") -> dict:
    """Read a TOML file; every failure is a ScenarioError (key ``""``) naming the file."""
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except FileNotFoundError:
        raise ScenarioError("", f"{what} file not found: {path}") from None
    except IsADirectoryError:
        raise ScenarioError("", f"{what} path is a directory, not a file: {path}") from None
    except OSError as exc:
        raise ScenarioError("", f"cannot read {what} file {path}: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        # tomllib's message carries "(at line L, column C)"
        raise ScenarioError("", f"{path}: TOML syntax error: {exc}") from None
    except UnicodeDecodeError as exc:
        raise ScenarioError("", f"{path}: not UTF-8 text: {exc}") from None


def load_scenario(path) -> Scenario:
    """Read and validate a scenario TOML file.

    Parameters
    ----------
    path : str or Path
        The scenario file. Relative paths inside it (``points_csv``) are resolved
        against its directory.

    Returns
    -------
    Scenario

    Raises
    ------
    ScenarioError
        Missing or unreadable file, TOML syntax error (key ``""``), or any invalid value.
    """
    path = Path(path)
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
    top = _Table(data, "", {"name", "description", "cable", "conduit", "contact", "pull", "gravity", "solver"})
    name = top.string("name", default=default_name)
    if not name.strip():
        raise ScenarioError("name", "must be a non-empty string")
    description = top.string("description", default="")

    cable = _parse_cable(top.table("cable"))
    conduit = _parse_conduit(top.table("conduit"), cable, Path(base_dir))
    contact = _parse_contact(top.table("contact", default={}))
    pull = _parse_pull(top.table("pull"))
    gravity_data = top.table("gravity", default=None)
    gravity = None if gravity_data is None else _parse_gravity(gravity_data)
    solver = _parse_solver(top.table("solver"))

    scenario = Scenario(
        name=name,
        description=description,
        cable=cable,
        conduit=conduit,
        contact=contact,
        pull=pull,
        gravity=gravity,
        solver=solver,
    )
    conduit_length_m = _conduit_length_m(scenario.build_conduit())
    # A relative tolerance absorbs float round-off when the length is written as the sum
    # of the route's pieces (e.g. ex1: 50 m cable in a 50 m conduit).
    if cable.length_m is not None and cable.length_m > conduit_length_m * (1.0 + 1e-9):
        raise ScenarioError(
            "cable.length",
            f"must be <= the conduit centreline length {conduit_length_m:.6g} m, got {cable.length_m!r}",
        )
    return scenario


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
        return f"a string ({value!r})"
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
    v = float(value)
    if not math.isfinite(v):
        raise ScenarioError(key, f"must be a finite number{_unit(unit)}, got {v}")
    return v


def _check_range(key: str, v, unit: str, gt=None, ge=None, lt=None, le=None) -> None:
    """Raise unless ``v`` satisfies every given bound; the message lists them all."""
    ok = (
        (gt is None or v > gt)
        and (ge is None or v >= ge)
        and (lt is None or v < lt)
        and (le is None or v <= le)
    )
    if ok:
        return
    parts = []
    if gt is not None:
        parts.append(f"> {gt:g}")
    if ge is not None:
        parts.append(f">= {ge:g}")
    if lt is not None:
        parts.append(f"< {lt:g}")
    if le is not None:
        parts.append(f"<= {le:g}")
    raise ScenarioError(key, f"must be {' and '.join(parts)}{_unit(unit)}, got {v!r}")


def _vector3(key: str, value, unit: str, nonzero: bool = False) -> tuple[float, float, float]:
    """Three finite numbers as a tuple."""
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
        if default is _REQUIRED:
            raise ScenarioError(self.k(name), f"required key is missing: give {what}")
        return default, False

    def number(self, name: str, unit: str, default=_REQUIRED, **bounds) -> float | None:
        value, given = self._get(name, default, f"a number{_unit(unit)}")
        if not given and value is None:
            return None
        v = _as_float(self.k(name), value, unit)
        _check_range(self.k(name), v, unit, **bounds)
        return v

    def integer(self, name: str, default=_REQUIRED, **bounds) -> int | None:
        value, given = self._get(name, default, "an integer")
        if not given and value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise ScenarioError(self.k(name), f"must be an integer, got {_describe(value)}")
        v = int(value)
        _check_range(self.k(name), v, "", **bounds)
        return v

    def boolean(self, name: str, default=_REQUIRED) -> bool:
        value, _ = self._get(name, default, "true or false")
        if not isinstance(value, bool):
            raise ScenarioError(self.k(name), f"must be true or false, got {_describe(value)}")
        return value

    def string(self, name: str, default=_REQUIRED) -> str:
        value, _ = self._get(name, default, "a string")
        if not isinstance(value, str):
            raise ScenarioError(self.k(name), f"must be a string, got {_describe(value)}")
        return value

    def choice(self, name: str, choices: tuple[str, ...], default=_REQUIRED) -> str | None:
        value, given = self._get(name, default)
        if not given and value is None:
            return None
        allowed = ", ".join(f'"{c}"' for c in choices)
        if not isinstance(value, str) or value not in choices:
            raise ScenarioError(self.k(name), f"must be one of {allowed}, got {_describe(value)}")
        return value

    def vector3(self, name: str, unit: str, default=_REQUIRED, nonzero: bool = False):
        value, given = self._get(name, default)
        if not given and value is None:
            return None
        return _vector3(self.k(name), value, unit, nonzero=nonzero)

    def table(self, name: str, default=_REQUIRED):
        value, given = self._get(name, default, f"a table [{self.k(name)}]")
        if given and not isinstance(value, dict):
            raise ScenarioError(self.k(name), f"must be a table [{self.k(name)}], got {_describe(value)}")
        return value


# --------------------------------------------------------------------------------------
# Sections
# --------------------------------------------------------------------------------------


def _parse_cable(data) -> CableSpec:
    t = _Table(
        data,
        "cable",
        {"radius", "density", "mass_per_length", "youngs_modulus", "elements", "length", "damping_time",
         "integration"},
    )
    radius = t.number("radius", "m", gt=0.0)
    if t.has("density") and t.has("mass_per_length"):
        raise ScenarioError("cable.mass_per_length", "give either density or mass_per_length, not both")
    if not t.has("density") and not t.has("mass_per_length"):
        raise ScenarioError("cable.density", "required: give density (kg/m^3) or mass_per_length (kg/m)")
    if t.has("density"):
        density = t.number("density", "kg/m^3", gt=0.0)
        mass_per_length = density * math.pi * radius**2
    else:
        density = None
        mass_per_length = t.number("mass_per_length", "kg/m", gt=0.0)
    return CableSpec(
        radius_m=radius,
        mass_per_length_kg_per_m=mass_per_length,
        density_kg_per_m3=density,
        youngs_modulus_Pa=t.number("youngs_modulus", "Pa", gt=0.0),
        elements=t.integer("elements", ge=1),
        length_m=t.number("length", "m", default=None, gt=0.0),
        damping_time_s=t.number("damping_time", "s", default=_DEFAULT_DAMPING_TIME_S, ge=0.0),
        integration=t.choice("integration", ("lobatto", "reduced", "full"), default="lobatto"),
    )


_PATH_KINDS: dict[str, set[str]] = {
    "straight": {"straight"},
    "bend": {"bend", "radius", "turn", "axis"},
    "helix_turns": {"helix_turns", "radius", "pitch", "turn"},
}
_BEND_TURNS = ("left", "right", "up", "down")
_HELIX_TURNS = ("left", "right")


def _parse_conduit(data, cable: CableSpec, base_dir: Path) -> ConduitSpec:
    t = _Table(
        data,
        "conduit",
        {
            "inner_radius", "start", "heading", "max_segment_angle", "segments_per_bend",
            "path", "points", "bend_radius", "points_csv",
        },
    )
    inner_radius = t.number("inner_radius", "m", gt=0.0)
    if inner_radius <= cable.radius_m:
        raise ScenarioError(
            "conduit.inner_radius",
            f"must be > the cable radius {cable.radius_m!r} m (cable.radius), got {inner_radius!r}",
        )
    if t.has("max_segment_angle") and t.has("segments_per_bend"):
        raise ScenarioError(
            "conduit.segments_per_bend", "give either max_segment_angle or segments_per_bend, not both"
        )
    segments_per_bend = t.integer("segments_per_bend", default=None, ge=1)
    max_angle = None
    if segments_per_bend is None:
        max_angle = t.number("max_segment_angle", "deg", default=_DEFAULT_MAX_SEGMENT_ANGLE_DEG, gt=0.0, le=45.0)

    # Exactly one route source.
    sources = [s for s in ("path", "points", "points_csv") if t.has(s)]
    if not sources:
        raise ScenarioError("conduit.path", "required: give path (a list of pieces), points or points_csv")
    if len(sources) > 1:
        raise ScenarioError(
            f"conduit.{sources[1]}", f"give only one of path, points, points_csv; got {' and '.join(sources)}"
        )

    path = points = bend_radius = points_csv = None
    if t.has("path"):
        if t.has("bend_radius"):
            raise ScenarioError("conduit.bend_radius", "only used with points or points_csv, not with path")
        start = t.vector3("start", "m", default=(0.0, 0.0, 0.0))
        heading = t.vector3("heading", "", default=(1.0, 0.0, 0.0), nonzero=True)
        path = _parse_path(t.data["path"], inner_radius)
    else:
        for path_key in ("start", "heading"):
            # Survey points fix the start and the initial direction themselves.
            if t.has(path_key):
                raise ScenarioError(f"conduit.{path_key}", "only used with path; survey points set the route")
        csv_radius = None
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
        start = points[0]
        heading = tuple(b - a for a, b in zip(points[0], points[1]))

    return ConduitSpec(
        inner_radius_m=inner_radius,
        start_m=start,
        heading=heading,
        max_segment_angle_deg=max_angle,
        segments_per_bend=segments_per_bend,
        path=path,
        points_m=points,
        bend_radius_m=bend_radius,
        points_csv=points_csv,
    )


def _parse_path(value, inner_radius: float) -> tuple:
    key = "conduit.path"
    if not isinstance(value, (list, tuple)) or len(value) == 0:
        raise ScenarioError(
            key,
            "must be a non-empty array of pieces like { straight = 1.0 }, "
            "{ bend = 90.0, radius = 0.5, turn = \"left\" }, { helix_turns = 2.0, radius = 1.0, pitch = 0.05 }; "
            f"got {_describe(value)}",
        )
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
                item = _geo.Straight(t.number("straight", "m", gt=0.0))
            elif kind == "bend":
                angle = t.number("bend", "deg", gt=0.0, lt=360.0)
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
                turns = t.number("helix_turns", "", gt=0.0)
                radius = _curve_radius(t, inner_radius)
                # Negative pitch descends; zero pitch over more than one turn is refused by geometry.
                pitch = t.number("pitch", "m")
                turn = t.choice("turn", _HELIX_TURNS, default="left")
                item = _geo.Helix(turns, radius, pitch, turn=turn)
        except GeometryError as exc:
            raise _rekey(exc, ikey) from None
        items.append(item)
    return tuple(items)


def _curve_radius(t: _Table, inner_radius: float) -> float:
    """Centreline radius of a bend or helix: the conduit tube must not fold onto itself."""
    radius = t.number("radius", "m", gt=0.0)
    if radius <= inner_radius:
        raise ScenarioError(
            t.k("radius"), f"must be > the conduit inner radius {inner_radius!r} m, got {radius!r}"
        )
    return radius


def _parse_points(key: str, value) -> tuple[tuple[float, float, float], ...]:
    if not isinstance(value, (list, tuple)) or len(value) < 2:
        raise ScenarioError(key, f"must be an array of at least 2 points [[x, y, z], ...] (m), got {_describe(value)}")
    return tuple(_vector3(f"{key}[{i}]", p, "m") for i, p in enumerate(value))


def _parse_bend_radius(value, n_points: int, inner_radius: float):
    key = "conduit.bend_radius"
    n_interior = max(n_points - 2, 0)

    def one(k, v):
        r = _as_float(k, v, "m")
        _check_range(k, r, "m", gt=0.0)
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


def _parse_contact(data) -> ContactSpec:
    t = _Table(
        data,
        "contact",
        {
            "stiffness", "damping", "exponent", "friction", "static_friction", "stribeck_velocity",
            "friction_regularisation_velocity", "check_points_per_element", "check_point_rule",
            "reference_spacing", "broad_phase", "surface", "damping_onset",
        },
    )
    friction = t.number("friction", "", default=0.0, ge=0.0)
    static_friction = t.number("static_friction", "", default=None, ge=0.0)
    if static_friction is not None and static_friction < friction:
        raise ScenarioError(
            "contact.static_friction",
            f"must be >= the kinetic friction {friction!r} (contact.friction), got {static_friction!r}",
        )
    return ContactSpec(
        stiffness=t.number("stiffness", "N/m^exponent", default=1.0e6, gt=0.0),
        damping=t.number("damping", "N s/m", default=1.0e3, ge=0.0),
        exponent=t.number("exponent", "", default=1.5, ge=1.0),
        friction=friction,
        static_friction=static_friction,
        stribeck_velocity_m_per_s=t.number("stribeck_velocity", "m/s", default=0.01, gt=0.0),
        friction_regularisation_velocity_m_per_s=t.number(
            "friction_regularisation_velocity", "m/s", default=1.0e-3, gt=0.0
        ),
        check_points_per_element=t.integer("check_points_per_element", default=20, ge=1),
        check_point_rule=t.choice("check_point_rule", ("gauss", "uniform"), default="gauss"),
        reference_spacing_m=t.number("reference_spacing", "m", default=1.0e-3, gt=0.0),
        broad_phase=t.choice("broad_phase", ("aabb", "none"), default="aabb"),
        surface=t.choice("surface", ("smooth", "segments"), default="smooth"),
        damping_onset_m=t.number("damping_onset", "m", default=1.0e-5, ge=0.0),
    )


def _parse_pull(data) -> PullSpec:
    t = _Table(data, "pull", {"speed", "direction", "back_tension", "force", "ramp_time"})
    speed = t.number("speed", "m/s", gt=0.0)
    direction = t.choice("direction", ("forward", "reverse"), default="forward")
    back_tension = t.number("back_tension", "N", default=0.0, ge=0.0)
    force = t.number("force", "N", default=None, gt=0.0)
    if force is not None and back_tension != 0.0:
        raise ScenarioError(
            "pull.force",
            f"a prescribed pulling force cannot be combined with a nonzero pull.back_tension ({back_tension!r} N); "
            "give one of them",
        )
    return PullSpec(
        speed_m_per_s=speed,
        direction=direction,
        back_tension_N=back_tension,
        force_N=force,
        ramp_time_s=t.number("ramp_time", "s", default=0.0, ge=0.0),
    )


def _parse_gravity(data) -> GravitySpec:
    t = _Table(data, "gravity", {"g"})
    return GravitySpec(g_m_per_s2=t.number("g", "m/s^2", ge=0.0))


SOLVER_MODES = ("dynamic", "steady")


def _parse_solver(data) -> SolverSpec:
    t = _Table(
        data,
        "solver",
        {
            "end_time", "step", "min_step", "spectral_radius", "newton_max_iterations", "newton_tolerance",
            "output_interval", "startup_time", "startup_damping",
            "steady_stop", "steady_window", "steady_tolerance", "pretension", "mode",
        },
    )
    end_time = t.number("end_time", "s", gt=0.0)
    step = t.number("step", "s", gt=0.0)
    min_step = t.number("min_step", "s", default=min(_DEFAULT_MIN_STEP_S, step), gt=0.0)
    if min_step > step:
        raise ScenarioError("solver.min_step", f"must be <= solver.step ({step!r} s), got {min_step!r}")
    mode = t.choice("mode", SOLVER_MODES, default="dynamic")
    pretension = t.boolean("pretension", default=True)
    if mode == "steady" and not pretension:
        raise ScenarioError("solver.pretension", 'solver.mode = "steady" starts from the rope solution\'s '
                            "tension profile near the steady state; set it to true (or use the dynamic mode)")
    return SolverSpec(
        end_time_s=end_time,
        step_s=step,
        min_step_s=min_step,
        spectral_radius=t.number("spectral_radius", "", default=0.5, ge=0.0, le=1.0),
        # 12 iterations and 1e-7: measured on Example 2, 735 -> 155 steps at the same pulling
        # force (within 0.02 %) as 8 and 1e-8 (exudyn-findings had 8 with a different start)
        newton_max_iterations=t.integer("newton_max_iterations", default=12, ge=1),
        newton_tolerance=t.number("newton_tolerance", "", default=1.0e-7, gt=0.0, lt=1.0),
        startup_time_s=t.number("startup_time", "s", default=0.05, ge=0.0),
        startup_damping_1_per_s=t.number("startup_damping", "1/s", default=200.0, ge=0.0),
        output_interval_s=t.number("output_interval", "s", default=max(step, end_time / 1000.0), gt=0.0),
        steady_stop=t.boolean("steady_stop", default=False),
        steady_window_s=t.number("steady_window", "s", default=0.2, gt=0.0),
        steady_tolerance=t.number("steady_tolerance", "", default=1.0e-3, gt=0.0),
        pretension=pretension,
        mode=mode,
    )


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


def _build_conduit(spec: ConduitSpec):
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
