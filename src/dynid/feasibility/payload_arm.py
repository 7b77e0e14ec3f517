"""The arm without the load, as payload identification subtracts it: every term of its model.

The load's torques are what the loaded data hold beyond the arm's own, so the arm's own
must be its model's whole prediction, the one validation compares with data
(:func:`~dynid.friction.validation.validated`):

* the rigid body with its rotors: an identified model's own prediction
  (:meth:`~dynid.identification.model.IdentifiedModel.torques`, its armature or its drive's
  rotor inertias included); a robot's links through RNEA plus the known rotor inertias of
  its drive (``K^T diag(I_a) K ddq``);
* the friction as identified: the model's own
  (:func:`~dynid.friction.validation.own_friction`: its law, standstill band and drive; a
  robot's published friction), or the one given;
* static data: ``M`` with the rotor inertias and ``g``.

Left out, an armature of ``0.03-0.1 kg m^2`` per joint is carried by the load's inertia,
whose estimate then comes out several times too large with tight standard deviations.

:func:`unloaded_arm` identifies the arm from data recorded without the load (the
difference method) with identification's own route: the structure (armature, friction
laws) chosen on held-out data (:func:`~dynid.identification.selection.identify_recordings`)
or the one given, at the loaded data's cut-off and decimation.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from ..dynamics.rnea import rnea
from ..dynamics.terms import gravity_torques, mass_matrix
from ..exceptions import ModelError
from ..friction.fit import model_drive
from ..friction.validation import own_friction
from ..identification.data import StaticDataset
from ..identification.log import TorqueLog
from ..identification.model import IdentifiedModel
from ..identification.selection import identify_recordings
from ..identification.solvers import scaled_lstsq
from ..identification.static import identify_static
from ..identification.structure import Structure
from ..model.drive import Drive
from ..model.robot import Robot

__all__ = [
    "parameter_spread",
    "ArmFriction",
    "ArmModel",
    "FrictionTorques",
    "arm_model",
    "holds_the_load",
    "model_structure",
    "unloaded_arm",
]


class FrictionTorques(Protocol):
    """A friction model as the arm's prediction uses it (a
    :class:`~dynid.friction.model.Friction`, or a sum of them)."""

    @property
    def kind(self) -> str:
        """The law's name."""
        ...

    def torques(self, v: NDArray[np.float64]) -> NDArray[np.float64]:
        """Joint torques [N m] (N, n) at joint velocities ``v`` [rad/s] (N, n)."""
        ...


#: The friction of :func:`arm_model`: the model's own, none, or a friction model.
ArmFriction = Literal["own"] | FrictionTorques | None


@dataclass(frozen=True, slots=True, eq=False)
class ArmModel:
    """The arm's prediction without the load.

    Attributes
    ----------
    model : IdentifiedModel or Robot
        The rigid-body model (an identified model holds its rotor inertias).
    drive : Drive or None
        The drive the logs are read through (an identified model's own); its known rotor
        inertias are added to a robot's torques.
    friction : FrictionTorques or None
        The arm's friction, added to its torques.
    """

    model: IdentifiedModel | Robot
    drive: Drive | None
    friction: FrictionTorques | None

    @property
    def robot(self) -> Robot:
        """Kinematics and gravity."""
        return self.model.robot if isinstance(self.model, IdentifiedModel) else self.model

    def _known_rotors(self) -> NDArray[np.float64] | None:
        """A robot's drive's known rotor inertias [kg m^2] (None: none to add)."""
        d = self.drive
        if isinstance(self.model, IdentifiedModel) or d is None or d.rotor_inertia is None:
            return None
        return np.asarray(d.rotor_inertia)

    def torques(
        self,
        q: NDArray[np.float64],
        dq: NDArray[np.float64],
        ddq: NDArray[np.float64],
        *,
        with_friction: bool = True,
    ) -> NDArray[np.float64]:
        """Joint torques [N m] (N, n) of the arm at joint positions [rad], velocities
        [rad/s] and accelerations [rad/s^2] (N, n): rigid body, a robot's joint spring,
        rotors and (unless ``with_friction`` is False) friction."""
        if isinstance(self.model, IdentifiedModel):
            tau = self.model.torques(q, dq, ddq)
        else:
            tau = rnea(self.model, q, dq, ddq)
            if self.model.spring is not None:
                tau = tau + self.model.spring.torques(q)
        ia = self._known_rotors()
        if ia is not None and self.drive is not None:
            tau = tau + self.drive.rotor_torques(ddq, ia)
        if self.friction is not None and with_friction:
            tau = tau + self.friction.torques(dq)
        return np.asarray(tau, dtype=np.float64)

    def mass_matrix(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """``M(q)`` [kg m^2] (N, n, n), rotor inertias included."""
        if isinstance(self.model, IdentifiedModel):
            return self.model.mass_matrix(q)
        M = mass_matrix(self.model, q)
        ia = self._known_rotors()
        if ia is not None and self.drive is not None:
            M = M + self.drive.rotor_mass_matrix(ia)
        return M

    def gravity_torques(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """``g(q)`` [N m] (N, n)."""
        if isinstance(self.model, IdentifiedModel):
            return self.model.gravity_torques(q)
        return gravity_torques(self.model, q)


def arm_model(
    arm: IdentifiedModel | Robot | ArmModel,
    *,
    drive: Drive | None = None,
    friction: ArmFriction = "own",
) -> ArmModel:
    """The arm's prediction from its model (module docstring).

    Parameters
    ----------
    arm : IdentifiedModel, Robot or ArmModel
        The arm without the load (an :class:`ArmModel` is returned as it is).
    drive : Drive, optional
        The drive the data were recorded through: an identified model's own by default
        (another one is refused); a robot's known rotor inertias come from it.
    friction : "own", None or a friction model
        The arm's friction: its own (default), none, or this one.

    Raises
    ------
    DataError
        ``drive`` differs from an identified model's own.
    ModelError
        A robot with a drive whose rotor inertias are to be identified: the arm's rotor
        inertias are unknown.
    """
    if isinstance(arm, ArmModel):
        return arm
    d = model_drive(arm, drive)
    if isinstance(arm, Robot) and d is not None and d.rotor_inertia is None:
        raise ModelError(
            'the drive\'s rotor inertias are to be identified (rotor_inertia = "identify"), '
            "so the arm's are unknown; hint: --model identification.json of the arm, "
            "--unloaded data of the arm without the load, or the rotor inertias in the drive"
        )
    fr: FrictionTorques | None
    if isinstance(friction, str):  # its own, where its drive puts it (as simulation does)
        fr = own_friction(arm, d)
    else:
        fr = friction
    return ArmModel(arm, d, fr)


def model_structure(model: IdentifiedModel) -> Structure | None:
    """The terms an identified model holds beside its links (its record of them), or None
    when the model does not say (a model identified before the terms were recorded)."""
    terms = model.info.extra.get("terms") if model.info.extra else None
    if terms is None:
        return None
    return Structure.parse(",".join(str(t) for t in terms))


def holds_the_load(model: IdentifiedModel, recordings: Sequence[Mapping[str, Any]]) -> str | None:
    """Why ``model`` already holds the load of the loaded ``recordings`` (their summary,
    :meth:`~dynid.identification.recordings.Recordings.summary`), or None: one of them is
    a recording the model was identified from, by the SHA-256 of its samples where both
    records hold one (whatever the files are called), else (a model recorded without it)
    by its file name and number of samples. The model's base parameters then hold the
    load's, and the load left beside them is none. A recording left out of the model's fit
    as outlying (``left_out``: a payload recording among unloaded ones) is not its own."""
    own = [dict(r) for r in model.info.recordings if not r.get("left_out")]
    sums = {r["sha256"] for r in own if "sha256" in r}
    same: list[str] = []
    how = "the same samples"
    for r in recordings:
        name = Path(str(r.get("file", ""))).name
        if "sha256" in r and sums:
            if r["sha256"] in sums:
                same.append(name)
            continue
        for m in own:  # a model recorded without digests: the name and sample count
            if Path(str(m.get("file", ""))).name == name and m.get("recorded") == r.get(
                "recorded", m.get("recorded")
            ):
                same.append(name)
                how = "the same file name and number of samples"
                break
    if not same:
        return None
    which = "this recording" if len(same) == 1 else "these recordings"
    return (
        f"{', '.join(same)}: --model was identified from {which} ({how}), so its "
        "base parameters already hold the load and none is left beside them; hint: --robot "
        "(the arm's description), --model of the arm identified without the load, or "
        "--unloaded recordings of the arm without the load (the difference method)"
    )


def unloaded_arm(
    robot: Robot,
    unloaded: StaticDataset | Sequence[TorqueLog],
    names: Sequence[str] | None = None,
    *,
    structure: Structure | Literal["auto"] = "auto",
    cutoff_hz: float | None = None,
    decimate: int | None = None,
    max_gap_s: float | None = None,
    drive: Drive | None = None,
    rtol: float | None = None,
    torque_delay_s: float = 0.0,
) -> tuple[ArmModel, str]:
    """The arm identified from data recorded without the load, and a note saying how.

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity.
    unloaded : StaticDataset or sequence of TorqueLog
        Static data, or one or more recordings.
    names : sequence of str, optional
        The recordings' names, for messages.
    structure : Structure or "auto"
        Recordings: the terms beside the links; ``"auto"``: chosen on held-out data as
        identification chooses them.
    cutoff_hz, decimate, max_gap_s
        Recordings: the preparation (the loaded data's, so that both are filtered alike).
    drive : Drive, optional
        The drive the data were recorded through.
    rtol : float, optional
        Relative rank tolerance (default: identification's).
    torque_delay_s : float
        Recordings: how far the torques lag the positions [s] (the loaded data's).
    """
    if isinstance(unloaded, StaticDataset):
        model = identify_static(robot, unloaded, rtol=rtol, drive=drive)
        what = f"{model.base.rank} base parameters"
    else:
        model = identify_recordings(
            robot,
            list(unloaded),
            names,
            structure=structure,
            cutoff_hz=cutoff_hz,
            decimate=decimate,
            max_gap_s=max_gap_s,
            drive=drive,
            rtol=rtol,
            torque_delay_s=torque_delay_s,
        )
        chosen = model_structure(model)
        how = "chosen on held-out data" if structure == "auto" else "given"
        what = f"{model.base.rank} base parameters, " + (
            f"{chosen.name} ({how})" if chosen is not None else "links"
        )
    note = (
        f"difference method: arm identified from the unloaded data ({what}); the "
        "standard deviations leave out the uncertainty of that fit"
    )
    return arm_model(model), note


def parameter_spread(
    arm: ArmModel,
    pieces: Sequence[TorqueLog],
    still: NDArray[np.bool_],
    W: NDArray[np.float64],
    p: int,
) -> NDArray[np.float64] | None:
    """The covariance (p, p) the identified arm's base parameters' own covariance puts into
    the first ``p`` coefficients of the load's least squares on the rows ``W`` (N n, k;
    the fitted columns only) of the prepared ``pieces`` (``still`` joints at rest).

    The load's rows are the measured torques less the arm's; an error ``d beta`` of the
    arm's base parameters moves them by ``-Y_b d beta`` (``Y_b`` the arm's base regressor
    at the prepared states: each column the change of the arm's torques per unit of one
    base parameter), the same error all along the recordings, which no residual shows:
    the load moves by ``K d beta`` with ``K = -(W^T W)^-1 W^T Y_b``, of covariance
    ``K C K^T``. Only the base parameters' covariance is known from a saved model (the
    friction's is not saved); None for a robot description or a model without it."""
    model = arm.model
    if not isinstance(model, IdentifiedModel) or model.fit.covariance is None:
        return None
    C = np.asarray(model.fit.covariance, dtype=np.float64)
    r = model.base.rank
    if C.shape != (r, r) or not np.all(np.isfinite(C)):
        return None
    x0 = np.concatenate(
        [np.asarray(model.fit.beta, dtype=np.float64)]
        + [np.asarray(t.values, dtype=np.float64).ravel() for t in model.appended]
    )
    moving = ~still
    states = [(x.q, x.dq * moving, x.ddq * moving) for x in pieces if x.ddq is not None]
    base = np.concatenate([arm.torques(*s, with_friction=False).ravel() for s in states])
    Yb = np.empty((base.size, r))
    for i in range(r):
        x = x0.copy()
        x[i] += 1.0
        other = dataclasses.replace(arm, model=model.with_coefficients(x))
        Yb[:, i] = np.concatenate([other.torques(*s, with_friction=False).ravel() for s in states])
        Yb[:, i] -= base
    K = -scaled_lstsq(W, Yb)[:p]
    return np.asarray(K @ C @ K.T, dtype=np.float64)
