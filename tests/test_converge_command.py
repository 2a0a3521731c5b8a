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
