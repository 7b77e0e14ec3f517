"""Exceptions and warnings raised by dynid.

Every error derives from :class:`DynidError`; each subclass also inherits the matching
builtin (``ValueError``, ``KeyError``, ...) so generic handlers keep working.
"""

from __future__ import annotations

from collections.abc import Callable


class DynidError(Exception):
    """Base class of every error raised by dynid."""


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
    """

    def __init__(
        self,
        message: str,
        *,
        rank: int | None = None,
        needed: int | None = None,
        dependent: tuple[str, ...] = (),
        combinations: tuple[str, ...] = (),
    ) -> None:
        super().__init__(message)
        self.rank = rank
        self.needed = needed
        self.dependent = tuple(dependent)
        self.combinations = tuple(combinations)


class InfeasibleError(DynidError, ValueError):
    """A specification of physical parameters cannot be met."""


class ConvergenceError(DynidError, RuntimeError):
    """An iterative method did not converge."""


class DynidWarning(UserWarning):
    """A recoverable problem: ill-conditioning, inconsistent inertials, dropped data."""


class SolverError(DynidError, RuntimeError):
    """A numerical solver failed (its status is named in the message)."""
