"""The momentum observer: a step for a control loop, and a whole log at once.

.. math:: r_k = r_{k-1} + \\gamma_k \\Big(\\frac{p_k - p_{k-1}}{T_k} - u_k - r_{k-1}\\Big),
          \\qquad u = \\tau - \\tau_f(\\dot q) + C^T \\dot q - g,

``T_k = t_k - t_{k-1}`` (any sample times), ``r_0 = 0`` at the first sample. With
``gamma = K_O T`` (``discretisation="euler"``) this is De Luca's
``r_k = K_O (p_k - I_k - p_0)``, ``I_k = I_{k-1} + T_k (u_k + r_{k-1})``, rearranged; with
``gamma = 1 - exp(-K_O T)`` (``"exact"``, the default) it is the exact discretisation of
``dr/dt = K_O (tau_ext - r)`` for an external torque constant over each step, so the
residual of a step contact follows ``A (1 - exp(-K_O t))`` at every sample. ``rule``
integrates ``u`` over a step by its new value (``"rectangle"``, De Luca's) or the mean of
both ends (``"trapezoid"``, second-order accurate: on exact data the residual then matches
the external torque to the simulation's rounding rather than to ``T/2`` times the rate of
change of the torques).

:class:`MomentumObserver` keeps the state: :meth:`~MomentumObserver.step` is one compiled
call per sample (:func:`dynid._kernels.observer.observer_step`: ``p``, ``g - C^T dq``,
rotor, friction and the update; no Python-level matrix work), and
:meth:`~MomentumObserver.run` continues over a block of samples
(:func:`dynid._kernels.observer.observer_batch`, the friction of the whole block evaluated
first by the model's own law). :func:`observe` runs a fresh observer over a log.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, _kernels
from ..exceptions import DataError, OptionError, ShapeError
from .friction import FRICTION_COLUMNS, canonical_friction
from .model import ObserverModel
from .terms import momentum_terms

__all__ = [
    "DEFAULT_GAIN",
    "DEFAULT_OPTIONS",
    "MomentumObserver",
    "ObserverOptions",
    "ObserverResult",
    "first_order_filtered",
    "first_order_lag",
    "observe",
]

#: Observer gain K_O [1/s] by default: a time constant of 20 ms.
DEFAULT_GAIN = 50.0


@dataclass(frozen=True, slots=True)
class ObserverOptions:
    """How the residual is computed (module docstring).

    Attributes
    ----------
    gain : float or tuple of float
        ``K_O`` [1/s], one for every joint or one per joint; > 0.
    discretisation : {"exact", "euler"}
    rule : {"rectangle", "trapezoid"}

    Raises
    ------
    OptionError
        A gain that is not positive and finite, an unknown discretisation or rule.
    """

    gain: float | tuple[float, ...] = DEFAULT_GAIN
    discretisation: Literal["exact", "euler"] = "exact"
    rule: Literal["rectangle", "trapezoid"] = "trapezoid"

    def __post_init__(self) -> None:
        g = np.atleast_1d(np.asarray(self.gain, dtype=np.float64))
        if g.ndim != 1 or not np.all(np.isfinite(g)) or np.any(g <= 0):
            raise OptionError(
                f"observer gain K_O must be > 0 [1/s]; got {_checks.short(self.gain)}"
            )
        if self.discretisation not in ("exact", "euler"):
            raise OptionError(
                f"discretisation must be 'exact' or 'euler'; got {self.discretisation!r}"
            )
        if self.rule not in ("rectangle", "trapezoid"):
            raise OptionError(f"rule must be 'rectangle' or 'trapezoid'; got {self.rule!r}")

    def gains(self, n: int) -> NDArray[np.float64]:
        """``K_O`` per joint (n,) [1/s].

        Raises
        ------
        ShapeError
            Per-joint gains for another number of joints.
        """
        g = np.atleast_1d(np.asarray(self.gain, dtype=np.float64))
        if g.size == 1:
            return np.full(n, float(g[0]))
        if g.shape != (n,):
            raise ShapeError(f"observer gains must be one or {n} values; got {g.size}")
        return g.copy()


#: The default options (a module-level instance: an argument default).
DEFAULT_OPTIONS = ObserverOptions()


@dataclass(frozen=True, slots=True, eq=False)
class ObserverResult:
    """The residual over a log.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Sample times [s].
    r : ndarray, shape (N, n)
        Residual = estimated external joint torque [N m] (0 at the first sample).
    options : ObserverOptions
    """

    t: NDArray[np.float64]
    r: NDArray[np.float64]
    options: ObserverOptions


def _packed(
    model: ObserverModel, options: ObserverOptions, F: NDArray[np.float64] | None, Kf: Any
) -> NDArray[np.float64]:
    """The observer's constants ``D`` (:mod:`dynid._kernels.observer`), read-only."""
    n = model.n
    C = _kernels.constants(model.robot)
    width = max(C.shape[1], n, len(FRICTION_COLUMNS) + 1)
    D = np.zeros((4 * n + 3, width))
    D[: n + 1, : C.shape[1]] = C
    D[n + 1 : 2 * n + 1, :n] = model.rotor_mass
    if F is not None:
        D[2 * n + 1 : 3 * n + 1, :n] = Kf
        D[3 * n + 1 : 4 * n + 1, : F.shape[1]] = F
        D[3 * n + 1 : 4 * n + 1, F.shape[1]] = 1.0 / (1.0 + np.exp(-F[:, 11] * F[:, 12]))
    D[4 * n + 1, :n] = options.gains(n)
    D[4 * n + 2, :3] = [
        options.discretisation == "exact",
        options.rule == "trapezoid",
        F is not None,
    ]
    return _checks.frozen(D)


class MomentumObserver:
    """The residual of one arm, sample after sample (module docstring).

    Parameters
    ----------
    model : ObserverModel
        :func:`~dynid.observer.model.from_identified` or
        :func:`~dynid.observer.model.from_robot`.
    options : ObserverOptions

    Raises
    ------
    ShapeError
        Per-joint gains for another number of joints.

    Examples
    --------
    >>> obs = MomentumObserver(from_identified(model))          # doctest: +SKIP
    >>> r = obs.step(q, dq, tau, t)      # every control cycle   # doctest: +SKIP
    """

    def __init__(self, model: ObserverModel, options: ObserverOptions = DEFAULT_OPTIONS) -> None:
        self.model, self.options = model, options
        n = self.n = model.n
        canon = canonical_friction(model.friction, n)
        self._python_friction = model.friction is not None and canon is None
        F, Kf = (None, None) if canon is None else (canon[1], canon[0])
        self._D = _packed(model, options, F, Kf)
        self._D_batch = _packed(model, options, None, None)  # u = tau - tau_f given
        self._S = np.zeros(4 * n + 3)
        self._shape = (n,)
        self._gains = options.gains(n)
        mod = _kernels.load("observer")
        self._kernels = mod
        self._entry: Any = None
        if mod is not None and n * 21 <= 1024:
            v = _kernels.VECTOR
            self._entry = _kernels.entry(
                mod.observer_step, self._D, self._S, v, v, v, 0.0, np.zeros(n)
            )

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """Forget every sample: the next one starts the residual at 0."""
        self._S[:] = 0.0

    @property
    def started(self) -> bool:
        """Whether a sample was seen since the start or the last :meth:`reset`."""
        return bool(self._S[0])

    @property
    def residual(self) -> NDArray[np.float64]:
        """The last residual (n,) [N m] (a copy)."""
        n = self.n
        return self._S[2 + 2 * n : 2 + 3 * n].copy()

    # ------------------------------------------------------------------ one sample
    def step(self, q: ArrayLike, dq: ArrayLike, tau: ArrayLike, t: float) -> NDArray[np.float64]:
        """The residual [N m] (n,) after the sample ``q, dq, tau`` (n,) at time ``t`` [s].

        One compiled call (float64 vectors of shape (n,) take it directly; anything else
        is validated first). The first sample after construction or :meth:`reset` gives 0.

        Raises
        ------
        ShapeError
            Not a vector of the robot's joint count.
        NonFiniteError
            NaN or inf in an input.
        DataError
            ``t`` not after the previous sample's time.
        """
        e = self._entry
        if (
            e is not None
            and not self._python_friction
            and type(q) is np.ndarray
            and type(dq) is np.ndarray
            and type(tau) is np.ndarray
            and q.dtype is _F64
            and dq.dtype is _F64
            and tau.dtype is _F64
            and q.shape == self._shape
            and dq.shape == self._shape
            and tau.shape == self._shape
            and isinstance(t, float | int)  # a time of shape (1,) is validated (named)
        ):
            r = np.empty(self.n)
            if e(self._D, self._S, q, dq, tau, float(t), r):
                return r
        return self._step_checked(q, dq, tau, t)

    def _step_checked(self, q: ArrayLike, dq: ArrayLike, tau: ArrayLike, t: Any) -> NDArray:
        n = self.n
        qa, dqa, taua = (
            _checks.as_exact(k, x, (n,)) for k, x in (("q", q), ("dq", dq), ("tau", tau))
        )
        tf = float(_checks.as_exact("t", t, ()))
        if self._S[0] and not tf > self._S[1]:
            raise DataError(
                f"t must increase from sample to sample; got {_checks.number_text(tf)} after "
                f"{_checks.number_text(self._S[1])}"
            )
        held = self.model.position_torques(qa[None])
        if held is not None:  # a spring's torque: spent beside the links'
            taua = taua - held[0]
        if self._python_friction and self.model.friction is not None:
            taua = taua - self.model.friction.torques(dqa)
        r = np.empty(n)
        if self._entry is not None and self._entry(self._D, self._S, qa, dqa, taua, tf, r):
            return r
        u = self._u(qa[None], dqa[None], taua[None], friction=not self._python_friction)
        return self._run_numpy(np.array([tf]), qa[None], dqa[None], u)[0]

    # ------------------------------------------------------------------ a block
    def run(self, t: ArrayLike, q: ArrayLike, dq: ArrayLike, tau: ArrayLike) -> NDArray[np.float64]:
        """The residual (N, n) [N m] over the samples ``t`` (N,), ``q, dq, tau`` (N, n),
        continuing from the state (the friction of the block first, by the model's law).

        Raises
        ------
        ShapeError, NonFiniteError
            As :meth:`step`.
        DataError
            Times that do not increase (the first such sample named).
        """
        n = self.n
        ta = _checks.as_array("t", t)
        if ta.ndim != 1:
            raise ShapeError(f"t must have shape (N,); got {ta.shape}")
        N = ta.shape[0]
        qa, dqa, taua = (
            _checks.as_exact(k, x, (N, n)) for k, x in (("q", q), ("dq", dq), ("tau", tau))
        )
        bad = np.flatnonzero(np.diff(ta) <= 0)
        if bad.size or (N and self._S[0] and not ta[0] > self._S[1]):
            k = int(bad[0]) + 1 if bad.size else 0
            raise DataError(
                "t must increase from sample to sample; sample "
                f"{k} (t = {_checks.number_text(ta[k])}) does not"
            )
        held = self.model.position_torques(qa)
        if held is not None:  # a spring's torque: spent beside the links'
            taua = taua - held
        mod = self._kernels
        if mod is not None and N:
            D, u = self._D, taua  # friction in the kernel, or first by the model's own law
            if self._python_friction:
                D, u = self._D_batch, self._u(qa, dqa, taua, friction=True)
            r = np.empty((N, n))
            fl = _kernels.flat
            # every array flat, C and writable (t of a frozen log is copied): one signature
            stop = mod.observer_batch(D, self._S, fl(ta), fl(qa), fl(dqa), fl(u), r.reshape(-1))
            if stop < 0:
                return r
            raise DataError(
                f"sample {stop} of the log stopped the observer "
                f"(t = {_checks.number_text(ta[stop])})"
            )
        u = self._u(qa, dqa, taua, friction=self.model.friction is not None)
        return self._run_numpy(ta, qa, dqa, u)

    def _u(self, q: NDArray, dq: NDArray, tau: NDArray, *, friction: bool) -> NDArray:
        """``tau - tau_f(dq)`` (N, n)."""
        if friction and self.model.friction is not None:
            return tau - self.model.friction.torques(dq)
        return np.array(tau, dtype=np.float64)

    def _run_numpy(self, t: NDArray, q: NDArray, dq: NDArray, u_in: NDArray) -> NDArray:
        """The numpy path of :meth:`run` (numba missing): same update, a loop over samples."""
        p, beta = momentum_terms(self.model, q, dq)
        u = u_in - beta
        S, n, K = self._S, self.n, self._gains
        exact, trap = self.options.discretisation == "exact", self.options.rule == "trapezoid"
        r = np.empty_like(u)
        for k in range(t.shape[0]):
            if not S[0]:
                S[0], S[1] = 1.0, t[k]
                S[2 : 2 + n], S[2 + n : 2 + 2 * n], S[2 + 2 * n : 2 + 3 * n] = p[k], u[k], 0.0
                r[k] = 0.0
                continue
            T = t[k] - S[1]
            gam = -np.expm1(-K * T) if exact else K * T
            ub = 0.5 * (u[k] + S[2 + n : 2 + 2 * n]) if trap else u[k]
            rk = S[2 + 2 * n : 2 + 3 * n]
            rk = rk + gam * ((p[k] - S[2 : 2 + n]) / T - ub - rk)
            S[1], S[2 : 2 + n], S[2 + n : 2 + 2 * n] = t[k], p[k], u[k]
            S[2 + 2 * n : 2 + 3 * n] = rk
            r[k] = rk
        return r


_F64 = _kernels.F64


def observe(
    model: ObserverModel,
    t: ArrayLike,
    q: ArrayLike,
    dq: ArrayLike,
    tau: ArrayLike,
    options: ObserverOptions = DEFAULT_OPTIONS,
) -> ObserverResult:
    """The residual of ``model`` over a log (a fresh :class:`MomentumObserver`).

    Parameters
    ----------
    model : ObserverModel
    t : array_like, shape (N,)
        Sample times [s], increasing (any steps).
    q, dq, tau : array_like, shape (N, n)
        Measured joint positions [rad], velocities [rad/s] and torques [N m] (the motor
        torques, with friction).
    options : ObserverOptions

    Returns
    -------
    ObserverResult

    Raises
    ------
    ShapeError, NonFiniteError, DataError
        As :meth:`MomentumObserver.run`.
    """
    obs = MomentumObserver(model, options)
    r = obs.run(t, q, dq, tau)
    return ObserverResult(_checks.frozen(np.array(t, dtype=np.float64)), _checks.frozen(r), options)


def first_order_lag(
    t: ArrayLike,
    x: ArrayLike,
    gain: ArrayLike,
    rule: Literal["rectangle", "trapezoid"] = "trapezoid",
) -> NDArray[np.float64]:
    """``x`` (N, n) sampled at ``t`` (N,) through ``K/(s + K)`` (``gain`` K [1/s]), from 0.

    Exact for an input held over each step at its new value (``"rectangle"``) or at the
    mean of both ends (``"trapezoid"``, second-order accurate for a smooth input): what the
    residual of an exact model gives for an external torque ``x`` (a test's truth). One
    compiled pass (:func:`dynid._kernels.observer.first_order_lag`) for ``x`` of shape
    (N, n); a loop over the samples otherwise.
    """
    ta = np.asarray(t, dtype=np.float64)
    xa = np.asarray(x, dtype=np.float64)
    K = np.asarray(gain, dtype=np.float64)
    mod = _kernels.load("observer")
    if mod is not None and xa.ndim == 2 and ta.shape == xa.shape[:1]:
        # C and writable arrays whatever the caller's (one compiled signature)
        Kn = np.array(np.broadcast_to(K, xa.shape[1:]), order="C")
        out = np.zeros(xa.shape)
        fl = _kernels.flat
        mod.first_order_lag(fl(ta), fl(xa).reshape(xa.shape), Kn, rule == "trapezoid", out)
        return out
    out = np.zeros_like(xa)
    for k in range(1, ta.shape[0]):
        a = -np.expm1(-K * (ta[k] - ta[k - 1]))
        xk = 0.5 * (xa[k] + xa[k - 1]) if rule == "trapezoid" else xa[k]
        out[k] = out[k - 1] + a * (xk - out[k - 1])
    return out


def first_order_filtered(
    gam: NDArray[np.float64],
    x: NDArray[np.float64],
    zi: NDArray[np.float64],
    out: NDArray[np.float64],
) -> None:
    """``x`` (m, n, r) through ``gam / (1 + (gam - 1) z^-1)`` per joint (``gam`` (n,))
    along its first axis, from the state ``zi`` (n, r) (updated) into ``out``: one compiled
    pass (:func:`dynid._kernels.observer.first_order_filter`), else
    ``scipy.signal.lfilter`` (the same numbers, bit for bit)."""
    mod = _kernels.load("observer")
    if mod is not None:
        mod.first_order_filter(gam, x, zi, out)
        return
    import scipy.signal  # the reference path: numba missing or turned off

    for j in range(x.shape[1]):
        out[:, j, :], zf = scipy.signal.lfilter(
            [gam[j]], [1.0, gam[j] - 1.0], x[:, j, :], axis=0, zi=zi[j][None]
        )
        zi[j] = zf[0]
