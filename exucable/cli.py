"""The ``exucable`` command: one entry point, a table of subcommands.

User errors (:class:`~exucable.errors.ExucableError`) print one line naming the offending
field and exit with status 2, without a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from .errors import ExucableError

__all__ = ["main", "SUBCOMMANDS"]

# name -> (module with add_arguments(parser) and main(args) -> int, one-line help)
SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "route": ("exucable.route", "draw a scenario's conduit route and print its table"),
    "run": ("exucable.run", "simulate one scenario and write its results"),
    "validate": ("exucable.validate", "run the paper's examples against their references"),
    "sweep": ("exucable.sweep", "run a parameter sweep (local pool or Dask)"),
    "compare": ("exucable.compare", "compare two result sets (yours and ours)"),
    "converge": ("exucable.commands.converge", "run a scenario on refined meshes and extrapolate its result"),
}


def _load(module_name: str):
    try:
        return importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name == module_name:
            return None
        raise


class _VersionAction(argparse.Action):
    """``--version``: imports Exudyn only when asked (it costs a second at start-up)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings=option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        from .versions import version_line
        print(version_line())            # stdout, as argparse's own version action
        parser.exit()


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="exucable",
        description="Cable pulling tension through 3D conduits on the Exudyn multibody engine "
                    "(after Yang et al., Multibody Syst Dyn 30, 2013).")
    parser.add_argument("--version", action=_VersionAction,
                        help="print exucable's and Exudyn's versions and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module_name, help_text) in SUBCOMMANDS.items():
        mod = _load(module_name)
        p = sub.add_parser(name, help=help_text if mod else f"{help_text} (not built yet)",
                           description=help_text)
        if mod is not None:
            mod.add_arguments(p)
            p.set_defaults(_main=mod.main)
        else:
            p.add_argument("rest", nargs=argparse.REMAINDER)
            p.set_defaults(_main=None)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    if args._main is None:
        print(f"exucable {args.command}: not built yet", file=sys.stderr)
        return 3
    try:
        return int(args._main(args) or 0)
    except ExucableError as exc:
        print(f"exucable {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"exucable {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
