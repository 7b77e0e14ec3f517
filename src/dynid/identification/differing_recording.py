"""A recording whose held-out error stands clearly above the others': named in a note.

A recording far above the others (:data:`~.candidates.OUTLIER_RATIO` x their median) is
left out (:mod:`~.outlying_recordings`). One whose torques differ less, a cold run whose
viscous friction is 20 % higher, stays below that rule, is fitted with the others and
pulls their coefficients towards it (a UR3's ``fv1`` 2.07 and ``fv2`` 2.09 for a true 2.0;
its held-out error 3.47 % against 1.84 to 2.13 % for the others). It is named, not left
out: the user compares the fit without it.

Each recording's held-out error (fitted on the others) is read in units of its own noise
floor (:func:`recording_floors`: the relative error a perfect model leaves on its torques,
:func:`~.metrics.noise_floor_percent`), which takes out what differs between recordings
for no fault of the model (the torques' size against the sensors' noise). Recordings alike
then sit near one another: their ratios scatter by the model's error on each motion. A
recording is named (:func:`differing_recording`) where its ratio stands above the median
of the others' by :data:`NOTE_Z` times their spread (their standard deviation, at least
:data:`SPREAD_SHARE` of their median: three or four close ratios can be closer than their
true scatter) and at least :data:`NOTE_RATIO` times that median (a difference that
matters, not only one the spread resolves). The spread of two to four other recordings
is itself uncertain (a Student t of 1 to 3 degrees of freedom: 4 lies at its 1.4 to 8 %
tail), hence both conditions at once and the floor on the spread: a recording alike would
have to stand 30 % above the others' median and 4 of their standard deviations above it.
The UR3's cold run stands 8.0 standard deviations and 1.9 x above its warm ones, the warm
ones at most 0.4 standard deviations and 1.2 x; the warm ones alone name none.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .candidates import Selection
from .metrics import noise_floor_percent
from .recordings import Recordings
from .verdict import ROUND_OFF_PERCENT

__all__ = ["DifferingRecording", "differing_recording", "recording_floors", "with_differing"]

#: A recording is named where its error over its floor lies this many standard deviations
#: of the others' above their median ...
NOTE_Z = 4.0
#: ... and at least this many times their median.
NOTE_RATIO = 1.3
#: The others' spread counted at least this share of their median ratio.
SPREAD_SHARE = 0.1


@dataclass(frozen=True, slots=True)
class DifferingRecording:
    """A recording whose held-out error stands clearly above the others' (module docstring).

    Attributes
    ----------
    name : str
    error : float
        Its held-out error [%] (fitted on the others).
    floor : float
        Its noise floor [%].
    others : tuple of (str, float, float)
        The other recordings judged: name, held-out error [%] and noise floor [%].
    z : float
        Its error over its floor above the others' median, in their spread.
    """

    name: str
    error: float
    floor: float
    others: tuple[tuple[str, float, float], ...]
    z: float

    @property
    def ratio(self) -> float:
        """Its held-out error over its noise floor."""
        return self.error / self.floor

    def sentence(self) -> str:
        """The note: the recording, its error against the others', what to do."""
        errs = [e for _, e, _ in self.others]
        ratios = [e / f for _, e, f in self.others]
        return (
            f"{self.name}: held-out error {self.error:.3g} % ({self.ratio:.3g} x its noise "
            f"floor of {self.floor:.3g} %), clearly above the other recordings' "
            f"({min(errs):.3g} to {max(errs):.3g} %, {min(ratios):.3g} to {max(ratios):.3g} x "
            f"theirs; {self.z:.2g} standard deviations of theirs above their median) though "
            "not outlying: its torques differ from theirs (friction that changed with "
            "temperature, a cold start, another payload or set-up?) and the fit, which "
            "keeps it, is pulled towards it; to compare, identify without it (--keep-outlying "
            "is unrelated: it keeps recordings left out as outlying); "
            "metadata.selection.differing_recordings"
        )

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready (an entry of ``metadata.selection.differing_recordings``)."""
        return {
            "file": self.name,
            "heldout_error_percent": self.error,
            "noise_floor_percent": self.floor,
            "floor_ratio": self.ratio,
            "z": self.z,
            "others": [
                {"file": n, "heldout_error_percent": e, "noise_floor_percent": f}
                for n, e, f in self.others
            ],
            "rule": (
                f"error over its floor >= {NOTE_RATIO:g} x the others' median and "
                f"{NOTE_Z:g} x their standard deviation (at least {SPREAD_SHARE:g} x their "
                "median) above it"
            ),
        }


def recording_floors(data: Recordings) -> dict[str, float]:
    """Each recording's noise floor [%] (:func:`~.metrics.noise_floor_percent` of its
    pieces' torques as judged: as measured where the pieces hold them, else low-passed,
    with the filter's noise gain), by name; a recording whose noise is not known is not
    in it."""
    from ..signals import lowpass_noise_gain

    out = {}
    for r, name in enumerate(data.names):
        mine = [p for p, k in zip(data.pieces, data.recording, strict=True) if k == r]
        if not mine or any(p.torque_noise_std is None for p in mine):
            continue
        measured = data.measured
        taus = [p.targets(p.tau_raw if measured and p.tau_raw is not None else None) for p in mine]
        gains = [
            1.0 if measured else lowpass_noise_gain(p.sample_rate_hz, p.cutoff_hz) for p in mine
        ]
        noise = [np.asarray(p.torque_noise_std, dtype=np.float64) for p in mine]
        floor = noise_floor_percent(taus, noise, gains)
        if floor is not None and floor > 0:
            out[name] = floor
    return out


def differing_recording(
    per: Sequence[tuple[str, float]],
    floors: dict[str, float],
    outlying: Collection[str] = (),
    round_off: float = 0.0,
) -> tuple[DifferingRecording, ...]:
    """The recordings whose held-out error (``per``: name and error [%], each fitted on the
    others) over its noise floor (``floors`` [%]) stands clearly above the others' (module
    docstring); those ``outlying`` neither judged nor counted among the others. None with
    fewer than three recordings judged, a floor unknown or at ``round_off`` [%] (exact
    logs: their errors say nothing of it)."""
    judged = [(n, e, floors.get(n)) for n, e in per if n not in outlying]
    if len(judged) < 3 or any(f is None or not f > round_off for _, _, f in judged):
        return ()
    rows = [(n, e, float(f)) for n, e, f in judged if f is not None]
    ratio = np.array([e / f for _, e, f in rows])
    out = []
    for k, (name, e, f) in enumerate(rows):
        rest = np.delete(ratio, k)
        med = float(np.median(rest))
        spread = max(float(np.std(rest, ddof=1)), SPREAD_SHARE * med)
        z = (ratio[k] - med) / spread if spread > 0 else 0.0
        if z >= NOTE_Z and ratio[k] >= NOTE_RATIO * med:
            others = tuple(r for j, r in enumerate(rows) if j != k)
            out.append(DifferingRecording(name, e, f, others, float(z)))
    return tuple(out)


def with_differing(selection: Selection, data: Recordings) -> Selection:
    """``selection`` with the recordings of ``data`` whose held-out error stands clearly
    above the others' (:func:`differing_recording` of its ``per_recording``, its outlying
    ones apart) in its notes and record (:attr:`~.candidates.Selection.differing`)."""
    found = differing_recording(
        selection.per_recording, recording_floors(data), selection.outlying, ROUND_OFF_PERCENT
    )
    if not found:
        return selection
    return replace(
        selection,
        notes=(*selection.notes, *(d.sentence() for d in found)),
        differing=tuple(d.as_dict() for d in found),
    )
