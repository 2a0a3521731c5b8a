"""Engineering formulas against the published (and, where none was found, the printed-formula) values of
reference/engineering.toml; arrangement rules; refusals that name the key."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pytest

from exucable.quasistatic import engineering as eng
from exucable.errors import ScenarioError
from exucable.scenario.units import to_si

REFERENCE = tomllib.loads((Path(__file__).resolve().parents[1] / "reference" / "engineering.toml").read_text())
IN = 0.0254
LBF = 4.4482216152605
CMIL = math.pi / 4 * (0.0254e-3) ** 2


def _diameters_m(i) -> tuple[float, float]:
    """(duct inner diameter, cable diameter) [m] from inputs given in inches or centimetres."""
    unit, suffix = (IN, "_in") if "duct_inner_diameter_in" in i else (0.01, "_cm")
    return i["duct_inner_diameter" + suffix] * unit, i["cable_diameter" + suffix] * unit


def _evaluate(entry):
    f, i = entry["function"], entry["inputs"]
    if f == "max_tension_from_conductors_N":
        return eng.max_tension_from_conductors_N(i["material"], i["area_cmil"] * CMIL, i["conductors"], i["rule"]) / LBF
    if f == "jam_ratio / 1.05":
        return eng.jam_ratio(i["duct_inner_diameter_in"] * IN, i["cable_diameter_in"] * IN) / 1.05
    if f == "T/R":
        return (i["tension_lbf"] * LBF) / (i["radius_ft"] * 0.3048) / (LBF / 0.3048)
    if f == "weight_correction_factor":
        return eng.weight_correction_factor(i["count"], i["arrangement"], *_diameters_m(i))
    if f == "clearance_m":
        return eng.clearance_m(i["count"], i["arrangement"], i["duct_inner_diameter_in"] * IN,
                               i["cable_diameter_in"] * IN) / IN
    raise AssertionError(f"no evaluator for {f}")


@pytest.mark.parametrize("entry", REFERENCE["worked"], ids=[w["name"] for w in REFERENCE["worked"]])
def test_worked_values(entry):
    expected = next(entry[k] for k in ("value", "value_lbf", "value_in", "value_lb_per_ft") if k in entry)
    got = _evaluate(entry)
    tol = entry.get("abs_tol", 0.0) + entry.get("rel_tol", 0.0) * abs(expected)
    assert abs(got - expected) <= tol, (got, expected, entry["source"])


def test_weight_correction_limits_and_order():
    d = 0.02
    # A wide duct: the cables lie as if alone (x -> 0).
    for count, arr in [(2, "triangular"), (3, "triangular"), (3, "cradled"), (4, "diamond"), (4, "cradled")]:
        assert eng.weight_correction_factor(count, arr, 1000 * d, d) == pytest.approx(1.0, abs=1e-5)
    # Cradled presses more than triangular at D/d = 3 (x = 1/2: 4/3 vs 2/sqrt(3)).
    assert eng.weight_correction_factor(3, "cradled", 3 * d, d) > eng.weight_correction_factor(3, "triangular", 3 * d, d)


def test_auto_arrangement_thresholds():
    d = 0.01
    assert eng.auto_arrangement(3, 2.49 * d, d) == "triangular"
    assert eng.auto_arrangement(3, 2.5 * d, d) == "cradled"
    assert eng.auto_arrangement(4, 2.99 * d, d) == "diamond"
    assert eng.auto_arrangement(4, 3.0 * d, d) == "cradled"
    assert eng.auto_arrangement(2, 5 * d, d) == "triangular"
    assert eng.auto_arrangement(1, 5 * d, d) == "single"


@pytest.mark.parametrize("ratio, risk", [(2.3, "very small"), (2.45, "small"), (2.55, "moderate"), (2.7, "significant"),
                                         (2.95, "moderate"), (3.1, "small"), (3.3, "very small")])
def test_jam_bands(ratio, risk):
    d = 0.01
    assert eng.jam_risk(3, ratio / 1.05 * d, d).risk == risk
    assert eng.jam_risk(4, ratio / 1.05 * d, d).risk == "not applicable"


def test_sidewall_pressure_factors():
    assert eng.sidewall_pressure_factor(1, "single", 1.0) == 1.0
    assert eng.sidewall_pressure_factor(3, "triangular", 1.2) == pytest.approx(0.6)
    assert eng.sidewall_pressure_factor(3, "cradled", 1.2) == pytest.approx((3.6 - 2) / 3)
    assert eng.sidewall_pressure_factor(4, "cradled", 1.2) == pytest.approx((4.8 - 3) / 4)


def test_conductor_rules():
    # 500 kcmil copper, 3 conductors, US rule: 0.008 * 3 * 500000 lb; > 3 conductors: 0.8 x.
    assert eng.max_tension_from_conductors_N("copper", 500e3 * CMIL, 3, "us") / LBF == pytest.approx(12000.0)
    assert eng.max_tension_from_conductors_N("copper", 500e3 * CMIL, 4, "us") / LBF == pytest.approx(0.8 * 16000.0)
    # IEC: 3 x 240 mm2 copper at 50 N/mm2 = 36 kN; aluminium 30 N/mm2.
    assert eng.max_tension_from_conductors_N("copper", 240e-6, 3, "iec") == pytest.approx(36e3)
    assert eng.max_tension_from_conductors_N("aluminium", 240e-6, 3, "iec") == pytest.approx(21.6e3)


@pytest.mark.parametrize("call, key", [
    (lambda: eng.weight_correction_factor(3, "triangular", 0.02, 0.01), "conduit.inner_radius"),  # 3 x 10 mm in 20 mm
    (lambda: eng.weight_correction_factor(-1, "single", 0.05, 0.01), "cable.count"),
    (lambda: eng.weight_correction_factor(5, "single", 0.05, 0.01), "cable.count"),
    (lambda: eng.weight_correction_factor(3, "hexagonal", 0.05, 0.01), "cable.arrangement"),
    (lambda: eng.weight_correction_factor(3, "diamond", 0.05, 0.01), "cable.arrangement"),
    (lambda: eng.max_tension_from_conductors_N("gold", 1e-4, 1), "limits.conductor_material"),
])
def test_refusals_name_the_key(call, key):
    with pytest.raises(ScenarioError) as exc:
        call()
    assert exc.value.key == key


def test_units_read_and_refuse():
    assert to_si("k", "500 lb/ft", "force_per_length") == pytest.approx(500 * LBF / 0.3048)
    assert to_si("k", 100.0, "length", "imperial") == pytest.approx(30.48)
    assert to_si("k", 1.0, "length", "imperial", small=True) == pytest.approx(0.0254)
    assert to_si("k", "240 mm2", "area") == pytest.approx(240e-6)
    with pytest.raises(ScenarioError, match="is a force, but this key is a force per length") as exc:
        to_si("limits.max_sidewall_pressure", "500 lb", "force_per_length")
    assert exc.value.key == "limits.max_sidewall_pressure"
    with pytest.raises(ScenarioError, match="unknown unit"):
        to_si("limits.max_tension", "5 tonnes", "force")
