"""Exceptions and warnings raised by dynid.

Every error derives from :class:`DynidError`; each subclass also inherits the matching
builtin (``ValueError``, ``KeyError``, ...) so generic handlers keep working.

An error about a file (or a recording) names it first, ``"log.csv: ..."``, and says so in
its ``file`` attribute: the prefix is written in one place, ``DynidError(text, file=name)``,
and :func:`in_file` names the file in an error raised while a file is processed that does
not name one yet (it reads ``file``, never the message).
"""

from __future__ import annotations

import contextlib
import copy
from collections.abc import Callable, Iterator


class DynidError(Exception):
    """Base class of every error raised by dynid.

    Parameters
    ----------
    *args
        The message (and any other arguments of the builtin).
    file : str, optional
        The file (or recording) the error is about: the message becomes
        ``"{file}: {message}"`` (``"{file}, {at}: {message}"`` with ``at``).
    at : str, optional
        Where in the file (``"line 5, column 'tau1'"``).

    Attributes
    ----------
    file : str or None
        The file (or recording) the message names first; None when it names none.
    """

    file: str | None = None

    def __init__(self, *args: object, file: str | None = None, at: str | None = None) -> None:
        if file is not None:
            where = file if at is None else f"{file}, {at}"
            args = (f"{where}: {args[0]}" if args else where, *args[1:])
        super().__init__(*args)
        if file is not None:
            self.file = file


class ShapeError(DynidError, ValueError):
    """An array has the wrong shape."""


class NonFiniteError(DynidError, ValueError):
    """An array holds NaN or infinite values."""


class UnknownNameError(DynidError, KeyError):
    """A frame, joint, link or column name is not known."""

    def __str__(self) -> str:  # KeyError quotes its message; keep it readable
        return str(self.args[0]) if self.args else ""


class OptionError(DynidError, ValueError):
    """An option or argument has a value outside its range, or options that do not go
    together (the message names them).

    Attributes
    ----------
    field : str or None
        The option at fault as the Python API names it (an options class's field or a
        function's parameter: ``cutoff_hz``), when one is; the message starts with it.
        The command line names it by its flag instead (``--cutoff``).
    others : tuple of str
        Other options the message names, written ``{name}`` in ``reason``.
    reason : str
        The message after the field's name, with ``{name}`` for each of ``others``.

    Examples
    --------
    >>> str(OptionError("applies with {unmodelled} only", field="arm_seed", others=("unmodelled",)))
    'arm_seed applies with unmodelled only'
    """

    def __init__(
        self, message: str, *, field: str | None = None, others: tuple[str, ...] = ()
    ) -> None:
        super().__init__(message if field is None else self.named(message, field, others, str))
        self.field = field
        self.others = tuple(others)
        self.reason = message

    @staticmethod
    def named(reason: str, field: str, others: tuple[str, ...], name: Callable[[str], str]) -> str:
        """The message with each option named by ``name`` (``str``: as the Python API
        names it; the command line gives its flags)."""
        for other in others:
            reason = reason.replace("{" + other + "}", name(other))
        return name(field) + ("" if reason[:1] in (",", ":", ";") else " ") + reason


class WrongTypeError(DynidError, TypeError):
    """An argument has the wrong type (the message names it)."""


class ModelError(DynidError, ValueError):
    """A robot description is malformed or cannot be modelled."""


class DataError(DynidError, ValueError):
    """A data set or log file is malformed."""


class OutputError(DynidError):
    """An output cannot be written as asked (read-only, or holding files of another run)."""


class LimitError(DynidError, ValueError):
    """A value lies outside the robot's limits where that matters."""


class RankDeficientError(DynidError, ValueError):
    """A regressor does not have the rank needed to identify the parameters.

    Attributes
    ----------
    rank : int or None
        The numerical rank found (None when not computed).
    needed : int or None
        The rank needed: the number of columns (coefficients) to identify.
    dependent : tuple of str
        Labels of the nearly dependent columns (the null direction's large entries,
        largest first); empty when not known.
    combinations : tuple of str
        Every combination of the columns the data do not excite (``needed - rank`` of
        them, ``"beta40 - 0.31*fc6"``); empty when not known.
    redundant : tuple of str
        The label naming each of those combinations (its first): without these columns
        the others have full rank (``("beta40",)``); empty when not known.
    structural : tuple of str
        The combinations that vanish at every state of the model, which no data identify
        (:func:`~dynid.identification.structural.structural_rank`; ``redundant`` then names
        these first); empty when none or not checked.
    """

    def __init__(
        self,
        message: str,
        *,
        rank: int | None = None,
        needed: int | None = None,
        dependent: tuple[str, ...] = (),
        combinations: tuple[str, ...] = (),
        redundant: tuple[str, ...] = (),
        structural: tuple[str, ...] = (),
    ) -> None:
        super().__init__(message)
        self.rank = rank
        self.needed = needed
        self.dependent = tuple(dependent)
        self.combinations = tuple(combinations)
        self.redundant = tuple(redundant)
        self.structural = tuple(structural)


class InfeasibleError(DynidError, ValueError):
    """A specification of physical parameters cannot be met."""


class ConvergenceError(DynidError, RuntimeError):
    """An iterative method did not converge."""


class DynidWarning(UserWarning):
    """A recoverable problem: ill-conditioning, inconsistent inertials, dropped data."""


class SolverError(DynidError, RuntimeError):
    """A numerical solver failed (its status is named in the message)."""


def named_file(exc: DynidError, name: str) -> DynidError:
    """``exc`` naming the file (or recording) ``name``: itself when it names one already
    (``exc.file``) or is about an option (an :class:`OptionError` with a ``field``, which the
    command line names by its flag), else a copy of the same class and attributes whose
    message starts with ``"{name}: "``."""
    if exc.file is not None or (isinstance(exc, OptionError) and exc.field is not None):
        return exc
    out = copy.copy(exc)
    out.args = (f"{name}: {exc.args[0]}" if exc.args else name, *exc.args[1:])
    out.file = name
    return out


@contextlib.contextmanager
def in_file(name: str) -> Iterator[None]:
    """Run the ``with`` block naming the file ``name`` in a :class:`DynidError` raised
    inside that names none (:func:`named_file`): the one place where an error is given
    the name of the file being processed.

    Raises
    ------
    DynidError
        What the block raises, its message starting with a file's name (``name`` unless
        the error named its own, or is about an option).
    """
    try:
        yield
    except DynidError as exc:
        out = named_file(exc, name)
        if out is exc:
            raise
        raise out from exc
