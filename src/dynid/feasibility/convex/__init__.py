"""The convex method of physically consistent parameters (LMI, semidefinite programming).

Every link's pseudo-inertia ``J_i(phi)`` (:mod:`dynid.feasibility.lmi`) is kept positive
definite with a margin, and the parameters are pulled towards a prior ``J0_i``
(:mod:`dynid.feasibility.prior`) in the directions the data cannot see:

.. math:: \\min_{\\phi, f} \\; w \\sum_i d(J_i(\\phi), J_{0,i})
          + \\tfrac12 \\| A (x - \\hat x) \\|^2, \\quad x = [P \\phi;\\, f]

subject to ``J_i >= epsilon tr(J_i) 1`` (every link), ``m_min <= m_i <= m_max``, the CoM box
``m_i c_min <= h_i <= m_i c_max`` and ``M_min <= sum m_i <= M_max``

(Wensing, Kim, Slotine, RA-L 2018; Lee, Wensing, Park, T-RO 2020). ``P`` maps the standard
parameters to the base parameters, ``x_hat`` is the least-squares estimate and ``A^T A`` the
inverse of its covariance, so the data term is the increase of the identification's
residual sum of squares in units of its noise variance (``Delta chi^2``).

* **Two-step** (:func:`retrieve_sdp`, the paper's setting): ``x = beta``, the identified
  coefficients with their full covariance. When the coefficients are exact (a residual below
  1e-9 relative), the data term becomes the equality ``P phi = beta`` and the result is
  polished by a minimum-norm correction so that it holds to round-off.
* **One-step** (:func:`identify_consistent`, :func:`consistent_from_identified`): the same
  problem on data, with the coefficients of the model's appended terms as extra unknowns
  (torque logs: the friction of the structure fitted, the classical ``fv, fc, fo`` per joint
  by default), each kept physical as its term declares (``nonnegative``: ``fv, fc >= 0``;
  ``dissipation_rows``: the friction opposing the motion within the velocity limits), or
  on static ``[tril M; g]`` data. The data term is then exactly
  ``||W x - y||^2 / sigma^2`` up to a constant, ``W`` the stacked regressor.

**The prior's weight** ``w``: when the data term holds held-out folds (torque logs: k-fold
over contiguous time blocks, or a separate log), the largest weight whose *held-out* error
is within ``residual_increase`` (1 %) of the best and, with two folds or more, within one
standard error of the difference paired over the folds, and the result is accepted when its
held-out error is within ``heldout_tol`` (5 %) of unconstrained least squares', whatever its
training residual (:mod:`dynid.feasibility.heldout`). Otherwise (static data,
coefficients) the largest weight (over a logarithmic search) whose fit keeps the
identification's residual RMS within ``residual_increase`` (1 %) of the unconstrained
least squares, ``Delta chi^2 <= ((1 + 0.01)^2 - 1) dof``. Either way the prior decides
only what the data leave open. A larger weight trusts the prior more.

**Margin** ``epsilon`` (default 1e-4): ``lambda_min(J) >= epsilon tr(J)`` for every link;
the published Panda's links lie between 2e-4 and 2e-3 of their trace.

**Objectives**: ``"logdet"`` (the Bregman divergence above, default) or ``"euclidean"``,
``sum_i ||S0_i^{-1} J_i S0_i^{-T} - 1||_F^2`` (the prior's own metric).

**Solver**: cvxpy with Clarabel, in whitened variables ``X_i = S0_i^{-1} J_i S0_i^{-T}``
(``J0_i = S0_i S0_i^T``), the prior's weight inside the log-det's exponential cones (their
duals about 1 at any weight) and the duality gap to a hundredth of ``Delta chi^2``; when
the interior-point method stalls it is retried with ``max_iter=500`` and static
regularisation ``1e-7``, then with SCS (``eps=1e-7``, 20 000 iterations), and the result's
notes say at how many solves; a failure raises
:class:`~dynid.exceptions.SolverError` with the solver's status. An equality that no
consistent set meets is reported (``feasible = False``, status ``"infeasible"``) with the
closest consistent set (least relative coefficient error) and how far it is.

Modules: :mod:`.options` (:class:`SDPOptions`), :mod:`.data_term` (:class:`DataTerm`,
:func:`coefficient_term`), :mod:`.problem` (the cvxpy problem and the solver fallback),
:mod:`.weight` (the prior's weight), :mod:`.result` (:class:`ConsistentResult`),
:mod:`.solve` (:func:`solve_consistent`) and :mod:`.fit` (the entry points
:func:`retrieve_sdp` and :func:`identify_consistent`, and :func:`with_drive`).
"""

from .data_term import DataTerm, coefficient_term
from .fit import consistent_from_identified, identify_consistent, retrieve_sdp, with_drive
from .options import DEFAULT_SDP_MARGIN, SDPOptions
from .result import ConsistentResult
from .solve import solve_consistent

__all__ = [
    "DEFAULT_SDP_MARGIN",
    "ConsistentResult",
    "DataTerm",
    "SDPOptions",
    "coefficient_term",
    "consistent_from_identified",
    "identify_consistent",
    "retrieve_sdp",
    "solve_consistent",
    "with_drive",
]
