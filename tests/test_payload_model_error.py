"""Payload identification on an arm whose model is wrong: standard deviations and inertia
that say so.

References: the loaded Panda's torques from Pinocchio's RNEA (example-robot-data's
kinematics, the published inertials of Gaz et al. 2019, the load added to link 7 at the
flange) with white sensor noise; the load is the truth the estimates are compared with.
The delete-one-block jackknife is checked against least squares refitted without each
block.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import dynid
from dynid.feasibility.payload import identify_payload
from dynid.feasibility.payload_fit import block_jackknife_covariance
from dynid.identification.log import TorqueLog
from dynid.io.payload_json import payload_to_dict
from dynid.model.inertia import inertia6_from_matrix
from dynid.simulation.trajectories import random_fourier, uniform_times

from conftest import pinocchio_panda_urdf

MASS, COM = 1.5, np.array([0.03, -0.02, 0.08])
INERTIA = np.diag([0.004, 0.005, 0.003])
ARM = dynid.panda().with_friction(None)
FLANGE_Z = 0.107  # the flange on link 7 [m]


@pytest.fixture(scope="module")
def loaded_log():
    """10 s at 500 Hz of the loaded Panda, Pinocchio's torques plus 0.05 N m noise."""
    pin = pytest.importorskip("pinocchio")
    full = pin.buildModelFromUrdf(pinocchio_panda_urdf())
    fingers = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(full, fingers, pin.neutral(full))
    for i in range(7):
        model.inertias[i + 1] = pin.Inertia(
            ARM.mass[i], np.array(ARM.com[i]), np.array(ARM.inertia[i])
        )
    model.inertias[7] += pin.Inertia(MASS, COM + [0.0, 0.0, FLANGE_Z], INERTIA)
    model.gravity.linear[:] = [0.0, 0.0, -9.80665]
    data = model.createData()
    t = uniform_times(10.0, 500.0)
    traj = random_fourier(ARM, np.random.default_rng(4), q0=dynid.PANDA_NEUTRAL_Q)(t)
    states = zip(traj.q, traj.dq, traj.ddq, strict=True)
    tau = np.array([pin.rnea(model, data, q, dq, ddq) for q, dq, ddq in states])
    noise = np.random.default_rng(2).normal(0.0, 0.05, tau.shape)
    return TorqueLog(t=t, q=traj.q, dq=traj.dq, tau=tau + noise)


def _estimate(arm, log):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dynid.DynidWarning)
        return identify_payload(arm, log)


def test_a_wrong_arm_model_widens_the_inertia_std_and_withholds_setload(loaded_log):
    """Regression (an identified arm's errors went into the load's inertia, Izz +40 % at
    3.4 of its std, and setLoad got it as plausible): with the true arm the load's inertia
    is determined and within 3 std; with 1 % errors in links 1-6 (the fit leaves over twice
    the torque noise) every inertia element's error stays within 3 of its std, widened to
    the spread over held-out time blocks, and setLoad's inertia is not written."""
    true = _estimate(ARM, loaded_log)
    err = inertia6_from_matrix(true.inertia) - inertia6_from_matrix(INERTIA)
    assert true.inertia_determined and true.plausible and abs(true.mass - MASS) < 0.005 * MASS
    assert np.max(np.abs(err / true.std_inertia)) < 3.0
    assert payload_to_dict(true, ARM)["load_inertia"] is not None
    phi = np.array(ARM.phi)
    phi[:6] *= 1 + 0.01 * np.random.default_rng(1).standard_normal(phi[:6].shape)
    wrong = _estimate(ARM.with_params(phi), loaded_log)
    err = inertia6_from_matrix(wrong.inertia) - inertia6_from_matrix(INERTIA)
    assert wrong.residual_rms > 2 * wrong.noise_rms and np.max(np.abs(err)) > 0.3 * 0.004
    assert np.max(np.abs(err / wrong.std_inertia)) < 3.0
    assert any("held-out time blocks" in note for note in wrong.notes)
    assert not wrong.inertia_determined and not wrong.plausible
    assert payload_to_dict(wrong, ARM)["load_inertia"] is None


def test_block_jackknife_against_refits_without_each_block():
    """The jackknife covariance equals (K-1)/K times the scatter of least squares refitted
    without each of K contiguous blocks of whole samples (np.linalg.lstsq)."""
    rng = np.random.default_rng(3)
    n, samples, K = 2, 103, 5
    W = rng.standard_normal((n * samples, 4)) * [1.0, 10.0, 0.1, 3.0]
    y = W @ [1.0, -2.0, 3.0, 0.5] + rng.standard_normal(n * samples)
    edges = np.linspace(0, samples, K + 1).astype(int) * n
    fits = []
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        keep = np.r_[0:a, b : W.shape[0]]
        fits.append(np.linalg.lstsq(W[keep], y[keep], rcond=None)[0])
    d = np.array(fits) - np.mean(fits, axis=0)
    expected = (K - 1) / K * d.T @ d
    got = block_jackknife_covariance(W, y, n, K)
    assert got is not None
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-14)
    assert block_jackknife_covariance(W[: 2 * n * K - n], y[: 2 * n * K - n], n, K) is None


def test_torques_the_arm_model_leaves_withhold_the_inertia_and_are_no_torque_scale(loaded_log):
    """Regression (a spring the arm's model lacks, on joints 2 and 4: the torque-scale
    column took it as a factor of 0.969 and the doubt said to read the torques with --units
    tau=1.032, which would not fix it; on a Panda with effects outside its model a load's
    Izz read ten times its truth at 5.5 x the noise and setLoad got it): the fit leaves over
    3 x the torque noise, so the inertia is not written and the doubt says why; the
    torques' scale is no doubt; the mass and CoM are still handed on."""
    import dataclasses

    tau = loaded_log.tau.copy()
    tau[:, 1] += 0.5 * (loaded_log.q[:, 1] - 0.2)
    tau[:, 3] += 0.25 * (loaded_log.q[:, 3] + 2.0)
    est = _estimate(ARM, dataclasses.replace(loaded_log, tau=tau))
    assert est.residual_rms > 3 * est.noise_rms
    assert not [d for d in est.doubts if "x the arm model's" in d], est.doubts
    assert est.undetermined == ("Ixx", "Ixy", "Ixz", "Iyy", "Iyz", "Izz")
    (said,) = est.inertia_doubts
    assert "is not determined" in said and "x the torque noise" in said and "--unloaded" in said
    d = payload_to_dict(est, ARM)
    assert d["load_inertia"] is None and d["load_mass"] is not None


def test_an_inertia_fitted_above_three_times_the_noise_is_doubted_whatever_its_std():
    """inertia_doubts with no element undetermined by its standard deviation: a fit that
    leaves 5.5 x the torque noise is doubted as a whole (the cause and --unloaded said), one
    at 2 x is not."""
    from dynid.feasibility.payload_doubts import inertia_doubts

    I, std = INERTIA, np.full(6, 1e-5)
    (said,) = inertia_doubts((), I, std, 0.275, 0.05, unexplained=True)
    assert "does not explain the torques to their noise" in said and "5.5 x the torque" in said
    assert "--unloaded" in said and "setLoad's inertia is not written" in said
    assert inertia_doubts((), I, std, 0.1, 0.05) == ()
