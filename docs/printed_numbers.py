"""The numbers the README and examples/README.md print, computed by running what they show.

Each printed number is produced here by running the very code the document shows (the README's Python
block, ``examples/paper_example2.py``, ``examples/friction_sweep.py``) and formatted as the document prints it; ``tests/test_docs_numbers.py``
runs :func:`stale` so a document whose number no longer matches what the code prints fails the suite.

Run from the repository root:

    .venv/bin/python docs/printed_numbers.py           # show each document's line and whether it is current
    .venv/bin/python docs/printed_numbers.py --write   # rewrite the stale lines in place
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import io
import math
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
EXAMPLES_README = ROOT / "examples" / "README.md"


def _readme_python_block() -> str:
    """The README's Python example (the first ```python block)."""
    text = README.read_text(encoding="utf-8")
    return re.search(r"```python\n(.*?)```", text, re.S).group(1)


def readme_snippet_comment() -> tuple[str, str]:
    """(pattern, line): the README snippet's results line as it must read, from running the snippet."""
    namespace: dict = {}
    exec(compile(_readme_python_block(), "README.md", "exec"), namespace)
    res = namespace["res"]
    capstan = 150.0 * math.exp(0.2 * math.pi / 2)      # the snippet's T2 e^(mu theta), paper Eq. 26
    line = (f"res.pull_force_N, res.pull_force_uncertainty_N, res.status      # {res.pull_force_N:.2f} N, "
            f"{res.pull_force_uncertainty_N:.2f} N, \"{res.status}\" (capstan {capstan:.2f} N)")
    return r"res\.pull_force_N, res\.pull_force_uncertainty_N, res\.status +#[^\n]*", line


def _load_example(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def example2_sentence() -> tuple[str, str]:
    """(pattern, text): examples/README.md's sentence on ``paper_example2.py``, from running it at full length."""
    module = _load_example("paper_example2")
    with contextlib.redirect_stdout(io.StringIO()):
        res, capstan = module.main()
    rel = 100 * (res.pull_force_N / capstan - 1)
    sign = "+" if rel >= 0 else "−"                  # the document's typographic minus
    text = (f"`paper_example2.py` {res.pull_force_N:.2f} ± {res.pull_force_uncertainty_N:.2f} N against the "
            f"capstan {capstan:.2f} N ({sign}{abs(rel):.3f} %)")
    return r"`paper_example2\.py` [0-9.]+ ± [0-9.]+ N against the capstan [0-9.]+ N \([+−-][0-9.]+ %\)", text


def _signed(x: float) -> str:
    return f"{'+' if x >= 0 else '−'}{abs(x):.3f}"


def friction_sweep_sentence() -> tuple[str, str]:
    """(pattern, text): examples/README.md's sentence on ``friction_sweep.py``, from running it at full length
    (the largest and smallest deviation from the capstan over its frictions)."""
    import tempfile

    module = _load_example("friction_sweep")
    with tempfile.TemporaryDirectory() as tmp, contextlib.redirect_stdout(io.StringIO()):
        mu, force, capstan = module.main(out=Path(tmp) / "friction_sweep.png")
    dev = [100 * (f / c - 1) for f, c in zip(force, capstan)]
    text = (f"`friction_sweep.py` μ = {mu[0]:g} … {mu[-1]:g} within {_signed(max(dev))} … {_signed(min(dev))} % "
            "of the capstan")
    return r"`friction_sweep\.py` μ = [0-9.]+ … [0-9.]+ within [+−-][0-9.]+ … [+−-][0-9.]+ % of the capstan", text


def winch_drum_sentence() -> tuple[str, str]:
    """(pattern, text): examples/README.md's sentence on ``winch_drum.py``, from running it at full length
    (the numbers it prints: the drum's torque over its radius, the reel's tension, exucable's own rig)."""
    module = _load_example("winch_drum")
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        module.main()
    lines = {line.split("  ")[0].strip(): line for line in printed.getvalue().splitlines()}
    drum = float(lines["drum torque / radius"].split()[-2])
    reel = float(lines["cable tension at reel"].split()[-2])
    rig_line = lines["exucable's rig"].split()
    rig, u = float(rig_line[-4]), float(rig_line[-1])
    text = (f"`winch_drum.py` (1 s, steady mean over the second half) drum torque / radius {drum:.3f} N, the "
            f"cable's tension at the reel {reel:.3f} N, exucable's rig on the same scenario {rig:.3f} ± {u:.2g} N "
            f"({_signed(100 * (drum / rig - 1))} %)")
    return (r"`winch_drum\.py` \(1 s, steady mean over the second half\) drum torque / radius [0-9.]+ N, the "
            r"cable's tension at the reel [0-9.]+ N, exucable's rig on the same scenario [0-9.]+ ± [0-9.e+-]+ N "
            r"\([+−-][0-9.]+ %\)"), text


GENERATED = ((README, readme_snippet_comment), (EXAMPLES_README, example2_sentence),
             (EXAMPLES_README, friction_sweep_sentence), (EXAMPLES_README, winch_drum_sentence))


_NUMBER = re.compile(r"[+−-]?[0-9]+\.([0-9]+)")


def _same(printed: str, computed: str) -> bool:
    """The same text with the same numbers, each within one unit of its last printed digit (a rerun on
    another machine may round the other way where the kernels' round-off differs)."""
    if _NUMBER.sub("#", printed) != _NUMBER.sub("#", computed):
        return False
    a, b = list(_NUMBER.finditer(printed)), list(_NUMBER.finditer(computed))
    return all(abs(float(x.group(0).replace("−", "-")) - float(y.group(0).replace("−", "-")))
               <= 1.01 * 10.0 ** -len(y.group(1)) for x, y in zip(a, b))


def stale() -> list[str]:
    """The generated lines a document does not carry, as "file: has ..., the code prints ..."; empty when
    all are current."""
    out = []
    for path, make in GENERATED:
        pattern, line = make()
        found = re.search(pattern, path.read_text(encoding="utf-8"))
        if found is None or not _same(found.group(0), line):
            out.append(f"{path.relative_to(ROOT)}: has {found.group(0) if found else 'nothing'!r}, the code prints "
                       f"{line!r}")
    return out


def write() -> list[Path]:
    """Rewrite every stale generated line in place; return the files changed."""
    from exucable.io import atomic_write_text

    changed = []
    for path, make in GENERATED:
        pattern, line = make()
        text = path.read_text(encoding="utf-8")
        new = re.sub(pattern, lambda _: line, text, count=1)
        if new != text:
            atomic_write_text(path, new)
            changed.append(path)
    return changed


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--write", action="store_true", help="rewrite the stale lines in place")
    args = p.parse_args()
    if args.write:
        for path in write():
            print(f"rewrote {path.relative_to(ROOT)}")
        return 0
    problems = stale()
    for line in problems:
        print(line)
    print("all printed numbers current" if not problems else f"{len(problems)} stale")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
