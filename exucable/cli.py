"""The ``exucable`` command: one entry point, a table of subcommands.

User errors (:class:`~exucable.errors.ExucableError`) print one line naming the offending
field and exit with status 2, without a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from .errors import ExucableError

__all__ = ["main", "console_main", "end_process", "SUBCOMMANDS", "ENDS_WITH_OS_EXIT"]

# name -> (module in exucable.commands with add_arguments(parser) and main(args) -> int, one-line help)
SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "route": ("exucable.commands.route", "draw a scenario's conduit route and print its table"),
    "run": ("exucable.commands.run", "simulate one scenario and write its results"),
    "scenarios": ("exucable.commands.scenarios", "list the shipped scenarios, by the names every command takes"),
    "validate": ("exucable.commands.validate", "run the paper's examples (or --suite industry: published pulls) against their references"),
    "sweep": ("exucable.commands.sweep", "run a parameter sweep (local pool or Dask)"),
    "compare": ("exucable.commands.compare", "compare two result sets (yours and ours)"),
    "converge": ("exucable.commands.converge", "run a scenario on refined meshes and extrapolate its result"),
    "export": ("exucable.commands.export", "write a scenario's exact discrete problem for another solver"),
    "plan": ("exucable.commands.plan", "plan a pull: both directions, section tables, limit checks, HTML report"),
    "fit": ("exucable.commands.fit", "fit the friction coefficient to a tension recorder's log and forecast the rest of the pull"),
    "compile": ("exucable.commands.compile", "compile the contact kernels into numba's cache now (the first run would do it)"),
}


class _VersionAction(argparse.Action):
    """``--version``: prints exucable's and Exudyn's versions (read from the installed metadata)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings=option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        from .output.versions import version_line
        print(version_line())            # stdout, as argparse's own version action
        parser.exit()


def _command_in(argv) -> str | None:
    """The subcommand named in ``argv`` (its first word that is not an option), if any."""
    for word in argv:
        if not word.startswith("-"):
            return word if word in SUBCOMMANDS else None
    return None


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The ``exucable`` parser. With ``only``, import just that subcommand's module (the others
    would cost a fifth of a second of imports that ``exucable run`` does not need) and give the
    others their one-line help."""
    parser = argparse.ArgumentParser(
        prog="exucable",
        description="Cable pulling tension through 3D conduits on the Exudyn multibody engine "
                    "(after Yang et al., Multibody Syst Dyn 30, 2013).")
    parser.add_argument("--version", action=_VersionAction,
                        help="print exucable's and Exudyn's versions and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module_name, help_text) in SUBCOMMANDS.items():
        if only is not None and name != only:
            sub.add_parser(name, help=help_text, description=help_text)
            continue
        mod = importlib.import_module(module_name)
        p = sub.add_parser(name, help=help_text, description=help_text)
        mod.add_arguments(p)
        p.set_defaults(_main=mod.main)
    return parser


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(only=_command_in(argv))
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    try:
        return int(args._main(args) or 0)
    except ExucableError as exc:
        print(f"exucable {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"exucable {args.command}: interrupted", file=sys.stderr)
        return 130
    except (MemoryError, RecursionError) as exc:
        # an input too large or too deeply nested for this machine: the user's to change
        print(f"exucable {args.command}: error: the input is too large or too deeply nested to process "
              f"({type(exc).__name__}){_logged(args.command, argv)}", file=sys.stderr)
        return 2
    except Exception as exc:  # an internal error: one line here, the traceback in a log file
        print(f"exucable {args.command}: internal error: {type(exc).__name__}: {_one_line(exc)}"
              f"{_logged(args.command, argv)}; please report it with that file", file=sys.stderr)
        return 3


#: Commands whose process, started as the ``exucable`` command, ends with ``os._exit`` once
#: :func:`main` has returned: by then every output file is written (atomically, through
#: exucable.io, fsynced and renamed) and the figures' helper process joined, and a normal
#: interpreter exit would spend 0.3-0.5 s of CPU finalising the loaded extensions (Exudyn, numba's
#: kernels; docs/decisions/0006-exit-without-finalising.md).
ENDS_WITH_OS_EXIT = frozenset({"run", "plan"})


def end_process(code: int) -> None:
    """End this process at once with exit status ``code``: stdout and stderr flushed, then
    ``os._exit`` (no interpreter finalisation, no atexit handlers). For the console entry point
    only, after :func:`main` returned; never when exucable runs inside another program.

    A stream that cannot be flushed (a closed pipe) makes the status 120 where it was 0, as the
    interpreter's own exit does."""
    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):
            code = code or 120
    os._exit(code)


def console_main() -> None:
    """The ``exucable`` command (and ``python -m exucable``): :func:`main` on the process's
    arguments, then exit with its status; a command of :data:`ENDS_WITH_OS_EXIT` skips the
    interpreter's finalisation (:func:`end_process`)."""
    argv = sys.argv[1:]
    code = main(argv)
    if _command_in(argv) in ENDS_WITH_OS_EXIT:
        end_process(code)
    sys.exit(code)


def _one_line(exc: BaseException, limit: int = 300) -> str:
    text = " ".join(str(exc).split())
    return text if len(text) <= limit else text[:limit] + " ..."


def _logged(command: str, argv) -> str:
    """Write the current exception's traceback to a log file; `` (details in PATH)`` or ``""``."""
    import os
    import tempfile
    import time
    import traceback

    from .io import atomic_write_text

    path = os.path.join(tempfile.gettempdir(), f"exucable-{command}-{time.strftime('%Y%m%dT%H%M%S')}-{os.getpid()}.log")
    try:
        atomic_write_text(path, f"exucable {' '.join(map(str, argv))}\n\n{traceback.format_exc()}")
    except Exception:      # the log is a courtesy: its own failure must not raise a second traceback
        return ""
    return f" (details in {path})"


if __name__ == "__main__":
    console_main()
