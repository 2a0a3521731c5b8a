"""Developer tool: rewrite the key tables of ``scenarios/README.md`` from the one field table
(:data:`exucable.scenario.fields.FIELDS`). Run ``python -m exucable.commands.key_tables [README]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

from ..data import data_path
from ..io import atomic_write_text
from ..scenario.fields import readme_with_tables

__all__ = ["main"]


def main(argv=None) -> int:
    """Rewrite the tables in place (default: the shipped ``scenarios/README.md``); 0 on success."""
    argv = sys.argv[1:] if argv is None else argv
    path = Path(argv[0]) if argv else data_path("scenarios", "README.md").resolve()
    old = path.read_text(encoding="utf-8")
    new = readme_with_tables(old)
    if new != old:
        atomic_write_text(path, new)
        print(f"updated the key tables of {path}")
    else:
        print(f"{path} is up to date")
    return 0


if __name__ == "__main__":
    sys.exit(main())
