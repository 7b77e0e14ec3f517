"""Friction laws in one canonical form that the observer's compiled step evaluates.

Every law of the registry (:mod:`dynid.friction.laws`) is a special case of, per motor,

.. math:: f(v) = f_{v+} v^+ + f_{v-} v^- + f_{c+} [s > 0] - f_{c-} [s < 0] + f_o
          + \\Delta_s e^{-(v / v_{st})^2} s + f_t \\tanh(v / v_s)
          + \\varphi_1 \\big(\\sigma(\\varphi_2 (v + \\varphi_3))
          - \\sigma(\\varphi_2 \\varphi_3)\\big) + f_q v |v|

with ``s`` the sign outside the standstill band (:func:`~dynid.friction.model.coulomb_sign`),
in the bump ``\\Delta_s e^{-(v / v_{st})^2}`` replaced by ``\\tanh(v / v_s)`` where
``v_s > 0`` (the smooth-sign Stribeck law: its bump takes its Coulomb term's sign),
and ``sigma`` the logistic function; ``tau_f = K_f^T f(K_f dq)`` with ``K_f`` the drive's
friction transmission (the identity at the joints). The 14 columns per motor, in order:
``fv+, fv-, fc+, fc-, fo, band, fs - fc, vst, ft, vs, phi1, phi2, phi3, fq``
(:data:`~dynid.friction.laws.base.CANONICAL_COLUMNS`).

:func:`canonical_friction` asks the model's law for that form
(:attr:`~dynid.friction.laws.base.FrictionLaw.canonical`); a law without one (None) has the
observer's step evaluate the model's own ``torques`` in Python.

:func:`standstill_margin` bounds what such a model cannot know about its friction near rest:
inside the standstill band the law's Coulomb term is off (or, for ``tanh(v / v_s)``, not yet
at its level), while the true friction of a slow reversal or a standstill lies anywhere in
``[-f_c, f_c]``. Its bound per motor is

.. math:: w(v) = \\max_{\\pm,\\, e \\in [0, 1]} |f_{c\\pm} + (f_s - f_c) e| \\, [|v| \\le b]
          + |f_t| \\big(1 - \\tanh(|v| / v_s)\\big)

(``b`` the band; the Stribeck bump is off inside it as well: the largest static friction
the law can hold is ``f_s`` for a positive bump and ``f_c`` for a negative one, where the
law's magnitude rises from ``f_s`` at rest to ``f_c``; a bump on the smooth sign is not yet
at its level with it: ``|f_t|`` becomes ``max(|f_t|, |f_t + f_s - f_c|)`` instead),
``|K_f|^T w(K_f dq)`` at the joints; 0 for the sigmoid law (no Coulomb level) and for
laws without a canonical form (before the noise band's term below).
A :class:`~dynid.friction.model.FrictionSum` (friction at the motors and at the joints)
gets the sum of its parts' bounds, each seen at the joints through its own transmission.

The friction is evaluated at the *measured* velocities, which lie within their noise band
``b`` (:func:`velocity_bands`: :data:`~dynid.identification.velocity_noise.NOISE_BAND_STD` robust
standard deviations of the velocity noise, per motor) of the true ones. A smooth Coulomb
step (the sigmoid ``phi1 sigma(phi2 (v + phi3))``, the term ``f_t tanh(v / v_s)``) narrower
than that band changes by up to its whole height between the two: per motor, each step's

.. math:: s(v) = \\max\\big(|h(v + b) - h(v)|,\\; |h(v - b) - h(v)|\\big)

(``h`` monotone: the largest change within the band is at one of its ends) is added to
``w``. Through a gear of ratio ``K`` a motor's velocity noise and its friction both grow
with ``K``: a motor sigmoid of 8 N m and ``phi2 = 30`` s/rad behind a ratio of 120 moves
the joint torque by up to 960 N m within the noise of a reversal, which a calibration
without this bound reads as the collision-free residual. A sharp step (``fc sign(dq)``)
with a standstill band well inside that noise band (none at all: a law typed without one)
flips its whole height with the sign of the noise at every rest; the observer takes the
noise band as its standstill band instead (:func:`banded_if_narrow`, as it bands a
narrow smooth law), and a note says so (:func:`banding_note`).

Velocities *derived* from the positions (a log without velocity columns) are smooth: the
noise estimate above finds next to nothing, and an identification on them a standstill
band of next to zero, while the derived velocity still departs from the true one by the
position noise passed through the derivative filter. Their band
(:func:`derived_velocity_bands`) is that noise: ``NOISE_BAND_STD`` times the std of the
motor positions' noise times the filter's noise gain ``sqrt(sum h_k^2)`` (``h`` the
derivative filter's impulse response). Within it the model's sharp Coulomb step may sit on
the wrong side of zero: ``w`` then also holds the step's change within the band, up to
``2 f_c`` where the band reaches across zero (``derived=True`` of
:func:`standstill_margin`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..friction.laws.base import CANONICAL_COLUMNS
from ..friction.model import FrictionModel, FrictionSum, friction_parts
from ..identification.log import OBSERVER_CUTOFF_HZ
from ..signals import below_nyquist, sample_rate

__all__ = [
    "DERIVED_CUTOFF_HZ",
    "FRICTION_COLUMNS",
    "NARROW_BAND",
    "banded_if_narrow",
    "banding_note",
    "canonical_friction",
    "derived_cutoff",
    "derived_velocity_bands",
    "noise_bands",
    "standstill_margin",
    "velocity_bands",
]

#: The canonical parameters per motor (module docstring).
FRICTION_COLUMNS = CANONICAL_COLUMNS

#: Cut-off [Hz] of the velocities the observer derives from the positions of a log without
#: velocity columns, above the observer's own bandwidth (``K_O / 2 pi`` = 8 Hz at the
#: default gain). The identification's 5 Hz smears every move's start and stop over
#: 0.1-0.2 s: the velocity rises before the joint moves and crosses zero before it stops,
#: and the model's Coulomb step fires early, which the residual reads as a contact. On
#: point-to-point moves with rests (a Panda with 1-3 N m of Coulomb friction; a 6-joint arm
#: identified on such logs): 16 and 7 false events at 5 Hz, 7 and 0 at 10 Hz, none at
#: 20 Hz, where the position noise through the derivative (bounded by
#: :func:`derived_velocity_bands`) raises the calibrated thresholds by 20-30 %.
DERIVED_CUTOFF_HZ = OBSERVER_CUTOFF_HZ


def derived_cutoff(t: NDArray[np.float64]) -> float:
    """The cut-off [Hz] the observer derives the velocities of a log of positions at, its
    samples at the times ``t`` (N,) [s]: :data:`DERIVED_CUTOFF_HZ`, or a quarter of the
    rate where that is not below half of it (:func:`~dynid.signals.below_nyquist`; the
    observer's 20 Hz crashed every log sampled at 40 Hz or less: a 30 Hz servo log is
    observed at 7.5 Hz)."""
    if t.shape[0] < 2:
        return DERIVED_CUTOFF_HZ
    return below_nyquist(DERIVED_CUTOFF_HZ, sample_rate(t))


def canonical_friction(
    friction: FrictionModel | FrictionSum | None, n: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """``(K_f, F)``: the friction transmission (n, n) and the canonical parameters (n, 14)
    of ``friction`` (zeros for None), or None for a law without a canonical form and for a
    sum of frictions in different places (evaluated in Python)."""
    if friction is None:
        return np.eye(n), np.zeros((n, len(FRICTION_COLUMNS)))
    if isinstance(friction, FrictionSum):
        return None
    canonical = getattr(friction.law, "canonical", None)  # a law outside the registry: none
    if canonical is None:
        return None
    return friction.transmission, canonical(np.asarray(friction.params), np.asarray(friction.band))


#: Consecutive samples per estimate of the velocity noise (:func:`velocity_bands` takes
#: the median of the windows' estimates: a long log in bounded memory).
_NOISE_WINDOW = 1 << 16


def velocity_bands(
    friction: FrictionModel | FrictionSum | None, dq: NDArray[np.float64]
) -> tuple[NDArray[np.float64], ...]:
    """The velocity noise band [rad/s] of the motors of every part of ``friction`` (one
    (n,) array per part; none without friction), estimated on the velocities ``dq`` (N, n)
    [rad/s] seen through the part's transmission
    (:func:`~dynid.identification.velocity_noise.velocity_noise_std` times
    :data:`~dynid.identification.velocity_noise.NOISE_BAND_STD`, the median of its estimates over
    windows of :data:`_NOISE_WINDOW` samples); zeros for fewer than 4 samples.
    """
    from ..identification.velocity_noise import noise_band, velocity_noise_std

    v = np.asarray(dq, dtype=np.float64)
    parts = friction_parts(friction)
    out = []
    for part in parts:
        if v.shape[0] < 4:
            out.append(np.zeros(part.n))
            continue
        K = np.asarray(part.transmission)
        sd = np.zeros(part.n)
        for k in range(part.n):  # a motor at a time, over windows: bounded temporaries
            est = [
                velocity_noise_std((v[a : a + _NOISE_WINDOW] @ K[k])[:, None])[0]
                for a in range(0, v.shape[0], _NOISE_WINDOW)
                if v.shape[0] - a >= 4
            ]
            sd[k] = np.median(est)
        out.append(np.asarray(noise_band(sd), dtype=np.float64))
    return tuple(out)


def noise_bands(
    friction: FrictionModel | FrictionSum | None, dq_std: NDArray[np.float64]
) -> tuple[NDArray[np.float64], ...]:
    """The velocity noise band [rad/s] of the motors of every part of ``friction`` (one
    (n,) array per part) for joint velocities of white-noise std ``dq_std`` (n,) [rad/s],
    independent per joint: :data:`~dynid.identification.velocity_noise.NOISE_BAND_STD` times
    ``sqrt(K^2 dq_std^2)`` through the part's transmission ``K`` (the noise a validation's
    prepared velocities carry, :func:`~dynid.identification.input_noise.state_noise`)."""
    from ..identification.velocity_noise import noise_band

    var = np.asarray(dq_std, dtype=np.float64) ** 2
    return tuple(
        np.asarray(noise_band(np.sqrt(np.asarray(p.transmission) ** 2 @ var)), dtype=np.float64)
        for p in friction_parts(friction)
    )


def derived_velocity_bands(
    friction: FrictionModel | FrictionSum | None,
    t: NDArray[np.float64],
    q: NDArray[np.float64],
    cutoff_hz: float,
) -> tuple[NDArray[np.float64], ...]:
    """The velocity band [rad/s] of the motors of every part of ``friction`` (one (n,)
    array per part) for velocities derived from the positions ``q`` (N, n) [rad] sampled
    at ``t`` (N,) [s] by :func:`~dynid.signals.filtered_derivative` at ``cutoff_hz``
    (module docstring): :data:`~dynid.identification.velocity_noise.NOISE_BAND_STD` times the
    position noise of each motor (:func:`~dynid.identification.velocity_noise.velocity_noise_std`
    of its positions, the median over windows) times the filter's noise gain; zeros for
    fewer than 4 samples."""
    from ..identification.velocity_noise import noise_band, velocity_noise_std
    from ..signals import derivative_noise_gain

    parts = friction_parts(friction)
    N = q.shape[0]
    if N < 4:
        return tuple(np.zeros(p.n) for p in parts)
    gain = derivative_noise_gain(float(np.median(np.diff(t))), cutoff_hz)
    out = []
    for part in parts:
        K = np.asarray(part.transmission)
        sd = np.zeros(part.n)
        for k in range(part.n):
            est = [
                velocity_noise_std((q[a : a + _NOISE_WINDOW] @ K[k])[:, None])[0]
                for a in range(0, N, _NOISE_WINDOW)
                if N - a >= 4
            ]
            sd[k] = np.median(est)
        out.append(np.asarray(noise_band(gain * sd), dtype=np.float64))
    return tuple(out)


#: A sharp Coulomb step (``fc s(dq)``) whose standstill band is below this fraction of the
#: velocity noise band is observed with the noise band (:func:`banded_if_narrow`). An
#: identified band is its own logs' noise band, estimated again on each observed log within
#: some tens of percent: only a band well inside the noise (none at all, a law typed by
#: hand) is widened.
NARROW_BAND = 0.5


def banded_if_narrow(
    friction: FrictionModel | FrictionSum | None,
    bands: tuple[NDArray[np.float64], ...],
    *,
    derived: bool = False,
    smooth: bool = True,
) -> FrictionModel | FrictionSum | None:
    """``friction`` as the observer evaluates it on velocities of noise band ``bands``
    (:func:`velocity_bands` or :func:`derived_velocity_bands`, one per part): a smooth
    Coulomb law ``fc tanh(dq / w)`` narrower than the band on every motor becomes the
    classical law with the band as its standstill band (``fc sign(dq)`` outside it, 0
    inside), a smooth-sign Stribeck law the banded Stribeck law; a law with a sharp Coulomb
    step (classical, quadratic, asymmetric, Stribeck) gets the band as its standstill band
    on every motor whose own band is below :data:`NARROW_BAND` times it (measured
    velocities only: ``derived`` bands are bounded by :func:`standstill_margin`'s derived
    term instead); each part of a sum on its own; any other friction as it is
    (:func:`banding_note` says what changed). ``smooth`` False keeps smooth laws as they
    are (validation judges a model's prediction in motion, for which identification chose
    the narrow law; the observer needs the band at rest).

    Inside the band a narrow ``tanh`` of the noise is a random level in ``[-fc, fc]``, and
    ``sign(dq)`` of the noise a random ``+-fc``, which bounds the residual of a joint at rest
    by ``2 fc`` (:func:`standstill_margin`); the band's zero bounds it by ``fc``, as for a
    law identified with the band, and outside the band both are the sign. Identification
    chooses the narrow law because it predicts torques in motion best; at rest the
    observer needs the band (a UR10 with a contact at rest: margins of 15.9 N m on joint
    1 with the narrow law, 7.1 N m with the band; a Z1 with classical friction typed
    without a band: thresholds 4-5 times those of the same law with its band, 10 of 13
    weak contacts missed)."""
    if isinstance(friction, FrictionSum):
        parts = tuple(
            _banded_part(p, b, derived, smooth) for p, b in zip(friction.parts, bands, strict=True)
        )
        if all(a is b for a, b in zip(parts, friction.parts, strict=True)):
            return friction
        return FrictionSum(parts)
    if friction is None:
        return friction
    (b,) = bands
    return _banded_part(friction, b, derived, smooth)


def _banded_part(
    friction: FrictionModel, b: NDArray[np.float64], derived: bool, smooth: bool = True
) -> FrictionModel:
    """One part of :func:`banded_if_narrow`."""
    from ..friction.laws import LAWS

    banded_law = {"smooth": "classical", "smooth_stribeck": "stribeck"}
    width = np.asarray(friction.band, dtype=np.float64)
    drive = getattr(friction, "drive", None)
    if width.size != b.size:
        return friction
    if friction.kind in banded_law:
        if not smooth or not np.all(width < b):
            return friction
        return LAWS[banded_law[friction.kind]].model(np.asarray(friction.params), b, drive)
    canon = canonical_friction(friction, b.size)
    if derived or canon is None or not getattr(friction.law, "standstill", False):
        return friction
    F = canon[1]
    sharp = (F[:, 2] != 0) | (F[:, 3] != 0) | ((F[:, 6] != 0) & (F[:, 9] == 0))
    narrow = sharp & (width < NARROW_BAND * b)
    if not narrow.any():
        return friction
    return friction.law.model(np.asarray(friction.params), np.where(narrow, b, width), drive)


def banding_note(
    friction: FrictionModel | FrictionSum | None,
    seen: Sequence[FrictionModel | FrictionSum | None],
    *,
    verb: str = "observed",
    read_as: str = "external torque",
) -> str | None:
    """One line saying which sharp Coulomb steps of ``friction`` :func:`banded_if_narrow`
    widened for the logs (``seen``: the friction each log was observed with): the law, the
    joints (or motors) and the largest band used [rad/s]; None where it widened none (a
    smooth law observed with the band, as identification means it, is not noted).
    ``verb`` and ``read_as``: what the command did with the band and what the flips would
    be read as (validation: ``"judged"``, ``"model error"``)."""
    changed = [s for s in seen if s is not None and s is not friction]
    said = []
    owned = []  # the largest band of its own each widened part carries [rad/s] (0: none)
    for k, part in enumerate(friction_parts(friction) if changed else ()):
        used = [u for s in changed if (u := friction_parts(s)[k]).kind == part.kind]
        widened = [np.asarray(u.band) > np.asarray(part.band) for u in used]
        if not np.any(widened):
            continue
        moved = np.any(widened, axis=0)
        bands = [np.asarray(u.band)[w] for u, w in zip(used, widened, strict=True)]
        top = max(float(np.max(b, initial=0.0)) for b in bands)
        own = np.broadcast_to(np.asarray(part.band, dtype=np.float64), moved.shape)[moved]
        owned.append(float(np.max(own, initial=0.0)))
        where = "motor" if part.at_motors else "joint"
        said.append(
            f"{part.kind} friction: the standstill band of {where}(s) "
            f"{', '.join(str(j + 1) for j in np.flatnonzero(moved))} is inside the velocity "
            f"noise, {verb} with the noise band (up to {top:.3g} rad/s)"
        )
    if not said:
        return None
    if max(owned) > 0.0:  # a band of its own, narrower than these logs' noise
        why = (
            f"its own band, up to {max(owned):.3g} rad/s from the velocities it was "
            "identified on, is narrower than these logs' noise"
        )
    else:
        why = "it carries no band of its own; a friction.json of `dynid friction` does"
    return (
        "; ".join(said) + ": sign(dq) of the noise at rest would flip the whole Coulomb "
        f"torque, read as {read_as} ({why})"
    )


def standstill_margin(
    friction: FrictionModel | FrictionSum | None,
    dq: NDArray[np.float64],
    bands: tuple[NDArray[np.float64], ...] | None = None,
    *,
    derived: bool = False,
) -> NDArray[np.float64]:
    """Bound [N m] (..., n) of the friction the model cannot know at velocities ``dq``
    [rad/s] (..., n): its Coulomb level where the law's Coulomb term is off or not at its
    level and, with ``bands`` (:func:`velocity_bands`, one per part), what its smooth
    Coulomb steps change within the velocity noise band (module docstring); with
    ``derived`` (``bands`` of :func:`derived_velocity_bands`) what its sharp Coulomb step
    changes within the band as well; zeros without friction or for a law without a
    canonical form; the sum of the parts' for a :class:`~dynid.friction.model.FrictionSum`.
    """
    v = np.asarray(dq, dtype=np.float64)
    if isinstance(friction, FrictionSum):
        each = bands if bands is not None else (None,) * len(friction.parts)
        parts = [
            standstill_margin(p, v, None if b is None else (b,), derived=derived)
            for p, b in zip(friction.parts, each, strict=True)
        ]
        total: NDArray[np.float64] = np.sum(parts, axis=0)
        return total
    n = v.shape[-1]
    canon = canonical_friction(friction, n)
    if friction is None or canon is None:
        return np.zeros_like(v)
    K, F = canon
    vm = v @ K.T  # motor velocities
    smooth = F[:, 9] > 0  # the bump on the smooth sign: with ft below
    level = _static_level(F[:, 2], F[:, 3], np.where(smooth, 0.0, F[:, 6]))
    w = np.where(np.abs(vm) <= F[:, 5], level, 0.0)
    ft, vs = _static_level(F[:, 8], F[:, 8], np.where(smooth, F[:, 6], 0.0)), F[:, 9]
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.where(vs > 0, np.abs(vm) / np.where(vs > 0, vs, 1.0), np.inf)
    w = w + ft * np.where(vs > 0, 1.0 - np.tanh(x), np.where(vm == 0.0, 1.0, 0.0))
    if bands is not None and bands[0] is not None:
        b = np.asarray(bands[0], dtype=np.float64)
        w = w + _step_spread(F, vm, b)
        if derived:  # the sharp step: off inside |v| <= band, its sign beyond
            a, band = np.abs(vm), F[:, 5]
            w = w + level * ((a > band) & (a <= band + b)) + level * (a < b - band)
    out: NDArray[np.float64] = w @ np.abs(K)
    return out


def _static_level(
    up: NDArray[np.float64], down: NDArray[np.float64], bump: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Per motor (n,) [N m]: the largest static friction a Coulomb step of levels ``up``
    and ``down`` (for positive and negative velocities) with a Stribeck bump ``bump``
    (``fs - fc``, decaying from its full height at rest to 0) can hold, the largest of
    ``|fc + bump e|`` over ``e`` in ``[0, 1]``: ``fs`` for a positive bump, ``fc`` for a
    negative one (the law's magnitude rises from ``fs`` to ``fc`` as the velocity grows)."""
    ends = (np.abs(up), np.abs(down), np.abs(up + bump), np.abs(down + bump))
    out: NDArray[np.float64] = np.maximum.reduce(ends)
    return out


def _step_spread(
    F: NDArray[np.float64], vm: NDArray[np.float64], b: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Per motor (..., n) [N m]: the largest change of the smooth Coulomb steps (sigmoid,
    tanh) within ``b`` (n,) [rad/s] of the motor velocities ``vm`` (module docstring)."""

    def steps(v: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            # phi1 sigma(phi2 (v + phi3)) less its constant phi1 / 2
            sig = F[:, 10] * (0.5 * np.tanh(0.5 * F[:, 11] * (v + F[:, 12])))
            vs, vst = F[:, 9], F[:, 7]
            decay = np.exp(-((v / np.where(vst > 0, vst, 1.0)) ** 2))
            bump = np.where(vst > 0, F[:, 6] * decay, 0.0)
            th = np.where(vs > 0, (F[:, 8] + bump) * np.tanh(v / np.where(vs > 0, vs, 1.0)), 0.0)
        return sig, th

    mid, lo, hi = steps(vm), steps(vm - b), steps(vm + b)
    out: NDArray[np.float64] = np.zeros_like(vm)
    for k in range(2):  # each step monotone: its largest change at an end of the band
        out = out + np.maximum(np.abs(hi[k] - mid[k]), np.abs(lo[k] - mid[k]))
    return out
