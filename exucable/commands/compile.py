"""``exucable compile``: build the ahead-of-time compiled contact kernels for this machine.

A run that finds them does not import numba (0.7 s less fixed cost per process); without them it
uses numba's JIT kernels, cached on disk. See :mod:`exucable.contact.aot`.
"""

from __future__ import annotations

from ..contact import aot, aot_build
from ..errors import ExucableError

__all__ = ["add_arguments", "main"]


def add_arguments(p) -> None:
    p.add_argument("--force", action="store_true", help="rebuild even if a valid module exists")
    p.add_argument("--check", action="store_true",
                   help="only say whether a valid module exists (exit status 0 if so, 1 if not)")
    p.add_argument("-q", "--quiet", action="store_true", help="say nothing when the module is up to date")


def main(args) -> int:
    state = aot.status()
    where = ", ".join(map(str, state["directories"]))
    if state["valid"] and not args.force:
        if not args.quiet:
            print(f"compiled kernels up to date: {state['path']}")
        return 0
    if args.check:
        print(f"no compiled kernels for these sources and this machine (key {state['key']}) in {where}; "
              "runs use numba's JIT kernels. Build them with `exucable compile`.")
        return 1
    print(f"compiling the contact kernels ahead of time (key {state['key']}; about a minute) ...", flush=True)
    try:
        path, seconds = aot_build.build()
    except RuntimeError as exc:
        raise ExucableError(f"{exc}. Runs still work, with numba's JIT kernels.") from exc
    print(f"compiled kernels written to {path} in {seconds:.0f} s")
    if state["forced_jit"]:
        print(f"note: {aot.MODE_VARIABLE}=jit is set: runs in this environment ignore them")
    return 0
