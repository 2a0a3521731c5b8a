"""Units at the boundary: quantities read as SI numbers, imperial numbers or ``"value unit"`` strings.

Everything inside exucable is SI. Engineers who plan pulls in the US think in lb, ft and lb/ft; this
module converts their inputs to SI on the way in and the results back on the way out, and nothing else.

A quantity is read with :func:`to_si`: a bare number is taken in the unit system's default unit for
its dimension (SI or imperial, table :data:`DEFAULT_UNIT`), a string ``"500 lb/ft"`` in the unit it
names. A unit of the wrong dimension (``"500 lb"`` for a sidewall pressure) is refused with the key.

Conversion factors are the exact definitions (NIST SP 811, Appendix B): 1 ft = 0.3048 m,
1 in = 0.0254 m, 1 lbf = 4.4482216152605 N, 1 lb = 0.45359237 kg, 1 cmil = π/4 · (0.0254e-3 m)².
"""

from __future__ import annotations

import math
import numbers
import re

from exucable.errors import ScenarioError

__all__ = ["UNITS", "DEFAULT_UNIT", "SYSTEMS", "to_si", "from_si", "display_unit"]

_FT = 0.3048
_IN = 0.0254
_LBF = 4.4482216152605
_LB = 0.45359237
_CMIL = math.pi / 4.0 * (0.0254e-3) ** 2

SYSTEMS = ("si", "imperial")

# unit name -> (dimension, factor to SI)
UNITS: dict[str, tuple[str, float]] = {
    # length
    "m": ("length", 1.0), "mm": ("length", 1e-3), "cm": ("length", 1e-2), "km": ("length", 1e3),
    "ft": ("length", _FT), "in": ("length", _IN),
    # force
    "N": ("force", 1.0), "kN": ("force", 1e3), "lbf": ("force", _LBF), "lb": ("force", _LBF),
    "kgf": ("force", 9.80665),
    # force per length (sidewall pressure, weight per length)
    "N/m": ("force_per_length", 1.0), "kN/m": ("force_per_length", 1e3),
    "lb/ft": ("force_per_length", _LBF / _FT), "lbf/ft": ("force_per_length", _LBF / _FT),
    # mass per length
    "kg/m": ("mass_per_length", 1.0), "lbm/ft": ("mass_per_length", _LB / _FT),
    # area (conductor cross-section)
    "m2": ("area", 1.0), "mm2": ("area", 1e-6), "cmil": ("area", _CMIL), "kcmil": ("area", 1e3 * _CMIL),
    "in2": ("area", _IN**2),
    # stress (allowed conductor stress)
    "Pa": ("stress", 1.0), "N/mm2": ("stress", 1e6), "MPa": ("stress", 1e6), "psi": ("stress", _LBF / _IN**2),
    "lb/cmil": ("stress", _LBF / _CMIL),
    # speed
    "m/s": ("speed", 1.0), "ft/s": ("speed", _FT), "ft/min": ("speed", _FT / 60.0), "m/min": ("speed", 1 / 60.0),
}

# The unit of a bare number, per dimension and system. Imperial mass per length is the cable's weight
# per foot as manuals print it (lb/ft), read as pound-mass per foot.
DEFAULT_UNIT: dict[str, dict[str, str]] = {
    "si": {"length": "m", "force": "N", "force_per_length": "N/m", "mass_per_length": "kg/m", "area": "m2",
           "stress": "Pa", "speed": "m/s"},
    "imperial": {"length": "ft", "force": "lbf", "force_per_length": "lb/ft", "mass_per_length": "lbm/ft",
                 "area": "kcmil", "stress": "psi", "speed": "ft/s"},
}

# Short lengths (diameters, radii of cross-sections) read and shown in inches in imperial.
_SMALL_LENGTH = {"si": "m", "imperial": "in"}

_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z][A-Za-z0-9/]*)\s*$")


def display_unit(dimension: str, system: str, small: bool = False) -> str:
    """The unit a quantity of ``dimension`` is shown in for ``system`` (``small``: cross-section lengths)."""
    if dimension == "length" and small:
        return _SMALL_LENGTH[system]
    return DEFAULT_UNIT[system][dimension]


def _short(value) -> str:
    """``repr(value)``, cut to 60 characters for the one-line error."""
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:40]}... ({len(text)} characters)"


def to_si(key: str, value, dimension: str, system: str = "si", small: bool = False) -> float:
    """Read one quantity and return it in SI.

    Parameters
    ----------
    key : str
        Dotted scenario key, named in every error.
    value : number or str
        A bare number (in the default unit of ``system``) or ``"<number> <unit>"``.
    dimension : str
        One of the dimensions of :data:`UNITS` (``"length"``, ``"force"``, ...).
    system : {"si", "imperial"}
        Unit system of bare numbers.
    small : bool
        A cross-section length (diameter, radius): bare imperial numbers are inches, not feet.

    Raises
    ------
    ScenarioError
        Not a number or quantity string, an unknown unit, or a unit of another dimension.
    """
    if isinstance(value, bool):
        raise ScenarioError(key, f"must be a number or a quantity such as \"12 {display_unit(dimension, system, small)}\", got {_short(value)}")
    if isinstance(value, numbers.Real):
        unit = display_unit(dimension, system, small)
        try:
            number = float(value)
        except OverflowError:        # an integer of hundreds of digits
            raise ScenarioError(key, f"must be a finite number, got an integer of {len(str(abs(value)))} digits") from None
    elif isinstance(value, str):
        m = _QUANTITY.match(value)
        if not m:
            raise ScenarioError(key, f"cannot read {_short(value)} as a quantity; write e.g. \"12 {display_unit(dimension, system, small)}\"")
        number, unit = float(m.group(1)), m.group(2)
        if unit not in UNITS:
            allowed = ", ".join(u for u, (d, _) in UNITS.items() if d == dimension)
            raise ScenarioError(key, f"unknown unit {unit!r}; for a {dimension.replace('_', ' ')} use one of {allowed}")
    else:
        raise ScenarioError(key, f"must be a number or a quantity string, got {type(value).__name__}")
    dim, factor = UNITS[unit]
    if dim != dimension:
        allowed = ", ".join(u for u, (d, _) in UNITS.items() if d == dimension)
        raise ScenarioError(key, f"{_short(value)} is a {dim.replace('_', ' ')}, but this key is a "
                                 f"{dimension.replace('_', ' ')}: use one of {allowed}")
    if not math.isfinite(number) or not math.isfinite(number * factor):
        raise ScenarioError(key, f"must be finite, got {_short(value)}")
    return number * factor


def from_si(value_si: float, dimension: str, system: str, small: bool = False) -> float:
    """Convert an SI value to the display unit of ``system`` (see :func:`display_unit`)."""
    return value_si / UNITS[display_unit(dimension, system, small)][1]
