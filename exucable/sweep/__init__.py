"""Parameter sweeps: one base scenario, values varied by dotted key, cases run in parallel.

``exucable sweep SWEEP.toml --out DIR`` runs every case of a sweep file (see
:mod:`exucable.sweep.spec` for the format) on a local process pool (``--workers N``) or on a
Dask distributed cluster (``--scheduler tcp://HOST:PORT``), each case in its own directory
``DIR/cases/<hash>/`` installed atomically, and writes ``DIR/sweep.csv`` (one row per case) and
``DIR/sweep.png``. Re-running the same command skips finished cases; failed ones are rerun with
``--retry-failed``.

Modules: :mod:`~exucable.scenario.dotted` (dotted keys), :mod:`~exucable.sweep.spec` (sweep files),
:mod:`~exucable.sweep.store` (the directory), :mod:`~exucable.sweep.worker` (one case),
:mod:`~exucable.sweep.execute` (pool/Dask), :mod:`~exucable.sweep.plot`,
:mod:`~exucable.sweep.progress`; the command line is :mod:`exucable.commands.sweep`.
"""

from .execute import default_workers, plan, run_sweep, worker_context
from .spec import Case, Sweep, load_sweep, parse_sweep, scenario_hash
from .store import read_table, rows_from_disk

__all__ = [
    "Case", "Sweep", "load_sweep", "parse_sweep", "scenario_hash", "run_sweep", "plan",
    "default_workers", "worker_context", "read_table", "rows_from_disk",
]
