"""Identified friction that is not dissipative within the velocity limits is named, and
the structure selection does not choose it.

References: closed forms of ``f(v) v`` for the quadratic law (``fv v^2 + fq v^2 |v| +
fc |v|``, negative beyond ``|v|`` where ``fv + fq |v| + fc / |v| = 0``) and for the
Stribeck law at standstill (``fc + fsp < 0`` pushes just outside the band); the Panda's
own friction (a sigmoid that saturates, which a quadratic viscous term follows only with
``fq < 0``).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import dynid
from dynid.exceptions import DynidWarning
from dynid.identification.dissipation import GRID, friction_violations
from dynid.identification.recordings import prepare_recordings
from dynid.identification.selection import select_structure
from dynid.identification.structure import Structure
from dynid.model.drive import Drive
from dynid.regressors.terms import LinearFriction
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier


def _quadratic(n=2):
    return LinearFriction(Drive.identity(n), parts=("viscous", "quadratic", "coulomb", "offset"))


def test_a_quadratic_law_that_turns_negative_is_named_at_the_limit():
    vmax = np.array([2.0, 2.0])
    fv, fq, fc = 0.2, -0.2, 0.1
    # joint 1: fv + fq v + fc / v = 0 at v = (1 + sqrt(1 + 2)) / 2 = 1.37 < 2: negative
    # beyond, worst at the limit; joint 2: fq > 0, and the offset is no friction of motion
    x = np.array([fv, fq, fc, 0.5, 0.2, 0.01, 0.1, -3.0])
    (line,) = friction_violations([(_quadratic(), x)], vmax)
    assert line.startswith("fq1 = -0.2 (joint 1:")
    assert "|v| = 2 rad/s" in line


def test_a_quadratic_law_dissipative_up_to_the_limit_is_not_named():
    # fv + fq vmax + fc / vmax = 0.2 - 0.1 * 2 + 0.1 / 2 > 0: f(v) v >= 0 up to the limit
    x = np.array([0.2, -0.1, 0.1, 0.0, 0.2, -0.1, 0.1, 0.0])
    assert friction_violations([(_quadratic(), x)], np.array([2.0, 2.0])) == ()
    # the same law beyond a higher limit: (0.2 + 0.1 / v) / 0.1 = v at v = 2.22
    (line,) = friction_violations([(_quadratic(), x)], np.array([3.0, np.inf]))
    assert line.startswith("fq1 = -0.1 (joint 1:")


def test_a_stribeck_bump_below_zero_pushes_at_standstill():
    t = LinearFriction(Drive.identity(1), parts=("viscous", "coulomb", "stribeck"), vst=0.05)
    (line,) = friction_violations([(t, np.array([0.1, 0.2, -0.5]))], np.array([2.0]))
    assert line.startswith("fsp1 = -0.5 (joint 1:")
    worst = float(line.split("|v| = ")[1].split(" rad/s")[0])
    # f(v) = 0.1 v + 0.2 - 0.5 exp(-(v / 0.05)^2) < 0 up to v = 0.05 sqrt(ln 2.5) = 0.048
    assert worst == pytest.approx(0.05 * np.sqrt(np.log(2.5)), abs=2 * 2.0 / GRID + 1e-3)


@pytest.fixture(scope="module")
def panda_data():
    robot = dynid.panda()
    logs = []
    for s in (1, 2, 3):
        traj = random_fourier(robot, np.random.default_rng(s))(sample_times(5.0, 400.0))
        logs.append(
            simulate_measurement(robot, traj, rng=np.random.default_rng(s), noise=SensorNoise())
        )
    return robot, prepare_recordings(robot, logs, ["a", "b", "c"])


def test_the_selection_skips_a_law_that_pushes_the_arm(panda_data):
    robot, data = panda_data
    quadratic = Structure(friction=("viscous", "quadratic", "coulomb", "offset"))
    cands = [Structure(friction=()), quadratic]
    sel = select_structure(robot, data, candidates=cands, per_joint=False)
    judged = {c.structure: c for c in sel.candidates}
    # the saturating friction of the Panda is fitted with fq < 0: the quadratic candidate
    # predicts better than the links alone, yet its friction turns negative at speed
    assert judged[quadratic].heldout_error_percent < judged[cands[0]].heldout_error_percent
    assert any(v.startswith("fq") for v in judged[quadratic].unphysical)
    assert sel.chosen == cands[0]
    # the printed table marks the skipped candidate (x) and one line says why
    from dynid.cli.structure_table import selection_lines

    lines = selection_lines(sel.as_dict())
    marks = {line[4:].split("  ")[0].strip(): line[2] for line in lines[2:] if line[2] in "*x "}
    assert marks[sel.chosen.name] == "*" and marks[quadratic.name] == "x", marks
    said = [line for line in lines if "not dissipative" in line]
    assert len(said) == 1 and said[0].startswith("  note: 1 candidate(s) marked x skipped")


def test_identify_warns_of_a_given_law_that_pushes_the_arm(panda_data):
    from dynid.identification.selection import identify_recordings

    robot, _ = panda_data
    logs = [
        simulate_measurement(
            robot,
            random_fourier(robot, np.random.default_rng(s))(sample_times(5.0, 400.0)),
            rng=np.random.default_rng(s),
            noise=SensorNoise(),
        )
        for s in (1, 2, 3)
    ]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DynidWarning)
        identify_recordings(
            robot, logs, structure=Structure.parse("viscous,quadratic,coulomb,offset")
        )
    said = [str(w.message) for w in caught if "not dissipative" in str(w.message)]
    assert said and all("fq" in m and "joint" in m for m in said)


def _friction_log(robot, tmp_path, friction, name):
    from dynid.io.torque_log import save_torque_log

    traj = random_fourier(robot, np.random.default_rng(5))(sample_times(6.0, 400.0))
    log = simulate_measurement(
        robot, traj, rng=np.random.default_rng(6), noise=SensorNoise(), friction=friction
    )
    save_torque_log(tmp_path / name, log)
    return tmp_path / name


def test_quadratic_friction_at_its_bound_is_explained_and_a_true_one_recovered(tmp_path):
    from dynid.friction.laws import LAWS
    from dynid.workflows.friction import FrictionOptions, fit_friction_files

    robot = dynid.panda()
    truth = np.tile([0.2, 0.3, 0.3, 0.0], (7, 1))  # fv, fq, fc, fo per joint
    quad = _friction_log(robot, tmp_path, LAWS["quadratic"].model(truth, None, None), "q.csv")
    own = _friction_log(robot, tmp_path, None, "own.csv")  # the Panda's saturating sigmoid
    opt = FrictionOptions(law="quadratic")
    for path, expect_warning in ((quad, False), (own, True)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", DynidWarning)
            res = fit_friction_files(robot, path, opt)
        said = [str(w.message) for w in caught if "fq held at its bound 0" in str(w.message)]
        assert bool(said) == expect_warning
        if not expect_warning:
            np.testing.assert_allclose(res.fit.friction.params[:, 1], truth[:, 1], rtol=0.1)


def test_a_coefficient_below_zero_within_its_uncertainty_is_no_violation():
    """A joint without Coulomb friction gets an estimate of -0.002 N m from noisy data:
    within 3 of its 0.01 N m standard deviations it is zero, not friction that pushes the
    arm (the selection skipped the true structure for it); 10 standard deviations below
    zero it is a violation."""
    term = LinearFriction(Drive.identity(2), parts=("viscous", "coulomb"))
    x = np.array([0.3, 0.5, 0.0005, -0.002])  # fv1, fc1, fv2, fc2: f2(v) v < 0 below 4 rad/s
    vmax = np.array([2.0, 2.0])
    assert friction_violations([(term, x)], vmax)  # without its uncertainty: fc2 < 0
    assert friction_violations([(term, x)], vmax, [np.full(4, 0.01)]) == ()
    assert friction_violations([(term, x)], vmax, [np.full(4, 0.0002)])


def test_normal_equations_give_the_classical_standard_deviations():
    """``Normals.std``: sqrt(diag(sigma^2 (W^T W)^-1)), sigma^2 = RSS / (rows - p), as
    numpy's least squares and inverse give them, on columns of very different scales."""
    from dynid.identification.holdout import block_normals

    rng = np.random.default_rng(0)
    W = rng.normal(size=(400, 5)) * np.array([1e-3, 1.0, 1e2, 1.0, 10.0])
    y = W @ rng.normal(size=5) + 0.1 * rng.normal(size=400)
    (N,) = block_normals(W, y, np.zeros(400, np.intp))
    x = N.solve()
    ref_x, rss, *_ = np.linalg.lstsq(W, y, rcond=None)
    ref = np.sqrt(rss[0] / (400 - 5) * np.diag(np.linalg.inv(W.T @ W)))
    np.testing.assert_allclose(x, ref_x, rtol=1e-9)
    np.testing.assert_allclose(N.std(x), ref, rtol=1e-8)
