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

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import DataError, NonFiniteError, ShapeError
from ..model.robot import Robot
from ..regressors.static import (
    static_first_columns,
    static_labels,
    static_regressor_columns,
    static_rows,
)
from ..regressors.terms import base_term_columns
from .core import ModelColumns, RegressorBlock
from .info import IdentificationInfo, StaticInfo
from .streaming import BLOCK_ROWS, streams

__all__ = ["StaticDataset", "DEFAULT_SYMMETRY_RTOL"]

#: Default tolerance of the symmetry check: ``max |M - M^T| <= rtol * max |M|`` per row.
#: Loose enough for a model library that rounds its output, tight enough to catch a
#: transposed or shifted matrix.
DEFAULT_SYMMETRY_RTOL = 1e-8

#: Largest piece of the static regressor [bytes] computed at once when it is streamed.
_BLOCK_BYTES = 16 << 20


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
        put("metadata", _checks.frozen_mapping(dict(self.metadata)))
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

    # the Dataset protocol of dynid.identification.core
    @property
    def route(self) -> Literal["static"]:
        """``"static"`` (Gaz et al. 2019, Sec. IV-A)."""
        return "static"

    @property
    def regressor_kind(self) -> Literal["static"]:
        """Rows ``[tril M; g]``."""
        return "static"

    @property
    def moving(self) -> bool:
        """False: nothing moves, friction does not act."""
        return False

    @property
    def source(self) -> str:
        """``"static regressor of N configuration(s)"``."""
        return f"static regressor of {self.n_configurations} configuration(s)"

    @property
    def hint(self) -> str:
        """What to do when the configurations do not excite every base parameter."""
        return (
            "add configurations spread over the joint ranges (Gaz et al. 2019 used 1010; "
            "dynid acquire-static --pool selects them)"
        )

    def frozen_columns(self, columns: ModelColumns) -> NDArray[np.bool_]:
        """None: every column acts at rest or is structurally zero (a rank error says so)."""
        return np.zeros(len(columns.labels), dtype=bool)

    #: Configurations are independent: no time structure (``std="hac"`` is HC1).
    serial = None

    def blocks(self, robot: Robot, columns: ModelColumns) -> Iterator[RegressorBlock]:
        """One block of ``N`` rows per row of ``s = [tril M; g]`` (``static_labels``).

        Row ``(i, j)`` of ``tril M`` and row ``g_i`` do not depend on the parameters of the
        links before link ``i``: each block is exactly zero in those leading columns
        (``first``). Known rotor inertias of ``columns.drive`` are subtracted from ``M``.

        When the stacked regressor, or the Gram matrices of its blocks, would exceed
        ``DYNID_MAX_STACK_BYTES`` (:func:`~dynid.identification.streaming.streams`; a
        50-joint arm has 1325 rows per configuration and 345 columns: 1.3 GB of Gram
        matrices), the blocks are pieces of configurations instead, each with
        the rows of ``s`` of its configurations (row ``k`` its noise group, named in
        ``group_labels``), computed when iterated: the core fits them in passes.
        """
        N, n = self.n_configurations, self.n
        s, c = static_rows(n), len(columns.labels)
        if streams(N * s, c) or streams(s * c, c):  # the rows, or a Gram matrix per row of s
            step = max(1, min(BLOCK_ROWS // s, _BLOCK_BYTES // (8 * s * c)))
            labels = static_labels(n)
            for a in range(0, N, step):
                Yb, S = self._rows(robot, columns, slice(a, a + step))
                B = S.shape[0]
                yield RegressorBlock(
                    W=Yb.reshape(Yb.shape[0], s * B).T,  # rows (k, b): row k of s, config b
                    y=S.T.reshape(-1),
                    groups=np.repeat(np.arange(s, dtype=np.intp), B),
                    group_labels=labels,
                )
            return
        Yb, S = self._rows(robot, columns, slice(0, N))
        first = static_first_columns(n, np.asarray(columns.base.independent))
        for k, label in enumerate(static_labels(n)):
            yield RegressorBlock(
                W=Yb[:, k, :].T,
                y=S[:, k],
                groups=np.full(N, k, dtype=np.intp),
                label=label,
                first=int(first[k]),
            )

    def _rows(
        self, robot: Robot, columns: ModelColumns, b: slice
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The regressor ``Yb[c, k, i]`` (column c, row k of ``s``, configuration i) and
        the targets ``S[i, k]`` of the configurations ``b``."""
        n = self.n
        ind = np.asarray(columns.base.independent)
        q = self.q[b]
        B = q.shape[0]
        # only the base columns computed
        Yb = static_regressor_columns(robot, q, ind[ind < 10 * n])
        extra = []
        for t, sel in base_term_columns(columns.terms, ind, n):  # rotor inertia: constant
            C = t.static_columns(B)
            extra.append(np.zeros((sel.size, Yb.shape[1], B)) if C is None else C[sel])
        for t in columns.appended:  # terms that do not act at rest give zero columns
            C = t.static_columns(B)
            extra.append(np.zeros((len(t.labels), Yb.shape[1], B)) if C is None else C)
        if extra:
            Yb = np.concatenate([Yb, *extra], axis=0)
        M = self.M[b]
        drive = columns.drive
        if drive is not None and drive.rotor_inertia is not None:  # known: not identified
            M = M - drive.rotor_mass_matrix(drive.rotor_inertia)
        i, j = np.tril_indices(n)
        S = np.concatenate([M[:, i, j], self.g[b]], axis=1)  # (B, s), columns as static_labels
        return Yb, S

    def record(self, n_rows: int) -> IdentificationInfo:
        """Configurations, rows per configuration and the data set's own metadata."""
        N = self.n_configurations
        seed = self.metadata.get("seed")
        return IdentificationInfo(
            reference="Gaz et al. 2019, Sec. IV-A, eqs. 17-21",
            static=StaticInfo(n_configurations=N, rows_per_configuration=n_rows // N),
            data=dict(self.metadata),
            seed=seed if isinstance(seed, int) else None,
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


#: How a message says what a static data argument must be.
STATIC_EXPECTED = (
    "a StaticDataset (dynid.acquire_static(controller), or StaticDataset(q, M, g); "
    "a file: dynid.io.static_data.load_static_data)"
)
