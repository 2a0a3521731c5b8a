"""`exucable compare` on synthetic CSVs: identical inputs, a known offset, interpolation, exit codes, errors."""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from exucable.commands.compare import add_arguments, main
from exucable.output.compare import compare_results, load_tolerances
from exucable.errors import ExucableError

# Differences of exactly representable synthetic data are computed to rounding: 1e-12 relative/absolute.
EXACT = 1e-12


def write_csv(path: Path, header: str, columns) -> Path:
    data = np.column_stack(columns)
    np.savetxt(path, data, delimiter=",", header=header, comments="", fmt="%.17g")
    return path


def profile(path: Path, s, tension) -> Path:
    return write_csv(path, "s_m,tension_N", [s, tension])


def history(path: Path, t, pull, trailing=None, maximum=None) -> Path:
    cols, names = [t, pull], ["time_s", "pull_force_N"]
    for name, col in (("trailing_tension_N", trailing), ("max_tension_N", maximum)):
        if col is not None:
            cols.append(col)
            names.append(name)
    return write_csv(path, ",".join(names), cols)


def run(*argv) -> int:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return main(parser.parse_args([str(a) for a in argv]))


@pytest.fixture
def s():
    return np.linspace(0.0, 10.0, 101)


def test_identical_profiles_give_zero(tmp_path, s, capsys):
    a = profile(tmp_path / "a.csv", s, 1.0 + s**2)
    result = compare_results(a, a)
    (c,) = result["comparisons"]
    assert c["max_abs"] == 0.0 and c["rms_abs"] == 0.0 and c["max_rel"] == 0.0 and result["passed"]
    assert run(a, a) == 0
    assert "tension_N" in capsys.readouterr().out


def test_known_offset_gives_known_numbers_and_exit_codes(tmp_path, s):
    a = profile(tmp_path / "a.csv", s, 10.0 * s / 10.0)  # max |A| = 10 N
    b = profile(tmp_path / "b.csv", s, 10.0 * s / 10.0 + 0.5)
    (c,) = compare_results(a, b)["comparisons"]
    assert c["max_abs"] == pytest.approx(0.5, abs=EXACT)
    assert c["rms_abs"] == pytest.approx(0.5, abs=EXACT)
    assert c["max_rel"] == pytest.approx(0.05, abs=EXACT)
    assert c["rms_rel"] == pytest.approx(0.05, abs=EXACT)
    assert run(a, b) == 1  # 5 % > default 1 %
    assert run(a, b, "--rtol", "0.06") == 0


def test_b_is_interpolated_onto_a_over_the_overlap(tmp_path, s):
    # B on a finer, shifted grid of the same linear function (linear interpolation is exact for it), covering
    # only s in [2, 20]: the comparison range is [2, 10] and the differences vanish.
    a = profile(tmp_path / "a.csv", s, 3.0 + 2.0 * s)
    sb = np.linspace(2.0, 20.0, 377)
    b = profile(tmp_path / "b.csv", sb, 3.0 + 2.0 * sb)
    (c,) = compare_results(a, b)["comparisons"]
    assert c["range"] == (2.0, 10.0)
    assert c["n_points"] == 81
    assert c["max_abs"] == pytest.approx(0.0, abs=1e-12)
    # Relative differences are scaled by max |A| over the overlap (23 N at s = 10).
    assert c["scale"] == pytest.approx(23.0, rel=EXACT)


def test_rms_of_a_sine_difference(tmp_path):
    # B - A = 0.1 sin(2 pi t) over whole periods: max 0.1 N, RMS 0.1/sqrt 2 N (to the sampling's rounding).
    t = np.linspace(0.0, 2.0, 2001)
    a = history(tmp_path / "a.csv", t, np.full_like(t, 20.0))
    b = history(tmp_path / "b.csv", t, 20.0 + 0.1 * np.sin(2 * np.pi * t))
    (c,) = compare_results(a, b)["comparisons"]
    assert c["column"] == "pull_force_N" and c["abscissa"] == "time_s"
    assert c["max_abs"] == pytest.approx(0.1, rel=1e-6)  # the sine's peaks are sample points
    assert c["rms_abs"] == pytest.approx(0.1 / np.sqrt(2.0), rel=1e-3)  # endpoint weighting of 2001 samples
    assert c["max_rel"] == pytest.approx(0.1 / 20.0, rel=1e-6)


def test_result_directories_compare_every_common_column(tmp_path, s):
    t = np.linspace(0.0, 1.0, 11)
    for name, offset in (("run_a", 0.0), ("run_b", 0.2)):
        d = tmp_path / name
        d.mkdir()
        profile(d / "tension_profile.csv", s, 5.0 + s)
        history(d / "history.csv", t, 20.0 + offset + t, trailing=np.full_like(t, 5.0),
                maximum=20.0 + t if name == "run_a" else None)
    result = compare_results(tmp_path / "run_a", tmp_path / "run_b")
    got = {(c["kind"], c["column"]): c for c in result["comparisons"]}
    assert set(got) == {("tension_profile", "tension_N"), ("history", "pull_force_N"), ("history", "trailing_tension_N")}
    assert got[("history", "pull_force_N")]["max_abs"] == pytest.approx(0.2, abs=EXACT)
    assert got[("tension_profile", "tension_N")]["max_abs"] == 0.0
    assert result["skipped"] == [("history", "max_tension_N", "only in A")]
    # A directory against a single CSV compares what they share.
    single = compare_results(tmp_path / "run_a", tmp_path / "run_b" / "tension_profile.csv")
    assert [c["column"] for c in single["comparisons"]] == ["tension_N"]


def test_overlay_plot_is_written_atomically(tmp_path, s, capsys):
    a = profile(tmp_path / "a.csv", s, 1.0 + s)
    b = profile(tmp_path / "b.csv", s, 1.0 + 1.001 * s)
    out = tmp_path / "plots" / "overlay.png"
    assert run(a, b, "--out", out) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in out.parent.iterdir()] == ["overlay.png"]  # no temporary file left behind
    assert "overlay plot" in capsys.readouterr().out


@pytest.mark.parametrize("content, message", [
    ("x,y\n1,2\n2,3\n", "no known abscissa"),
    ("s_m,force\n1,2\n2,3\n", "missing its value column"),
    ("time_s,speed\n1,2\n2,3\n", "missing its value column"),
    ("s_m,tension_N\n0,1\n1,abc\n", "not a number"),
    ("s_m,tension_N\n0,1\n", "at least two data rows"),
    ("", "empty file"),
])
def test_malformed_files_raise_clear_errors(tmp_path, s, content, message):
    bad = tmp_path / "bad.csv"
    bad.write_text(content)
    good = profile(tmp_path / "good.csv", s, s)
    with pytest.raises(ExucableError, match=message):
        compare_results(good, bad)


def test_missing_inputs_and_mismatches_raise_clear_errors(tmp_path, s):
    a = profile(tmp_path / "a.csv", s, s)
    with pytest.raises(ExucableError, match="no such file"):
        compare_results(a, tmp_path / "absent.csv")
    (tmp_path / "empty_dir").mkdir()
    with pytest.raises(ExucableError, match="result directory has none of"):
        compare_results(a, tmp_path / "empty_dir")
    h = history(tmp_path / "h.csv", s, s)
    with pytest.raises(ExucableError, match="nothing to compare"):
        compare_results(a, h)
    far = profile(tmp_path / "far.csv", s + 100.0, s)
    with pytest.raises(ExucableError, match="do not overlap"):
        compare_results(a, far)
    with pytest.raises(ExucableError, match="rtol"):
        run(a, a, "--rtol", "-1")


def test_module_entry_point_reports_errors_without_traceback(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "exucable", "compare", str(tmp_path / "nope.csv"),
                           str(tmp_path / "nope.csv")], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert "no such file" in proc.stderr and "Traceback" not in proc.stderr


def snapshot_tension(path: Path, times, x, f) -> Path:
    rows = [(t, e, 0.0, xx, f(t, xx)) for t in times for e, xx in enumerate(x)]
    return write_csv(path, "time_s,element,xi,x_m,tension_N", np.array(rows).T)


def test_snapshots_are_compared_time_by_time(tmp_path, s, capsys):
    for name in ("a", "b"):
        (tmp_path / name).mkdir()
    a = snapshot_tension(tmp_path / "a" / "snapshot_tension.csv", [0.1, 0.2, 0.3], s, lambda t, x: 100.0 + t * x)
    # B on every other station (linear in x: interpolation is exact), 0.5 N off at t = 0.2 s, no t = 0.3 s
    b = snapshot_tension(tmp_path / "b" / "snapshot_tension.csv", [0.1, 0.2], s[::2],
                         lambda t, x: 100.0 + t * x + (0.5 if t == 0.2 else 0.0))
    result = compare_results(a.parent, b.parent)
    (c,) = result["comparisons"]
    assert (c["kind"], c["abscissa"], c["times"]) == ("snapshot_tension", "x_m", [0.1, 0.2])
    assert c["max_abs"] == pytest.approx(0.5, abs=EXACT) and c["worst_at"][1] == 0.2
    assert c["scale"] == pytest.approx(102.0, rel=EXACT)      # max |A| over the times compared
    assert result["skipped"] == [("snapshot_tension", "*", "snapshot t = 0.3 s only in A")]
    # B lacks A's t = 0.3 s: within tolerances on the overlap, but it does not cover A
    assert not result["covered"] and not result["passed"]
    assert run(a.parent, b.parent, "--atol", "0.4", "--rtol", "0") == 1
    assert run(a.parent, b.parent, "--atol", "0.6", "--rtol", "0") == 1
    assert run(a.parent, b.parent, "--atol", "0.6", "--rtol", "0", "--allow-partial", "--out", tmp_path / "figs") == 0
    assert [p.name for p in (tmp_path / "figs").iterdir()] == ["compare_snapshot_tension_tension_N.png"]


def test_per_quantity_tolerances_from_toml(tmp_path, capsys):
    t = np.linspace(0.0, 1.0, 11)
    a = history(tmp_path / "a.csv", t, 100.0 + t, trailing=np.full_like(t, 50.0))
    b = history(tmp_path / "b.csv", t, 101.0 + t, trailing=np.full_like(t, 50.2))
    tol = tmp_path / "tol.toml"
    tol.write_text("[default]\nrtol = 0.0\natol = 0.25\n\n[pull_force_N]\nrtol = 0.02\n")
    result = compare_results(a, b, tolerances=load_tolerances(tol))
    got = {c["column"]: c for c in result["comparisons"]}
    assert (got["pull_force_N"]["rtol"], got["pull_force_N"]["atol"]) == (0.02, 0.25)
    assert got["pull_force_N"]["passed"] and got["trailing_tension_N"]["passed"]
    tol.write_text("[history.trailing_tension_N]\natol = 0.1\nrtol = 0.0\n")
    assert run(a, b, "--tolerances", tol, "--rtol", "0.02") == 1
    assert "BEYOND" in capsys.readouterr().out
    tol.write_text("[pull_force_N]\nrtol = -1\n")
    with pytest.raises(ExucableError, match="pull_force_N.rtol: must be a finite number >= 0"):
        load_tolerances(tol)


def test_old_column_names_are_read_with_a_note_and_new_ones_directly(tmp_path, s, capsys):
    old = profile(tmp_path / "tension_profile.csv", s, 1.0 + s)
    new = write_csv(tmp_path / "new.csv", "x_m,tension_N", [s, 1.0 + s])
    result = compare_results(new, old)
    assert result["passed"] and result["comparisons"][0]["kind"] == "tension_profile"
    assert result["notes"] == ["tension_profile.csv: read old column 's_m' as 'x_m' (old names are read for one release)"]
    contact_old = write_csv(tmp_path / "c_old.csv", "s_m,normal_force_per_length_N_per_m", [s, s])
    contact_new = write_csv(tmp_path / "c_new.csv", "s_conduit_m,normal_force_per_length_N_per_m", [s, s])
    assert compare_results(contact_new, contact_old)["comparisons"][0]["kind"] == "contact_profile"


def _state_result_dir(path: Path, mode: str, history_rows: int, times) -> Path:
    """A minimal result directory: summary.json with its mode, history.csv, snapshot_tension.csv
    with the profile 100 + x at each snapshot time."""
    path.mkdir()
    (path / "summary.json").write_text('{"mode": "%s"}' % mode)
    t = np.arange(1.0, history_rows + 1.0)
    history(path / "history.csv", t, 100.0 + t)
    x = np.linspace(0.0, 2.0, 9)
    rows = [np.column_stack([np.full_like(x, ti), np.arange(x.size), x, 100.0 + x]) for ti in times]
    np.savetxt(path / "snapshot_tension.csv", np.vstack(rows), delimiter=",",
               header="time_s,element,x_m,tension_N", comments="", fmt="%.17g")
    return path


def test_a_steady_result_is_compared_by_state_not_by_pseudo_time(tmp_path):
    """A steady result's one-row pseudo-time history is neither read nor compared; its state (t = 0)
    is compared with a dynamic run's last snapshot, and the note says which times."""
    steady = _state_result_dir(tmp_path / "steady", "steady", 1, [0.0])
    dynamic = _state_result_dir(tmp_path / "dynamic", "dynamic", 5, [0.1, 0.3])
    result = compare_results(steady, dynamic)
    (c,) = result["comparisons"]
    assert c["kind"] == "snapshot_tension" and c["times"] == [0.0] and c["times_b"] == [0.3]
    assert c["max_abs"] == 0.0 and result["passed"]
    assert any(k == "history" and "pseudo-time" in why for k, _, why in result["skipped"])
    assert any("latest state" in n for n in result["notes"])
    # two dynamic runs still align on their times, and a one-row history there is an error
    with pytest.raises(ExucableError, match="at least two data rows"):
        compare_results(_state_result_dir(tmp_path / "short", "dynamic", 1, [0.3]), dynamic)


def _result_dir(path: Path, t, s) -> Path:
    path.mkdir()
    history(path / "history.csv", t, 20.0 + t, trailing=np.full_like(t, 5.0), maximum=21.0 + t)
    profile(path / "tension_profile.csv", s, 5.0 + s)
    write_csv(path / "rope_profile.csv", "s_conduit_m,tension_N,sidewall_pressure_N_per_m", [s, 5.0 + s, 0 * s])
    return path


def test_b_holding_a_few_of_as_rows_and_none_of_its_profiles_does_not_agree(tmp_path, s, capsys):
    """B = A's first 3 of 42 history rows, no profile files: the overlap agrees exactly, yet B does
    not cover A, so compare fails (exit 1) and says what is missing: rows, range, files."""
    t = np.linspace(0.0, 0.41, 42)
    a = _result_dir(tmp_path / "a", t, s)
    b = tmp_path / "b"
    b.mkdir()
    history(b / "history.csv", t[:3], 20.0 + t[:3], trailing=np.full(3, 5.0), maximum=21.0 + t[:3])
    result = compare_results(a, b)
    assert all(c["max_abs"] == 0.0 for c in result["comparisons"])
    assert not result["covered"] and not result["passed"]
    cov = {c["file"]: c for c in result["coverage"]}
    assert (cov["history.csv"]["rows_a"], cov["history.csv"]["rows_b"]) == (42, 3)
    assert cov["history.csv"]["range_b"] == (0.0, pytest.approx(0.02))
    assert cov["tension_profile.csv"]["missing"] == ["tension_profile.csv not in B"]
    assert cov["rope_profile.csv"]["missing"] == ["rope_profile.csv not in B"]
    assert run(a, b) == 1
    text = capsys.readouterr().out
    assert "INCOMPLETE: B does not cover A" in text and "agree within tolerances" not in text
    assert "rows A     42, B      3" in text
    assert run(a, b, "--allow-partial") == 0
    assert "--allow-partial: B does not cover A" in capsys.readouterr().out


def test_b_covering_a_on_its_own_grid_agrees(tmp_path, s):
    """Another solver's output times need not be A's: B on a finer grid ending within one of A's
    steps of A's end covers A; a single CSV B answers only for its own family."""
    t = np.linspace(0.0, 0.41, 42)
    a = _result_dir(tmp_path / "a", t, s)
    b = _result_dir(tmp_path / "b", np.linspace(0.0, 0.405, 82), s)
    result = compare_results(a, b)
    assert result["covered"] and result["passed"]
    one = compare_results(a, b / "history.csv")
    assert one["covered"] and one["passed"]
    assert {c["file"]: c["checked"] for c in one["coverage"]}["tension_profile.csv"] is False


def test_a_byte_order_mark_is_read_and_a_binary_file_refused_in_one_line(tmp_path, s, capsys):
    a = profile(tmp_path / "a.csv", s, 1.0 + s)
    bom = tmp_path / "bom.csv"
    bom.write_bytes(b"\xef\xbb\xbf" + a.read_bytes())
    assert compare_results(a, bom)["passed"]
    tol = tmp_path / "tol.toml"
    tol.write_bytes(b"\xef\xbb\xbf[default]\nrtol = 0.5\n")
    assert load_tolerances(tol) == {"default": {"rtol": 0.5}}
    binary = tmp_path / "history.csv"
    binary.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(ExucableError, match="not a text CSV file"):
        compare_results(a, binary)
    nul = tmp_path / "nul.csv"
    nul.write_bytes(b"x_m,tension_N\n0,\x001\n1,2\n")
    with pytest.raises(ExucableError, match="not a text CSV file|not a number"):
        compare_results(a, nul)
    res = subprocess.run([sys.executable, "-m", "exucable", "compare", str(a), str(binary)],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1 and "Traceback" not in res.stderr
