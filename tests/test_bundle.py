"""Several cables in one conduit, simulated (exucable/model/bundle.py, steady mode).

Closed-form references: the statics of rigid circles in a circle (frictionless between the cables)
give the calculators' weight correction factors, triangular 1/√(1 - x²) and cradled 1 + (4/3)x²
with x = d/(D - d) (Cableizer f_wc, IEEE 1185 / Southwire; exucable/quasistatic/engineering.py,
checked there against the published values). Global axial equilibrium of a horizontal straight
checks the pulling force against the wall's friction. Coarse meshes (8 elements of 0.5 m).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import exucable as xc
from exucable.errors import ModelError
from exucable.model.bundle import arrangement_offsets, build_bundle_model, bundle_report
from exucable.quasistatic import engineering as eng
from exucable.solve.steady import solve_steady

D_CABLE = 0.03          # cable diameter [m]
MU = 0.3
BACK = 30.0             # the bundle's back tension [N]


def straight_duct(count, arrangement, ratio, **extra):
    """A 4 m horizontal duct of inner diameter ratio·d with ``count`` cables, steady mode, rig at the exit."""
    cable = dict(radius=D_CABLE / 2, density=2000.0, youngs_modulus=2e8, count=count, arrangement=arrangement,
                 elements=8)
    cable.update(extra.pop("cable", {}))
    return xc.Scenario(route=xc.Route(inner_radius=ratio * D_CABLE / 2).straight(4.0),
                       cable=xc.Cable(**cable),
                       contact=xc.Contact(friction=MU, check_points_per_element=8, **extra),
                       pull=xc.Pull(speed=0.1, back_tension=BACK), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", end_time=1.0, steady_lead_out=0.0))


@pytest.mark.parametrize("arrangement, ratio", [("triangular", 2.4), ("triangular", 3.3), ("cradled", 2.8),
                                                ("cradled", 3.3)])
def test_straight_duct_gives_the_rigid_circle_weight_correction(arrangement, ratio):
    """Three cables, frictionless between them: the tension rise along the straight's middle half
    over the cables' alone is the calculators' factor within 0.2 %. What separates them is the Hertz
    compliance (penetrations ~5 µm against 15 mm radii move the contact angles by ~1e-3 relative,
    the factor by a fraction of that) and the check points' discrete contact on a coarse mesh;
    measured -0.01 to +0.08 % with the cables' tensions from their loads' equilibrium (-0.04 to
    -0.11 % read off EA·ε)"""
    sc = straight_duct(3, arrangement, ratio)
    model = build_bundle_model(sc)
    out = solve_steady(model)
    assert out.status == "ok", out.message
    report = bundle_report(model)
    (straight,) = report["straights"]
    formula = eng.weight_correction_factor(3, arrangement, ratio * D_CABLE, D_CABLE)
    assert report["formula_weight_correction_factor"] == formula
    assert straight["weight_correction_factor"] == pytest.approx(formula, rel=2e-3)
    # the eye's pull is the sum of the shares; minus the back tension it is the wall's friction
    # (frictionless between the cables, horizontal): μ Σ N up to the friction's regularisation
    # (v/√(v² + ε²) = 1 - 5e-5 at 0.1 m/s, ε = 1 mm/s)
    F = report["pull_force_N"]
    assert F == pytest.approx(sum(c["pull_share_N"] for c in report["cables"]), rel=1e-12)
    wall = sum(c["wall_normal_force_N"] for c in report["cables"])
    assert F - BACK == pytest.approx(MU * wall, rel=1e-3)
    # the whole route's factor includes the ends (the pinned eye carries the weight next to it):
    # below the formula (measured -1.2 to -1.4 %)
    assert report["weight_correction_factor"] == pytest.approx(formula, rel=0.02)


def test_two_cables_and_the_mirror_symmetry():
    """Two cables side by side (the calculators' triangular formula for two): the factor, and the
    two cables' equal shares of the pull."""
    sc = straight_duct(2, "triangular", 3.3)
    model = build_bundle_model(sc)
    assert solve_steady(model).status == "ok"
    report = bundle_report(model)
    formula = eng.weight_correction_factor(2, "triangular", 3.3 * D_CABLE, D_CABLE)
    assert report["straights"][0]["weight_correction_factor"] == pytest.approx(formula, rel=2e-3)
    a, b = (c["pull_share_N"] for c in report["cables"])
    assert a == pytest.approx(b, rel=1e-6)
    assert report["cables"][0]["pull_share"] == pytest.approx(0.5, rel=1e-6)


@pytest.mark.parametrize("count, arrangement", [(2, "triangular"), (3, "triangular"), (3, "cradled"), (4, "cradled"),
                                                (4, "diamond")])
def test_arrangement_offsets_touch_wall_and_neighbours(count, arrangement):
    """Rigid circles: every cable within the duct (axis at most R - r out), the cables on the wall
    exactly there, every pair at least 2r apart and each cable touching at least one other."""
    R, r = 0.05, 0.0175
    p = arrangement_offsets(count, arrangement, R, r)
    dist = np.hypot(p[:, 0], p[:, 1])
    assert np.all(dist <= R - r + 1e-12)
    assert np.count_nonzero(np.isclose(dist, R - r, rtol=1e-12)) >= 2
    gaps = np.hypot(*(p[:, None, :] - p[None, :, :]).transpose(2, 0, 1)) + np.eye(count) * 1.0
    assert gaps.min() >= 2 * r * (1 - 1e-12)
    assert np.all(np.isclose(gaps, 2 * r, rtol=1e-12).any(axis=1))


def test_run_writes_the_bundle_report(tmp_path):
    """`exucable run` of a bundle: summary.json's bundle keys, each cable's tension profile."""
    res = xc.run(straight_duct(3, "cradled", 3.3), out_dir=tmp_path)
    assert res.status == "ok"
    summary = json.loads((tmp_path / "summary.json").read_text())
    b = summary["bundle"]
    assert b["count"] == 3 and b["arrangement"] == "cradled"
    assert summary["pull_force_N"] == pytest.approx(sum(c["pull_share_N"] for c in b["cables"]), rel=1e-12)
    assert [c["cable"] for c in b["cables"]] == [1, 2, 3]
    header = (tmp_path / "cable_tensions.csv").read_text().splitlines()[0]
    assert header == "x_m,cable_1_tension_N,cable_2_tension_N,cable_3_tension_N"
    # the middle cable (on the bottom, pressed by both others) pulls hardest
    shares = [c["pull_share_N"] for c in b["cables"]]
    assert shares[1] > shares[0] and shares[1] > shares[2]


@pytest.mark.parametrize("change, key", [
    ({"pull.force": 100.0, "pull.back_tension": 0.0}, "pull.force"),
    ({"contact.surface": "segments"}, "contact.surface"),
])
def test_uncovered_cases_are_refused_naming_the_key(change, key):
    sc = straight_duct(3, "triangular", 3.3).replace(**change)
    with pytest.raises(ModelError) as err:
        xc.run(sc)
    assert key in str(err.value)



def test_diamond_that_would_collapse_is_refused():
    """In a wide duct the diamond's top cable would fall through onto the bottom one: refused,
    naming the key, rather than laid overlapping."""
    with pytest.raises(ModelError) as err:
        arrangement_offsets(4, "diamond", 0.05, 0.012)
    assert "cable.arrangement" in str(err.value)


def test_command_line_prints_the_bundle(tmp_path):
    """`exucable run` on a scenario file with three cables: exit 0, the factor and the shares printed."""
    import subprocess
    import sys

    path = tmp_path / "three.toml"
    path.write_text('name = "three"\n[cable]\nradius = 0.015\ndensity = 2000.0\nyoungs_modulus = 2e8\ncount = 3\n'
                    'arrangement = "cradled"\nelements = 8\n[conduit]\ninner_radius = 0.0495\npath = [{straight = 4.0}]\n'
                    '[contact]\nfriction = 0.3\ncheck_points_per_element = 8\n[pull]\nspeed = 0.1\nback_tension = 30.0\n'
                    '[gravity]\ng = 9.81\n[solver]\nmode = "steady"\nend_time = 1.0\nsteady_lead_out = 0.0\n')
    proc = subprocess.run([sys.executable, "-m", "exucable", "run", str(path), "--out", str(tmp_path / "out"),
                           "--no-plots"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "3 cables cradled" in proc.stdout and "weight correction factor" in proc.stdout
    assert proc.stdout.count("  cable ") == 3
