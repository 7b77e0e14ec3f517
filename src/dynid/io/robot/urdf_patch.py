"""Write a robot's link inertials back into the URDF it came from (a template).

:func:`patch_urdf_inertials` takes the original URDF text and replaces only the
``<inertial>`` elements of the chain's moving links between ``base`` and ``tip``; every
other byte is kept (names, meshes, other links, a gripper, ``<dynamics>``, comments,
formatting). The robot's link ``k`` must be the chain's moving link ``k``: the same
number of joints and the same joint frames and axes (checked to 1e-9 m/rad).

Merged fixed links. dynid lumps links fixed to moving link ``k`` (``panda_link8``, a
hand) into body ``k`` (:mod:`dynid.io.robot.urdf_parse`). Three ways to write body ``k`` back:

* ``merged="subtract"`` (default): the fixed links keep their inertials and the moving
  link gets the rest, ``phi_k - sum(phi_fixed)``. When that rest is not physically
  consistent (a positive mass, positive principal moments meeting the triangle
  inequality) nothing is written: a :class:`~dynid.exceptions.ModelError` names the link,
  the fixed links, both masses and the other two policies, each with the recording it
  fits (the arm recorded with them: ``move``; without them: ``keep``);
* ``merged="move"``: the moving link gets all of ``phi_k`` and the ``<inertial>`` of each
  fixed link merged into body ``k`` is removed;
* ``merged="keep"``: the fixed links keep their inertials and the moving link gets all of
  ``phi_k``: for a body identified without them (a Panda identified without its hand,
  exported into the vendor's URDF with the hand).

Links moving below the last body on joints of their own, past the tip (a gripper's
fingers), are lumped into the last body by the reader at their joints' zero position
(:mod:`dynid.io.robot.urdf_branches`), and a body identified from torques with them on the
arm holds them. They keep their ``<inertial>`` with every policy (a simulator drops a
moving link without one): with ``subtract`` and ``move`` the moving link gets the body
without them at rest, so that the file counts them once and its total mass is the
identified one, and a note names them; with ``keep`` (a body identified without the hand)
the moving link gets the whole body. Branches off earlier bodies (another arm on a torso)
move on their own and stay.

With ``subtract`` and ``move`` the template read back between the same ``base`` and ``tip``
gives exactly the robot's ``phi``; with ``keep``, the robot's ``phi`` plus the fixed links'
(checked before returning). A fixed link of negative mass merged into a body is refused
(the template is wrong). Links fixed to the base, and links reached through joints off
the chain from the base, are left as they are.

Inertials are written as ``<origin xyz="c" rpy="0 0 0"/>`` (CoM in the link frame [m]),
``<mass>`` [kg] and ``<inertia>`` about the CoM in link axes [kg m^2].

Joint friction (:func:`patch_urdf_dynamics`): a URDF's ``<dynamics damping friction>`` of
the chain's joints is read back as the robot's friction (as Pinocchio reads it), so the
export replaces a template's (a vendor's damping, say) by the identified viscous and
Coulomb coefficients, or removes them when the model has no friction (the element, or
its two attributes set to 0 when it holds others); every other byte is kept.
"""

from __future__ import annotations

import html
import logging
import re
import warnings
import xml.etree.ElementTree as ET

import numpy as np
from numpy.typing import NDArray

from ... import _checks, spatial
from ..._checks import caller_level
from ...exceptions import DynidWarning, ModelError
from ...model.inertia import inertia6_from_matrix, inertial_from_phi, phi_from_inertial
from ...model.robot import Robot
from ...progress import NOTE
from .urdf_branches import Branch
from .urdf_parse import chain_with_branches, robot_from_urdf_string

__all__ = ["MERGED_POLICIES", "patch_urdf_dynamics", "patch_urdf_inertials"]

MERGED_POLICIES = ("subtract", "move", "keep")

_LINK = re.compile(r"<link\b[^>]*?\bname\s*=\s*([\"'])(.*?)\1[^>]*?(/?)>", re.S)
_INERTIAL = re.compile(r"<inertial\b[^>]*?/>|<inertial\b.*?</inertial>", re.S)
_COMMENT = re.compile(r"<!--.*?-->", re.S)
_JOINT = re.compile(r"<joint\b[^>]*?\bname\s*=\s*([\"'])(.*?)\1[^>]*?(/?)>", re.S)
_DYNAMICS = re.compile(r"<dynamics\b[^>]*?/>|<dynamics\b[^>]*?>.*?</dynamics>", re.S)
_FRICTION_ATTR = re.compile(r"\s+(damping|friction)\s*=\s*([\"']).*?\2", re.S)
_log = logging.getLogger(__name__)
_ATTRS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def _f(x: float) -> str:
    x = float(x)
    return "0" if x == 0.0 else repr(x)


def _v(v: NDArray[np.float64]) -> str:
    return " ".join(_f(x) for x in v)


def _own_phi(elem: ET.Element) -> NDArray[np.float64]:
    """Standard parameters (10,) of a link's own ``<inertial>`` in the link frame (0 if none)."""
    inertial = elem.find("inertial")
    if inertial is None:
        return np.zeros(10)
    o = inertial.find("origin")
    get = (lambda a: None) if o is None else o.get
    xyz = [float(x) for x in (get("xyz") or "0 0 0").split()]
    rpy = [float(x) for x in (get("rpy") or "0 0 0").split()]
    R = spatial.matrix_from_rpy(rpy)
    m_el = inertial.find("mass")
    m = float(m_el.get("value", "0")) if m_el is not None else 0.0
    i_el = inertial.find("inertia")
    I6 = [float(i_el.get(a, "0")) if i_el is not None else 0.0 for a in _ATTRS]
    xx, xy, xz, yy, yz, zz = I6
    I = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    return phi_from_inertial(m, np.asarray(xyz, dtype=float), R @ I @ R.T)


def _inertial_xml(phi: NDArray[np.float64], indent: str, step: str) -> str:
    m, c, I = inertial_from_phi(phi)
    i6 = inertia6_from_matrix(I)
    inner = indent + step
    attrs = " ".join(f'{a}="{_f(x)}"' for a, x in zip(_ATTRS, i6, strict=True))
    return (
        f'<inertial>\n{inner}<origin xyz="{_v(c)}" rpy="0 0 0"/>\n'
        f'{inner}<mass value="{_f(float(m))}"/>\n{inner}<inertia {attrs}/>\n{indent}</inertial>'
    )


def _line_indent(text: str, pos: int) -> str:
    start = text.rfind("\n", 0, pos) + 1
    lead = text[start:pos]
    return lead if lead.strip() == "" else ""


def _link_spans(text: str, names: list[str]) -> dict[str, tuple[int, int, int, bool]]:
    """Link name -> (start, end of opening tag, end of element, self-closing), comments masked;
    ``names``: the parser's, in document order (entities of the DTD resolved too)."""
    masked = _COMMENT.sub(lambda m: " " * len(m.group(0)), text)
    spans = {}
    found = list(_LINK.finditer(masked))
    if len(found) != len(names):
        names = [html.unescape(m.group(2)) for m in found]  # &amp; -> &
    for m, name in zip(found, names, strict=True):
        if m.group(3) == "/":
            spans[name] = (m.start(), m.end(), m.end(), True)
        else:
            end = masked.find("</link>", m.end())
            if end < 0:
                raise ModelError(f"link {_checks.short(name)} has no closing </link>")
            spans[name] = (m.start(), m.end(), end, False)
    return spans


def _check_same_chain(robot: Robot, chain: Robot, source: str) -> None:
    if robot.n != chain.n:
        raise ModelError(
            f"the chain has {chain.n} moving joints, the robot {robot.n}; "
            "choose base=.../tip=... so that the chains match",
            file=source,
        )
    for i in range(robot.n):
        same = np.allclose(robot.T_parent_joint[i], chain.T_parent_joint[i], atol=1e-9) and (
            np.allclose(robot.axes[i], chain.axes[i], atol=1e-9)
            and bool(robot.prismatic[i]) == bool(chain.prismatic[i])
        )
        if not same:
            raise ModelError(
                f"joint {chain.joint_names[i]!r} has another frame, axis or type "
                f"than the robot's joint {robot.joint_names[i]!r}; the inertials would be in "
                "different link frames",
                file=source,
            )


def patch_urdf_inertials(
    template: str,
    robot: Robot,
    *,
    base: str | None = None,
    tip: str | None = None,
    merged: str = "subtract",
    source: str = "URDF template",
) -> str:
    """The template URDF with the chain's link inertials replaced by the robot's.

    Parameters
    ----------
    template : str
        The original URDF text.
    robot : Robot
        The robot whose ``phi`` (n, 10) is written; its chain must match the template's.
    base, tip : str, optional
        Chain of the template (defaults as in :func:`dynid.io.robot.urdf.load_urdf`).
    merged : {"subtract", "move", "keep"}
        How body ``k`` is split over the moving link and the fixed links merged into it
        (module docstring).
    source : str
        Name of the template in messages.

    Returns
    -------
    str
        The patched URDF text.

    Raises
    ------
    ModelError
        Malformed template, chains that do not match, an unknown ``merged`` policy, a
        fixed link of negative mass merged into a body; ``merged="subtract"`` would
        leave a moving link with an inertial that is not physically consistent (the
        message names the link, its fixed links and the other policies).
    UnknownNameError
        ``base`` or ``tip`` is not a link of the template.
    """
    if merged not in MERGED_POLICIES:
        raise ModelError(f"merged must be one of {MERGED_POLICIES}; got {merged!r}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)  # the template's own inertials
        chain, off = chain_with_branches(template, base, tip, source=source)
    _check_same_chain(robot, chain, source)
    root = ET.fromstring(template)
    elems = {el.get("name"): el for el in root if el.tag.rsplit("}", 1)[-1] == "link"}
    spans = _link_spans(template, [el.get("name", "") for el in root.iter("link")])
    new_xml, expected = _bodies(robot, chain, off.branches, elems, merged, source)
    edits: list[tuple[int, int, str]] = []
    for link, new in new_xml.items():
        start, open_end, end, closed = spans[link]
        body = template[open_end:end]
        masked = _COMMENT.sub(lambda m: " " * len(m.group(0)), body)
        found = _INERTIAL.search(masked)
        if new is None:
            if found is not None:
                a, b = open_end + found.start(), open_end + found.end()
                line_start = template.rfind("\n", 0, a)
                if _line_indent(template, a) and line_start >= 0:
                    a = line_start
                edits.append((a, b, ""))
            continue
        link_indent = _line_indent(template, start)
        if found is not None:
            a = open_end + found.start()
            indent = _line_indent(template, a) or link_indent + "  "
            step = _indent_step(indent, link_indent)
            edits.append((a, open_end + found.end(), _inertial_xml(new, indent, step)))
        elif closed:
            indent = link_indent + "  "
            tag = template[start:open_end]
            opening = tag[:-2].rstrip() + ">"
            xml = _inertial_xml(new, indent, "  ")
            edits.append((start, open_end, f"{opening}\n{indent}{xml}\n{link_indent}</link>"))
        else:
            indent = link_indent + "  "
            xml = _inertial_xml(new, indent, "  ")
            edits.append((open_end, open_end, f"\n{indent}{xml}"))
    out = template
    for a, b, s in sorted(edits, reverse=True):
        out = out[:a] + s + out[b:]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        back = robot_from_urdf_string(out, base, tip, source=source, note_angles=False)
    scale = max(float(np.max(np.abs(expected))), 1e-300)
    if not np.allclose(back.phi, expected, rtol=1e-9, atol=1e-12 * scale):
        raise ModelError("the patched inertials do not read back as the robot's", file=source)
    if merged != "keep" and (said := _branches_line(off.branches, chain, source, new_xml)):
        if any(x in new_xml and new_xml[x] is None for b in off.lumped for x in b.links):
            warnings.warn(said, DynidWarning, stacklevel=caller_level())
        else:
            _log.log(NOTE, "%s", said)
    return out


def _bodies(
    robot: Robot,
    chain: Robot,
    branches: tuple[Branch, ...],
    elems: dict,
    merged: str,
    source: str,
) -> tuple[dict[str, NDArray[np.float64] | None], NDArray[np.float64]]:
    """The inertials to write (link -> phi (10,), None: remove) and the ``phi`` (n, 10) the
    patched template's chain must read back as (as a reader reads it: the branches past the
    tip lumped at rest, the others left out).

    ``subtract`` and ``move`` take the identified body ``k`` to hold everything that moved
    with it on the arm: the fixed links merged into it and, for the last body, the
    branches hanging off it past the tip (fingers), which keep their inertials while the
    moving link gets the body without them at their joints' zero (as the reader lumps
    them), so that the file counts them once; ``keep`` holds neither. A branch off an
    earlier body (another arm on a torso) moves on its own while the chain is recorded
    and stays."""
    new_xml: dict[str, NDArray[np.float64] | None] = {}
    expected = np.array(robot.phi, dtype=float)
    moving = set(chain.link_names[1:])
    for k in range(1, robot.n + 1):
        link = chain.link_names[k]
        own = _own_phi(elems[link])
        fixed = [
            name
            for name, fr in chain.frames.items()
            if fr.link == k and name in elems and name not in moving
            and elems[name].find("inertial") is not None
        ]  # fmt: skip
        _check_masses(fixed, elems, source)
        phi: NDArray[np.float64] = np.array(robot.phi[k - 1])
        lumped = [b for b in branches if k == robot.n == b.body and b.lumpable]
        carried = [x for b in lumped for x in b.links if elems[x].find("inertial") is not None]
        held = np.sum([b.phi for b in lumped], axis=0) if lumped else np.zeros(10)
        if merged == "subtract":  # chain.phi holds the fixed links and the lumped branches
            phi = robot.phi[k - 1] - (chain.phi[k - 1] - own)
            if carried and not _is_body(phi) and _is_body(phi + held):
                phi = phi + held  # the body holds less than the fingers' own inertia
                new_xml.update(dict.fromkeys(carried))
            _check_consistent(link, phi, fixed + carried, robot.phi[k - 1], source)
        elif merged == "move":
            new_xml.update(dict.fromkeys(fixed))
            if carried and _is_body(robot.phi[k - 1] - held):  # they stay, counted once
                phi = robot.phi[k - 1] - held
            else:
                new_xml.update(dict.fromkeys(carried))
        else:  # keep: the fixed links stay, the body goes on the moving link
            expected[k - 1] += chain.phi[k - 1] - own
        new_xml[link] = phi
    return new_xml, expected


def _branches_line(
    branches: tuple[Branch, ...],
    chain: Robot,
    source: str,
    new_xml: dict[str, NDArray[np.float64] | None],
) -> str | None:
    """The line naming the branches past the tip the identified last body held, and what
    was done with them: kept, the moving link written without them; or, when the body
    holds less than their own inertia, their inertials removed; None when there are none
    with mass."""
    held = [b for b in branches if b.mass > 0 and b.body == chain.n and b.lumpable]
    if not held:
        return None
    names = ", ".join(
        f"{b.links[0]} ({b.mass:.4g} kg, inertia up to {b.inertia:.4g} kg m^2, joint {b.joint!r})"
        for b in held
    )
    total = sum(b.mass for b in held)
    last = _checks.short(chain.link_names[-1])
    if any(x in new_xml and new_xml[x] is None for b in held for x in b.links):
        return (
            f"{source}: links moving on joints of their own past the tip written without "
            f"their inertials ({total:.4g} kg in all: {names}): the identified {last} holds "
            "them, but less inertia than the template gives them alone, so it cannot be "
            "split into them and the rest; the whole body is on the moving link, and a "
            "simulator that drops a moving link without <inertial> (Gazebo) drops them: "
            "give them an inertial of their size in the template, or --merged keep keeps "
            "them as they are (counted twice)"
        )
    return (
        f"{source}: links moving on joints of their own past the tip keep their inertials "
        f"({total:.4g} kg in all: {names}) and the identified {last} is written without "
        "them at their joints' zero: the identified body holds them, as they were on the "
        "arm when it was recorded, so the file counts them once and its total mass is the "
        "identified one; for a body identified without them, --merged keep writes the "
        "whole body"
    )


def _indent_step(indent: str, link_indent: str) -> str:
    step = indent[len(link_indent) :] if indent.startswith(link_indent) else ""
    return step or "  "


def _is_body(phi: NDArray[np.float64]) -> bool:
    """A positive mass whose principal moments about its CoM are >= 0 and meet the
    triangle inequality."""
    m, _, I = inertial_from_phi(phi)
    lam = np.linalg.eigvalsh(I)
    return bool(m > 0 and lam[0] >= 0 and lam[0] + lam[1] >= lam[2])


def _check_consistent(
    link: str,
    phi: NDArray[np.float64],
    fixed: list[str],
    identified: NDArray[np.float64],
    source: str,
) -> None:
    """Raise when the rest of body ``link`` after subtracting its ``fixed`` links is not a
    body; the message gives both masses and the remedy for each way the arm was recorded."""
    if _is_body(phi):
        return
    m, _, I = inertial_from_phi(phi)
    lam = np.linalg.eigvalsh(I)
    them = float(identified[0] - m)
    hint = (
        f"the identified body is {float(identified[0]):.6g} kg, they are {them:.6g} kg; if "
        "the arm was recorded with them on it (the identified body holds them), export with "
        "--merged move (the whole identified body on the moving link, the fixed links' "
        "inertials removed); if it was recorded without them, with --merged keep (the "
        "template's links stay as they are, the identified body goes on the moving link)"
    )
    raise ModelError(
        f"link {_checks.short(link)}: the identified body minus the template's "
        f"links merged into it {_checks.short(fixed)} is not physically consistent (mass "
        f"{float(m):.6g} kg, principal moments {[float(f'{x:.4g}') for x in lam]} kg m^2), "
        f"so --merged subtract cannot split it: {hint}",
        file=source,
    )


def _check_masses(fixed: list[str], elems: dict, source: str) -> None:
    """Refuse a fixed link of the template whose own mass is negative."""
    for name in fixed:
        m = float(_own_phi(elems[name])[0])
        if m < 0:
            raise ModelError(
                f"link {_checks.short(name)} has a negative mass ({m:.6g} kg); "
                "correct its <inertial> in the template",
                file=source,
            )


def patch_urdf_dynamics(
    template: str,
    joints: list[str],
    dynamics: tuple[NDArray[np.float64], NDArray[np.float64]] | None,
) -> str:
    """The template with the ``<dynamics>`` friction of ``joints`` replaced.

    Parameters
    ----------
    template : str
        URDF text.
    joints : list of str
        The chain's moving joints, in order.
    dynamics : (ndarray, ndarray) or None
        Per joint ``damping`` [N m s/rad or N s/m] and Coulomb ``friction`` [N m or N]:
        written as those attributes of each joint's ``<dynamics>`` (added, after the
        joint's last child, when it has none), each value where it stands; None: the
        element is removed, or, when it holds other attributes (Gazebo's), its two set to
        0 (urdfdom refuses a ``<dynamics>`` without either). Other attributes stay.

    Raises
    ------
    ModelError
        A joint of ``joints`` is not in the template, or has no closing ``</joint>``.
    """
    masked = _COMMENT.sub(lambda m: " " * len(m.group(0)), template)
    spans = {  # a robot's joints have a type; a <transmission>'s <joint> has none
        html.unescape(m.group(2)): m
        for m in _JOINT.finditer(masked)
        if re.search(r"\btype\s*=", m.group(0))
    }
    edits: list[tuple[int, int, str]] = []
    for i, name in enumerate(joints):
        m = spans.get(name)
        if m is None or m.group(3) == "/":
            raise ModelError(f"joint {_checks.short(name)} of the chain has no <joint> element")
        end = masked.find("</joint>", m.end())
        if end < 0:
            raise ModelError(f"joint {_checks.short(name)} has no closing </joint>")
        found = _DYNAMICS.search(masked, m.end(), end)
        if dynamics is None:
            if found is not None:
                edits.append(_removed(template, found.start(), found.end()))
            continue
        attrs = f'damping="{_f(dynamics[0][i])}" friction="{_f(dynamics[1][i])}"'
        if found is None:
            inner = re.search(r"\n([ \t]*)<", template[m.end() : end])
            child = inner.group(1) if inner else _line_indent(template, m.start()) + "  "
            line = template.rfind("\n", m.end(), end)
            if line >= 0 and not template[line + 1 : end].strip():  # </joint> on its line
                edits.append((line, line, f"\n{child}<dynamics {attrs}/>"))
            else:
                edits.append((end, end, f"<dynamics {attrs}/>"))
            continue
        edits.append(_set_friction(template, found.start(), dynamics[0][i], dynamics[1][i]))
    out = template
    for a, b, text in sorted(edits, reverse=True):
        out = out[:a] + text + out[b:]
    return out


def _set_friction(template: str, a: int, damping: float, friction: float) -> tuple[int, int, str]:
    """The edit giving the ``<dynamics>`` tag at ``a`` these ``damping`` and ``friction``:
    each value replaced where it stands, a missing attribute added after the others."""
    tag_end = template.index(">", a)
    closed = template[tag_end - 1] == "/"
    head = template[a : tag_end - (1 if closed else 0)]
    for name, value in (("damping", damping), ("friction", friction)):
        attr = re.compile(rf"(\s{name}\s*=\s*)([\"'])(.*?)\2", re.S)
        found = attr.search(head)
        if found is not None:
            q = found.group(2)
            head = f"{head[: found.start()]}{found.group(1)}{q}{_f(value)}{q}{head[found.end() :]}"
        else:
            head = head.rstrip() + f' {name}="{_f(value)}"'
    return a, tag_end + 1, head + ("/>" if closed else ">")


def _removed(template: str, a: int, b: int) -> tuple[int, int, str]:
    """The edit removing the friction of the ``<dynamics>`` at ``[a, b)``: the element (and
    its line) when it holds nothing else, else its ``damping`` and ``friction`` set to 0
    (urdfdom refuses a ``<dynamics>`` without either)."""
    tag_end = template.index(">", a)
    closed = template[tag_end - 1] == "/"
    head = template[a + len("<dynamics") : tag_end - (1 if closed else 0)]
    rest = _FRICTION_ATTR.sub("", head).rstrip()
    body = "" if closed else template[tag_end + 1 : b - len("</dynamics>")]
    if rest.strip() or body.strip():
        return _set_friction(template, a, 0.0, 0.0)
    line_start = template.rfind("\n", 0, a)
    if _line_indent(template, a) and line_start >= 0:
        a = line_start
    return a, b, ""
