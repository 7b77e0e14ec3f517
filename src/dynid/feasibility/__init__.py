"""Physically consistent link parameters: the convex (LMI) methods and the paper's penalty method.

* :func:`retrieve_sdp` (two-step) and :func:`identify_consistent` (one-step, from torque
  logs or static data): every link's pseudo-inertia kept positive definite, pulled towards
  a :class:`Prior` (:mod:`.convex`, :mod:`.lmi`, :mod:`.prior`).
* :func:`retrieve`: Gaz et al. 2019, Algorithm 1 (:mod:`.penalty`).
* :data:`METHODS`: both methods behind one registry, each answering "from coefficients"
  and "from data" (:class:`ConsistentMethod`, :mod:`.methods`).
* :class:`FeasibleResult`: what both methods return (:class:`ConsistentResult`,
  :class:`RetrievalResult`) and files and figures read (:mod:`.result`).
* :func:`compare_methods`: both on the same coefficients (:mod:`.compare`).
* :func:`identify_payload`: a load's mass, CoM and inertia on a known arm, with the same
  LMI (:mod:`.payload`).
* :func:`feasibility_report`, :class:`Bounds`: constraints and their margins
  (:mod:`.constraints`); :func:`validate_newton_euler` (from :mod:`dynid.friction.validation`).
"""

from ..friction.validation import validate_newton_euler
from .bounds import Bounds, default_bounds, kinematic_bounds, panda_bounds
from .compare import MethodSummary, compare_methods, perturbed_robot
from .constraints import feasibility_report
from .convex import (
    ConsistentResult,
    SDPOptions,
    identify_consistent,
    retrieve_sdp,
    solve_consistent,
)
from .lmi import log_det_divergence, pseudo_inertia, pseudo_inertia_margin
from .methods import METHODS, ConsistentMethod, method
from .payload import PayloadEstimate, identify_payload, model_with_payload, robot_with_payload
from .penalty import RetrievalOptions, RetrievalResult, retrieve, retrieve_from_static
from .prior import Prior, default_prior, generic_prior, prior_from_robot
from .result import FeasibleResult

__all__ = [
    "METHODS",
    "Bounds",
    "ConsistentMethod",
    "ConsistentResult",
    "FeasibleResult",
    "MethodSummary",
    "PayloadEstimate",
    "Prior",
    "RetrievalOptions",
    "RetrievalResult",
    "SDPOptions",
    "compare_methods",
    "default_bounds",
    "feasibility_report",
    "default_prior",
    "generic_prior",
    "identify_consistent",
    "identify_payload",
    "kinematic_bounds",
    "log_det_divergence",
    "method",
    "panda_bounds",
    "perturbed_robot",
    "prior_from_robot",
    "pseudo_inertia",
    "pseudo_inertia_margin",
    "retrieve",
    "retrieve_from_static",
    "retrieve_sdp",
    "model_with_payload",
    "robot_with_payload",
    "solve_consistent",
    "validate_newton_euler",
]
