"""Hard steady cases end clearly and soon: the cause of a failed steady solve (load scale reached,
residual, strain at the head) and advice that can help (exucable.solve.steady_advice), and the time
limit `solver.steady_time_limit`. Coarse models only."""

from __future__ import annotations

import math
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from exucable.run import run_scenario
from exucable.scenario.specs import load_scenario
from exucable.solve.steady_advice import LARGE_STRAIN, TIME_LIMIT_KEY, failure_advice, head_strain

ROOT = Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "data" / "sweep" / "tiny_bend.toml"


def _model(E_Pa: float, radius_m: float, rope_max_N: float | None):
    """What failure_advice reads of a model: the cable's EA and the rope reference's tensions."""
    area = math.pi * radius_m ** 2
    cable = SimpleNamespace(axial_stiffness_N=E_Pa * area)
    rope = None if rope_max_N is None else SimpleNamespace(tension_N=np.array([100.0, rope_max_N]))
    return SimpleNamespace(scenario=SimpleNamespace(cable=cable), rope=rope)


def test_head_strain_is_the_ropes_largest_tension_over_EA():
    # E 3e8 Pa over a 15 mm radius: EA = 3e8·π·0.015² = 212 058 N; 17 kN at the head is 8.0 %
    T, EA, strain = head_strain(_model(3.0e8, 0.015, 17_000.0))
    assert EA == pytest.approx(212_057.5, rel=1e-6)
    assert T == 17_000.0 and strain == pytest.approx(0.0802, abs=1e-4)
    assert math.isnan(head_strain(_model(3.0e8, 0.015, None))[2])


def test_a_large_strain_at_the_head_is_reported_with_the_modulus_to_check():
    text = failure_advice(_model(3.0e8, 0.015, 17_000.0), load_scale=0.0, residual_N=120.0, tolerance_N=0.017,
                          timed_out=False, still_converging=False, time_limit_s=60.0)
    assert "load scale reached 0 of 1" in text and "residual 120 N (stop at 0.017 N)" in text
    assert "strain at the head 8.02 %" in text and "check `cable.youngs_modulus`" in text
    small = failure_advice(_model(3.0e8, 0.015, 2_000.0), load_scale=0.0, residual_N=120.0, tolerance_N=0.017,
                           timed_out=False, still_converging=False, time_limit_s=60.0)
    assert "youngs_modulus" not in small


def test_a_residual_reached_at_another_load_scale_names_it():
    """A solve that failed at the full loads before any ramp reached λ = 0; its residual was at λ = 1,
    and the message says so instead of leaving it to read as the start's."""
    model = _model(3.0e8, 0.015, 2_000.0)
    text = failure_advice(model, load_scale=0.0, residual_N=34.2, tolerance_N=0.00175, timed_out=False,
                          still_converging=False, time_limit_s=60.0, residual_load_scale=1.0)
    assert "load scale reached 0 of 1, residual 34.2 N at load scale 1 (stop at 0.00175 N)" in text
    same = failure_advice(model, load_scale=0.5, residual_N=3.0, tolerance_N=0.002, timed_out=False,
                          still_converging=False, time_limit_s=60.0, residual_load_scale=0.5)
    assert "residual 3 N (stop at" in same


def test_a_solve_out_of_time_while_converging_is_told_to_allow_more():
    stiff = _model(3.0e8, 0.015, 2_000.0)            # 0.94 % at the head: not the cause
    assert head_strain(stiff)[2] < LARGE_STRAIN
    text = failure_advice(stiff, load_scale=1.0, residual_N=0.5, tolerance_N=0.002, timed_out=True,
                          still_converging=True, time_limit_s=60.0)
    assert "time limit of 60 s CPU" in text and TIME_LIMIT_KEY in text
    stalled = failure_advice(stiff, load_scale=0.5, residual_N=0.5, tolerance_N=0.002, timed_out=False,
                             still_converging=False, time_limit_s=60.0)
    assert TIME_LIMIT_KEY not in stalled and "cable.element_length" in stalled


def test_the_time_limit_stops_a_steady_solve_soon_with_the_cause(tmp_path):
    """A limit far below what the solve needs: status failed, the message names the key, the load
    scale and residual reached and the strain at the head; nothing already computed is lost (the
    result files are written)."""
    sc = load_scenario(TINY).replace(**{"solver.mode": "steady", "solver.steady_time_limit": 1e-3})
    c0 = time.process_time()
    res = run_scenario(sc, tmp_path, plots=False)
    assert time.process_time() - c0 < 30.0
    s = res.summary
    assert s["status"] == "failed"
    assert TIME_LIMIT_KEY in s["message"] and "load scale reached" in s["message"]
    assert "strain at the head" in s["message"] and "(stop at" in s["message"]
    assert "a larger `solver.steady_time_limit`" in s["message"]      # nothing converged: more time can help
    assert (tmp_path / "summary.json").exists()


def test_the_default_time_limit_leaves_a_normal_case_alone():
    sc = load_scenario(TINY).replace(**{"solver.mode": "steady"})
    assert sc.solver.steady_time_limit_s == 60.0
    res = run_scenario(sc, None, plots=False)
    assert res.summary["status"] == "ok", res.summary["message"]


TIGHT = """name = "tight_clearance"
[cable]
radius = 0.0295
mass_per_length = 1.5
youngs_modulus = 5e9
[conduit]
inner_radius = 0.03
path = [{{straight = 20}}, {{bend = 30, radius = 10.0, turn = "left"}}, {{straight = 20}}]
[contact]
friction = 0.2
stiffness = {stiffness}
[pull]
speed = 1.0
back_tension = 500.0
[gravity]
g = 9.81
[solver]
mode = "steady"
"""


def test_a_steady_solve_in_a_tight_conduit_is_checked_for_penetration(tmp_path):
    """A stiff 59 mm cable in a 60 mm duct (0.5 mm clearance) through a 30° bend: with the default
    contact stiffness the wall's compliance takes a third of the clearance at the bend ends and the
    pull comes out low (5 % below an independent rigid-wall beam model, quasistatic/beam.py, on the
    same bend with 30 m straights); a steady run must say so as a dynamic one does (status
    `penetration`, where, and the key to raise), not end `ok`. Stiffer contact passes the check."""
    soft = tmp_path / "soft.toml"
    soft.write_text(TIGHT.format(stiffness=1e6))
    res = run_scenario(soft, tmp_path / "soft", plots=False, error_bar=False)
    s = res.summary
    assert s["status"] == "penetration", s["status"]
    flag = next(f for f in s["flags"] if f["flag"] == "penetration")
    assert flag["value_m"] > flag["limit_m"] == pytest.approx(0.25 * 0.0005)
    bend_ends_m = (20.0, 20.0 + 10.0 * math.pi / 6)
    assert min(abs(flag["s_conduit_m"] - e) for e in bend_ends_m) < 1.0     # at a bend end
    assert "contact.stiffness" in flag["message"]
    stiff = tmp_path / "stiff.toml"
    stiff.write_text(TIGHT.format(stiffness=1e8))
    assert run_scenario(stiff, tmp_path / "stiff", plots=False, error_bar=False).summary["status"] == "ok"


def _beam_rigid_wall_N(straight_m: float, clearance_m: float) -> tuple[float, float]:
    """The TIGHT route's pull against a rigid wall from the independent beam-in-conduit model
    (quasistatic/beam.py: a node chain, not ANCF, not Exudyn) at 40/80/160 nodes per bending length,
    extrapolated by Aitken's Δ² (Richardson with the observed order), and the extrapolation's step [N]."""
    from exucable.quasistatic.beam import stiff_route_difference

    pieces = [(straight_m, 0.0), (10.0 * math.pi / 6.0, 0.1), (straight_m, 0.0)]
    EJ = 5e9 * math.pi * 0.0295 ** 4 / 4.0
    F = [stiff_route_difference(pieces, clearance_m, 0.2, 1.5 * 9.81, EJ, 500.0, nodes_per_bending_length=n)["stiff_N"]
         for n in (40.0, 80.0, 160.0)]
    d1, d2 = F[1] - F[0], F[2] - F[1]
    assert 0.0 < d2 < d1, F            # converging monotonically: the extrapolation applies
    limit = F[2] - d2 * d2 / (d2 - d1)
    return limit, limit - F[2]


def test_the_steady_error_bar_covers_the_rigid_wall_at_tight_clearance(tmp_path):
    """The stiff cable in the 0.5 mm clearance with a contact stiffness 10x the default: the wall's
    compliance takes ~10 % of the clearance (inside the `penetration` limit) and the pull comes out ~2 %
    below the rigid wall's (studies/wall_compliance_study.py). The reported force stays the simulated
    one; its error bar, with the wall's part |F − F_rope|·(√(1 + δ/c) − 1), covers the rigid-wall pull
    of the independent beam model (extrapolated in its node spacing; covering the extrapolated limit
    is stricter than covering its finest level, which lies below it); the part is not vacuous (at most
    twice the actual shortfall; the law's first-order error at δ/c 0.1 is ~5 % of it) and the run
    warns, naming `contact.stiffness`."""
    path = tmp_path / "k1e7.toml"
    path.write_text(TIGHT.format(stiffness=1e7))
    res = run_scenario(path, None, plots=False)
    s = res.summary
    assert s["status"] == "ok", s["message"]
    parts = s["pull_force_uncertainty"]
    F, u, wall = s["pull_force_N"], s["pull_force_uncertainty_N"], parts["wall_N"]
    rigid, step = _beam_rigid_wall_N(20.0, 0.0005)
    assert 0.01 < (rigid - F) / rigid < 0.03, (F, rigid)      # the case does what it is here for
    assert F + u >= rigid, (F, u, rigid, step)
    assert wall <= 2.0 * (rigid - F), (wall, rigid - F)
    assert u == pytest.approx(parts["mesh_N"] + parts["solve_N"] + wall, rel=1e-12)
    assert "wall's compliance" in s["pull_force_uncertainty_method"]
    assert any("contact.stiffness" in w and "rigid wall" in w for w in s["warnings"]), s["warnings"]


def test_several_cables_that_stall_are_sent_to_the_dynamic_run_not_to_a_coarser_mesh():
    """Where several cables' steady solve stalls (the triangle turning over in an up-bend), the mesh
    rule's coarsest mesh stalled too (studies/bundle_upbend_study.py): the advice names the dynamic
    run alone, and still a larger time limit where the residual was falling."""
    bundle = _model(2.0e8, 0.015, 1_753.0)
    bundle.n_cables = 3
    stalled = failure_advice(bundle, load_scale=0.0, residual_N=465.0, tolerance_N=0.00175, timed_out=False,
                             still_converging=False, time_limit_s=60.0)
    assert 'solver.mode = "dynamic"' in stalled and "cable.element_length" not in stalled
    timed = failure_advice(bundle, load_scale=1.0, residual_N=0.5, tolerance_N=0.00175, timed_out=True,
                           still_converging=True, time_limit_s=60.0)
    assert TIME_LIMIT_KEY in timed and 'solver.mode = "dynamic"' in timed
    single = failure_advice(_model(2.0e8, 0.015, 1_753.0), load_scale=0.0, residual_N=465.0, tolerance_N=0.00175,
                            timed_out=False, still_converging=False, time_limit_s=60.0)
    assert "cable.element_length" in single


@pytest.mark.parametrize("duct_radius_m, arrangement, named", [
    (0.05, "triangular", True),       # D/d 3.33: the calculators take three cables cradled
    (0.035, "triangular", False),     # D/d 2.33 < 2.5: triangular is the calculators' own choice
    (0.05, "cradled", False),         # already the cradle
])
def test_a_stalled_triangle_where_the_calculators_take_a_cradle_is_told_the_cradled_arrangement(
        duct_radius_m, arrangement, named):
    """A triangle of three cables at D/d ≥ 2.5 loses its top cable into the cradle's place in the
    bends, which the steady solve has not followed (reference/README.md): its failure names the
    arrangement that solves, with the D/d; a triangle below 2.5, or a cradle, is not told so."""
    bundle = _model(2.0e8, 0.015, 1_753.0)
    bundle.n_cables, bundle.arrangement = 3, arrangement
    bundle.scenario.cable.radius_m = 0.015
    bundle.scenario.conduit = SimpleNamespace(inner_radius_m=duct_radius_m)
    text = failure_advice(bundle, load_scale=0.0, residual_N=29.4, tolerance_N=0.00175, timed_out=False,
                          still_converging=False, time_limit_s=60.0)
    assert 'solver.mode = "dynamic"' in text
    assert ('cable.arrangement = "cradled"' in text) == named
    if named:
        assert "D/d 3.33" in text


def test_steps_rejected_to_the_stiffest_spring_say_so_and_how_many(monkeypatch):
    """One-iteration steps that every time fail are retried at 4× the spring rate until 1e6 c0; the
    message then says that, after how many steps and the last failure, not "no equilibrium after
    <budget> steps" (the budget of 80 was never spent)."""
    from exucable.data import data_path
    from exucable.model.build import build_model
    from exucable.solve.steady import SteadySolver

    model = build_model(load_scenario(data_path("scenarios/fast/paper_ex2_bend90.toml"))
                        .replace(**{"solver.mode": "steady"}))
    solver = SteadySolver(model)
    monkeypatch.setattr(solver, "pseudo_step", lambda c, settings: (False, "Newton diverged", float("nan")))
    ok, why = solver.relax_one_iteration(1.0)
    # from c0 to beyond 1e6 c0 by 4×: 4^k > 1e6 first at k = 10
    assert not ok
    assert why == ("one-iteration pseudo-time steps: a step rejected up to a spring rate of 1e6 c0 after 10 "
                   "steps (none accepted); last: Newton diverged")
