"""The reference values exucable is validated against, read from ``reference/paper_values.toml``.

Every entry there is a table with its ``value`` (SI units as its key's suffix says), its ``kind``
(paper input, chosen, closed form, reported) and its ``source``; see ``reference/README.md``. The
file ships as package data (:mod:`exucable.data`). Validation and its figures both read it here.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from . import data_path

__all__ = ["reference_file", "load_reference_entries", "load_reference"]


def reference_file() -> Path:
    """Path of the shipped ``paper_values.toml``."""
    return data_path("reference", "paper_values.toml")


def load_reference_entries(path=None) -> dict:
    """The whole file as ``{section: {key: {"value": ..., "kind": ..., "source": ...}}}``
    (plus the top-level scalars such as ``schema_version``)."""
    with open(reference_file() if path is None else path, "rb") as f:
        return tomllib.load(f)


def load_reference(path=None) -> dict:
    """The reference values alone, as a nested dict ``{section: {key: value}}``.

    Parameters
    ----------
    path : str or os.PathLike, optional
        Another reference file of the same form (default: the shipped one).
    """
    data = load_reference_entries(path)
    return {sec: {k: v["value"] for k, v in tab.items() if isinstance(v, dict) and "value" in v}
            for sec, tab in data.items() if isinstance(tab, dict)}
