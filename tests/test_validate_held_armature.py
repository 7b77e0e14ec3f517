"""validate never advises adding the armature to a model that holds it.

A 6-DoF arm identified with ``--terms armature``, validated on noise-free held-out data, had
its joint 1 residual (which followed the acceleration) answered with "add armature to
--terms of dynid identify", although the model held the armature: joint 1's grouped with
the link inertias in a base parameter (``J1zz + ... + Ia1``), which the fit does not name
``armature`` (its term is ``rotor_inertia``). The reference: a planar 2R arm simulated with
known rotor inertias (joint 1's grouped with the links' ``Izz`` in a base parameter), its
held-out recording given an extra inertia at joint 1 the model cannot hold, so that the
residual there is that known inertia times the acceleration.
"""

from __future__ import annotations

import numpy as np

from dynid.friction.model import ClassicalFriction
from dynid.identification.residual_dependence import held_terms
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.torque_log import save_torque_log
from dynid.workflows.validate import ValidateOptions, validate_files

from conftest import planar_2r, recordings

#: The rotor inertias [kg m^2] of the arm identified; the held-out arm's joint 1 has EXTRA
#: more, which no model of the training data holds.
ARMATURE = np.array([0.20, 0.10])
EXTRA = np.array([0.15, 0.0])
FV = np.array([0.3, 0.2])  # N m s/rad


def _model_and_heldout(tmp_path):
    """The model identified with the armature on exact recordings, and the path of an exact
    held-out recording with the extra inertia at joint 1."""
    robot = planar_2r()
    fr = ClassicalFriction(FV, np.zeros(2), np.zeros(2))
    train = recordings(robot, (1, 2), friction=fr, duration=3.0, armature=ARMATURE)
    model = identify_recordings(
        robot, train, cutoff_hz=None, structure=Structure.parse("armature, viscous")
    )
    (held,) = recordings(robot, (9,), friction=fr, duration=3.0, armature=ARMATURE + EXTRA)
    return model, save_torque_log(tmp_path / "held.csv", held)


def test_the_armature_grouped_in_a_base_parameter_is_a_held_term(tmp_path):
    """An identified model with the armature (joint 1's only in a base parameter with the
    link inertias) holds the ``armature`` term, as ``--terms`` names it."""
    model, _ = _model_and_heldout(tmp_path)
    assert "armature" in held_terms(model)


def test_validate_does_not_advise_the_armature_the_model_holds(tmp_path):
    """The residual of an inertia beyond the model's (joint 1's extra 0.15 kg m^2) follows
    the acceleration: the verdict says so, beyond the model's armature, and does not advise
    adding the armature to --terms."""
    model, path = _model_and_heldout(tmp_path)
    reason = validate_files(model, path, ValidateOptions(cutoff_hz="none")).verdict.reason
    assert "follows its acceleration" in reason, reason
    assert "add armature to --terms" not in reason, reason
    assert "which holds the armature" in reason, reason
