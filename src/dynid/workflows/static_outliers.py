"""Static data's outlying configurations, as ``identify`` and ``retrieve --static`` meet
them: named in one warning with their lines of the file, and left out of the fit, as an
outlying torque log is (``--keep-outlying`` fits them); the finding recorded in the data's
metadata (``outlying_configurations``), which ``identification.json`` carries.

What makes a configuration outlying: :mod:`dynid.identification.static_outliers`.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from .._checks import caller_level
from ..exceptions import DynidWarning
from ..identification.data import StaticDataset
from ..identification.static_outliers import outlying_configurations
from ..io.static_data import data_row_lines
from ..model.drive import Drive
from ..model.robot import Robot

__all__ = ["OUTLYING_KEY", "without_outlying"]

#: The data's metadata entry that records the finding.
OUTLYING_KEY = "outlying_configurations"


def without_outlying(
    robot: Robot,
    path: Path,
    data: StaticDataset,
    *,
    keep: bool = False,
    drive: Drive | None = None,
    keep_flag: str = "--keep-outlying",
) -> StaticDataset:
    """``data`` without its outlying configurations (all of it with ``keep``), which one
    warning names with their lines of ``path`` (rows of an NPZ file) and how far each
    stands off; ``data`` itself when none is found.

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity the data were recorded with.
    path : Path
        The file the data were read from (its lines named).
    data : StaticDataset
    keep : bool
        Fit them too (warned all the same).
    drive : Drive, optional
        The drive whose rotor inertias the controller's ``M`` holds.
    keep_flag : str
        The option that keeps them, as the command names it ("" for none).

    Returns
    -------
    StaticDataset
        The configurations fitted, with ``outlying_configurations`` in the metadata:
        ``rows`` (from 0), ``lines`` (of the file, or null), ``ratios`` and ``left_out``.

    Warns
    -----
    DynidWarning
        The configurations found, once.
    """
    found = outlying_configurations(robot, data, drive=drive)
    if found is None:
        return data
    lines = data_row_lines(path, data.n_configurations)
    where = [
        (f"line {lines[r]} (row {r}" if lines is not None else f"row {r} (")
        + f": {x:.3g} times the median)"
        for r, x in zip(found.rows, found.ratios, strict=True)
    ]
    k, N = len(found.rows), data.n_configurations
    what = "it" if k == 1 else "them"
    done = (
        f"fitted all the same ({keep_flag})"
        if keep
        else f"left out of the fit{f' ({keep_flag} fits {what})' if keep_flag else ''}"
    )
    warnings.warn(
        f"{path.name}: {k} configuration(s) of {N} stand off the others: {', '.join(where)}, "
        "their residual predicted by the fit of the others against the median of all; a "
        "controller's M and g are its model's output, exact to its rounding, so such a row "
        f"holds a wrong q (out of step with its M and g, or logged before the arm settled); "
        f"{done}; hint: check {'that line' if k == 1 else 'those lines'} of the file "
        "(delete or correct it) and identify again",
        DynidWarning,
        stacklevel=caller_level(),
    )
    record = {
        "rows": list(found.rows),
        "lines": None if lines is None else [lines[r] for r in found.rows],
        "ratios": list(found.ratios),
        "left_out": not keep,
    }
    kept = data if keep else data.select(~np.isin(np.arange(N), found.rows))
    return kept.with_metadata(**{OUTLYING_KEY: record})
