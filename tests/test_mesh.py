"""The mesh rule (exucable.scenario.mesh): element length from bend radius and clearance, check points from
the bending length, overrides checked, too-coarse meshes refused with the count needed."""

from __future__ import annotations

import math

import pytest

from exucable.errors import ModelError
from exucable.geometry.path import Bend, Straight, centreline_from_path
from exucable.scenario.mesh import MAX_SAGITTA_CLEARANCES, MAX_TURN_RAD, plan_mesh

from conftest import make_scenario


def _route(*items):
    return centreline_from_path([0, 0, 0], [1, 0, 0], list(items))


def _bend(deg, R, turn="left"):
    return Bend(angle_deg=deg, radius_m=R, turn=turn)


EX2 = dict(clearance_m=0.001, bending_stiffness_N_m2=1e9 * math.pi * 0.0025**4 / 4, max_tension_N=205.4)


def test_single_bend_rule_keeps_sagitta_and_turning_within_bounds():
    cl = _route(Straight(1.0), _bend(90, 0.5), Straight(1.0))
    plan = plan_mesh(cl, cable_length_m=cl.length_m, **EX2)
    L_e = plan.element_length_m
    assert L_e**2 / (8 * 0.5) <= MAX_SAGITTA_CLEARANCES * 0.001 * (1 + 1e-9)
    assert L_e / 0.5 <= MAX_TURN_RAD
    # the sagitta bound decides here: √(16·0.5·0.001) = 0.0894 m -> ceil(2.785/0.0894) = 32
    assert plan.elements == 32 and plan.source == "rule" and not plan.warnings
    # check points every λ/4 at most, λ = √(EJ/T) = 12.2 mm
    lam = math.sqrt(EX2["bending_stiffness_N_m2"] / 205.4)
    assert plan.bending_length_m == pytest.approx(lam)
    assert L_e / plan.check_points_per_element <= lam / 4


@pytest.mark.parametrize("clearance_m, bound_m", [(0.0084, 0.6),            # turning 0.2 rad · 3 m decides
                                                  (0.002, math.sqrt(0.096))])  # sagitta 2 c: √(16 R c)
def test_multi_bend_route_rule_scales_with_the_clearance(clearance_m, bound_m):
    """Issue #10's ~100 m route, four 45° bends of R 3 m (97.4 m): 163 elements at 8.4 mm
    clearance, 315 at 2 mm (where 110 gave +16 % and 440 +0.5 %)."""
    items = [Straight(20.0)]
    for turn in ("left", "right", "left", "right"):
        items += [_bend(45, 3.0, turn), Straight(17.0)]
    cl = _route(*items)
    plan = plan_mesh(cl, clearance_m, cl.length_m, 2.58, 300.0)
    assert plan.elements == math.ceil(cl.length_m / bound_m)
    assert plan.elements == {0.0084: 163, 0.002: 315}[clearance_m]


def test_straight_route_gets_the_minimum():
    cl = _route(Straight(50.0))
    plan = plan_mesh(cl, 0.001, 50.0, 0.03, 7.3)
    assert plan.elements == 10 and plan.check_points_per_element == 8


def test_coarse_override_warns_and_too_coarse_is_refused_naming_the_key():
    items = [Straight(20.0)] + [_bend(45, 3.0), Straight(17.0)] * 4
    cl = _route(*items)
    # 110 elements at 8.4 mm clearance: sagitta 4 c -> runs, but says it is coarser than the rule
    plan = plan_mesh(cl, 0.0084, cl.length_m, 2.58, 300.0, elements=110)
    assert plan.elements == 110 and plan.warnings and "cable.elements" in plan.warnings[0]
    # 110 elements at 2 mm clearance: sagitta 17 c (issue #10: +16 %) -> refused with the count needed
    with pytest.raises(ModelError) as info:
        plan_mesh(cl, 0.002, cl.length_m, 2.58, 300.0, elements=110)
    assert info.value.key == "cable.elements" and "at least" in str(info.value)
    with pytest.raises(ModelError) as info:
        plan_mesh(cl, 0.002, cl.length_m, 2.58, 300.0, element_length_m=1.0)
    assert info.value.key == "cable.element_length"


def test_element_length_and_refinement():
    cl = _route(Straight(1.0), _bend(90, 0.5), Straight(1.0))
    plan = plan_mesh(cl, cable_length_m=cl.length_m, element_length_m=0.05, **EX2)
    assert plan.elements == math.ceil(cl.length_m / 0.05) and plan.source == "cable.element_length"
    assert plan_mesh(cl, cable_length_m=cl.length_m, refine=2.0, **EX2).elements == 64


def test_scenario_without_elements_builds_with_the_rule():
    import dataclasses
    from exucable.model.build import build_model
    sc = make_scenario(conduit={"inner_radius": 0.0035, "path": [{"straight": 1.0},
                                                                  {"bend": 90, "radius": 0.5, "turn": "left"},
                                                                  {"straight": 1.0}]},
                       pull={"speed": 0.1, "back_tension": 150.0})
    sc = dataclasses.replace(sc, cable=dataclasses.replace(sc.cable, elements=None))
    m = build_model(sc)
    assert m.mesh.elements == 32 and m.layout.n_elements == 32
    assert m.kernel.n_check_points == m.mesh.check_points_per_element
