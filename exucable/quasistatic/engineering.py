"""The installation engineer's formulas: several cables per duct and the limits a pull must respect.

Pure functions of numbers (no Exudyn, no scenario objects). Every formula is the one printed in the
source named in its docstring; ``reference/engineering.toml`` holds the same sources with the published
worked values that ``tests/test_engineering.py`` checks.

Notation (all calculators use it): D duct inner diameter [m], d outer diameter of one cable [m],
x = d / (D − d).

Arrangements of n identical cables in a duct:

* ``single``      1 cable;
* ``triangular``  3 cables, one on top of two (also used for 2 cables, after ArcFM and Cableizer);
* ``cradled``     3 cables side by side in the bottom of the duct (4 cables likewise);
* ``diamond``     4 cables, one on top, two in the middle, one at the bottom.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from exucable.errors import ScenarioError

__all__ = [
    "ARRANGEMENTS", "CONDUCTOR_STRESS_IEC_Pa", "CONDUCTOR_STRESS_US_LB_PER_CMIL",
    "auto_arrangement", "check_arrangement", "check_fit", "weight_correction_factor", "sidewall_pressure_factor",
    "jam_ratio", "jam_risk", "clearance_m", "max_tension_from_conductors_N", "JamAssessment", "conduit_fill_percent",
    "NEC_MAX_FILL_PERCENT", "JAM_RANGE_D_OVER_d", "in_jam_range",
]

ARRANGEMENTS = ("single", "triangular", "cradled", "diamond")
_ALLOWED = {1: ("single",), 2: ("triangular",), 3: ("triangular", "cradled"), 4: ("diamond", "cradled")}

# Allowed stress on the conductors of a cable pulled by an eye on them [Pa]: copper 50 N/mm²,
# aluminium 30 N/mm² (Nexans, "Cable pulling", admissible pulling force with a pulling head, after VDE;
# the same values as Cableizer's "UK / VDE" column of f_ppc).
CONDUCTOR_STRESS_IEC_Pa = {"copper": 50e6, "aluminium": 30e6}
# US rule (Southwire, "Wire and Cable Pulling Tensions", Table 1): lb per circular mil of conductor.
CONDUCTOR_STRESS_US_LB_PER_CMIL = {"copper": 0.008, "aluminium": 0.006}
_LBF_N = 4.4482216152605
_CMIL_M2 = math.pi / 4.0 * (0.0254e-3) ** 2


def _ratio(duct_inner_diameter_m: float, cable_diameter_m: float) -> float:
    """x = d / (D − d) [-]."""
    return cable_diameter_m / (duct_inner_diameter_m - cable_diameter_m)


def check_fit(count: int, duct_inner_diameter_m: float, cable_diameter_m: float) -> None:
    """Refuse cables that do not fit the duct, naming the scenario keys.

    The tightest arrangement of each count must fit inside the circle of diameter D: one cable needs
    D > d; two side by side D > 2d; three in trefoil D > (1 + 2/√3) d = 2.155 d; four in a square
    D > (1 + √2) d = 2.414 d (circumscribed circles, Cableizer "Diameter factor in duct" DC_p).

    Raises
    ------
    ScenarioError
        ``cable.count`` if it is not 1…4; ``conduit.inner_radius`` if the cables do not fit.
    """
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= 4:
        raise ScenarioError("cable.count", f"must be an integer 1…4 (cables of the described kind per duct), got {count!r}")
    factor = {1: 1.0, 2: 2.0, 3: 1.0 + 2.0 / math.sqrt(3.0), 4: 1.0 + math.sqrt(2.0)}[count]
    if not duct_inner_diameter_m > factor * cable_diameter_m:
        raise ScenarioError(
            "conduit.inner_radius",
            f"{count} cable(s) of diameter {cable_diameter_m * 1e3:.4g} mm (cable.radius) do not fit a duct of inner "
            f"diameter {duct_inner_diameter_m * 1e3:.4g} mm: need more than {factor * cable_diameter_m * 1e3:.4g} mm; "
            "use a larger duct or fewer cables (cable.count)")


def auto_arrangement(count: int, duct_inner_diameter_m: float, cable_diameter_m: float) -> str:
    """The arrangement the calculators assume from the conduit ratio D/d.

    Cableizer, "Conduit ratio" CR_pull: three unbound cables are triangular for D/d < 2.5 and cradled
    for D/d ≥ 2.5; four are diamond for D/d < 3.0 and cradled for D/d ≥ 3.0. Two cables: triangular
    (ArcFM Solution Configuration Guide 10.1, "Pulling Configuration").
    """
    ratio = duct_inner_diameter_m / cable_diameter_m
    if count == 1:
        return "single"
    if count == 2:
        return "triangular"
    if count == 3:
        return "triangular" if ratio < 2.5 else "cradled"
    return "diamond" if ratio < 3.0 else "cradled"


def check_arrangement(count: int, arrangement: str) -> None:
    """Refuse an arrangement that is not one of ``count`` cables (key ``cable.arrangement``)."""
    if arrangement not in ARRANGEMENTS:
        raise ScenarioError("cable.arrangement", f"must be one of \"auto\", {', '.join(repr(a) for a in ARRANGEMENTS)}, "
                                                 f"got {arrangement!r}")
    if arrangement not in _ALLOWED[count]:
        raise ScenarioError("cable.arrangement", f"{arrangement!r} is not an arrangement of {count} cable(s); "
                                                 f"allowed: {', '.join(_ALLOWED[count])} or \"auto\"")


def weight_correction_factor(count: int, arrangement: str, duct_inner_diameter_m: float,
                             cable_diameter_m: float) -> float:
    """Weight correction factor w_c [-]: how much more normal force n cables press on the wall than n·w.

    Cableizer, "Weight correction factor" f_wc (the IEEE 1185 / Southwire equations), x = d/(D − d):

    * 1 cable: 1;
    * 2 cables, 3 triangular: 1 / √(1 − x²);
    * 3 cradled, 4 diamond: 1 + (4/3)·x²;
    * 4 cradled: 1 + 2·x².

    The tension equations then read T_out = T_in + w_c μ W L on a straight (W = n·w the weight of all
    cables per length) and T_out = T_in e^{w_c μ θ} in a bend (Polywater, "Weight Correction Factor in
    Pulling Tension Calculations").
    """
    check_fit(count, duct_inner_diameter_m, cable_diameter_m)
    check_arrangement(count, arrangement)
    x = _ratio(duct_inner_diameter_m, cable_diameter_m)
    if arrangement == "single":
        return 1.0
    if arrangement == "triangular":
        if x >= 1.0:  # unreachable after check_fit (D > 2.155 d gives x < 0.87), kept as the formula's domain
            raise ScenarioError("conduit.inner_radius", "a triangular arrangement needs D > 2d")
        return 1.0 / math.sqrt(1.0 - x * x)
    if arrangement == "diamond" or count == 3:
        return 1.0 + 4.0 / 3.0 * x * x
    return 1.0 + 2.0 * x * x


def sidewall_pressure_factor(count: int, arrangement: str, weight_correction: float) -> float:
    """Factor on T/R giving the sidewall bearing pressure on the most loaded cable [-].

    Cableizer, "Sidewall bearing pressure factor" f_rad: 1 cable 1; 2 cables, 3 triangular, 4 diamond
    w_c/2; 3 cradled (3w_c − 2)/3; 4 cradled (4w_c − 3)/4. (Cableizer's page F_cable prints
    (w_c − 1) for the diamond instead; we follow f_rad and record the disagreement in
    ``reference/engineering.toml``.)
    """
    check_arrangement(count, arrangement)
    if arrangement == "single":
        return 1.0
    if arrangement == "cradled":
        return (3.0 * weight_correction - 2.0) / 3.0 if count == 3 else (4.0 * weight_correction - 3.0) / 4.0
    return weight_correction / 2.0


def jam_ratio(duct_inner_diameter_m: float, cable_diameter_m: float) -> float:
    """Jam ratio 1.05·D/d [-] (Cableizer JR_p; the 5 % allows for the oval cross-section of bends)."""
    return 1.05 * duct_inner_diameter_m / cable_diameter_m


@dataclass(frozen=True)
class JamAssessment:
    """Jam ratio with its risk band.

    Attributes
    ----------
    jam_ratio : float
        1.05·D/d [-].
    risk : str
        ``"very small"``, ``"small"``, ``"moderate"``, ``"significant"`` (three cables), or
        ``"not applicable"`` (jamming is a three-cable phenomenon).
    """

    jam_ratio: float
    risk: str


def jam_risk(count: int, duct_inner_diameter_m: float, cable_diameter_m: float) -> JamAssessment:
    """Jam ratio and its risk band (Cableizer JR_p, the bands of Southwire's manual).

    very small: JR < 2.4 or JR ≥ 3.2; small: 2.4 ≤ JR < 2.5 or 3.0 ≤ JR < 3.2; moderate: 2.5 ≤ JR < 2.6
    or 2.9 ≤ JR < 3.0; significant: 2.6 ≤ JR < 2.9. Only three cables jam (Cableizer CJ_pull:
    "While jamming can occur when pulling four or more cables into a conduit, the probability is very low").
    """
    jr = jam_ratio(duct_inner_diameter_m, cable_diameter_m)
    if count != 3:
        return JamAssessment(jr, "not applicable")
    if jr < 2.4 or jr >= 3.2:
        risk = "very small"
    elif jr < 2.5 or jr >= 3.0:
        risk = "small"
    elif jr < 2.6 or jr >= 2.9:
        risk = "moderate"
    else:
        risk = "significant"
    return JamAssessment(jr, risk)


#: Duct inner diameter over cable diameter D/d between which three cables may jam [-]: NFPA 70
#: (National Electrical Code), Chapter 9, Table 1, Informational Note No. 2 ("When pulling three
#: conductors or cables into a raceway, if the ratio of the raceway (inside diameter) to the conductor
#: or cable (outside diameter) is between 2.8 and 3.2, jamming can occur"); IEEE 1185 and Polywater
#: print the same band as "probable" (Cableizer CJ_pull's table of references).
JAM_RANGE_D_OVER_d = (2.8, 3.2)


def in_jam_range(count: int, duct_inner_diameter_m: float, cable_diameter_m: float) -> bool:
    """Whether ``count`` cables have D/d in :data:`JAM_RANGE_D_OVER_d` (only three cables jam)."""
    lo, hi = JAM_RANGE_D_OVER_d
    return count == 3 and lo <= duct_inner_diameter_m / cable_diameter_m <= hi


def clearance_m(count: int, arrangement: str, duct_inner_diameter_m: float, cable_diameter_m: float) -> float:
    """Clearance between the top of the uppermost cable and the duct's top [m].

    Cableizer, "Conduit clearance" CC_pull:

    * 1 cable: D − d;  2 cables: D − 2d;
    * 3 triangular, 4 cradled: D/2 − 1.366 d + (D − d)/2 · √(1 − x²);
    * 3 cradled: (D − d)/2 + (D − d)/2 · √(1 − (d / (2(D − d)))²);
    * 4 diamond: D − d − 2d²/(D − d).
    """
    check_fit(count, duct_inner_diameter_m, cable_diameter_m)
    check_arrangement(count, arrangement)
    D, d = duct_inner_diameter_m, cable_diameter_m
    x = _ratio(D, d)
    if count == 1:
        return D - d
    if count == 2:
        return D - 2.0 * d
    if (count == 3 and arrangement == "triangular") or (count == 4 and arrangement == "cradled"):
        return D / 2.0 - 1.366 * d + (D - d) / 2.0 * math.sqrt(1.0 - x * x)
    if count == 3:
        return (D - d) / 2.0 + (D - d) / 2.0 * math.sqrt(1.0 - (d / (2.0 * (D - d))) ** 2)
    return D - d - 2.0 * d * d / (D - d)


#: Largest fill of a conduit by cables [%] by the number of cables: NFPA 70 (National Electrical Code),
#: Chapter 9, Table 1 "Percent of Cross Section of Conduit and Tubing for Conductors and Cables": 53 % for
#: one, 31 % for two, 40 % for more than two. Building wiring; utility ducts follow their own standards,
#: so exucable checks fill only against ``limits.max_fill`` and quotes these for orientation.
NEC_MAX_FILL_PERCENT = {1: 53.0, 2: 31.0, 3: 40.0}


def conduit_fill_percent(count: int, duct_inner_diameter_m: float, cable_diameter_m: float) -> float:
    """Conduit fill: the cables' cross-sections over the duct's, n·d²/D², in percent."""
    return 100.0 * count * (cable_diameter_m / duct_inner_diameter_m) ** 2


def max_tension_from_conductors_N(material: str, area_m2: float, conductors: int, rule: str = "iec") -> float:
    """Largest tension the conductors take through a pulling eye [N].

    Parameters
    ----------
    material : {"copper", "aluminium"}
    area_m2 : float
        Cross-section of ONE conductor [m²].
    conductors : int
        Conductors that share the pull (all conductors of all cables on the eye).
    rule : {"iec", "us"}
        ``"iec"``: T = N · A · σ with σ = 50 N/mm² copper, 30 N/mm² aluminium (Nexans, after VDE).
        ``"us"``: T = N · S · A_cmil [lb] with S = 0.008 lb/cmil copper, 0.006 lb/cmil aluminium, and
        0.8 × that for more than three conductors (Southwire, "Wire and Cable Pulling Tensions").
    """
    if material not in CONDUCTOR_STRESS_IEC_Pa:
        raise ScenarioError("limits.conductor_material", f"must be \"copper\" or \"aluminium\", got {material!r}")
    if rule == "iec":
        return conductors * area_m2 * CONDUCTOR_STRESS_IEC_Pa[material]
    if rule == "us":
        lb = conductors * CONDUCTOR_STRESS_US_LB_PER_CMIL[material] * area_m2 / _CMIL_M2
        if conductors > 3:
            lb *= 0.8
        return lb * _LBF_N
    raise ScenarioError("limits.conductor_rule", f"must be \"iec\" or \"us\", got {rule!r}")
