"""Rank decisions that do not depend on units or gear ratios (issue 26, item 3).

A rotor's column grows with the square of its gear ratio and a change of units scales each
family of columns (masses, first moments, inertias) by its own power of ten: the base set
must not move. References: the rank of the column-normalised random-state regressor
(numpy's SVD), the regressor of the same arm written in millimetres (the kinematics in mm,
gravity in mm/s^2), and Pinocchio's RNEA plus the drive terms written out
(``tests/test_drive.py``) for held-out torques.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.exceptions import RankDeficientError
from dynid.identification.least_squares import fit_with_pruning, unexcited_combinations
from dynid.model.drive import Drive
from dynid.regressors.base import base_parameters, base_parameters_from_regressor, link_families
from dynid.regressors.terms import drive_terms

PI = np.pi
#: Gear-ratio shape of a six-axis arm (times the ratio of the sweep), wrist coupled.
SHAPE = np.array([1.2, 1.2, 1.0, 0.7, 0.7, 0.5])


def _industrial(mm: bool = False) -> dynid.Robot:
    """The six-axis arm of the coupled-wrist tutorial, in m (or mm: kinematics, centres of
    mass, inertias and gravity converted)."""
    u = 1e3 if mm else 1.0
    return dynid.Robot.from_mdh(
        a=u * np.array([0.0, 0.26, 0.68, 0.035, 0.0, 0.0]),
        d=u * np.array([0.675, 0.0, 0.0, 0.67, 0.0, 0.0]),
        alpha=[0.0, -PI / 2, 0.0, -PI / 2, PI / 2, -PI / 2],
        mass=[40.0, 35.0, 20.0, 10.0, 4.0, 1.0],
        com=u
        * np.array(
            [
                [0.0, -0.05, -0.15],
                [0.34, 0.0, 0.05],
                [0.0, 0.0, 0.02],
                [0.0, -0.25, 0.0],
                [0.0, 0.0, 0.01],
                [0.0, 0.0, 0.02],
            ]
        ),
        inertia=u**2
        * np.array(
            [
                [1.2, 0.0, 0.0, 1.1, 0.0, 0.8],
                [0.4, 0.0, 0.0, 1.6, 0.0, 1.5],
                [0.3, 0.0, 0.0, 0.3, 0.0, 0.1],
                [0.25, 0.0, 0.0, 0.05, 0.0, 0.25],
                [0.01, 0.0, 0.0, 0.01, 0.0, 0.008],
                [0.002, 0.0, 0.0, 0.002, 0.0, 0.003],
            ]
        ),
        gravity=(0.0, 0.0, -9.81 * u),
        name="industrial",
    )


def _drive(ratio: float) -> Drive:
    """Gear ratios ``ratio * SHAPE``, motor 6 turning with joint 5 too, rotors identified."""
    return Drive.from_gears(ratio * SHAPE, [(6, 5, 0.6 * ratio)], side="motor")


def _normalised_rank(robot: dynid.Robot, drive: Drive) -> int:
    """numpy's rank of the random-state torque regressor with unit columns (zero columns
    left out), the reference for a complete base."""
    from dynid.regressors.torque import torque_regressor

    rng = np.random.default_rng(3)
    q = rng.uniform(-PI, PI, (64, 6))
    dq, ddq = rng.uniform(-2, 2, q.shape), rng.uniform(-5, 5, q.shape)
    W = np.concatenate([torque_regressor(robot, q, dq, ddq), drive.rotor_columns(ddq)], axis=-1)
    W = W.reshape(-1, W.shape[-1])
    n = np.linalg.norm(W, axis=0)
    keep = n > 1e-9 * n.max()
    return int(np.linalg.matrix_rank(W[:, keep] / n[keep], tol=1e-9))


@pytest.mark.parametrize("kind", ["torque", "static"])
def test_base_set_is_the_same_for_every_gear_ratio_from_1_to_200(kind):
    """Rotor columns from 1 to 40,000 times a link inertia's: the same rank, independent
    columns and combinations (K_d scaled by the ratio squared) at every gear ratio, and the
    rank is numpy's of the normalised regressor."""
    robot = _industrial()
    ref = base_parameters(robot, kind=kind, terms=drive_terms(_drive(1.0), 6, friction=False))
    assert ref.rank == _normalised_rank(robot, _drive(1.0))
    for ratio in (2.0, 10.0, 50.0, 100.0, 150.0, 200.0):
        bp = base_parameters(robot, kind=kind, terms=drive_terms(_drive(ratio), 6, friction=False))
        assert bp.rank == ref.rank, ratio
        np.testing.assert_array_equal(bp.independent, ref.independent)
        np.testing.assert_array_equal(bp.dependent, ref.dependent)


def test_base_set_is_the_same_in_millimetres_and_newton_millimetres():
    """The arm written in mm (masses' columns 1e3, first moments' 1, inertias' 1e-3 of the
    SI ones in N mm): the same base set, K_d converted by the units of its entries, and the
    same with geared rotors."""
    for drive in (None, _drive(100.0)):
        terms = () if drive is None else drive_terms(drive, 6, friction=False)
        si = base_parameters(_industrial(), kind="torque", terms=terms)
        mm = base_parameters(_industrial(mm=True), kind="torque", terms=terms)
        assert mm.rank == si.rank
        np.testing.assert_array_equal(mm.independent, si.independent)
        # parameter units: m [kg], mc [kg mm] = 1e3 [kg m], J and Ia [kg mm^2] = 1e6 [kg m^2]
        unit = np.concatenate([np.tile([1.0, 1e3, 1e3, 1e3] + [1e6] * 6, 6), np.full(6, 1e6)])
        unit = unit[: si.n_std]
        expect = si.K_d * unit[si.independent][:, None] / unit[si.dependent][None, :]
        np.testing.assert_allclose(mm.K_d, expect, rtol=1e-8, atol=1e-9 * np.abs(expect).max())


def test_column_and_row_scaling_leave_the_base_of_a_regressor_unchanged():
    """Scales of 1e-3 .. 1e3 per family (units; round-off is what falls below 1e-12 of the
    largest column) and of the rows (mN m): the same base."""
    robot = _industrial()
    drive = _drive(80.0)
    rng = np.random.default_rng(4)
    q = rng.uniform(-PI, PI, (40, 6))
    dq, ddq = rng.uniform(-2, 2, q.shape), rng.uniform(-5, 5, q.shape)
    from dynid.regressors.torque import torque_regressor

    W = np.concatenate([torque_regressor(robot, q, dq, ddq), drive.rotor_columns(ddq)], axis=-1)
    W = W.reshape(-1, 66)
    fam = link_families(6, 6)
    ref = base_parameters_from_regressor(W, families=fam)
    for _ in range(3):
        per_family = 10.0 ** rng.uniform(-3, 3, fam.max() + 1)
        bp = base_parameters_from_regressor(1e3 * W * per_family[fam], families=fam)
        np.testing.assert_array_equal(bp.independent, ref.independent)


def test_unexcited_combinations_are_named_whatever_the_basis():
    """Columns 1 and 3 never excited and column 4 = 2000 x column 0: three combinations,
    each with a label of its own, in the columns' units, the same from the fit's pivoted
    factor as from an unpivoted one."""
    rng = np.random.default_rng(5)
    A = rng.normal(size=(200, 3))
    W = np.column_stack([A[:, 0], 0 * A[:, 0], A[:, 1], 0 * A[:, 0], 2e3 * A[:, 0], A[:, 2]])
    labels = ("a", "b", "c", "d", "e", "f")
    with pytest.raises(RankDeficientError) as info:
        fit_with_pruning(W, A @ [1.0, 2.0, 3.0], labels=labels)
    assert info.value.rank == 3 and len(info.value.combinations) == 3
    norms = np.linalg.norm(W, axis=0)
    scale = np.where(norms > 0, norms, 1.0)
    R = np.linalg.qr(W / scale, mode="r")
    combos = unexcited_combinations(R, scale, 3, labels)
    assert {"b", "d"} <= set(combos) and combos == info.value.combinations
    pair = next(c for c in combos if c not in ("b", "d"))
    assert pair in ("e - 2000*a", "a - 0.0005*e")


def test_identify_names_every_combination_a_still_wrist_leaves_unexcited():
    """A motor-side log whose joints 5 and 6 never move: the rotor inertias of motors 5 and
    6 are not excited; the error names both, with their base parameters' meaning."""
    from dynid.identification.classical import identify_from_log
    from dynid.identification.log import TorqueLog

    robot = _industrial()
    drive = _drive(60.0)
    t = np.arange(0.0, 4.0, 1 / 200)
    rng = np.random.default_rng(6)
    w, ph = rng.uniform(1.0, 3.0, 6), rng.uniform(0, 2 * PI, 6)
    amp = np.array([0.5, 0.4, 0.4, 0.6, 0.0, 0.0])
    q = amp * np.sin(w * t[:, None] + ph) + 0.2
    dq = amp * w * np.cos(w * t[:, None] + ph)
    ddq = -amp * w**2 * np.sin(w * t[:, None] + ph)
    tau = dynid.rnea(robot, q, dq, ddq) + drive.rotor_torques(ddq, np.full(6, 1e-4))
    K = drive.transmission
    log = TorqueLog(t, q @ K.T, dq @ K.T, np.linalg.solve(K.T, tau.T).T, ddq @ K.T)
    with pytest.warns(Warning), pytest.raises(RankDeficientError) as info:
        identify_from_log(
            robot,
            log,
            cutoff_hz=None,
            decimate=1,
            drive=drive,
            structure="classical",
            estimator="ols",
        )
    msg = str(info.value)
    assert "not excited by the data" in msg and "the model's structural rank" in msg
    assert "= Ia5" in msg and "= Ia6" in msg
    assert len(info.value.combinations) == info.value.needed - info.value.rank


def test_the_scaled_rank_and_least_squares_ignore_column_units() -> None:
    import scipy.linalg

    from dynid.identification.solvers import column_scale, pivoted_rank, scaled_lstsq

    rng = np.random.default_rng(5)
    W = rng.standard_normal((200, 6))
    W[:, 5] = W[:, 1] - 2.0 * W[:, 3]  # one combination the rows cannot excite
    units = np.array([1e-6, 1.0, 1e4, 1e-3, 1.0, 1e5])  # mm, gear ratios squared, ...
    for Wu in (W, W * units):
        R = scipy.linalg.qr(Wu / column_scale(Wu), mode="r", pivoting=True)[0]
        assert pivoted_rank(R, 1e-9) == np.linalg.matrix_rank(W) == 5
    x = rng.standard_normal(5)
    y = W[:, :5] @ x
    np.testing.assert_allclose(scaled_lstsq(W[:, :5] * units[:5], y) * units[:5], x, rtol=1e-9)
    assert np.array_equal(column_scale(np.zeros((3, 2))), np.ones(2))
