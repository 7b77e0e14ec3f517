"""The link/joint tree of a URDF document and the readers of its elements.

``_parse_tree`` indexes the ``<link>`` and ``<joint>`` elements of a ``<robot>`` (names
unique, every joint with a type and known parent and child links, each link the child of at
most one joint); ``_chain`` walks from a tip link up to a base link; the element readers
(``_child``, ``_floats``, ``_float``, ``_origin``) refuse malformed numbers and
repeated elements with a :class:`~dynid.exceptions.ModelError` naming the element. The chain
read on top of them is in :mod:`dynid.io.robot.urdf_parse`.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ... import _checks, spatial
from ...exceptions import ModelError
from .urdf_angles import AngleRounding


@dataclass(frozen=True, slots=True)
class _Joint:
    """One ``<joint>`` element: its name, type, parent and child link, and the element."""

    name: str
    type: str
    parent: str
    child: str
    elem: ET.Element


def _tag(elem: ET.Element) -> str:
    """Element tag without an XML namespace."""
    return elem.tag.rsplit("}", 1)[-1]


def _children(elem: ET.Element, tag: str) -> list[ET.Element]:
    return [c for c in elem if _tag(c) == tag]


def _child(elem: ET.Element, tag: str) -> ET.Element | None:
    """The one ``<tag>`` child of ``elem`` or None; two are refused (a reader would take
    the first and drop the other's numbers silently: a second ``<mass>``)."""
    found = _children(elem, tag)
    if len(found) > 1:
        name = elem.get("name")
        owner = f"<{_tag(elem)}{'' if name is None else f' name={name!r}'}>"
        raise ModelError(f"{owner} holds {len(found)} <{tag}> elements; URDF allows one")
    return found[0] if found else None


def _floats(
    text: str | None, count: int, what: str, default: tuple[float, ...]
) -> NDArray[np.float64]:
    """Parse ``count`` whitespace-separated floats; ``default`` when the attribute is absent."""
    if text is None:
        return np.array(default, dtype=np.float64)
    parts = text.split()
    try:
        values = np.array([_checks.decimal(x) for x in parts], dtype=np.float64)
    except ValueError:
        raise ModelError(f"{what} must hold {count} numbers; got {_checks.short(text)}") from None
    if values.shape != (count,):
        raise ModelError(
            f"{what} must hold {count} numbers; got {len(parts)} in {_checks.short(text)}"
        )
    if not np.all(np.isfinite(values)):
        raise ModelError(f"{what} must be finite; got {_checks.short(text)}")
    return values


def _float(elem: ET.Element, attr: str, what: str) -> float | None:
    """A float attribute, or None when absent."""
    text = elem.get(attr)
    if text is None:
        return None
    try:
        value = _checks.decimal(text)
    except ValueError:
        raise ModelError(
            f"{what} attribute {attr!r} must be a number; got {_checks.short(text)}"
        ) from None
    if np.isnan(value):
        raise ModelError(f"{what} attribute {attr!r} is NaN")
    return value


def _origin(
    elem: ET.Element, what: str, angles: AngleRounding | None = None, joint: str = ""
) -> NDArray[np.float64]:
    """Pose given by the ``<origin xyz rpy>`` child of ``elem`` (identity when absent), (4, 4);
    a joint's ``rpy`` goes through ``angles`` (rounded angles recorded, snapped if asked)."""
    o = _child(elem, "origin")
    if o is None:
        return np.eye(4)
    xyz = _floats(o.get("xyz"), 3, f"{what} origin xyz", (0.0, 0.0, 0.0))
    rpy = _floats(o.get("rpy"), 3, f"{what} origin rpy", (0.0, 0.0, 0.0))
    if angles is not None:
        rpy = angles.rpy(joint, rpy)
    return spatial.transform_from_xyz_rpy(xyz, rpy)


def _parse_tree(
    root: ET.Element,
) -> tuple[str, dict[str, ET.Element], dict[str, _Joint], dict[str, list[_Joint]]]:
    """Robot name, links by name, the joint whose child is each link, child joints per link."""
    if _tag(root) != "robot":
        raise ModelError(f"the root element of a URDF must be <robot>; got <{_tag(root)}>")
    links: dict[str, ET.Element] = {}
    for el in _children(root, "link"):
        name = el.get("name")
        if not name:
            raise ModelError("a <link> has no name attribute")
        if name in links:
            raise ModelError(f"duplicate link name {name!r}")
        links[name] = el
    if not links:
        raise ModelError("the URDF holds no <link>")
    parent_joint: dict[str, _Joint] = {}
    child_joints: dict[str, list[_Joint]] = {name: [] for name in links}
    joint_names: set[str] = set()
    for el in _children(root, "joint"):
        name = el.get("name")
        if not name:
            raise ModelError("a <joint> has no name attribute")
        if name in joint_names:
            raise ModelError(f"duplicate joint name {name!r}")
        joint_names.add(name)
        jtype = el.get("type")
        if not jtype:
            raise ModelError(f"joint {name!r} has no type attribute")
        ends = []
        for tag in ("parent", "child"):
            sub = _child(el, tag)
            link = None if sub is None else sub.get("link")
            if not link:
                raise ModelError(f"joint {name!r} has no <{tag} link=...>")
            if link not in links:
                raise ModelError(f"joint {name!r} refers to unknown {tag} link {link!r}")
            ends.append(link)
        joint = _Joint(name, jtype, ends[0], ends[1], el)
        if joint.child in parent_joint:
            raise ModelError(
                f"link {joint.child!r} is the child of two joints "
                f"({parent_joint[joint.child].name!r} and {name!r}); a URDF must be a tree"
            )
        parent_joint[joint.child] = joint
        child_joints[joint.parent].append(joint)
    return root.get("name") or "robot", links, parent_joint, child_joints


def _subtree_leaves(base: str, child_joints: dict[str, list[_Joint]]) -> list[str]:
    """Links below ``base`` (``base`` included) that have no child joint, in document order."""
    leaves, stack, seen = [], [base], set()
    while stack:
        link = stack.pop()
        if link in seen:
            raise ModelError(f"the joints below link {base!r} form a cycle through {link!r}")
        seen.add(link)
        kids = child_joints[link]
        if not kids:
            leaves.append(link)
        stack.extend(j.child for j in reversed(kids))
    return leaves


def _chain(base: str, tip: str, parent_joint: dict[str, _Joint]) -> list[_Joint]:
    """Joints from ``base`` down to ``tip``, in order."""
    path: list[_Joint] = []
    link, seen = tip, {tip}
    while link != base:
        joint = parent_joint.get(link)
        if joint is None:
            raise ModelError(f"tip link {tip!r} is not below base link {base!r}")
        path.append(joint)
        link = joint.parent
        if link in seen:
            raise ModelError(f"the joints above link {tip!r} form a cycle through {link!r}")
        seen.add(link)
    return path[::-1]
