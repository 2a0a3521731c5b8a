"""Several cables laid at given positions (``cable.positions``) instead of an arrangement's rest.

Closed-form references as in tests/test_bundle.py: the rigid-circle statics of three cables in a
circle (frictionless between them) give the triangular factor 1/√(1 - x²) and the cradled
1 + (4/3)x², x = d/(D - d). The positions here are those rests written out in the test from the
geometry (ρ = R - r, two touching cables on the wall α = 2 asin(r/ρ) apart), not taken from
exucable's arrangement code. The eye holds the leading ends where they are laid, and the formula
values stay ``cable.arrangement``'s.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

from exucable.errors import ScenarioError
from exucable.model.bundle import build_bundle_model, bundle_report
from exucable.quasistatic import engineering as eng
from exucable.scenario.specs import load_scenario
from exucable.solve.steady import solve_steady

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_bundle import D_CABLE, straight_duct  # noqa: E402  (the 4 m horizontal duct, 8 elements)

R_CABLE = D_CABLE / 2


def on_wall(ratio, turns):
    """Cables on the wall of a duct D = ratio·d at the angles turns·α from the bottom [m]."""
    rho = ratio * R_CABLE - R_CABLE
    alpha = 2.0 * math.asin(R_CABLE / rho)
    return [[rho * math.sin(k * alpha), -rho * math.cos(k * alpha)] for k in turns]


def triangle(ratio):
    """Two cables on the wall ±α/2 from the bottom and one resting on them [m]."""
    a, b = on_wall(ratio, (-0.5, 0.5))
    half = (b[0] - a[0]) / 2.0
    return [a, b, [0.0, a[1] + math.sqrt(D_CABLE**2 - half**2)]]


def solved(sc):
    model = build_bundle_model(sc)
    out = solve_steady(model)
    assert out.status == "ok", out.message
    return bundle_report(model)


def test_cradled_rest_given_as_positions_gives_the_cradled_factor():
    # the tolerance is test_bundle's: 0.2 % for the Hertz compliance and the coarse mesh's check points
    ratio = 3.3
    pos = on_wall(ratio, (-1.0, 0.0, 1.0))
    report = solved(straight_duct(3, "cradled", ratio, cable=dict(positions=pos)))
    assert report["positions_given"] is True
    for c, (h, v) in zip(report["cables"], pos):
        assert (c["start_offset_horizontal_m"], c["start_offset_up_m"]) == (h, v)
    formula = eng.weight_correction_factor(3, "cradled", ratio * D_CABLE, D_CABLE)
    assert report["straights"][0]["weight_correction_factor"] == pytest.approx(formula, rel=2e-3)


def test_the_mechanics_follows_the_positions_and_the_formula_the_arrangement():
    # at D/d 3.3 the calculators' rule says cradled; laid as a triangle, the cables stay one (it
    # stands at 3.3) and give the triangle's factor, while the formula beside is the rule's
    ratio = 3.3
    report = solved(straight_duct(3, "auto", ratio, cable=dict(positions=triangle(ratio))))
    assert report["arrangement"] == "cradled"
    assert report["formula_weight_correction_factor"] == eng.weight_correction_factor(3, "cradled", ratio * D_CABLE, D_CABLE)
    tri = eng.weight_correction_factor(3, "triangular", ratio * D_CABLE, D_CABLE)
    assert report["straights"][0]["weight_correction_factor"] == pytest.approx(tri, rel=2e-3)


def test_mirrored_positions_give_the_same_pull():
    # three cables in a row up one side of the duct, and the same row up the other side: the duct and
    # gravity are symmetric about the vertical plane, so the pull is the same up to the solve's tolerance
    ratio = 3.3
    row = on_wall(ratio, (0.0, 1.0, 2.0))
    left = solved(straight_duct(3, "cradled", ratio, cable=dict(positions=row)))
    right = solved(straight_duct(3, "cradled", ratio, cable=dict(positions=[[-h, v] for h, v in row])))
    assert right["pull_force_N"] == pytest.approx(left["pull_force_N"], rel=1e-6)
    assert [c["pull_share_N"] for c in right["cables"]] == pytest.approx([c["pull_share_N"] for c in left["cables"]],
                                                                        rel=1e-5)


@pytest.mark.parametrize("positions, key, says", [
    ([[0.0, -0.035], [0.0, 0.0]], "cable.positions", "cable.count = 3"),                  # two for three cables
    ([[0.0, -0.04], [0.03, -0.03], [-0.03, -0.03]], "cable.positions[0]", "wall"),        # 0.04 m > ρ = 0.0345 m
    ([[0.0, -0.0345], [0.01, -0.03], [-0.03, -0.017]], "cable.positions[1]", "overlap"),  # 11 mm apart < 30 mm
    ([[0.0, -0.0345], "up", [-0.03, -0.017]], "cable.positions[1]", "pair"),
])
def test_positions_that_cannot_be_are_refused_naming_the_entry(positions, key, says):
    with pytest.raises(ScenarioError) as err:
        straight_duct(3, "cradled", 3.3, cable=dict(positions=positions))
    assert err.value.key == key and says in str(err.value)


def test_positions_read_from_a_scenario_file(tmp_path):
    f = tmp_path / "three.toml"
    f.write_text("""name = "three"
[conduit]
inner_radius = 0.0495
path = [{straight = 4.0}]
[cable]
radius = 0.015
density = 2000.0
youngs_modulus = 2e8
count = 3
arrangement = "cradled"
positions = [[-0.027, -0.0214], [0.0, -0.0345], [0.027, -0.0214]]
[contact]
friction = 0.3
[pull]
speed = 0.1
[solver]
mode = "steady"
""")
    sc = load_scenario(f)
    assert sc.cable.positions_m == ((-0.027, -0.0214), (0.0, -0.0345), (0.027, -0.0214))
    assert sc.cable.to_dict()["positions"] == [[-0.027, -0.0214], [0.0, -0.0345], [0.027, -0.0214]]


def test_one_cable_has_no_positions():
    with pytest.raises(ScenarioError, match="several cables"):
        straight_duct(1, "single", 3.3, cable=dict(positions=[[0.0, -0.03]]))


def test_dynamic_pull_from_the_positions_keeps_the_lay(capsys):
    # the dynamic model starts from the steady bundle laid at the positions (solver.start_from =
    # "steady"): a triangle at D/d 3.3 stays a triangle, each straight's factor the triangle's within
    # the dynamic test's 0.3 % (tests/test_bundle_dynamic.py), while the formula beside is the rule's
    import exucable as xc
    from exucable.commands.run import _print_bundle

    ratio = 3.3
    sc = straight_duct(3, "auto", ratio, cable=dict(positions=triangle(ratio)))
    sc = sc.replace(**{"solver.mode": "dynamic", "solver.start_from": "steady", "solver.end_time": 0.4})
    res = xc.run(sc)
    s = res.summary
    assert s["mode"] == "dynamic" and s["bundle"]["positions_given"] is True
    tri = eng.weight_correction_factor(3, "triangular", ratio * D_CABLE, D_CABLE)
    (straight,) = s["bundle"]["straights"]
    assert straight["weight_correction_factor"] == pytest.approx(tri, rel=3e-3)
    _print_bundle(s, Path("out"))
    assert "3 cables laid at cable.positions (formulas: cradled)" in capsys.readouterr().out


def test_positions_typed_to_a_few_digits_are_taken():
    # the D/d 3.3 triangle's exact bottom cables sit at (±0.015, −0.0310689…) m: typed as −0.031069 they
    # overlap the wall by 0.5 µm, inside the allowed 1e-3 r = 15 µm; 30 µm into the wall is refused
    from exucable.scenario.specs import POSITIONS_OVERLAP

    typed = [[-0.015, -0.031069], [0.015, -0.031069], [0.0, -0.005087]]
    sc = straight_duct(3, "triangular", 3.3, cable=dict(positions=typed))
    assert sc.cable.positions_m[0] == (-0.015, -0.031069)
    assert POSITIONS_OVERLAP * R_CABLE == pytest.approx(15e-6)
    rho = 3.3 * R_CABLE - R_CABLE
    with pytest.raises(ScenarioError, match=r"cable.positions\[0\].*wall"):
        straight_duct(3, "cradled", 3.3, cable=dict(positions=[[0.0, -(rho + 30e-6)], [0.03, -0.02], [-0.03, -0.02]]))
