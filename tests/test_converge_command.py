"""``exucable converge`` end to end on the sweep tests' tiny bend (three coarse levels, seconds)."""

from __future__ import annotations

import json

from exucable.cli import main as cli_main
from exucable.output.results import read_csv

from conftest import ROOT


def test_converge_writes_the_table_and_an_extrapolation(tmp_path, capsys):
    f = ROOT / "tests" / "data" / "sweep" / "tiny_bend.toml"     # 8 elements × 8 check points
    rc = cli_main(["converge", str(f), "--levels", "3", "--out", str(tmp_path / "out"), "--quiet"])
    out = capsys.readouterr().out
    rep = json.loads((tmp_path / "out" / "converge.json").read_text())
    assert [r["elements"] for r in rep["levels"]] == [8, 16, 32]
    assert all(r["check_points_per_element"] == 8 for r in rep["levels"])   # spacing refined with h
    table = read_csv(tmp_path / "out" / "converge.csv")
    assert list(table["elements"]) == [8, 16, 32]
    assert rep["error_N"] > 0 and rep["method"]
    # the capstan 20·e^(0.2·π/2) = 27.39 N: the extrapolation lands near it
    assert abs(rep["extrapolated_N"] / 27.3906 - 1) < 0.01
    assert "extrapolated:" in out and (tmp_path / "out" / "level_2" / "summary.json").exists()
    assert rc == (0 if rep["trusted"] else 1)


def test_a_failed_level_is_not_extrapolated(tmp_path, monkeypatch):
    """A level whose steady solve fails reports its last iterate's force; that value must not enter
    the extrapolation (it did: Gera's route 8x refined, a stalled solve's force, read as converged).
    The finest level is made to fail for real: its stop residual asked below round-off."""
    from exucable.commands import converge as conv

    real = conv.run_scenario

    def finest_fails(sc, out_dir, **kw):
        if str(out_dir).endswith("level_3"):
            sc = sc.replace(**{"solver.steady_residual": 1e-15})
        return real(sc, out_dir, **kw)

    monkeypatch.setattr(conv, "run_scenario", finest_fails)
    f = ROOT / "tests" / "data" / "sweep" / "tiny_bend.toml"
    rep = conv.converge(f, tmp_path / "out", levels=4, mode="steady")
    assert rep["levels"][3]["status"] == "failed"
    assert rep["levels_used"] == [0, 1, 2] and not rep["trusted"]
    assert "level 3" in rep["method"] and "failed" in rep["method"]
    # the extrapolation is the one of the three trusted levels alone
    alone = conv.extrapolate([r["value_N"] for r in rep["levels"][:3]], 2.0,
                             [r["uncertainty_N"] for r in rep["levels"][:3]])
    assert rep["extrapolated_N"] == alone.value
