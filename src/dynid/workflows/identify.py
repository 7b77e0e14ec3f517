"""Identify from a data file: the entry point of ``dynid identify``, with every check the
command applies, so that the Python API behaves as the command does.

* The file's kind (static data or a torque log, :func:`~.data_files.data_kind`) picks the
  route; the data are read strictly and checked against the robot
  (:mod:`dynid.workflows.data_files`: joint count, recorded robot, log cleaning).
* Static data: configurations outside the joint limits and a relative error far above
  the recorded noise level are :class:`~dynid.exceptions.DynidWarning` warnings.
* ``std`` (standard deviations, ``--std``) is honoured on both routes (default: robust
  for static data, classical for torque logs); the consistent fit refuses it and
  ``max_std_percent``, which do not apply to it.
* The column map the data were read with is recorded in the model (``info.column_map``).
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Literal

from ..exceptions import DataError, DynidWarning
from ..feasibility.convex import (
    ConsistentResult,
    SDPOptions,
    consistent_from_identified,
    identify_consistent,
)
from ..identification.consistency import fit_mismatch, limit_violations
from ..identification.estimators import EstimatorName
from ..identification.least_squares import StdMethod
from ..identification.model import IdentifiedModel
from ..identification.selection import identify_recordings
from ..identification.static import identify_static
from ..identification.structure import Structure
from ..model.drive import Drive
from ..model.robot import Robot
from .data_files import (
    ColumnSpec,
    column_map,
    data_kind,
    in_file,
    read_static_file,
    read_torque_log,
)

__all__ = ["ColumnSpec", "data_files", "identify_consistent_file", "identify_file"]


def _columns(spec: ColumnSpec | None, cutoff_hz: float | None) -> Any:
    return None if spec is None else column_map(*spec, cutoff_hz=cutoff_hz)


def _heldout(
    path: Path,
    kind: str,
    folds: int | None,
    validate_on: str | Path | None,
    n: int,
    cmap: Any,
    drop_invalid: bool,
) -> dict[str, Any]:
    """``folds``/``validate_on`` of the torque-log routes (the log read as ``path`` is);
    refused for static data."""
    if folds is None and validate_on is None:
        return {}
    if kind != "torque_log":
        raise DataError(
            f"{path.name}: --folds and --validate-on apply to torque logs, not static data"
        )
    kw: dict[str, Any] = {} if folds is None else {"folds": folds}
    if validate_on is not None:
        kw["validate_on"] = read_torque_log(validate_on, n, columns=cmap, drop_invalid=drop_invalid)
    return kw


def _record(model: IdentifiedModel, spec: ColumnSpec | None) -> IdentifiedModel:
    """The model with the column map its data were read with (``info.column_map``)."""
    if spec is None or spec == (None, None):
        return model
    info = dataclasses.replace(model.info, column_map={"columns": spec[0], "units": spec[1]})
    return dataclasses.replace(model, info=info)


def data_files(paths: str | Path | Sequence[str | Path]) -> list[Path]:
    """The data files of ``--data``: the paths given, a folder standing for its ``.csv``
    and ``.npz`` files in name order.

    Raises
    ------
    DataError
        No path, a folder without data files, or a file named twice.
    """
    given = [paths] if isinstance(paths, str | Path) else list(paths)
    out: list[Path] = []
    for p in map(Path, given):
        if p.is_dir():
            found = sorted(f for f in p.iterdir() if f.suffix.lower() in (".csv", ".npz"))
            if not found:
                raise DataError(f"{p.name}: the folder holds no .csv or .npz data file")
            out += found
        else:
            out.append(p)
    if not out:
        raise DataError("no data file given")
    twice = sorted({p.name for p in out if out.count(p) > 1})
    if twice:
        raise DataError(f"{', '.join(twice)}: data file given twice")
    return out


def _terms(terms: str | Structure | None) -> Structure | Literal["auto"]:
    """``--terms``: ``"auto"``/None (chosen on held-out data) or the terms named."""
    if terms is None or terms == "auto":
        return "auto"
    return terms if isinstance(terms, Structure) else Structure.parse(terms)


def identify_file(
    robot: Robot,
    path: str | Path | Sequence[str | Path],
    *,
    terms: str | Structure | None = None,
    columns: ColumnSpec | None = None,
    drop_invalid: bool = False,
    max_std_percent: float | None = None,
    rtol: float | None = None,
    std: StdMethod | None = None,
    estimator: EstimatorName = "ols",
    drive: Drive | None = None,
    cutoff_hz: float | None = None,
    max_gap_s: float | None = None,
    folds: int | None = None,
    validate_on: str | Path | None = None,
) -> IdentifiedModel:
    """The base parameters (and, from a torque log, friction) of ``robot`` from ``path``.

    Parameters
    ----------
    robot : Robot
        The robot the data belong to.
    path : str, Path or a sequence of them
        Static data (``q, M, g``), or one or more torque logs (a folder: its ``.csv``
        and ``.npz`` files), each ``.csv`` or ``.npz``.
    terms : str or Structure, optional
        Torque logs: the model's terms beside the links (``"armature,viscous"``,
        :class:`~dynid.identification.structure.Structure`); default ``"auto"``: chosen on
        held-out data (:mod:`dynid.identification.selection`).
    columns : (str or None, str or None), optional
        ``--columns`` and ``--units`` of a file of another tool (recorded in the model).
    drop_invalid : bool
        Drop invalid rows (counted, named) instead of failing.
    max_std_percent, rtol, estimator, drive
        As :func:`~dynid.identification.static.identify_static`.
    std : {"robust", "classical"}, optional
        Standard deviations (default robust for static data, classical for a log).
    cutoff_hz : float, optional
        Torque logs: zero-phase low-pass cutoff [Hz] (default: read from the log,
        :mod:`dynid.identification.rate`); also the
        cutoff of velocities derived from positions through ``columns``.
    max_gap_s : float, optional
        Torque logs: longest gap bridged by interpolation [s]; a longer one cuts the log
        into pieces prepared on their own.
    folds : int, optional
        Torque logs: contiguous time blocks of the held-out judgement (``--folds``).
    validate_on : str or Path, optional
        Torque logs: judge on this separate log (read as ``path``) instead of time blocks.

    Returns
    -------
    IdentifiedModel

    Raises
    ------
    DataError
        A bad file, data of another robot or joint count, invalid rows without
        ``drop_invalid``; ``folds`` or ``validate_on`` with static data.
    """
    paths = data_files(path)
    path = paths[0]
    cmap = _columns(columns, cutoff_hz)
    kind = data_kind(path, cmap)
    heldout = _heldout(path, kind, folds, validate_on, robot.n, cmap, drop_invalid)
    if kind == "torque_log":
        logs = [
            read_torque_log(
                p, robot.n, columns=cmap, drop_invalid=drop_invalid, owner=f"robot {robot.name!r}"
            )
            for p in paths
        ]
        fit = lambda: identify_recordings(  # noqa: E731
            robot,
            logs,
            [p.name for p in paths],
            structure=_terms(terms),
            max_std_percent=max_std_percent,
            rtol=rtol,
            max_gap_s=max_gap_s,
            drive=drive,
            estimator=estimator,
            std=std or "classical",
            cutoff_hz="auto" if cutoff_hz is None else cutoff_hz,
            **heldout,
        )
        model = in_file(path, fit) if len(paths) == 1 else fit()
    else:
        _one_static_file(paths, terms)
        data = read_static_file(path, robot, columns=cmap, drop_invalid=drop_invalid)
        outside = limit_violations(robot, data.q)
        if outside is not None:
            warnings.warn(f"{path.name}: {outside}", DynidWarning, stacklevel=2)
        model = in_file(
            path,
            lambda: identify_static(
                robot,
                data,
                max_std_percent=max_std_percent,
                rtol=rtol,
                std=std or "robust",
                drive=drive,
                estimator=estimator,
            ),
        )
        misfit = fit_mismatch(model.fit.relative_error_percent, data.metadata)
        if misfit is not None:
            warnings.warn(f"{path.name}: {misfit}", DynidWarning, stacklevel=2)
    return _record(model, columns)


def _consistent_structure_fit(
    robot: Robot,
    logs: list[Any],
    names: list[str],
    terms: Structure | Literal["auto"],
    **kw: Any,
) -> IdentifiedModel:
    """The unconstrained fit of the one-step consistent route: the armature chosen on
    held-out data (or given), the classical friction (``fv, fc, fo``) with it; the choice
    recorded.

    Raises
    ------
    DataError
        ``terms`` name friction other than the classical parts together.
    """
    classical = ("viscous", "coulomb", "offset")
    if terms != "auto" and terms.friction not in (classical, ()):
        raise DataError(
            "--consistent keeps the classical friction (viscous, coulomb, offset) physical: "
            f"--terms may add armature to it; got {terms.name!r}"
        )
    selection = None
    if terms == "auto":
        selection = identify_recordings(robot, logs, names, **kw).info.selection
        chosen = Structure.parse(str((selection or {}).get("chosen", "")))
        terms = Structure(chosen.armature, classical, at=chosen.at)
    else:
        terms = Structure(terms.armature, classical, at=terms.at)
    model = identify_recordings(robot, logs, names, structure=terms, **kw)
    info = dataclasses.replace(model.info, selection=selection)
    return dataclasses.replace(model, info=info)


def _one_static_file(paths: list[Path], terms: object) -> None:
    """Static data come in one file, and have no terms to choose."""
    if len(paths) > 1:
        raise DataError(
            f"{paths[0].name} holds static data: give one static data file ({len(paths)} given)"
        )
    if terms is not None and terms != "auto":
        raise DataError(f"{paths[0].name}: --terms applies to torque logs, not static data")


def identify_consistent_file(
    robot: Robot,
    path: str | Path | Sequence[str | Path],
    *,
    terms: str | Structure | None = None,
    max_gap_s: float | None = None,
    prior: Robot | None = None,
    total_mass: tuple[float, float] | None = None,
    options: SDPOptions | None = None,
    columns: ColumnSpec | None = None,
    drop_invalid: bool = False,
    rtol: float | None = None,
    estimator: EstimatorName = "ols",
    drive: Drive | None = None,
    cutoff_hz: float | None = None,
    max_std_percent: float | None = None,
    std: str | None = None,
    folds: int | None = None,
    validate_on: str | Path | None = None,
) -> ConsistentResult:
    """Physically consistent link parameters of ``robot`` identified in one step from
    ``path`` (:func:`~dynid.feasibility.convex.fit.identify_consistent`), the data read and
    checked as by :func:`identify_file`.

    ``max_std_percent`` and ``std`` are refused (nothing is pruned; the data term is the
    residual itself, weighted by ``estimator``); they are parameters so that a caller
    passing them learns it. ``folds``/``validate_on`` (torque logs) choose the held-out
    judgement of the prior weight and of the fit. Other parameters as :func:`identify_file` and
    :func:`~dynid.feasibility.convex.fit.identify_consistent`.

    Torque logs (one or more, prepared as :func:`identify_file` prepares them, ``max_gap_s``
    honoured): the armature is chosen on held-out data as :func:`identify_file` chooses it
    (or given by ``terms``), and the friction is the classical ``fv, fc, fo >= 0`` per joint
    (motor), the terms the convex problem keeps physical.

    Returns
    -------
    ConsistentResult
        ``identified`` holds the unconstrained fit (with the column map recorded).

    Raises
    ------
    DataError
        ``max_std_percent`` or ``std`` given; a bad file or data of another robot.
    """
    if max_std_percent is not None:
        raise DataError("--max-std-percent does not apply to --consistent (nothing is pruned)")
    if std is not None:
        raise DataError(
            "--std does not apply to --consistent: its data term is the residual itself "
            "(weighted by --estimator)"
        )
    paths = data_files(path)
    path = paths[0]
    cmap = _columns(columns, cutoff_hz)
    kind = data_kind(path, cmap)
    heldout = _heldout(path, kind, folds, validate_on, robot.n, cmap, drop_invalid)
    common: dict[str, Any] = dict(prior=prior, total_mass=total_mass, options=options)
    if kind == "torque_log":
        logs = [
            read_torque_log(
                p, robot.n, columns=cmap, drop_invalid=drop_invalid, owner=f"robot {robot.name!r}"
            )
            for p in paths
        ]

        def fit() -> ConsistentResult:
            model = _consistent_structure_fit(
                robot,
                logs,
                [p.name for p in paths],
                _terms(terms),
                rtol=rtol,
                drive=drive,
                estimator=estimator,
                cutoff_hz="auto" if cutoff_hz is None else cutoff_hz,
                max_gap_s=max_gap_s,
                **heldout,
            )
            return consistent_from_identified(robot, model, kind="log", **common)

        result = in_file(path, fit) if len(paths) == 1 else fit()
    else:
        _one_static_file(paths, terms)
        if max_gap_s is not None:
            raise DataError(f"{path.name}: --max-gap applies to torque logs, not static data")
        data = read_static_file(path, robot, columns=cmap, drop_invalid=drop_invalid)
        result = in_file(
            path,
            lambda: identify_consistent(
                robot, data, rtol=rtol, drive=drive, estimator=estimator, **common
            ),
        )
    if result.identified is None:  # pragma: no cover - identify_consistent always sets it
        raise DataError("the one-step identification returned no unconstrained fit")
    return dataclasses.replace(result, identified=_record(result.identified, columns))
