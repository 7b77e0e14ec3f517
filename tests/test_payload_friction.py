"""The friction a payload fit estimates beside the load, chosen as identification chooses it.

Reference: simulated truth. The loaded arm's torques are computed here, ``rnea`` of the
arm with the load added by ``Robot.with_tool`` plus a friction the classical law cannot
hold (viscous, a Coulomb term rounded by ``tanh(dq / 0.01)``, a Stribeck bump of 0.6
``fc`` at 0.08 rad/s) and a 0.8 N m offset on joint 2, with seeded white noise; the
load's known mass and CoM are the answer.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DataError, DynidWarning
from dynid.feasibility.payload import identify_payload
from dynid.identification.log import TorqueLog
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.static_data import save_static_csv
from dynid.simulation.trajectories import random_fourier, uniform_times

MASS = 1.2
COM = np.array([0.01, 0.0, 0.08])
INERTIA = np.diag([0.006, 0.007, 0.003])
FC = np.array([0.6, 0.7, 0.5, 0.5, 0.35, 0.3, 0.25])
FV = np.array([0.25, 0.3, 0.2, 0.2, 0.12, 0.1, 0.06])
OFFSET = np.array([0.0, 0.8, 0.0, 0.0, 0.0, 0.0, 0.0])
ARM = dynid.panda()
DURATION, RATE = 6.0, 250.0  # [s], [Hz]


def _friction(dq):
    """The true friction [N m] at joint velocities ``dq`` [rad/s]: smooth Stribeck."""
    bump = 0.6 * FC * np.exp(-((dq / 0.08) ** 2))
    return FV * dq + (FC + bump) * np.tanh(dq / 0.01) + OFFSET


def _log(seed):
    """A short log of the loaded arm with the true friction and noise."""
    rng = np.random.default_rng(seed)
    traj = random_fourier(ARM, rng, q0=dynid.PANDA_NEUTRAL_Q)(uniform_times(DURATION, RATE))
    loaded = ARM.with_tool(np.eye(4), MASS, COM, INERTIA, name="load")
    tau = dynid.rnea(loaded, traj.q, traj.dq, traj.ddq) + _friction(traj.dq)
    tau = tau + rng.normal(0.0, 0.05, tau.shape)
    q = traj.q + rng.normal(0.0, 1e-4, traj.q.shape)
    dq = traj.dq + rng.normal(0.0, 1e-3, traj.dq.shape)
    return TorqueLog(traj.t, q, dq, tau)


@pytest.fixture(scope="module")
def logs():
    """Two seeded recordings of the loaded arm."""
    return [_log(3), _log(4)]


def _quiet(fn, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return fn(*args, **kw)


def test_a_stribeck_friction_is_chosen_and_the_load_trusted(logs):
    """Regression (a 1.2 kg load found to 0.03 % yet "not a load to trust", the classical
    friction leaving 9.2 x the torque noise): the friction identify chooses is estimated
    beside the load, the fit is near the noise, the load trusted and within 3 std."""
    est = _quiet(identify_payload, ARM, logs, names=["a.csv", "b.csv"])
    assert est.plausible, est.doubts
    assert "stribeck" in est.friction_terms
    assert est.residual_rms < 1.5 * est.noise_rms
    assert abs(est.mass - MASS) < 3 * est.std_mass and est.std_mass < 0.01 * MASS
    assert np.all(np.abs(est.com - COM) < 3 * est.std_com + 1e-4)
    assert abs(est.friction[1, 2] - 0.8) < 0.05  # the offset of joint 2, estimated alongside
    said = " ".join(est.notes)
    assert "the classical friction fv, fc, fo beside the load leaves" in said


def test_the_classical_friction_alone_leaves_the_load_in_doubt(logs):
    """The same data with the classical friction forced (``terms=None``): the misfit is
    real for that model, so the load stays in doubt."""
    est = _quiet(identify_payload, ARM, logs, terms=None)
    assert est.friction_terms == "viscous + coulomb + offset"
    assert est.doubts and est.residual_rms > 3 * est.noise_rms


def test_a_wrong_description_stays_in_doubt_with_the_chosen_friction(logs):
    """A description whose link 4 is 0.5 kg too heavy: the friction chosen fits the
    friction, not the links, so the misfit stays and the load is doubted."""
    phi = np.array(ARM.phi, dtype=float).reshape(ARM.n, 10)
    phi[3, 0] += 0.5
    wrong = ARM.with_params(phi.ravel())
    est = _quiet(identify_payload, wrong, logs)
    assert "stribeck" in est.friction_terms  # the friction's choice is the data's
    assert est.residual_rms > 3 * est.noise_rms and not est.plausible
    assert any("torque noise" in d for d in est.doubts)


def test_a_model_identified_from_the_loaded_recordings_is_named_as_holding_the_load(logs):
    """Regression (payload --model of a model identified from the loaded logs gave
    1.6e-05 kg, "unloaded data, or a load too light"): the recordings are recognised by
    their samples, whatever they are called, and the cause named."""
    terms = Structure.parse("viscous,smooth:10,stribeck:0.08,offset")
    model = _quiet(identify_recordings, ARM, logs, ["rec1.csv", "rec2.csv"], structure=terms)
    renamed = [dataclasses.replace(log) for log in logs]
    with pytest.raises(DataError, match="already hold the load"):
        _quiet(identify_payload, model, renamed, names=["x.csv", "y.csv"])


def test_terms_given_fix_the_friction_and_an_armature_is_refused(logs):
    """``terms`` given: its friction parts with an offset are estimated beside the load;
    an armature (the arm's model's term) is refused by name."""
    terms = Structure.parse("viscous,smooth:10,stribeck:0.08")
    est = _quiet(identify_payload, ARM, logs[:1], terms=terms)
    assert est.friction_terms.endswith("+ offset") and "stribeck" in est.friction_terms
    with pytest.raises(dynid.OptionError, match="armature"):
        identify_payload(ARM, logs[:1], terms=Structure.parse("armature,viscous"))


def test_cli_terms_apply_to_torque_logs_only(tmp_path, capsys):
    """``payload --terms`` with static data is refused naming the flag, as identify's is."""
    ctrl = dynid.SimulatedController(ARM, relative_noise=1e-4, rng=np.random.default_rng(5))
    save_static_csv(tmp_path / "s.csv", dynid.acquire_static(ctrl, 30, np.random.default_rng(6)))
    argv = ["payload", "--robot", "panda", "--data", str(tmp_path / "s.csv")]
    assert main([*argv, "--terms", "viscous,offset", "--out", str(tmp_path / "p")]) == 2
    assert "--terms" in capsys.readouterr().err
