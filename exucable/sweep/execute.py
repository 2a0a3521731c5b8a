"""Running a sweep: which cases to run, on a local process pool or a Dask cluster, and the table.

Nothing lost, nothing twice:

- a case is *finished* when ``DIR/cases/<hash>/case.json`` says so and the files it lists are
  there as written (:func:`~exucable.sweep.store.read_verified_record`); finished cases are never
  run again, a damaged one is; failed ones are rerun only with ``retry_failed``;
- every case directory is installed by one rename of a complete temporary directory, so a
  kill of the sweep, or of a worker, at any moment loses no finished case;
- ``sweep.csv`` is rewritten atomically after every finished case.

Local pool (:mod:`exucable.sweep.pool`): every case in a fresh process of the ``forkserver``
context, whose server process has only imported the modules (:mod:`exucable.sweep._preload`)
and never run a model, so forking from it is safe for Exudyn and saves the ~1.7 s of imports per
case that ``spawn`` costs. A case whose process dies (killed, segfault) is started once more, then
recorded as failed. (Forkserver children inherit the environment of the server process, which is
fixed when the first sweep of the Python session starts; ``sys.path`` is passed on at every case.)
As with any multiprocessing code, a script calling :func:`run_sweep` must guard its top level
with ``if __name__ == "__main__":``.

Dask: ``scheduler="tcp://HOST:PORT"`` (or a ``distributed.Client``) submits one task per case;
the worker returns the case's files and this process installs them, so no shared file system
is needed. Dask reruns a task whose worker died (up to its ``allowed-failures``), then reports
``KilledWorker``, recorded as the case's failure.
"""

from __future__ import annotations

import copy
import multiprocessing
import os
import sys
import time
import uuid
import warnings
from pathlib import Path

from ..errors import ExucableError
from ..output.outdir import check_out_dir
from .pool import run_local
from .progress import SweepProgress
from .store import (
    CASES_DIR,
    TABLE,
    SweepLock,
    extra_columns,
    case_dir,
    is_finished,
    make_row,
    read_verified_record,
    remove_stale,
    table_columns,
    write_manifest,
    write_table,
)
from .worker import install_packed, record_failure, run_case_packed

__all__ = ["run_sweep", "default_workers", "worker_context", "plan"]

PLOT = "sweep.png"

#: While a sweep runs, ``sweep.csv`` is rewritten at most this often [s] (and always when it ends).
TABLE_REFRESH_S = 2.0


def default_workers() -> int:
    """Cores available to this process."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def worker_context(method: str | None = None):
    """The multiprocessing context of the local pool: ``forkserver`` with the modules preloaded
    where the platform has it, else ``spawn``. Never plain ``fork``: a process that has run an
    Exudyn model must not be forked."""
    methods = multiprocessing.get_all_start_methods()
    method = method or ("forkserver" if "forkserver" in methods else "spawn")
    ctx = multiprocessing.get_context(method)
    if method == "forkserver":
        ctx.set_forkserver_preload(["exucable.sweep._preload"])
    return ctx


def plan(sweep, out_dir, retry_failed: bool = False) -> tuple[dict, list[int]]:
    """What is on disk and what to run.

    Returns
    -------
    (dict, list of int)
        Case hash → record on disk (or None), and the indices of the cases to run: those without
        a record, and failed ones if ``retry_failed``.
    """
    ids = sweep.case_ids()
    records = {cid: read_verified_record(case_dir(out_dir, cid)) for cid in ids}
    todo = [i for i, cid in enumerate(ids)
            if records[cid] is None or (retry_failed and not is_finished(records[cid]))]
    return records, todo


def run_sweep(sweep, out_dir, workers: int | None = None, scheduler=None, retry_failed: bool = False,
              quiet: bool = True, plots: bool = True, runner=None, mp_context=None) -> list[dict]:
    """Run the cases of ``sweep`` that are not finished in ``out_dir``; write the table and plot.

    Parameters
    ----------
    sweep : Sweep
        From :func:`~exucable.sweep.load_sweep`.
    out_dir : str or Path
        The sweep directory (created); see :mod:`exucable.sweep.store` for its layout.
    workers : int, optional
        Local pool size; default: the cores available. Ignored with ``scheduler``.
    scheduler : str or distributed.Client, optional
        ``"tcp://HOST:PORT"`` of a running Dask scheduler (needs ``exucable[dask]``).
    retry_failed : bool
        Rerun cases recorded as failed (otherwise they stay failed).
    quiet : bool
        No progress bar (it is drawn only on a terminal anyway).
    plots : bool
        Write each case's PNG figures (``sweep.png`` is always written).
    runner : callable, optional
        ``runner(scenario, out_dir, quiet, plots)`` in place of :func:`exucable.run.run_scenario`
        (see :mod:`exucable.sweep.worker`); must be importable by the workers.
    mp_context : multiprocessing context, optional
        Default :func:`worker_context`.

    Returns
    -------
    list of dict
        The table rows, in case order (``sweep.csv``'s content).
    """
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ExucableError(f"--workers must be an integer >= 1, got {workers!r}")
    client = owned = None
    if scheduler is not None:
        # before anything is written: a missing extra or an unreachable scheduler is the user's to fix
        client, owned = _dask_client(scheduler)
    try:
        return _run_sweep(sweep, Path(out_dir).resolve(), workers, client, retry_failed, quiet, plots,
                          runner, mp_context)
    finally:
        if owned:
            client.close()


def _run_sweep(sweep, out: Path, workers, client, retry_failed, quiet, plots, runner, mp_context) -> list[dict]:
    check_out_dir(out)
    cases_dir = check_out_dir(out / CASES_DIR)
    keys = sweep.keys
    ids = sweep.case_ids()
    extra = extra_columns(sweep.output)
    columns = table_columns(keys, sweep.output)

    with SweepLock(out):
        remove_stale(cases_dir)
        write_manifest(out, sweep)
        records, todo = plan(sweep, out, retry_failed)

        def rows() -> list[dict]:
            return [make_row(keys, c.params, cid, records[cid], extra) for c, cid in zip(sweep.cases, ids)]

        def counts():
            done = sum(1 for cid in ids if records[cid] is not None and (cid not in pending))
            failed = sum(1 for cid in ids if records[cid] is not None and not is_finished(records[cid])
                         and cid not in pending)
            return done, failed

        pending = {ids[i] for i in todo}
        progress = SweepProgress(sweep.name, len(ids), enabled=not quiet)
        state = {"running": 0}

        last_table = [time.monotonic()]

        def on_record(cid: str, record: dict) -> None:
            records[cid] = record
            pending.discard(cid)
            # Rewriting the whole table after every case costs O(n) per case, O(n²) per sweep; the case
            # directories are the durable record (the table is rebuilt from them on resume), so while
            # running the table is refreshed at most every TABLE_REFRESH_S, and always at the end.
            now = time.monotonic()
            if now - last_table[0] >= TABLE_REFRESH_S:
                write_table(out / TABLE, rows(), columns)
                last_table[0] = now
            progress.update(*counts(), state["running"])

        def on_running(n: int) -> None:
            state["running"] = n
            progress.update(*counts(), n)

        write_table(out / TABLE, rows(), columns)
        tasks = [_task(sweep, i, ids[i], cases_dir, plots, portable=client is not None) for i in todo]
        progress.update(*counts(), 0)
        try:
            if tasks:
                if client is not None:
                    _run_dask(tasks, client, runner, on_record, on_running, cases_dir)
                else:
                    n = min(workers or default_workers(), len(tasks))
                    run_local(tasks, n, runner, mp_context or worker_context(), on_record, on_running,
                              record_failure)
        finally:
            progress.close()
            write_table(out / TABLE, rows(), columns)
            try:
                from .plot import plot_sweep
                plot_sweep(out / PLOT, rows(), keys, sweep.output, sweep.mode, title=sweep.name)
            except Exception as exc:  # a figure must not hide the run's outcome
                warnings.warn(f"{PLOT} not written: {type(exc).__name__}: {exc}", RuntimeWarning, stacklevel=2)
        return rows()


def _task(sweep, index: int, case_id: str, cases_dir: Path, plots: bool, portable: bool = False) -> dict:
    """A case as plain data for a worker.

    ``portable``: for workers on other machines, a survey route read from a CSV file travels as
    inline points (``portable_scenario``; the same route). ``scenario`` stays the canonical dict
    that ``case.json`` records and the hash is taken of.
    """
    case = sweep.cases[index]
    task = {
        "sweep": sweep.name,
        "case": case_id,
        "index": index,
        "params": case.params,
        "scenario": case.scenario.to_dict(),
        "base_dir": str(sweep.base_dir),
        "cases_dir": str(cases_dir),
        "plots": bool(plots),
    }
    spec = case.scenario.conduit
    if portable and spec.points_csv is not None:
        data = copy.deepcopy(task["scenario"])
        data["conduit"].pop("points_csv")
        data["conduit"]["points"] = [list(p) for p in spec.points_m]
        task["portable_scenario"] = data
    return task


# --------------------------------------------------------------------------------------------
# Dask
# --------------------------------------------------------------------------------------------


def _dask_client(scheduler):
    try:
        import distributed
    except ImportError:
        raise ExucableError(
            "--scheduler needs Dask's distributed scheduler, which is not installed: "
            "pip install 'exucable[dask]' (or 'dask[distributed]')") from None
    if not isinstance(scheduler, str):
        return scheduler, False          # a Client given by the caller: theirs to close
    try:
        client = distributed.Client(scheduler, timeout="15s", set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise ExucableError(f"cannot connect to the Dask scheduler at {scheduler}: {exc}") from None
    return client, True


def _run_dask(tasks, client, runner, on_record, on_running, cases_dir: Path) -> None:
    from distributed import as_completed

    futures = {}
    try:
        run_tag = uuid.uuid4().hex[:8]
        for task in tasks:
            # pure=False and a unique key: a case submitted again by a later run is run again
            # only if that run found it unfinished on disk.
            fut = client.submit(run_case_packed, task, runner, pure=False,
                                key=f"exucable-case-{task['case']}-{run_tag}", priority=-task["index"])
            futures[fut] = task
        on_running(min(len(futures), max(1, len(client.scheduler_info().get("workers", {})))))
        for fut in as_completed(list(futures), loop=client.loop):
            task = futures[fut]
            cid = task["case"]
            try:
                packed = fut.result()
            except Exception as exc:
                record = record_failure(task, f"Dask task failed: {type(exc).__name__}: {exc}")
            else:
                record = install_packed(cases_dir, cid, packed)
            on_record(cid, record)
        on_running(0)
    finally:
        pending = [f for f in futures if not f.done()]
        if pending:
            client.cancel(pending)
