"""One arc-length convention: profiles along the scenario's conduit whatever the pull direction."""

from __future__ import annotations

import numpy as np
import pytest

from exucable.run import run_scenario
from exucable.scenario.specs import load_scenario, parse_scenario

from conftest import ROOT


@pytest.fixture(scope="module")
def both_directions():
    """Fast Example 2 (straight 1 m, 90° bend R 0.5 m, straight 1 m: symmetric) pulled both ways."""
    data = load_scenario(ROOT / "scenarios/fast/paper_ex2_bend90.toml").to_dict()
    runs = {}
    for direction in ("forward", "reverse"):
        data["pull"]["direction"] = direction
        runs[direction] = run_scenario(parse_scenario(data, ROOT), None, quiet=True, plots=False)
    return runs


L_M = 2.0 + np.pi / 4


@pytest.mark.parametrize("profile, column, rtol", [
    ("rope_profile", "tension_N", 1e-12),
    ("rope_profile", "sidewall_pressure_N_per_m", 1e-12),
    # the two dynamic runs are the same computation mirrored, up to the order of floating-point sums
    ("contact_profile", "normal_force_per_length_N_per_m", 1e-6),
])
def test_forward_and_reverse_profiles_are_mirror_images(both_directions, profile, column, rtol):
    f = getattr(both_directions["forward"], profile)
    r = getattr(both_directions["reverse"], profile)
    for p in (f, r):
        assert np.all(np.diff(p["s_conduit_m"]) >= 0.0) and 0.0 <= p["s_conduit_m"][0] <= p["s_conduit_m"][-1] <= L_M
    s = np.linspace(0.0, L_M, 2001)
    a = np.interp(s, f["s_conduit_m"], f[column])
    b = np.interp(L_M - s, r["s_conduit_m"], r[column])
    assert np.max(np.abs(a - b)) <= rtol * np.max(np.abs(a))


@pytest.mark.parametrize("direction, bend_end_m", [("forward", 1.0 + np.pi / 4), ("reverse", 1.0)])
def test_rope_and_contact_profiles_peak_at_the_same_place(both_directions, direction, bend_end_m):
    """Both peak at the bend's pulled end (highest tension, T/R); the cable's bending stiffness
    moves the contact peak by less than one element (0.139 m)."""
    res = both_directions[direction]
    c, rp = res.contact_profile, res.rope_profile
    s_contact = c["s_conduit_m"][np.argmax(c["normal_force_per_length_N_per_m"])]
    s_rope = rp["s_conduit_m"][np.argmax(rp["sidewall_pressure_N_per_m"])]
    element_m = L_M / 20
    assert abs(s_rope - bend_end_m) < 1e-2
    assert abs(s_contact - s_rope) < element_m
