"""What a URDF chain leaves out or merges, said once when the chain is read.

A chain (:mod:`dynid.io.robot.urdf_parse`) holds the links from its base to its tip.
Links hanging off a moving link of the chain through fixed joints only (a hand, a
tool-centre-point frame) are merged into that link: their inertials are added to it. A
link hanging off it through a moving joint (a gripper's jaw, fingers, the joints past the
tip) cannot be merged exactly, as it moves: it is left out with everything below it, and
its mass is in no link of the model. :func:`off_chain` names both, with their masses (the
reader warns about a branch with mass and logs a massless one; it notes the merged links
with mass that hang off the chain, a hand beyond the tip, and logs the others).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .urdf_tree import _child, _float, _Joint

__all__ = ["Branch", "OffChain", "off_chain"]


@dataclass(frozen=True, slots=True)
class Branch:
    """A link hanging off the chain through a moving joint, and what it carries.

    Attributes
    ----------
    joint, type, parent : str
        The moving joint, its URDF type and the chain's link it hangs from.
    links : tuple of str
        The joint's child link, then every link below it.
    mass : float
        Their masses summed [kg].
    """

    joint: str
    type: str
    parent: str
    links: tuple[str, ...]
    mass: float


@dataclass(frozen=True, slots=True)
class OffChain:
    """What the chain leaves out (``branches``) and merges (``merged``: fixed link, the
    moving link it is merged into, its mass [kg]; ``hanging``: the merged links off the
    chain, below its links rather than between them, as a hand beyond the tip);
    :attr:`left_out`, :attr:`merged_line` and :attr:`hanging_line` say it."""

    source: str
    branches: tuple[Branch, ...]
    merged: tuple[tuple[str, str, float], ...]
    hanging: tuple[str, ...] = ()

    @property
    def mass_left_out(self) -> float:
        """The mass [kg] of every branch left out."""
        return float(sum(b.mass for b in self.branches))

    @property
    def left_out(self) -> str | None:
        """One line naming the branches left out and their masses, or None."""
        if not self.branches:
            return None
        said = "; ".join(
            f"{b.links[0]}"
            + (f" and {len(b.links) - 1} link(s) below it" if len(b.links) > 1 else "")
            + f" ({b.mass:.4g} kg, through {b.type} joint {b.joint!r} on {b.parent})"
            for b in self.branches
        )
        return (
            f"{self.source}: left out of the chain, as they move on joints of their own: "
            f"{said}; their mass is in no link of the model (a fixed joint in place of "
            "the moving one merges a link into the one it hangs from)"
        )

    @property
    def merged_line(self) -> str | None:
        """One line naming the links fixed to the chain and merged, or None."""
        if not self.merged:
            return None
        said = ", ".join(f"{link} into {body} ({m:.4g} kg)" for link, body, m in self.merged)
        return f"{self.source}: links fixed to the chain merged (their inertials added): {said}"

    @property
    def hanging_line(self) -> str | None:
        """One line naming the links with mass that hang off the chain through fixed joints
        (a hand beyond the tip) and were merged into its bodies, with their masses; None
        when there are none."""
        said = [(x, body, m) for x, body, m in self.merged if x in self.hanging and m > 0]
        if not said:
            return None
        names = ", ".join(f"{link} ({m:.4g} kg) into {body}" for link, body, m in said)
        total = sum(m for _, _, m in said)
        return (
            f"{self.source}: links fixed to the chain beyond its own (past the tip or off its "
            f"side) merged into its bodies, their inertials added ({total:.4g} kg in all): "
            f"{names}; for an arm run without them, leave them out of the URDF"
        )


def _mass(el: ET.Element, link: str) -> float:
    """A link's mass [kg] (0 without ``<inertial>`` or ``<mass>``)."""
    inertial = _child(el, "inertial")
    mass = None if inertial is None else _child(inertial, "mass")
    value = None if mass is None else _float(mass, "value", f"link {link!r} <mass>")
    return 0.0 if value is None or not np.isfinite(value) else float(value)


def _below(link: str, child_joints: Mapping[str, Sequence[_Joint]]) -> list[str]:
    """``link`` and every link below it, depth first."""
    out, stack = [], [link]
    while stack:
        cur = stack.pop()
        out.append(cur)
        stack.extend(j.child for j in reversed(child_joints.get(cur, ())))
    return out


def off_chain(
    source: str,
    links: Mapping[str, ET.Element],
    child_joints: Mapping[str, Sequence[_Joint]],
    on_chain: set[str],
    placed: Mapping[str, tuple[int, NDArray[np.float64]]],
    link_names: Sequence[str],
    fixed_joint: Mapping[str, str],
) -> OffChain:
    """The links a chain leaves out and those it merges (module docstring).

    Parameters
    ----------
    source : str
        The URDF's name, for the lines.
    links, child_joints : mapping
        The URDF's link elements by name, and the joints below each link.
    on_chain : set of str
        The names of the chain's joints.
    placed : mapping
        Every link of the model: ``link -> (body k, pose)``, 0 the base.
    link_names : sequence of str
        The chain's bodies (base first).
    fixed_joint : mapping
        The links placed through a fixed joint, with its name.
    """
    branches = []
    for link, (k, _) in placed.items():
        if k == 0:  # fixed to the base: no joint torque feels it
            continue
        for joint in child_joints.get(link, ()):
            if joint.name in on_chain or joint.type == "fixed" or joint.child in placed:
                continue
            below = _below(joint.child, child_joints)
            mass = sum(_mass(links[x], x) for x in below)
            branches.append(Branch(joint.name, joint.type, link, tuple(below), mass))
    merged = tuple(
        (link, link_names[k], _mass(links[link], link))
        for link, (k, _) in placed.items()
        if k > 0 and link in fixed_joint
    )
    hanging = tuple(link for link, _, _ in merged if fixed_joint[link] not in on_chain)
    return OffChain(source, tuple(branches), merged, hanging)
