"""`exucable plan` (rope engine) reproduces the published worked pulls of reference/industry_values.toml
within their published rounding, propagated along the route (rule in that file's header)."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pytest

from exucable.plan import load_plan_scenario, plan_pull

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = tomllib.loads((ROOT / "reference" / "industry_values.toml").read_text())
LBF = 4.4482216152605
FT = 0.3048
LB_PER_FT = LBF / FT


def _published(example) -> dict:
    """The example's published numbers in N, N/m and m, whichever units it was printed in."""
    if "tension_out_N" in example:
        tension = example.get("tension_out_corrected_N", example["tension_out_N"])
        return {"tension_N": list(map(float, tension)), "rounding_N": example["tension_rounding_N"],
                "pressure_N_per_m": example.get("sidewall_pressure_N_per_m", []),
                "radius_m": example.get("bend_radius_m"), "pressure_rounding_N_per_m": example.get("pressure_rounding_N_per_m")}
    tension = example.get("tension_out_corrected_lbf", example["tension_out_lbf"])
    return {"tension_N": [t * LBF for t in tension], "rounding_N": example["tension_rounding_lbf"] * LBF,
            "pressure_N_per_m": [p * LB_PER_FT for p in example.get("sidewall_pressure_lb_per_ft", [])],
            "radius_m": example["bend_radius_ft"] * FT if "bend_radius_ft" in example else None,
            "pressure_rounding_N_per_m": example.get("pressure_rounding_lb_per_ft", 0.0) * LB_PER_FT}


def _bounds(example, rows, mu_bend, w_N_per_m):
    """Bound |exact - published| [N] for every published tension: interval propagation of the hand calculation.

    Per step from the previous published value to the next: the carried error times the bend factors
    between (chained calculations), the bend factors' rounding, the weight correction factor's rounding
    on the straights' add-ons, the weight in the bends the hand calculation drops (``bend_weight_ignored``)
    and the printed value's own rounding (reference/industry_values.toml header).
    """
    pub = _published(example)
    delta = example["bend_factor_rounding"]
    wc_rel = example.get("weight_correction_rounding", 0.0) / example.get("weight_correction_published", 1.0)
    bounds, e, prev_idx, prev_pub = [], 0.0, 0, 0.0
    for idx, value in zip(example["sections"], pub["tension_N"]):
        between = rows[prev_idx:idx]
        bends = [b for b in between if b["kind"] == "bend"]
        factor = math.prod(math.exp(mu_bend * math.radians(b["angle_deg"])) for b in bends)
        carried = factor * e if example["chained"] else 0.0
        # within the step, in pull order: a straight's add-on error, a bend multiplies what came before
        # and adds the weight the hand calculation drops in it
        step = 0.0
        for r in between:
            if r["kind"] == "straight":
                step += wc_rel * (r["tension_out_N"] - r["tension_in_N"])
                continue
            grow = math.exp(mu_bend * math.radians(r["angle_deg"]))
            step *= grow
            if example.get("bend_weight_ignored", False):
                R = r["radius_m"]
                step += ((grow - 1.0) * w_N_per_m**2 * R**2 / (2.0 * r["tension_in_N"]) if r["plane"] == "horizontal"
                         else (grow - 1.0) * w_N_per_m * R)
        e = carried + len(bends) * delta * max(prev_pub, 0.0) * factor + pub["rounding_N"] + step
        bounds.append(e)
        prev_idx, prev_pub = idx, value
    return bounds


@pytest.mark.parametrize("example", REFERENCE["example"],
                         ids=[f"{x['scenario']}-{x['direction']}" for x in REFERENCE["example"]])
def test_published_section_tensions_and_swbp(example):
    scenario, spec = load_plan_scenario(ROOT / "scenarios" / "industry" / example["scenario"])
    plan = plan_pull(scenario, spec)
    rows = plan["directions"][example["direction"]]["sections"]
    mu = scenario.contact.friction
    mu_bend = mu * plan["weight_correction_factor"] if spec.weight_correction_in_bends else mu
    w = plan["inputs"]["weight_per_length_one_cable_N_per_m"] * plan["count"]
    pub = _published(example)
    bounds = _bounds(example, rows, mu_bend, w)
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
    plan = plan_pull(scenario, spec)
    assert round(plan["weight_correction_factor"], 2) == 1.07 and plan["arrangement"] == "triangular"
    assert plan["weight_correction_in_bends"] is False


def test_commscope_recommends_the_direction_the_manual_finds_easier():
    # Manual p. 44: pulling from A to H = 64 lb, from H to A = 54 lb.
    scenario, spec = load_plan_scenario(ROOT / "scenarios" / "industry" / "commscope_conquest_run_a_h.toml")
    plan = plan_pull(scenario, spec)
    assert plan["recommended_direction"] == "reverse"
    assert plan["directions"]["reverse"]["pull_force_N"] < plan["directions"]["forward"]["pull_force_N"]


def test_tes_recommends_the_direction_the_standard_finds_easier():
    # Sect. 4.5.2: "Pulling from at point (F) to at point (A) results in considerably less tension".
    scenario, spec = load_plan_scenario(ROOT / "scenarios" / "industry" / "sec_tes_p_104_05_three_cables.toml")
    plan = plan_pull(scenario, spec)
    assert plan["recommended_direction"] == "reverse" and plan["passed"]
