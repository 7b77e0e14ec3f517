"""Sample containers for identification: the static data set of Gaz et al. 2019, Sec. IV-A.

A :class:`StaticDataset` holds what a robot controller's model library returns at ``N``
static configurations: the joint positions ``q`` (N, n) [rad, or m for a prismatic joint],
the joint-space inertia matrices ``M`` (N, n, n) [kg m^2; kg m and kg in prismatic rows and
columns] and the gravity torques ``g`` (N, n) [N m, or N] for the gravity vector of the
robot the data belong to. Row ``s`` of every array is configuration ``s`` (0-based).

The container is strict: shapes must agree, every value must be finite and each ``M`` must
be symmetric to within ``symmetry_rtol`` of its largest entry; otherwise the error names
the array and the first bad row. Its arrays are read-only copies. Cleaning (dropping bad
rows of a recorded file) belongs to :mod:`dynid.io.static_data`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import DataError, NonFiniteError, ShapeError
from ..model.robot import Robot

__all__ = ["StaticDataset", "DEFAULT_SYMMETRY_RTOL"]

#: Default tolerance of the symmetry check: ``max |M - M^T| <= rtol * max |M|`` per row.
#: Loose enough for a model library that rounds its output, tight enough to catch a
#: transposed or shifted matrix.
DEFAULT_SYMMETRY_RTOL = 1e-8


@dataclass(frozen=True, slots=True, eq=False)
class StaticDataset:
    """Inertia matrices and gravity torques at static configurations.

    Attributes
    ----------
    q : ndarray, shape (N, n)
        Joint positions [rad] (m for prismatic joints).
    M : ndarray, shape (N, n, n)
        Joint-space inertia matrices [kg m^2], symmetric.
    g : ndarray, shape (N, n)
        Gravity torques [N m] for the robot's gravity vector.
    metadata : mapping
        Where the data come from (source, noise level, seed, dropped rows); read-only,
        JSON-serialisable values.
    symmetry_rtol : float
        Tolerance of the symmetry check, relative to the largest ``|M|`` of each row.

    Raises
    ------
    ShapeError
        ``q`` not (N, n) with N >= 1, or ``M``/``g`` not (N, n, n)/(N, n).
    NonFiniteError
        NaN or inf in ``q``, ``M`` or ``g``; the message names the array, the row and the
        entry.
    DataError
        An ``M`` not symmetric within ``symmetry_rtol``; the message names the row.
    """

    q: NDArray[np.float64]
    M: NDArray[np.float64]
    g: NDArray[np.float64]
    metadata: Mapping[str, Any] = field(default_factory=dict)
    symmetry_rtol: float = DEFAULT_SYMMETRY_RTOL

    def __post_init__(self) -> None:
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731 (frozen init)
        q = _checks.as_array("q", self.q, allow_nonfinite=True)
        if q.ndim != 2 or q.shape[0] < 1 or q.shape[1] < 1:
            raise ShapeError(f"q must have shape (N, n) with N >= 1 configurations; got {q.shape}")
        N, n = q.shape
        M = _checks.as_exact("M", self.M, (N, n, n), allow_nonfinite=True)
        g = _checks.as_exact("g", self.g, (N, n), allow_nonfinite=True)
        for name, a in (("q", q), ("M", M), ("g", g)):
            _finite_rows(name, a)
        scale = np.max(np.abs(M), axis=(1, 2))
        asym = np.max(np.abs(M - np.swapaxes(M, 1, 2)), axis=(1, 2))
        bad = np.flatnonzero(asym > self.symmetry_rtol * scale)
        if bad.size:
            s = int(bad[0])
            raise DataError(
                f"M must be symmetric; row {s} has max |M - M^T| = {asym[s]:.3g} with max |M| = "
                f"{scale[s]:.3g} (tolerance {self.symmetry_rtol:g} relative), {bad.size} row(s) "
                "in all; hint: check the matrix layout (column- vs row-major) of the source"
            )
        put("q", _checks.frozen(q))
        put("M", _checks.frozen(M))
        put("g", _checks.frozen(g))
        put("metadata", MappingProxyType(dict(self.metadata)))
        put("symmetry_rtol", float(self.symmetry_rtol))

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.q.shape[1])

    @property
    def n_configurations(self) -> int:
        """Number of configurations N."""
        return int(self.q.shape[0])

    def __len__(self) -> int:
        return self.n_configurations

    def check_robot(self, robot: Robot) -> None:
        """Raise :class:`DataError` unless the data have ``robot.n`` joints."""
        if self.n != robot.n:
            raise DataError(
                f"static data set has {self.n} joints (q of shape {self.q.shape}); robot "
                f"{robot.name!r} has {robot.n}; hint: pass the robot the data were recorded with"
            )

    def select(self, rows: ArrayLike) -> StaticDataset:
        """A data set of some rows: integer indices or a boolean mask of length N."""
        idx = np.asarray(rows)
        if idx.dtype == bool and idx.shape != (self.n_configurations,):
            raise ShapeError(
                f"a boolean row mask must have shape ({self.n_configurations},); got {idx.shape}"
            )
        return StaticDataset(
            self.q[idx], self.M[idx], self.g[idx], dict(self.metadata), self.symmetry_rtol
        )

    def with_metadata(self, **items: Any) -> StaticDataset:
        """A copy with metadata entries added or replaced."""
        meta = dict(self.metadata)
        meta.update(items)
        return StaticDataset(self.q, self.M, self.g, meta, self.symmetry_rtol)


def _finite_rows(name: str, a: NDArray[np.float64]) -> None:
    """Raise NonFiniteError naming the first row (and entry) of ``a`` that is not finite."""
    ok = np.isfinite(a)
    if ok.all():
        return
    bad = np.argwhere(~ok)[0]
    s = int(bad[0])
    rows = int(np.sum(~ok.reshape(a.shape[0], -1).all(axis=1)))
    entry = tuple(int(i) for i in bad[1:])
    where = f", entry {entry if len(entry) > 1 else entry[0]}" if entry else ""
    raise NonFiniteError(
        f"{name} must be finite; got {a[tuple(bad)]} in row {s}{where} ({rows} row(s) in all); "
        "hint: drop the invalid rows when loading (drop_invalid=True)"
    )
