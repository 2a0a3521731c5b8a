"""Runners injected into ``exucable sweep`` by tests/test_sweep.py (``--runner`` / ``runner=``).

They must be importable by the worker processes: the tests put this directory on PYTHONPATH.
"""

import json
import math
import os
import signal
import time
from pathlib import Path

from exucable.run import run_scenario
from exucable.sweep import scenario_hash


def counting_runner(scenario, out_dir, quiet=True, plots=True):
    """The real run, after appending the case's hash to $EXUCABLE_TEST_RUN_LOG (a run counter)."""
    log = os.environ.get("EXUCABLE_TEST_RUN_LOG")
    if log:
        with open(log, "a") as f:  # one short O_APPEND write per line: safe across processes
            f.write(scenario_hash(scenario) + "\n")
    return run_scenario(scenario, out_dir, quiet=quiet, plots=plots)


def dying_runner(scenario, out_dir, quiet=True, plots=True):
    """A stand-in: the capstan force for friction mu; the process kills itself (SIGKILL) for
    mu = 0.3 always, and for mu = 0.2 only the first time (a marker file in the sweep directory,
    DIR, two levels above the case's DIR/cases/.<hash>.tmp-<pid>; not an environment variable:
    forkserver children inherit the server's environment, fixed when it started)."""
    mu = scenario.contact.friction
    markers = Path(out_dir).resolve().parent.parent
    time.sleep(0.2)
    if mu == 0.3:
        os.kill(os.getpid(), signal.SIGKILL)
    if mu == 0.2:
        marker = markers / "died-once"
        if not marker.exists():
            marker.write_text("x")
            os.kill(os.getpid(), signal.SIGKILL)
    T2 = scenario.pull.back_tension_N
    summary = {"status": "ok", "message": "", "pull_force_N": T2 * math.exp(mu * math.pi / 2)}
    Path(out_dir, "summary.json").write_text(json.dumps(summary))
    return summary


def quick_runner(scenario, out_dir, quiet=True, plots=True):
    """A stand-in: the capstan force for friction mu, written as summary.json and a one-row
    history.csv (the files a finished case is verified by)."""
    T2 = scenario.pull.back_tension_N
    summary = {"status": "ok", "message": "", "pull_force_N": T2 * math.exp(scenario.contact.friction * math.pi / 2)}
    Path(out_dir, "history.csv").write_text(f"time_s,pull_force_N\n0.0,{summary['pull_force_N']!r}\n")
    Path(out_dir, "summary.json").write_text(json.dumps(summary))
    return summary


def sleeping_runner(scenario, out_dir, quiet=True, plots=True):
    """A stand-in that computes for a minute (a case the tests kill its sweep under)."""
    time.sleep(60)
    return quick_runner(scenario, out_dir, quiet, plots)
