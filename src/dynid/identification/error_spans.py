"""Where a validation's error sits in a few short spans: a contact, a logging fault, or
friction's step at a velocity reversal.

A model validated on a log with a burst of torque it does not hold (a contact, a logging
fault on one joint for a fraction of a second) leaves an error far above the noise there
and at the noise elsewhere. :func:`error_spans` finds the spans where the residual stands
off (:func:`~dynid.identification.outlying_spans.outlying_spans`) and judges them to hold
the error when, together no longer than :data:`SHORT_SHARE` of the recording's samples,
they hold at least :data:`MOST_SHARE` of its squared error above the noise
(``sum e^2 - N sum noise^2``). A model missing a term leaves its error spread over the
motion and is not judged so. Given the velocities and the model's friction, a span where
each of its joints reverses and that stands off by no more than the model's friction
steps there (:func:`~dynid.identification.friction_steps.friction_step`) is said to be
friction's step at those reversals, which the model's friction does not follow at the
instant (its standstill band, its velocities derived through a filter), not a contact.
Times [s] as the log holds them, torques [N m], velocities [rad/s].
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._times import offset_text, stamp_text
from .friction_steps import friction_step
from .outlying_spans import MIN_SHARE, SPANS_SHOWN, Span, outlying_spans, robust_levels
from .verdict import FLOOR_GOOD

__all__ = ["CONTACT_CLAUSE", "MOST_SHARE", "SHORT_SHARE", "ErrorSpans", "error_spans"]

#: The spans' least share of the recording's squared error above the noise [1].
MOST_SHARE = 0.5
#: The spans' largest share of the recording's samples [1].
SHORT_SHARE = 0.1
#: What a span that is not friction's step at a reversal is said to be.
CONTACT_CLAUSE = "a contact or a logging fault there, not the model"


@dataclass(frozen=True, slots=True)
class ErrorSpans:
    """A recording whose error above the noise sits in a few short spans.

    Attributes
    ----------
    name : str
        The recording's name (its file).
    spans : tuple of Span
        The spans, the largest share of the squared residual first.
    share : float
        Their share of the recording's squared error above the noise [1].
    rest_ratio : float
        The RMS error of the rest of the recording (the spans' samples left out) over the
        noise's RMS, all joints [1]: 1 at the noise floor.
    t0 : float or None
        The log's first stamp [s] (the spans' offsets are said from it).
    reversal : tuple of bool
        Per span, whether it is friction's step at its joints' velocity reversals
        (:func:`~dynid.identification.friction_steps.friction_step`), not a contact;
        empty: none is.
    """

    name: str
    spans: tuple[Span, ...]
    share: float
    rest_ratio: float
    t0: float | None = None
    reversal: tuple[bool, ...] = ()

    @property
    def contact(self) -> bool:
        """Whether some span is not friction's step at a reversal (a contact or a logging
        fault)."""
        return not all(self._at_reversal())

    def _at_reversal(self) -> tuple[bool, ...]:
        """Per span, whether it is friction's step at a reversal."""
        return (
            self.reversal if len(self.reversal) == len(self.spans) else (False,) * len(self.spans)
        )

    def sentence(self, joint_names: tuple[str, ...], named: bool = False) -> str:
        """``92 % of the error above the noise sits in t = 3.008 to 3.184 s on elbow_joint
        (up to 50 N m): a contact or a logging fault there, not the model; the rest of the
        recording at 1.1 x the noise floor``; the spans at reversals said as friction's
        (``...: friction at elbow_joint's velocity reversals (its step as the velocity
        changes sign, which the model's friction does not follow at the instant), not a
        contact or a logging fault``); ``named``: the recording named."""
        at = self._at_reversal()
        contacts = [s for s, r in zip(self.spans, at, strict=True) if not r]
        steps = [s for s, r in zip(self.spans, at, strict=True) if r]
        parts = []
        if contacts:
            parts.append(f"{self._said(contacts, joint_names)}: {CONTACT_CLAUSE}")
        if steps:
            joints = sorted({j for s in steps for j in s.joints})
            whose = (
                f"{joint_names[joints[0]]}'s velocity reversals"
                if len(joints) == 1
                else f"the velocity reversals of {', '.join(joint_names[j] for j in joints)}"
            )
            parts.append(
                f"{self._said(steps, joint_names)}: friction at {whose} (its step as the "
                "velocity changes sign, which the model's friction does not follow at the "
                "instant), not a contact or a logging fault"
            )
        where = f" of {self.name}" if named else ""
        return (
            f"{100 * self.share:.0f} % of the error above the noise{where} sits in "
            f"{'; and in '.join(parts)}; the rest of the recording at "
            f"{self.rest_ratio:.3g} x the noise floor"
        )

    def _said(self, spans: list[Span], joint_names: tuple[str, ...]) -> str:
        """``t = 3.008 to 3.184 s on elbow_joint (up to 50 N m); ...``: ``spans``' times
        (with their offsets into the log), joints and peaks."""
        said = []
        for s in spans:
            into = offset_text([s.t0 - float(self.t0 or 0.0)], self.t0, self.name)
            said.append(
                f"t = {stamp_text(s.t0)} to {stamp_text(s.t1)} s"
                + (f" ({into})" if into else "")
                + f" on {', '.join(joint_names[j] for j in s.joints)} (up to {s.peak:.3g} N m)"
            )
        return "; ".join(said)

    def as_dict(self) -> dict[str, Any]:
        """``file``, ``spans`` (each ``t0``, ``t1`` [s], ``joints`` from 0, ``peak`` [N m],
        ``reversal``: friction's step at a velocity reversal, not a contact), ``share`` [1]
        and ``rest_ratio`` [1], as ``validation.json`` records them."""
        return {
            "file": self.name,
            "spans": [
                {"t0": s.t0, "t1": s.t1, "joints": list(s.joints), "peak": s.peak, "reversal": r}
                for s, r in zip(self.spans, self._at_reversal(), strict=True)
            ],
            "share": self.share,
            "rest_ratio": self.rest_ratio,
        }


def error_spans(
    t: NDArray[np.float64],
    e: NDArray[np.float64],
    noise_rms: NDArray[np.float64],
    name: str = "",
    t0: float | None = None,
    *,
    dq: NDArray[np.float64] | None = None,
    friction: NDArray[np.float64] | None = None,
    band: NDArray[np.float64] | float = 0.0,
) -> ErrorSpans | None:
    """The short spans holding most of a recording's error above the noise, or None.

    Parameters
    ----------
    t : ndarray, shape (N,)
        Sample times [s], ascending (pieces one after another).
    e : ndarray, shape (N, n)
        Residual [N m]: measured torques less the model's.
    noise_rms : ndarray, shape (n,)
        The noise a perfect model leaves per joint [N m].
    name : str
        The recording's name.
    t0 : float, optional
        The log's first stamp [s].
    dq : ndarray, shape (N, n), optional
        The joint velocities the model was evaluated at [rad/s]; with ``friction``, the
        spans of friction's step at a reversal are told (``ErrorSpans.reversal``).
    friction : ndarray, shape (N, n), optional
        The model's friction torques [N m] at those samples.
    band : ndarray, shape (n,), or float
        The velocities' standstill band [rad/s]
        (:func:`~dynid.identification.friction_steps.reverses`).

    Returns
    -------
    ErrorSpans or None
        None where the error is within :data:`~dynid.identification.verdict.FLOOR_GOOD`
        x the noise, no span stands off, or the spans do not hold most of the error
        above the noise (module docstring).
    """
    t = np.asarray(t, dtype=np.float64)
    e = np.asarray(e, dtype=np.float64)
    noise2 = float(np.sum(np.asarray(noise_rms, dtype=np.float64) ** 2))
    sq = np.sum(e**2, axis=1)
    if noise2 <= 0 or t.size == 0 or sq.sum() <= FLOOR_GOOD**2 * t.size * noise2:
        return None
    spans = tuple(s for s in outlying_spans(t, e) if s.share >= MIN_SHARE)[:SPANS_SHOWN]
    if not spans:
        return None
    inside = np.zeros(t.size, dtype=bool)
    for s in spans:
        inside |= (t >= s.t0) & (t <= s.t1)
    share = float(sq[inside].sum() - inside.sum() * noise2) / float(sq.sum() - t.size * noise2)
    if share < MOST_SHARE or inside.mean() > SHORT_SHARE or inside.all():
        return None
    rest = float(np.sqrt(sq[~inside].mean() / noise2))
    at: tuple[bool, ...] = ()
    if dq is not None and friction is not None:
        dev, level = robust_levels(e)
        v, f = np.asarray(dq, dtype=np.float64), np.asarray(friction, dtype=np.float64)
        at = tuple(friction_step(s, t, dev, level, v, f, band) for s in spans)
    return ErrorSpans(name, spans, min(share, 1.0), rest, t0, at)
