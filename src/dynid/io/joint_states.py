"""JointState messages to a torque log: joints matched by name, cleaning counted.

The readers of ROS recordings (:mod:`dynid.io.rosbag` for bags,
:mod:`dynid.io.joint_state_csv` for CSV exports of a JointState topic) put each message
into :class:`JointStateMessages`; :func:`assemble` makes the torque log of them:

* **Joints by name.** Each message's ``name`` list may come in any order. A recorded
  name matches a robot joint when the names are equal, or when one is the other preceded
  by a prefix ending in ``_`` (``panda_joint1`` matches ``joint1``); of several, the equal
  name, else the one whose prefix matches the most robot joints (franka_ros's
  ``panda_finger_joint1`` does not take ``joint1`` from ``panda_joint1``; see
  :func:`match_joints`). Recorded joints that match no robot joint (fingers) are left
  out, said in ``notes``; one the robot's description holds at rest past its tip
  (``past_tip``: a gripper's joint, the chain cut before it) that the recording shows
  moving or away from 0 is said with its recorded range and the tip that keeps it.
  A missing or ambiguous match is an error unless ``joints=``
  names the recorded joints in the robot's joint order (the message gives the value to
  pass).
* **Signals.** ``position`` -> ``q`` [rad or m], ``velocity`` -> ``dq``, ``effort`` ->
  ``tau`` [N m or N]. When no message carries velocities the log is one of positions
  and torques (``velocity_derived``): its ``dq`` is the zero-phase filtered derivative of
  the positions (:func:`~dynid.identification.log.with_derived_velocities`), marked
  derived, so that every command derives it again at its own cut-off and
  :func:`~dynid.io.torque_log.save_torque_log` writes no velocities. Messages without
  effort cannot make a torque log.
* **Time.** ``header.stamp``; when any stamp is zero (unset), the receive times are used
  for all messages instead, said in ``notes``. Times are seconds **from the first
  message** (``t0_ns`` holds the first stamp in nanoseconds), so float64 keeps
  nanoseconds over days.
* **Cleaning, counted.** A message lacking one of the joints or with fewer
  ``position``/``velocity``/``effort`` entries than names is dropped; one holding NaN or
  inf in a used value is dropped; messages are sorted by time (counted when out of order)
  and a repeated stamp keeps the first message only.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import DataError
from ..identification.log import TorqueLog, timing_notes, with_derived_velocities

__all__ = [
    "JointStateImport",
    "JointStateMessages",
    "assemble",
    "match_joints",
    "past_tip_notes",
    "unused_joints",
]


def _prefix(bag: str, name: str) -> tuple[str, str] | None:
    """How bag name ``bag`` matches robot joint ``name``: ``("", "")`` equal names,
    ``("bag", p)`` the bag's name is ``p + name`` (``p`` ending in ``_``), ``("robot", p)``
    the robot's is ``p + bag``; None: no match (whole ``_``-separated tokens only)."""
    if bag == name:
        return ("", "")
    if bag.endswith("_" + name):
        return ("bag", bag[: -len(name)])
    if name.endswith("_" + bag):
        return ("robot", name[: -len(bag)])
    return None


def match_joints(
    robot_joints: Sequence[str],
    bag_joints: Sequence[str],
    joints: Sequence[str] | None = None,
    *,
    source: str = "bag",
) -> list[str]:
    """The recording's joint name for each robot joint, in the robot's order.

    A recorded name matches a robot joint when the names are equal, or when one is the other
    preceded by a prefix ending in ``_`` (``panda_joint1`` matches ``joint1``). Where
    several match (``panda_joint1`` and ``panda_finger_joint1`` for ``joint1``), the equal
    name wins, else the one of the prefix that matches the most robot joints
    (``panda_``: all seven; ``panda_finger_``: two). Bag joints that match no robot joint
    (a gripper's) are left out (:func:`unused_joints`).

    Parameters
    ----------
    robot_joints : sequence of str
        The robot's joint names (``robot.joint_names``).
    bag_joints : sequence of str
        Every joint name seen in the recording.
    joints : sequence of str, optional
        The recorded names in the robot's joint order (overrides the rule).
    source : str
        What the recording is called in messages (``"bag"``, ``"file"``).

    Returns
    -------
    list of str, length n

    Raises
    ------
    DataError
        ``joints`` of the wrong length or naming a joint not in the recording; a robot
        joint with no matching recorded name, or several that the rule does not tell apart (the
        message lists them and the ``--joints`` value to pass).
    """
    bag = list(dict.fromkeys(bag_joints))
    if joints is not None:
        joints = list(joints)
        if len(joints) != len(robot_joints):
            raise DataError(
                f"--joints must name {len(robot_joints)} joints (the robot's); got {len(joints)}"
            )
        unknown = [j for j in joints if j not in bag]
        if unknown:
            raise DataError(f"joint(s) {unknown} not in the {source}; the {source} has {bag}")
        return joints
    cands = {
        name: {b: k for b in bag if (k := _prefix(b, name)) is not None} for name in robot_joints
    }
    reach: dict[tuple[str, str], int] = {}  # robot joints each prefix matches
    for found in cands.values():
        for k in set(found.values()):
            reach[k] = reach.get(k, 0) + 1
    out = []
    for name in robot_joints:
        found = cands[name]
        best = [b for b, k in found.items() if k == ("", "")]
        if not best and found:
            top = max(reach[k] for k in found.values())
            best = [b for b, k in found.items() if reach[k] == top]
        if len(best) != 1:
            what = "no" if not found else f"several ({list(found)})"
            raise DataError(
                f"{what} {source} joint(s) match robot joint {name!r}; the {source} has "
                f"{bag}; hint: --joints with the {source}'s name of each robot joint "
                f"({', '.join(robot_joints)}), "
                f"in that order, e.g. --joints {_guess(robot_joints, bag, cands)}"
            )
        out.append(best[0])
    return out


def _guess(
    robot_joints: Sequence[str], bag: list[str], cands: dict[str, dict[str, tuple[str, str]]]
) -> str:
    """A ``--joints`` value to start from: each robot joint's first match, else the bag's
    name at its place."""
    names = [
        next(iter(cands[r]), bag[i] if i < len(bag) else r) for i, r in enumerate(robot_joints)
    ]
    return ",".join(names)


def unused_joints(bag_joints: Sequence[str], used: Sequence[str]) -> list[str]:
    """The recorded joints that no robot joint reads (a gripper's fingers), in their order."""
    return [b for b in dict.fromkeys(bag_joints) if b not in set(used)]


@dataclass(frozen=True, slots=True)
class JointStateImport:
    """A torque log read from a recording of JointState messages and what the reading found.

    Attributes
    ----------
    log : TorqueLog
        ``t`` [s] from the first kept message, ``q``, ``dq``, ``tau`` in the robot's order.
    topic : str
    joints : tuple of str
        The recording's joint name for each robot joint.
    time_source : str
        ``"header"`` (header stamps) or ``"receive"`` (receive times of the recording)
    t0_ns : int
        Time of the first kept message [ns] (the log's ``t = 0``).
    n_messages : int
        Messages on the topic.
    n_other_topics : int
        Messages on other topics (skipped).
    n_missing : int
        Messages dropped for a missing joint or field.
    n_nonfinite : int
        Messages dropped for NaN or inf.
    n_out_of_order : int
        Messages whose time was below the previous one's (sorted).
    n_duplicate_stamps : int
        Messages dropped because their time repeated the previous one.
    velocity_derived : bool
        No message carried velocities: the log's ``dq`` is derived from its positions
        (marked so; a saved log holds none).
    notes : tuple of str
    """

    log: TorqueLog
    topic: str
    joints: tuple[str, ...]
    time_source: str
    t0_ns: int
    n_messages: int
    n_other_topics: int
    n_missing: int
    n_nonfinite: int
    n_out_of_order: int
    n_duplicate_stamps: int
    velocity_derived: bool
    notes: tuple[str, ...]


#: Messages per chunk of the arrays a recording is read into (at most; the chunks of one
#: joint-name list start at :data:`_FIRST` and double, so that a bag whose messages list the
#: joints in many orders holds a small chunk per order, not a full one).
_CHUNK = 16_384
_FIRST = 4


class _Chunk:
    """Up to ``capacity`` messages of one joint-name list: their index in the recording and
    their ``position``, ``velocity``, ``effort`` in the list's order (NaN where short)."""

    def __init__(self, width: int, capacity: int) -> None:
        self.index = np.empty(capacity, dtype=np.int64)
        self.values = np.full((3, capacity, width), np.nan)
        self.capacity = capacity
        self.size = 0


class JointStateMessages:
    """JointState messages read one at a time into numpy chunks, grouped by their
    joint-name list (a recording of 1.6 million messages is never a list of message objects).

    ``count`` is the expected number of messages (0 when unknown); the per-message
    arrays grow beyond it when needed.
    """

    def __init__(self, count: int) -> None:
        self.n = 0
        self.stamp = np.empty(max(count, 1024), dtype=np.int64)
        self.recv = np.empty_like(self.stamp)
        self.short = np.zeros(self.stamp.size, dtype=bool)  # position or effort short
        self.short_vel = np.zeros(self.stamp.size, dtype=bool)
        self.keys: dict[tuple[str, ...], list[_Chunk]] = {}
        self.any_velocity = False
        self.any_effort = False

    def _reserve(self, count: int) -> int:
        """Room for ``count`` more messages; returns the index of the first."""
        k = self.n
        size = self.stamp.size
        while size < k + count:
            size *= 2
        if size != self.stamp.size:
            for a in ("stamp", "recv", "short", "short_vel"):
                old = getattr(self, a)
                new = np.zeros(size, dtype=old.dtype)
                new[: old.size] = old
                setattr(self, a, new)
        return k

    def _chunks(self, key: tuple[str, ...], k: int) -> list[_Chunk]:
        """The chunks of joint-name list ``key`` (first seen in message ``k``: checked)."""
        chunks = self.keys.setdefault(key, [])
        if not chunks:
            dup = sorted({s for s in key if key.count(s) > 1})
            if dup:  # the last value of the name was taken silently
                raise DataError(
                    f"message {k} names joint(s) {_checks.short(dup)} more than once; a "
                    "JointState message lists each joint once"
                )
        return chunks

    def add(self, recv_ns: int, m: object) -> None:
        """Store one message (``sensor_msgs/JointState``)."""
        k = self._reserve(1)
        st = m.header.stamp  # type: ignore[attr-defined]
        self.stamp[k] = int(st.sec) * 1_000_000_000 + int(st.nanosec)
        self.recv[k] = int(recv_ns)
        key = tuple(m.name)  # type: ignore[attr-defined]
        w = len(key)
        chunks = self._chunks(key, k)
        if not chunks:
            chunks.append(_Chunk(w, _FIRST))
        elif chunks[-1].size == chunks[-1].capacity:
            chunks.append(_Chunk(w, min(2 * chunks[-1].capacity, _CHUNK)))
        c = chunks[-1]
        c.index[c.size] = k
        fields = (m.position, m.velocity, m.effort)  # type: ignore[attr-defined]
        for f, v in enumerate(fields):
            if len(v) >= w:
                c.values[f, c.size] = np.asarray(v[:w], dtype=np.float64)
        self.any_velocity |= len(fields[1]) > 0
        self.any_effort |= len(fields[2]) > 0
        self.short[k] = len(fields[0]) < w or len(fields[2]) < w
        self.short_vel[k] = len(fields[1]) < w
        c.size += 1
        self.n += 1

    def add_block(
        self,
        stamp_ns: NDArray[np.int64],
        recv_ns: NDArray[np.int64],
        key: tuple[str, ...],
        values: NDArray[np.float64],
        blank: NDArray[np.bool_],
    ) -> None:
        """Store messages of one joint-name list at once (the rows of a CSV export).

        Parameters
        ----------
        stamp_ns, recv_ns : ndarray, shape (N,)
            Header stamps and receive times [ns] (0: unset).
        key : tuple of str, length w
            The joint names of every message of the block.
        values : ndarray, shape (3, N, w)
            ``position``, ``velocity``, ``effort`` in the order of ``key``.
        blank : ndarray of bool, shape (3, N, w)
            Where a value was not recorded (a field the export lacks is blank
            throughout): such a message is short, as one whose field lists fewer
            entries than names.
        """
        N, w = values.shape[1], len(key)
        k = self._reserve(N)
        chunks = self._chunks(key, k)
        c = _Chunk(w, N)
        c.index[:] = np.arange(k, k + N)
        c.values[:] = np.where(blank, np.nan, values)
        c.size = N
        chunks.append(c)
        self.stamp[k : k + N] = stamp_ns
        self.recv[k : k + N] = recv_ns
        self.short[k : k + N] = blank[0].any(axis=1) | blank[2].any(axis=1)
        self.short_vel[k : k + N] = blank[1].any(axis=1)
        self.any_velocity |= bool(np.any(~blank[1]))
        self.any_effort |= bool(np.any(~blank[2]))
        self.n += N

    def names(self) -> list[str]:
        """Every joint name, in the order of first appearance."""
        seen: dict[str, None] = {}
        for key in self.keys:
            seen.update(dict.fromkeys(key))
        return list(seen)

    def arrays(
        self, mapping: list[str]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
        """``q, dq, tau`` (N, n) in the order of ``mapping`` and which messages hold every
        joint of it."""
        n, N = len(mapping), self.n
        out = np.full((3, N, n), np.nan)
        has = np.zeros(N, dtype=bool)
        for key, chunks in self.keys.items():
            pos = {s: i for i, s in enumerate(key)}
            if not all(s in pos for s in mapping):
                continue
            idx = [pos[s] for s in mapping]
            for c in chunks:
                rows = c.index[: c.size]
                out[:, rows] = c.values[:, : c.size][:, :, idx]
                has[rows] = True
        return out[0], out[1], out[2], has


#: A recorded position [rad or m] that the model at 0 misdescribes: a joint past the tip
#: moving more than this, or never nearer 0 than this.
AWAY_FROM_ZERO = 1e-3


def past_tip_notes(
    source: str,
    msgs: JointStateMessages,
    extra: Sequence[str],
    past_tip: Mapping[str, tuple[str | None, str]],
) -> dict[str, str]:
    """The note of each recorded joint of ``extra`` (matching no robot joint) that
    ``past_tip`` names (a URDF joint past the chain's tip, held at 0 in the model: its
    tip link that keeps it, or None, and its unit; :func:`~dynid.io.robot.urdf_parse.
    joints_past_tip`) and that the recording shows moving, or resting away from 0, by
    more than :data:`AWAY_FROM_ZERO`: its recorded range and the tip that keeps it."""
    out: dict[str, str] = {}
    for bag in extra:
        robot = next((r for r in past_tip if _prefix(bag, r) is not None), None)
        if robot is None:
            continue
        q = msgs.arrays([bag])[0][:, 0]
        q = q[np.isfinite(q)]
        if q.size == 0:
            continue
        lo, hi = float(q.min()), float(q.max())
        nearest = 0.0 if lo <= 0.0 <= hi else min(abs(lo), abs(hi))
        if max(hi - lo, nearest) <= AWAY_FROM_ZERO:
            continue
        tip, unit = past_tip[robot]
        where = (
            f"held at {lo:.3g} {unit}"
            if hi - lo <= AWAY_FROM_ZERO
            else f"moving from {lo:.3g} to {hi:.3g} {unit}" + (", never at 0" if nearest else "")
        )
        keep = f"; tip_link={tip!r} keeps it as a joint of the model" if tip else ""
        out[bag] = (
            f"{source} joint {bag} lies past the robot's tip, where the model holds its links "
            f"at rest (its joint at 0), but the {source} records it {where}: the model "
            f"misdescribes what the arm carries there{keep}"
        )
    return out


def assemble(
    name: str,
    topic: str,
    msgs: JointStateMessages,
    n_total: int,
    robot_joints: Sequence[str],
    joints: Sequence[str] | None,
    cutoff_hz: float,
    gap_factor: float,
    source: str = "bag",
    past_tip: Mapping[str, tuple[str | None, str]] | None = None,
) -> JointStateImport:
    """The torque log of ``msgs`` (the module docstring's rules) and what was found.

    ``name`` is the recording's file name and ``source`` what messages call it (``"bag"``,
    ``"file"``); ``n_total`` counts the recording's messages on every topic (those on
    other topics are counted as skipped); ``joints``, ``cutoff_hz``, ``gap_factor`` and
    ``past_tip`` as in :func:`~dynid.io.rosbag.load_joint_state_bag`.

    Raises
    ------
    DataError
        No message, joints that do not match, no effort, fewer than 2 usable messages,
        or times :meth:`TorqueLog.from_raw` refuses.
    """
    n_msg = msgs.n
    if n_msg == 0:
        raise DataError(f"topic {topic!r} holds no message", file=name)
    mapping = match_joints(robot_joints, msgs.names(), joints, source=source)
    stamps = msgs.stamp[:n_msg]
    notes = []
    extra = unused_joints(msgs.names(), mapping)
    past = past_tip_notes(source, msgs, extra, past_tip or {})
    if rest := [b for b in extra if b not in past]:
        notes.append(f"{source} joint(s) {', '.join(rest)} match no robot joint: left out")
    notes += past.values()
    if np.any(stamps == 0):
        stamps = msgs.recv[:n_msg]
        time_source = "receive"
        notes.append(f"header stamps unset (zero): receive times of the {source} used instead")
    else:
        time_source = "header"
    has_vel = msgs.any_velocity
    if not msgs.any_effort:
        raise DataError(
            f"no JointState message on {topic!r} holds effort; a torque log needs torques",
            file=name,
        )
    q, dq, tau, keep = msgs.arrays(mapping)
    keep &= ~msgs.short[:n_msg]
    if has_vel:
        keep &= ~msgs.short_vel[:n_msg]
    n_missing = int(np.count_nonzero(~keep))
    finite = np.all(np.isfinite(q), 1) & np.all(np.isfinite(tau), 1)
    if has_vel:
        finite &= np.all(np.isfinite(dq), 1)
    n_nonfinite = int(np.count_nonzero(keep & ~finite))
    keep &= finite
    stamps, q, dq, tau = stamps[keep], q[keep], dq[keep], tau[keep]
    n_out = int(np.count_nonzero(np.diff(stamps) < 0))
    order = np.argsort(stamps, kind="stable")
    stamps, q, dq, tau = stamps[order], q[order], dq[order], tau[order]
    first = np.concatenate([[True], np.diff(stamps) != 0]) if stamps.size else stamps.astype(bool)
    n_dup = int(np.count_nonzero(~first))
    stamps, q, dq, tau = stamps[first], q[first], dq[first], tau[first]
    if stamps.size < 2:
        same = ""
        if n_dup:  # every usable message has the one stamp left
            sec, ns = divmod(int(stamps[0]), 1_000_000_000)
            same = (
                f", {n_dup + 1} sharing one {time_source} stamp ({sec}.{ns:09d} s): a log needs "
                "messages at distinct times"
            )
        raise DataError(
            f"fewer than 2 usable JointState messages on {topic!r} "
            f"({n_missing} missing a joint or field, {n_nonfinite} with NaN{same})",
            file=name,
        )
    t0 = int(stamps[0])
    t = (stamps - t0).astype(np.float64) * 1e-9
    try:
        if has_vel:
            log = TorqueLog.from_raw(t, q, dq, tau, gap_factor=gap_factor)
        else:
            raw = TorqueLog.from_raw(t, q, np.zeros_like(q), tau, gap_factor=gap_factor)
            log = with_derived_velocities(raw, cutoff_hz)  # marked derived: never saved
    except DataError as exc:
        raise DataError(str(exc), file=name) from exc
    for count, what in (
        (n_total - n_msg, "message(s) on other topics skipped"),
        (n_missing, "message(s) missing a joint or field dropped"),
        (n_nonfinite, "message(s) with NaN or inf dropped"),
        (n_out, "message(s) out of time order sorted"),
        (n_dup, "message(s) with a repeated stamp dropped"),
    ):
        if count:
            notes.append(f"{count} {what}")
    notes += timing_notes(log.cleaning)
    return JointStateImport(
        log=log,
        topic=topic,
        joints=tuple(mapping),
        time_source=time_source,
        t0_ns=t0,
        n_messages=n_msg,
        n_other_topics=n_total - n_msg,
        n_missing=n_missing,
        n_nonfinite=n_nonfinite,
        n_out_of_order=n_out,
        n_duplicate_stamps=n_dup,
        velocity_derived=not has_vel,
        notes=tuple(notes),
    )
