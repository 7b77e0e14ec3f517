"""When a payload estimate is not a load to trust.

* a mass less than :data:`MIN_MASS_SIGMAS` standard deviations above zero: the data
  cannot tell the load from none (unloaded data, or a load too light for them); its CoM
  is then the first moment ``m c`` divided by a mass near zero, and its inertia noise;
* a CoM farther from the frame than the arm is long (:func:`arm_length`): no load the arm
  carries reaches past its own base;
* measured torques of another scale than the arm description's
  (:func:`~dynid.feasibility.payload_scale.scale_doubts`): the load carries the factor;
* an identified arm whose identification recorded its gravity torques one factor off the
  description's (:func:`model_scale_doubts`: torque constants given at the motors, a gear
  ratio off): the efforts are read through the same drive, and the load carries the factor.

Such an estimate is not handed to a controller (``payload.json`` leaves libfranka's
``setLoad`` values out).

The inertia is judged element by element (:func:`undetermined_inertia`): a moment less
than :data:`MIN_INERTIA_SIGMAS` standard deviations above zero, or a product of inertia
whose standard deviation exceeds a :data:`MIN_INERTIA_SIGMAS`-th of the largest magnitude
a rigid body allows it (half the third moment: ``|Ixy| <= Izz / 2``), is not determined
by the data (a load that barely rotates). An inertia the pseudo-inertia LMI moved onto
the consistency bound is not determined as a whole: the least squares gave no body's
inertia, and the bound, not the data, sets the result. :func:`inertia_doubts` says which
and what to record; the mass and CoM are still handed on, the inertia is not.

A fit of torque logs that leaves more than :data:`~dynid.identification.verdict.FLOOR_FAIR` times
its noise floor, the torque noise after the low-pass and the states' noise through the arm's model
(:mod:`~dynid.feasibility.payload_floor`; :func:`misfit_doubts`, the rule the residual's verdict and
the torques' scale apply) is the arm's model missing torques, which go into the mass and CoM as well
as the inertia, by more than the residual's covariance says: the whole load is in doubt, no setLoad
values are written, and its standard deviations are raised to the largest change an unmodelled
torque as large as the misfit can make (:func:`~dynid.feasibility.payload_fit.misfit_covariance`).
With recordings of the same motion without the load, the residual judged is the loaded fit's less
the unloaded arm's at matched states (:mod:`~dynid.feasibility.payload_difference`): an arm's misfit
common to both does not doubt the load, what the load leaves unexplained does.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..identification.verdict import FLOOR_FAIR
from ..kinematics.forward import link_poses
from ..model.inertia import INERTIA_ORDER, inertia6_from_matrix
from ..model.robot import Robot
from .payload_difference import JudgedResidual

__all__ = [
    "MIN_INERTIA_SIGMAS",
    "MIN_MASS_SIGMAS",
    "arm_length",
    "doubts_about",
    "inertia_doubts",
    "misfit_doubts",
    "misfit_above",
    "misfit_ratio",
    "undetermined_inertia",
]

#: A load's mass must lie this many standard deviations above zero to be told from none.
MIN_MASS_SIGMAS = 3.0
#: A moment of inertia must lie this many standard deviations above zero, and a product's
#: standard deviation stay below this part of its largest possible magnitude.
MIN_INERTIA_SIGMAS = 3.0
#: The moment that bounds each product of inertia, ``|I_ab| <= I_cc / 2`` (indices into
#: ``xx xy xz yy yz zz``); a moment is judged against itself.
_BOUND = {"xx": 0, "xy": 5, "xz": 3, "yy": 3, "yz": 0, "zz": 5}


def model_scale_doubts(recorded: tuple[float, str] | None, mass: float) -> tuple[str, ...]:
    """The doubt of a load weighed through an identified arm whose identification recorded
    its gravity torques ``recorded[0]`` times the robot description's on every loaded
    joint (:func:`~dynid.identification.gravity_scale.recorded_scale`; ``recorded[1]`` its
    finding), with the load's ``mass`` [kg]: the logs are read through the same drive, so
    the load's torques carry the factor as the arm's masses do (a UR5 read through its
    motors' torque constants, 101 times too small at the joints: 0.0121 kg for 1.2 kg).
    Empty without a record."""
    if recorded is None:
        return ()
    factor = recorded[0]
    return (
        f"the arm's model records that its gravity torques are {factor:.3g} times the robot "
        "description's on every joint gravity loads (identify's warning: the drive file's "
        f"torque_constant or gear_ratio looks off by that factor; multiply it by "
        f"{1 / factor:.3g}): the load's torques are read through the same drive and carry "
        f"the factor: {mass:.4g} kg here, {mass / factor:.4g} kg at the description's scale; "
        "no setLoad values written; hint: correct the drive file as the model's note says, "
        "identify again and weigh the load with that model",
    )


def arm_length(robot: Robot) -> float:
    """The arm's length [m]: the distances between consecutive link frames (fixed for
    revolute joints) summed, plus the longest offset of a frame from its link."""
    p = np.asarray(link_poses(robot, np.zeros(robot.n)))[:, :3, 3]
    links = float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1)))
    offsets = [float(np.linalg.norm(f.T_link_frame[:3, 3])) for f in robot.frames.values()]
    return links + max(offsets, default=0.0)


def doubts_about(
    robot: Robot,
    frame: str,
    m: float,
    sm: float,
    c: NDArray[np.float64],
    *,
    misfit: bool = False,
) -> tuple[str, ...]:
    """Why the estimate is not a load to trust (module docstring); empty when none.
    ``misfit``: the fit leaves more than :data:`~dynid.identification.verdict.FLOOR_FAIR`
    times the noise (:func:`misfit_doubts`, the whole load's doubt): a mass near zero is
    then that misfit's, not data that cannot tell a load from none, and is not said apart."""
    out = []
    if not misfit and not m > MIN_MASS_SIGMAS * sm:
        out.append(
            f"the load's mass {m:.3g} kg is not significantly above zero (std {sm:.2g} kg, "
            f"{m / sm if sm > 0 else float('inf'):.1f} std; at least {MIN_MASS_SIGMAS:g} "
            "needed): the data cannot tell this load from none (unloaded data, a load too "
            "light for them, or an identified arm model that holds the load already: one "
            "identified from loaded recordings); its CoM and inertia are noise divided by "
            "that mass"
        )
    reach = arm_length(robot)
    dist = float(np.linalg.norm(c))
    if dist > reach:
        out.append(
            f"the load's CoM lies {dist:.3g} m from frame {frame!r}, farther than the arm is "
            f"long ({reach:.3g} m): no load the arm carries reaches that far; the first "
            "moment m c was divided by a mass near zero, or the arm's model is wrong"
        )
    return tuple(out)


def undetermined_inertia(inertia: NDArray[np.float64], std: NDArray[np.float64]) -> tuple[str, ...]:
    """The elements of the inertia the data do not determine (module docstring), named
    ``"Ixx"`` .. ``"Izz"`` in the order ``xx xy xz yy yz zz``; empty when every one is,
    or when the inertia was not identified (``std`` NaN).

    Parameters
    ----------
    inertia : ndarray, shape (3, 3)
        About the CoM [kg m^2].
    std : ndarray, shape (6,)
        Standard deviations of ``xx xy xz yy yz zz`` [kg m^2].
    """
    v = inertia6_from_matrix(np.asarray(inertia, dtype=np.float64))
    s = np.asarray(std, dtype=np.float64)
    out = []
    for k, name in enumerate(INERTIA_ORDER):
        b = _BOUND[name]
        scale = v[b] if b == k else 0.5 * v[b]
        if np.isfinite(s[k]) and not MIN_INERTIA_SIGMAS * s[k] < scale:
            out.append(f"I{name}")
    return tuple(out)


def misfit_ratio(residual_rms: float, noise_rms: float | None) -> float | None:
    """The fit's residual [N m] over the torque noise after the low-pass ``noise_rms``
    [N m]; None when the noise is not known (static data)."""
    return residual_rms / noise_rms if noise_rms else None


def misfit_above(residual_rms: float, noise_rms: float | None) -> float | None:
    """:func:`misfit_ratio` when above :data:`~dynid.identification.verdict.FLOOR_FAIR`
    (a fit that leaves torques its model does not explain), else None: the one rule the
    load's doubt and the torques' scale apply."""
    ratio = misfit_ratio(residual_rms, noise_rms)
    return ratio if ratio is not None and ratio > FLOOR_FAIR else None


def misfit_doubts(judged: JudgedResidual, *, difference: bool = False) -> tuple[str, ...]:
    """The doubt about a load whose ``judged`` residual
    (:mod:`~dynid.feasibility.payload_difference`: the fit's, or with recordings of the same motion
    without the load, its difference from the unloaded arm's at matched states) is more than
    :data:`~dynid.identification.verdict.FLOOR_FAIR` times the noise it holds
    (:attr:`~dynid.feasibility.payload_difference.JudgedResidual.ratio`: the torques' noise and the
    states' through the arm's model): torques the load's and the arm's models do not explain go into
    the load's mass, CoM and inertia, by more than a noise-based standard deviation says (an
    unmodelled spring on a Panda's joints 2 and 4 at 74 x the noise read a 1.5 kg load as 1.04 kg,
    3.7 of its std off; the standard deviations are raised for it,
    :func:`~dynid.feasibility.payload_fit.misfit_covariance`), and no setLoad values are written;
    the likely causes and what to record (``difference``: the arm was identified from unloaded data
    already). Empty at or below the threshold,
    or when the noise is not known (static data)."""
    ratio = judged.ratio
    if ratio is None or not ratio > FLOOR_FAIR:
        return ()
    if judged.kind == "difference":
        return (
            f"{judged.what} leaves {ratio:.3g} x the noise of both recordings "
            f"({judged.residual_rms:.2g} N m RMS{_parts(judged)}, more than {FLOOR_FAIR:g} x): "
            "the load does "
            "not explain what changed between the recordings (the load moved or slipped, "
            "another load, a load that is no rigid body, or the motions differ where they "
            "matched), and those torques go into its mass, CoM and inertia (the standard "
            "deviations are raised to the largest change a torque as large as that misfit "
            "makes, a rough bound); no setLoad values are written; hint: fix the load "
            "rigidly and record the same trajectory with and without it",
        )
    hint = (
        "identify the arm without the load with the terms these torques need (its friction "
        "law, a joint spring, the base's tilt: dynid identify on a log without the load, "
        "then --model), or record the same motion without the load and give it as "
        "--unloaded (the difference method cancels the arm's model errors)"
    )
    if difference:
        hint = (
            "the arm identified from the --unloaded data does not explain the loaded data: "
            "it lacks terms these torques need (a joint spring, another friction law): "
            "identify the arm on the unloaded data (dynid identify names what its residual "
            "follows) and give it as --model, whose terms the --unloaded data are then "
            "fitted with; where the loaded and unloaded motions differ, record them alike "
            "(the arm's errors cancel only where the motions match)"
        )
    if judged.states_rms and judged.noise_rms and judged.states_rms > judged.noise_rms:
        hint = (
            "the states' noise through the arm's model is larger than the torques' (noisy "
            "recorded velocities through a steep friction law, or a high cut-off): where it "
            "is the larger part of the residual, a log without the velocity columns "
            "(velocities derived from the positions at the cut-off) or a lower --cutoff "
            f"leaves less of it; else {hint}"
        )
    return (
        f"the fit leaves {ratio:.3g} x the torque noise{_with_states(judged)} "
        f"({judged.residual_rms:.2g} N m RMS{_parts(judged)}, more than {FLOOR_FAIR:g} x): "
        "torques the arm's model does not explain (unmodelled "
        "friction, a joint spring, a tilted base, the links' or the drive's parameters, or "
        "the states' noise at a high cut-off) go into the load's mass, CoM and inertia, by "
        "more than a noise-based standard deviation says (the standard deviations are "
        "raised to the largest change a torque as large as the misfit makes, a rough "
        f"bound); no setLoad values are written; hint: {hint}",
    )


def _with_states(judged: JudgedResidual) -> str:
    """`` and the states' noise through the arm's model`` when it counts in the floor."""
    return "" if judged.states_rms is None else " and the states' noise through the arm's model"


def _parts(judged: JudgedResidual) -> str:
    """The noise floor's parts in words: ``; against 0.0073 and 0.06 N m, each sample
    weighed against its own noise``; empty when the states' noise is not known."""
    if judged.states_rms is None or not judged.noise_rms:
        return ""
    how = ", each sample weighed against its own noise" if judged.weighted is not None else ""
    return f"; against {judged.noise_rms:.2g} and {judged.states_rms:.2g} N m{how}"


def inertia_doubts(
    names: tuple[str, ...],
    inertia: NDArray[np.float64],
    std: NDArray[np.float64],
    *,
    at_bound: bool = False,
    margin: float = 0.0,
) -> tuple[str, ...]:
    """The doubt about an inertia whose elements ``names`` are not determined
    (:func:`undetermined_inertia`), each with its value and standard deviation [kg m^2],
    or that the LMI of ``margin`` put on its bound (``at_bound``), with the likely cause
    and what to record; empty for neither. A fit that leaves more than
    :data:`~dynid.identification.verdict.FLOOR_FAIR` times the torque noise is doubted as
    a whole load (:func:`misfit_doubts`), its inertia with it."""
    if not names and not at_bound:
        return ()
    v = inertia6_from_matrix(np.asarray(inertia, dtype=np.float64))
    order = [f"I{n}" for n in INERTIA_ORDER]
    which = ", ".join(f"{n} {v[order.index(n)]:.2g} (std {std[order.index(n)]:.2g})" for n in names)
    what = []
    if names:
        what.append(
            f"{which} kg m^2 (a moment needs {MIN_INERTIA_SIGMAS:g} std above zero, a product "
            f"a std under 1/{MIN_INERTIA_SIGMAS:g} of half the third moment)"
        )
    if at_bound:
        what.append(
            f"the consistency constraint (pseudo-inertia margin {margin:g}) set it on its "
            "bound, not the data (the least squares gave no body's inertia)"
        )
    cause = "the load turns too little or too slowly about some axis for the data to weigh it"
    hint = "a recording that turns the flange faster, about every axis"
    return (
        f"the load's inertia is not determined: {'; '.join(what)}; {cause}; setLoad's "
        f"inertia is not written; hint: {hint}",
    )
