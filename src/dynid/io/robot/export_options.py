"""The seam of the robot exports: the options every writer receives and one format's entry.

A format is one module of :mod:`dynid.io.robot` with a writer
``export_X(path, robot, options) -> Path`` that takes what it can hold from
:class:`ExportOptions` and ignores the rest, and one :class:`RobotFormat` line in
:data:`dynid.io.export.ROBOT_FORMATS`; ``dynid export --format``, the suffix dispatch of
:func:`dynid.io.export.save_robot` and the robot files of an output folder
(:func:`dynid.io.export.save_robot_files`) all read that table.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ...friction.model import Friction, FrictionSum
from ...model.drive import Drive
from ...model.robot import Robot
from ...simulation.trajectories import Trajectory

__all__ = [
    "Along",
    "ExportOptions",
    "RobotFormat",
    "friction_losses",
    "kept_elsewhere",
    "with_caveat",
    "xml_comment",
]


@dataclass(frozen=True, slots=True)
class Along:
    """A motion an MJCF export measures ``mj_inverse``'s friction along, against the law's.

    Attributes
    ----------
    name : str
        How the warning names it (the file's name).
    trajectory : Trajectory
        Its times [s], velocities [rad/s] and accelerations [rad/s^2] (the positions are
        not used: MuJoCo's friction rows are each joint's own velocity's).
    """

    name: str
    trajectory: Trajectory


@dataclass(frozen=True, slots=True)
class ExportOptions:
    """What a robot export may write beside the robot; each format takes what it can hold.

    Attributes
    ----------
    template : Path or None
        URDF: the original URDF, written back with only the chain's inertials replaced.
    base, tip : str or None
        URDF template: the chain's base and tip links.
    merged : {"subtract", "move"}
        URDF template: how a body is split over its moving and fixed links.
    friction : bool, Friction or FrictionSum
        True: the robot's own friction where the format holds it; a friction model of any
        law (at the joints, or at the motors of a drive); False: none.
    all_frames : bool
        URDF chain: every named frame as a fixed, massless link.
    drive : Drive or None
        A drive train: MJCF ``armature`` from its rotor inertias, a TOML ``[drive]`` table.
    beside : mapping of str to str
        The files of other formats written beside this one by the same run, by format
        name (an output folder's ``{"mjcf": "robot.xml", "toml": "robot.toml"}``); a
        warning names them as holding what this format cannot, and says how to write the
        others (:func:`kept_elsewhere`).
    source : str or None
        The name of the file that holds the exported friction exactly (the
        ``feasible.json`` or robot TOML it was read from, or written beside), for the
        same warnings; None: no such file.
    caveat : str or None
        A line every format writes at the top of the file, as a comment: why the fit
        whose parameters it holds was not accepted (:func:`with_caveat`).
    frictionloss : bool
        MJCF: write the dry friction as ``frictionloss`` (MuJoCo's constraint); False:
        left out, the viscous friction only.
    along : Along or None
        MJCF: the motion the warning measures ``mj_inverse``'s friction along; None: a
        sine of each joint (:func:`~dynid.friction.mujoco_soft.representative_motion`).
    """

    template: Path | None = None
    base: str | None = None
    tip: str | None = None
    merged: str = "subtract"
    friction: bool | Friction | FrictionSum = True
    all_frames: bool = False
    drive: Drive | None = None
    beside: Mapping[str, str] = field(default_factory=dict)
    source: str | None = None
    caveat: str | None = None
    frictionloss: bool = True
    along: Along | None = None


@dataclass(frozen=True, slots=True)
class RobotFormat:
    """One robot file format the exports can write.

    Attributes
    ----------
    name : str
        The name ``--format`` takes (``"urdf"``).
    suffixes : tuple of str
        File suffixes that select it, lower case with the dot; the first names the file
        in an output folder (``robot.urdf``).
    save : callable
        ``save(path, robot, options) -> Path``: writes the file atomically.
    template : bool
        Whether the format takes ``ExportOptions.template`` (others refuse one).
    """

    name: str
    suffixes: tuple[str, ...]
    save: Callable[[str | Path, Robot, ExportOptions], Path]
    template: bool = False


#: How a warning names a format's export, and the suffix of the file that writes it.
_EXPORT_NAMES = {"urdf": ("URDF", ".urdf"), "mjcf": ("MJCF", ".xml"), "toml": ("TOML", ".toml")}


def kept_elsewhere(
    options: ExportOptions,
    path: str | Path,
    what: str,
    holders: Sequence[tuple[str, str]],
    source: str = "",
) -> str:
    """Where what the file ``path`` cannot hold is kept, for its warning: only files that
    are written, and how to write the others.

    Parameters
    ----------
    options : ExportOptions
        Its ``beside`` (formats written by the same run) and ``source``.
    path : str or Path
        The file written.
    what : str
        The pronoun of what is kept (``"it"``, ``"them"``).
    holders : sequence of (str, str)
        The formats that hold it, and how (``("mjcf", "as armature")``).
    source : str
        How ``options.source`` holds it (``"exactly"``); empty: ``options.source`` is not
        named. When named, a format of its own suffix is not offered.

    Returns
    -------
    str
        ``the MJCF export (robot.xml) holds them as armature, the TOML export (robot.toml)
        as its [drive] table``; a format not written as ``a TOML export (r.toml, not
        written) would hold it exactly`` (each one so), after those written with ``, and``:
        the file's name, not how it is asked for (``path`` of
        :func:`~dynid.io.export.save_robot`, ``--out`` of a command).
    """
    stem = Path(path).stem
    named = source and options.source is not None
    own = Path(options.source).suffix.lower() if named and options.source else None
    held = [
        (f"the {_EXPORT_NAMES[f][0]} export ({options.beside[f]})", how)
        for f, how in holders
        if f in options.beside
    ]
    if named:
        held.append((str(options.source), source))
    groups: dict[str, list[str]] = {}  # how -> the files that hold it so, in order
    for name, how in held:
        groups.setdefault(how, []).append(name)
    verb = ["holds" if len(names) == 1 else "hold" for names in groups.values()]
    said = [
        " and ".join(names) + (f" {verb[0]} {what}" if k == 0 else "") + f" {how}"
        for k, (how, names) in enumerate(groups.items())
    ]
    parts = [", ".join(said)] if said else []
    unwritten = [
        (f, how)
        for f, how in holders
        if f not in options.beside and _EXPORT_NAMES[f][1] != own  # the source's own format
    ]
    others = [
        f"{_article(_EXPORT_NAMES[f][0])} export ({stem}{_EXPORT_NAMES[f][1]}, not written)"
        + (f" would hold {what} {how}" if k == 0 else f" {how}")
        for k, (f, how) in enumerate(unwritten)
    ]
    if others:
        parts.append(", ".join(others))
    return ", and ".join(parts)


#: The statement a friction note makes of a part a per-joint file has no element for.
_NO_TERM = " has no per-joint term"


#: A coupled drive's note of terms dropped (:func:`~dynid.friction.mujoco.drive_joint_terms`).
_COUPLED = re.compile(
    r"(.+): the coupling's off-diagonal terms have no per-joint term and are dropped \((.+)\)"
)


def friction_losses(kind: str, lost: Sequence[str]) -> tuple[str, str]:
    """How a per-joint file (URDF ``<dynamics>``, MJCF ``damping`` and ``frictionloss``)
    writes a friction law of kind ``kind`` and what it leaves out, from the notes ``lost``
    (:func:`~dynid.friction.mujoco.joint_coulomb_viscous`,
    :func:`~dynid.friction.mujoco.unheld_friction`), for one sentence: the notes' own
    ``"<kind> friction: "`` is left off (the sentence names the law), ``"X has no per-joint
    term"`` reads ``"X (no per-joint term)"``.

    Returns
    -------
    (str, str)
        ``written``: how the viscous and Coulomb coefficients were written (``"as the
        nonnegative viscous and Coulomb friction closest to the law ..."``), empty when
        they are the law's own; ``left``: what is left out, ``"A, B and C"`` (empty for
        nothing).
    """
    written, left = "", []
    for note in lost:
        text = note
        head = f"{kind} friction"
        if text.startswith(head) and ": " in text:
            said, _, text = text[len(head) :].partition(": ")
            text = text + (f" {said.strip()}" if said.strip() else "")
        if text.startswith("written "):
            written = text.removeprefix("written ")
            continue
        if text.endswith(_NO_TERM):
            text = text.removesuffix(_NO_TERM) + " (no per-joint term)"
        if coupled := _COUPLED.fullmatch(text):  # "without" the coupling, not the friction
            text = f"the coupling's off-diagonal terms of the {coupled[1]} ({coupled[2]})"
        left.append(text)
    joined = ", ".join(left[:-1]) + " and " + left[-1] if len(left) > 1 else "".join(left)
    return written, joined


def _article(name: str) -> str:
    """``an MJCF``, ``a TOML``, ``a URDF``: the article as the letters are spoken."""
    return f"{'an' if name[0] in 'AEFHILMNORSX' else 'a'} {name}"


def with_caveat(text: str, caveat: str | None, *, xml: bool) -> str:
    """A robot file's ``text`` with ``caveat`` as a comment at its top (after an XML
    declaration); ``text`` itself when ``caveat`` is None."""
    if caveat is None:
        return text
    flat = " ".join(caveat.split())
    if not xml:
        return f"# {flat}\n{text}"
    line = xml_comment(flat) + "\n"
    if text.startswith("<?xml"):
        head, _, rest = text.partition("\n")
        return f"{head}\n{line}{rest}"
    return line + text


#: A command-line flag in a comment's text (``--out``, ``--prior-weight``).
_FLAG = re.compile(r"(?<![\w-])--([A-Za-z][\w-]*)")


def xml_comment(text: str) -> str:
    """``<!-- text -->`` on one line, valid XML: a comment holds no ``--`` and does not
    end in ``-``. A command-line flag reads as the option it is (``--out r.xml`` as
    ``option out r.xml``), any other run of hyphens as one dash between spaces."""
    flat = _FLAG.sub(r"option \1", " ".join(text.split()))
    flat = re.sub(r"\s*-{2,}\s*", " - ", flat)
    return f"<!-- {flat} -->"
