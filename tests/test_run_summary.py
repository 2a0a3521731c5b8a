"""The typed run summary (exucable.output.summary.RunSummary): one record whose fields are
summary.json's keys, written by the results writer and read by the Python API, and every key
named in docs/results-format.md."""

from __future__ import annotations

import dataclasses
import json
import re

import pytest

import exucable as xc
from exucable.output.summary import SUMMARY_KEYS, RunSummary

from conftest import ROOT, make_scenario


def _documented_names() -> set[str]:
    """Every backticked name of the `exucable run` section of docs/results-format.md."""
    doc = (ROOT / "docs" / "results-format.md").read_text(encoding="utf-8")
    section = doc[doc.index("## `exucable run SCENARIO --out DIR`"):doc.index("## `exucable export SCENARIO DIR`")]
    return set(re.findall(r"`([^`]+)`", section))


def test_every_summary_key_is_documented():
    assert sorted(set(SUMMARY_KEYS) - _documented_names()) == []


def test_keys_follow_the_kind_of_run():
    one = RunSummary(name="a", status="ok", mode_rule="given", pull_force_N=1.0)
    bundle = RunSummary(name="b", mode="steady", status="ok", bundle={"count": 2})
    # a single cable writes every one-cable key (unset ones as null) and no bundle report; the
    # optional keys only when set
    assert "bundle" not in one and one["mode_rule"] == "given" and one["rope_pull_force_N"] is None
    assert not {"start", "failed_at_s", "snapshots_s", "files", "pressure_window_m"} & set(one)
    assert "mode_rule" not in bundle and bundle["bundle"] == {"count": 2}
    # a steady bundle states its pull's uncertainty as one cable does (exucable.solve.error_bar.bundle_error_bar)
    assert set(bundle) == {"name", "mode", "status", "message", "flags", "pull_force_N", "trailing_tension_N",
                           "max_tension_N", "bundle", "steps", "newton_iterations", "wall_time_s", "build_time_s",
                           "mesh", "warnings", "scenario", "versions", "pull_force_uncertainty_N",
                           "pull_force_uncertainty_method", "pull_force_uncertainty"}
    assert list(one) == [k for k in SUMMARY_KEYS if k in one]          # written in the record's order
    assert one.get("failed_at_s", "absent") == "absent" and one["flags"] == []
    # a force-controlled steady solve states its trailing tension's uncertainty, null when it has none
    forced = RunSummary(trailing_tension_uncertainty_method="none possible")
    assert forced["trailing_tension_uncertainty_N"] is None and "trailing_tension_uncertainty_N" not in one
    with pytest.raises(dataclasses.FrozenInstanceError):
        one.status = "failed"                                           # noqa: the record is a value
    assert RunSummary.from_dict(json.loads(json.dumps(one.to_dict()))).to_dict() == one.to_dict()
    with pytest.raises(ValueError, match="pull_force"):
        RunSummary.from_dict({"pull_force": 1.0})


def test_written_and_exposed_alike(tmp_path):
    """A real (coarse) run: summary.json holds the record's keys and values; the API's Result reads
    them as typed attributes."""
    sc = make_scenario(pull={"speed": 0.1, "back_tension": 50.0}, solver={"mode": "steady"})
    res = xc.run(sc, out_dir=tmp_path)
    written = json.loads((tmp_path / "summary.json").read_text())
    assert isinstance(res.summary, RunSummary)
    assert list(written) == list(res.summary)
    assert written["files"] == res.summary.files and "history.csv" in written["files"]
    assert written["pull_force_N"] == res.summary.pull_force_N == res.pull_force_N
    assert res.status == res.summary.status == written["status"]
    assert res.summary.pull_force_uncertainty_N == written["pull_force_uncertainty_N"]
    assert res.summary.mode == "steady" and res.summary.scenario == written["scenario"]
