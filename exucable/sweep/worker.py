"""Running one case, in a worker process (local pool) or a Dask worker.

A *task* is a plain dict (JSON-able apart from nothing): the case's hash, index, varied
parameters, full scenario dict (``Scenario.to_dict()``) and where to put the result. The worker
re-validates the scenario from that dict, so nothing but plain data crosses process boundaries.

- :func:`run_case` (local pool): runs into ``DIR/cases/.<hash>.tmp-<pid>`` and installs the
  directory itself with one rename, so a finished case survives whatever happens to the parent.
- :func:`run_case_packed` (Dask): runs into a temporary directory on the worker's machine and
  returns the files' bytes; the client installs them (no shared file system needed).

A *runner* is a callable with :func:`exucable.run.run_scenario`'s signature
``runner(scenario, out_dir, quiet=True, plots=True)`` returning an object with a ``summary``
dict (or the dict itself). It is the injection point for tests and alternative solvers; the
default runs the Exudyn model.
"""

from __future__ import annotations

import datetime
import os
import shutil
import socket
import tempfile
import threading
import time
import traceback
from pathlib import Path

from ..version import __version__
from ..io import atomic_write_bytes, atomic_write_text
from ..scenario.specs import parse_scenario
from .store import CASE_JSON, RECORD_OUTPUTS, install_case, is_finished, read_verified_record, temp_dir, write_record

__all__ = ["default_runner", "execute_case", "run_case", "run_case_packed", "install_packed",
           "record_failure"]

# One case at a time per process: a Dask worker may run several tasks in threads, and Exudyn's
# solver and the user-function callbacks are not meant to share a process concurrently.
_PROCESS_LOCK = threading.Lock()


def default_runner(scenario, out_dir, quiet: bool = True, plots: bool = True):
    """:func:`exucable.run.run_scenario` (imported in the worker, not at module import)."""
    from ..run import run_scenario
    return run_scenario(scenario, out_dir, quiet=quiet, plots=plots)


def _base_record(task: dict) -> dict:
    return {
        "case": task["case"],
        "index": task.get("index"),
        "sweep": task.get("sweep"),
        "params": task.get("params", {}),
        "status": "failed",
        "message": "",
    }


def _stamp(record: dict, task: dict) -> dict:
    record.update(
        scenario=task["scenario"],
        host=socket.gethostname(),
        pid=os.getpid(),
        finished_at=datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        exucable=__version__,
    )
    return record


def execute_case(task: dict, workdir, runner=None) -> dict:
    """Run one case into ``workdir`` (created if needed) and write its ``case.json``.

    Never raises for a failing case: an exception from validation, model building or the runner
    is recorded as ``status = "failed"`` with ``"<Type>: <message>"`` (traceback in ``error.txt``).

    Returns
    -------
    dict
        The record written to ``case.json``: ``case``, ``index``, ``params``, ``status``,
        ``message``, the outputs of :data:`~exucable.sweep.store.RECORD_OUTPUTS`, ``wall_time_s``
        (the whole case, [s]), ``cpu_time_s`` (this process's CPU time over the case, user + system
        [s]), ``solver_wall_time_s`` [s], the scenario and where it ran.
    """
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    record = _base_record(task)
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        with _PROCESS_LOCK:
            data = task.get("portable_scenario") or task["scenario"]
            scenario = parse_scenario(data, Path(task["base_dir"]), default_name=str(data.get("name", "case")))
            result = (runner or default_runner)(scenario, workdir, quiet=True, plots=task.get("plots", True))
        summary = result if isinstance(result, dict) else result.summary
        record["status"] = str(summary.get("status", "failed"))
        record["message"] = str(summary.get("message") or "")
        for k in RECORD_OUTPUTS:
            record[k] = summary.get(k)
        record["solver_wall_time_s"] = summary.get("wall_time_s")
    except Exception as exc:  # recorded, never propagated: one case must not stop the sweep
        record["status"] = "failed"
        record["message"] = f"{type(exc).__name__}: {exc}"
        atomic_write_text(workdir / "error.txt", traceback.format_exc())
    record["wall_time_s"] = time.perf_counter() - t0
    record["cpu_time_s"] = time.process_time() - c0
    # what the case finished with, so a later run can tell a damaged case from a finished one
    record["files"] = {p.relative_to(workdir).as_posix(): p.stat().st_size for p in sorted(workdir.rglob("*"))
                       if p.is_file() and p.name != CASE_JSON and not p.name.startswith(".")}
    write_record(workdir, _stamp(record, task))
    return record


def run_case(task: dict, runner=None) -> dict:
    """Local-pool entry: run a case and install ``DIR/cases/<hash>/`` atomically.

    A case already finished on disk is returned as it is (never run twice).
    """
    cases_dir = Path(task["cases_dir"])
    final = cases_dir / task["case"]
    existing = read_verified_record(final)
    if is_finished(existing):
        return existing
    tmp = temp_dir(cases_dir, task["case"], os.getpid())
    shutil.rmtree(tmp, ignore_errors=True)
    execute_case(task, tmp, runner)
    return install_case(tmp, final)


def run_case_packed(task: dict, runner=None) -> dict:
    """Dask entry: run a case in a local temporary directory and return its files.

    Returns
    -------
    dict
        ``{"record": case.json's record, "files": {relative path: bytes}}``.
    """
    with tempfile.TemporaryDirectory(prefix=f"exucable-case-{task['case']}-") as d:
        work = Path(d) / "case"
        record = execute_case(task, work, runner)
        files = {str(p.relative_to(work)): p.read_bytes() for p in sorted(work.rglob("*")) if p.is_file()}
    return {"record": record, "files": files}


def install_packed(cases_dir, case_id: str, packed: dict) -> dict:
    """Client side of :func:`run_case_packed`: write the files into a temporary directory
    (``case.json`` last) and install it as ``cases/<hash>/``."""
    cases_dir = Path(cases_dir)
    tmp = temp_dir(cases_dir, case_id, os.getpid())
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    files = dict(packed["files"])
    record_bytes = files.pop(CASE_JSON, None)
    for rel, data in files.items():
        atomic_write_bytes(tmp / rel, data)
    if record_bytes is None:
        write_record(tmp, packed["record"])
    else:
        atomic_write_bytes(tmp / CASE_JSON, record_bytes)
    return install_case(tmp, cases_dir / case_id)


def record_failure(task: dict, message: str, detail: str = "") -> dict:
    """Record a case that failed outside :func:`execute_case` (its worker died, the task was
    lost): a case directory with ``case.json`` only (and ``error.txt`` with ``detail``)."""
    cases_dir = Path(task["cases_dir"])
    tmp = temp_dir(cases_dir, task["case"], f"{os.getpid()}-parent")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    record = _base_record(task)
    record["message"] = message
    record["wall_time_s"] = None
    if detail:
        atomic_write_text(tmp / "error.txt", detail)
    write_record(tmp, _stamp(record, task))
    return install_case(tmp, cases_dir / task["case"])
