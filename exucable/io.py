"""The one way exucable writes files: atomically, so no reader ever sees half a file.

Every writer goes through :func:`atomic_write_bytes` or an :class:`AtomicBatch`: the data go to a
temporary file in the target's directory, are flushed to disk (``fsync``), and the temporary file
is renamed onto the target (``os.replace``, atomic on POSIX and Windows). A crash or a kill leaves
either the old file or the new one, never a torn one, and never a stray temporary file on an
error. A batch (a run's result files) flushes its files together, concurrently, before renaming
them in the order they were added: the same guarantee as one file after the other, at the cost of
about one flush instead of one per file.

Figures are :class:`matplotlib.figure.Figure` objects with their own canvas (no pyplot state,
no backend switch): importing exucable never changes the user's matplotlib backend.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import re
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

__all__ = ["atomic_write_bytes", "atomic_write_text", "AtomicBatch", "write_csv", "csv_text", "repr_rows", "read_csv",
           "write_json", "json_safe", "new_figure", "save_figure", "remove_stale_temporaries", "pid_alive", "probe_writable"]

# A temporary file is named ".<target>.<writer's pid>.<random>.tmp": a writer killed (kill -9)
# between creating and renaming it leaves it behind, and the pid tells whether its writer is gone.
_TEMPORARY = re.compile(r"^\..+\.(\d+)\.[A-Za-z0-9_]+\.tmp$")
#: A dead writer's temporary file is removed only when older than this [s]: a writer on another
#: machine sharing the directory (whose pid means nothing here) has renamed it long before.
STALE_TEMPORARY_AGE_S = 60.0
_swept_dirs: set = set()


def atomic_write_bytes(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically (temporary file in the same directory + ``os.replace``).

    The parent directory is created if needed. Returns the path written.
    """
    batch = AtomicBatch()
    batch.add(path, data)
    return batch.commit()[0]


class AtomicBatch:
    """Files written atomically, flushed to disk together, renamed into place in order.

    :meth:`add` writes each file's data to a temporary file next to its target at once;
    :meth:`commit` flushes all of them to disk concurrently (the file system commits concurrent
    ``fsync`` calls together: on this project's shared disk seven result files took 25-70 ms one
    after the other, 4-40 ms together), then renames them onto their targets in the order they were
    added. As with one file after the other, a name never appears before its whole content is on
    disk, and a later file (``summary.json``, added last) never before an earlier one.

    As a context manager it commits on leaving, also when an error leaves it: the files already
    added are kept (no result already written is lost), then the error propagates.
    """

    def __init__(self):
        self._pending = []          # (open temporary file, its path, target)

    def add(self, path, data: bytes) -> Path:
        """Write ``data`` to a temporary file beside ``path`` (the parent created if needed);
        ``path`` receives it at :meth:`commit`. Returns ``path``."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        _sweep_once(path.parent)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}.", suffix=".tmp", dir=path.parent)
        f = os.fdopen(fd, "wb")
        try:
            if hasattr(os, "fchmod"):
                # mkstemp makes the file 0600; a file made by open() gets 0666 less the umask, which
                # lets colleagues on a shared drive read results as they read any other file of the user's
                os.fchmod(fd, 0o666 & ~_umask())
            f.write(data)
            f.flush()
        except BaseException:
            _remove(f, tmp)                 # this file only: those added before stay
            raise
        self._pending.append((f, tmp, path))
        return path

    def add_text(self, path, text: str) -> Path:
        """:meth:`add` of ``text`` as UTF-8."""
        return self.add(path, text.encode("utf-8"))

    def commit(self) -> list[Path]:
        """Flush every added file to disk, then rename each onto its target, in order. Returns the
        targets. On an error no temporary file is left behind."""
        pending, self._pending = self._pending, []
        renamed = 0
        try:
            if len(pending) > 1:
                with ThreadPoolExecutor(max_workers=min(len(pending), 8)) as pool:
                    list(pool.map(lambda item: os.fsync(item[0].fileno()), pending))
            elif pending:
                os.fsync(pending[0][0].fileno())
            for f, _, _ in pending:
                f.close()
            for _, tmp, path in pending:
                os.replace(tmp, path)
                renamed += 1
        except BaseException:
            self._pending = pending[renamed:]
            self.discard()
            raise
        return [path for _, _, path in pending]

    def discard(self) -> None:
        """Remove the temporary files of everything added and not yet committed."""
        pending, self._pending = self._pending, []
        for f, tmp, _ in pending:
            _remove(f, tmp)

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        self.commit()
        return False


def _umask() -> int:
    """The process's umask, read without changing it where the system allows (Linux ``/proc``);
    elsewhere set and restored at once."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _remove(f, tmp) -> None:
    """Close and delete a temporary file being thrown away."""
    try:
        f.close()
    except OSError:
        pass                                # its unwritten buffer no longer matters
    try:
        os.unlink(tmp)
    except FileNotFoundError:
        pass


def pid_alive(pid: int) -> bool:
    """Whether a process ``pid`` exists on this machine (one we may not signal counts as alive)."""
    if pid <= 0 or pid >= 2**31:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True                 # exists, but is not ours to signal
    # a zombie (dead, not yet reaped by its parent) still answers signal 0
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            return f.read().rsplit(b")", 1)[1].split()[0] not in (b"Z", b"X")
    except (OSError, IndexError):
        return True                 # no /proc here: signal 0 is all there is


def remove_stale_temporaries(directory, min_age_s: float = STALE_TEMPORARY_AGE_S) -> list[Path]:
    """Remove the temporary files that writers killed mid-write left in ``directory``.

    Only files named as :class:`AtomicBatch` names them, whose writer's process no longer exists
    and which are older than ``min_age_s`` [s]; a live writer's file is never touched. Returns the
    paths removed.
    """
    removed = []
    now = time.time()
    try:
        entries = list(os.scandir(directory))
    except OSError:
        return removed
    for entry in entries:
        m = _TEMPORARY.match(entry.name)
        if m is None or pid_alive(int(m.group(1))):
            continue
        try:
            if not entry.is_file(follow_symlinks=False) or now - entry.stat().st_mtime < min_age_s:
                continue
            os.unlink(entry.path)
            removed.append(Path(entry.path))
        except OSError:
            pass                            # gone already, or not ours to remove
    return removed


def probe_writable(directory) -> None:
    """Create and delete a temporary file in ``directory`` as the writers here do; raises the
    :class:`OSError` a write there would (permissions alone do not tell: root ignores them, and a
    read-only mount does not show in them)."""
    fd, probe = tempfile.mkstemp(prefix=f".exucable-write-check.{os.getpid()}.", suffix=".tmp", dir=directory)
    os.close(fd)
    os.unlink(probe)


def _sweep_once(directory: Path) -> None:
    """:func:`remove_stale_temporaries` the first time this process writes into ``directory``."""
    key = os.path.abspath(directory)
    if key not in _swept_dirs:
        _swept_dirs.add(key)
        remove_stale_temporaries(directory)


def atomic_write_text(path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def write_csv(path, columns, data: dict, batch: AtomicBatch | None = None) -> Path:
    """Write equal-length columns ``data[c]`` for ``c in columns`` as CSV with a header, atomically
    (into ``batch`` if given, see :func:`csv_text` for the format)."""
    text = csv_text(columns, data)
    return batch.add_text(path, text) if batch is not None else atomic_write_text(path, text)


def csv_text(columns, data: dict, rows=None) -> str:
    """Equal-length columns ``data[c]`` for ``c in columns`` as CSV text with a header.

    Floats are written with ``repr`` (shortest round-trip form), so reading them back is exact;
    integer arrays (indices) as integers. ``rows``: what turns the list of column arrays into the
    rows' text, :func:`repr_rows` or one giving the same characters faster
    (:func:`exucable.output.numbers_text.csv_rows`).
    """
    lengths = {c: len(data[c]) for c in columns}
    if len(set(lengths.values())) > 1:    # zip below would silently cut every column to the shortest
        raise ValueError(f"columns of unequal length {lengths}: one row per value is needed")
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow(columns)
    return buf.getvalue() + (rows or repr_rows)([np.asarray(data[c]) for c in columns])


def repr_rows(arrays) -> str:
    """Equal-length columns as CSV rows, each ended by a newline ("" for none): integer arrays as
    ``str(int)``, the others as ``repr(float)`` of their float64 values."""
    # integer columns (node and element indices) stay integers; tolist() gives Python ints and
    # floats, whose str/repr are the forms above, formatted column by column (a per-row csv
    # writer took ~10 µs a row: 0.03 s of a 0.3 s steady run's 6600 rows)
    text = [list(map(str, a.astype(np.int64).tolist())) if np.issubdtype(a.dtype, np.integer)
            else list(map(repr, a.astype(float).tolist())) for a in arrays]
    body = "\n".join(map(",".join, zip(*text)))
    return body + ("\n" if body else "")


def read_csv(path) -> dict[str, np.ndarray]:
    """Read a numeric CSV with a header row into a dict of float arrays keyed by header."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        raise ValueError(f"{path}: empty file")
    header = [h.strip() for h in rows[0]]
    body = np.array([[float(x) for x in r] for r in rows[1:] if r], dtype=float).reshape(-1, len(header))
    return {h: body[:, i] for i, h in enumerate(header)}


def json_safe(obj):
    """``obj`` with numpy scalars and arrays as Python numbers and lists, non-finite floats as None
    (JSON has no nan/inf), paths as strings."""
    if isinstance(obj, dict):
        return {str(k): json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        v = float(obj)
        return v if math.isfinite(v) else None
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.ndarray):
        return json_safe(obj.tolist())
    if isinstance(obj, Path):
        return str(obj)
    return obj


def write_json(path, obj, indent: int = 2, batch: AtomicBatch | None = None) -> Path:
    """Write ``obj`` as JSON (through :func:`json_safe`), newline-terminated, atomically (into
    ``batch`` if given)."""
    text = json.dumps(json_safe(obj), indent=indent) + "\n"
    return batch.add_text(path, text) if batch is not None else atomic_write_text(path, text)


def new_figure(figsize=(7.0, 4.0), **kwargs):
    """A :class:`matplotlib.figure.Figure` on its own Agg canvas: no pyplot state, no backend switch,
    safe without a display and in worker processes. ``kwargs`` go to ``Figure`` (``dpi``, ``layout``)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, **kwargs)
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig, path, dpi: float | None = 120, **savefig_kwargs) -> Path:
    """Render ``fig`` into memory and write it to ``path`` atomically; the format follows the suffix
    (PNG when there is none). ``dpi=None`` keeps the figure's own. Returns the path written."""
    path = Path(path)
    buf = io.BytesIO()
    fmt = path.suffix.lstrip(".").lower() or "png"
    kwargs = dict(savefig_kwargs)
    if dpi is not None:
        kwargs["dpi"] = dpi
    fig.savefig(buf, format=fmt, **kwargs)
    return atomic_write_bytes(path, buf.getvalue())
