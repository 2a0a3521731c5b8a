"""Closed forms: their limits, an independent integration of the vertical-bend ODEs, and the stored reference
values of reference/paper_values.toml recomputed from the published formulas and parameters."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from exucable.quasistatic import closed_forms as cf

REFERENCE = Path(__file__).resolve().parents[1] / "reference" / "paper_values.toml"
W = 1000.0 * math.pi * 2.5e-3**2 * 9.8  # the paper's cable, rho A g [N/m]
# Identities below hold to rounding; 1e-12 relative allows a few ulps through exp/cosh of O(1) arguments.
EXACT = 1e-12


# ---------------------------------------------------------------- limits and identities
def test_incline_eq25_and_its_slope():
    theta = math.radians(30.0)
    assert cf.incline_tension_N(50.0, W, 0.3, theta) == pytest.approx(W * (0.3 * math.cos(theta) + 0.5) * 50.0,
                                                                       rel=EXACT)
    np.testing.assert_allclose(cf.incline_tension_N([0.0, 2.0], W, 0.3, 0.0), [0.0, 0.6 * W], rtol=EXACT)


def test_capstan_and_inverse():
    assert cf.capstan_out_N(150.0, 0.2, math.pi / 2) == pytest.approx(150.0 * math.exp(0.1 * math.pi), rel=EXACT)
    assert cf.capstan_in_N(cf.capstan_out_N(7.0, 0.3, 2.0), 0.3, 2.0) == pytest.approx(7.0, rel=EXACT)


def test_helix_turning_angle():
    assert cf.helix_turning_angle_rad(3.0, 1.0, 0.0) == pytest.approx(6 * math.pi, rel=EXACT)
    # A helix of pitch 2 pi a rises at 45 deg: curvature a/(2a^2), length 2 pi a sqrt 2 per turn -> pi sqrt 2.
    assert cf.helix_turning_angle_rad(1.0, 1.0, 2 * math.pi) == pytest.approx(math.pi * math.sqrt(2.0), rel=EXACT)


def test_horizontal_bend_limits():
    assert cf.horizontal_bend_out_N(3.0, 0.2, 1.0, 0.0, 0.5) == pytest.approx(cf.capstan_out_N(3.0, 0.2, 1.0), rel=EXACT)
    assert cf.horizontal_bend_out_N(3.0, 0.0, 1.0, W, 0.5) == pytest.approx(3.0, rel=EXACT)
    # From zero tension only the weight's friction drives it: T = wR sinh(mu theta).
    assert cf.horizontal_bend_out_N(0.0, 0.3, 2.0, W, 0.5) == pytest.approx(W * 0.5 * math.sinh(0.6), rel=EXACT)


@pytest.mark.parametrize("elevation_deg", [0.0, -20.0, 35.0])
def test_vertical_bends_reduce_to_capstan_and_to_the_height_change(elevation_deg):
    phi0, theta, radius = math.radians(elevation_deg), math.radians(50.0), 2.0
    for fn in (cf.sag_bend_out_N, cf.hump_bend_out_N):
        assert fn(4.0, 0.3, theta, 0.0, radius, phi0) == pytest.approx(cf.capstan_out_N(4.0, 0.3, theta), rel=EXACT)
    # Frictionless: the tension changes by w times the rise of the bend's end.
    rise_sag = radius * (math.cos(phi0) - math.cos(phi0 + theta))  # centre above the entry
    rise_hump = radius * (math.cos(phi0 - theta) - math.cos(phi0))  # centre below the entry
    assert cf.sag_bend_out_N(4.0, 0.0, theta, W, radius, phi0) == pytest.approx(4.0 + W * rise_sag, rel=EXACT)
    assert cf.hump_bend_out_N(4.0, 0.0, theta, W, radius, phi0) == pytest.approx(4.0 + W * rise_hump, rel=EXACT)


def _integrate_vertical_bend(t_in, mu, theta, w, radius, phi0, sag):
    """The vertical-bend rope ODE integrated directly in the turned angle psi (independent of exucable.quasistatic.rope):
    dT/dpsi = mu |T -+ wR cos phi| + wR sin phi, phi = phi0 +- psi."""
    wr = w * radius

    def rate(psi, y):
        phi = phi0 + psi if sag else phi0 - psi
        return [mu * abs(y[0] + (-wr if sag else wr) * math.cos(phi)) + wr * math.sin(phi)]

    sol = solve_ivp(rate, (0.0, theta), [t_in], method="DOP853", rtol=1e-12, atol=1e-14)
    return float(sol.y[0, -1])


# (sag?, T_in [N], entry elevation [deg], bend angle [deg]), all inside the closed forms' validity range; they
# include sag bends with the cable on the upper wall (sigma = +1) and on the lower wall (0.1 N at -40 deg).
VERTICAL_CASES = [(True, 1.0, 0.0, 90.0), (True, 5.0, -40.0, 160.0), (True, 0.3, 40.0, 60.0), (True, 0.1, -40.0, 60.0),
                  (True, 2.0, 60.0, 30.0), (False, 1.0, 0.0, 90.0), (False, 5.0, -40.0, 30.0),
                  (False, 0.3, 40.0, 60.0), (False, 0.1, 60.0, 160.0), (False, 2.0, 60.0, 30.0)]


@pytest.mark.parametrize("sag, t_in, elevation_deg, angle_deg", VERTICAL_CASES)
def test_vertical_bends_against_direct_integration(sag, t_in, elevation_deg, angle_deg):
    fn = cf.sag_bend_out_N if sag else cf.hump_bend_out_N
    args = (t_in, 0.3, math.radians(angle_deg), W, 2.0, math.radians(elevation_deg))
    # rtol 1e-9: the integration runs at 1e-12; the closed form is exact.
    assert fn(*args) == pytest.approx(_integrate_vertical_bend(*args, sag=sag), rel=1e-9)


def test_validity_is_checked():
    theta = math.radians(60.0)
    # Sag: a light cable on the lower wall is lifted to the upper one as its tension grows.
    with pytest.raises(ValueError, match="normal force changes sign"):
        cf.sag_bend_out_N(0.3, 0.3, theta, W, 2.0)
    # Hump entered horizontally with no tension: the descent makes T negative (slack).
    with pytest.raises(ValueError, match="negative"):
        cf.hump_bend_out_N(0.0, 0.3, math.radians(90.0), W, 2.0)
    # Hump running past the vertical (entered at -40 deg, turning down 60 deg): weight pulls off the lower wall.
    with pytest.raises(ValueError, match="normal force changes sign"):
        cf.hump_bend_out_N(0.3, 0.3, theta, W, 2.0, math.radians(-40.0))
    with pytest.raises(ValueError):
        cf.sag_bend_out_N(1.0, 0.3, -0.1, W, 2.0)


# ---------------------------------------------------------------- reference/paper_values.toml
def _load():
    with open(REFERENCE, "rb") as fh:
        return tomllib.load(fh)


def _entries(data):
    for group, table in data.items():
        if isinstance(table, dict):
            for name, entry in table.items():
                yield f"{group}.{name}", entry


def _recompute(ref):
    """Every closed_form entry of the reference file, recomputed from the stored inputs with closed_forms."""
    v = {key: entry["value"] for key, entry in _entries(ref)}
    w = v["common.density_kg_per_m3"] * math.pi * v["common.cable_radius_m"] ** 2 * v["common.gravity_m_per_s2"]
    theta1 = math.radians(v["example1.inclination_deg"])
    beta3 = cf.helix_turning_angle_rad(v["example3.turns"], v["example3.coil_radius_m"], v["example3.pitch_m"])
    beta3_0 = cf.helix_turning_angle_rad(v["example3.turns"], v["example3.coil_radius_m"], 0.0)

    def fig12(pitch):
        return [cf.capstan_out_N(v["fig12.back_tension_N"], v["example3.friction"],
                                 cf.helix_turning_angle_rad(n, v["example3.coil_radius_m"], pitch))
                for n in v["fig12.coils"]]

    return {
        "common.weight_per_length_N_per_m": w,
        "example1.tension_slope_N_per_m": cf.incline_tension_N(1.0, w, v["example1.friction"], theta1),
        "example1.pull_force_N": cf.incline_tension_N(v["example1.cable_length_m"], w, v["example1.friction"], theta1),
        "example2.turning_angle_rad": math.pi / 2,
        "example2.pull_force_N": cf.capstan_out_N(v["example2.back_tension_N"], v["example2.friction"], math.pi / 2),
        "example3.turning_angle_rad": beta3,
        "example3.turning_angle_pitch0_rad": beta3_0,
        "example3.back_tension_N": cf.capstan_in_N(v["example3.pull_force_N"], v["example3.friction"], beta3),
        "example3.back_tension_pitch0_N": cf.capstan_in_N(v["example3.pull_force_N"], v["example3.friction"], beta3_0),
        "fig12.pull_force_N": fig12(v["example3.pitch_m"]),
        "fig12.pull_force_pitch0_N": fig12(0.0),
    }


def test_every_reference_entry_has_a_kind_and_a_source():
    entries = dict(_entries(_load()))
    assert len(entries) > 30
    for key, entry in entries.items():
        assert entry["kind"] in {"paper_input", "chosen", "closed_form", "reported"}, key
        assert len(entry["source"]) > 10, key
        assert "value" in entry, key


def test_reference_closed_form_values_recompute_within_their_rounding():
    ref = _load()
    recomputed = _recompute(ref)
    closed = {key: entry for key, entry in _entries(ref) if entry["kind"] == "closed_form"}
    # A stored closed-form value without a recomputation here would go unchecked.
    assert set(closed) == set(recomputed)
    for key, entry in closed.items():
        stored = np.atleast_1d(np.asarray(entry["value"], dtype=float))
        fresh = np.atleast_1d(np.asarray(recomputed[key], dtype=float))
        tol = entry.get("abs_tol", 0.0) + entry.get("rel_tol", 0.0) * np.abs(fresh)
        assert stored.shape == fresh.shape, key
        assert np.all(np.abs(stored - fresh) <= tol), f"{key}: stored {stored}, recomputed {fresh}"


def test_reference_matches_the_numbers_quoted_in_the_notes():
    # The brief and NOTES.md quote these; the file must carry the same numbers.
    v = {key: entry["value"] for key, entry in _entries(_load())}
    assert v["example1.pull_force_N"] == 7.3102
    assert v["example2.pull_force_N"] == 205.37
    assert v["example3.back_tension_pitch0_N"] == 11.384
    assert v["fig12.pull_force_pitch0_N"] == [18.74, 35.14, 65.86, 123.45, 231.41]
    assert [v[f"table1.cpu_time_{k}_min"] for k in ("with_aabb", "without_aabb", "recurdyn")] == [4.6, 63.2, 180.0]
    assert v["example3.relative_error_reported"] == 0.0039
