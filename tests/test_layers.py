"""Architecture: each module imports only from its own layer or an earlier one."""

from __future__ import annotations

import ast
import functools
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "dynid"

#: Layers in data-flow order (ARCHITECTURE.md, "Layers").
LAYERS = [
    {
        "exceptions",
        "_checks",
        "_kernels",
        "_memo",
        "_parallel",
        "_times",
        "progress",
        "spatial",
        "butterworth",
        "signals",
    },
    {"model"},
    {"kinematics"},
    {"dynamics"},
    {"regressors"},
    {"identification"},
    {"friction"},
    {"simulation"},
    {"feasibility"},
    {"observer"},
    {"pipeline"},
    {"io"},
    {"outputs"},
    {"report"},
    {"workflows"},
    {"plots"},
    {"cli", "__main__"},
]


def _layer(part: str) -> int | None:
    for k, names in enumerate(LAYERS):
        if part in names:
            return k
    return None


def _module_layer(path: Path) -> int | None:
    rel = path.relative_to(SRC).with_suffix("")
    return _layer(rel.parts[0])


@functools.cache
def _tree(path: Path) -> ast.Module:
    """The parsed source of ``path`` (parsed once for every test of this file)."""
    return ast.parse(path.read_text())


def _imported_parts(path: Path) -> list[str]:
    tree = _tree(path)
    rel = path.relative_to(SRC)
    pkg = list(rel.parts[:-1])
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg[: len(pkg) - (node.level - 1)]
                target = base + (node.module.split(".") if node.module else [])
                if not target:  # "from . import x" at the package root
                    target = [a.name for a in node.names]
                    out += target
                    continue
                out.append(target[0])
            elif node.module and node.module.startswith("dynid."):
                out.append(node.module.split(".")[1])
        elif isinstance(node, ast.Import):
            out += [a.name.split(".")[1] for a in node.names if a.name.startswith("dynid.")]
    return out


#: The only imports of a later layer, each inside one function (imported when called):
#: ``Robot.from_urdf`` and ``Robot.from_toml`` are facades over the readers of io/robot, so
#: that ``dynid.Robot.from_urdf(path)`` keeps working while the model layer holds no file
#: format and importing it loads no reader. ``panda`` builds its published sigmoid friction
#: as the one friction type, whose laws are a later layer's registry (importing the model
#: layer loads no law). (module, function) -> the later package.
FACADES = {
    ("model/robot.py", "from_urdf"): "io",
    ("model/robot.py", "from_toml"): "io",
    ("model/panda.py", "panda"): "friction",
}


def _facade_imports(path: Path) -> list[tuple[str, str]]:
    """(function, imported part) of the imports inside the listed facade functions."""
    rel = path.relative_to(SRC).as_posix()
    out: list[tuple[str, str]] = []
    if rel not in {module for module, _ in FACADES}:
        return out
    for node in ast.walk(_tree(path)):
        if isinstance(node, ast.FunctionDef) and (rel, node.name) in FACADES:
            for sub in ast.walk(node):
                if isinstance(sub, ast.ImportFrom) and sub.level and sub.module:
                    pkg = list(path.relative_to(SRC).parts[:-1])
                    base = pkg[: len(pkg) - (sub.level - 1)]
                    out.append((node.name, (base + sub.module.split("."))[0]))
    return out


def test_modules_import_only_from_earlier_or_same_layers():
    """No module imports from a later layer of the data flow (but the listed facades)."""
    bad = []
    for path in SRC.rglob("*.py"):
        own = _module_layer(path)
        if own is None:
            continue
        allowed = [part for _, part in _facade_imports(path)]
        for part in _imported_parts(path):
            dep = _layer(part)
            if dep is not None and dep > own:
                if part in allowed:
                    allowed.remove(part)
                    continue
                bad.append(f"{path.relative_to(SRC)} imports {part}")
    assert not bad, "layering violations:\n" + "\n".join(bad)


def test_facades_import_what_they_are_listed_for():
    """Each listed facade exists and imports its later package (the list holds no stale entry)."""
    for (module, function), part in FACADES.items():
        assert (function, part) in _facade_imports(SRC / module), (module, function)


def test_every_package_is_assigned_a_layer():
    """Every subpackage and top-level module of dynid belongs to a layer."""
    names = {p.stem for p in SRC.glob("*.py")} | {p.name for p in SRC.iterdir() if p.is_dir()}
    names -= {"__init__", "__pycache__", "py.typed"}
    assert {n for n in names if _layer(n) is None} == set()


def test_import_dynid_does_not_load_matplotlib():
    """Importing the library keeps matplotlib unloaded (figures import it lazily)."""
    import subprocess
    import sys

    code = "import sys, dynid; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_command_help_loads_neither_scipy_nor_numba_nor_matplotlib():
    """``dynid --help`` and each subcommand's ``--help`` import no scipy, numba or
    matplotlib (start-up time: the parsers need the library's light modules only)."""
    import subprocess
    import sys

    code = (
        "import contextlib, io, sys\n"
        "from dynid.cli.__main__ import SUBCOMMANDS, main\n"
        "for argv in [[], *([c.replace('_', '-')] for c in SUBCOMMANDS)]:\n"
        "    if argv == ['import-bag']:\n"
        "        argv = ['import']\n"
        "    with contextlib.redirect_stdout(io.StringIO()) as out:\n"
        "        assert main([*argv, '--help']) == 0, argv\n"
        "    assert 'usage: dynid' in out.getvalue(), argv\n"
        "heavy = sorted(m for m in ('scipy', 'numba', 'matplotlib') if m in sys.modules)\n"
        "print(' '.join(heavy))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "", f"imported by --help: {out.stdout.strip()}"


def test_io_exports_every_public_name_lazily_and_only_save_load_verbs():
    """dynid.io resolves each exported name on first use; every file verb is save_/load_."""
    import importlib
    import re

    io = importlib.import_module("dynid.io")
    for name in io.__all__:
        assert callable(getattr(io, name)), name
        assert name.startswith(("save_", "load_")), name
    defs = set()
    for path in (SRC / "io").rglob("*.py"):
        defs |= set(re.findall(r"^def ((?:read|write)_\w+)\(", path.read_text(), re.M))
    assert defs <= {"write_text", "write_bytes"}, sorted(defs)  # the atomic primitives only


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    return ".".join(["dynid", *(parts[:-1] if parts[-1] == "__init__" else parts)])


def _imports(path: Path, top_level_only: bool, type_only: bool = False) -> list[tuple[str, str]]:
    """(module, name) of each ``from dynid... import name`` of ``path``, absolute; only the
    statements run on import when ``top_level_only`` (not in functions or TYPE_CHECKING),
    those under TYPE_CHECKING too with ``type_only``."""
    own = _module_name(path).split(".")
    pkg = own if path.name == "__init__.py" else own[:-1]
    out = []

    def visit(body: list[ast.stmt]) -> None:
        for node in body:
            if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
                if type_only:
                    visit(node.body)
                continue
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = pkg[: len(pkg) - (node.level - 1)]
                    module = ".".join(base + (node.module.split(".") if node.module else []))
                else:
                    module = node.module or ""
                if module.startswith("dynid"):
                    out.extend((module, a.name) for a in node.names)
            elif isinstance(node, ast.Import):
                out.extend((a.name, "") for a in node.names if a.name.startswith("dynid"))
            if isinstance(node, ast.If | ast.Try | ast.With):
                visit(node.body)
                visit(getattr(node, "orelse", []))
                for h in getattr(node, "handlers", []):
                    visit(h.body)
                visit(getattr(node, "finalbody", []))
            elif not top_level_only and isinstance(
                node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef
            ):
                visit(node.body)

    visit(_tree(path).body)
    return out


def test_no_function_over_120_lines_outside_the_compiled_kernels():
    """Long functions are split into named steps; the numba kernels of _kernels/ may not be
    (a call between compiled functions is not free in a per-sample loop)."""
    long = [
        f"{path.relative_to(SRC)}:{node.lineno} {node.name} ({node.end_lineno - node.lineno + 1})"
        for path in SRC.rglob("*.py")
        if path.relative_to(SRC).parts[0] != "_kernels"
        for node in ast.walk(_tree(path))
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
        and node.end_lineno is not None
        and node.end_lineno - node.lineno + 1 > 120
    ]
    assert not long, long


def test_no_private_name_is_imported_from_another_package():
    """A private name (``_x``) is imported only inside its own subpackage; the shared private
    modules of the root (``dynid._checks``, ``dynid._kernels``, ``dynid._parallel``) are
    imported as modules."""
    modules = {_module_name(p) for p in SRC.rglob("*.py")}
    bad = []
    for path in SRC.rglob("*.py"):
        mine = _module_name(path).split(".")[:2]
        for module, name in _imports(path, top_level_only=False):
            full = f"{module}.{name}"
            if not name.startswith("_") or name.startswith("__"):
                continue
            if full in modules and full.count(".") == 1:  # a root private module
                continue
            if module.split(".")[:2] != mine:
                bad.append(f"{path.relative_to(SRC)} imports {full}")
    assert not bad, bad


def test_no_import_circle():
    """The modules' import-time dependencies, type-only ones (under TYPE_CHECKING) included,
    form no cycle (depth-first search)."""
    modules = {_module_name(p): p for p in SRC.rglob("*.py")}
    graph = {
        name: {
            f"{m}.{n}" if f"{m}.{n}" in modules else m
            for m, n in _imports(path, top_level_only=True, type_only=True)
        }
        & (modules.keys() - {name})
        for name, path in modules.items()
    }
    state: dict[str, int] = {}  # 1: on the current path, 2: done

    def cycle_from(v: str, path: list[str]) -> list[str] | None:
        state[v] = 1
        for w in sorted(graph[v]):
            if state.get(w) == 1:
                return [*path, v, w]
            if w not in state and (found := cycle_from(w, [*path, v])):
                return found
        state[v] = 2
        return None

    for v in sorted(graph):
        if v not in state:
            found = cycle_from(v, [])
            assert found is None, " -> ".join(found or [])
