"""``exucable sweep``: the command-line face of :func:`~exucable.sweep.run_sweep`."""

from __future__ import annotations

import importlib
import json
import signal
import sys
from pathlib import Path

from ..errors import ExucableError
from ..output.outdir import default_out_dir
from ..sweep.execute import PLOT, plan, run_sweep
from ..sweep.plot import plot_sweep
from ..sweep.spec import OUTPUTS, load_sweep
from ..sweep.store import TABLE, extra_columns, is_finished, make_row, table_columns, write_table

__all__ = ["add_arguments", "main", "load_runner"]


def add_arguments(p) -> None:
    p.add_argument("sweep", help="sweep file (TOML): base scenario, [set], unset, [vary], mode")
    p.add_argument("--out", "-o", default=None, help="sweep directory (default: out/<sweep name>, the name made safe as a directory name)")
    p.add_argument("--workers", "-j", type=int, default=None,
                   help="local worker processes (default: the cores available)")
    p.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                   help="run the cases on this Dask distributed scheduler instead (needs exucable[dask])")
    p.add_argument("--retry-failed", action="store_true",
                   help="rerun cases recorded as failed (finished ones are never rerun)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    p.add_argument("--no-plots", action="store_true", help="skip each case's PNG figures (sweep.png is kept)")
    p.add_argument("--dry-run", action="store_true",
                   help="validate the sweep and list its cases and their state; run nothing")
    p.add_argument("--collect", action="store_true",
                   help=f"rebuild {TABLE} and {PLOT} from the case directories; run nothing")
    p.add_argument("--runner", default=None, metavar="MODULE:FUNCTION",
                   help="advanced: run each case with this callable instead of exucable.run:run_scenario "
                        "(same signature; importable by the workers)")


def load_runner(spec: str | None):
    """``"module:function"`` → the callable (None → None, the default runner)."""
    if not spec:
        return None
    mod, sep, name = spec.partition(":")
    if not sep or not mod or not name:
        raise ExucableError(f"--runner must be MODULE:FUNCTION, got {spec!r}")
    try:
        obj = importlib.import_module(mod)
        for part in name.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError) as exc:
        raise ExucableError(f"--runner {spec}: {exc}") from None
    if not callable(obj):
        raise ExucableError(f"--runner {spec}: not callable")
    return obj


def _terminated(signum, frame):
    raise KeyboardInterrupt(f"signal {signum}")


def _fmt(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.6g}"
    return v if isinstance(v, str) else json.dumps(v)


def _print_table(rows, keys, output: str, rope_key: str | None) -> None:
    cols = list(keys) + ["case", "status", output] + ([rope_key] if rope_key else [])
    body = [[_fmt(r.get(c)) for c in cols] for r in rows]
    widths = [max(len(c), *(len(b[j]) for b in body)) for j, c in enumerate(cols)]
    print("  " + "  ".join(c.ljust(w) for c, w in zip(cols, widths)))
    for b in body:
        print("  " + "  ".join(x.ljust(w) for x, w in zip(b, widths)))


def main(args) -> int:
    sweep = load_sweep(args.sweep)
    out_dir = Path(args.out) if args.out else default_out_dir(sweep.name)
    rope_key = OUTPUTS.get(sweep.output)
    n = len(sweep.cases)

    if args.dry_run or args.collect:
        records, todo = plan(sweep, out_dir, args.retry_failed)
        ids = sweep.case_ids()
        extra = extra_columns(sweep.output)
        rows = [make_row(sweep.keys, c.params, cid, records[cid], extra) for c, cid in zip(sweep.cases, ids)]
        if args.collect:
            if not out_dir.is_dir():
                raise ExucableError(f"--collect: {out_dir} does not exist")
            write_table(out_dir / TABLE, rows, table_columns(sweep.keys, sweep.output))
            plot_sweep(out_dir / PLOT, rows, sweep.keys, sweep.output, sweep.mode, title=sweep.name)
            print(f"{sweep.name}: {out_dir / TABLE} and {out_dir / PLOT} rebuilt from {n} case(s) on disk")
        else:
            print(f"{sweep.name}: {n} case(s) ({sweep.mode} over {', '.join(sweep.keys)}), "
                  f"{len(todo)} to run in {out_dir}")
        _print_table(rows, sweep.keys, sweep.output, rope_key)
        return 0

    before, todo = plan(sweep, out_dir, args.retry_failed)
    ids = sweep.case_ids()
    skipped_failed = sum(1 for i, cid in enumerate(ids)
                         if i not in todo and before[cid] is not None and not is_finished(before[cid]))
    where = f"Dask scheduler {args.scheduler}" if args.scheduler else "local pool"
    if not args.quiet:
        print(f"{sweep.name}: {n} case(s), {len(todo)} to run on the {where}, "
              f"{n - len(todo)} already on disk", file=sys.stderr)
    runner = load_runner(args.runner)
    if todo and args.runner is None:
        from .compile import announce_compiling

        announce_compiling()
    # SIGTERM like Ctrl-C: stop the case processes and write the table before leaving
    previous = signal.signal(signal.SIGTERM, _terminated)
    try:
        rows = run_sweep(sweep, out_dir, workers=args.workers, scheduler=args.scheduler,
                         retry_failed=args.retry_failed, quiet=args.quiet, plots=not args.no_plots,
                         runner=runner)
    finally:
        signal.signal(signal.SIGTERM, previous)
    failed = [r for r in rows if r["status"] not in ("ok", "steady")]
    print(f"{sweep.name}: {n - len(failed)}/{n} case(s) finished, {len(failed)} failed; "
          f"{out_dir / TABLE}, {out_dir / PLOT}")
    _print_table(rows, sweep.keys, sweep.output, rope_key)
    for r in failed:
        params = ", ".join(f"{k}={_fmt(r[k])}" for k in sweep.keys)
        print(f"  FAILED {r['case']} ({params}): {r['message']}")
    if skipped_failed > 0:
        print(f"  ({skipped_failed} failed case(s) from an earlier run kept; --retry-failed reruns them)")
    return 1 if failed else 0
