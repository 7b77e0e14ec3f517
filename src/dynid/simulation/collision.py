"""Capsule model of a serial arm, obstacles (planes, boxes) and distances for collision checks.

Geometry. Capsule ``k`` (``k = 0 .. n``) is the segment from the origin of link frame ``k``
to the origin of link frame ``k + 1`` (for ``k = n``, the ``flange``), swept by a sphere
of radius ``r_k``; it belongs to link ``k`` (0 = the base), and both ends are fixed in
that link, so its length is a constant of the kinematics. A modified-DH link with both an
``a`` and a ``d`` offset is an L; the straight segment cuts the corner, which the radius
covers for radii above about a third of the shorter leg.

Sizes. The default radius and clearances scale with the arm (:func:`collision_sizes`):
an arm whose chain (the capsules' lengths summed, base to flange, and the strokes of its
prismatic joints) is at least :data:`FULL_SIZE_CHAIN` = 1.3 m long gets
:data:`DEFAULT_RADIUS` = 0.06 m, :data:`DEFAULT_SELF_CLEARANCE` = 0.02 m and
:data:`DEFAULT_OBSTACLE_CLEARANCE` = 0.05 m (the Panda, 1.32 m: its links are 0.11-0.13 m
across in Franka's collision meshes, so the capsules enclose the arm's cross-section); a
shorter arm gets them scaled by its chain over 1.3 m (an SO-101 of 0.55 m: 0.025 m,
0.0085 m, 0.021 m). Pass ``radii`` for a tool or a gripper.

Self-collision. Two capsules are checked when the links strictly between them are longer
in total than the sum of their radii and the clearance ("non-adjacent"): nearer, no
motion can part them by the clearance (their distance is at most those links' length),
so they touch by construction, as the Panda's links 1 and 5 do, whose frame origins
coincide with the next one.

Obstacles, in the base frame [m]: a :class:`Plane` (``point`` and a ``normal`` pointing
to the free side; a floor or a table top) and axis-aligned :class:`Box` es (``center``,
``size``). Capsules 0 and 1 (the base and the first link, which only turns about the
mounting axis) are not checked against obstacles: they stand on the support. The
distance from a capsule to a box is evaluated at :data:`BOX_SAMPLES` points along the
segment (exact for planes); its error is at most a half sample spacing times the sine of
the angle to the nearest face, covered by the margins.

Distances are signed: positive when apart, negative when penetrating [m].
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, _kernels
from ..exceptions import OptionError, ShapeError
from ..kinematics.forward import link_poses
from ..model.robot import Robot

__all__ = [
    "BOX_SAMPLES",
    "DEFAULT_OBSTACLE_CLEARANCE",
    "DEFAULT_RADIUS",
    "DEFAULT_SELF_CLEARANCE",
    "FULL_SIZE_CHAIN",
    "MAX_OBSTACLE_EXTENT",
    "Box",
    "CapsuleModel",
    "CollisionSizes",
    "Obstacles",
    "Plane",
    "capsule_model",
    "capsule_segments",
    "chain_length",
    "collision_sizes",
    "obstacle_capsule_distances",
    "obstacle_distances",
    "self_distances",
]

#: Capsule radius [m] of an arm of chain :data:`FULL_SIZE_CHAIN` or longer (module docstring).
DEFAULT_RADIUS = 0.06
#: Smallest distance between non-adjacent capsules [m] of such an arm.
DEFAULT_SELF_CLEARANCE = 0.02
#: Smallest distance of a capsule to an obstacle [m] of such an arm.
DEFAULT_OBSTACLE_CLEARANCE = 0.05
#: Chain length [m] from which the defaults hold unscaled (the Panda's is 1.32 m).
FULL_SIZE_CHAIN = 1.3
#: Points along a capsule's segment at which its distance to a box is evaluated.
BOX_SAMPLES = 9
#: The largest coordinate of a plane's point or a box's centre, and the largest box edge
#: [m]: farther than any workspace, and small enough that squared distances stay finite.
MAX_OBSTACLE_EXTENT = 1e6


def _within_extent(what: str, x: NDArray[np.float64]) -> None:
    big = float(np.max(np.abs(x)))
    if not big <= MAX_OBSTACLE_EXTENT:
        raise OptionError(
            f"{what} must be at most {MAX_OBSTACLE_EXTENT:g} m in absolute value; got "
            f"{[float(v) for v in x]}; lengths are in metres"
        )


@dataclass(frozen=True, slots=True)
class Plane:
    """A half-space boundary: ``normal . (p - point) >= 0`` is free [m].

    Raises
    ------
    OptionError
        A zero normal, or a point coordinate beyond :data:`MAX_OBSTACLE_EXTENT`.
    """

    point: tuple[float, float, float]
    normal: tuple[float, float, float]

    def __post_init__(self) -> None:
        p = _checks.as_exact("point", self.point, (3,))
        _within_extent("plane point", p)
        nrm = _checks.as_exact("normal", self.normal, (3,))
        big = float(np.max(np.abs(nrm)))
        if not big > 0:
            raise OptionError("plane normal must be non-zero")
        u = nrm / big  # scaled first: the norm of [0, 0, 1e300] overflows, of 1e-300 not
        object.__setattr__(self, "point", tuple(float(x) for x in p))
        object.__setattr__(self, "normal", tuple(float(x) for x in u / np.linalg.norm(u)))


@dataclass(frozen=True, slots=True)
class Box:
    """An axis-aligned box in the base frame: ``center`` and edge lengths ``size`` [m].

    Raises
    ------
    OptionError
        An edge not positive, or a centre coordinate or an edge beyond
        :data:`MAX_OBSTACLE_EXTENT`.
    """

    center: tuple[float, float, float]
    size: tuple[float, float, float]

    def __post_init__(self) -> None:
        c = _checks.as_exact("center", self.center, (3,))
        s = _checks.as_exact("size", self.size, (3,))
        _within_extent("box center", c)
        if np.any(s <= 0):
            raise OptionError(f"box size must be positive; got {[float(v) for v in s]}")
        _within_extent("box size", s)
        object.__setattr__(self, "center", tuple(float(x) for x in c))
        object.__setattr__(self, "size", tuple(float(x) for x in s))


@dataclass(frozen=True, slots=True)
class Obstacles:
    """Planes and boxes around the robot, with names for reports."""

    planes: tuple[Plane, ...] = ()
    boxes: tuple[Box, ...] = ()
    names: tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        k = len(self.planes) + len(self.boxes)
        if not self.names:
            names = [f"plane{i + 1}" for i in range(len(self.planes))]
            names += [f"box{i + 1}" for i in range(len(self.boxes))]
            object.__setattr__(self, "names", tuple(names))
        elif len(self.names) != k:
            raise ShapeError(f"obstacles need {k} names (planes, then boxes); got {self.names}")

    def __len__(self) -> int:
        return len(self.planes) + len(self.boxes)

    @classmethod
    def floor(cls, height: float = 0.0) -> Obstacles:
        """The plane ``z = height`` of the base frame, free above (the mounting surface)."""
        return cls(planes=(Plane((0.0, 0.0, height), (0.0, 0.0, 1.0)),), names=("floor",))


@dataclass(frozen=True, slots=True, eq=False)
class CapsuleModel:
    """Capsules of a robot: radii, lengths and the self-collision pairs.

    Attributes
    ----------
    radii : ndarray, shape (n + 1,)
        Radius of capsule ``k`` (link ``k``; 0 = base) [m].
    lengths : ndarray, shape (n + 1,)
        Segment lengths [m].
    pairs : ndarray of int, shape (k, 2)
        Capsule pairs checked for self-collision (``i < j``).
    """

    radii: NDArray[np.float64]
    lengths: NDArray[np.float64]
    pairs: NDArray[np.intp]


def capsule_segments(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """Capsule segment end points in the base frame: (..., n) -> (..., n + 1, 2, 3) [m]."""
    T = link_poses(robot, q)  # (..., n + 1, 4, 4)
    fl = robot.frames["flange"]
    T_f = T[..., fl.link, :, :] @ fl.T_link_frame
    starts = T[..., :, :3, 3]
    ends = np.concatenate([T[..., 1:, :3, 3], T_f[..., None, :3, 3]], axis=-2)
    return np.stack([starts, ends], axis=-2)


def chain_length(robot: Robot) -> float:
    """Length of the arm's chain [m]: its capsules' lengths at ``q = 0`` summed, base to
    flange, plus the stroke of each prismatic joint with finite limits (the Panda's:
    1.319 m)."""
    seg = capsule_segments(robot, np.zeros(robot.n))
    stroke = np.where(robot.prismatic, robot.q_max - robot.q_min, 0.0)
    return float(
        np.linalg.norm(seg[:, 1] - seg[:, 0], axis=-1).sum() + stroke[np.isfinite(stroke)].sum()
    )


@dataclass(frozen=True, slots=True)
class CollisionSizes:
    """The default capsule radius and clearances of an arm, scaled to its size.

    Attributes
    ----------
    radius : float
        Capsule radius [m]: :data:`DEFAULT_RADIUS` times ``scale``.
    self_clearance : float
        Between non-adjacent capsules [m]: :data:`DEFAULT_SELF_CLEARANCE` times ``scale``.
    obstacle_clearance : float
        To obstacles [m]: :data:`DEFAULT_OBSTACLE_CLEARANCE` times ``scale``.
    chain_length : float
        The arm's chain [m] (:func:`chain_length`).
    scale : float
        ``min(1, chain_length / FULL_SIZE_CHAIN)``; 1 for a chain of no length (one joint
        at the base's origin: nothing to scale by).
    """

    radius: float
    self_clearance: float
    obstacle_clearance: float
    chain_length: float
    scale: float


def collision_sizes(robot: Robot) -> CollisionSizes:
    """The default capsule radius and clearances of ``robot`` (module docstring): those of
    an arm of chain :data:`FULL_SIZE_CHAIN` or longer, scaled by a shorter chain's length."""
    length = chain_length(robot)
    scale = min(1.0, length / FULL_SIZE_CHAIN) if length > 0 else 1.0
    return CollisionSizes(
        radius=DEFAULT_RADIUS * scale,
        self_clearance=DEFAULT_SELF_CLEARANCE * scale,
        obstacle_clearance=DEFAULT_OBSTACLE_CLEARANCE * scale,
        chain_length=length,
        scale=scale,
    )


def capsule_model(
    robot: Robot, radii: ArrayLike | float | None = None, *, clearance: float = 0.0
) -> CapsuleModel:
    """Capsules of ``robot`` with ``radii`` (scalar or (n + 1,); default the arm's
    :func:`collision_sizes` radius), checked pairwise when the links between them are
    longer than both radii and ``clearance`` [m] (module docstring).

    Raises
    ------
    ShapeError
        ``radii`` not a scalar or (n + 1,), or not positive.
    OptionError
        A radius above :data:`MAX_OBSTACLE_EXTENT`.
    """
    n1 = robot.n + 1
    if radii is None:
        radii = collision_sizes(robot).radius
    r = np.asarray(radii, dtype=np.float64)
    if r.ndim == 0:
        r = np.full(n1, float(r))
    if r.shape != (n1,) or not np.all(r > 0):
        raise ShapeError(f"radii must be positive, a scalar or shape ({n1},); got {r}")
    _within_extent("capsule radius", r)  # 1e300: squared distances overflowed
    seg = capsule_segments(robot, np.zeros(robot.n))
    lengths = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=-1)
    pairs = [
        (i, j)
        for i in range(n1)
        for j in range(i + 2, n1)
        if lengths[i + 1 : j].sum() > r[i] + r[j] + clearance
    ]
    return CapsuleModel(
        radii=_checks.frozen(r),
        lengths=_checks.frozen(lengths),
        pairs=_checks.frozen(np.array(pairs, dtype=np.intp).reshape(-1, 2)),
    )


def _segment_distance(
    p1: NDArray[np.float64],
    q1: NDArray[np.float64],
    p2: NDArray[np.float64],
    q2: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Distance of segments ``p1 q1``, ``p2 q2``: (..., 3) -> (...,) (Ericson 2005, 5.1.9)."""
    return _segment_distance_xyz(*(np.moveaxis(np.asarray(x), -1, 0) for x in (p1, q1, p2, q2)))


def _dot3(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """``u . v`` of vectors held component-first, (3, ...) -> (...): the products summed
    ``(x + z) + y``, the order numpy's ``einsum`` sums three (the distances of earlier
    releases, to the last bit), on whole planes instead of three numbers at a time."""
    return (u[0] * v[0] + u[2] * v[2]) + u[1] * v[1]


def _segment_distance_xyz(
    p1: NDArray[np.float64],
    q1: NDArray[np.float64],
    p2: NDArray[np.float64],
    q2: NDArray[np.float64],
) -> NDArray[np.float64]:
    """:func:`_segment_distance` of end points held component-first: (3, ...) -> (...)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a = _dot3(d1, d1)
    e = _dot3(d2, d2)
    f = _dot3(d2, r)
    c = _dot3(d1, r)
    b = _dot3(d1, d2)
    eps = 1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = a * e - b * b
        s = np.where(
            denom > eps * np.maximum(a * e, eps), np.clip((b * f - c * e) / denom, 0, 1), 0.0
        )
        t = np.where(e > eps, (b * s + f) / e, 0.0)
        s = np.where(t < 0, np.where(a > eps, np.clip(-c / a, 0, 1), 0.0), s)
        s = np.where(t > 1, np.where(a > eps, np.clip((b - c) / a, 0, 1), 0.0), s)
        t = np.clip(t, 0, 1)
        # the second segment a point: t = 0 and s from the first segment alone
        point2 = e <= eps
        s = np.where(point2, np.where(a > eps, np.clip(-c / np.where(a > eps, a, 1), 0, 1), 0), s)
        t = np.where(point2, 0.0, t)
    x = (p1 + s * d1) - (p2 + t * d2)
    x *= x
    return np.sqrt((x[0] + x[1]) + x[2])  # numpy's norm sums the squares in this order


def self_distances(
    robot: Robot, q: ArrayLike, model: CapsuleModel, *, segments: NDArray | None = None
) -> NDArray[np.float64]:
    """Signed distances of the self-collision pairs: (..., n) -> (..., k) [m].

    ``segments`` (from :func:`capsule_segments`) skips the kinematics when given. The
    compiled kernel (:mod:`dynid._kernels.collision`) computes the distances of a batch
    of samples, the numpy path (the same numbers) a single sample before numba is loaded
    and when it is missing or turned off.
    """
    seg = capsule_segments(robot, q) if segments is None else segments
    i, j = model.pairs[:, 0], model.pairs[:, 1]
    k = len(i)
    flat = seg.reshape(-1, seg.shape[-3], 2, 3)
    mod = _kernels.load("collision") if _uses_kernel(len(flat)) else None
    if mod is not None:
        out = np.empty((len(flat), k))
        mod.segment_pair_distances(np.ascontiguousarray(flat), model.pairs, out)
        d = out.reshape(seg.shape[:-3] + (k,))
    else:
        d = _pair_distances_numpy(seg, i, j)
    return d - model.radii[i] - model.radii[j]


def _uses_kernel(samples: int) -> bool:
    """Whether the distances of ``samples`` samples take the compiled kernel: a batch
    always (numba missing or turned off aside), a single sample once numba is loaded or
    after a few (:func:`dynid._kernels.small_call_uses_kernels`)."""
    return samples > 1 or _kernels.small_call_uses_kernels()


def _pair_distances_numpy(
    seg: NDArray[np.float64], i: NDArray[np.intp], j: NDArray[np.intp]
) -> NDArray[np.float64]:
    """Distances [m] of the segments ``i`` and ``j`` (k each) of ``seg`` (..., c, 2, 3):
    (..., k), the numpy path of :func:`self_distances`."""
    k = len(i)
    # end points end-major (2 c, 3, M), gathered a whole row (one coordinate of one end
    # over the M samples) at a time, then held component-first (3, 4 k, M)
    ends = np.ascontiguousarray(seg.reshape(-1, 2 * seg.shape[-3], 3).transpose(1, 2, 0))
    g = np.take(ends, np.concatenate([2 * i, 2 * i + 1, 2 * j, 2 * j + 1]), axis=0)
    g = g.transpose(1, 0, 2)
    d = _segment_distance_xyz(g[:, :k], g[:, k : 2 * k], g[:, 2 * k : 3 * k], g[:, 3 * k :])
    return np.ascontiguousarray(d.T).reshape(seg.shape[:-3] + (k,))


def obstacle_capsule_distances(
    robot: Robot,
    q: ArrayLike,
    obstacles: Obstacles,
    model: CapsuleModel,
    *,
    segments: NDArray | None = None,
) -> NDArray[np.float64]:
    """Signed distance of each of capsules 2 .. n to each obstacle:
    (..., n) -> (..., n - 1, len(obstacles)) [m] (capsule ``k`` at index ``k - 2``)."""
    seg = capsule_segments(robot, q) if segments is None else segments
    seg = seg[..., 2:, :, :]
    rad = model.radii[2:]
    out = []
    for pl in obstacles.planes:
        nrm, p0 = pl.normal, pl.point
        d = seg - np.asarray(p0)
        # the products summed (x + z) + y, as numpy's einsum sums three: a third of its time
        h = (d[..., 0] * nrm[0] + d[..., 2] * nrm[2]) + d[..., 1] * nrm[1]
        out.append(np.minimum(h[..., 0], h[..., 1]) - rad)
    if obstacles.boxes:
        u = np.linspace(0.0, 1.0, BOX_SAMPLES)
        pts = seg[..., :1, :] + u[:, None] * (seg[..., 1:2, :] - seg[..., :1, :])  # (..., c, S, 3)
        for bx in obstacles.boxes:
            c, h = np.asarray(bx.center), 0.5 * np.asarray(bx.size)
            o = np.abs(pts - c) - h
            outside = np.linalg.norm(np.maximum(o, 0.0), axis=-1)
            inside = np.minimum(o.max(axis=-1), 0.0)
            out.append((outside + inside).min(axis=-1) - rad)
    if not out:
        return np.zeros(np.shape(seg)[:-2] + (0,))
    return np.stack(out, axis=-1)


def obstacle_distances(
    robot: Robot,
    q: ArrayLike,
    obstacles: Obstacles,
    model: CapsuleModel,
    *,
    segments: NDArray | None = None,
) -> NDArray[np.float64]:
    """Signed distance of capsules 2 .. n to each obstacle: (..., n) -> (..., len(obstacles)) [m].

    The smallest over the capsules checked (see the module docstring); ``inf`` for a
    one-joint arm, which has no capsule to check.
    """
    seg = capsule_segments(robot, q) if segments is None else segments
    if seg.shape[-3] <= 2:  # a one-joint arm: no capsule is checked, none can touch
        return np.full(seg.shape[:-3] + (len(obstacles),), np.inf)
    d = obstacle_capsule_distances(robot, q, obstacles, model, segments=seg)
    return d.min(axis=-2)
