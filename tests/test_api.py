"""The public Python API: the issue's code block runs as written and gives the capstan value;
routes, parts and replace validate like the scenario file."""

from __future__ import annotations

import math

import numpy as np
import pytest

import exucable as xc
from exucable.quasistatic.closed_forms import capstan_out_N


def test_exports():
    for name in ("Route", "Cable", "Contact", "Pull", "Gravity", "Solver", "Scenario", "run", "load_scenario",
                 "vary", "Result", "ScenarioError"):
        assert name in xc.__all__ and hasattr(xc, name)


def test_issue_code_block_gives_the_capstan():
    """Issue 13's block with end_time 0.3 s: 90° bend, μ 0.2, back tension 150 N, no gravity.
    Reference: capstan T1 = T2·exp(μθ) = 205.37 N (Euler-Eytelwein, paper Eq. 26)."""
    route = (xc.Route(inner_radius=3.5e-3)
             .straight(1.0).bend(90, radius=0.5, turn="left").straight(1.0))
    sc = xc.Scenario(route=route,
                     cable=xc.Cable(radius=2.5e-3, density=1000.0, youngs_modulus=1e9),
                     contact=xc.Contact(friction=0.2), pull=xc.Pull(speed=0.1, back_tension=150.0),
                     gravity=None, solver=xc.Solver(mode="dynamic", end_time=0.3))
    res = xc.run(sc)
    reference = capstan_out_N(150.0, 0.2, math.pi / 2)
    assert res.status == "ok", res.message
    assert abs(res.pull_force_N / reference - 1) < 2e-3, (res.pull_force_N, reference)
    assert 0 < res.pull_force_uncertainty_N < 1e-3 * reference
    h = res.history
    assert isinstance(h.time_s, np.ndarray) and h.time_s.shape == h.pull_force_N.shape and h.time_s[-1] == 0.3
    tp = res.tension_profile
    assert tp.s_m[0] == 0 and tp.s_m[-1] == pytest.approx(route.length_m)
    assert tp.tension_N[0] == pytest.approx(150.0, rel=2e-2)
    assert res.max_tension_N >= np.max(tp.tension_N) - 1e-9     # the steady window ends in this state
    assert res.max_sidewall_pressure_N_per_m > 0.0
    q, v = res.model.coordinates()
    assert q.shape == (sc.cable.elements + 1, 6)
    assert res.model.kernel is not None and res.model.mbs is not None
    assert res.out_dir is None


def test_route_pieces_are_checked_with_the_files_keys():
    with pytest.raises(xc.ScenarioError) as info:
        xc.Route(inner_radius=3.5e-3).straight(1.0).bend(90, radius=-0.5, turn="left")
    assert str(info.value) == "conduit.path[1].radius: must be > 0 (m), got -0.5"
    with pytest.raises(xc.ScenarioError, match="conduit.path.0..turn"):
        xc.Route(inner_radius=3.5e-3).helix(1, radius=1.0, pitch=0.1, turn="up")
    with pytest.raises(xc.ScenarioError, match="conduit.inner_radius"):
        xc.Route(inner_radius=-1).straight(1.0)


def test_route_from_survey_and_csv_equal_the_file_route(tmp_path):
    pts = [[0, 0, 0], [2, 0, 0], [2, 2, 0]]
    r1 = xc.Route.from_survey(pts, bend_radius=0.5, inner_radius=3.5e-3)
    csv = tmp_path / "route.csv"
    csv.write_text("x,y,z\n" + "\n".join(",".join(str(c) for c in p) for p in pts) + "\n")
    r2 = xc.Route.from_csv(csv, inner_radius=3.5e-3, bend_radius=0.5)
    assert r1.to_spec().points_m == r2.to_spec().points_m
    assert r1.length_m == pytest.approx(r2.length_m) == pytest.approx(4 - 2 * 0.5 + math.pi / 4)
    with pytest.raises(xc.ScenarioError, match="conduit.points_csv"):
        xc.Route.from_csv(tmp_path / "missing.csv", inner_radius=3.5e-3, bend_radius=0.5)


def test_scenario_python_equals_file(tmp_path):
    text = """
[cable]
radius = 0.0025
density = 1000.0
youngs_modulus = 1e9
[conduit]
inner_radius = 0.0035
path = [{ straight = 1.0 }, { bend = 90.0, radius = 0.5, turn = "left" }, { straight = 1.0 }]
[contact]
friction = 0.2
[pull]
speed = 0.1
back_tension = 150.0
[solver]
end_time = 0.5
"""
    f = tmp_path / "scenario.toml"
    f.write_text(text)
    from_file = xc.load_scenario(f)
    route = xc.Route(inner_radius=3.5e-3).straight(1.0).bend(90, radius=0.5, turn="left").straight(1.0)
    in_python = xc.Scenario(route=route, cable=xc.Cable(radius=2.5e-3, density=1000.0, youngs_modulus=1e9),
                            contact=xc.Contact(friction=0.2), pull=xc.Pull(speed=0.1, back_tension=150.0),
                            solver=xc.Solver(end_time=0.5))
    assert in_python == from_file
    assert in_python.replace(**{"contact.friction": 0.3}).contact.friction == 0.3


def test_parts_refuse_bad_values_and_unknown_keys():
    with pytest.raises(xc.ScenarioError) as info:
        xc.Pull(speed=-0.1)
    assert str(info.value) == "pull.speed: must be > 0 (m/s), got -0.1"
    with pytest.raises(xc.ScenarioError, match="did you mean 'youngs_modulus'"):
        xc.Cable(radius=2.5e-3, density=1000.0, young_modulus=1e9)
    with pytest.raises(xc.ScenarioError, match="^cable: required"):
        xc.Scenario(route=xc.Route(inner_radius=3.5e-3).straight(1.0), pull=xc.Pull(speed=0.1),
                    solver=xc.Solver(end_time=0.1))
    with pytest.raises(xc.ScenarioError, match="conduit.inner_radius: must be > the cable radius"):
        xc.Scenario(route=xc.Route(inner_radius=2e-3).straight(1.0),
                    cable=xc.Cable(radius=2.5e-3, density=1000.0, youngs_modulus=1e9),
                    pull=xc.Pull(speed=0.1), solver=xc.Solver(end_time=0.1))
    assert "speed" in xc.Pull.__doc__ and "m/s" in xc.Pull.__doc__


def test_import_changes_no_matplotlib_backend():
    import subprocess
    import sys
    code = ("import matplotlib; b = matplotlib.get_backend(); import exucable; "
            "assert matplotlib.get_backend() == b; import sys; assert 'exudyn' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)


def test_run_and_sweep_stay_functions_after_the_submodules_are_imported():
    import exucable.run  # noqa: F401  (modules of the same names as the functions)
    import exucable.sweep  # noqa: F401
    from exucable.api import run, vary
    assert xc.run is run and xc.vary is vary
