"""Stage 6 of the demo, beyond the paper: the identified model detects a collision.

The paper ends with its future work: use the identified model to detect collisions. Here
the model of stage 2 (with the friction of stage 3) runs the momentum observer of
:mod:`dynid.observer` on two simulated motions of the real robot: a collision-free one
calibrates the thresholds (with the model's uncertainty when it has a covariance), and the
same kind of motion with a push on link 6 is searched for contacts.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..friction.model import FrictionModel
from ..identification.model import IdentifiedModel
from ..model.robot import Robot
from ..observer.detection import (
    ContactEvent,
    Thresholds,
    calibrate,
    detect,
    residual_std,
    standstill_series,
)
from ..observer.model import from_identified
from ..observer.residual import ObserverOptions, first_order_lag, observe
from ..simulation.contact import Contact, contact_torques
from ..simulation.measurement import SensorNoise, simulate_measurement
from ..simulation.trajectories import random_fourier, uniform_times

__all__ = ["DEMO_CONTACT", "CollisionStageResult", "collision_stage"]

#: The demo's collision: 15 N down on link 6 from 4 s to 4.5 s.
DEMO_CONTACT = Contact("link6", (0.0, 0.0, -15.0), 4.0, 4.5)


@dataclass(frozen=True, slots=True, eq=False)
class CollisionStageResult:
    """Stage 6: thresholds, the events found and how close the residual came to the truth.

    Attributes
    ----------
    contact : Contact
        The simulated push.
    thresholds : Thresholds
    events : list of ContactEvent
    delay : float or None
        First event's start after the push's [s] (None: not found).
    residual_error_rms : ndarray, shape (n,)
        RMS of the residual minus the true external torque through ``K_O / (s + K_O)``
        over the push [N m].
    t, r, tau_ext : ndarray
        The collision log's times (N,) [s], residual and true external torques (N, n)
        [N m].
    seed : int
    """

    contact: Contact
    thresholds: Thresholds
    events: list[ContactEvent]
    delay: float | None
    residual_error_rms: NDArray[np.float64]
    t: NDArray[np.float64]
    r: NDArray[np.float64]
    tau_ext: NDArray[np.float64]
    seed: int


def collision_stage(
    model: IdentifiedModel,
    friction: FrictionModel | None,
    seed: int,
    *,
    truth: Robot,
    contact: Contact = DEMO_CONTACT,
    duration: float = 8.0,
) -> CollisionStageResult:
    """Calibrate on a free motion of ``truth``, then find ``contact`` in another one.

    Both motions are one random Fourier series of ``truth`` (10 s period, within the
    limits) at 1 kHz with the default sensor noise, each with its own noise.
    """
    rng = np.random.default_rng([seed, 6])
    traj = random_fourier(truth, rng, n_harmonics=4, w_f=2 * np.pi / 10.0)(
        uniform_times(duration, 1000.0)
    )
    noise = SensorNoise()
    free = simulate_measurement(truth, traj, rng=rng, noise=noise)
    hit = simulate_measurement(truth, traj, rng=rng, noise=noise, contacts=(contact,))
    obs = from_identified(model, friction)
    opts = ObserverOptions()
    r_free = observe(obs, free.t, free.q, free.dq, free.tau, opts).r
    std = None
    if obs.covariance is not None:
        std = [residual_std(obs, free.t, free.q, free.dq, opts)]
    w_free = standstill_series(obs, free.t, free.dq, opts)
    th = calibrate([r_free], opts, std=std, standstill=[w_free])
    r = observe(obs, hit.t, hit.q, hit.dq, hit.tau, opts).r
    s_hit = None if std is None else residual_std(obs, hit.t, hit.q, hit.dq, opts)
    w_hit = standstill_series(obs, hit.t, hit.dq, opts)
    events = detect(hit.t, r, th, std=s_hit, standstill=w_hit)
    ext = contact_torques(truth, (contact,), traj.t, traj.q)
    lag = first_order_lag(hit.t, ext, opts.gains(truth.n), opts.rule)
    on = (hit.t >= contact.start) & (hit.t < contact.end)
    err = np.sqrt(np.mean((r[on] - lag[on]) ** 2, axis=0))
    found = [e for e in events if e.end >= contact.start and e.start <= contact.end + 0.1]
    delay = None if not found else found[0].start - contact.start
    return CollisionStageResult(contact, th, events, delay, err, hit.t, r, ext, seed)
