"""The per-joint panel titles of dynid's figures fit beside each other: rendered for a
6- and a 7-joint arm with long joint names, no title's box overlaps another's or leaves
the figure (the friction figure's "motor 1 (shoulder_pan_joint): joint RMS ..." ran into
its neighbour's).

Reference: the titles' rendered boxes [pixels] as matplotlib lays them out.
"""

from __future__ import annotations

import numpy as np
import pytest

from dynid.friction.fit import FrictionFit, FrictionResidual
from dynid.friction.model import ClassicalFriction, DriveFriction
from dynid.friction.validation import NewtonEulerValidation, Validation
from dynid.identification.log import TorqueLog
from dynid.identification.metrics import torque_errors
from dynid.model.drive import Drive

pytest.importorskip("matplotlib")

#: Long joint names (a UR arm's, the trial's, and a 7th of the same length).
NAMES = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
    "wrist_4_extra_joint",
)


def _clashes(fig) -> list[tuple[str, str]]:
    """Pairs of panel titles of ``fig`` whose boxes overlap, and titles outside it."""
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    frame = fig.bbox
    boxes = [
        (ax.title.get_text(), ax.title.get_window_extent(r))
        for ax in fig.axes
        if ax.get_visible() and ax.title.get_text()
    ]
    out = [(a, "figure") for a, b in boxes if b.x0 < frame.x0 - 1 or b.x1 > frame.x1 + 1]
    for i, (a, ba) in enumerate(boxes):
        out += [(a, b) for b, bb in boxes[i + 1 :] if ba.overlaps(bb)]
    return out


def _log(rng: np.random.Generator, n: int, N: int = 300) -> TorqueLog:
    """A log of random signals of ``n`` joints."""
    t = 0.01 * np.arange(N)
    q, dq, tau, ddq = (rng.normal(size=(N, n)) for _ in range(4))
    return TorqueLog(t, q, dq, tau, ddq)


@pytest.mark.parametrize("n", [6, 7])
def test_friction_figure_titles_of_a_drive_do_not_overlap(n):
    """Friction fitted at the motors of a 6- or 7-motor drive, RMS of 5.627 -> 0.306 N m
    (the trial's): every panel title stands clear of the others."""
    from dynid.plots.friction import plot_friction_fit

    rng = np.random.default_rng(40 + n)
    drive = Drive(np.diag(np.full(n, 100.0)), np.zeros(n), side="motor")
    fr = DriveFriction(ClassicalFriction(np.full(n, 1e-4), np.full(n, 0.05), np.zeros(n)), drive)
    log = _log(rng, n)
    res = FrictionResidual(log, np.zeros_like(log.tau), fr.torques(log.dq))
    before, after = np.full(n, 5.627), np.full(n, 0.306)
    fit = FrictionFit(fr, before, after, np.ones(n, bool), np.zeros(n, int), 300, np.ones(n, bool))
    fig = plot_friction_fit(res, fit, joint_names=NAMES[:n], title="own (classical) friction")
    assert _clashes(fig) == []
    fig.clf()


@pytest.mark.parametrize("n", [6, 7])
def test_residual_histogram_and_newton_euler_titles_do_not_overlap(n):
    """The held-out residual histograms (with samples beyond the axis) and the
    Newton-Euler validation of a 6- or 7-joint arm: every panel title stands clear."""
    from dynid.friction.heldout_torques import HeldOutTorques
    from dynid.plots.feasible import plot_newton_euler_validation
    from dynid.plots.identification import plot_residual_histograms

    rng = np.random.default_rng(50 + n)
    log = _log(rng, n)
    hat = log.tau + rng.normal(0.0, 0.05, log.tau.shape)
    hat[:3] += 3.0  # a few samples beyond the histogram's axis
    v = Validation(log, hat, np.zeros_like(hat), torque_errors(log.tau, hat), None, None)
    hist = plot_residual_histograms(HeldOutTorques(v, np.full(n, 0.05), "block 5", NAMES[:n]))
    errors = torque_errors(log.tau, hat)
    ne = NewtonEulerValidation(
        log.t, log.tau, hat, None, hat, errors, errors, errors, NAMES[:n], None
    )
    feasible = plot_newton_euler_validation(ne)
    for fig in (hist, feasible):
        assert _clashes(fig) == [], _clashes(fig)
        fig.clf()
