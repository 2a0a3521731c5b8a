"""The house rules, checked: one folder per stage of the data flow with imports pointing down the
stages (lazy imports count too), no import cycles, at most a handful of top-level modules, only
``model/`` and ``solve/`` import Exudyn, no module changes matplotlib's backend, no absolute paths
of a development machine in the repository, the contact modules share only public names."""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "exucable"


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _is_package(name: str, modules: dict[str, Path]) -> bool:
    return modules[name].name == "__init__.py"


def _imports(name: str, modules: dict[str, Path]) -> set[str]:
    """exucable modules that module ``name`` imports anywhere (top level or inside a function)."""
    tree = ast.parse(modules[name].read_text(encoding="utf-8"))
    package = name if _is_package(name, modules) else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                stem = ".".join(base + ([node.module] if node.module else []))
            else:
                stem = node.module or ""
            # `from pkg import sub` imports the module pkg.sub when there is one
            targets = [stem] + [f"{stem}.{alias.name}" for alias in node.names]
        else:
            continue
        found.update(t for t in targets if t in modules and t != name)
    return found


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on_stack, result = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                result.append(sorted(component))

    for v in graph:
        if v not in index:
            visit(v)
    return result


def test_the_import_graph_is_read():
    modules = _modules()
    graph = {m: _imports(m, modules) for m in modules}
    # known edges, one relative and one lazy (inside a function), so that the cycle test below
    # cannot pass by reading nothing
    assert "exucable.io" in graph["exucable.output.results"]
    assert "exucable.run" in graph["exucable.sweep.worker"]
    assert "exucable.model.build" in graph["exucable.run"]


def test_no_import_cycles_inside_the_package():
    modules = _modules()
    graph = {m: _imports(m, modules) for m in modules}
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]  # the detector works
    assert _cycles(graph) == [], "import cycles (lazy imports count)"


# Modules that may import Exudyn: the model layer and the solver driving it.
EXUDYN_ALLOWED = re.compile(r"^exucable\.(model|solve)(\..+)?$")


# The stages of the data flow, lowest first. A module may import its own room and the rooms of lower
# stages, never a room of its own stage or above: pure libraries (geometry, the quasi-static models,
# post-processing formulas, figures) under the scenario that checks routes with them; the scenario
# under the contact law, the model and the solvers; their results under the applications and commands.
STAGES = [
    {"errors", "io", "version", "data"},
    {"geometry", "quasistatic", "plots"},
    {"scenario"},
    {"contact"},
    {"post"},
    {"model"},
    {"solve"},
    {"output"},
    {"run"},
    {"api"},
    {"plan", "sweep"},
    {"fit"},
    {"validation"},
    {"commands"},
    {"cli", "__init__"},
    {"__main__"},
]
TOP_LEVEL_MODULES_AT_MOST = 12


def _room(name: str) -> str:
    parts = name.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def test_every_room_has_a_stage():
    rooms = {_room(m) for m in _modules()}
    staged = set().union(*STAGES)
    assert rooms - staged == set(), "a new top-level module or folder: give it a stage in STAGES"
    assert staged - rooms == set(), "STAGES names rooms that no longer exist"


def test_imports_point_down_the_stages():
    modules = _modules()
    rank = {room: i for i, stage in enumerate(STAGES) for room in stage}
    upward = []
    for name in modules:
        for target in _imports(name, modules):
            a, b = _room(name), _room(target)
            if a != b and rank[b] >= rank[a]:
                upward.append(f"{name} -> {target}")
    assert upward == [], "imports that point up or sideways across the stages"


def test_modules_share_only_public_names():
    # modules share what they export (the contact kernels their parts through
    # contact/kernel_parts.py): a module's underscored names stay its own, so it can change them
    modules = _modules()
    found = []
    for name, path in modules.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith("exucable")):
                found += [f"{name}: {node.module}.{a.name}" for a in node.names
                          if a.name.startswith("_") and not a.name.startswith("__")]
    assert not found, f"private names imported from another module: {found}"


def test_a_handful_of_top_level_modules():
    top = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert len(top) <= TOP_LEVEL_MODULES_AT_MOST, top


def test_only_model_and_solve_import_exudyn_directly():
    offenders = []
    for name, path in _modules().items():
        if EXUDYN_ALLOWED.match(name):
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level else [])
            if any(n == "exudyn" or n.startswith("exudyn.") for n in names):
                offenders.append(f"{name} (line {node.lineno})")
    assert offenders == []


def _exudyn_free_modules() -> list[str]:
    """Modules that must import with Exudyn absent: all but model/, solve*, and those importing them
    at module level (run, commands that run models, the sweep's worker preload)."""
    modules = _modules()
    top_level = {}
    for name, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        package = name if _is_package(name, modules) else name.rpartition(".")[0]
        deps = set()
        for node in tree.body:  # module level only: lazy imports inside functions are allowed
            if isinstance(node, ast.ImportFrom):
                base = package.split(".")[:len(package.split(".")) - (node.level - 1)] if node.level else []
                stem = ".".join(base + ([node.module] if node.module else [])) if node.level else node.module
                deps.update(t for t in [stem] + [f"{stem}.{a.name}" for a in node.names] if t in modules)
            elif isinstance(node, ast.Import):
                deps.update(a.name for a in node.names if a.name in modules)
        top_level[name] = deps
    needs = {m for m in modules if EXUDYN_ALLOWED.match(m) or m == "exucable.sweep._preload"}
    changed = True
    while changed:
        changed = False
        for m, deps in top_level.items():
            if m not in needs and deps & needs:
                needs.add(m)
                changed = True
    return sorted(set(modules) - needs - {"exucable.__main__"})  # __main__ runs the command


def test_exudyn_free_modules_import_with_exudyn_blocked():
    free = _exudyn_free_modules()
    for expected in ("exucable.geometry", "exucable.contact", "exucable.contact.fast", "exucable.quasistatic.rope",
                     "exucable.quasistatic.closed_forms", "exucable.scenario.specs", "exucable.post.tension", "exucable.output.results",
                     "exucable.io", "exucable.data.reference_values", "exucable.plots.route", "exucable.output.compare",
                     "exucable.validation.paper", "exucable.sweep"):
        assert expected in free, f"{expected} should not need Exudyn at import"
    script = textwrap.dedent(f"""
        import importlib, sys
        class Block:
            def find_spec(self, name, path=None, target=None):
                if name == "exudyn" or name.startswith("exudyn."):
                    raise ImportError("exudyn is blocked in this test")
        sys.meta_path.insert(0, Block())
        for name in {free!r}:
            importlib.import_module(name)
        assert not any(m == "exudyn" or m.startswith("exudyn.") for m in sys.modules)
        print(len({free!r}))
    """)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                       cwd=ROOT, env=env)
    assert p.returncode == 0, p.stderr
    assert int(p.stdout.strip()) == len(free) > 20


def test_importing_exucable_keeps_the_users_matplotlib_backend():
    script = textwrap.dedent("""
        import matplotlib
        matplotlib.use("svg")
        import importlib, pkgutil, exucable
        for m in pkgutil.walk_packages(exucable.__path__, "exucable."):
            if not m.name.endswith("__main__"):  # that one runs the command
                importlib.import_module(m.name)
        print(matplotlib.get_backend())
    """)
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=180, cwd=ROOT,
                       env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip().splitlines()[-1] == "svg"
    offenders = [str(f.relative_to(ROOT)) for f in PACKAGE.rglob("*.py") if "matplotlib.use(" in f.read_text()]
    assert offenders == []


def test_no_absolute_paths_of_a_development_machine():
    try:
        files = subprocess.run(["git", "ls-files"], capture_output=True, text=True, cwd=ROOT,
                               check=True).stdout.split()
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout")
    pattern = re.compile(r"(?<![\w.])/(work|root|home|Users)/")
    offenders = []
    for rel in files:
        path = ROOT / rel
        if path.is_symlink() or not path.is_file() or path.suffix in (".png", ".pdf"):
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
            if pattern.search(line) and rel != "tests/test_architecture.py":
                offenders.append(f"{rel}:{n}: {line.strip()[:80]}")
    assert offenders == []


def _layout_table() -> list[str]:
    """Paths named in the first column of the README's layout table (``exucable/x.py``, ``y.py``:
    a bare name continues the row's first directory)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text[text.index("## Layout"):]
    section = section[:section.index("\n## ", 3)]
    paths = []
    for line in section.splitlines():
        cells = line.split("|")
        if len(cells) < 3 or not cells[1].strip().startswith("`"):
            continue
        names = re.findall(r"`([^`]+)`", cells[1])
        first = names[0].rstrip("/")
        base = first.rsplit("/", 1)[0] + "/" if "/" in first else ""
        paths += [names[0]] + [n if "/" in n.rstrip("/") else base + n for n in names[1:]]
    return paths


def test_readme_layout_table_matches_the_tree():
    paths = _layout_table()
    assert len(paths) > 10
    missing = [p for p in paths if not (ROOT / p).exists()]
    assert missing == [], "README's layout table names paths that do not exist"
    named = {p.rstrip("/") for p in paths}
    unlisted = [f"exucable/{p.name}" for p in sorted(PACKAGE.iterdir())
                if (p.suffix == ".py" and p.name != "__init__.py" or (p / "__init__.py").is_file())
                and f"exucable/{p.name}" not in named]
    assert unlisted == [], "modules and packages missing from README's layout table (add a row)"


def test_one_atomic_writer():
    """Files are written through exucable.io only (temporary file + os.replace). Not files of
    results: the sweep's lock file (held open, flock'ed, see sweep/store.py); its case directories
    are installed by a rename of a complete directory."""
    lock_file = ("exucable/sweep/store.py", 'f = open(self.path, "a+")')
    writes = re.compile(r"os\.replace\(|mkstemp\(|NamedTemporaryFile\(|\.write_text\(|\.write_bytes\(|"
                        r"open\([^)]*['\"][wax]b?\+?['\"]")
    offenders = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name == "io.py" and path.parent == PACKAGE:
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if (writes.search(line) and not line.lstrip().startswith("#")
                    and (str(path.relative_to(ROOT)), line.strip()) != lock_file):
                offenders.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()}")
    assert offenders == []


def test_plots_import_nothing_above_them():
    """Figures are drawn from data: plots/ may use the writer and the reference values, nothing
    that runs, reads results or builds models."""
    modules = _modules()
    allowed = {"exucable.io", "exucable.data.reference_values", "exucable.data"}
    for name in modules:
        if name.startswith("exucable.plots"):
            above = {m for m in _imports(name, modules) if not m.startswith("exucable.plots")} - allowed
            assert above == set(), f"{name} imports {sorted(above)}"


def test_only_the_command_line_prints_and_exits():
    """Library code returns values and raises; printing and exit statuses belong to commands/,
    cli.py and __main__.py (progress bars write to a stream they are given, not print)."""
    command_line = {"exucable.cli", "exucable.__main__"}
    offenders = []
    for name, path in _modules().items():
        if name in command_line or name.startswith("exucable.commands"):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call):
                f = node.func
                called = f.id if isinstance(f, ast.Name) else f"{getattr(f.value, 'id', '?')}.{f.attr}" \
                    if isinstance(f, ast.Attribute) else ""
                if called in ("print", "exit", "quit", "sys.exit", "os._exit"):
                    offenders.append(f"{name}:{node.lineno} {called}()")
            elif isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call) \
                    and getattr(node.exc.func, "id", "") == "SystemExit":
                offenders.append(f"{name}:{node.lineno} raise SystemExit")
    assert offenders == []


def test_code_and_guides_keep_no_diary():
    """Code, the guides in docs/ and reference/README.md state rules and sources, not when or in which
    working session something was measured: no ISO dates, no sessions (history: CHANGELOG.md and
    docs/decisions/)."""
    diary = re.compile(r"\b20\d\d-\d\d-\d\d\b|(?<!Python )\bsession\b", re.IGNORECASE)
    files = [*PACKAGE.rglob("*.py"), *(ROOT / "docs").glob("*.md"), ROOT / "reference" / "README.md"]
    offenders = [f"{f.relative_to(ROOT)}:{i}" for f in files
                 for i, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1) if diary.search(line)]
    assert offenders == []
