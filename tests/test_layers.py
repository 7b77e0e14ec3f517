"""Architecture: each module imports only from its own layer or an earlier one."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "dynid"

#: Layers in data-flow order (ARCHITECTURE.md, "Layers").
LAYERS = [
    {"exceptions", "_checks", "_kernels", "_parallel", "spatial", "signals"},
    {"model"},
    {"kinematics"},
    {"dynamics"},
    {"regressors"},
    {"identification"},
    {"friction"},
    {"simulation"},
    {"feasibility"},
    {"pipeline"},
    {"io"},
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


def _imported_parts(path: Path) -> list[str]:
    tree = ast.parse(path.read_text())
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
#: format and importing it loads no reader. (module, function) -> the later package.
FACADES = {
    ("model/robot.py", "from_urdf"): "io",
    ("model/robot.py", "from_toml"): "io",
}


def _facade_imports(path: Path) -> list[tuple[str, str]]:
    """(function, imported part) of the imports inside the listed facade functions."""
    rel = path.relative_to(SRC).as_posix()
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
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
