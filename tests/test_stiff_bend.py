"""The stiff-bend model (exucable.quasistatic.stiff_bend) and exucable against it (issue #10 items 5–6).

The model's own limits are closed forms: the capstan (EJ = 0, paper Eq. 26), no change without
friction (N + EJκ²/2 is conserved along a frictionless elastica), its small-λ expansion and the
span's offset λ²/(2ρ). exucable (steady mode, a coarse mesh) is then checked against it on a tight
bend where the effect is 1 %: the pulling force, the bend-end point loads and their places, and
the point loads' convergence over two meshes.
"""

from __future__ import annotations

import math

import pytest

from exucable.quasistatic.stiff_bend import free_span_stiffness_N, stiff_bend


@pytest.mark.parametrize("ej", [0.0, 0.1, 1.0, 4.0])
def test_frictionless_bend_keeps_the_tension(ej):
    b = stiff_bend(100.0, 0.0, math.pi / 2, 0.5, ej)
    assert b.tension_out_N == pytest.approx(100.0, rel=1e-12)


def test_no_bending_stiffness_is_the_capstan():
    b = stiff_bend(150.0, 0.2, math.pi / 2, 0.5, 0.0)
    assert b.tension_out_N == pytest.approx(150.0 * math.exp(0.1 * math.pi), rel=1e-12)
    assert b.entry_point_load_N == 0.0 and b.exit_point_load_N == 0.0


@pytest.mark.parametrize("lam_over_rho", [0.01, 0.03])
def test_small_bending_length_expansion(lam_over_rho):
    """T_out/(T_in e^{μθ}) − 1 ≈ −(1 + μ²) EJ/(2ρ²) (1/T_in − 1/T_out); point loads √(EJ T)/ρ."""
    mu, theta, rho, t_in = 0.5, math.pi / 2, 3.0, 100.0
    ej = (lam_over_rho * rho) ** 2 * t_in
    b = stiff_bend(t_in, mu, theta, rho, ej)
    t_out = b.tension_out_N
    expected = -(1 + mu * mu) * ej / (2 * rho * rho) * (1 / t_in - 1 / t_out)
    assert b.vs_rope == pytest.approx(expected, rel=3 * lam_over_rho)      # next order: λ/ρ
    assert b.entry_point_load_N == pytest.approx(math.sqrt(ej * t_in) / rho, rel=lam_over_rho ** 2)
    assert b.entry_edge_m == pytest.approx(math.sqrt(ej / t_in), rel=lam_over_rho ** 2)
    assert b.entry_offset_m == pytest.approx(ej / t_in / (2 * rho), rel=1e-12)
    assert b.fits(clearance_m=b.entry_offset_m / 2 * 1.01) and not b.fits(clearance_m=b.entry_offset_m / 2 * 0.99)


def test_a_held_exit_turns_the_cable_further():
    free = stiff_bend(100.0, 0.5, math.pi / 2, 0.485, 1.0)
    held = stiff_bend(100.0, 0.5, math.pi / 2, 0.485, 1.0, exit_held_m=2.0)
    turn = math.atan(held.exit_offset_m / (2.0 + held.exit_edge_m))
    assert held.tension_out_N / free.tension_out_N == pytest.approx(math.exp(0.5 * turn), rel=2e-4)


def test_free_span_term_is_linear_in_EJ_and_needs_a_span():
    a = free_span_stiffness_N(7.9, 0.3, 4.99, 0.01, 9.81, 214.7)
    assert free_span_stiffness_N(25.0, 0.3, 4.99, 0.01, 9.81, 214.7) == pytest.approx(a * 25 / 7.9, rel=1e-12)
    k = 9.81 / 214.7
    span = math.sqrt(4 * 0.01 / (k * (1 - k * 4.99)))
    assert a == pytest.approx(0.3 * 7.9 / (4.99 * span), rel=1e-12)
    assert free_span_stiffness_N(7.9, 0.3, 4.99, 0.01, 9.81, 40.0) == 0.0    # T/ρ < w⊥: on the floor


def _tight_bend(element_length_m: float):
    """Tight horizontal bend, no gravity: R 0.5 m, 15 mm clearance, the 18 mm fibre cable with
    EJ 1 N m² (λ/R = 0.2 at the 100 N back tension), μ 0.5; a steady solve."""
    from exucable.scenario.specs import parse_scenario
    from conftest import ROOT
    r, length = 0.009, 4.0 + math.pi * 0.5 / 2
    data = {"name": "tight-ej1",
            "cable": {"radius": r, "density": 0.21 / (math.pi * r * r), "youngs_modulus": 5e8,
                      "bending_stiffness": 1.0, "elements": int(math.ceil(length / element_length_m))},
            "conduit": {"inner_radius": r + 0.015, "path": [{"straight": 2.0},
                                                            {"bend": 90.0, "radius": 0.5, "turn": "left"},
                                                            {"straight": 2.0}]},
            "contact": {"friction": 0.5, "check_points_per_element": int(round(element_length_m / 0.0025))},
            "pull": {"speed": 0.2, "back_tension": 100.0},
            "solver": {"end_time": 1.0, "mode": "steady"}}
    return parse_scenario(data, ROOT, default_name="tight-ej1")


@pytest.fixture(scope="module")
def tight_runs():
    from exucable.run import run_scenario
    return [run_scenario(_tight_bend(le), None, quiet=True, plots=False).summary for le in (0.05, 0.025)]


def test_exucable_matches_the_stiff_bend_model(tight_runs):
    """Pull: the model −1.10 % from the rope with clearance (steady solves at 0.05/0.025/0.0125 m
    elements: −1.028/−1.030/−1.028 %); 0.15 percentage point is the model's neglect (rigid,
    inextensible, exact arc) seen over the study's sweep (reference/README.md). Point loads:
    within 10 % of T sin ψ_e, places within 10 mm of the contact edges."""
    m = stiff_bend(100.0, 0.5, math.pi / 2, 0.485, 1.0, exit_held_m=2.0)
    for s in tight_runs:
        assert s["status"] in ("ok", "steady")
        rel = s["pull_force_N"] / s["rope_clearance_pull_force_N"] - 1
        assert rel == pytest.approx(m.vs_rope, abs=1.5e-3)
        assert rel < -0.9e-2                                     # well beyond the mesh's 3e-5
        b = s["bends"][0]
        assert b["entry_point_load_N"] == pytest.approx(m.entry_point_load_N, rel=0.1)
        assert b["exit_point_load_N"] == pytest.approx(m.exit_point_load_N, rel=0.1)
        scale = 0.5 / 0.485                                      # axis arc → centreline arc
        assert b["entry_s_conduit_m"] == pytest.approx(2.0 + m.entry_edge_m * scale, abs=0.01)
        assert b["exit_s_conduit_m"] == pytest.approx(2.0 + math.pi / 4 - m.exit_edge_m * scale, abs=0.01)


def test_point_loads_converge(tight_runs):
    """Halving the elements moves the pulling force by < 1e-4 and each point load by < 10 %."""
    coarse, fine = tight_runs
    assert fine["pull_force_N"] == pytest.approx(coarse["pull_force_N"], rel=1e-4)
    for key in ("entry_point_load_N", "exit_point_load_N"):
        assert fine["bends"][0][key] == pytest.approx(coarse["bends"][0][key], rel=0.1)
