"""How far the torques of a log lag its positions, read from a fit's residual.

Sensor filtering and bus latency put the measured torques a few milliseconds behind the
positions they belong to: ``tau_measured(t) = tau(t - delta)``. To first order
``tau(t - delta) = tau(t) - delta d(tau)/dt``, so the residual
``e = tau_measured - tau_model`` holds
``-delta d(tau_model)/dt``; the fit takes what of it its own columns can (a Panda's joint 2:
``delta dg2/dq2`` on the viscous column, +0.087 N m s/rad for 2 ms), the rest stays in the
residual. :func:`torque_delay` fits the residual, each joint weighed by its RMS less what
the columns beside take, with the column ``-d(tau_model)/dt`` beside the model's own columns
(their share of the delay taken back: the coefficient is ``delta`` itself), the derivative
taken within each prepared piece (never across a gap) of the rigid-body prediction
(friction's steps at a reversal are no first-order term). One delay common to every joint (a
bus) with its standard deviation over the pieces' serially correlated residual
(:mod:`~dynid.identification.serial`: Newey-West) or, when larger, over the spread of
:data:`BLOCKS` contiguous time blocks' delays (a model error the residual holds, correlated
over seconds, moves the delay from block to block more than the noise does), and each
joint's alone for the report.

The delay is named (:attr:`TorqueDelay.named`) when it stands :data:`SIGNIFICANT` standard
deviations clear, explains at least :data:`SHARE` of the residual's weighted sum of squares
and is at most :data:`MAX_DELAY_S` (a sensor's or a bus's); :meth:`TorqueDelay.sentence`
then says it with the hint to ``--torque-delay``, which reads the states that much earlier
before filtering (:attr:`~dynid.identification.prepare.Preprocessing.torque_delay_s`); of a
model's validation, :meth:`TorqueDelay.sentence` with ``refit`` says to identify again with
the whole delay (the model's coefficients bent to it), and of a description's, without a
fit, only the pairing. :class:`AppliedDelay` is the delay a command prepared its logs with
and where it came from (given, or the model's record).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from .serial import SerialMeat, serial_of_pieces
from .solvers import tall_r

__all__ = [
    "BLOCKS",
    "MAX_DELAY_S",
    "SHARE",
    "SIGNIFICANT",
    "AppliedDelay",
    "TorqueDelay",
    "applied_delay",
    "delay_decimals",
    "ms_text",
    "torque_delay",
]

#: Smallest ratio of the delay to its standard deviation for the delay to be named.
SIGNIFICANT = 3.0
#: Smallest share of the residual's weighted sum of squares the delay must explain.
SHARE = 0.01
#: The largest delay [s] named: a sensor's filter or a bus lags the torques a few
#: milliseconds to a few tens (a first-order 10 Hz filter's group delay is 16 ms); beyond
#: it the first-order column stands in for a model error (a description's friction ten
#: times off read as the torques leading by 155 ms), not a lag.
MAX_DELAY_S = 0.05
#: Contiguous time blocks of the pieces whose delays' spread the standard deviation covers.
BLOCKS = 8
#: Fewest samples of a piece whose derivative is taken.
_MIN_SAMPLES = 5


@dataclass(frozen=True, slots=True)
class TorqueDelay:
    """The lag of the torques behind the positions a residual points to.

    Attributes
    ----------
    delay_s : float
        The delay common to every joint [s] (positive: the torques late).
    std_s : float
        Its standard deviation [s]: Newey-West within each piece, or the spread of
        :data:`BLOCKS` time blocks' delays when larger.
    share : float
        The share of the residual's weighted sum of squares the common delay explains.
    joints_s, joints_std_s : tuple of float
        Each joint's own delay and its standard deviation [s] (nan where the joint's
        prediction does not change, and every joint's when the common delay is not
        named: they are read for the report of a named delay only).
    """

    delay_s: float
    std_s: float
    share: float
    joints_s: tuple[float, ...]
    joints_std_s: tuple[float, ...]

    @property
    def plausible(self) -> bool:
        """Whether the delay is within :data:`MAX_DELAY_S` of 0 (a sensor's filter or a
        bus; beyond it, a model error the first-order column took, not a lag)."""
        return bool(abs(self.delay_s) <= MAX_DELAY_S)

    @property
    def named(self) -> bool:
        """Whether the delay stands :data:`SIGNIFICANT` standard deviations clear,
        explains at least :data:`SHARE` of the residual and is :attr:`plausible`."""
        clear = abs(self.delay_s) > SIGNIFICANT * self.std_s
        return bool(clear and self.share >= SHARE and self.plausible)

    def sentence(self, applied_s: float = 0.0, *, refit: bool = False, fit: bool = True) -> str:
        """The delay in words with the option that removes it: ``--torque-delay`` with the
        whole delay, ``applied_s`` [s] (the one the logs were prepared with, to which the
        residual's is added) and this one. ``refit``: of an identified model's
        validation, whose coefficients were fitted to torques this late (viscous friction
        bends to the lag), so that the remedy is to identify again with it. ``fit``
        (without ``refit``): the residual is a fit's, on these logs (``identify``'s), which
        bends to the lag; False: a prediction without a fit (a robot description
        validated), of which only the pairing is said."""
        ms, sd = 1e3 * self.delay_s, 1e3 * self.std_s
        late = "lag" if ms > 0 else "lead"
        d = delay_decimals(sd)  # the delay to its std's first digit (2.06 +- 0.03, not 2.1)
        whole = f"{1e3 * applied_s + ms:.{d}f}"
        said = (
            f"the torques {late} the positions by {abs(ms):.{d}f} ms (+- {sd:.{d}f} ms; "
            f"{100 * self.share:.2g} % of the residual; a filtered sensor or the bus)"
        )
        if applied_s:
            said += f" beyond the {ms_text(1e3 * applied_s)} ms the logs were prepared with"
        if refit:
            return (
                f"{said}: the model's coefficients were fitted to torques this late (viscous "
                f"friction first); hint: identify it again with --torque-delay {whole}, "
                f"then validate the new model (validate --torque-delay {whole} only pairs "
                "this log's torques with its positions)"
            )
        bends = ": the fit bends to it (viscous friction first)" if fit else ""
        return (
            f"{said}{bends}; hint: --torque-delay {whole} pairs the torques with the "
            "positions they belong to before filtering"
        )

    @property
    def joints_clear(self) -> tuple[bool, ...]:
        """Per joint, whether its own delay stands :data:`SIGNIFICANT` standard deviations
        clear (False where it was not read)."""
        return tuple(
            bool(np.isfinite(d) and np.isfinite(s) and abs(d) > SIGNIFICANT * s)
            for d, s in zip(self.joints_s, self.joints_std_s, strict=True)
        )

    def as_dict(self) -> dict[str, Any]:
        """The record of ``identify``'s and ``validate``'s JSON: the delays in ms; each
        joint's own only where it stands clear (:attr:`joints_clear`; ``null`` for the
        others), the lists left out when no joint's does."""
        rec: dict[str, Any] = {
            "delay_ms": 1e3 * self.delay_s,
            "std_ms": 1e3 * self.std_s,
            "share": self.share,
            "named": self.named,
        }
        clear = self.joints_clear
        if any(clear):
            rec["joints_ms"] = [
                1e3 * d if c else None for d, c in zip(self.joints_s, clear, strict=True)
            ]
            rec["joints_std_ms"] = [
                1e3 * s if c else None for s, c in zip(self.joints_std_s, clear, strict=True)
            ]
        return rec


def delay_decimals(std_ms: float) -> int:
    """The decimals [-] that show a delay to the first significant digit of its standard
    deviation ``std_ms`` [ms] (0.024 -> 2, 0.4 -> 1, 3 -> 0; at most 4): the summary's,
    the report's and the hint's ``--torque-delay``."""
    if not np.isfinite(std_ms) or std_ms <= 0.0:
        return 2
    return int(min(max(-np.floor(np.log10(float(f"{std_ms:.1g}"))), 0), 4))


def ms_text(ms: float) -> str:
    """A delay in milliseconds as said: one decimal (``3.0``), more digits where it has
    them (``2.25``)."""
    return f"{ms:.1f}" if abs(10 * ms - round(10 * ms)) < 1e-6 else f"{ms:.3g}"


@dataclass(frozen=True, slots=True)
class AppliedDelay:
    """The torques' delay a command prepared its logs with, and where it came from.

    Attributes
    ----------
    delay_s : float
        The delay [s] (positive: the torques late): the states read that much earlier.
    source : "given" or "model"
        ``--torque-delay`` as given, or the one the model was identified with
        (``identification.json``'s ``metadata.torque_delay_s``).
    """

    delay_s: float
    source: Literal["given", "model"]

    def text(self) -> str:
        """``3.0 ms (given)`` or ``3.0 ms (from the model's identification.json)``."""
        where = "given" if self.source == "given" else "from the model's identification.json"
        return f"{ms_text(1e3 * self.delay_s)} ms ({where})"

    def sentence(self) -> str:
        """``torque delay 3.0 ms (given)``: the line of a command's summary."""
        return f"torque delay {self.text()}"

    def as_dict(self) -> dict[str, Any]:
        """The record of ``validation.json`` and ``observe``'s files: the delay in ms, its
        source and the sentence."""
        return {"delay_ms": 1e3 * self.delay_s, "source": self.source, "said": self.sentence()}


def applied_delay(given_s: float | None, recorded_s: float) -> AppliedDelay | None:
    """The delay a command applies: ``given_s`` [s] (``--torque-delay``, 0 included) when
    given, else the model's ``recorded_s`` [s]; None when neither applies one (none given,
    none recorded)."""
    if given_s is not None:
        return AppliedDelay(float(given_s), "given")
    return AppliedDelay(float(recorded_s), "model") if recorded_s else None


def torque_delay(
    t: Sequence[NDArray[np.float64]],
    predicted: Sequence[NDArray[np.float64]],
    error: Sequence[NDArray[np.float64]],
    columns: Sequence[NDArray[np.float64]] | None = None,
    lag: int = 0,
    every: int = 1,
) -> TorqueDelay | None:
    """The delay of the torques behind the positions that the residual ``error`` points to
    (module docstring).

    Parameters
    ----------
    t : sequence of ndarray, each (N_k,)
        The times of each prepared piece [s], increasing.
    predicted : sequence of ndarray, each (N_k, n)
        The model's rigid-body torques at those samples [N m] (friction left out).
    error : sequence of ndarray, each (N_k, n)
        Measured less predicted torques [N m].
    columns : sequence of ndarray, each (ceil(N_k / every), n, p), optional
        The model's own columns at every ``every``-th sample, fitted beside the delay's.
    lag : int
        The Newey-West window [samples] (:func:`~dynid.identification.serial.hac_lag`).
    every : int
        Fit every ``every``-th sample of each piece (the derivative taken at the full
        rate first): a long log's check in bounded memory.

    Returns
    -------
    TorqueDelay or None
        None without a piece of at least 5 samples or a prediction that changes.
    """
    keep = [k for k, x in enumerate(t) if np.asarray(x).shape[0] >= _MIN_SAMPLES]
    if not keep:
        return None
    E = [np.asarray(error[k], dtype=np.float64)[::every] for k in keep]
    D = [
        -np.gradient(np.asarray(predicted[k], float), np.asarray(t[k], float), axis=0)[::every]
        for k in keep
    ]
    lag = -(-lag // every)  # in the rows kept
    C = None if columns is None else [np.asarray(columns[k], dtype=np.float64) for k in keep]
    n = E[0].shape[1]
    rms = _left_rms(E, C)
    w = np.where(rms > 0, 1.0 / np.where(rms > 0, rms, 1.0), 0.0)
    sizes = [e.shape[0] for e in E]
    common = _fit(D, E, C, w, sizes, lag, range(n))
    if common is None:
        return None
    nan = (float("nan"),) * n
    delay = TorqueDelay(common[0], common[1], common[2], nan, nan)
    if not delay.named:
        return delay
    joints = [_fit(D, E, C, w, sizes, lag, [j]) or (nan[0], nan[0], 0.0) for j in range(n)]
    return dataclasses.replace(
        delay, joints_s=tuple(x[0] for x in joints), joints_std_s=tuple(x[1] for x in joints)
    )


def _fit(
    D: list[NDArray[np.float64]],
    E: list[NDArray[np.float64]],
    C: list[NDArray[np.float64]] | None,
    w: NDArray[np.float64],
    sizes: list[int],
    lag: int,
    joints: Sequence[int],
) -> tuple[float, float, float] | None:
    """The delay [s], its Newey-West standard deviation [s] and the share of the weighted
    residual it explains, from the rows of ``joints``: the delay's column ``D`` with the
    columns ``C`` taken out of it and of the residual ``E`` (Frisch-Waugh-Lovell)."""
    j = np.asarray(joints)
    x = np.concatenate([d[:, j] * w[j] for d in D]).ravel()
    y = np.concatenate([e[:, j] * w[j] for e in E]).ravel()
    if C is not None:
        A = _scaled_columns(C, j, w)
        if A.shape[1]:
            both = _projected(A, np.stack([x, y], axis=1))
            x, y = x - A @ both[:, 0], y - A @ both[:, 1]
    xx = float(x @ x)
    yy = float(y @ y)
    if not xx > 0 or not yy > 0:
        return None
    delta = float(x @ y) / xx
    r = y - delta * x
    meat = SerialMeat(serial_of_pieces(sizes, len(j), [lag]), 1)
    meat.add((x * r)[:, None])
    m = x.shape[0]
    var = float(meat.result()[0, 0]) / xx**2 * m / max(m - 1, 1)
    var = max(var, _blocks_var(x * r, sizes, len(j)) / xx**2)
    return delta, float(np.sqrt(max(var, 0.0))), delta**2 * xx / yy


def _left_rms(
    E: list[NDArray[np.float64]], C: list[NDArray[np.float64]] | None
) -> NDArray[np.float64]:
    """Each joint's RMS [N m] (n,) of the residual ``E`` less what the columns ``C`` take of
    it (least squares over every joint, unweighted): the weights' scale. A residual the
    columns explain (a description's viscous friction ten times off: 5 N m on a joint whose
    noise is 0.2 N m) does not weigh that joint down against the others (an xArm7's torques
    10 ms late read as 5.4 +- 1.7 ms by the raw RMS, as 10.4 +- 0.4 ms by this one)."""
    e = np.concatenate(E)
    if C is not None:
        A = np.concatenate(C)
        A = A.reshape(-1, A.shape[-1])
        A = A[:, np.any(A != 0, axis=0)]
        if A.shape[1]:
            A = A / np.linalg.norm(A, axis=0)
            y = e.ravel()
            e = (y - A @ _projected(A, y[:, None])[:, 0]).reshape(e.shape)
    return np.asarray(np.sqrt(np.mean(e**2, axis=0)), dtype=np.float64)


def _scaled_columns(
    C: list[NDArray[np.float64]], j: NDArray[np.intp], w: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The columns ``C`` (each (N_k, n, p)) at the rows of the joints ``j``, each joint's
    times its weight ``w`` (n,) [1/(N m)], the pieces stacked (sum N_k * len(j), p')
    column-major, the columns that are zero on every row left out and each of the others
    scaled to unit norm. Written into one array in place (the delay's check of a 10 s,
    1 kHz Panda log: 50 MB a copy), the same numbers as the weighted pieces
    concatenated, their zero columns dropped (a column-major copy) and divided by their
    norms."""
    p = C[0].shape[-1]
    rows = [c.shape[0] * j.size for c in C]
    A = np.empty((sum(rows), p), order="F")
    wj = w[j][None, :, None]
    every = j.size == C[0].shape[1] and bool(np.all(j == np.arange(j.size)))
    start = 0
    for c, m in zip(C, rows, strict=True):
        piece = A.T[:, start : start + m].reshape(p, c.shape[0], j.size)  # a view
        np.multiply(c if every else c[:, j, :], wj, out=piece.transpose(1, 2, 0))
        start += m
    scale = np.linalg.norm(A, axis=0)
    if not np.all(scale > 0):  # a column zero on every row (or of norm below range)
        A = A[:, np.any(A != 0, axis=0)]
        scale = np.linalg.norm(A, axis=0)
    A /= scale
    return A


def _projected(A: NDArray[np.float64], B: NDArray[np.float64]) -> NDArray[np.float64]:
    """``lstsq(A, B, rcond=1e-10)`` (p, q) of ``A`` (m, p), ``B`` (m, q): of a tall ``A``
    from the triangular factor ``[[R, C], [0, D]]`` of ``[A B]`` (blocked QR,
    :func:`~dynid.identification.solvers.tall_r`) as ``lstsq(R, C)``: ``R`` holds ``A``'s
    singular values, the same rank cut, in a third of the time on the whole rows."""
    m, p = A.shape
    if m < 4 * (p + B.shape[1]):
        return np.asarray(np.linalg.lstsq(A, B, rcond=1e-10)[0], dtype=np.float64)
    T = tall_r(A, np.ones(p), B)
    return np.asarray(np.linalg.lstsq(T[:p, :p], T[:p, p:], rcond=1e-10)[0], dtype=np.float64)


def _blocks_var(score: NDArray[np.float64], sizes: list[int], rows: int) -> float:
    """The variance of the scores' sum ``score`` (sum(sizes) * rows,) [s^-2 ...] over
    :data:`BLOCKS` contiguous time blocks taken as independent (a cluster-robust
    variance, ``G / (G - 1)`` corrected): each piece cut into blocks in proportion to its
    samples ``sizes``, at least one; 0 with fewer than two blocks."""
    total = sum(sizes)
    labels, first = [], 0
    for size in sizes:
        k = max(1, min(size, round(BLOCKS * size / total)))
        labels.append(first + np.minimum(np.arange(size) * k // size, k - 1))
        first += k
    if first < 2:
        return 0.0
    sums = np.bincount(np.repeat(np.concatenate(labels), rows), weights=score, minlength=first)
    return float(sums @ sums) * first / (first - 1)
