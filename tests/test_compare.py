"""`exucable compare` on synthetic CSVs: identical inputs, a known offset, interpolation, exit codes, errors."""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from exucable.commands.compare import add_arguments, main
from exucable.compare import compare_results
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
    assert c["max_abs_N"] == 0.0 and c["rms_abs_N"] == 0.0 and c["max_rel"] == 0.0 and result["passed"]
    assert run(a, a) == 0
    assert "tension_N" in capsys.readouterr().out


def test_known_offset_gives_known_numbers_and_exit_codes(tmp_path, s):
    a = profile(tmp_path / "a.csv", s, 10.0 * s / 10.0)  # max |A| = 10 N
    b = profile(tmp_path / "b.csv", s, 10.0 * s / 10.0 + 0.5)
    (c,) = compare_results(a, b)["comparisons"]
    assert c["max_abs_N"] == pytest.approx(0.5, abs=EXACT)
    assert c["rms_abs_N"] == pytest.approx(0.5, abs=EXACT)
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
    assert c["max_abs_N"] == pytest.approx(0.0, abs=1e-12)
    # Relative differences are scaled by max |A| over the overlap (23 N at s = 10).
    assert c["scale_N"] == pytest.approx(23.0, rel=EXACT)


def test_rms_of_a_sine_difference(tmp_path):
    # B - A = 0.1 sin(2 pi t) over whole periods: max 0.1 N, RMS 0.1/sqrt 2 N (to the sampling's rounding).
    t = np.linspace(0.0, 2.0, 2001)
    a = history(tmp_path / "a.csv", t, np.full_like(t, 20.0))
    b = history(tmp_path / "b.csv", t, 20.0 + 0.1 * np.sin(2 * np.pi * t))
    (c,) = compare_results(a, b)["comparisons"]
    assert c["column"] == "pull_force_N" and c["abscissa"] == "time_s"
    assert c["max_abs_N"] == pytest.approx(0.1, rel=1e-6)  # the sine's peaks are sample points
    assert c["rms_abs_N"] == pytest.approx(0.1 / np.sqrt(2.0), rel=1e-3)  # endpoint weighting of 2001 samples
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
    assert set(got) == {("profile", "tension_N"), ("history", "pull_force_N"), ("history", "trailing_tension_N")}
    assert got[("history", "pull_force_N")]["max_abs_N"] == pytest.approx(0.2, abs=EXACT)
    assert got[("profile", "tension_N")]["max_abs_N"] == 0.0
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
    ("x,y\n1,2\n2,3\n", "neither 's_m'"),
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
    with pytest.raises(ExucableError, match="neither tension_profile.csv nor history.csv"):
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
