"""The cable's tension profile from the equilibrium of its loads (exucable.post.tension.equilibrium_tension).

Coarse steady solves of a tight stiff bend (tests/test_stiff_bend.py's: EJ 1 N m², λ/R 0.2, point loads at
both bend ends) and the paper's Example 2 (fast variant). EA·ε of the same states spikes at the bend ends
(tight bend at 0.1 m elements: 52.7…260.4 N for a 217.0 N pull over a 100 N back tension)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from conftest import ROOT
from test_stiff_bend import _tight_bend

from exucable.post.tension import (CableLoads, equilibrium_tension, hermite_integral_weights, load_imbalance_N,
                                   tension_profile)

BACK_N = 100.0


@pytest.fixture(scope="module")
def tight():
    """The tight bend at 0.1 and 0.05 m elements: (run result, stations x [m], their s along the conduit [m])."""
    from exucable.run import cable_tension_along_conduit, run_scenario
    out = []
    for le in (0.1, 0.05):
        r = run_scenario(_tight_bend(le), None, quiet=True, plots=False)
        m = r.model
        x_nodes = np.concatenate([[0.0], np.cumsum(m.layout.element_length_m)])
        s_nodes, _ = cable_tension_along_conduit(m)
        out.append((r, r.tension_profile["x_m"], np.interp(r.tension_profile["x_m"], x_nodes, s_nodes)))
    return out


def test_the_loads_balance_and_the_ends_carry_their_forces(tight):
    """The steady state's loads sum to zero within the solve's tolerance (2e-5 N measured; the stop
    tolerance is 1e-4 of the rope's largest tension), so N meets the back tension at the trailing end
    and the rig's pulling force at the leading end (within 1e-5: N is along the cable's own end tangent,
    the pull along the rig's line, and the rig also holds the end laterally; 2.6e-6 measured)."""
    for r, x, _ in tight:
        m = r.model
        pull = r.summary["pull_force_N"]
        assert np.linalg.norm(load_imbalance_N(m.loads(), m.layout.element_length_m)) < 1e-6 * pull
        N = r.tension_profile["tension_N"]
        assert N[0] == pytest.approx(BACK_N, rel=1e-6)
        assert N[-1] == pytest.approx(pull, rel=1e-5)


def test_the_profile_stays_within_the_physical_tensions(tight):
    """No value below the back tension or above the pulling force by more than 1 % of the pull (the
    dip, 0.5 % here, is where the stiff cable lands on the wall at an angle: the wall's normal force
    has a component along it). EA·ε of the same coarse state leaves that band by 20 %."""
    for r, x, _ in tight:
        pull = r.summary["pull_force_N"]
        N = r.tension_profile["tension_N"]
        assert N.min() >= BACK_N - 0.01 * pull
        assert N.max() <= pull + 0.01 * pull
        assert r.summary["max_tension_N"] == pytest.approx(N.max(), rel=1e-12)
    r, _, _ = tight[0]
    q, _ = r.model.coordinates()
    _, strain_N = tension_profile(q, r.model.layout.element_length_m, r.model.axial_stiffness_N)
    assert strain_N.max() > 1.15 * r.summary["pull_force_N"]          # the artefact this replaces


def test_the_profile_converges_under_refinement(tight):
    """Halving the elements moves the profile by < 0.5 % of the pull anywhere (0.42 % measured, at a
    bend end where a check point's friction step moves; 0.24 % from 0.05 to 0.025 m) — EA·ε moves by 15 %."""
    (coarse, xc, _), (fine, xf, _) = tight
    pull = fine.summary["pull_force_N"]
    Nc, Nf = coarse.tension_profile["tension_N"], fine.tension_profile["tension_N"]
    assert np.max(np.abs(np.interp(xc, xf, Nf) - Nc)) < 0.005 * pull


def test_the_profile_matches_the_independent_beam_model(tight):
    """The steady beam in its conduit (exucable.quasistatic.beam, a discrete elastica with its own
    contact and friction, 2 cm segments) gives the same tension along the route: within 0.5 % of the
    pull away from the bend ends (±0.15 m, where each model puts its point loads' friction steps at its
    own resolution) and 0.3 % rms overall; the pulls differ by 0.13 %."""
    from exucable.quasistatic.beam import route_pieces, solve_planar_beam
    r, x, s = tight[1]
    sc = r.model.scenario
    centre = sc.build_conduit().centreline
    beam = solve_planar_beam(route_pieces(centre), 0.015, 0.5, 0.0, 1.0, BACK_N, 0.02)
    mid = 0.5 * (beam.station_m[1:] + beam.station_m[:-1])
    pull = r.summary["pull_force_N"]
    inside = (s > 0.1) & (s < centre.length_m - 0.1)
    diff = r.tension_profile["tension_N"][inside] - np.interp(s[inside], mid, beam.tension_N)
    ends = (2.0, 2.0 + math.pi * 0.5 / 2)
    away = np.all([np.abs(s[inside] - e) > 0.15 for e in ends], axis=0)
    assert np.max(np.abs(diff[away])) < 0.005 * pull
    assert np.sqrt(np.mean(diff**2)) < 0.003 * pull


def test_the_bend_body_follows_the_capstan():
    """Example 2 (a flexible cable, λ = 1.4 cm on a 0.5 m bend): in the bend body the tension is the
    rope's capstan T_b·e^(μθ) within 1 % of the pull anywhere and 0.3 % on average (measured 0.57 % and
    0.25 %; its pull differs from the rope's by 0.06 %). What is left is the coarse variant's own contact:
    its 0.14 m elements press the wall unevenly along their chords, and N follows the loads applied."""
    from exucable.run import cable_tension_along_conduit, run_scenario
    r = run_scenario(ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml", None, quiet=True, plots=False,
                     mode="steady")
    m = r.model
    x_nodes = np.concatenate([[0.0], np.cumsum(m.layout.element_length_m)])
    s_nodes, _ = cable_tension_along_conduit(m)
    x, N = r.tension_profile["x_m"], r.tension_profile["tension_N"]
    s = np.interp(x, x_nodes, s_nodes)
    bend = next(p for p in m.scenario.build_conduit().centreline.pieces if p.kind == "bend")
    body = (s > bend.s_start_m + 0.1) & (s < bend.s_end_m - 0.1)
    assert body.sum() >= 5
    theta = (s[body] - bend.s_start_m) / 0.5
    diff = N[body] - 150.0 * np.exp(0.2 * theta)
    assert np.max(np.abs(diff)) < 0.01 * r.summary["pull_force_N"]
    assert abs(np.mean(diff)) < 0.003 * r.summary["pull_force_N"]


def test_equilibrium_of_a_hanging_chain_closed_form():
    """A straight vertical cable of weight w per length hanging from its top (leading) end, free below:
    N(x) = w·x exactly, from either end's force; and the inertia term: the same cable accelerating
    upward at a, held at the top, carries N = ρA (g + a) x."""
    n_el, L, mu, g, a = 4, 2.0, 0.5, 9.81, 3.0
    Le = np.full(n_el, L / n_el)
    z = np.linspace(0.0, L, n_el + 1)
    q = np.zeros((n_el + 1, 6))
    q[:, 2], q[:, 5] = z, 1.0                                        # x runs upward along +z
    x = np.linspace(0.0, L, 17)
    weight = np.array([0.0, 0.0, -mu * g])
    top = mu * g * L * np.array([0.0, 0.0, 1.0])
    loads = CableLoads(point_x_m=np.zeros(0), point_force_N=np.zeros((0, 3)), node_force_N=np.zeros((n_el + 1, 3)),
                       line_load_N_per_m=weight, mass_per_length_kg_per_m=mu, acceleration=None,
                       trailing_force_N=np.zeros(3), leading_force_N=top)
    assert np.linalg.norm(load_imbalance_N(loads, Le)) < 1e-12
    np.testing.assert_allclose(equilibrium_tension(q, Le, loads, x), mu * g * x, atol=1e-12)
    acc = np.zeros((n_el + 1, 6))
    acc[:, 2] = a
    moving = dataclasses.replace(loads, acceleration=acc, leading_force_N=mu * (g + a) * L * np.array([0, 0, 1.0]),
                                 trailing_force_N=None)
    np.testing.assert_allclose(equilibrium_tension(q, Le, moving, x), mu * (g + a) * x, atol=1e-12)
    # the integrated shape functions: ∫₀^L r dx of a straight element is L·(r_i + r_j)/2
    w = hermite_integral_weights(np.ones(1), np.array([2.0]))[0]
    assert w[0] == pytest.approx(1.0) and w[2] == pytest.approx(1.0) and w[1] == pytest.approx(-w[3])
