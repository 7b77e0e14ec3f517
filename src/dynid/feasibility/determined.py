"""What the data of an identified model determine among the parameters a retrieval returns.

The coefficients of a model whose base holds rotor inertias (a drive whose rotor inertias
are identified, the armature term) are of two kinds: combinations of the links'
parameters and rotor inertias. With ``P`` the base projection over the kept coefficients
(``beta = P [phi; I_a]``), the links' share is the rank of ``P``'s link columns and the
rotor inertias' share what the rotor columns add: ``rank(P) - rank(P_links)``.

A standard parameter (a link's mass, a rotor inertia ``I_a``) is

* ``"data"`` when the unit vector ``e_j`` lies in the row space of ``P``: its value is a
  linear function of the coefficients, whatever the prior;
* ``"prior"`` when column ``j`` of ``P`` is zero: the data do not excite it at all;
* ``"sum"`` otherwise: the data give it only in sums with other parameters (the Panda's
  rotor of joint 1 in ``J1zz + Ia1``), and the retrieval's prior (its pull on the links)
  and the constraints decide its share.

Ranks and row spaces come from pivoted QR with ``P``'s columns scaled to unit norm
(scaling a parameter changes neither), the tolerance returned.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from ..identification.model import IdentifiedModel
from .prior_share import PRIOR_SHARE

__all__ = ["DATA", "PRIOR", "SUM", "Determined", "determined_by_data", "PRIOR_MARK"]

#: The value is a linear function of the coefficients.
DATA = "data"
#: The data give the parameter only in sums with others: the prior decides its share.
SUM = "sum"
#: The data do not excite the parameter: the prior (and the constraints) give it.
PRIOR = "prior"
#: Relative tolerance of the rank and row-space decisions (on unit columns).
RANK_TOL = 1e-9
#: The sign beside a value the prior sets, and what it means (under the tables).
PRIOR_MARK = "~"


@dataclass(frozen=True, slots=True)
class Determined:
    """Which retrieved parameters the coefficients of an identified model determine.

    Attributes
    ----------
    n_link : int
        Link base parameters: the rank of the link columns of the kept coefficients'
        projection.
    n_rotor : int
        Rotor inertias (armatures) the coefficients give beside the links:
        ``rank(P) - n_link``.
    labels : tuple of str
        The standard parameters, links then rotor inertias (``m1 .. Izz7, Ia1 ..``).
    source : tuple of str
        Per label: ``"data"``, ``"sum"`` or ``"prior"`` (module docstring).
    rotor_motor : tuple of int
        The motor (from 0) of each rotor-inertia label, in order.
    n : int
        Joints (motors).
    tol : float
        Relative tolerance of the rank and row-space decisions.
    prior_share : tuple of float or None
        Per label: the prior's share in the consistent fit's value, 0 (the data's) to 1
        (the prior's; :mod:`dynid.feasibility.prior_share`); None when not computed.
    """

    n_link: int
    n_rotor: int
    labels: tuple[str, ...]
    source: tuple[str, ...]
    rotor_motor: tuple[int, ...]
    n: int
    tol: float
    prior_share: tuple[float, ...] | None = None

    def with_share(self, share: NDArray[np.float64] | None) -> Determined:
        """The same with the prior's share of each label (None leaves it out)."""
        if share is None:
            return self
        return replace(self, prior_share=tuple(float(x) for x in share))

    @property
    def by_prior(self) -> tuple[bool, ...]:
        """Per label: the prior sets the value: the data give the parameter only in
        combinations (``"sum"``) or not at all (``"prior"``), or its prior share is above
        :data:`~dynid.feasibility.prior_share.PRIOR_SHARE` (poorly excited)."""
        share = self.prior_share or (0.0,) * len(self.labels)
        return tuple(s != DATA or x > PRIOR_SHARE for s, x in zip(self.source, share, strict=True))

    def link_marks(self) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
        """Which links' mass (n,) and CoM components (n, 3) the prior sets: the mass as
        :attr:`by_prior`; a CoM ``c = (m c) / m`` when its first moment or the mass is."""
        b = np.array(self.by_prior[: 10 * self.n], dtype=bool).reshape(self.n, 10)
        return b[:, 0], b[:, 1:4] | b[:, :1]

    @property
    def mass_source(self) -> tuple[str, ...]:
        """Per link (n,): the source of its mass (``"data"``, ``"sum"``, ``"prior"``)."""
        return tuple(self.source[10 * i] for i in range(self.n))

    @property
    def rotor_source(self) -> tuple[str, ...] | None:
        """Per motor (n,): the source of its rotor inertia, ``""`` for a rotor the model
        does not hold; None without rotor inertias in the base."""
        if not self.rotor_motor:
            return None
        out = [""] * self.n
        for m, s in zip(self.rotor_motor, self.source[10 * self.n :], strict=True):
            out[m] = s
        return tuple(out)

    @property
    def rotor_from_prior(self) -> NDArray[np.bool_] | None:
        """(n,): the rotor inertias the data do not give alone (``"sum"`` or ``"prior"``);
        None without rotor inertias in the base."""
        src = self.rotor_source
        return None if src is None else np.array([s in (SUM, PRIOR) for s in src])

    def counts(self) -> str:
        """``"43 link base parameters + 5 rotor inertias (armatures)"``."""
        links = f"{self.n_link} link base parameters"
        if not self.rotor_motor:
            return links
        return f"{links} + {self.n_rotor} rotor inertias (armatures)"

    def as_dict(self) -> dict[str, object]:
        """JSON-ready: the counts, each label's source, the motors' sources, each label's
        prior share (None when not computed) and the labels the prior sets."""
        return {
            "link_base_parameters": self.n_link,
            "rotor_inertias": self.n_rotor,
            "source": dict(zip(self.labels, self.source, strict=True)),
            "rotor_source": None if self.rotor_source is None else list(self.rotor_source),
            "tolerance": self.tol,
            "prior_share": None
            if self.prior_share is None
            else dict(zip(self.labels, self.prior_share, strict=True)),
            "set_by_prior": [lab for lab, b in zip(self.labels, self.by_prior, strict=True) if b],
        }


def _row_space(P: NDArray[np.float64], tol: float) -> tuple[int, NDArray[np.float64]]:
    """The rank of ``P`` (r, p) and, per column ``j``, the squared norm of ``e_j``'s
    projection on its row space (p,), by pivoted QR of ``P^T`` (``P``'s columns, then its
    rows, scaled to unit norm: a rotor's gear ratio squared does not hide its sum)."""
    import scipy.linalg  # scipy on first use (start-up time)

    if P.size == 0:
        return 0, np.zeros(P.shape[1])
    cols = P / np.maximum(np.linalg.norm(P, axis=0), 1e-300)  # e_j's membership unchanged
    rows = cols / np.maximum(np.linalg.norm(cols, axis=1, keepdims=True), 1e-300)
    Q, R, _ = scipy.linalg.qr(rows.T, mode="economic", pivoting=True)
    d = np.abs(np.diag(R))
    rank = int(np.sum(d > tol * max(float(d[0]) if d.size else 0.0, 1e-300)))
    Q = Q[:, :rank]
    return rank, np.einsum("jk,jk->j", Q, Q)


def _rank(P: NDArray[np.float64], tol: float) -> int:
    """The rank of ``P`` with unit columns (pivoted QR)."""
    import scipy.linalg  # scipy on first use (start-up time)

    cols = np.linalg.norm(P, axis=0)
    keep = cols > 0
    if not keep.any():
        return 0
    A = P[:, keep] / cols[keep]
    R = scipy.linalg.qr(A, mode="r", pivoting=True)[0]
    d = np.abs(np.diag(R))
    return int(np.sum(d > tol * float(d[0])))


def _rotor_motors(model: IdentifiedModel, k: int) -> tuple[int, ...]:
    """The motor of each of the ``k`` rotor-inertia columns of the base, in the order of
    the model's terms in the base (each maps its own: a masked armature holds fewer)."""
    out: list[int] = []
    for t in model.terms.values():
        if not t.term.in_base:
            continue
        for c in range(len(t.term.labels)):
            unit = np.zeros(len(t.term.labels))
            unit[c] = 1.0
            got = t.term.inertia(unit)
            if got is not None:
                out.append(int(np.argmax(np.abs(got))))
    return tuple(out) if len(out) == k else tuple(range(k))


def determined_by_data(model: IdentifiedModel, *, tol: float = RANK_TOL) -> Determined:
    """Which standard parameters the kept coefficients of ``model`` determine (module
    docstring).

    Parameters
    ----------
    model : IdentifiedModel
        An identified model; its pruned coefficients are left out, as a retrieval leaves
        them out.
    tol : float
        Relative tolerance of the rank decisions (> 0).

    Returns
    -------
    Determined
    """
    base = model.base
    n = model.robot.n
    kept = np.asarray(model.fit.kept, dtype=bool)[: base.rank]
    P = np.asarray(base.projection, dtype=np.float64)[kept]
    rank, inside = _row_space(P, tol)
    n_link = _rank(P[:, : 10 * n], tol)
    col = np.linalg.norm(P, axis=0)
    source = tuple(
        PRIOR
        if col[j] <= tol * max(float(col.max(initial=0.0)), 1.0)
        else DATA
        if inside[j] >= 1.0 - 1e3 * tol
        else SUM
        for j in range(base.n_std)
    )
    k = base.n_std - 10 * n
    return Determined(
        n_link=n_link,
        n_rotor=rank - n_link,
        labels=tuple(base.std_labels),
        source=source,
        rotor_motor=_rotor_motors(model, k) if k > 0 else (),
        n=n,
        tol=tol,
    )
