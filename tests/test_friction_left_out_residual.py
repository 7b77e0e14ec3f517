"""A residual that follows a joint's velocity where the model left that joint's friction
out is said to be that friction, with the recordings of opposite sign that average it to
nothing as a cause (it was called "friction the law misses", and the friction laws
compared, for a model fitted to two recordings of opposite signs on joint 7).

References: a simulated Panda recording with known viscous and Coulomb friction on every
joint, exact, identified with joint 7's left out; residuals of a known Coulomb step plus white
noise.
"""

from __future__ import annotations

import numpy as np

import dynid
from dynid.friction.model import ClassicalFriction
from dynid.identification.residual_dependence import dependence_hint, friction_left_out
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure

from conftest import recordings


def test_the_friction_a_model_left_out_is_named_where_the_residual_follows_the_velocity():
    """Joint 7's viscous and Coulomb friction left out of the structure: the model reports
    fv7 and fc7 left out, and the residual's velocity dependence there (a 0.3 N m Coulomb
    step) names them instead of the friction laws."""
    panda = dynid.panda()
    fr = ClassicalFriction(np.full(7, 0.2), np.full(7, 0.3), np.zeros(7))
    logs = recordings(panda, (61,), friction=fr, duration=3.0)
    model = identify_recordings(
        panda, logs, cutoff_hz=None, structure=Structure.parse("viscous, coulomb, -fv7, -fc7")
    )
    gone = friction_left_out(model)
    assert gone == {6: ("fv7", "fc7")}, gone
    assert friction_left_out(panda) == {}
    rng = np.random.default_rng(62)
    N, sigma = 4000, 0.05
    q, dq = rng.uniform(-1.0, 1.0, (N, 7)), rng.normal(0.0, 0.5, (N, 7))
    e = rng.normal(0.0, sigma, (N, 7))
    e[:, 6] += 0.3 * np.sign(dq[:, 6])
    names = panda.joint_names
    said = dependence_hint([q], [dq], [e], np.full(7, sigma), names, left_out=gone)
    assert said is not None and said.startswith("joint7: 0.3 of 0.3 N m RMS residual follows its")
    assert "friction the model left out there (fv7, fc7 dropped by its fit" in said, said
    assert "disagree in joint7's torque sign" in said and "the law misses" not in said
    plain = dependence_hint([q], [dq], [e], np.full(7, sigma), names)
    assert plain is not None and "friction the law misses" in plain
