"""Which options apply to which route of a command: each command's table ``APPLIES``,
checked once by :func:`dynid.cli.__main__.main` before the command runs.

An option the command line gave (not a default) whose route the run does not take
(``--harmonics`` with ``--trajectory sinusoid``, ``--base`` with a built-in robot, ``--seed``
with the convex method) is refused in one line naming it and the route it applies to,
rather than accepted and ignored. Values the library's typed options can tell apart from
their defaults are refused there too, for the Python API (``OptionError`` with ``field``).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..exceptions import OptionError

__all__ = [
    "Applies",
    "check_applies",
    "given_options",
    "is_urdf",
    "urdf_chain",
]


@dataclass(frozen=True, slots=True)
class Applies:
    """Options (argparse dests) that apply only on one route of a command.

    Attributes
    ----------
    options : tuple of str
        The dests (``"base_freq"`` for ``--base-freq``).
    when : callable
        ``when(args)`` is True on the route where they apply.
    route : str
        The route as the user names it (``"--trajectory fourier"``), for the message.
    why : str
        Why they do not apply elsewhere, when the route does not say it.
    """

    options: tuple[str, ...]
    when: Callable[[argparse.Namespace], bool]
    route: str
    why: str = ""


def is_urdf(spec: object) -> bool:
    """``spec`` (an option's value) names a ``.urdf`` file."""
    return isinstance(spec, str | Path) and str(spec).lower().endswith(".urdf")


def urdf_chain(
    robot: str = "robot",
    options: tuple[str, ...] = ("base", "tip", "snap_angles"),
    also: tuple[str, ...] = (),
) -> Applies:
    """``--base``/``--tip`` (and ``--snap-angles``) apply to a URDF ``--robot`` (the
    option ``robot``, or one of ``also``: a ``--params`` read as ``--robot`` reads it)
    only: a built-in robot, a TOML or a feasible.json has one chain."""
    names = (robot, *also)
    flags = " or ".join("--" + x.replace("_", "-") for x in names)
    return Applies(
        options, lambda a: any(is_urdf(getattr(a, x, None)) for x in names), f"a URDF {flags}"
    )


def given_options(parser: argparse.ArgumentParser, argv: Sequence[str]) -> frozenset[str]:
    """The dests of the options ``argv`` gives (defaults left out): ``argv`` parsed once
    more with every default suppressed. ``parser`` is built for this one run (its
    defaults are changed)."""
    stack = [parser]
    while stack:
        p = stack.pop()
        for action in p._actions:
            action.default = argparse.SUPPRESS
            if isinstance(action, argparse._SubParsersAction):
                stack.extend(action.choices.values())
        p._defaults.clear()
    given = vars(parser.parse_args(list(argv)))
    return frozenset(k for k in given if k != "command")


def check_applies(args: argparse.Namespace, given: Iterable[str], table: Iterable[Applies]) -> None:
    """Refuse the first option of ``given`` that ``table`` says does not apply to the
    route ``args`` takes.

    Raises
    ------
    OptionError
        ``field`` the option: "applies to ROUTE only; leave it out".
    """
    given = set(given)
    for rule in table:
        if rule.when(args):
            continue
        for dest in rule.options:
            if dest in given:
                why = f" ({rule.why})" if rule.why else ""
                raise OptionError(f"applies to {rule.route} only{why}; leave it out", field=dest)
