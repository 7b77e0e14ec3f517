"""The structural base parameters computed once per robot and base terms while
:func:`dynid.identification.core.shared_bases` is active, and a friction term's labels."""

from __future__ import annotations

import numpy as np

from dynid.identification.core import model_columns, shared_bases
from dynid.model.drive import Drive
from dynid.regressors.base import base_parameters
from dynid.regressors.terms import LinearFriction, RotorInertia


class _Torques:
    """The part of a data set :func:`model_columns` reads: its regressor kind."""

    regressor_kind = "torque"
    moving = True


def _same(a, b) -> None:
    assert a.labels == b.labels and a.std_labels == b.std_labels and a.rank == b.rank
    np.testing.assert_array_equal(a.independent, b.independent)
    np.testing.assert_array_equal(a.dependent, b.dependent)
    np.testing.assert_array_equal(a.K_d, b.K_d)


def test_shared_bases_are_those_of_each_robot_and_rotor_terms(planar2r):
    """Within the block, equal rotor terms (built apart) read one base, a term holding one
    rotor its own, each equal to base_parameters computed alone; a caller writing into
    its arrays leaves the next call's as they were."""
    geared = Drive.from_gears([50.0, 80.0], rotor_inertia=None)
    friction = LinearFriction(Drive.identity(2))
    one = RotorInertia(geared, mask=(False, True))
    ref = base_parameters(planar2r, kind="torque", terms=(RotorInertia(geared),))
    ref_one = base_parameters(planar2r, kind="torque", terms=(one,))
    with shared_bases():
        first = model_columns(planar2r, _Torques(), terms=(RotorInertia(geared), friction)).base
        first.K_d[...] = 1e9
        again = model_columns(planar2r, _Torques(), terms=(RotorInertia(geared),)).base
        moved = model_columns(planar2r, _Torques(), terms=(one,)).base
        plain = model_columns(planar2r, _Torques(), terms=(friction,)).base
    _same(again, ref)
    _same(moved, ref_one)
    assert "Ia1" not in ref_one.std_labels
    _same(plain, base_parameters(planar2r, kind="torque"))
    assert "Ia1" in ref.std_labels and "Ia1" not in plain.std_labels


def test_friction_labels_follow_parts_mask_and_prefix():
    """Labels per motor in the parts' order, the masked coefficients left out, the
    prefix before each."""
    term = LinearFriction(
        Drive.identity(2),
        parts=("viscous", "coulomb", "offset"),
        mask=(True, False, True, True, True, False),
        prefix="j",
    )
    assert term.labels == ("jfv1", "jfo1", "jfv2", "jfc2")
    assert LinearFriction(Drive.identity(2)).labels == ("fv1", "fc1", "fo1", "fv2", "fc2", "fo2")


def test_static_identify_and_retrieve_compute_the_base_once(tmp_path, monkeypatch):
    """Regression: identify on static data computed the structural base twice (the
    outlier search's fit and the fit itself: 4.6 s of 9 s for a 50-joint arm), retrieve
    --static too; now once each, and the fit still predicts Pinocchio's M and g."""
    import dynid
    import dynid.identification.core as core
    from dynid.identification.data import StaticDataset
    from dynid.io.static_data import save_static_csv
    from dynid.workflows.identify import identify_files
    from dynid.workflows.retrieve import RetrieveOptions, retrieve_files

    from conftest import pinocchio_panda_static

    q, M, g = pinocchio_panda_static(21, 40)
    save_static_csv(tmp_path / "s.csv", StaticDataset(q, M, g))
    calls = []
    monkeypatch.setattr(
        core, "base_parameters", lambda *a, **k: calls.append(1) or base_parameters(*a, **k)
    )
    robot = dynid.panda()
    model = identify_files(robot, tmp_path / "s.csv").model
    assert len(calls) == 1
    q2, M2, g2 = pinocchio_panda_static(22, 5)
    np.testing.assert_allclose(model.gravity_torques(q2), g2, atol=1e-8)
    np.testing.assert_allclose(model.mass_matrix(q2), M2, atol=1e-8)
    retrieve_files(tmp_path / "s.csv", RetrieveOptions(method="sdp"), kind="static", robot=robot)
    assert len(calls) == 2
