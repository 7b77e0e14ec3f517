"""The identified model at work: external joint torques and collision detection.

The generalized-momentum residual of De Luca et al. estimates the external joint torque
from the measured ``q, dq, tau`` without accelerations:

.. math:: r = K_O \\Big(p - p_0 - \\int (\\tau - \\tau_f + C^T \\dot q - g + r)\\, dt\\Big),
          \\qquad \\dot r = K_O (\\tau_{ext} - r)

(De Luca, Albu-Schaeffer, Haddadin, Hirzinger, IROS 2006; Haddadin, De Luca,
Albu-Schaeffer, IEEE T-RO 2017), on any model dynid produces.

* :mod:`~dynid.observer.model`: :class:`ObserverModel` from an identified model or a robot;
* :mod:`~dynid.observer.terms`: ``p = M dq`` and ``g - C^T dq`` (compiled pass), the
  momentum regressor;
* :mod:`~dynid.observer.friction`: friction laws in the compiled step's canonical form;
* :mod:`~dynid.observer.residual`: :class:`MomentumObserver` (``step`` for a control loop)
  and :func:`observe` (a whole log);
* :mod:`~dynid.observer.pieces`: a log cut at its gaps (the observer starts again on
  each piece), positions that jump;
* :mod:`~dynid.observer.wrench`: the external wrench at a frame by damped least squares;
* :mod:`~dynid.observer.detection`: thresholds calibrated on collision-free data, the
  model's uncertainty propagated to the residual, the standstill margin;
* :mod:`~dynid.observer.rest_margin`: the standstill margin at rest calibrated from the
  calibration's rests (the Coulomb level kept with too few of them);
* :mod:`~dynid.observer.sign`: measured torques of the opposite sign to the model's,
  read from the residual (a calibration refuses them);
* :mod:`~dynid.observer.thresholds`: the thresholds and their value at every sample;
* :mod:`~dynid.observer.gain_noise`: how much of a calibration residual is the
  velocities' noise times the gain (thresholds that grow with it);
* :mod:`~dynid.observer.events`: contact and collision events, from a whole log or a
  block of samples at a time (:class:`EventDetector`);
* :mod:`~dynid.observer.scoring`: the events against labelled contacts (a 0/1 column or
  the true external torques): detected, missed, false alarms and delays;
  :mod:`~dynid.observer.missed_reason` why a missed one was missed (its torque below the
  threshold of its joint standing still or moving).
* :mod:`~dynid.observer.unmodelled_load`: the weight of a load at the flange that the
  model lacks, fitted to the residual off contacts.
"""

from .detection import calibrate, residual_std
from .events import ContactEvent, EventDetector, detect
from .model import ObserverModel, from_identified, from_robot
from .residual import MomentumObserver, ObserverOptions, ObserverResult, first_order_lag, observe
from .terms import base_momentum_regressor, momentum_regressor, momentum_terms
from .thresholds import ModelFingerprint, Thresholds
from .wrench import WrenchEstimate, external_wrench

__all__ = [
    "ContactEvent",
    "EventDetector",
    "ModelFingerprint",
    "MomentumObserver",
    "ObserverModel",
    "ObserverOptions",
    "ObserverResult",
    "Thresholds",
    "WrenchEstimate",
    "base_momentum_regressor",
    "calibrate",
    "detect",
    "external_wrench",
    "first_order_lag",
    "from_identified",
    "from_robot",
    "momentum_regressor",
    "momentum_terms",
    "observe",
    "residual_std",
]
