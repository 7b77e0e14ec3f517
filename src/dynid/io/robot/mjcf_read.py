"""Read a robot from MJCF, MuJoCo's model format, through MuJoCo's own compiler.

MuJoCo (the optional ``mujoco`` package) compiles the file (defaults, angle units,
orientations in any of their forms, inertias from geoms where the file asks for it); the
compiled model is read at ``qpos = 0`` in world coordinates:

* the joints, hinge (revolute) or slide (prismatic), one per moving body, make one serial
  chain (every moving body's nearest moving ancestor is the previous one); link ``i``'s
  frame has the axes of body ``i`` and its origin at the joint's anchor (the body's origin
  for a joint without ``pos``); ``T_parent_joint`` is its pose in link ``i-1`` (the world
  frame for link 0, named after the first joint's parent body, or ``world``);
* link ``i``'s inertial parameters are those of body ``i`` and of every body fixed to it
  (no joint of its own), summed as standard parameters; the bodies fixed to the world
  are the base (their inertia is not used);
* the names of the bodies fixed to a link and of the sites become frames of it;
* ``range`` of a limited joint are its position limits; the ``ctrlrange`` of an actuator on
  one joint times its gear, the torque limit; velocity and acceleration limits are
  unknown (``inf``); ``<option gravity>`` is the gravity;
* the joints' ``damping`` [N m s/rad] and ``frictionloss`` [N m] are read as viscous and
  Coulomb friction as MuJoCo applies them: ``frictionloss`` is a soft constraint, a ramp
  of the velocity of slope ``S`` at rest saturating at ``fc``
  (:mod:`dynid.friction.mujoco_soft`; ``S`` from the joint's ``solreffriction``,
  ``solimpfriction`` and MuJoCo's inverse weight, :func:`frictionloss_slopes`), read as the
  smooth law ``fv dq + fc tanh(dq / width)`` with the width whose ``tanh`` is closest to
  that ramp, ``width = RAMP_WIDTH fc / S`` (the ramp's acceleration term, ``ddq d
  timeconst / 2`` in velocity, left out), said in one note; their ``armature``
  [kg m^2], a direct drive's rotor inertias (:func:`mjcf_drive`).

* the joints' ``stiffness`` [N m/rad] about ``springref`` [rad], MuJoCo's passive spring
  ``qfrc_spring = -k (q - q0)``, is the robot's joint spring
  (:attr:`~dynid.model.robot.Robot.spring`, the motors' torque ``k (q - q0)`` against it;
  none when every stiffness is zero).

What a serial-chain model cannot hold is refused in one line naming the file: ball and
free joints, a body with several joints, a tree with branches.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ...exceptions import DataError, DynidError
from ...model.drive import Drive
from ...model.inertia import phi_from_inertial
from ...model.robot import Frame, Robot
from ...model.stiffness import JointStiffness
from ...progress import NOTE

if TYPE_CHECKING:
    from ...friction.laws.base import Friction

__all__ = ["RAMP_WIDTH", "frictionloss_slopes", "load_mjcf", "mjcf_drive"]

_log = logging.getLogger(__name__)

_HINGE, _SLIDE = 3, 2  # mjtJoint

#: The ``tanh`` closest to a ramp ``fc min(|dq| / c, 1)`` (RMS over velocities past the
#: corner ``c = fc / S``) has the width ``RAMP_WIDTH c``: MuJoCo's dry friction read as the
#: smooth law (the MJCF export writes a smooth law of width ``w`` as the slope closest to
#: it, about ``0.8 fc / w``, so an export reads back near its own width).
RAMP_WIDTH = 0.7546


@dataclass(frozen=True)
class _Compiled:
    """What the reader needs of MuJoCo's compiled model (world poses at ``qpos = 0``)."""

    model: Any
    data: Any
    chain: list[int]  # the moving bodies, base to tip
    owner: NDArray[np.intp]  # per body: its link (0 = the base)


def _compiled(path: Path) -> _Compiled:
    try:
        import mujoco
    except ImportError as exc:
        raise DataError(
            "reading an MJCF robot needs MuJoCo's Python package (pip install dynid[mjcf]); "
            "hint: the TOML export (robot.toml) holds the same robot",
            file=path.name,
        ) from exc
    try:
        m = mujoco.MjModel.from_xml_path(str(path))
    except Exception as exc:  # MuJoCo's compiler: one message
        msg = " ".join(str(exc).split())
        raise DataError(f"MuJoCo cannot read it: {msg}", file=path.name) from exc
    bad = [
        mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) or f"#{j}"
        for j in range(m.njnt)
        if m.jnt_type[j] not in (_HINGE, _SLIDE)
    ]
    if bad:
        raise DataError(
            f"joint(s) {', '.join(bad)}: only hinge and slide joints make a serial chain",
            file=path.name,
        )
    if m.njnt == 0:
        raise DataError("no hinge or slide joint", file=path.name)
    several = [b for b in range(m.nbody) if m.body_jntnum[b] > 1]
    if several:
        raise DataError(f"body {_body(m, several[0])} has several joints", file=path.name)
    owner = np.zeros(m.nbody, dtype=np.intp)
    chain: list[int] = []
    for b in range(1, m.nbody):  # parents come before their children
        if m.body_jntnum[b] == 1:
            if owner[m.body_parentid[b]] != len(chain):
                raise DataError(
                    f"body {_body(m, b)} branches off the chain at "
                    f"{_body(m, m.body_parentid[b])}: only one serial chain is read",
                    file=path.name,
                )
            chain.append(b)
            owner[b] = len(chain)
        else:
            owner[b] = owner[m.body_parentid[b]]
    d = mujoco.MjData(m)
    d.qpos[:] = 0.0
    mujoco.mj_kinematics(m, d)
    return _Compiled(m, d, chain, owner)


def _body(m: Any, b: int) -> str:
    import mujoco

    return repr(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(b)) or f"#{b}")


def _pose(R: NDArray[np.float64], p: NDArray[np.float64]) -> NDArray[np.float64]:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    return T


def load_mjcf(path: str | Path) -> Robot:
    """A robot from an MJCF file (module docstring), its friction the joints' ``damping``
    and ``frictionloss`` (none when both are zero).

    Raises
    ------
    DataError
        MuJoCo is not installed or refuses the file, or the file's model is not one
        serial chain of hinge and slide joints (named).
    """
    import mujoco

    path = Path(path)
    c = _compiled(path)
    m, d = c.model, c.data
    n = len(c.chain)
    jnt = [int(m.body_jntadr[b]) for b in c.chain]
    name = lambda kind, k: mujoco.mj_id2name(m, kind, int(k)) or ""  # noqa: E731
    # link frames in the world: the body's axes, the joint's anchor
    W = [np.eye(4)] + [
        _pose(d.xmat[b].reshape(3, 3), d.xanchor[j]) for b, j in zip(c.chain, jnt, strict=True)
    ]
    first = int(m.body_parentid[c.chain[0]])
    base_at_world = first == 0 or np.allclose(
        _pose(d.xmat[first].reshape(3, 3), d.xpos[first]), W[0]
    )
    base = name(mujoco.mjtObj.mjOBJ_BODY, first) if first and base_at_world else "world"
    inv = [np.linalg.inv(T) for T in W]
    phi = np.zeros((n, 10))
    frames: dict[str, Frame] = {}
    for b in range(1, m.nbody):
        i = int(c.owner[b])
        if i and m.body_mass[b] > 0:
            R = inv[i][:3, :3] @ d.ximat[b].reshape(3, 3)
            com = (inv[i] @ np.append(d.xipos[b], 1.0))[:3]
            phi[i - 1] += phi_from_inertial(
                m.body_mass[b], com, R @ np.diag(m.body_inertia[b]) @ R.T
            )
        if m.body_jntnum[b] == 0:
            frames[name(mujoco.mjtObj.mjOBJ_BODY, b)] = Frame(
                i, inv[i] @ _pose(d.xmat[b].reshape(3, 3), d.xpos[b])
            )
    for s in range(m.nsite):
        i = int(c.owner[m.site_bodyid[s]])
        frames[name(mujoco.mjtObj.mjOBJ_SITE, s)] = Frame(
            i, inv[i] @ _pose(d.site_xmat[s].reshape(3, 3), d.site_xpos[s])
        )
    frames.pop(base, None)
    frames.pop("", None)
    limited = np.asarray(m.jnt_limited[jnt], dtype=bool)
    dofs = np.asarray(m.jnt_dofadr[jnt])
    fv, fc = np.asarray(m.dof_damping[dofs]), np.asarray(m.dof_frictionloss[dofs])
    try:
        robot = Robot(
            name=bytes(m.names).split(b"\0", 1)[0].decode() or path.stem,
            joint_names=tuple(
                name(mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint{k + 1}" for k, j in enumerate(jnt)
            ),
            link_names=(base, *(name(mujoco.mjtObj.mjOBJ_BODY, b) for b in c.chain)),
            T_parent_joint=np.stack([inv[i] @ W[i + 1] for i in range(n)]),
            axes=np.stack([W[i + 1][:3, :3].T @ d.xaxis[j] for i, j in enumerate(jnt)]),
            prismatic=np.array([m.jnt_type[j] == _SLIDE for j in jnt]),
            phi=phi,
            q_min=np.where(limited, m.jnt_range[jnt, 0], -np.inf),
            q_max=np.where(limited, m.jnt_range[jnt, 1], np.inf),
            dq_max=np.full(n, np.inf),
            ddq_max=np.full(n, np.inf),
            tau_max=_torque_limits(m, jnt),
            gravity=np.array(m.opt.gravity, dtype=np.float64),
            frames=frames,
        )
    except DynidError as exc:
        raise DataError(str(exc), file=path.name) from exc
    if np.any(fv != 0.0) or np.any(fc != 0.0):
        robot = robot.with_friction(_friction_as_applied(m, dofs, fv, fc, path.name))
    k = np.asarray(m.jnt_stiffness[jnt], dtype=np.float64)
    if np.any(k != 0.0):
        q0 = np.asarray(m.qpos_spring[m.jnt_qposadr[jnt]], dtype=np.float64)
        robot = robot.with_spring(JointStiffness(k, q0))
    return robot


def frictionloss_slopes(m: Any, dofs: NDArray[np.intp]) -> NDArray[np.float64]:
    """MuJoCo's dry friction torque per velocity at rest [N m s/rad] of the compiled
    model ``m``'s dofs ``dofs``: ``b / R`` of the soft constraint (MuJoCo's documentation,
    Computation), ``R = (1 - d) / d A_0`` with ``d`` solimp's ``dmin`` (a friction row's
    violation is zero) and ``A_0`` the dof's ``dof_invweight0``; ``b = 2 / (dmax tc)`` for
    solref's standard form (``tc`` raised to two timesteps, as MuJoCo does), ``-solref[1] /
    dmax`` for its direct form. Equal to ``mj_inverse``'s slope at zero acceleration."""
    from ...friction.mujoco_soft import MAX_IMPEDANCE, MIN_IMPEDANCE

    ref, imp = np.asarray(m.dof_solref[dofs]), np.asarray(m.dof_solimp[dofs])
    dmin, dmax = (np.clip(imp[:, k], MIN_IMPEDANCE, MAX_IMPEDANCE) for k in (0, 1))
    tc = np.maximum(ref[:, 0], 2.0 * float(m.opt.timestep))
    b = np.where(ref[:, 0] > 0, 2.0 / (dmax * tc), -ref[:, 1] / dmax)
    R = (1.0 - dmin) / dmin * np.asarray(m.dof_invweight0[dofs])
    return np.asarray(b / R, dtype=np.float64)


def _friction_as_applied(
    m: Any, dofs: NDArray[np.intp], fv: NDArray[np.float64], fc: NDArray[np.float64], name: str
) -> Friction:
    """The joints' ``damping`` ``fv`` and ``frictionloss`` ``fc`` (n,) as MuJoCo applies
    them (module docstring): the smooth law of width ``RAMP_WIDTH fc / S``
    (:func:`frictionloss_slopes`), the plain sign where ``fc`` is zero; said in a note."""
    from ...friction.laws import LAWS

    n = fv.shape[0]
    slope = frictionloss_slopes(m, dofs)
    held = fc > 0
    width = np.where(held, RAMP_WIDTH * fc / np.where(held, slope, 1.0), 0.0)
    if np.any(held):
        _log.log(
            NOTE,
            "%s: frictionloss read as MuJoCo applies it, a ramp of the velocity up to fc of "
            "slope %s N m s/rad at rest (its solreffriction and solimpfriction), not a sharp "
            "Coulomb: as fc tanh(dq / width), width %s rad/s, the tanh closest to the ramp "
            "(joint(s) %s)",
            name,
            _span(slope[held]),
            _span(width[held]),
            ", ".join(str(j + 1) for j in np.flatnonzero(held)),
        )
    return LAWS["smooth"].model(np.stack([fv, fc, np.zeros(n)], axis=1), width)


def _span(x: NDArray[np.float64]) -> str:
    """``x``'s range as a note says it: ``0.0201`` or ``0.0201-0.0284``."""
    lo, hi = float(np.min(x)), float(np.max(x))
    return f"{lo:.3g}" if f"{lo:.3g}" == f"{hi:.3g}" else f"{lo:.3g}-{hi:.3g}"


def _torque_limits(m: Any, jnt: list[int]) -> NDArray[np.float64]:
    """Per joint: ``|ctrlrange| |gear|`` of a limited actuator on it, else ``inf``."""
    out = np.full(len(jnt), np.inf)
    for a in range(m.nu):
        if m.actuator_trntype[a] != 0 or not m.actuator_ctrllimited[a]:  # mjTRN_JOINT
            continue
        j = int(m.actuator_trnid[a, 0])
        if j in jnt:
            k = jnt.index(j)
            hi = float(np.max(np.abs(m.actuator_ctrlrange[a]))) * abs(float(m.actuator_gear[a, 0]))
            out[k] = hi if not np.isfinite(out[k]) else max(out[k], hi)
    return out


def mjcf_drive(path: str | Path) -> Drive | None:
    """A direct drive whose rotor inertias are the joints' ``armature`` [kg m^2]; None
    when every armature is zero."""
    c = _compiled(Path(path))
    m = c.model
    ia = np.array([m.dof_armature[m.jnt_dofadr[m.body_jntadr[b]]] for b in c.chain])
    if not np.any(ia != 0.0):
        return None
    d = Drive.identity(len(c.chain))
    return Drive(transmission=d.transmission, offset=d.offset, rotor_inertia=ia)
