"""How well the wrench at a frame explains an event's residual, and what a poor fit says.

The estimate at a frame (:func:`~dynid.observer.wrench.external_wrench`) is the wrench
whose joint torques ``J^T w`` best explain the residual ``r``; what it leaves,
``|r - J^T w|^2`` per sample (:attr:`~dynid.observer.wrench.WrenchEstimate.unexplained`),
is noise when the contact acts where the estimate assumes it, and most of the residual
when it does not: a contact on a link before the frame (an elbow, with ``--frame flange``)
gives no torque on the joints between it and the frame, which no wrench at the frame
reproduces. On a simulated Panda, a force at the hand leaves 0.3-0.5 % of ``|r|``
unexplained over its event, one at link4 43-68 % of it at the flange.

* :func:`unexplained_shares`: per event, ``sqrt(sum |r - J^T w|^2 / sum |r|^2)`` over its
  samples (0 to 1), and the same with the noise's own share taken off first (the noise
  of ``r`` outside the range of ``J^T``: ``(n - k) / n`` of ``sum (c_j / 3)^2`` per sample,
  ``c`` the contact thresholds, at least three of the residual's standard deviations:
  an upper bound of the noise);
* :func:`force_torques`: the joint torques ``J_v^T f`` of the estimate's force part
  alone, and :func:`force_peaks`, their largest per event;
* :func:`off_frame_warning`: one line per log naming the events whose share over the
  noise exceeds :data:`UNEXPLAINED_SHARE`, or that leave :data:`QUIET_JOINTS` or more
  joints just before the frame under their contact threshold while the estimate's force
  alone, ``J_v^T f``, puts more than their threshold on them: only a moment cancelling
  it there keeps them quiet (with seven joints and six components the flange can explain
  most of an elbow contact's torques by a large force and moment that cancel on them,
  which the share alone misses: 1-15 % unexplained on three of seven such events). A
  force truly at the frame that loads those joints less than their thresholds (a UR5's
  wrist under a push at tool0, 0.6-1.1 % unexplained) is not blamed: the joints' quiet
  is then what the force itself says. With the last joint whose residual clearly rose
  over its noise (the likely link) and the way out (``--frame`` at that link).

Times in seconds, torques in N m. Pure functions over arrays.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..kinematics.jacobian import jacobian
from ..model.robot import Robot
from .detection import ContactEvent

__all__ = [
    "QUIET_JOINTS",
    "UNEXPLAINED_SHARE",
    "force_peaks",
    "force_torques",
    "likely_joint",
    "off_frame_warning",
    "quiet_joints",
    "unexplained_shares",
]

#: Joints just before the frame (those a wrench at the frame loads: all but the frame's
#: own last joint, whose axis its origin often lies on) whose residual staying under their
#: contact threshold through an event, while the estimate's force alone loads them over
#: it, says the contact is on a link before them (a moment at the frame cancels the
#: force's torque there): a hand contact loads them 3-40 times over it, an elbow contact
#: leaves them under 0.6 times it.
QUIET_JOINTS = 2
#: The share of an event's ``|r|`` that the wrench at the frame may leave unexplained, the
#: noise's own share taken off, before a warning says the contact is likely elsewhere: a
#: hand contact leaves under 1 % at the flange, an elbow contact over 40 %.
UNEXPLAINED_SHARE = 0.2


def unexplained_shares(
    t: ArrayLike,
    events: Sequence[ContactEvent],
    left: ArrayLike,
    r: ArrayLike,
    contact: ArrayLike,
    determined: int,
) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """What the wrench at a frame leaves of each event's residual.

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s].
    events : sequence of ContactEvent
        The log's events (``start``, ``end`` [s]).
    left : array_like, shape (N,)
        ``|r - J^T w|^2`` per sample [N^2 m^2] (NaN where the observer did not run).
    r : array_like, shape (N, n)
        The residual [N m].
    contact : array_like, shape (n,)
        The contact thresholds [N m], three or more standard deviations of the noise.
    determined : int
        The components the estimate determined (``k``, the rank of ``J^T``).

    Returns
    -------
    share, over_noise : tuple of float
        Per event (0 to 1; NaN: no sample): ``sqrt(sum left / sum |r|^2)``, and the same
        with the noise's expected share taken off ``sum left`` first (module docstring).
    """
    t = np.asarray(t, dtype=np.float64)
    lf = np.asarray(left, dtype=np.float64)
    ra = np.asarray(r, dtype=np.float64)
    c = np.asarray(contact, dtype=np.float64)
    n = ra.shape[-1]
    noise = max(n - determined, 0) / n * float(np.sum((c / 3.0) ** 2))
    share, over = [], []
    for e in events:
        a, b = np.searchsorted(t, e.start, "left"), np.searchsorted(t, e.end, "right")
        ok = np.isfinite(lf[a:b]) & np.all(np.isfinite(ra[a:b]), axis=-1)
        total = float(np.sum(ra[a:b][ok] ** 2))
        if not ok.any() or total <= 0.0:
            share.append(float("nan"))
            over.append(float("nan"))
            continue
        unexplained = float(np.sum(lf[a:b][ok]))
        share.append(min(np.sqrt(unexplained / total), 1.0))
        over.append(min(np.sqrt(max(unexplained - noise * int(ok.sum()), 0.0) / total), 1.0))
    return tuple(share), tuple(over)


def force_torques(robot: Robot, q: ArrayLike, wrench: ArrayLike, frame: str) -> NDArray[np.float64]:
    """``J_v(q)^T f`` (..., n) [N m]: the joint torques of the force part ``f`` (the first
    three components of ``wrench`` (..., 6) [N, N m], base axes, at ``frame``'s origin)
    alone, without its moment; NaN where the wrench is NaN."""
    J = jacobian(robot, np.asarray(q, dtype=np.float64), frame)[..., :3, :]
    f = np.asarray(wrench, dtype=np.float64)[..., :3]
    return np.asarray(np.einsum("...ij,...i->...j", J, f), dtype=np.float64)


def force_peaks(
    t: ArrayLike, events: Sequence[ContactEvent], pushed: ArrayLike
) -> tuple[tuple[float, ...], ...]:
    """The largest ``|J_v^T f|`` (:func:`force_torques`, ``pushed`` (N, n) [N m] at the
    times ``t`` (N,) [s]) per joint over each event (NaN: no sample)."""
    ta = np.asarray(t, dtype=np.float64)
    P = np.abs(np.asarray(pushed, dtype=np.float64))
    out = []
    for e in events:
        a, b = np.searchsorted(ta, e.start, "left"), np.searchsorted(ta, e.end, "right")
        ok = np.all(np.isfinite(P[a:b]), axis=1)
        top = P[a:b][ok].max(axis=0) if ok.any() else np.full(P.shape[1], np.nan)
        out.append(tuple(float(x) for x in top))
    return tuple(out)


def quiet_joints(
    event: ContactEvent, j: int, frame_link: int, contact: ArrayLike, pushed: Sequence[float]
) -> int:
    """How many joints after joint ``j`` (1-based) and before the frame's last
    (``frame_link``, the joints moving it) stay under their ``contact`` threshold (n,)
    [N m] through ``event`` while the estimate's force alone loads them over it
    (``pushed`` (n,) [N m], :func:`force_peaks`): only a cancelling moment keeps them
    quiet."""
    c = np.asarray(contact, dtype=np.float64)
    peak = np.abs(np.asarray(event.peak, dtype=np.float64))
    f = np.asarray(pushed, dtype=np.float64)
    idx = np.arange(j, max(frame_link - 1, j))
    return int(np.count_nonzero((peak[idx] <= c[idx]) & (f[idx] > c[idx])))


def likely_joint(event: ContactEvent, contact: ArrayLike) -> int:
    """The last joint (1-based) whose ``|peak|`` over ``event`` exceeds its contact
    threshold ``contact`` (n,) [N m]: the contact is on its link or one before; the
    event's last joint over the threshold when no peak does."""
    c = np.asarray(contact, dtype=np.float64)
    over = np.flatnonzero(np.abs(np.asarray(event.peak, dtype=np.float64)) > c)
    return int(over[-1]) + 1 if over.size else int(max(event.joints))


def off_frame_warning(
    log: str,
    frame: str,
    noun: str,
    events: Sequence[ContactEvent],
    share: Sequence[float],
    over_noise: Sequence[float],
    contact: ArrayLike,
    joint_names: Sequence[str],
    link_names: Sequence[str],
    frame_link: int,
    pushed: Sequence[Sequence[float]],
) -> str | None:
    """One line for a log whose events leave more than :data:`UNEXPLAINED_SHARE` of their
    residual unexplained by the ``noun`` (wrench or force) at ``frame``, the noise's share
    taken off (``over_noise``, :func:`unexplained_shares`), or leave
    :data:`QUIET_JOINTS` or more joints before it under their threshold that the
    estimate's force alone loads over it (``pushed``, :func:`force_peaks`, one (n,) per
    event; :func:`quiet_joints`): which events,
    how much (``share``, before the noise is taken off), the
    last joint clearly over its noise in them (:func:`likely_joint`) and its link
    (``link_names[j]``, the base first), before or after the frame's link
    (``frame_link``, the joints moving it), and ``--frame`` there; None when none does."""
    bad = []
    for e, raw, s, f in zip(events, share, over_noise, pushed, strict=True):
        j = likely_joint(e, contact)
        quiet = quiet_joints(e, j, frame_link, contact, f)  # a moment cancels the force
        if (np.isfinite(s) and s > UNEXPLAINED_SHARE) or quiet >= QUIET_JOINTS:
            what = f"{100.0 * raw:.2g} %" if np.isfinite(raw) else "?"
            if quiet >= QUIET_JOINTS:
                what += f", {joint_names[j]}..{joint_names[frame_link - 2]} quiet"
            bad.append((e, what, j))
    if not bad:
        return None
    j = max(k for *_, k in bad)
    when = ", ".join(f"{e.start:.3f} s ({what})" for e, what, _ in bad)
    link = link_names[j]
    where = (
        f"before {frame} or away from its origin"
        if j <= frame_link
        else f"after {frame} (its joints feel it)"
    )
    hint = (
        f"--frame {link}"
        if link != frame
        else f"a frame at the contact point (the {noun} at {frame}'s origin cannot be it)"
    )
    return (
        f"{log}: the {noun} at {frame} does not fit {len(bad)} event(s): {when} (of |r| "
        f"unexplained by it; more than {100.0 * UNEXPLAINED_SHARE:.0f} % over the noise, or "
        f"{QUIET_JOINTS} or more joints before {frame} under their contact threshold that "
        f"the force at {frame} alone loads over it): it is no {noun} at {frame} (at best "
        "the contact's equivalent there, often off). The contact is "
        f"likely on a link {where}: the last joint whose residual rises clearly over its "
        f"noise is {joint_names[j - 1]}, so on {link}, or on a later link at a point on the "
        f"axes of the joints after {joint_names[j - 1]} (which then feel nothing); try "
        f"{hint} (events.json: unexplained_share per event)"
    )
