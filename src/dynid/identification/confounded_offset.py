"""A torque offset left out that the data cannot tell from a link parameter: ``identify``'s
note.

A joint moved over a narrow range of positions gives gravity columns that hardly change
there: a centre of mass along ``cos(q)`` is then nearly a constant, which a torque offset
is too. The structure search judges the offset on held-out data of the same poses, which
do not miss it (the link parameter takes it up), and its coefficient is loose in the fit
that holds it (its standard deviation large because of that collinearity): it is left
out, and the link parameter carries the offset (a Kinova arm, joint 2 within 2.6..3.7 rad,
``fo2 = -0.10 N m`` left out and ``mc2x`` 0.0100 kg m against 0, 14 standard deviations
off), wrong at other poses.

:func:`confounded_offsets` fits, on the training's prepared samples, the model's columns
with each offset left out added back, and reads from that fit the offset's variance
inflation (its variance over what it would be were it the only column:
``1 / (1 - R^2)`` of the offset's column on the others, each joint's rows weighed by its
residual's noise), its relative standard deviation and the coefficient its estimate is
most correlated with. One whose inflation is at least :data:`INFLATION` and whose relative
standard deviation is above
:data:`~dynid.identification.candidates.DETERMINED_STD_PERCENT` is named
(:meth:`ConfoundedOffset.sentence`), with the joint's range of positions in training.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .candidates import DETERMINED_STD_PERCENT
from .log import TorqueLog
from .log_rows import term_regressor
from .model import IdentifiedModel
from .residual_dependence import offsets_of

__all__ = ["INFLATION", "ConfoundedOffset", "confounded_offsets", "with_confounded_offsets"]

#: An offset whose variance the other columns inflate at least this many times (its
#: standard deviation 10 times what it would be alone) is confounded with them.
INFLATION = 100.0
#: Samples at most the check fits (every k-th of the prepared pieces).
MAX_SAMPLES = 4000


@dataclass(frozen=True)
class ConfoundedOffset:
    """A joint's offset left out that the data cannot tell from a link parameter.

    Attributes
    ----------
    joint : int
        The joint (0-based).
    label : str
        The offset's label (``fo2``).
    value, std_percent : float
        The offset [N m] fitted with the model's columns, and its relative standard
        deviation [%] there.
    inflation : float
        Its variance over what it would be as the only column.
    partner : str
        The coefficient its estimate is most correlated with, with what it holds
        (``beta2 = mc2x``).
    correlation : float
        That correlation, -1 to 1.
    position_range : (float, float) or None
        The joint's lowest and highest position in training [rad or m].
    """

    joint: int
    label: str
    value: float
    std_percent: float
    inflation: float
    partner: str
    correlation: float
    position_range: tuple[float, float] | None

    def sentence(self, joint_name: str, unit: str = "rad", terms: str | None = None) -> str:
        """The note: the joint, its range in training, the parameter and the remedies
        (``terms``: the chosen structure's ``--terms`` that keep the offset)."""
        where = ""
        if self.position_range is not None:
            lo, hi = self.position_range
            where = f" (it moved only within {lo:.3g}..{hi:.3g} {unit} in training)"
        return (
            f"joint {self.joint + 1} ({joint_name}): its torque offset {self.label} was left "
            f"out, but the data cannot tell it from {self.partner}{where}: fitted with it, "
            f"{self.label} = {self.value:+.3g} N m +- {self.std_percent:.3g} %, correlated "
            f"{self.correlation:+.3f} with it (its variance {self.inflation:.3g} x what it "
            f"would be alone), so {self.partner.split(' = ')[0]} carries whatever offset there "
            f"is, right at these poses only; hint: --terms {terms or '...,offset'} keeps it, "
            "or record poses over a wider range of that joint"
        )

    def as_dict(self) -> dict[str, object]:
        """JSON-ready: ``joint`` (from 1), ``label``, ``value`` [N m], ``std_percent``,
        ``inflation``, ``partner``, ``correlation`` and ``position_range``."""
        return {
            "joint": self.joint + 1,
            "label": self.label,
            "value": self.value,
            "std_percent": self.std_percent,
            "inflation": self.inflation,
            "partner": self.partner,
            "correlation": self.correlation,
            "position_range": None if self.position_range is None else list(self.position_range),
        }


def _columns(
    model: IdentifiedModel, pieces: Sequence[TorqueLog]
) -> tuple[NDArray[np.float64], NDArray[np.float64], tuple[str, ...], NDArray[np.bool_]]:
    """The model's columns (N, n, c) at every k-th prepared sample (at most
    :data:`MAX_SAMPLES`), the torques (N, n), the columns' labels and which the model
    keeps."""
    total = sum(p.n_samples for p in pieces)
    step = max(1, int(np.ceil(total / MAX_SAMPLES)))
    q = np.concatenate([p.q[::step] for p in pieces])
    dq = np.concatenate([p.dq[::step] for p in pieces])
    ddq = np.concatenate([p.ddq[::step] for p in pieces if p.ddq is not None])
    tau = np.concatenate([p.tau[::step] for p in pieces])
    terms = tuple(t.term for t in model.terms.values())
    Y, labels = term_regressor(model.robot, model.base, terms, q, dq, ddq)
    kept = np.concatenate([np.asarray(model.fit.kept)] + [t.kept for t in model.appended])
    return Y, tau, labels, kept


def _expression(model: IdentifiedModel, labels: Sequence[str], k: int) -> str:
    """Column ``k``'s label with the standard parameters it holds (a base parameter's)."""
    r = model.base.rank
    if k < r and model.base.expressions[k] != labels[k]:
        return f"{labels[k]} = {model.base.expressions[k]}"
    return labels[k]


def _judged(
    A: NDArray[np.float64], b: NDArray[np.float64], o: int
) -> tuple[float, float, float, int, float]:
    """Least squares of ``b`` on the columns ``A`` (unit-noise rows): column ``o``'s
    value, standard deviation, variance inflation, its most correlated column and that
    correlation."""
    norms = np.linalg.norm(A, axis=0)
    norms[norms == 0] = 1.0
    As = A / norms
    x, *_ = np.linalg.lstsq(As, b, rcond=None)
    dof = max(A.shape[0] - A.shape[1], 1)
    s2 = float(np.sum((b - As @ x) ** 2)) / dof
    C = np.linalg.pinv(As.T @ As)
    d = np.sqrt(np.clip(np.diag(C), 1e-300, None))
    corr = C[o] / (d[o] * d)
    corr[o] = 0.0
    k = int(np.argmax(np.abs(corr)))
    value, std = float(x[o] / norms[o]), float(np.sqrt(s2 * C[o, o]) / norms[o])
    return value, std, float(C[o, o]), k, float(corr[k])


def confounded_offsets(
    model: IdentifiedModel, pieces: Sequence[TorqueLog]
) -> tuple[ConfoundedOffset, ...]:
    """The joints whose offset ``model`` left out and the data of ``pieces`` (the
    training's prepared pieces, joint side) cannot tell from another coefficient (module
    docstring); empty when none, or the pieces lack accelerations."""
    left = {j: lab for j, (lab, held) in offsets_of(model).items() if not held}
    if not left or not pieces or any(p.ddq is None for p in pieces):
        return ()
    Y, tau, labels, kept = _columns(model, pieces)
    cols = np.flatnonzero(kept)
    fitted, *_ = np.linalg.lstsq(Y[..., cols].reshape(-1, cols.size), tau.ravel(), rcond=None)
    rest = tau - Y[..., cols] @ fitted
    noise = np.sqrt(np.mean(rest**2, axis=0))
    w = 1.0 / np.where(noise > 0, noise, 1.0)
    ranges = None if model.info.log is None else model.info.log.position_range
    found = []
    base = Y[..., cols]
    for j, label in sorted(left.items()):
        offset = np.zeros(base.shape[:-1] + (1,))
        offset[:, j] = 1.0  # a constant torque at the joint [N m]
        A = (np.concatenate([base, offset], axis=-1) * w[:, None]).reshape(-1, cols.size + 1)
        value, std, inflation, k, corr = _judged(A, (tau * w).ravel(), cols.size)
        rel = 100 * std / abs(value) if value != 0 else np.inf
        if inflation >= INFLATION and rel > DETERMINED_STD_PERCENT:
            found.append(
                ConfoundedOffset(
                    j, label, value, float(rel), inflation,
                    _expression(model, labels, int(cols[k])), corr,
                    None if ranges is None else (ranges[j][0], ranges[j][1]),
                )
            )  # fmt: skip
    return tuple(found)


def _kept_terms(model: IdentifiedModel, label: str) -> str | None:
    """The chosen structure's ``--terms`` without the leave-out of ``label`` (None: the
    structure is not recorded)."""
    terms = model.info.extra.get("terms")
    if not isinstance(terms, list | tuple) or not terms:
        return None
    return ",".join(str(t) for t in terms if str(t) != f"-{label}")


def with_confounded_offsets(
    model: IdentifiedModel, pieces: Sequence[TorqueLog]
) -> tuple[IdentifiedModel, tuple[str, ...]]:
    """``model`` with a note per offset left out that its training ``pieces`` cannot tell
    from another coefficient (:func:`confounded_offsets`) in its notes and with
    ``metadata.confounded_offsets`` (each :meth:`ConfoundedOffset.as_dict`), and the notes;
    ``model`` itself and none when there is none."""
    found = confounded_offsets(model, pieces)
    if not found:
        return model, ()
    names = model.robot.joint_names
    units = ["m" if p else "rad" for p in model.robot.prismatic]
    said = tuple(
        c.sentence(names[c.joint], units[c.joint], _kept_terms(model, c.label)) for c in found
    )
    info = dataclasses.replace(
        model.info,
        notes=(*model.info.notes, *said),
        extra={**model.info.extra, "confounded_offsets": [c.as_dict() for c in found]},
    )
    return dataclasses.replace(model, info=info), said
