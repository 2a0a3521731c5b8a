"""`exucable plan` (rope engine) reproduces the published worked pulls of reference/industry_values.toml
within their published rounding, propagated along the route (rule in that file's header)."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pytest

from exucable.plan.pull import load_plan_scenario, plan_pull
from exucable.validation.industry import published_bounds_N, published_values

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = tomllib.loads((ROOT / "reference" / "industry_values.toml").read_text())
LBF = 4.4482216152605
FT = 0.3048
LB_PER_FT = LBF / FT


@pytest.mark.parametrize("example", REFERENCE["example"],
                         ids=[f"{x['scenario']}-{x['direction']}" for x in REFERENCE["example"]])
def test_published_section_tensions_and_swbp(example):
    scenario, spec = load_plan_scenario(ROOT / "scenarios" / "industry" / example["scenario"])
    plan = plan_pull(scenario, spec, engine="rope")
    rows = plan["directions"][example["direction"]]["sections"]
    mu = scenario.contact.friction
    mu_bend = mu * plan["weight_correction_factor"] if spec.weight_correction_in_bends else mu
    w = plan["inputs"]["weight_per_length_one_cable_N_per_m"] * plan["count"]
    pub = published_values(example)
    bounds = published_bounds_N(example, rows, mu_bend, w)
    for idx, value, bound in zip(example["sections"], pub["tension_N"], bounds):
        ours = rows[idx - 1]["tension_out_N"]
        assert abs(ours - value) <= bound, f"section {idx}: ours {ours:.2f} N, published {value:.2f} N, bound {bound:.2f}"
    for idx, value in zip(example.get("bend_sections", []), pub["pressure_N_per_m"]):
        e_t = bounds[example["sections"].index(idx)]
        row = rows[idx - 1]
        if example.get("sidewall_pressure_of") == "bundle":
            ours = row["tension_out_N"] / row["radius_m"]
            # and exucable's own SWBP is the most loaded cable's: T/R times the arrangement's factor
            assert row["sidewall_pressure_N_per_m"] == pytest.approx(ours * plan["sidewall_pressure_factor"], rel=0.02)
        else:
            ours = row["sidewall_pressure_N_per_m"]
        bound = e_t / pub["radius_m"] + pub["pressure_rounding_N_per_m"]
        assert abs(ours - value) <= bound, f"bend {idx}: ours {ours:.3f} N/m, published {value:.3f}, bound {bound:.3f}"


def test_errata_follow_from_their_printed_operands():
    """A corrected value is the printed operands' arithmetic (reference header, `erratum`), re-evaluated here."""
    tes = next(x for x in REFERENCE["example"] if "erratum" in x)
    printed, corrected = tes["tension_out_N"], tes["tension_out_corrected_N"]
    # the standard truncates to whole newtons (TB of Sect. 4.5.1: 3002.5 printed 3002)
    assert math.floor(printed[2] * 1.48) == corrected[3] != printed[3]          # TB = TC x 1.48
    assert corrected[4] - corrected[3] == printed[4] - printed[3] == 3002        # TA = TB + the 60 m add-on
    assert math.floor(9.8 * 60 * (3.15 * 1.01) * 0.5 * 1.07 * 3) == 3002         # that add-on, Eq. 05-1 as printed


def test_tes_weight_correction_is_the_published_occupancy_factor():
    """TES-P-104.05 p. 10: OF = 1/sqrt(1 - (4.13/(15.4 - 4.13))^2) = 1.07 for the three cables."""
    scenario, spec = load_plan_scenario(ROOT / "scenarios" / "industry" / "sec_tes_p_104_05_three_cables.toml")
    plan = plan_pull(scenario, spec, engine="rope")
    assert round(plan["weight_correction_factor"], 2) == 1.07 and plan["arrangement"] == "triangular"
    assert plan["weight_correction_in_bends"] is False


def test_commscope_recommends_the_direction_the_manual_finds_easier():
    # Manual p. 44: pulling from A to H = 64 lb, from H to A = 54 lb.
    scenario, spec = load_plan_scenario(ROOT / "scenarios" / "industry" / "commscope_conquest_run_a_h.toml")
    plan = plan_pull(scenario, spec, engine="rope")
    assert plan["recommended_direction"] == "reverse"
    assert plan["directions"]["reverse"]["pull_force_N"] < plan["directions"]["forward"]["pull_force_N"]


def test_tes_recommends_the_direction_the_standard_finds_easier():
    # Sect. 4.5.2: "Pulling from at point (F) to at point (A) results in considerably less tension".
    scenario, spec = load_plan_scenario(ROOT / "scenarios" / "industry" / "sec_tes_p_104_05_three_cables.toml")
    plan = plan_pull(scenario, spec, engine="rope")
    assert plan["recommended_direction"] == "reverse" and plan["passed"]
