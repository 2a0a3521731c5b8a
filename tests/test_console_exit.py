"""The ``exucable`` command ends ``run`` and ``plan`` with ``os._exit`` once everything is written
(exucable.cli.console_main; docs/decisions/0006-exit-without-finalising.md): the exit status, the
printed lines (stdout is a pipe here, so block-buffered: they must be flushed first) and every
output file must be what the same command gives when called in-process (``main``), where the
process is not ended. Coarse, fast cases only: each process is a few seconds of CPU."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

from exucable.cli import ENDS_WITH_OS_EXIT, main

ROOT = Path(__file__).resolve().parents[1]
EX2 = ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml"


def console(*args, cwd=None) -> subprocess.CompletedProcess:
    """``python -m exucable ARGS`` (the same console_main as the installed ``exucable`` script)."""
    return subprocess.run([sys.executable, "-m", "exucable", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd or ROOT, timeout=600)


def files(directory: Path) -> set[str]:
    return {p.relative_to(directory).as_posix() for p in directory.rglob("*") if p.is_file()}


def untimed(text: str) -> str:
    """``text`` with the wall times it prints masked (the two processes' differ)."""
    return re.sub(r"wall [0-9.]+ s", "wall - s", text)


def without_times(value):
    """A JSON value without its ``*_time_s`` entries (the two processes' differ)."""
    if isinstance(value, dict):
        return {k: without_times(v) for k, v in value.items() if not k.endswith("time_s")}
    if isinstance(value, list):
        return [without_times(v) for v in value]
    return value


def test_run_and_plan_are_the_commands_that_end_so():
    assert ENDS_WITH_OS_EXIT == {"run", "plan"}


def test_a_steady_run_ends_with_its_status_its_printout_and_every_file(tmp_path, capsys):
    """Figures on: the helper process that draws them is joined before the process ends, so the
    PNGs are complete; the data files are the in-process run's, the history bit for bit."""
    ended, inside = tmp_path / "ended", tmp_path / "inside"
    done = console("run", EX2, "--mode", "steady", "--out", ended, "-q")
    assert done.returncode == 0, done.stderr[-2000:]
    assert main(["run", str(EX2), "--mode", "steady", "--out", str(inside), "-q", "--no-plots"]) == 0
    printed = capsys.readouterr().out
    assert untimed(done.stdout) == untimed(printed.replace(str(inside), str(ended)))
    pngs = {"pull_force.png", "tension_profile.png", "pressure.png"}
    assert files(ended) == files(inside) | pngs
    for name in pngs:
        assert (ended / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and (ended / name).stat().st_size > 10_000
    assert (ended / "history.csv").read_bytes() == (inside / "history.csv").read_bytes()
    a, b = (json.loads((d / "summary.json").read_text()) for d in (ended, inside))
    assert a["pull_force_N"] == b["pull_force_N"] and a["status"] == b["status"] == "ok"
    assert not list(ended.glob(".*.tmp"))          # no temporary file left by the atomic writes


def test_an_untrusted_run_and_bad_input_keep_their_exit_status(tmp_path):
    """A result that must not be trusted exits 1 with its reason on stderr and its files written;
    a bad scenario exits 2 with one line naming the key (the parser's error: the process ends
    there too)."""
    text = re.sub(r"(?m)^end_time = .*$", "end_time = 0.001", EX2.read_text())
    text = re.sub(r"(?m)^step = .*$", "step = 1.0e-3", text)
    short = tmp_path / "short.toml"
    short.write_text(text)
    # an atexit handler shows that the interpreter's exit is skipped (and with it the finalisation)
    code = ("import atexit, sys\nfrom exucable.cli import console_main\n"
            "atexit.register(lambda: print('interpreter exit ran'))\n"
            f"sys.argv = ['exucable', 'run', {str(short)!r}, '--out', {str(tmp_path / 'short')!r}, '-q', '--no-plots']\n"
            "console_main()\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert done.returncode == 1, done.stderr[-2000:]
    assert "NOT TRUSTED" in done.stderr and "status" in done.stdout
    assert "interpreter exit ran" not in done.stdout
    assert json.loads((tmp_path / "short" / "summary.json").read_text())["status"] == "not_steady"
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("friction = ", "friction = -", 1))
    done = console("run", bad, "--out", tmp_path / "bad", "-q", "--no-plots")
    assert done.returncode == 2
    assert done.stderr.startswith("exucable run: error: contact.friction") and len(done.stderr.splitlines()) == 1


def test_a_plan_ends_with_its_report_and_tables(tmp_path, capsys):
    """The rope engine (instant): the exit status, the printout and every file as in-process."""
    scenario = ROOT / "scenarios" / "industry" / "commscope_conquest_500ft_bend90.toml"
    ended, inside = tmp_path / "ended", tmp_path / "inside"
    done = console("plan", scenario, "--engine", "rope", "--out", ended)
    code = main(["plan", str(scenario), "--engine", "rope", "--out", str(inside)])
    printed = capsys.readouterr().out
    assert done.returncode == code, done.stderr[-2000:]
    assert untimed(done.stdout) == untimed(printed.replace(str(inside), str(ended)))
    assert files(ended) == files(inside) and "report.html" in files(ended)
    a, b = (without_times(json.loads((d / "plan.json").read_text().replace(str(d), "OUT"))) for d in (ended, inside))
    assert a == b
