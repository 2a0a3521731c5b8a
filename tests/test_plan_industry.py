"""`exucable plan` (rope engine) reproduces the published worked pulls of reference/industry_values.toml
within their published rounding, propagated along the route (rule in that file's header)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from exucable.plan import load_plan_scenario, plan_pull
from exucable.validate_industry import published_bounds_lbf

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = tomllib.loads((ROOT / "reference" / "industry_values.toml").read_text())
LBF = 4.4482216152605
LB_PER_FT = LBF / 0.3048


@pytest.mark.parametrize("example", REFERENCE["example"],
                         ids=[f"{x['scenario']}-{x['direction']}" for x in REFERENCE["example"]])
def test_published_section_tensions_and_swbp(example):
    scenario, spec = load_plan_scenario(ROOT / "scenarios" / "industry" / example["scenario"])
    plan = plan_pull(scenario, spec)
    rows = plan["directions"][example["direction"]]["sections"]
    mu = scenario.contact.friction * plan["weight_correction_factor"]
    bounds = published_bounds_lbf(example, rows, mu)
    for idx, pub, bound in zip(example["sections"], example["tension_out_lbf"], bounds):
        ours = rows[idx - 1]["tension_out_N"] / LBF
        assert abs(ours - pub) <= bound, f"section {idx}: ours {ours:.3f} lbf, published {pub}, bound {bound:.3f}"
    for idx, pub in zip(example.get("bend_sections", []), example.get("sidewall_pressure_lb_per_ft", [])):
        e_t = bounds[example["sections"].index(idx)]
        ours = rows[idx - 1]["sidewall_pressure_N_per_m"] / LB_PER_FT
        bound = e_t / example["bend_radius_ft"] + example["pressure_rounding_lb_per_ft"]
        assert abs(ours - pub) <= bound, f"bend {idx}: ours {ours:.3f} lb/ft, published {pub}, bound {bound:.3f}"


def test_commscope_recommends_the_direction_the_manual_finds_easier():
    # Manual p. 44: pulling from A to H = 64 lb, from H to A = 54 lb.
    scenario, spec = load_plan_scenario(ROOT / "scenarios" / "industry" / "commscope_conquest_run_a_h.toml")
    plan = plan_pull(scenario, spec)
    assert plan["recommended_direction"] == "reverse"
    assert plan["directions"]["reverse"]["pull_force_N"] < plan["directions"]["forward"]["pull_force_N"]
