"""``exucable converge`` end to end on a tiny bend (three coarse levels, a few seconds)."""

from __future__ import annotations

import json

from exucable.cli import main as cli_main
from exucable.results import read_csv

TOML = """
name = "tiny-converge"
[cable]
radius = 0.0025
density = 1000.0
youngs_modulus = 1.0e9
elements = 8
[conduit]
inner_radius = 0.0035
segments_per_bend = 16
path = [ { straight = 0.5 }, { bend = 90.0, radius = 0.5, turn = "left" }, { straight = 0.5 } ]
[contact]
friction = 0.2
check_points_per_element = 6
[pull]
speed = 0.1
back_tension = 20.0
[solver]
end_time = 0.3
step = 0.01
steady_stop = true
steady_window = 0.1
steady_tolerance = 5.0e-3
"""


def test_converge_writes_the_table_and_an_extrapolation(tmp_path, capsys):
    f = tmp_path / "tiny.toml"
    f.write_text(TOML)
    rc = cli_main(["converge", str(f), "--levels", "3", "--out", str(tmp_path / "out"), "--quiet"])
    out = capsys.readouterr().out
    rep = json.loads((tmp_path / "out" / "converge.json").read_text())
    assert [r["elements"] for r in rep["levels"]] == [8, 16, 32]
    assert all(r["check_points_per_element"] == 6 for r in rep["levels"])   # spacing refined with h
    table = read_csv(tmp_path / "out" / "converge.csv")
    assert list(table["elements"]) == [8, 16, 32]
    assert rep["error_N"] > 0 and rep["method"]
    # the capstan 20·e^(0.2·π/2) = 27.39 N: the extrapolation lands near it
    assert abs(rep["extrapolated_N"] / 27.3906 - 1) < 0.01
    assert "extrapolated:" in out and (tmp_path / "out" / "level_2" / "summary.json").exists()
    assert rc == (0 if rep["trusted"] else 1)
