"""An MJCF's ``frictionloss`` read back as MuJoCo applies it, and the export's warning that
names the smooth law, its width and the ramp MuJoCo holds instead.

Reference: MuJoCo itself (``mj_inverse`` of the file at zero acceleration: the dry
friction's ramp, its slope at rest and its corner); the law's closed form
``fc tanh(dq / w)``.
"""

from __future__ import annotations

import logging
import warnings

import numpy as np
import pytest

import dynid
from dynid.friction.laws import law_named
from dynid.io.robot.mjcf import save_mjcf
from dynid.io.robot.mjcf_read import frictionloss_slopes, load_mjcf

mujoco = pytest.importorskip("mujoco")

FV = np.array([0.6, 0.5, 0.4, 0.4, 0.3, 0.2, 0.1])  # N m s/rad
FC = np.array([1.5, 1.2, 1.0, 1.0, 0.6, 0.5, 0.4])  # N m
WIDTH = 0.02  # rad/s

HINGES = """<mujoco><option timestep="0.002"/><worldbody><body>
  <joint name="a" type="hinge" axis="0 0 1" frictionloss="3" damping="0.2"/>
  <geom type="capsule" size="0.05 0.2" fromto="0 0 0 0.4 0 0" mass="2"/>
  <body pos="0.4 0 0"><joint name="b" type="hinge" axis="0 1 0" frictionloss="1.5"
    solreffriction="-800 -40" solimpfriction="0.5 0.8 0.001"/>
  <geom type="capsule" size="0.04 0.15" fromto="0 0 0 0.3 0 0" mass="1"/></body>
</body></worldbody></mujoco>"""


def _dry_friction(model, dq):
    """MuJoCo's friction torque [N m] (N, nv) at velocities ``dq``, zero acceleration and
    positions: ``mj_inverse`` with ``frictionloss`` minus without it."""
    data = mujoco.MjData(model)
    out = np.empty_like(dq)
    keep = model.dof_frictionloss.copy()
    for s in range(dq.shape[0]):
        data.qvel[:] = dq[s]
        mujoco.mj_inverse(model, data)
        with_it = data.qfrc_inverse.copy()
        model.dof_frictionloss[:] = 0.0
        mujoco.mj_inverse(model, data)
        model.dof_frictionloss[:] = keep
        out[s] = with_it - data.qfrc_inverse
    return out


def _smooth_panda(tmp_path):
    """The Panda exported with a smooth law of width :data:`WIDTH`, its warnings."""
    law = law_named("smooth").model(np.column_stack([FV, FC, np.zeros(7)]), np.full(7, WIDTH))
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        path = save_mjcf(tmp_path / "panda.xml", dynid.panda(), friction=law)
    return path, [str(w.message) for w in got]


def test_the_slopes_read_are_mujocos_at_rest():
    """Default solref/solimp (standard form, raised to two timesteps) and the direct form
    with dmin != dmax: the slope read equals mj_inverse's torque per velocity near rest."""
    model = mujoco.MjModel.from_xml_string(HINGES)
    dq = np.full((1, 2), 1e-5)
    measured = _dry_friction(model, dq)[0] / 1e-5
    np.testing.assert_allclose(frictionloss_slopes(model, np.arange(2)), measured, rtol=1e-9)


def test_an_export_reads_back_as_the_ramp_mujoco_applies(tmp_path, caplog):
    """The Panda exported with a smooth law (width 0.02 rad/s) reads back as MuJoCo applies
    its frictionloss: along velocities across the ramp's corner the friction read is within
    15 % of fc of mj_inverse's (the tanh against the ramp's corner), 5 % RMS (as a sharp
    Coulomb it was up to fc off near rest), its width within 10 % of the law's, and a note
    names the file and the widths."""
    path, _ = _smooth_panda(tmp_path)
    with caplog.at_level(logging.INFO):
        robot = load_mjcf(path)
    model = mujoco.MjModel.from_xml_path(str(path))
    v = np.linspace(-0.2, 0.2, 81)
    dq = np.repeat(v[:, None], 7, axis=1)
    applied = _dry_friction(model, dq) + FV * dq  # MuJoCo's dry friction and damping
    read = robot.friction.torques(dq)
    off = np.abs(read - applied) / FC
    assert np.max(off) < 0.15 and np.sqrt(np.mean(off**2)) < 0.05
    sharp = FV * dq + FC * np.sign(dq)
    assert np.max(np.abs(sharp - applied) / FC) > 0.5  # what the classical reading held
    np.testing.assert_allclose(robot.friction.band, WIDTH, rtol=0.1)
    said = " ".join(r.getMessage() for r in caplog.records)
    assert "panda.xml: frictionloss read as MuJoCo applies it" in said and "width 0.0" in said


def test_the_export_warns_once_with_the_width_and_the_ramp(tmp_path):
    """One warning names the smooth law, its width, and the ramp MuJoCo applies instead:
    the velocity it reaches fc at, as mj_inverse of the file shows (fc over its slope)."""
    path, said = _smooth_panda(tmp_path)
    assert len(said) == 1
    text = said[0]
    assert "fc tanh(dq / width) (width 0.02 rad/s)" in text
    assert "ramp of the velocity MuJoCo applies" in text
    model = mujoco.MjModel.from_xml_path(str(path))
    slope = _dry_friction(model, np.full((1, 7), 1e-5))[0] / 1e-5
    corner = FC / slope
    lo, hi = f"{corner.min():.3g}", f"{corner.max():.3g}"
    assert f"|dq| = {lo}-{hi} rad/s" in text
