"""URDF robot descriptions: read a serial chain, write a robot, patch a template.

Reading (:func:`load_urdf`, :func:`robot_from_urdf_string`): the serial chain between a
base and a tip link, fixed joints merged (:mod:`dynid.io.robot.urdf_parse` states the
conventions). Writing (:func:`save_urdf`, :func:`urdf_from_robot`; a robot with retrieved
feasible parameters, say, for simulators) gives one ``<link>`` per link of the robot and one
``<joint>`` per joint, keeping the robot's link and joint names:

* link ``i`` (1..n) carries an ``<inertial>``: ``<origin xyz="c_i" rpy="0 0 0"/>`` (the
  CoM in the link frame [m]), ``<mass value="m_i"/>`` [kg] and ``<inertia ixx ixy ixz iyy
  iyz izz/>`` [kg m^2], the tensor **about the CoM** in link axes (URDF's convention:
  the entries of the matrix, products of inertia included with their sign). The base
  link (link 0) has no inertial (it does not enter a fixed-base model).
* joint ``i``: ``<origin xyz rpy>`` = ``T_parent_joint[i]`` (URDF roll-pitch-yaw
  ``Rz(yaw) Ry(pitch) Rx(roll)``, :func:`dynid.spatial.rpy_from_matrix`),
  ``<axis xyz>`` in the child link, ``revolute`` (``continuous`` when it has no position
  limits) or ``prismatic``, ``<limit lower upper effort velocity>``. URDF (urdfdom)
  requires finite ``effort`` and ``velocity`` and a prismatic joint's ``lower``/``upper``:
  a missing (infinite) limit is written as the largest float, ``1.7976931348623157e+308``.
* the ``flange`` frame (the tip) keeps the source robot's name for it: when the robot
  was read from a URDF whose tip link is fixed to the last moving link (``panda_link8``),
  that link is written as a ``fixed`` joint ``<tip>_joint`` (``<tip>_joint_2`` when a joint of
  the robot has that name) to a massless link ``<tip>``;
  when the tip is the last moving link itself nothing is added; otherwise (an MDH robot)
  a massless link ``flange`` is added. The file's only leaf is the tip, so
  :func:`load_urdf` needs no ``tip_link``. With ``all_frames=True`` every other
  named frame is written the same way (then load with ``tip_link=`` the tip's name).
* with ``template=`` the original URDF is written back with only the chain's
  ``<inertial>`` elements replaced (:func:`dynid.io.robot.urdf_patch.patch_urdf_inertials`)
  and, by the export (:func:`export_urdf`), the friction of their ``<dynamics>``
  (:func:`dynid.io.robot.urdf_patch.patch_urdf_dynamics`): read back, a vendor's damping
  would be the robot's friction.

Gravity is not part of URDF; a friction model (``dynamics=``, :func:`export_urdf`) is
written as ``<dynamics damping friction>`` per joint, the description's sigmoid is not;
reading takes it back as the robot's classical friction (:mod:`dynid.io.robot.urdf_parse`).
Numbers use Python's
shortest round-trip representation, so the parameters read back exactly.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import NDArray

from ... import __version__, spatial
from ..._checks import caller_level
from ...dynamics.terms import mass_matrix
from ...exceptions import DynidWarning, ModelError, ShapeError
from ...friction.model import Friction, FrictionSum, robot_friction, sigmoid_parameters
from ...friction.mujoco import drive_joint_terms, joint_coulomb_viscous, unheld_friction
from ...model.drive import Drive
from ...model.inertia import inertia6_from_matrix
from ...model.robot import Frame, Robot
from ..atomic import write_text
from ..input_files import file_text
from .export_options import (
    ExportOptions,
    friction_losses,
    kept_elsewhere,
    with_caveat,
    xml_comment,
)
from .urdf_parse import load_urdf, robot_from_urdf_string
from .urdf_patch import patch_urdf_dynamics, patch_urdf_inertials

__all__ = [
    "export_urdf",
    "load_urdf",
    "robot_from_urdf_string",
    "save_urdf",
    "tip_name",
    "urdf_from_robot",
]

_BIG = sys.float_info.max


def _f(x: float) -> str:
    x = float(x)
    if x == 0.0:
        return "0"
    return repr(x)


def _v(v: np.ndarray) -> str:
    return " ".join(_f(x) for x in v)


def _fixed(name: str, parent: str, f: Frame, joints: set[str]) -> list[str]:
    """A fixed joint from ``parent`` to a massless link ``name`` at the frame ``f``: named
    as in the robot's source (``f.joint``), else ``<name>_joint`` (``<name>_joint_2``, ...
    when ``joints`` holds that name; added to ``joints``)."""
    T = f.T_link_frame
    rpy = spatial.rpy_from_matrix(T[:3, :3])
    joint, k = f.joint or name + "_joint", 1
    while joint in joints:
        k += 1
        joint = f"{name}_joint_{k}"
    joints.add(joint)
    return [
        f'  <joint name={quoteattr(joint)} type="fixed">',
        f"    <parent link={quoteattr(parent)}/>",
        f"    <child link={quoteattr(name)}/>",
        f'    <origin xyz="{_v(T[:3, 3])}" rpy="{_v(rpy)}"/>',
        "  </joint>",
        f"  <link name={quoteattr(name)}/>",
    ]


def tip_name(robot: Robot) -> str | None:
    """Name of the source link at the ``flange`` frame, None when it is a moving link.

    The first named frame (in the robot's order) at the flange's pose: a URDF tip link
    fixed to the last moving link (``panda_link8``) precedes ``flange``, while frames added
    later (``with_tool`` at the flange) follow it. ``"flange"`` when no source name precedes.
    """
    f = robot.frame("flange")
    if f.link == robot.n and np.array_equal(f.T_link_frame, np.eye(4)):
        return None
    for name, g in robot.frames.items():
        if name in robot.link_names:
            continue
        if name == "flange":
            return "flange"
        if g.link == f.link and np.allclose(g.T_link_frame, f.T_link_frame, atol=1e-12):
            return name
    return "flange"


def urdf_from_robot(
    robot: Robot,
    *,
    all_frames: bool = False,
    comment: str | None = None,
    dynamics: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
) -> str:
    """The URDF document of a robot: kinematics, limits and link inertials.

    Parameters
    ----------
    robot : Robot
    all_frames : bool
        Also write every named frame other than the links and ``flange`` as a fixed,
        massless link (see the module docstring).
    comment : str, optional
        Text of an XML comment at the top (default: the writer and the conventions).
    dynamics : (ndarray, ndarray), optional
        Per-joint ``damping`` [N m s/rad] and Coulomb ``friction`` [N m], written as
        ``<dynamics damping friction>`` (identified linear friction).

    Returns
    -------
    str
        The URDF XML text.
    """
    n = robot.n
    I6 = inertia6_from_matrix(robot.inertia)
    mass, com = robot.mass, robot.com
    text = comment or (
        f"written by dynid {__version__}: inertials about the CoM in link axes [kg, m, kg m^2]"
        + (
            "; joint friction as <dynamics damping friction>"
            if dynamics is not None
            else "; gravity and friction are not part of URDF"
        )
    )
    lines = [
        '<?xml version="1.0"?>',
        xml_comment(text),
        f"<robot name={quoteattr(robot.name)}>",
    ]
    lines.append(f"  <link name={quoteattr(robot.link_names[0])}/>")
    for i in range(n):
        T = robot.T_parent_joint[i]
        rpy = spatial.rpy_from_matrix(T[:3, :3])
        lo, hi = robot.q_min[i], robot.q_max[i]
        if robot.prismatic[i]:
            jtype = "prismatic"
        elif np.isfinite(lo) and np.isfinite(hi):
            jtype = "revolute"
        else:
            jtype = "continuous"
        eff = robot.tau_max[i] if np.isfinite(robot.tau_max[i]) else _BIG
        vel = robot.dq_max[i] if np.isfinite(robot.dq_max[i]) else _BIG
        limit = f'effort="{_f(eff)}" velocity="{_f(vel)}"'
        if jtype != "continuous":
            lo_s = lo if np.isfinite(lo) else -_BIG
            hi_s = hi if np.isfinite(hi) else _BIG
            limit = f'lower="{_f(lo_s)}" upper="{_f(hi_s)}" ' + limit
        child = robot.link_names[i + 1]
        lines += [
            f'  <joint name={quoteattr(robot.joint_names[i])} type="{jtype}">',
            f"    <parent link={quoteattr(robot.link_names[i])}/>",
            f"    <child link={quoteattr(child)}/>",
            f'    <origin xyz="{_v(T[:3, 3])}" rpy="{_v(rpy)}"/>',
            f'    <axis xyz="{_v(robot.axes[i])}"/>',
            f"    <limit {limit}/>",
            *(
                [f'    <dynamics damping="{_f(dynamics[0][i])}" friction="{_f(dynamics[1][i])}"/>']
                if dynamics is not None
                else []
            ),
            "  </joint>",
            f"  <link name={quoteattr(child)}>",
            "    <inertial>",
            f'      <origin xyz="{_v(com[i])}" rpy="0 0 0"/>',
            f'      <mass value="{_f(mass[i])}"/>',
            '      <inertia ixx="{}" ixy="{}" ixz="{}" iyy="{}" iyz="{}" izz="{}"/>'.format(
                *(_f(x) for x in I6[i])
            ),
            "    </inertial>",
            "  </link>",
        ]
    names = set(robot.link_names)
    tip = tip_name(robot)
    frames = [] if tip is None else [(tip, robot.frames.get(tip, robot.frame("flange")))]
    if all_frames:
        frames += [
            (k, f) for k, f in robot.frames.items() if k not in names and k not in ("flange", tip)
        ]
    joints = set(robot.joint_names)
    for name, f in frames:
        lines += _fixed(name, robot.link_names[f.link], f, joints)
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def save_urdf(
    path: str | Path,
    robot: Robot,
    *,
    all_frames: bool = False,
    template: str | Path | None = None,
    base: str | None = None,
    tip: str | None = None,
    merged: str = "subtract",
    dynamics: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    template_dynamics: bool = False,
    caveat: str | None = None,
) -> Path:
    """Write the robot as URDF to ``path``; returns the path.

    Parameters
    ----------
    path : str or Path
    robot : Robot
    all_frames : bool
        Chain export only: also write every named frame (:func:`urdf_from_robot`).
    template : str or Path, optional
        The original URDF file: written back with only the chain's ``<inertial>``
        elements replaced (:func:`dynid.io.robot.urdf_patch.patch_urdf_inertials`, with
        ``base``, ``tip`` and ``merged``).
    dynamics : (ndarray, ndarray), optional
        Per-joint damping and Coulomb friction (:func:`urdf_from_robot`); with a template
        written only with ``template_dynamics``.
    template_dynamics : bool
        Template: also replace the friction of the chain's ``<dynamics>`` by ``dynamics``
        (None: removed; :func:`dynid.io.robot.urdf_patch.patch_urdf_dynamics`); default:
        the template's ``<dynamics>`` are kept.
    caveat : str, optional
        A comment at the top of the file (after the XML declaration): why the fit was not
        accepted.

    Raises
    ------
    ModelError
        The template cannot be read, its chain does not match the robot's, or (``merged``
        ``"subtract"``) a moving link minus the template's fixed links is not a physically
        consistent body; nothing is written then.
    """
    path = Path(path)
    if template is None:
        text = urdf_from_robot(robot, all_frames=all_frames, dynamics=dynamics)
    else:
        tpath = Path(template)
        try:
            original = file_text(tpath)
        except OSError as exc:
            raise ModelError(f"cannot read URDF template {str(tpath)!r}: {exc}") from exc
        text = patch_urdf_inertials(
            original,
            robot,
            base=base,
            tip=tip,
            merged=merged,
            source=f"URDF template {tpath.name!r}",
        )
        if template_dynamics:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", DynidWarning)  # the template's own
                chain = robot_from_urdf_string(  # read for its joint names alone
                    original, base, tip, source=f"URDF template {tpath.name!r}", note_angles=False
                )
            text = patch_urdf_dynamics(text, list(chain.joint_names), dynamics)
        friction = None if not template_dynamics else dynamics is not None
        text = with_caveat(text, _template_header(robot, tpath.name, friction), xml=True)
    write_text(path, with_caveat(text, caveat, xml=True))
    return path


def _template_header(robot: Robot, template: str, friction: bool | None) -> str:
    """The comment a template export opens with: what dynid wrote into the template
    (``friction``: True the identified joint friction written, False the template's
    removed, None the template's kept) and what the file leaves out."""
    said = {
        True: "the joints' friction as <dynamics damping friction> (identified)",
        False: "the joints' <dynamics> friction removed (the model has none)",
        None: "the joints' <dynamics> as the template has them",
    }[friction]
    return (
        f"written by dynid {__version__} into the template {template}: the <inertial> of "
        f"the chain's {robot.n} moving links ({robot.link_names[1]} to "
        f"{robot.link_names[-1]}) identified, about the CoM in link axes [kg, m, kg m^2]; "
        f"{said}; every other element as the template has it; gravity, rotor inertia and "
        "friction offsets are not part of URDF"
    )


#: An armature below this fraction of its joint's inertia (the diagonal ``M_jj`` of the
#: arm's mass matrix at the middle of the joint ranges) is negligible: leaving it out
#: changes that joint's inertial torque by less than 0.1 %, far below a torque sensor's
#: noise, and the URDF export does not warn of it (:func:`armature_shares`).
NEGLIGIBLE_ARMATURE = 1e-3


def armature_shares(robot: Robot, armature: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each joint's ``armature`` (n,) [kg m^2] over the diagonal ``M_jj`` (n,) of the
    robot's mass matrix at the middle of its joint ranges (0 for an unlimited joint): the
    share of the joint's inertia a URDF without it leaves out (``inf`` where ``M_jj`` is 0,
    a robot without link inertias)."""
    lo, hi = np.asarray(robot.q_min), np.asarray(robot.q_max)
    limited = np.isfinite(lo) & np.isfinite(hi)  # an unlimited joint's middle: 0
    mid = 0.5 * (np.where(limited, lo, 0.0) + np.where(limited, hi, 0.0))
    diag = np.diagonal(mass_matrix(robot, mid)) if np.any(robot.phi) else np.zeros(robot.n)
    a = np.asarray(armature, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(a == 0, 0.0, a / np.abs(diag))


def _rotor_warning(
    drive: Drive | None, robot: Robot, path: Path, options: ExportOptions
) -> str | None:
    """What URDF cannot hold of a drive, as a warning of its own: its rotor inertias (the
    armature per joint, ``diag(K^T diag(I_a) K)`` [kg m^2]) by joint with their share of
    the joint's inertia, and the exports that hold them (MJCF ``armature``, the TOML
    ``[drive]`` table: the files written beside it, or how to write them); None without
    any, or when every one is below :data:`NEGLIGIBLE_ARMATURE` of its joint's inertia. A
    drive without gears (``K = 1``: an armature identified without a drive) is spoken of
    as the armature."""
    if drive is None or drive.rotor_inertia is None or not np.any(drive.rotor_inertia != 0):
        return None
    arm = drive_joint_terms(drive.transmission, drive.rotor_inertia, None, None).armature
    share = armature_shares(robot, arm)
    if not np.any(share >= NEGLIGIBLE_ARMATURE):
        return None
    values = ", ".join(
        f"{name} {a:.4g} ({_share(s)} of the joint's inertia)"
        for name, a, s in zip(robot.joint_names, arm, share, strict=True)
        if a != 0
    )
    geared = not np.array_equal(np.asarray(drive.transmission), np.eye(drive.n))
    what = (
        "the drive's rotor inertias"
        if geared
        else "the armature (rotor inertia at the joints, without gears)"
    )
    holders = (("mjcf", "as armature"), ("toml", "as its [drive] table"))
    return (
        f"URDF export: {path.name} leaves out {what}, which URDF has no element for "
        f"(armature per joint [kg m^2]: {values}, the inertia M_jj + armature at the middle "
        "of the joint ranges); " + kept_elsewhere(options, path, "them", holders)
    )


def _share(x: float) -> str:
    """The armature's share of its joint's inertia with it, from ``x`` (armature over
    ``M_jj``): ``12 %``, at most ``100 %`` (a joint without link inertia); a wrist's rotor
    14 times its links' inertia reads 93 %, not 1.4e+03 %, and one 250 times 99.6 %, not
    1e+02 %."""
    if not np.isfinite(x):
        return "100 %"
    share = 100.0 * x / (1.0 + x)
    return f"{share:.2g} %" if share < 99.0 else f"{share:.3g} %"


def export_urdf(path: str | Path, robot: Robot, options: ExportOptions) -> Path:
    """:func:`save_urdf` with the export options (the entry of ``urdf`` in the exports).

    A friction model (``options.friction``, any law of the registry, at the joints or
    reflected from the motors of a drive) is written as ``<dynamics damping friction>``,
    what its law maps to viscous and dry friction
    (:func:`dynid.friction.mujoco.joint_coulomb_viscous`), into the chain export or the
    template's joints (a template's own ``<dynamics>`` friction replaced, or removed when
    nothing is written). What URDF cannot hold of the model's friction (a smooth law's
    rounding, a standstill band, the offsets, an asymmetry, a Stribeck peak, a quadratic
    term, friction at the motors, a coupled drive's off-diagonal terms;
    :func:`dynid.friction.mujoco.unheld_friction`) is named in one warning line, and the
    rotor inertias of a drive, by joint, in a second, each with the files that hold them;
    a joint spring (``robot.spring``), which URDF does not hold, in a third and in a
    comment at the top of the file.
    ``friction=True`` writes the robot's own friction when it is a law other than the
    description's sigmoid at the joints (which URDF does not hold); the drive is not part
    of URDF.

    Raises
    ------
    ModelError
        As :func:`save_urdf` (a template that cannot be read or does not match).
    ShapeError
        A friction model of another number of joints.
    """
    dynamics = None
    model = None if isinstance(options.friction, bool) else options.friction
    if options.friction is True and sigmoid_parameters(robot.friction) is None:
        model = robot_friction(robot)  # the description's sigmoid: none
    notes: tuple[str, ...] = ()
    if model is not None:
        if model.n != robot.n:
            raise ShapeError(f"friction has {model.n} joints; robot {robot.name!r} has {robot.n}")
        vmax = np.where(np.isfinite(robot.dq_max), robot.dq_max, 2.0)
        jt = joint_coulomb_viscous(model, vmax)
        dynamics = (jt.damping, jt.frictionloss)
        lost = jt.notes + unheld_friction(model, vmax)
        if lost:
            exact = () if isinstance(model, FrictionSum) else (("toml", "exactly"),)
            holds = kept_elsewhere(options, path, "it", exact, source="exactly")
            written, left = friction_losses(model.kind, lost)
            notes = (
                f"{Path(path).name} holds the {model.kind} friction as <dynamics damping "
                f"friction>, viscous and sharp Coulomb friction at the joints"
                + (f", written {written}" if written else "")
                + (f", without {left}" if left else "")
                + (f"; {holds}" if holds else ""),
            )
    replace = False
    if options.template is not None:
        held = _template_friction(options)
        replace = not _holds(held, dynamics)
        if replace and dynamics is None and held is not None:
            notes += (_removed_note(held, robot),)
    drive = options.drive if options.drive is not None else getattr(model, "drive", None)
    spring = _spring_note(robot, Path(path), options)
    caveat = "; ".join(c for c in (options.caveat, spring) if c is not None) or None
    spring = None if spring is None else f"URDF export: {spring}"
    out = save_urdf(
        path,
        robot,
        all_frames=options.all_frames,
        template=options.template,
        base=options.base,
        tip=options.tip,
        merged=options.merged,
        dynamics=dynamics,
        template_dynamics=replace,
        caveat=caveat,
    )
    if notes:  # one line, once written: what URDF cannot hold of the friction
        warnings.warn(f"URDF export: {'; '.join(notes)}", DynidWarning, stacklevel=caller_level())
    rotors = _rotor_warning(drive, robot, Path(path), options)
    if rotors is not None:  # a line of its own: it costs far more than the friction's
        warnings.warn(rotors, DynidWarning, stacklevel=caller_level())
    if spring is not None:  # said in the file too (a comment at its top)
        warnings.warn(spring, DynidWarning, stacklevel=caller_level())
    return out


def _spring_note(robot: Robot, path: Path, options: ExportOptions) -> str | None:
    """What the URDF export says of the robot's joint spring, which URDF has no element
    for: the stiffnesses left out and the exports that hold them (MJCF ``stiffness`` and
    ``springref``, the TOML ``[spring]`` table); None without a spring."""
    if robot.spring is None:
        return None
    values = ", ".join(
        f"{name} {k:.4g}"
        for name, k in zip(robot.joint_names, robot.spring.k, strict=True)
        if k != 0
    )
    holders = (("mjcf", "as stiffness and springref"), ("toml", "as its [spring] table"))
    return (
        f"{path.name} leaves out the joint spring (tau_s = k (q - q0)), which "
        f"URDF has no element for (k [N m/rad]: {values or 'all zero'}); "
        + kept_elsewhere(options, path, "it", holders, source="exactly")
    )


def _template_friction(options: ExportOptions) -> Robot | None:
    """The template's chain (its ``<dynamics>`` read as its friction), None when it
    cannot be read (:func:`save_urdf` names what is wrong with it)."""
    assert options.template is not None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DynidWarning)
            return load_urdf(options.template, options.base, options.tip, note_angles=False)
    except ModelError:
        return None


def _holds(
    chain: Robot | None, dynamics: tuple[NDArray[np.float64], NDArray[np.float64]] | None
) -> bool:
    """Whether the template's chain already holds ``dynamics`` (damping, friction; None:
    no friction) in its ``<dynamics>`` (a robot read from that template, say): then its
    bytes are kept."""
    held = None if chain is None else chain.friction
    if held is None:
        return dynamics is None or (not np.any(dynamics[0]) and not np.any(dynamics[1]))
    if dynamics is None or not isinstance(held, Friction):
        return False
    P = np.asarray(held.as_array())
    return bool(
        P.shape == (len(dynamics[0]), 3)
        and np.array_equal(P[:, 0], dynamics[0])
        and np.array_equal(P[:, 1], dynamics[1])
    )


def _removed_note(chain: Robot, robot: Robot) -> str:
    """The line saying which joints' ``<dynamics>`` friction the template loses."""
    held = chain.friction
    P = np.asarray(held.as_array()) if isinstance(held, Friction) else np.ones((chain.n, 2))
    names = [chain.joint_names[j] for j in range(chain.n) if np.any(P[j, :2] != 0)]
    return (
        f"the template's <dynamics> friction of joint(s) {', '.join(names)} is removed "
        f"(damping and friction 0 where the element holds other attributes): the model of "
        f"{robot.name!r} written has no friction URDF holds, and read back it would be the "
        "robot's friction"
    )
