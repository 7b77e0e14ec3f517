"""How the compiled kernels see a robot: one packed array of constants, and the array kinds.

Every kernel takes the robot as one read-only float64 array ``C`` of shape ``(n + 1, W)``
(:func:`pack`, memoised per robot by :func:`dynid._kernels.dispatch.packed`): row ``i < n``
holds joint ``i``'s constants, the last row the gravity vector. One array instead of five
keeps the call overhead of a single-sample call small (numba types each argument on every
call).

=========  =====================================================================
columns    row ``i`` (joint ``i + 1``, link ``i + 1`` in link ``i``)
=========  =====================================================================
0-11       ``T_parent_joint[i, :3, :]`` row-major (rotation and origin [m])
12-14      unit joint axis in the child link's frame
15         1.0 for a prismatic joint, 0.0 for a revolute one
16-25      standard parameters ``phi[i]`` (``m, m c, J`` about the link origin)
26-52      ``A0, A1, A2`` (row-major) of the joint rotation ``A0 + cos q A1 + sin q A2``
53-55      ``u = F a``, the joint's slide direction in link ``i`` (``p = p0 + q u``)
=========  =====================================================================

With ``F`` the rotation of ``T_parent_joint[i]`` and ``a`` the axis, ``A0 = F a a^T``,
``A1 = F (E - a a^T)``, ``A2 = F [a]x`` for a revolute joint (Rodrigues' formula with
``F`` multiplied in) and ``0, F, 0`` for a prismatic one.

Row ``n``, columns 0-2: gravity in the base frame [m/s^2]. The kinematics kernels take a
frame too: :func:`pack_frame` appends row ``n + 1`` holding the frame's pose ``T_lf`` in
its link (16 entries, row-major, a tool already multiplied in) and, in column 16, the link
(0 = base).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import _checks

#: Column offsets of the packed constants (see the module docstring).
C_T, C_AXIS, C_PRISMATIC, C_PHI, C_ROT, C_SLIDE, C_WIDTH = 0, 12, 15, 16, 26, 53, 56

#: Cholesky pivot^2 over the diagonal of the mass matrix below which a joint moves no
#: inertia of its own (independent of the joints before it): the mass matrix is singular
#: to rounding (the forward dynamics' kernel and its Python path share it)
SINGULAR_PIVOT = 1e-12


def pack(robot: Any, phi: Any = None, gravity: Any = None) -> NDArray[np.float64]:
    """The constants ``C`` (n + 1, W) of ``robot`` (see the module docstring), read-only.

    ``phi`` (n, 10) and ``gravity`` (3,) replace the robot's when given (validated arrays).
    """
    n = robot.T_parent_joint.shape[0]
    C = np.zeros((n + 1, C_WIDTH))
    C[:n, C_T : C_T + 12] = robot.T_parent_joint[:, :3, :].reshape(n, 12)
    C[:n, C_AXIS : C_AXIS + 3] = robot.axes
    C[:n, C_PRISMATIC] = robot.prismatic
    C[:n, C_PHI : C_PHI + 10] = robot.phi if phi is None else phi
    F, a = robot.T_parent_joint[:, :3, :3], robot.axes
    aa = a[:, :, None] * a[:, None, :]
    K = np.zeros((n, 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -a[:, 2], a[:, 1], -a[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = a[:, 2], -a[:, 1], a[:, 0]
    pri = robot.prismatic[:, None, None]
    A0 = np.where(pri, 0.0, F @ aa)
    A1 = np.where(pri, F, F @ (np.eye(3) - aa))
    A2 = np.where(pri, 0.0, F @ K)
    C[:n, C_ROT : C_ROT + 27] = np.concatenate([A.reshape(n, 9) for A in (A0, A1, A2)], axis=1)
    C[:n, C_SLIDE : C_SLIDE + 3] = (F @ a[:, :, None])[:, :, 0]
    C[n, :3] = robot.gravity if gravity is None else gravity
    C.setflags(write=False)
    return C


#: float64 (the thin paths check ``x.dtype is F64``)
F64 = np.dtype(np.float64)
#: a float64 vector of any strides: the type of the thin paths' joint vectors ('A' layout)
VECTOR = np.zeros(4)[::2]  # (2,) with stride 16: not contiguous, so typed with any strides


def pack_frame(C: NDArray[np.float64], link: int, T_lf: NDArray[np.float64]) -> NDArray:
    """``C`` with a last row for the frame ``T_lf`` (4, 4) of ``link`` (read-only)."""
    CF = np.zeros((C.shape[0] + 1, C_WIDTH))
    CF[:-1] = C
    CF[-1, :16] = np.asarray(T_lf, dtype=np.float64).reshape(16)
    CF[-1, 16] = link
    CF.setflags(write=False)
    return CF


def c_float64(x: Any) -> NDArray[np.float64] | None:
    """``x`` as a float64 C-contiguous array of at least one dimension (no copy when it is
    one), or None (a scalar, or not numeric): the input of the kernels' lean paths; None
    sends a call to the full validation, which raises the documented errors."""
    if type(x) is np.ndarray and x.dtype is F64 and x.flags.c_contiguous:
        return x if x.ndim else None
    if isinstance(x, np.ndarray | np.generic) and x.dtype.kind not in "biuf":
        return None  # complex (numpy drops the imaginary part), text (read as numbers)
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        return None
    if not a.ndim:
        return None
    return a if a.flags.c_contiguous else np.ascontiguousarray(a)


def flat(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """``x`` as a flat C-contiguous, aligned, writeable array (a view when it can be).

    The kernels then see a single argument type, so they are compiled once.
    """
    if x.ndim != 1:
        x = x.reshape(-1)
    return x if x.flags.carray else np.array(x)


def readonly(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """``x`` as a read-only C array, as the robot's constants are (one kernel type)."""
    f = x.flags
    return x if f.c_contiguous and f.aligned and not f.writeable else _checks.frozen(x)
