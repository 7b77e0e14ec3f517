"""What an identification did: the typed record an identified model carries.

:class:`IdentificationInfo` replaces a free dictionary: the route, the reference, the rows
used and dropped, the coefficients pruned, the estimator and how the standard deviations
were estimated, the rank tolerance and gap, the identifiability of every standard
parameter, and the route's own part: :class:`StaticInfo` (configurations) or
:class:`LogInfo` (filtering, decimation, sample counts). The model terms' coefficients
(friction) are the model's own (:class:`~dynid.identification.model.IdentifiedTerm`). It is
written to and read from the ``metadata`` object of ``identification.json`` with the keys
that file has always used (:mod:`dynid.io.model_json`); keys this version does not know are
kept in ``extra``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from .least_squares import StdMethod
from .prepare import Preprocessing

__all__ = ["IdentificationInfo", "LogInfo", "Route", "StaticInfo"]

#: The identification routes: static data (Gaz et al. 2019, Sec. IV-A) or a torque log
#: (Sec. IV-B).
Route = Literal["static", "classical"]


@dataclass(frozen=True, slots=True)
class StaticInfo:
    """The static route's data.

    Attributes
    ----------
    n_configurations : int
        Configurations ``N``.
    rows_per_configuration : int
        Rows of ``[tril M; g]`` used per configuration (after dropping those without
        information).
    """

    n_configurations: int
    rows_per_configuration: int


@dataclass(frozen=True, slots=True)
class LogInfo:
    """The classical route's preparation of the torque log.

    Attributes
    ----------
    cutoff_hz : float or None
        Zero-phase low-pass cutoff [Hz]; None without filtering.
    trim_s : float
        Seconds dropped at the start (filter edge).
    decimate : int
        Every ``decimate``-th sample was kept.
    sample_rate_hz : float
        Rate of the raw log [Hz].
    n_samples_log, n_samples_used : int
        Samples in the raw log and in the fit.
    duration_s : float
        Length of the raw log [s].
    n_nan_rows, n_duplicates, n_gaps : int
        What cleaning the raw log found (:class:`~dynid.identification.log.LogCleaning`).
    cutoff_source : {"given", "motion", "exact"}
        The cut-off was given, or read from the motion (:mod:`dynid.identification.rate`);
        ``"exact"``: none, the logs being exact to round-off
        (:func:`~dynid.identification.input_noise.exact_to_round_off`), and ``validate``
        and ``friction`` read a recording's own from its motion unless it is exact too.
    motion_frequency_hz : float or None
        The motion's highest significant frequency [Hz] when the cut-off was read from it.
    resampled : bool
        The timestamps were not uniform: the log was resampled onto a uniform grid.
    n_cuts : int
        Gaps longer than the longest gap bridged: the logs were cut into pieces there
        (``n_gaps`` counts the gaps bridged).
    max_gap_s : float or None
        The longest gap bridged, as given [s]; None: the default rule
        (:func:`~dynid.identification.log.default_max_gap`). ``validate`` and ``friction``
        cut their recordings with it unless told otherwise.
    n_dropped : int
        Samples missing from the stamps' grid over the recordings (jitter drops none).
    stamp_jitter_s : float
        Standard deviation of the timestamps about their grid [s] (the largest of the
        recordings'; 0 for uniform stamps).
    torque_delay_s : float
        How far the torques were taken to lag the positions [s] (``--torque-delay``;
        :attr:`~dynid.identification.prepare.Preprocessing.torque_delay_s`): each piece's
        torques read that much later before filtering. ``validate`` and ``friction``
        prepare their recordings with it unless told otherwise; 0 in older records.
    speed_max : tuple of float or None
        Each joint's largest speed [rad/s or m/s] over the samples used (as prepared, at
        the joints): the motion the model was identified on, which ``validate`` compares
        a recording's with (:mod:`~dynid.identification.motion_range`); None in older
        records.
    position_range, velocity_range : tuple of (float, float) or None
        Each joint's lowest and highest position [rad or m] and velocity [rad/s or m/s]
        over the samples used (as prepared, at the joints): the poses and motion the model
        was identified on, which ``validate`` compares a recording's with
        (:mod:`~dynid.identification.training_range`); None in older records.
    drop_invalid : bool
        Rows with NaN/inf or a repeated timestamp were dropped from the logs
        (``--drop-invalid``) instead of refused: ``validate``, ``friction``, ``observe``
        and ``payload`` read their recordings so too (False in older records).
    """

    cutoff_hz: float | None
    trim_s: float
    decimate: int
    sample_rate_hz: float
    n_samples_log: int
    n_samples_used: int
    duration_s: float
    n_nan_rows: int = 0
    n_duplicates: int = 0
    n_gaps: int = 0
    cutoff_source: str = "given"
    motion_frequency_hz: float | None = None
    resampled: bool = False
    n_cuts: int = 0
    max_gap_s: float | None = None
    speed_max: tuple[float, ...] | None = None
    n_dropped: int = 0
    stamp_jitter_s: float = 0.0
    torque_delay_s: float = 0.0
    drop_invalid: bool = False
    position_range: tuple[tuple[float, float], ...] | None = None
    velocity_range: tuple[tuple[float, float], ...] | None = None

    @property
    def preprocessing(self) -> Preprocessing:
        """The preparation the log was identified with, as the record
        :func:`~dynid.identification.prepare.prepare_log` reads: the cut-off, the gap rule and
        the decimation (the torques low-passed), ``trim_s`` None (each recording's filter
        edge is its own, :func:`~dynid.identification.trim.edge_seconds`). Validation, the
        friction fit and payload identification prepare their recordings with it unless told
        otherwise."""
        return Preprocessing(
            cutoff_hz=self.cutoff_hz,
            max_gap_s=self.max_gap_s,
            decimate=int(self.decimate),
            torque_delay_s=float(self.torque_delay_s),
        )


@dataclass(frozen=True, slots=True)
class IdentificationInfo:
    """What an identification did (module docstring).

    Attributes
    ----------
    route : {"static", "classical"} or None
        None for a model built by hand.
    reference : str
        The method's source (paper, section, equations).
    n_rows : int
        Rows in the least squares.
    dropped_rows : tuple of str
        Rows without information for this robot (``"g1"``).
    pruned : tuple of str
        Labels of the coefficients removed above ``max_std_percent``.
    max_std_percent : float or None
    std : {"classical", "robust", "hac"} or None
        How the standard deviations were estimated (``std=``, ``--std``; the file's
        ``std_estimator``).
    estimator : str
        ``"ols"``, ``"wls"``, ``"irls"`` or a user's estimator's name.
    rtol : float or None
        The rank tolerance asked for (None: the defaults).
    rank_gap : tuple of float, optional
        Singular values either side of the base parameters' rank cut (relative).
    identifiability : mapping
        ``identifiable``, ``combination`` or ``unidentifiable`` per standard parameter.
    seed : int or None
        The seed of simulated data, when known.
    data : mapping
        The static data set's own metadata (source, noise, seed, robot).
    static, log : StaticInfo or LogInfo, optional
        The route's own part.
    heldout : mapping, optional
        Training and held-out errors of least squares
        (:meth:`~dynid.identification.holdout.HeldOutErrors.as_dict`).
    column_map : mapping, optional
        ``{"columns": ..., "units": ...}``: how the data file's columns were read
        (``--columns``/``--units``), so that validation reads a log the same way.
    selection : mapping, optional
        The model structure chosen on held-out data
        (:mod:`dynid.identification.selection`): ``rule``, ``validation``, ``chosen`` and
        every ``candidates`` entry with its parameters, training and held-out errors.
    estimator_choice : mapping, optional
        The estimator chosen on held-out data
        (:class:`~dynid.identification.estimator_choice.EstimatorChoice`): ``rule``,
        ``chosen`` and every ``candidates`` entry (``estimator`` with its training and
        held-out errors); None when the estimator was given or not chosen.
    recordings : tuple of mapping
        Torque logs: each recording read (``file``, ``pieces``, ``samples``, ``duration_s``).
    notes : tuple of str
        Remarks for the reader (one sentence each).
    extra : mapping
        Entries of a file that this version does not know (kept when saved again).
    combined : mapping of str to str
        The coefficients that hold a structurally combined one left out (a differential
        wrist's viscous friction at both motors and both joints: ``jfv7`` left out), each
        with what it holds (``{"fv6": "fv6 + 0.0005556*jfv7"}``,
        :func:`~dynid.identification.structural.absorbed_by`); empty for none.
    """

    route: Route | None = None
    reference: str = ""
    n_rows: int = 0
    dropped_rows: tuple[str, ...] = ()
    pruned: tuple[str, ...] = ()
    max_std_percent: float | None = None
    std: StdMethod | None = None
    estimator: str = "ols"
    rtol: float | None = None
    rank_gap: tuple[float, float] | None = None
    identifiability: Mapping[str, str] = field(default_factory=dict)
    seed: int | None = None
    data: Mapping[str, Any] = field(default_factory=dict)
    static: StaticInfo | None = None
    log: LogInfo | None = None
    heldout: Mapping[str, Any] | None = None
    column_map: Mapping[str, str | None] | None = None
    notes: tuple[str, ...] = ()
    extra: Mapping[str, Any] = field(default_factory=dict)
    selection: Mapping[str, Any] | None = None
    estimator_choice: Mapping[str, Any] | None = None
    recordings: tuple[Mapping[str, Any], ...] = ()
    combined: Mapping[str, str] = field(default_factory=dict)

    def fitted_on(self, names: Sequence[str]) -> tuple[str, ...]:
        """Those of ``names`` (recordings' file names or paths) that name a recording the
        model was identified from (by file name: the record holds no path); not one left
        out of the fit as outlying (``left_out``)."""
        fitted = {
            Path(str(r.get("file", ""))).name for r in self.recordings if not r.get("left_out")
        }
        return tuple(n for n in names if Path(str(n)).name in fitted)

    def left_out_of(self, names: Sequence[str]) -> tuple[str, ...]:
        """Those of ``names`` that name a recording left out of the fit as outlying
        (``left_out``; by file name)."""
        out = {Path(str(r.get("file", ""))).name for r in self.recordings if r.get("left_out")}
        return tuple(n for n in names if Path(str(n)).name in out)
