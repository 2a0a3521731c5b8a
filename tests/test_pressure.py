"""Sidewall pressure an engineer can use (exucable.post.pressure, issue #10 item 5): windowed pressure
against the rope's T/R in a bend's body, point loads at bend ends as forces, bends.csv."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from exucable.geometry.path import Bend, Straight, centreline_from_path
from exucable.post.pressure import BEND_COLUMNS, bend_table, default_window_m
from exucable.output.results import read_csv
from exucable.run import run_scenario
from exucable.scenario.specs import load_scenario

from conftest import ROOT


def _ex2_route():
    return centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(1.0), Bend(90.0, 0.5, "left"), Straight(1.0)])


def _stiff_cable_loads(spread_points: int):
    """Check points every 0.1 mm carry the capstan rope's T/R, except where a stiff cable lifts off
    after the bend's start (12 mm) and before its end (8 mm); there it lands with 2 N and 3 N,
    each spread over ``spread_points`` points as a mesh spreads them."""
    cl = _ex2_route()
    mu, T2, R = 0.2, 150.0, 0.5
    s1 = 1.0 + np.pi * R / 2

    def rope(s):
        T = T2 * np.exp(mu * np.clip((s - 1.0) / R, 0.0, np.pi / 2))
        return T, np.where((s > 1.0) & (s < s1), T / R, 0.0)

    s = np.arange(0.00005, cl.length_m, 0.0001)          # a point per 0.1 mm carries its 0.1 mm of load
    T, p = rope(s)
    F = p * 0.0001
    F[(s > 1.0) & (s < 1.012)] = 0.0
    F[(s > s1 - 0.008) & (s < s1)] = 0.0
    for place, load in ((1.012, 2.0), (s1 - 0.008, 3.0)):
        i = np.argmin(abs(s - place))
        F[i - spread_points // 2:i + spread_points // 2 + 1] += load / spread_points
    s_rope = np.linspace(0.0, cl.length_m, 300001)
    T_rope, p_rope = rope(s_rope)
    return cl, s, F, T, s_rope, T_rope, p_rope, s1


@pytest.mark.parametrize("spread_points", [1, 7])
def test_bend_table_recovers_a_known_distribution(spread_points):
    """The body mean is T/R, and the point loads come back as forces at their places whether
    concentrated on one check point or spread over several (their moments fix both)."""
    cl, s, F, T, s_rope, T_rope, p_rope, s1 = _stiff_cable_loads(spread_points)
    w = default_window_m(cl)
    assert w == 0.25
    rows = bend_table(cl.pieces, s, F, s, T, s_rope, T_rope, p_rope, w, bending_length_m=0.012,
                      element_length_m=0.003)
    assert len(rows) == 1
    b = rows[0]
    assert abs(b["mean_pressure_vs_rope"]) < 1e-3
    # a point carries 0.1 mm: the load's place is known to its spread, the load to the body's
    # pressure (300–410 N/m) over half a point's share, 0.02 N
    assert b["entry_point_load_N"] == pytest.approx(2.0, abs=0.03)
    assert b["entry_s_conduit_m"] == pytest.approx(1.012, abs=4e-4)
    assert b["exit_point_load_N"] == pytest.approx(3.0, abs=0.03)
    assert b["exit_s_conduit_m"] == pytest.approx(s1 - 0.008, abs=4e-4)
    assert b["tension_in_N"] == pytest.approx(150.0, rel=1e-3)
    assert b["tension_out_N"] == pytest.approx(150 * np.exp(0.1 * np.pi), rel=1e-3)
    rev = bend_table(cl.pieces, s, F, s, T, s_rope, T_rope, p_rope, w, 0.012, direction="reverse",
                     element_length_m=0.003)[0]
    assert rev["entry_point_load_N"] == b["exit_point_load_N"] and rev["tension_in_N"] == b["tension_out_N"]


@pytest.mark.parametrize("spread_points", [1, 7])
@pytest.mark.parametrize("weight_N", [0.0, 1e-6])
def test_point_loads_look_only_near_their_bend_end(spread_points, weight_N, monkeypatch):
    """bend_end_point_load works on the sorted points near its bend end only (pressure._near_end,
    for speed): the same loads and places, to the bit, as over the whole route, at both ends,
    whether a lift-off gap is found or not (every point loaded by a weight: the excess over ±w/2)."""
    import exucable.post.pressure as pressure

    cl, s, F, T, s_rope, T_rope, p_rope, s1 = _stiff_cable_loads(spread_points)
    F = F + weight_N
    w = default_window_m(cl)
    args = (cl.pieces, s, F, s, T, s_rope, T_rope, p_rope, w, 0.012)
    near = bend_table(*args, element_length_m=0.003)
    monkeypatch.setattr(pressure, "_near_end", lambda s, F, s_end_m, reach_m, s_sorted=False: (s, F))
    whole = bend_table(*args, element_length_m=0.003)
    assert near == whole
    assert near[0]["entry_point_load_N"] != 0.0 and near[0]["exit_point_load_N"] != 0.0


@pytest.fixture(scope="module")
def ex2_rule_mesh(tmp_path_factory):
    """Paper Example 2 (fast variant) on the mesh rule's mesh: 32 elements × 29 check points."""
    sc = load_scenario(ROOT / "scenarios/fast/paper_ex2_bend90.toml")
    sc = dataclasses.replace(sc, cable=dataclasses.replace(sc.cable, elements=None),
                             contact=dataclasses.replace(sc.contact, check_points_per_element=None))
    out = tmp_path_factory.mktemp("ex2rule")
    return run_scenario(sc, out), out


def test_windowed_pressure_matches_T_over_R_in_the_bend_body(ex2_rule_mesh):
    res, out = ex2_rule_mesh
    s = res.summary
    assert s["status"] in ("ok", "steady") and s["mesh"]["source"] == "rule"
    b = s["bends"][0]
    assert abs(b["mean_pressure_vs_rope"]) < 0.02            # issue #10: within 2 % of T/R
    # the pulling force of the rule mesh: the capstan within 0.1 % (paper Eq. 26)
    assert s["pull_force_N"] == pytest.approx(150 * np.exp(0.2 * np.pi / 2), rel=1e-3)
    # bend-end loads are forces of order √(EJ·T)/R or less, not spikes in N/m
    assert abs(b["entry_point_load_N"]) < 5.0 and abs(b["exit_point_load_N"]) < 5.0
    table = read_csv(out / "bends.csv")
    assert list(table) == list(BEND_COLUMNS) and len(table["bend"]) == 1
    assert list(read_csv(out / "pressure_profile.csv")) == ["s_conduit_m", "windowed_pressure_N_per_m",
                                                            "rope_windowed_pressure_N_per_m"]
    assert (out / "pressure.png").stat().st_size > 5000
