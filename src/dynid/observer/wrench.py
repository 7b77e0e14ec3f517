"""The external wrench at a frame from the residual, by damped least squares.

The residual estimates the external joint torque ``tau_ext = J(q)^T w`` of a wrench
``w = [f; m]`` (force [N], moment [N m], base axes) at a frame's origin, ``J`` its
geometric Jacobian (:func:`dynid.kinematics.jacobian.jacobian`, rows ``v, w``), ``k`` the
joints that move the frame (at most six) and ``D J = U S V^T`` the first ``k`` singular
triplets of the Jacobian with its linear rows divided by the chain's length ``L``
(``D = diag(E / L, E)``, :func:`chain_length`), so that its singular values are free of
units and ``epsilon`` means the same on a 0.4 m arm as on a 1 m one:

.. math:: \\hat w = D \\sum_{i \\le k} \\frac{\\sigma_i}{\\sigma_i^2 + \\lambda^2} u_i v_i^T r,
          \\qquad
          \\lambda^2 = \\lambda_{max}^2 \\big(1 - (\\sigma_k / \\epsilon)^2\\big)
          \\text{ where } \\sigma_k < \\epsilon \\text{, else } 0

(Nakamura and Hanafusa 1986; Chiaverini 1997): plain least squares away from singular
configurations, damped near them, where ``sigma_k`` falls below ``epsilon``; those samples
are flagged. Away from them, with six joints or more, this is ``(J J^T)^{-1} J r``. A frame
moved by fewer than six joints (a 5-joint arm) never determines a whole wrench: ``k``
joint torques fix only the ``k`` components in the range of ``J`` (which turns with the
pose), and the estimate is the least-norm wrench that explains them (in the norm
``L^2 |f|^2 + |m|^2``), zero
along the wrenches the joints cannot feel (``J^T a = 0``); that is no singularity and is
not flagged (:func:`underdetermined_note`).

A contact on a link is most often a point contact: a force at a known point, no moment.
The estimate of ``kind="force"`` (:data:`WRENCH_KINDS`) takes that as its model: the
moment at the frame's origin is zero and the force alone, three unknowns, is solved the
same way on the linear rows ``J_v`` of the Jacobian (``D = E / L``, ``k`` at most 3),
so that three to five joints determine it whole where their axes allow.

``k`` is the Jacobian's structural rank (:func:`wrench_rank`): its rank at generic poses,
at most the joints moving the frame and the rows solved on. A frame on a joint's axis
(a Panda's ``link4``, whose origin lies on joint 4's axis) leaves that joint out of its
linear rows, so that the force there has a direction no joint feels at any pose: that is
structural, not a singular configuration, and is not flagged either.

What the estimate leaves of the residual, ``r - J^T w``, is kept per sample
(:attr:`WrenchEstimate.unexplained`): a contact on a link before the frame gives torques
no wrench at the frame explains (those of the joints between the contact and the frame
vanish, which no wrench at the frame reproduces), and a large unexplained share over an
event says so. A moment about
the origin (a force elsewhere on the link, a twist) is outside that model: the force
that best explains its torques is written, off the true one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import OptionError
from ..kinematics.forward import fk, link_poses
from ..kinematics.jacobian import jacobian
from ..model.robot import Robot

__all__ = [
    "FORCE",
    "FULL",
    "WRENCH_KINDS",
    "WrenchEstimate",
    "WrenchKind",
    "chain_length",
    "estimate_words",
    "external_wrench",
    "structural_rank",
    "underdetermined_note",
    "wrench_kind",
    "wrench_rank",
]


@dataclass(frozen=True, slots=True)
class WrenchKind:
    """What an estimate solves for at a frame's origin (module docstring).

    Attributes
    ----------
    name : str
        ``full`` or ``force`` (``dynid observe --wrench``).
    rows : int
        The Jacobian rows solved on, first to last: 6 (``v, w``: force and moment) or 3
        (``v``: the force, the moment zero).
    what : str
        What is estimated, in words (summaries, file headers).
    noun : str
        Its name in a sentence (``wrench``, ``force``).
    caveat : str
        What the estimate cannot tell, in words ("" when nothing).
    """

    name: str
    rows: int
    what: str
    noun: str
    caveat: str = ""


#: The whole wrench: force and moment at the frame's origin, 6 unknowns.
FULL = WrenchKind("full", 6, "the wrench (force and moment)", "wrench")
#: A point contact at the frame's origin: the force alone, the moment zero, 3 unknowns.
FORCE = WrenchKind(
    "force",
    3,
    "the force of a point contact (moment zero)",
    "force",
    "a moment there (a force elsewhere on the link) reads as a wrong force",
)
#: The estimates by name.
WRENCH_KINDS = {k.name: k for k in (FULL, FORCE)}


def wrench_kind(kind: str | WrenchKind) -> WrenchKind:
    """The :class:`WrenchKind` of a name in :data:`WRENCH_KINDS` (or the kind itself).

    Raises
    ------
    OptionError
        An unknown name.
    """
    if isinstance(kind, WrenchKind):
        return kind
    if kind not in WRENCH_KINDS:
        raise OptionError(f"must be one of {', '.join(WRENCH_KINDS)}; got {kind!r}", field="wrench")
    return WRENCH_KINDS[kind]


@dataclass(frozen=True, slots=True, eq=False)
class WrenchEstimate:
    """External wrenches at a frame.

    Attributes
    ----------
    frame : str
    wrench : ndarray, shape (..., 6)
        ``fx, fy, fz`` [N], ``mx, my, mz`` [N m], base axes, at the frame's origin (the
        moment 0 when ``kind`` is :data:`FORCE`).
    sigma_min : ndarray, shape (...)
        Smallest of the ``determined`` singular values of the frame's Jacobian (its
        ``kind.rows`` first rows), its linear rows divided by the chain's length
        (unitless; module docstring).
    damped : ndarray of bool, shape (...)
        Near a singular configuration (``sigma_min < epsilon``): the estimate is damped.
    determined : int
        Components the joint torques determine: the joints moving the frame, at most
        ``kind.rows`` (6 or 3); with fewer the estimate is the least-norm one (module
        docstring).
    kind : WrenchKind
        What was estimated: :data:`FULL` (the wrench) or :data:`FORCE` (the force of a
        point contact at the frame's origin).
    unexplained : ndarray, shape (...), or None
        ``|r - J^T w|^2`` [N^2 m^2]: what the estimate leaves of the residual at each
        sample (NaN where ``r`` is); None: not computed.
    """

    frame: str
    wrench: NDArray[np.float64]
    sigma_min: NDArray[np.float64]
    damped: NDArray[np.bool_]
    determined: int = 6
    kind: WrenchKind = FULL
    unexplained: NDArray[np.float64] | None = None


def external_wrench(
    robot: Robot,
    q: ArrayLike,
    r: ArrayLike,
    frame: str = "flange",
    *,
    epsilon: float = 0.05,
    damping: float = 0.05,
    kind: str | WrenchKind = FULL,
) -> WrenchEstimate:
    """The wrench at ``frame`` whose joint torques best explain the residual ``r`` (or,
    ``kind="force"``, the force at its origin whose torques ``J_v^T f`` do).

    Parameters
    ----------
    robot : Robot
    q : array_like, shape (..., n)
        Joint positions [rad].
    r : array_like, shape (..., n)
        Residual (external joint torques) [N m].
    frame : str
        A frame of the robot (``flange``, a link).
    epsilon : float
        Smallest singular value below which the solution is damped (> 0, unitless: a
        lever of ``epsilon`` times the chain's length).
    damping : float
        Largest damping ``lambda_max`` (> 0, unitless).
    kind : str or WrenchKind
        ``full`` (:data:`FULL`: force and moment, 6 unknowns) or ``force`` (:data:`FORCE`:
        a point contact at the frame's origin, moment zero, 3 unknowns).

    Returns
    -------
    WrenchEstimate

    Raises
    ------
    ShapeError, NonFiniteError, UnknownNameError
        Bad shapes, NaN, an unknown frame.
    OptionError
        ``epsilon`` or ``damping`` not positive, an unknown ``kind``.
    """
    if not (np.isfinite(epsilon) and epsilon > 0 and np.isfinite(damping) and damping > 0):
        raise OptionError(f"epsilon and damping must be > 0; got {epsilon}, {damping}")
    kd = wrench_kind(kind)
    qa = _checks.as_batch("q", q, (robot.n,))
    ra = _checks.as_exact("r", r, qa.shape)
    k = wrench_rank(robot, frame, kd)
    D = np.repeat([1.0 / chain_length(robot, frame), 1.0], 3)[: kd.rows]
    J = D[:, None] * jacobian(robot, qa, frame)[..., : kd.rows, :]
    U, s, Vt = np.linalg.svd(J, full_matrices=False)  # s descending, (..., min(rows, n))
    U, s, Vt = U[..., :k], s[..., :k], Vt[..., :k, :]
    smin = s[..., -1]
    damped = smin < epsilon
    lam2 = np.where(damped, damping**2 * (1.0 - smin**2 / epsilon**2), 0.0)
    gain = s / (s**2 + lam2[..., None])
    coef = gain * (Vt @ ra[..., None])[..., 0]
    w = np.zeros((*qa.shape[:-1], 6))
    w[..., : kd.rows] = D * (U @ coef[..., None])[..., 0]
    fit = (np.swapaxes(Vt, -1, -2) @ (s * coef)[..., None])[..., 0]  # J^T w, (D J)^T D^-1 w
    left = np.sum((ra - fit) ** 2, axis=-1)
    return WrenchEstimate(frame, w, smin, damped, k, kd, left)


def chain_length(robot: Robot, frame: str) -> float:
    """The length [m] of the chain that moves ``frame``: the distances from each joint's
    origin to the next one's and from the last to the frame, summed (at ``q = 0``; fixed
    for revolute joints); 1 m for a frame on the joints' origins.

    Raises
    ------
    UnknownNameError
        An unknown frame.
    """
    k = robot.frame(frame).link
    T = link_poses(robot, np.zeros(robot.n))
    p = np.vstack([T[1 : k + 1, :3, 3], fk(robot, np.zeros(robot.n), frame)[None, :3, 3]])
    length = float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1)))
    return length if length > 0.0 else 1.0


#: Poses at which :func:`structural_rank` reads the Jacobian's rank (random, fixed seed).
RANK_POSES = 4
#: A singular value below this share of the largest is zero in :func:`structural_rank`.
RANK_TOL = 1e-8


def structural_rank(robot: Robot, frame: str, kind: str | WrenchKind = FULL) -> int:
    """The rank of the Jacobian at ``frame`` (its ``kind.rows`` first rows, the linear
    rows scaled by :func:`chain_length`) at generic poses: the largest over
    :data:`RANK_POSES` random ones (a fixed seed; the rank is the same at almost every
    pose, lower only at singular ones). Below the joints moving the frame when a joint's
    axis passes through its origin (the force there) or axes line up by construction.

    Raises
    ------
    UnknownNameError
        An unknown frame.
    OptionError
        An unknown ``kind``.
    """
    kd = wrench_kind(kind)
    if int(robot.frame(frame).link) == 0:
        return 0
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (RANK_POSES, robot.n))
    D = np.repeat([1.0 / chain_length(robot, frame), 1.0], 3)[: kd.rows]
    s = np.linalg.svd(D[:, None] * jacobian(robot, q, frame)[..., : kd.rows, :], compute_uv=False)
    return int(np.max(np.sum(s > RANK_TOL * np.maximum(s[..., :1], 1e-300), axis=-1)))


def wrench_rank(robot: Robot, frame: str, kind: str | WrenchKind = FULL) -> int:
    """The components at ``frame`` that joint torques determine: the structural rank of
    its Jacobian (:func:`structural_rank`), at most the joints that move it (those up to
    its link), 6 for the wrench and 3 for the force alone (``kind``).

    Raises
    ------
    UnknownNameError
        An unknown frame.
    OptionError
        A frame on the base (no joint moves it) or, for the force, with its origin on the
        axes of every joint moving it (structural rank 0), an unknown ``kind``.
    """
    kd = wrench_kind(kind)
    k = min(kd.rows, int(robot.frame(frame).link))
    if k == 0:
        raise OptionError(f"frame {frame!r} is fixed to the base: no joint torque tells its wrench")
    k = min(k, structural_rank(robot, frame, kd))
    if k == 0:
        raise OptionError(
            f"frame {frame!r}'s origin lies on the axes of the joints moving it: no joint "
            f"torque tells a {kd.noun} there; estimate the wrench (--wrench full) or at a "
            "frame further out"
        )
    return k


def underdetermined_note(robot: Robot, frame: str, kind: str | WrenchKind = FULL) -> str | None:
    """One line when the joint torques cannot determine the whole estimate at ``frame``
    (fewer than six joints move it for the wrench, fewer than three for the force alone:
    ``kind``), saying what the estimate is; None otherwise.

    Raises
    ------
    UnknownNameError
        An unknown frame.
    OptionError
        An unknown ``kind``.
    """
    kd = wrench_kind(kind)
    k = wrench_rank(robot, frame, kd)
    if k >= kd.rows:
        return None
    what = kd.noun
    hint = ""
    if kd.rows > FORCE.rows and wrench_rank(robot, frame, FORCE) >= FORCE.rows:
        hint = (
            f"; the force of a point contact at {frame}'s origin (3 components, moment zero) "
            "is determined: --wrench force"
        )
    joints = int(robot.frame(frame).link)
    who = f"{k} joint torques determine"
    if joints > k:  # more joints than components: their axes leave a direction out
        who = (
            f"the {joints} joints moving {frame} determine (structurally, at every pose: "
            f"its Jacobian has rank {k}, a joint's axis through its origin or axes lined up)"
        )
    return (
        f"{who} only {k} of the {kd.rows} {what} components at {frame} "
        f"(those in the range of its Jacobian, turning with the pose): the {what} written is "
        f"the least-norm one that explains the residual, blind to any {what} the joints do "
        f"not feel (J^T a = 0), so a force's components can differ from the true ones; "
        f"'damped' flags only poses where the joints lose one more direction" + hint
    )


def estimate_words(robot: Robot, frame: str, kind: str | WrenchKind = FULL) -> str:
    """What is estimated at ``frame``, in words for a summary: the wrench or the force of
    a point contact (``kind``), with the components the joints moving it determine
    (``"the force of a point contact (moment zero) at tool0's origin: 3 components from
    5 joints"``).

    Raises
    ------
    UnknownNameError
        An unknown frame.
    OptionError
        An unknown ``kind``.
    """
    kd = wrench_kind(kind)
    k, joints = wrench_rank(robot, frame, kd), int(robot.frame(frame).link)
    part = "" if k >= kd.rows else f" ({k} determined, the least-norm estimate)"
    out = (
        f"{kd.what} at {frame}'s origin, base axes: {kd.rows} components{part} from "
        f"{joints} joint{'s' if joints > 1 else ''}"
    )
    return out + (f"; {kd.caveat}" if kd.caveat else "")
