"""Serial chains read from URDF text: the reading half of :mod:`dynid.io.robot.urdf`.

:func:`robot_from_urdf_string` extracts the serial chain between a base link and a tip link
of a URDF document and returns a :class:`~dynid.model.robot.Robot`; :func:`load_urdf` does
the same for a file. Only the standard library's ``xml.etree.ElementTree`` is used.

Conventions
-----------
* The base frame (link 0) is the frame of ``base_link``. Gravity is ``(0, 0, -9.80665)``
  m/s^2 in that frame (URDF holds no gravity); change it with ``Robot.with_gravity``.
* Every ``revolute``, ``continuous`` or ``prismatic`` joint on the chain becomes a joint of
  the robot, with the URDF joint and child-link names. A joint origin ``xyz`` [m] / ``rpy``
  [rad] is the pose of the child link in the parent link at ``q = 0``; ``rpy`` is URDF's
  ``Rz(yaw) Ry(pitch) Rx(roll)`` (:func:`dynid.spatial.matrix_from_rpy`). The axis is given
  in the child-link frame and normalised (URDF default ``(1, 0, 0)``).
* ``fixed`` joints are merged. Fixed joints before the first moving joint fold into
  ``T_parent_joint[0]``; a fixed joint after a moving joint makes its child part of the
  rigid body of the preceding moving link. Every URDF link on the chain, and every link
  hanging off a chain link through fixed joints only (a hand, a tool-centre-point link),
  becomes a named frame ``Frame(link index, T_link_frame)`` at its own pose; ``flange``
  is the frame of the tip link, unless the URDF has a link of that name (then it is that
  link's frame, as every other link's).
* The inertia of a link rigidly fixed to moving link ``k`` (on or off the chain) is added
  to link ``k``: its CoM and its inertia about the CoM are carried into link-``k``
  coordinates (``c_k = R c + p``, ``I_k = R I R^T``) before the standard parameters are
  summed. Inertials of links fixed to the base do not enter the dynamics and are dropped.
  An ``<inertial>`` origin rotates the principal frame: the inertia about the CoM in link
  axes is ``R_o I R_o^T``. A link without ``<inertial>`` has zero mass.
* Limits: ``lower``/``upper`` [rad or m] (a ``continuous`` joint, or a missing
  attribute, gives ``-inf``/``inf``), ``velocity`` [rad/s or m/s] and ``effort``
  [N m or N] (missing or non-positive: ``inf``); URDF holds no acceleration limit, so
  ``ddq_max`` is ``inf``.
* Joint friction: ``<dynamics damping friction>`` of a moving joint on the chain is read
  as Pinocchio reads it (``model.damping``, ``model.friction``): ``damping`` the viscous
  coefficient ``fv`` [N m s/rad or N s/m], ``friction`` the Coulomb level ``fc`` [N m or
  N] (a missing attribute is 0). When some joint holds a non-zero value the robot's own
  friction is the classical law at the joints (there whatever drive the robot is used
  with), ``tau_f = fv dq + fc sign(dq)``
  (:func:`~dynid.friction.model.ClassicalFriction`, no offset, no standstill band), and one
  log line names those joints; zeros everywhere mean no friction. dynid's export writes
  its friction there (:func:`~dynid.io.robot.urdf.export_urdf`), so it reads back. A
  negative coefficient is refused.
* Lumped, left out, said once (:mod:`dynid.io.robot.urdf_branches`): the links hanging
  off the last body through moving joints past the tip (a gripper's fingers, the joints
  past a tip chosen mid-arm) are lumped into it at their joints' zero position, as
  Pinocchio's model with those joints locked at neutral, in a note naming them, their
  mass and inertia (level :data:`~dynid.progress.NOTE`); they are no frames of the robot.
  The links hanging off earlier moving links through moving joints (another arm on a
  torso), or past the tip through a floating or planar joint, are left out: a warning
  names them, their mass and inertia, which no link of the model holds (a log line when
  they are massless); the links with mass hanging off the chain through fixed joints
  and merged into its bodies (a hand beyond the tip) in a note naming them and their
  mass; every link merged through a fixed joint in a log line (``-v``).
* Ignored: mimic joints off the chain, transmissions, gazebo tags, visual and collision
  geometry, ``<dynamics>`` of fixed joints, the other attributes of ``<dynamics>``
  (Gazebo's ``K``, ``D``, ``mu_coulomb``, ...), ``<safety_controller>``.
"""

from __future__ import annotations

import logging
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..._checks import caller_level
from ...exceptions import DynidWarning, ModelError, UnknownNameError
from ...friction.model import ClassicalFriction, Friction
from ...model.inertia import READ_AS_GIVEN, inertial_problems, phi_from_inertial
from ...model.placeholders import placeholder_words
from ...model.robot import MAX_LINK_MASS, MAX_LINK_OFFSET, Frame, Robot
from ...progress import NOTE
from ..input_files import file_bytes
from .urdf_angles import AngleRounding, rounding_message, snapped_message
from .urdf_branches import OffChain, off_chain
from .urdf_tree import (
    _chain,
    _child,
    _float,
    _floats,
    _Joint,
    _origin,
    _parse_tree,
    _subtree_leaves,
)

__all__ = ["chain_with_branches", "joints_past_tip", "load_urdf", "robot_from_urdf_string"]

_log = logging.getLogger(__name__)

_MOVING = {"revolute": False, "continuous": False, "prismatic": True}  # type -> prismatic
_UNSUPPORTED = ("floating", "planar")
_INERTIA_ATTRS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def _inertial(
    link: str, el: ET.Element
) -> tuple[float, NDArray[np.float64], NDArray[np.float64]] | None:
    """Mass [kg], CoM [m] and inertia about the CoM [kg m^2] in link axes, or None if absent.

    Warns (:class:`DynidWarning`) when the values are physically inconsistent.
    """
    inertial = _child(el, "inertial")
    if inertial is None:
        return None
    what = f"link {link!r} <inertial>"
    T_link_o = _origin(inertial, what)
    if not float(np.max(np.abs(T_link_o[:3, 3]))) <= MAX_LINK_OFFSET:  # 1e300: NaN inertia
        raise ModelError(
            f"{what} origin must lie within {MAX_LINK_OFFSET:g} m of the link frame; got "
            f"{T_link_o[:3, 3].tolist()}"
        )
    mass_el = _child(inertial, "mass")
    mass = None if mass_el is None else _float(mass_el, "value", f"{what} <mass>")
    if mass is None or not np.isfinite(mass):
        raise ModelError(f"{what} needs a finite <mass value=...>")
    if mass > MAX_LINK_MASS:
        raise ModelError(f"{what} <mass> must be at most {MAX_LINK_MASS:g} kg; got {mass!r}")
    I6 = np.zeros(6)
    inertia_el = _child(inertial, "inertia")
    if inertia_el is not None:
        for k, attr in enumerate(_INERTIA_ATTRS):
            v = _float(inertia_el, attr, f"{what} <inertia>")
            if v is not None and not np.isfinite(v):
                raise ModelError(f"{what} <inertia> attribute {attr!r} must be finite")
            I6[k] = 0.0 if v is None else v
    xx, xy, xz, yy, yz, zz = I6
    I_o = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    _warn_if_inconsistent(link, mass, I_o)
    R = T_link_o[:3, :3]
    return mass, T_link_o[:3, 3].copy(), R @ I_o @ R.T


#: What a placeholder inertial becomes when read (:mod:`dynid.model.placeholders`).
PLACEHOLDER_READ = (
    "read as given (a model taken from the description lacks their weight; identification "
    "fits the links anew, and a consistent fit's prior puts the generic cylinder in their "
    "place, their masses not bounded by the stand-in's)"
)


def _warn_if_inconsistent(link: str, mass: float, I: NDArray[np.float64]) -> None:
    """Warn when mass < 0, I is not positive semi-definite or violates the triangle inequality."""
    problems = inertial_problems(mass, I)
    if problems:
        warnings.warn(
            f"link {link!r} has a physically inconsistent inertial: {'; '.join(problems)}; "
            + READ_AS_GIVEN,
            DynidWarning,
            stacklevel=caller_level(),
        )


def _limits(joint: _Joint) -> tuple[float, float, float, float]:
    """Lower, upper, velocity and effort limits of a moving joint (inf where none)."""
    lim = _child(joint.elem, "limit")
    what = f"joint {joint.name!r} <limit>"
    get = (lambda a: None) if lim is None else (lambda a: _float(lim, a, what))
    lower, upper = get("lower"), get("upper")
    if joint.type == "continuous":
        lower = upper = None
    lo = -np.inf if lower is None else lower
    hi = np.inf if upper is None else upper
    if not lo < hi:
        raise ModelError(
            f"joint {joint.name!r}: lower limit must be below the upper one; got {lo} >= {hi}"
        )
    out = []
    for attr in ("velocity", "effort"):
        v = get(attr)
        if v is not None and v <= 0.0:
            warnings.warn(
                f"joint {joint.name!r} has {attr} limit {v}; treated as unbounded",
                DynidWarning,
                stacklevel=caller_level(),
            )
            v = None
        out.append(np.inf if v is None else v)
    return lo, hi, out[0], out[1]


def _dynamics(joint: _Joint) -> tuple[float, float]:
    """Viscous ``damping`` [N m s/rad or N s/m] and Coulomb ``friction`` [N m or N] of a
    moving joint's ``<dynamics>`` (0 where absent), as Pinocchio reads them."""
    el = _child(joint.elem, "dynamics")
    if el is None:
        return 0.0, 0.0
    what = f"joint {joint.name!r} <dynamics>"
    out = []
    for attr in ("damping", "friction"):
        v = _float(el, attr, what)
        v = 0.0 if v is None else v
        if not (np.isfinite(v) and v >= 0.0):
            raise ModelError(
                f"{what} attribute {attr!r} must be a finite number >= 0 (a dissipative "
                f"joint); got {v!r}"
            )
        out.append(v)
    return out[0], out[1]


def _friction(w: _Walk) -> Friction | None:
    """The chain's joint friction of ``<dynamics>`` (module docstring), None when every
    coefficient is zero."""
    fv_fc = np.array(w.dynamics, dtype=np.float64).reshape(-1, 2)
    if not np.any(fv_fc != 0.0):
        return None
    n = len(fv_fc)
    # per joint, without a drive: a description's friction, which a geared drive leaves at
    # the joints unless its file says friction_at = "motor" (Friction.placed)
    return ClassicalFriction(fv_fc[:, 0], fv_fc[:, 1], np.zeros(n))


def robot_from_urdf_string(
    text: str | bytes,
    base_link: str | None = None,
    tip_link: str | None = None,
    *,
    source: str = "URDF text",
    snap_angles: bool = False,
    note_angles: bool = True,
) -> Robot:
    """Serial chain between ``base_link`` and ``tip_link`` of a URDF document.

    Parameters
    ----------
    text : str or bytes
        The URDF XML document.
    base_link : str, optional
        Link whose frame is the base frame (link 0). Default: the root link of the tree.
    tip_link : str, optional
        Last link of the chain; its frame is ``flange`` (unless a URDF link is named
        ``flange``). Default: the unique leaf link
        below ``base_link``.
    source : str
        Name of the document used in error messages (a file path, say).
    snap_angles : bool
        Snap the joint-origin ``rpy`` angles within 1e-3 rad of a multiple of pi/2 to it
        (``rpy="1.5708"`` read as pi/2; :mod:`dynid.io.robot.urdf_angles`).
    note_angles : bool
        Name the rounded angles in a note (level :data:`~dynid.progress.NOTE`): read as
        written, with the leftovers and condition numbers, or snapped. False for a file
        read for its inertials alone (a prior), whose angles are the robot's to report.

    Returns
    -------
    Robot
        ``n`` = number of revolute, continuous and prismatic joints between base and tip.
        ``T_parent_joint`` (n, 4, 4) [m], ``axes`` (n, 3) unit vectors in link
        coordinates, ``phi`` (n, 10) standard parameters about the link origins [SI],
        limits (n,), gravity ``(0, 0, -9.80665)`` m/s^2 in the base frame, frames for every
        URDF link on the chain and fixed to it (each at its own pose), ``flange`` at the tip
        link unless a URDF link has that name. See the module
        docstring for the merging of fixed joints.

    Raises
    ------
    ModelError
        Malformed XML or URDF (missing names, unknown link references, duplicates, a link
        with two parents, cycles, unparsable numbers); several root links and no
        ``base_link``; several leaves below the base and no ``tip_link``; tip not below
        base; a ``floating``, ``planar``, unknown-type or mimic joint on the chain; no
        moving joint between base and tip; a lower limit not below the upper one.
    UnknownNameError
        ``base_link`` or ``tip_link`` is not a link of the URDF (the message lists them).

    Warns
    -----
    DynidWarning
        The inertial of a link that enters the model is physically inconsistent
        (negative mass, inertia not positive semi-definite, triangle inequality violated):
        it is kept as given. A link's mass is a placeholder (above zero and under 1 % of
        the median link mass, :mod:`dynid.model.placeholders`): one warning names them all,
        kept as given. A velocity or
        effort limit is not positive: it is treated as unbounded. Joint-origin
        angles are rounded near multiples of pi/2 (``rpy="1.5708"``) in a way that
        matters and ``snap_angles`` is False: the joints and the unscaled condition
        numbers of the structural regressor as written and snapped are named (a harmless
        rounding is a note, as are angles snapped).
    """
    return _robot_from_text(text, base_link, tip_link, source, snap_angles, note_angles)


def chain_with_branches(
    text: str | bytes,
    base_link: str | None = None,
    tip_link: str | None = None,
    *,
    source: str = "URDF text",
) -> tuple[Robot, OffChain]:
    """The chain (angles as written, nothing said) and what it leaves out or merges.

    Parameters
    ----------
    text, base_link, tip_link, source
        As :func:`robot_from_urdf_string`.

    Returns
    -------
    robot : Robot
        The chain, read as :func:`robot_from_urdf_string` reads it.
    off : OffChain
        The branches (links hanging off a moving body through moving joints: those past
        the tip, fingers, lumped into the last body; the others left out) and the fixed
        links merged (:func:`~dynid.io.robot.urdf_branches.off_chain`).

    Raises
    ------
    ModelError, UnknownNameError
        As :func:`robot_from_urdf_string`.
    """
    return _read_chain(text, base_link, tip_link, source, AngleRounding())


def joints_past_tip(
    path: str | Path, base_link: str | None = None, tip_link: str | None = None
) -> dict[str, tuple[str | None, str]]:
    """The moving joints past the tip of a URDF file's chain, whose links the chain lumps
    into its last body at their zero (a gripper's past a tip chosen before it), each with
    the tip link that keeps it a joint of the model (None: no one link does, as for two
    fingers) and the unit of its position (``"rad"``, ``"m"`` for a prismatic joint).
    Nothing is said or warned (the robot's reader says it).

    Raises
    ------
    ModelError, UnknownNameError
        As :func:`load_urdf`.
    """
    p = Path(path)
    try:
        data = file_bytes(p)
    except OSError as exc:
        raise ModelError(f"cannot read URDF file {str(p)!r}: {exc.strerror or exc}") from exc
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        _, off = chain_with_branches(data, base_link, tip_link, source=f"URDF file {str(p)!r}")
    return {
        joint: (b.tip, "m" if prismatic else "rad")
        for b in off.lumped
        for joint, prismatic in zip(b.joints, b.prismatic, strict=True)
    }


def _chain_ends(
    source: str,
    links: dict[str, ET.Element],
    parent_joint: dict[str, _Joint],
    child_joints: dict[str, list[_Joint]],
    base_link: str | None,
    tip_link: str | None,
) -> tuple[str, str]:
    """The base and tip links: as given (checked to exist), else the unique root and leaf."""
    for role, given in (("base", base_link), ("tip", tip_link)):
        if given is not None and given not in links:
            raise UnknownNameError(f"Unknown {role} link {given!r}; available: {sorted(links)}")
    if base_link is None:
        roots = [link for link in links if link not in parent_joint]
        if len(roots) != 1:
            raise ModelError(
                f"{source} has {len(roots)} root links {roots}; pass base_link=... to choose one"
            )
        base_link = roots[0]
    if tip_link is None:
        leaves = _subtree_leaves(base_link, child_joints)
        if len(leaves) != 1:
            raise ModelError(
                f"several leaf links below base link {base_link!r}: {leaves}; "
                "pass tip_link=... to choose the end of the chain"
            )
        tip_link = leaves[0]
    return base_link, tip_link


def _check_chain(path: list[_Joint], base_link: str, tip_link: str) -> None:
    """Refuse joints a serial chain cannot hold, and a chain without a moving joint."""
    for joint in path:
        if joint.type in _UNSUPPORTED:
            raise ModelError(
                f"joint {joint.name!r} of type {joint.type!r} on the chain cannot be modelled; "
                "a serial chain holds revolute, continuous, prismatic and fixed joints only"
            )
        if joint.type not in _MOVING and joint.type != "fixed":
            raise ModelError(f"joint {joint.name!r} has unknown type {joint.type!r}")
        if joint.type in _MOVING and _child(joint.elem, "mimic") is not None:
            raise ModelError(
                f"joint {joint.name!r} on the chain mimics another joint; coupled joints "
                "cannot be modelled, choose a tip link before it"
            )
    if not any(j.type in _MOVING for j in path):
        raise ModelError(
            f"no revolute, continuous or prismatic joint between base link {base_link!r} "
            f"and tip link {tip_link!r}"
        )


def _axis(joint: _Joint) -> NDArray[np.float64]:
    """Unit axis (3,) of a moving joint in its child link (URDF default ``(1, 0, 0)``)."""
    axis_el = _child(joint.elem, "axis")
    axis = _floats(
        None if axis_el is None else axis_el.get("xyz"),
        3,
        f"joint {joint.name!r} axis",
        (1.0, 0.0, 0.0),
    )
    with np.errstate(over="ignore"):
        norm = float(np.linalg.norm(axis))
    if norm < 1e-12:
        raise ModelError(f"joint {joint.name!r} has a zero axis")
    if not np.isfinite(norm):
        raise ModelError(
            f"joint {joint.name!r} axis {axis.tolist()} is too large to normalise "
            "(its squared length overflows a float); give the axis as a unit vector"
        )
    return axis / norm


@dataclass
class _Walk:
    """The chain walked from the base: the robot's joints and where every URDF link sits.

    ``placed[link] = (k, T_k_link)``: the link is rigidly part of body ``k`` (0 = base) at
    pose ``T_k_link``; ``order`` lists the placed links in the order they were placed;
    ``fixed_joint[link]`` names the fixed joint whose child the link is.
    """

    link_names: list[str]
    joint_names: list[str]
    T_fix: list[NDArray[np.float64]]
    axes: list[NDArray[np.float64]]
    prismatic: list[bool]
    limits: list[tuple[float, float, float, float]]
    dynamics: list[tuple[float, float]]
    placed: dict[str, tuple[int, NDArray[np.float64]]]
    order: list[str]
    fixed_joint: dict[str, str] = field(default_factory=dict)


def _walk(path: list[_Joint], base_link: str, angles: AngleRounding) -> _Walk:
    """Walk the chain: fixed joints fold into the next joint's pose or the current body."""
    w = _Walk([base_link], [], [], [], [], [], [], {base_link: (0, np.eye(4))}, [base_link])
    k, T_k_cur = 0, np.eye(4)
    for joint in path:
        T = T_k_cur @ _origin(joint.elem, f"joint {joint.name!r}", angles, joint.name)
        if joint.type == "fixed":
            T_k_cur = T
            w.fixed_joint[joint.child] = joint.name
        else:
            w.axes.append(_axis(joint))
            w.joint_names.append(joint.name)
            w.T_fix.append(T)
            w.prismatic.append(_MOVING[joint.type])
            w.limits.append(_limits(joint))
            w.dynamics.append(_dynamics(joint))
            w.link_names.append(joint.child)
            k, T_k_cur = k + 1, np.eye(4)
        w.placed[joint.child] = (k, T_k_cur)
        w.order.append(joint.child)
    return w


def _place_fixed_links(w: _Walk, path: list[_Joint], child_joints: dict[str, list[_Joint]]) -> None:
    """Add the links hanging off placed links through fixed joints only (hands, TCP frames)."""
    on_chain = {j.name for j in path}
    stack = list(reversed(w.order))
    while stack:
        link = stack.pop()
        kl, T_k_link = w.placed[link]
        for joint in child_joints[link]:
            if joint.name in on_chain or joint.type != "fixed":
                continue
            if joint.child in w.placed:
                raise ModelError(f"the joints form a cycle through link {joint.child!r}")
            w.placed[joint.child] = (kl, T_k_link @ _origin(joint.elem, f"joint {joint.name!r}"))
            w.fixed_joint[joint.child] = joint.name
            w.order.append(joint.child)
            stack.append(joint.child)


def _subtree_phi(
    joint: _Joint,
    T_k_parent: NDArray[np.float64],
    links: dict[str, ET.Element],
    child_joints: dict[str, list[_Joint]],
) -> NDArray[np.float64]:
    """Standard parameters (10,) of ``joint``'s child link and every link below it in the
    frame of the body whose frame holds the parent at pose ``T_k_parent`` (4, 4) [m],
    every joint at zero (its child at the joint's origin)."""
    phi = np.zeros(10)
    stack = [(joint, T_k_parent)]
    while stack:
        j, T_k = stack.pop()
        T_k_child = T_k @ _origin(j.elem, f"joint {j.name!r}")
        inertial = _inertial(j.child, links[j.child])
        if inertial is not None:
            mass, c, I = inertial
            R, p = T_k_child[:3, :3], T_k_child[:3, 3]
            phi += phi_from_inertial(mass, R @ c + p, R @ I @ R.T)
        stack.extend((c_j, T_k_child) for c_j in child_joints[j.child])
    return phi


def _body_phi(w: _Walk, links: dict[str, ET.Element]) -> NDArray[np.float64]:
    """Standard parameters (n, 10) of each body: its links' inertials summed in its frame."""
    phi = np.zeros((len(w.joint_names), 10))
    for link in w.order:
        kl, T_k_link = w.placed[link]
        if kl == 0:
            continue
        inertial = _inertial(link, links[link])
        if inertial is None:
            continue
        mass, c_link, I_link = inertial
        R, p = T_k_link[:3, :3], T_k_link[:3, 3]
        phi[kl - 1] += phi_from_inertial(mass, R @ c_link + p, R @ I_link @ R.T)
    return phi


def _robot_from_text(
    text: str | bytes,
    base_link: str | None,
    tip_link: str | None,
    source: str,
    snap_angles: bool = False,
    note_angles: bool = True,
) -> Robot:
    """Body of the two public readers (called directly by both, so warnings point at the caller)."""
    angles = AngleRounding(snap=snap_angles)
    robot, found = _read_chain(text, base_link, tip_link, source, angles)
    if (lumped := found.lumped_line) is not None:
        _log.log(NOTE, "%s", lumped)
    if (left := found.left_out) is not None:
        if found.mass_left_out > 0.0:  # a mass the model misses
            warnings.warn(left, DynidWarning, stacklevel=caller_level())
        else:
            _log.info("%s", left)
    if (hanging := found.hanging_line) is not None:
        _log.log(NOTE, "%s", hanging)
    if (merged := found.merged_line) is not None:
        _log.info("%s", merged)
    if angles.found and snap_angles and note_angles:
        _log.log(NOTE, "%s", snapped_message(source, angles.found))
    elif angles.found and not snap_angles:
        with warnings.catch_warnings():  # the inertials' warnings were given once
            warnings.simplefilter("ignore", DynidWarning)
            snapped = _read_chain(text, base_link, tip_link, source, AngleRounding(snap=True))[0]
        msg, harmful = rounding_message(source, angles.found, robot, snapped)
        if harmful:
            warnings.warn(msg, DynidWarning, stacklevel=caller_level())
        elif note_angles:
            _log.log(NOTE, "%s", msg)
    if (stand_in := placeholder_words(robot)) is not None:
        warnings.warn(
            f"{source}: {stand_in}; {PLACEHOLDER_READ}", DynidWarning, stacklevel=caller_level()
        )
    fr = robot.friction
    if isinstance(fr, Friction):
        held = [
            name
            for name, fv, fc in zip(robot.joint_names, fr.fv, fr.fc, strict=True)
            if fv != 0.0 or fc != 0.0
        ]
        _log.info(
            "%s: joint friction read from <dynamics> of joints %s (damping as viscous "
            "N m s/rad, friction as Coulomb N m)",
            source,
            ", ".join(held),
        )
    return robot


def _read_chain(
    text: str | bytes,
    base_link: str | None,
    tip_link: str | None,
    source: str,
    angles: AngleRounding,
) -> tuple[Robot, OffChain]:
    """The robot of the chain, its joint-origin angles through ``angles``, and what it
    leaves out or merges (:func:`~dynid.io.robot.urdf_branches.off_chain`)."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ModelError(f"{source} is not well-formed XML: {exc}") from exc
    name, links, parent_joint, child_joints = _parse_tree(root)
    base, tip = _chain_ends(source, links, parent_joint, child_joints, base_link, tip_link)
    path = _chain(base, tip, parent_joint)
    _check_chain(path, base, tip)
    w = _walk(path, base, angles)
    _place_fixed_links(w, path, child_joints)
    phi = _body_phi(w, links)

    moving_links = set(w.link_names)
    frames = {
        link: Frame(kl, T, w.fixed_joint.get(link))
        for link, (kl, T) in w.placed.items()
        if link not in moving_links
    }
    if "flange" not in w.placed:  # a URDF link 'flange' keeps its own pose (Pinocchio's)
        k_tip, T_tip = w.placed[tip]
        frames["flange"] = Frame(k_tip, T_tip)

    n = len(w.joint_names)
    lim = np.array(w.limits)
    on_chain = {j.name for j in path}
    found = off_chain(
        source,
        links,
        child_joints,
        on_chain,
        w.placed,
        w.link_names,
        w.fixed_joint,
        lambda joint, T: _subtree_phi(joint, T, links, child_joints),
    )
    for branch in found.lumped:  # past the tip (fingers): at their joints' zero
        phi[n - 1] += branch.phi
    robot = Robot(
        name=name,
        joint_names=tuple(w.joint_names),
        link_names=tuple(w.link_names),
        T_parent_joint=np.stack(w.T_fix),
        axes=np.stack(w.axes),
        prismatic=np.array(w.prismatic),
        phi=phi,
        q_min=lim[:, 0],
        q_max=lim[:, 1],
        dq_max=lim[:, 2],
        ddq_max=np.full(n, np.inf),
        tau_max=lim[:, 3],
        frames=frames,
        friction=_friction(w),
    )
    return robot, found


def load_urdf(
    path: str | Path,
    base_link: str | None = None,
    tip_link: str | None = None,
    *,
    snap_angles: bool = False,
    note_angles: bool = True,
) -> Robot:
    """Serial chain between ``base_link`` and ``tip_link`` of a URDF file.

    Parameters
    ----------
    path : str or Path
        URDF file. Mesh references are not read.
    base_link : str, optional
        Link whose frame is the base frame (link 0). Default: the root link.
    tip_link : str, optional
        Last link of the chain; its frame is ``flange`` (unless a URDF link is named
        ``flange``). Default: the unique leaf link
        below ``base_link``.
    snap_angles : bool
        Snap joint-origin angles rounded near multiples of pi/2 (:func:`robot_from_urdf_string`).
    note_angles : bool
        Name rounded angles in a note (:func:`robot_from_urdf_string`).

    Returns
    -------
    Robot
        See :func:`robot_from_urdf_string` and the module docstring.

    Raises
    ------
    ModelError
        The file does not exist or cannot be read, or its content cannot be modelled
        (see :func:`robot_from_urdf_string`).
    UnknownNameError
        ``base_link`` or ``tip_link`` is not a link of the URDF.

    Warns
    -----
    DynidWarning
        Physically inconsistent inertials (kept as given); non-positive velocity or effort
        limits (treated as unbounded); joint-origin angles rounded near multiples of pi/2.

    Examples
    --------
    >>> robot = load_urdf("panda.urdf", "panda_link0", "panda_hand")  # doctest: +SKIP
    >>> robot.joint_names[0]  # doctest: +SKIP
    'panda_joint1'
    """
    p = Path(path)
    try:
        data = file_bytes(p)
    except FileNotFoundError as exc:
        raise ModelError(f"URDF file not found: {str(p)!r}") from exc
    except OSError as exc:
        raise ModelError(f"cannot read URDF file {str(p)!r}: {exc.strerror or exc}") from exc
    return _robot_from_text(
        data, base_link, tip_link, f"URDF file {str(p)!r}", snap_angles, note_angles
    )
