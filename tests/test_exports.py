"""The names ``dynid`` exports: its three hand-kept lists agree, and every error is exported.

``dynid/__init__.py`` holds the names three times: the static imports for type checkers
(under ``TYPE_CHECKING``), the lazy table ``_LAZY`` (name -> module, attribute) and
``__all__``. The references here are the source files themselves (their ``__all__`` and
the classes defined in ``exceptions.py``), read independently of the lazy table.
"""

from __future__ import annotations

import ast
import importlib
import inspect
from pathlib import Path

import dynid
from dynid import exceptions

INIT = Path(dynid.__file__)


def _type_checking_imports() -> dict[str, tuple[str, str]]:
    """Name -> (module under dynid, attribute) of the imports under ``if TYPE_CHECKING:``."""
    tree = ast.parse(INIT.read_text())
    block = next(
        n for n in tree.body if isinstance(n, ast.If) and ast.unparse(n.test) == "TYPE_CHECKING"
    )
    out = {}
    for node in block.body:
        assert isinstance(node, ast.ImportFrom) and node.level == 1, ast.unparse(node)
        for alias in node.names:
            out[alias.asname or alias.name] = (node.module, alias.name)
    return out


def _error_classes() -> set[str]:
    """Every exception and warning class defined in dynid/exceptions.py."""
    return {
        name
        for name, obj in vars(exceptions).items()
        if inspect.isclass(obj)
        and obj.__module__ == exceptions.__name__
        and issubclass(obj, exceptions.DynidError | exceptions.DynidWarning)
    }


def test_every_name_in_all_is_importable():
    """``from dynid import X`` works for every X in ``__all__``, and no name is listed twice."""
    assert len(dynid.__all__) == len(set(dynid.__all__))
    for name in dynid.__all__:
        assert getattr(dynid, name) is not None, name


def test_every_error_class_is_exported():
    """Each DynidError subclass (and DynidWarning) is in ``__all__`` as the class itself."""
    errors = _error_classes()
    assert {"DynidError", "OptionError", "WrongTypeError", "OutputError"} <= errors
    assert errors <= set(dynid.__all__), sorted(errors - set(dynid.__all__))
    for name in errors:
        assert getattr(dynid, name) is getattr(exceptions, name)


def test_the_three_lists_agree():
    """TYPE_CHECKING imports == the lazy table == ``__all__`` without errors and version."""
    static = _type_checking_imports()
    lazy = dynid._LAZY
    assert static == lazy
    assert set(dynid.__all__) == set(lazy) | _error_classes() | {"__version__"}


def test_lazy_names_are_public_names_of_their_modules():
    """Each lazily exported name is in its defining module's ``__all__``, and in its
    subpackage's ``__all__`` where the subpackage keeps one (kinematics, feasibility, ...)."""
    for name, (module, attr) in dynid._LAZY.items():
        mod = importlib.import_module(f"dynid.{module}")
        assert attr in mod.__all__, f"{name}: {attr} not in dynid.{module}.__all__"
        package = importlib.import_module(f"dynid.{module.split('.')[0]}")
        if hasattr(package, "__all__") and package.__name__ != mod.__name__:
            assert attr in package.__all__, f"{name}: not in {package.__name__}.__all__"
        assert getattr(dynid, name) is getattr(mod, attr)
