"""Where results go: names made safe as paths, and output directories checked and owned up front.

- :func:`name_as_path_part`: a scenario's or sweep's ``name`` is a label, never a path; wherever a
  default output path is made from it, it goes through this one helper (no ``..``, no separator,
  no absolute path, no hidden or option-like name).
- :func:`owned_out_dir`: a run's output directory, checked *before* the solve (a file in the way, a
  parent that is a file, a directory that cannot be written are refused in one line), locked
  against a second process writing into it (``flock`` on the directory itself: nothing left
  behind, released when the process dies), and cleared of the temporary files of dead writers.
- :func:`check_out_file`: the same check for a single output file (a figure, a report).

Every refusal is an :class:`~exucable.errors.OutputError` naming the path and what to do.
"""

from __future__ import annotations

import contextlib
import os
import re
from pathlib import Path

from ..errors import OutputError
from ..io import probe_writable, remove_stale_temporaries

__all__ = ["name_as_path_part", "owned_out_dir", "check_out_dir", "check_out_file", "default_out_dir"]

# Letters and digits of any script, '_', '.', '+', '-'; everything else (separators, spaces,
# control characters, ':' and the like) becomes '_'
_UNSAFE = re.compile(r"[^\w.+-]+")
#: Longest path component made from a name (file systems allow 255 bytes; room for prefixes/suffixes).
NAME_PART_MAX = 96


def name_as_path_part(name, default: str = "scenario") -> str:
    """``name`` as one safe path component (a directory or file name, never a path).

    Runs of characters other than letters, digits, ``_ . + -`` become ``_``; leading and trailing
    ``. _ -`` are dropped (no ``..``, no hidden file, nothing read as a command-line option); the
    result is cut to :data:`NAME_PART_MAX` characters. A name with nothing left gives ``default``.

    Examples: ``"paper-ex2-bend90"`` stays; ``"../../etc/x"`` → ``"etc_x"``; ``"/tmp/a b"`` →
    ``"tmp_a_b"``.
    """
    part = _UNSAFE.sub("_", str(name)).strip("._-")[:NAME_PART_MAX].rstrip("._-")
    return part or default


def default_out_dir(name, parent="out", suffix: str = "") -> Path:
    """``parent/<name as a path part><suffix>``: the default output directory made from a name."""
    return Path(parent) / (name_as_path_part(name) + suffix)


def check_out_dir(path) -> Path:
    """Create directory ``path`` (and its parents) if needed and make sure a file can be created in
    it; return it. Raises :class:`~exucable.errors.OutputError` with the reason in one line."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise OutputError(path, "exists and is not a directory; give a directory (or a new name) for the results")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        raise OutputError(path, "a part of this path is a file, not a directory; give a directory for the results") from None
    except OSError as exc:
        raise OutputError(path, f"cannot create this directory ({exc.strerror}); give a writable place for the results") from None
    try:
        probe_writable(path)
    except OSError as exc:
        raise OutputError(path, f"cannot write into this directory ({exc.strerror}); give a writable directory") from None
    return path


def check_out_file(path) -> Path:
    """Check that file ``path`` can be written: not a directory, its directory creatable and
    writable (created if needed). Returns ``path``."""
    path = Path(path)
    if path.is_dir():
        raise OutputError(path, "is a directory; give a file name to write to")
    check_out_dir(path.parent if str(path.parent) else Path("."))
    return path


@contextlib.contextmanager
def owned_out_dir(path):
    """An output directory owned by this process for the ``with`` block: checked and created
    (:func:`check_out_dir`), temporary files of dead writers removed, and locked.

    The lock is an exclusive ``flock`` on the directory itself, taken without waiting: a second
    process (or a second run in this one) writing into the same directory is refused at once. It is
    released when the block ends or the process dies, and leaves no file behind. Where ``fcntl``
    does not exist (Windows) there is no lock.
    """
    path = check_out_dir(path)
    remove_stale_temporaries(path)
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield path
        return
    fd = os.open(path, os.O_RDONLY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise OutputError(path, "another exucable run is writing into this directory; wait for it "
                                    "or give another output directory") from None
        yield path
    finally:
        os.close(fd)          # closing the descriptor releases the lock
