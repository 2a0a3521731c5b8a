"""Sidewall pressure an engineer can use (exucable.pressure, issue #10 item 5): windowed pressure
against the rope's T/R in a bend's body, point loads at bend ends as forces, bends.csv."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from exucable.geometry.path import Bend, Straight, centreline_from_path
from exucable.pressure import BEND_COLUMNS, bend_table, default_window_m
from exucable.results import read_csv
from exucable.run import run_scenario
from exucable.scenario import load_scenario

from conftest import ROOT


def _ex2_route():
    return centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(1.0), Bend(90.0, 0.5, "left"), Straight(1.0)])


def test_bend_table_recovers_a_known_distribution():
    """Check points every mm carry the capstan rope's T/R plus 2 N and 3 N at the bend's ends:
    the body mean is T/R and the point loads come back as forces at their places."""
    cl = _ex2_route()
    mu, T2, R = 0.2, 150.0, 0.5

    def rope(s):
        T = T2 * np.exp(mu * np.clip((s - 1.0) / R, 0.0, np.pi / 2))
        return T, np.where((s > 1.0) & (s < 1.0 + np.pi * R / 2), T / R, 0.0)

    s = np.arange(0.0005, cl.length_m, 0.001)            # a point per mm carries its mm of load
    T, p = rope(s)
    F = p * 0.001                                         # (the cells at the bend's ends err by < 0.05 N)
    s_rope = np.linspace(0.0, cl.length_m, 300001)
    T_rope, p_rope = rope(s_rope)
    F[np.argmin(abs(s - 1.003))] += 2.0
    F[np.argmin(abs(s - (1.0 + np.pi * R / 2 - 0.003)))] += 3.0
    w = default_window_m(cl)
    assert w == 0.25
    rows = bend_table(cl.pieces, s, F, s, T, s_rope, T_rope, p_rope, w, bending_length_m=0.012)
    assert len(rows) == 1
    b = rows[0]
    assert abs(b["mean_pressure_vs_rope"]) < 1e-3
    assert b["entry_point_load_N"] == pytest.approx(2.0, abs=0.05) and b["entry_s_conduit_m"] == pytest.approx(1.0)
    assert b["exit_point_load_N"] == pytest.approx(3.0, abs=0.05)
    assert b["tension_in_N"] == pytest.approx(150.0, rel=1e-3)
    assert b["tension_out_N"] == pytest.approx(150 * np.exp(0.1 * np.pi), rel=1e-3)
    rev = bend_table(cl.pieces, s, F, s, T, s_rope, T_rope, p_rope, w, 0.012, direction="reverse")[0]
    assert rev["entry_point_load_N"] == pytest.approx(3.0, abs=0.05) and rev["tension_in_N"] == b["tension_out_N"]


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
