"""Files shipped with exucable as package data: the scenarios (``scenarios/``) and the reference
values with their sources (``reference/``).

In a source checkout both are the top-level directories of the repository (linked here); in an
installed wheel they are copies inside the package. Either way :func:`data_path` finds them through
:mod:`importlib.resources`, so ``exucable validate`` runs from any directory, and
:func:`resolve_scenario_path` lets every command take a shipped scenario by name
(``exucable run paper_ex2_bend90``) or by its path in the repository (``scenarios/fast/paper_ex2_bend90.toml``)
from anywhere.
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

__all__ = ["data_path", "shipped_scenarios", "resolve_scenario_path"]

#: Folders of ``scenarios/`` that hold sweep files, not scenarios.
_NOT_SCENARIOS = ("sweeps",)


def data_path(*parts: str) -> Path:
    """The shipped file or directory ``parts`` (e.g. ``data_path("scenarios", "fast")``) as a path.

    Raises
    ------
    FileNotFoundError
        If it is not there (an incomplete installation), naming the path looked for.
    """
    path = Path(str(files(__name__).joinpath(*parts)))
    if not path.exists():
        raise FileNotFoundError(f"exucable's package data has no {'/'.join(parts)} (looked for {path}); "
                                "reinstall exucable")
    return path


def shipped_scenarios() -> dict[str, Path]:
    """The scenarios shipped with exucable: name → file, the name being the file's path under
    ``scenarios/`` without ``.toml`` (``"paper_ex2_bend90"``, ``"fast/paper_ex2_bend90"``,
    ``"industry/commscope_conquest_run_a_h"``), sorted by name. Sweep files are not listed."""
    root = data_path("scenarios")
    found = {}
    for path in sorted(root.rglob("*.toml")):
        rel = path.relative_to(root)
        if rel.parts[0] in _NOT_SCENARIOS:
            continue
        found[rel.with_suffix("").as_posix()] = path
    return found


def resolve_scenario_path(arg) -> Path:
    """The file a command-line scenario argument means.

    An existing file is itself. Otherwise, in this order: a path starting with ``scenarios/`` (as
    the README writes them) is looked for in the shipped ``scenarios/``; a shipped scenario's name
    (:func:`shipped_scenarios`, with or without ``.toml``), or a file name matching exactly one
    shipped scenario. If nothing matches, ``arg`` comes back unchanged (the reader then says it is
    not found).
    """
    path = Path(arg)
    if path.exists():
        return path
    parts = path.parts
    if len(parts) > 1 and parts[0] == "scenarios":
        try:
            return data_path("scenarios", *parts[1:])
        except FileNotFoundError:
            pass
    try:
        shipped = shipped_scenarios()
    except FileNotFoundError:
        return path
    name = path.as_posix().removesuffix(".toml")
    if name in shipped:
        return shipped[name]
    by_stem = [p for n, p in shipped.items() if n.rpartition("/")[2] == name]
    return by_stem[0] if len(by_stem) == 1 else path
