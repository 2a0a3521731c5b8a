"""`exucable validate --fast`: the paper's examples on coarse meshes, against reference/.

Runs the fast scenario variants (a few minutes in all) with the fast tolerances of
exucable.validation.paper.TOLERANCES, which the coarse meshes hold; the paper-fidelity set is behind the
``slow`` marker.
"""

from __future__ import annotations

import csv

import pytest

from exucable.validation.paper import TOLERANCES, format_table, validate


@pytest.fixture(scope="module")
def fast_validation(tmp_path_factory):
    out = tmp_path_factory.mktemp("validation")
    return validate(fast=True, out_dir=out, quiet=True), out


def test_fast_validation_passes_every_check(fast_validation):
    vr, out = fast_validation
    assert not vr.failures, vr.failures
    failed = [c for c in vr.checks if not c.passed]
    assert not failed, format_table(vr)
    cases = {c.case for c in vr.checks}
    assert cases == {"Ex. 1", "Ex. 2", "Ex. 3", "Fig. 12", "Ex. 4"}
    for mode in ("dynamic", "steady"):       # every case in both solver modes
        assert sum(c.case == "Fig. 12" and c.mode == mode for c in vr.checks) == 3
    # and their difference, one row per check. Every velocity-controlled pull is compared in the
    # same state (the steady cable laid out as far as the dynamic run had pulled it): there the
    # issue's bound, 0.2 %, holds even on the coarse meshes (measured 2026-11-29: at most 0.07 %).
    # Example 3's force-controlled pull has no such extent (its own lead-out): within 1 %.
    diffs = vr.differences
    assert len(diffs) == len(vr.checks) // 2
    assert {d.case for d in diffs if d.same_state} == {"Ex. 1", "Ex. 2", "Fig. 12", "Ex. 4"}
    assert all(d.agrees for d in diffs if d.same_state), format_table(vr)
    assert all(abs(d.rel_difference) < 1e-2 for d in diffs), format_table(vr)


def test_validation_writes_table_and_figures(fast_validation):
    vr, out = fast_validation
    with open(out / "validation.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(vr.checks)
    assert all(float(r["tolerance"]) in {t for pair in TOLERANCES.values() for t in pair} for r in rows)
    md = (out / "validation.md").read_text()
    assert "| case |" in md and "PASS" in md
    for name in ("fig07_ex1_tension_along_incline.png", "fig09_ex2_end_tensions.png",
                 "fig11_ex3_end_tensions.png", "fig12_coils.png", "fig14_ex4_pull_force.png"):
        assert (out / name).stat().st_size > 5000, name


@pytest.mark.slow
def test_paper_fidelity_validation(tmp_path):
    """The issue's accuracy targets at the paper's fidelity (minutes to hours: see issue 7)."""
    vr = validate(fast=False, out_dir=tmp_path, quiet=True, modes=("dynamic",))
    assert not vr.failures and all(c.passed for c in vr.checks), format_table(vr)


@pytest.mark.slow
def test_paper_fidelity_validation_steady(tmp_path):
    """The steady mode at the paper's fidelity (about 2.5 min on a loaded machine, 2026-11-29)."""
    vr = validate(fast=False, out_dir=tmp_path, quiet=True, modes=("steady",))
    assert not vr.failures and all(c.passed for c in vr.checks), format_table(vr)
