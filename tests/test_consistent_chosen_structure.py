"""The one-step consistent fit keeps the model structure of the unconstrained fit as it is:
its friction law (a Stribeck term with its fixed velocity), its per-joint leave-outs and
its armature mask, each term kept physical as it declares.

References: the least-squares fit of the same structure on the same held-out blocks (the
consistent fit cannot predict better than least squares and must not predict worse than
its tolerance); the velocity limits of the robot for the dissipation of the friction kept
(evaluated here directly from the law's parameters, ``f(v) v >= 0``); the structure named
by ``--terms``.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning
from dynid.identification.log import TorqueLog
from dynid.io.torque_log import save_torque_log
from dynid.model.drive import Drive
from dynid.regressors.terms import LinearFriction
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.simulation.unmodelled import UnmodelledEffects
from dynid.workflows.identify import IdentifyOptions, identify_files

TERMS = "viscous,coulomb,stribeck:0.2,offset,-fo3"


@pytest.fixture(scope="module")
def log_file(tmp_path_factory):
    """Exact torques of the Panda with its own (sigmoid) friction: a Stribeck structure
    fits them to a small, non-zero error."""
    robot = dynid.panda()
    traj = random_fourier(robot, np.random.default_rng(3))(sample_times(8.0, 200.0))
    log = simulate_measurement(robot, traj, rng=np.random.default_rng(4), noise=SensorNoise.none())
    path = tmp_path_factory.mktemp("chosen") / "log.csv"
    save_torque_log(path, log)
    return path


@pytest.fixture(scope="module")
def consistent(log_file):
    opt = IdentifyOptions(terms=TERMS, consistent=True, prior="panda", prior_weight=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return identify_files(dynid.panda(), log_file, opt).consistent


def test_the_consistent_fit_reaches_the_held_out_error_of_its_structure(consistent):
    j = consistent.heldout
    assert j is not None and j.ls_heldout_percent > 0
    # least squares is the lower bound on the data; the consistent fit within 5 % of it
    assert j.heldout_percent <= 1.05 * j.ls_heldout_percent
    assert consistent.feasible


def test_the_consistent_fit_keeps_the_law_and_its_leave_outs(consistent):
    fr = consistent.friction
    assert fr.law.name == "stribeck"
    P = np.asarray(fr.params)  # fv, fc, fs, vst, fo per joint
    np.testing.assert_array_equal(P[:, 3], 0.2)  # the Stribeck velocity as fixed
    assert P[2, 4] == 0.0  # fo3 left out
    # physical: fv, fc >= 0 and the friction opposes the motion within the limits
    assert np.all(P[:, :2] >= 0.0)
    v = np.linspace(1e-4, 1.0, 2001)[:, None] * dynid.panda().dq_max[None, :]
    f = P[:, 0] * v + P[:, 1] + (P[:, 2] - P[:, 1]) * np.exp(-((v / 0.2) ** 2))
    assert np.all(f >= -1e-9)


def test_dissipation_rows_allow_a_rising_friction_and_refuse_a_pushing_one():
    """fs below fc (a friction that rises from standstill) is physical; fs < 0 is not."""
    term = LinearFriction(Drive.identity(1), parts=("coulomb", "stribeck"), vst=0.1)
    G = term.dissipation_rows(np.array([2.0]))
    assert np.all(G @ np.array([0.5, -0.3]) >= 0)  # fc 0.5, fs 0.2
    assert np.any(G @ np.array([0.5, -0.6]) < 0)  # fs = -0.1: pushes near standstill
    assert not term.nonnegative[1]  # the Stribeck excess has no sign of its own


def test_leave_outs_given_with_terms_are_honoured(log_file, tmp_path):
    argv = ["identify", "--robot", "panda", "--data", str(log_file), "--consistent"]
    argv += ["--terms", f"armature,{TERMS},-ia3", "--prior", "panda", "--prior-weight", "1"]
    argv += ["--no-figures", "-q"]  # a given weight: no search (the test is of the structure)
    assert main([*argv, "--out", str(tmp_path / "c")]) == 0
    d = json.loads((tmp_path / "c" / "feasible.json").read_text())
    fr = d["linear_friction"]
    assert fr["model"] == "stribeck" and fr["vst"] == [0.2] * 7
    assert fr["fo"][2] == 0.0 and all(x != 0.0 for x in fr["fo"][:2] + fr["fo"][3:])
    ia = d["drive"]["rotor_inertia"]  # the armature held on every joint but joint 3
    assert len(ia) == 7 and ia[2] == 0.0 and min(ia) >= 0.0
    ident = json.loads((tmp_path / "c" / "identification.json").read_text())
    labels = [lab for t in ident["terms"] for lab in t["labels"]]
    assert "Ia1" in labels and "fo1" in labels and "Ia3" not in labels and "fo3" not in labels


def test_dissipation_rows_bound_a_saturating_quadratic_viscous_at_the_limit():
    """``fv v + fq v |v| >= 0`` up to ``v_max = 2`` rad/s holds iff ``fv + 2 fq >= 0``."""
    term = LinearFriction(Drive.identity(1), parts=("viscous", "quadratic"))
    G = term.dissipation_rows(np.array([2.0]))
    assert np.all(G @ np.array([1.0, -0.45]) >= 0)  # 1 - 0.9 >= 0
    assert np.any(G @ np.array([1.0, -0.55]) < 0)  # 1 - 1.1 < 0 at the limit
    assert not term.nonnegative[1] and term.nonnegative[0]


def test_dissipation_rows_leave_the_offset_aside():
    """The offset is a constant torque of either sign, not friction: its column is zero in
    ``G`` and a negative offset beside friction that opposes the motion is physical."""
    term = LinearFriction(Drive.identity(1), parts=("viscous", "coulomb", "offset"))
    G = term.dissipation_rows(np.array([2.0]))
    assert G.shape[0] > 0 and np.all(G[:, 2] == 0.0)
    assert np.all(G @ np.array([0.2, 0.3, -5.0]) >= 0)
    assert np.any(G @ np.array([0.2, -0.3, 0.0]) < 0)  # fc < 0 still refused


def test_a_consistent_fit_keeps_a_negative_offset(tmp_path):
    """Exact torques of the Panda's links with viscous and Coulomb friction and offsets of
    either sign (-0.5 N m at joint 4): the consistent fit returns the data's offsets (the
    closed form: the constant in the torques) and friction. Offsets kept inside the
    dissipation rows came out pulled towards ``-fc`` (fo4 -0.38, fo2 +0.43 for +0.3)."""
    robot = dynid.panda()
    fo = np.array([0.0, 0.3, 0.0, -0.5, 0.0, 0.0, 0.0])
    fv, fc = 0.2, 0.3
    traj = random_fourier(robot, np.random.default_rng(3))(sample_times(8.0, 200.0))
    log = simulate_measurement(
        robot, traj, rng=np.random.default_rng(4), noise=SensorNoise.none(), friction=None,
        effects=UnmodelledEffects(np.zeros(7), fo),
    )  # fmt: skip
    tau = log.tau + fv * log.dq + fc * np.sign(log.dq)
    path = save_torque_log(tmp_path / "log.csv", TorqueLog(t=log.t, q=log.q, dq=log.dq, tau=tau))
    opt = IdentifyOptions(
        terms="viscous,coulomb,offset", consistent=True, prior="panda", prior_weight=1e-3
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        P = np.asarray(identify_files(robot, path, opt).consistent.friction.params)
    np.testing.assert_allclose(P[:, 2], fo, atol=0.01)  # fo
    np.testing.assert_allclose(P[:, 0], fv, atol=0.01)
    np.testing.assert_allclose(P[:, 1], fc, atol=0.01)
