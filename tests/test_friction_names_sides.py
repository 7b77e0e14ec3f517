"""dynid friction names the model's own friction by its law, and draws a friction fitted at
the motors where it was fitted.

Reference: the classical law in closed form (``fv v + fc sign(v)``) at motor velocities
``K dq`` computed with numpy; the law's name as :class:`~dynid.friction.model.Friction`
gives it (what validate's verdict and the figure's title say).
"""

from __future__ import annotations

import numpy as np
import pytest

from dynid.friction.fit import FrictionFit, FrictionResidual
from dynid.friction.model import ClassicalFriction, DriveFriction
from dynid.friction.select import OWN, select_friction
from dynid.identification.log import TorqueLog
from dynid.model.drive import Drive


def _residual(rng: np.random.Generator, tau_f, n: int = 2, N: int = 3000) -> FrictionResidual:
    """A log moving every joint back and forth, its residual the friction plus noise."""
    t = 0.01 * np.arange(N)
    dq = np.column_stack([np.sin((0.7 + 0.3 * j) * t) for j in range(n)])
    q = np.cumsum(dq, axis=0) * 0.01
    r = tau_f(dq) + rng.normal(0.0, 0.01, dq.shape)
    log = TorqueLog(t, q, dq, r)
    return FrictionResidual(log=log, tau_model=np.zeros_like(r), residual=r)


def test_the_own_friction_is_named_by_its_law_in_the_table():
    """The model's own friction was the row "own  fv, fc" beside "classical" in the
    figure's title and validate's verdict; the table names it "own (classical)"."""
    rng = np.random.default_rng(21)
    own = ClassicalFriction([0.5, 0.2], [1.0, 0.4], [0.0, 0.0])
    sel = select_friction(_residual(rng, own.torques), own=own)
    assert own.kind == "classical"
    assert sel.label(OWN) == "own (classical)" and sel.label("smooth") == "smooth"
    rows = [line for line in sel.table().splitlines() if "own" in line.split("[")[0]]
    assert any(line[2:].startswith("own (classical)") for line in rows), sel.table()
    assert sel.as_dict()["candidates"][0]["model"] == OWN  # the file keeps its name


def test_the_friction_figure_is_drawn_at_the_motors_it_was_fitted_at():
    """Regression: friction fitted per motor of a coupled drive was drawn against joint
    velocities; each panel now shows motor j's residual against its velocity (K dq) on
    the law's curve, the axes naming the motor side."""
    pytest.importorskip("matplotlib")
    from dynid.plots.friction import plot_friction_fit

    rng = np.random.default_rng(22)
    K = np.array([[10.0, 0.0], [5.0, 20.0]])  # motor 2 turns with both joints
    drive = Drive(K, np.zeros(2), side="motor")
    fv, fc = np.array([0.01, 0.02]), np.array([0.05, 0.03])
    fr = DriveFriction(ClassicalFriction(fv, fc, [0.0, 0.0]), drive)
    res = _residual(rng, fr.torques, N=400)
    res = FrictionResidual(res.log, res.tau_model, fr.torques(res.dq))  # exact
    ones = np.ones(2)
    fit = FrictionFit(fr, ones, ones, np.ones(2, bool), np.zeros(2, int), 400, np.ones(2, bool))
    fig = plot_friction_fit(res, fit, joint_names=["a", "b"], max_points=400)
    v_m = res.dq @ K.T
    for j in range(2):
        ax = fig.axes[j]
        x, y = (np.asarray(a) for a in ax.lines[0].get_data())
        np.testing.assert_allclose(x, v_m[:, j], atol=1e-12)
        np.testing.assert_allclose(y, fv[j] * x + fc[j] * np.sign(x), atol=1e-12)
        xc, yc = (np.asarray(a) for a in ax.lines[1].get_data())
        np.testing.assert_allclose(yc, fv[j] * xc + fc[j] * np.sign(xc), atol=1e-12)
        assert ax.get_xlabel() == "motor velocity [rad/s]"
        assert ax.get_ylabel() == "motor torque [N m]"
        assert ax.get_title().startswith(f"motor {j + 1} ({'ab'[j]})")
    fig.clf()


def test_the_table_says_the_laws_were_fitted_at_the_motors_of_a_geared_drive():
    """Through a drive whose friction acts at its motors (gear ratios 50 and 30; the
    residual the classical law's in closed form at ``K dq``, mapped by ``K^T``) the table
    and the record say the laws were fitted there; without a drive they say nothing of
    motors."""
    rng = np.random.default_rng(22)
    drive = Drive.from_gears([50.0, 30.0])
    fv, fc = np.array([2e-4, 1e-4]), np.array([0.02, 0.01])

    def motors(dq):
        v = dq @ drive.transmission.T
        return (fv * v + fc * np.sign(v)) @ drive.transmission

    sel = select_friction(_residual(rng, motors), drive)
    assert sel.at_motors and "fitted at the drive's motors" in sel.table()
    assert sel.as_dict()["laws_at"] == "motors"
    plain = select_friction(_residual(rng, ClassicalFriction([0.5], [1.0], [0.0]).torques, n=1))
    assert not plain.at_motors and "motors" not in plain.table()
    assert plain.as_dict()["laws_at"] == "joints"
