"""What a URDF chain leaves out or merges, said once when the chain is read.

A chain (:mod:`dynid.io.robot.urdf_parse`) holds the links from its base to its tip.
Links hanging off a moving link of the chain through fixed joints only (a hand, a
tool-centre-point frame) are merged into that link: their inertials are added to it. A
link hanging off the last body through a moving joint past the tip (a gripper's fingers,
the joints past a tip chosen mid-arm) moves with that body wherever its own joints stand:
it is lumped into the last body with everything below it at their joints' zero position
(a gripper at rest, as Pinocchio's model with those joints locked at their neutral
position), the best description there is of what the arm carries. A branch off an earlier
body (another arm on a torso) moves on its own while the chain is recorded: it is left
out with everything below it, and its mass is in no link of the model. :func:`off_chain`
names them all, with their masses and inertias (the reader notes the branches lumped,
warns about a branch left out with mass and logs a massless one; it notes the merged
links with mass that hang off the chain, a hand beyond the tip, and logs the others).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ...model.inertia import inertial_from_phi
from .urdf_tree import _child, _float, _Joint

_RIGID_AT_ZERO = {"revolute", "continuous", "prismatic", "fixed"}

__all__ = ["Branch", "OffChain", "off_chain"]


@dataclass(frozen=True, slots=True, eq=False)
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
    body : int
        The chain's body (1 the first moving link) the branch hangs off.
    phi : ndarray, shape (10,)
        Their standard parameters summed in body ``body``'s frame [SI], every joint of the
        branch at zero (zeros when the branch holds a joint that has no zero position, a
        floating or planar one).
    lumpable : bool
        Every joint of the branch is revolute, continuous, prismatic or fixed: the branch
        has a rigid pose at its joints' zero.
    joints : tuple of str
        The branch's moving joints: ``joint``, then those below it.
    prismatic : tuple of bool
        Which of ``joints`` are prismatic (their positions in m, the others' in rad).
    tip : str or None
        The link a chain through the branch ends at, which keeps ``joints`` as joints of
        the model: the branch's one leaf, reached through joints a serial chain holds
        (none mimicking another); None when there is no such one link.
    """

    joint: str
    type: str
    parent: str
    links: tuple[str, ...]
    mass: float
    body: int = 0
    phi: NDArray[np.float64] = field(default_factory=lambda: np.zeros(10))
    lumpable: bool = False
    joints: tuple[str, ...] = ()
    prismatic: tuple[bool, ...] = ()
    tip: str | None = None

    @property
    def inertia(self) -> float:
        """The largest principal moment [kg m^2] of the branch's inertia about its own
        centre of mass, its joints at zero (0 when massless)."""
        if not self.phi[0] > 0.0:
            return 0.0
        _, _, I = inertial_from_phi(self.phi)
        return float(np.max(np.linalg.eigvalsh(I)))

    def said(self) -> str:
        """The branch in a few words: its links, mass, inertia and joint."""
        below = f" and {len(self.links) - 1} link(s) below it" if len(self.links) > 1 else ""
        return (
            f"{self.links[0]}{below} ({self.mass:.4g} kg, inertia up to {self.inertia:.4g} "
            f"kg m^2 about its CoM, through {self.type} joint {self.joint!r} on {self.parent})"
        )


@dataclass(frozen=True, slots=True)
class OffChain:
    """What the chain lumps, leaves out (``branches``: every branch off a moving body through
    a moving joint; those off the last body, ``last``, with a zero pose are lumped into it)
    and merges (``merged``: fixed link, the moving link it is merged into, its mass [kg];
    ``hanging``: the merged links off the chain, below its links rather than between them,
    as a hand beyond the tip); :attr:`lumped_line`, :attr:`left_out`, :attr:`merged_line`
    and :attr:`hanging_line` say it."""

    source: str
    branches: tuple[Branch, ...]
    merged: tuple[tuple[str, str, float], ...]
    hanging: tuple[str, ...] = ()
    last: int = -1

    @property
    def lumped(self) -> tuple[Branch, ...]:
        """The branches past the tip lumped into the last body at their joints' zero."""
        return tuple(b for b in self.branches if b.body == self.last and b.lumpable)

    @property
    def outside(self) -> tuple[Branch, ...]:
        """The branches left out of the model."""
        return tuple(b for b in self.branches if not (b.body == self.last and b.lumpable))

    @property
    def mass_left_out(self) -> float:
        """The mass [kg] of every branch left out."""
        return float(sum(b.mass for b in self.outside))

    @property
    def left_out(self) -> str | None:
        """One line naming the branches left out, their masses and inertias, or None."""
        if not self.outside:
            return None
        said = "; ".join(b.said() for b in self.outside)
        return (
            f"{self.source}: left out of the chain, as they move on joints of their own: "
            f"{said}; their mass and inertia are in no link of the model (a fixed joint in "
            "place of the moving one merges a link into the one it hangs from)"
        )

    @property
    def lumped_line(self) -> str | None:
        """One line naming the branches past the tip lumped into the last body, or None."""
        said = [b for b in self.lumped if b.mass != 0.0]
        if not said:
            return None
        total = sum(b.mass for b in said)
        keeps = [
            f"tip_link={b.tip!r} keeps {', '.join(b.joints)} as joint(s) of the model"
            for b in said
            if b.tip is not None
        ]
        return (
            f"{self.source}: links moving on joints of their own past the tip lumped into "
            f"the last body at their joints' zero position ({total:.4g} kg in all): "
            + "; ".join(b.said() for b in said)
            + "; they ride on the arm at whatever opening they have, held at rest in the "
            "model: the best description there is when their joints are not recorded"
            + (f" (where a recording holds them moving: {'; '.join(keeps)})" if keeps else "")
            + "; for an arm run without them, leave them out of the URDF"
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


def _moving(
    joint: _Joint, below: Sequence[str], child_joints: Mapping[str, Sequence[_Joint]]
) -> tuple[tuple[str, ...], tuple[bool, ...], str | None]:
    """The moving joints of the branch through ``joint`` (its links ``below``), which of
    them are prismatic, and the tip that keeps them (:class:`Branch`)."""
    every = [joint, *(j for x in below for j in child_joints.get(x, ()))]
    moving = [j for j in every if j.type != "fixed"]
    leaves = [x for x in below if not child_joints.get(x)]
    chain_holds = all(
        j.type in _RIGID_AT_ZERO and (j.type == "fixed" or _child(j.elem, "mimic") is None)
        for j in every
    )
    tip = leaves[0] if len(leaves) == 1 and chain_holds else None
    return tuple(j.name for j in moving), tuple(j.type == "prismatic" for j in moving), tip


def off_chain(
    source: str,
    links: Mapping[str, ET.Element],
    child_joints: Mapping[str, Sequence[_Joint]],
    on_chain: set[str],
    placed: Mapping[str, tuple[int, NDArray[np.float64]]],
    link_names: Sequence[str],
    fixed_joint: Mapping[str, str],
    branch_phi: Callable[[_Joint, NDArray[np.float64]], NDArray[np.float64]] | None = None,
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
    branch_phi : callable, optional
        ``(joint, T_k_parent) -> phi`` (10,): the standard parameters of the joint's child
        link and everything below it in body ``k``'s frame, every joint at zero, given the
        pose (4, 4) [m] of the joint's parent link in body ``k``; None: zeros.
    """
    branches = []
    for link, (k, T_k_link) in placed.items():
        if k == 0:  # fixed to the base: no joint torque feels it
            continue
        for joint in child_joints.get(link, ()):
            if joint.name in on_chain or joint.type == "fixed" or joint.child in placed:
                continue
            below = _below(joint.child, child_joints)
            mass = sum(_mass(links[x], x) for x in below)
            types = {joint.type} | {j.type for x in below for j in child_joints.get(x, ())}
            lumpable = types <= _RIGID_AT_ZERO
            phi = np.zeros(10)
            if lumpable and branch_phi is not None:
                phi = branch_phi(joint, T_k_link)
            branches.append(
                Branch(
                    joint.name,
                    joint.type,
                    link,
                    tuple(below),
                    mass,
                    k,
                    phi,
                    lumpable,
                    *_moving(joint, below, child_joints),
                )
            )
    merged = tuple(
        (link, link_names[k], _mass(links[link], link))
        for link, (k, _) in placed.items()
        if k > 0 and link in fixed_joint
    )
    hanging = tuple(link for link, _, _ in merged if fixed_joint[link] not in on_chain)
    return OffChain(source, tuple(branches), merged, hanging, len(link_names) - 1)
