"""The gains per motor of a torque log (``drive_gains``): each fold's rows factored once
against the same judgement computed on the explicit rows, the method it replaced.

A Panda's base regressor with viscous, Coulomb and rotor-inertia columns per joint (64
columns) at ``--samples`` random states, torques logged through factors 1.5, 0.7 and 1.2
on joints 2, 4 and 6 with 1 % noise, the description's gravity torques for the common
scale, five contiguous time blocks as folds. ``drive_gains`` factors each fold's rows of
the model's columns and the efforts once (tall-skinny QR) and fits every training set
from the other folds' triangular factors stacked. The reference computes the same
numbers from the rows themselves, as the code before did: the pivoted QR of the model's
columns with ``Q`` formed and the efforts projected on the rows, per fold the pivoted QR
of the training rows, and the common scale by an SVD least squares (``np.linalg.lstsq``)
on the rows, in-sample and per fold (it factors the model's columns once where the code
before did three times: the ratio is a lower bound of the speed-up). The factors, the
held-out gains and their standard errors must agree to 1e-8 relative before timing.

``python benchmarks/bench_drive_gains.py [--samples N ...] [--repeats R] [--json [PATH]]``
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import scipy.linalg

sys.path.insert(0, str(Path(__file__).resolve().parent))  # this folder
from common import Case, bench_parser, check_close, measure_pair, random_states, report  # noqa: E402

import dynid  # noqa: E402
from dynid.dynamics.terms import gravity_torques  # noqa: E402
from dynid.identification.drive_gains import drive_gains, effort_columns  # noqa: E402
from dynid.identification.holdout import DEFAULT_FOLDS, block_labels  # noqa: E402
from dynid.identification.solvers import tall_pivoted_qr  # noqa: E402
from dynid.regressors.base import base_parameters  # noqa: E402
from dynid.regressors.torque import torque_regressor  # noqa: E402

#: The factors the torques are logged through (the true effort over the logged one).
TRUTH = np.array([1.0, 1.5, 1.0, 0.7, 1.0, 1.2, 1.0])


def _log(samples: int, seed: int = 3):
    """The model's columns (N, 7, 64), the logged torques (N, 7) [N m], their noise (7,)
    [N m], the gravity columns and the description's gravity torques (N, 7) [N m]."""
    robot = dynid.panda()
    base = base_parameters(robot, kind="torque", rng=np.random.default_rng(seed))
    q, dq, ddq = random_states(robot, samples, seed)
    eye = np.eye(robot.n)
    own = [dq[:, :, None] * eye, np.sign(dq)[:, :, None] * eye, ddq[:, :, None] * eye]
    terms = np.concatenate(own, axis=-1)
    W = np.concatenate([base.reduce(torque_regressor(robot, q, dq, ddq)), terms], axis=-1)
    rest = np.zeros_like(q)
    G = np.concatenate([base.reduce(torque_regressor(robot, q, rest, rest)), 0 * terms], -1)
    theta = np.concatenate(
        [base.beta_from_phi(robot.phi), np.full(7, 0.5), np.ones(7), np.full(7, 0.1)]
    )
    tau = W @ theta
    noise = 0.01 * np.sqrt(np.mean(tau**2, axis=0))
    rng = np.random.default_rng(seed)
    return W, tau / TRUTH + rng.normal(size=tau.shape) * noise, noise, G, gravity_torques(robot, q)


def _basis(X):
    """The pivoted QR of ``X``'s rows with ``Q`` formed, cut at rank (relative 1e-10)."""
    Q, R, piv = tall_pivoted_qr(X)
    d = np.abs(np.diag(R))
    r = int(np.count_nonzero(d > 1e-10 * d[0]))
    return Q[:, :r], R[:r, :r], piv[:r]


def _gains(Ba, Q):
    """The smallest eigenvector of the efforts' normal matrix with ``Q`` projected out."""
    P = Ba - Q @ (Q.T @ Ba)
    V = scipy.linalg.eigh(P.T @ P)[1]
    return V[:, 0] * np.sign(V[:, 0].sum())


def _scale(g, A, B, G, gd):
    """The description's scale of ``g``: the fitted gravity torques over the described."""
    x = np.linalg.lstsq(A, B @ g, rcond=None)[0]
    gm = G @ x
    loaded = np.any(gd != 0, axis=0)
    d, f = gd[:, loaded].ravel(), gm[:, loaded].ravel()
    return float(d @ f / (d @ d))


def explicit(W, tau, s, G, gd, labels):
    """The factors and the held-out gains and standard errors of ``drive_gains`` with every
    motor fitted (as on this log), each fit on the explicit rows."""
    N, n, p = W.shape
    A = (W / s[:, None]).reshape(N * n, p)
    B = (effort_columns(tau) / s[:, None]).reshape(N * n, n)
    norms = np.linalg.norm(A, axis=0)
    norms[norms == 0] = 1.0
    g = _gains(B, _basis(A / norms)[0])
    g = g * np.linalg.norm(B.sum(axis=1)) / np.linalg.norm(B @ g)
    factor = g / _scale(g, A, B, G, gd)
    rows, diffs = np.repeat(labels, n), []
    for f in np.unique(labels):
        tr, te = rows != f, rows == f
        Q, R, cols = _basis(A[tr] / norms)
        gf = _gains(B[tr], Q)
        unit = _scale(gf, A[tr], B[tr], G[labels != f], gd[labels != f])

        def mean_square(h, Q=Q, R=R, cols=cols, tr=tr, te=te):
            y = B @ h
            x = scipy.linalg.solve_triangular(R, Q.T @ y[tr])
            return float(np.mean((y[te] - (A[te] / norms)[:, cols] @ x) ** 2))

        held = [np.where(np.arange(n) == k, unit, gf) for k in range(n)]
        diffs.append([mean_square(h) - mean_square(gf) for h in held])
    D = np.asarray(diffs)
    return factor, D.mean(axis=0), D.std(axis=0, ddof=1) / np.sqrt(D.shape[0])


def main(argv: list[str] | None = None) -> dict:
    parser = bench_parser(__doc__)
    parser.add_argument("--samples", type=int, nargs="+", default=[500, 2000])
    args = parser.parse_args(argv)
    cases = []
    for samples in args.samples:
        W, tau, s, G, gd = _log(samples)
        labels = block_labels(samples, DEFAULT_FOLDS)

        def ours(W=W, tau=tau, s=s, G=G, gd=gd, labels=labels):
            return drive_gains(W, tau, s, None, G, gd, labels)

        def ref(W=W, tau=tau, s=s, G=G, gd=gd, labels=labels):
            return explicit(W, tau, s, G, gd, labels)

        found, (factor, gain, se) = ours(), ref()
        assert found is not None and found.scaled and found.determined.all()
        for name, a, b in (
            ("factor", found.factor, factor),
            ("heldout_gain", found.heldout_gain, gain),
            ("heldout_se", found.heldout_se, se),
        ):
            check_close(f"{name}, {samples} samples", a, b, 1e-8 * float(np.max(np.abs(b))))
        t_ours, t_ref = measure_pair(ours, ref, min_time=args.min_time, repeats=args.repeats)
        note = (
            f"{samples * 7} rows x {W.shape[-1] + 7} columns, {DEFAULT_FOLDS} folds; "
            f"new/old {t_ours.median / t_ref.median:.3f}"
        )
        cases.append(Case(f"drive_gains, {samples} samples", samples, t_ours, t_ref,
                          ref_name="explicit rows", note=note))  # fmt: skip
    return report("drive_gains", cases, args)


if __name__ == "__main__":
    main()
