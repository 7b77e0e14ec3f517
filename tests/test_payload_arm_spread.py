"""The identified arm's own parameter uncertainty in a load's standard deviations.

References: the Panda's torques from Pinocchio's RNEA (example-robot-data's kinematics,
the published inertials of Gaz et al. 2019), with and without a load at the flange, and
white sensor noise; the load's change under a change of the arm's base parameters is
taken by finite differences of whole refits.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

import dynid
from dynid.feasibility.payload import identify_payload
from dynid.identification.log import TorqueLog
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.simulation.trajectories import random_fourier, uniform_times

from conftest import pinocchio_panda_model

MASS, COM = 1.5, np.array([0.03, -0.02, 0.08])
INERTIA = np.diag([0.004, 0.005, 0.003])
ARM = dynid.panda().with_friction(None)
FLANGE_Z = 0.107  # the flange on link 7 [m]


@pytest.fixture(scope="module")
def arm_and_load():
    """The arm identified (links only) from 6 s of the unloaded Panda, and 6 s of another
    trajectory with the load; Pinocchio's torques plus 0.05 N m noise."""
    pin = pytest.importorskip("pinocchio")
    model = pinocchio_panda_model(ARM)
    t = uniform_times(6.0, 500.0)
    arm7 = model.inertias[7].copy()

    def log(seed, loaded):
        model.inertias[7] = (
            arm7 + pin.Inertia(MASS, COM + [0, 0, FLANGE_Z], INERTIA) if loaded else arm7
        )
        data = model.createData()
        traj = random_fourier(ARM, np.random.default_rng(seed), q0=dynid.PANDA_NEUTRAL_Q)(t)
        states = zip(traj.q, traj.dq, traj.ddq, strict=True)
        tau = np.array([pin.rnea(model, data, q, dq, ddq) for q, dq, ddq in states])
        tau += np.random.default_rng(seed + 100).normal(0.0, 0.05, tau.shape)
        return TorqueLog(t=t, q=traj.q, dq=traj.dq, tau=tau)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dynid.DynidWarning)
        arm = identify_recordings(ARM, [log(7, False)], structure=Structure.parse("links"))
    return arm, log(8, True)


def _estimate(arm, log):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dynid.DynidWarning)
        return identify_payload(arm, log, terms=None)


def _with_covariance(model, cov):
    return dataclasses.replace(model, fit=dataclasses.replace(model.fit, covariance=cov))


def test_the_arm_parameters_uncertainty_is_in_the_load_std(arm_and_load):
    """Regression (a load on an identified arm read 1.50389 kg at 0.00088 kg, 4.4 of its
    standard deviation from the truth, the arm's own parameter errors, the same all along
    the recordings, left out): with the arm's base-parameter covariance ``u u^T``, the
    load's variance grows by the square of the change refits make when the arm's
    parameters move by ``u`` (finite differences of whole refits, to 2 % for the mass and
    10 % for the first moment, which the consistency constraint moves a little)."""
    arm, log = arm_and_load
    r = arm.base.rank
    C = np.asarray(arm.fit.covariance)
    u = np.linalg.cholesky(C) @ np.random.default_rng(5).standard_normal(r)
    none = _estimate(_with_covariance(arm, np.zeros((r, r))), log)
    along = _estimate(_with_covariance(arm, np.outer(u, u)), log)
    moved = arm.with_coefficients(np.asarray(arm.fit.beta) + u)
    refit = _estimate(_with_covariance(moved, np.zeros((r, r))), log)
    change = refit.phi[:4] - none.phi[:4]  # m, m c
    added = np.sqrt(np.diag(along.covariance - none.covariance)[:4])
    assert abs(change[0]) > 0.3 * none.std_mass  # the arm's error matters
    assert abs(added[0] - abs(change[0])) < 0.02 * abs(change[0])
    np.testing.assert_allclose(added[1:], np.abs(change[1:]), rtol=0.1)
    assert any("base parameters' uncertainty" in note for note in along.notes)
