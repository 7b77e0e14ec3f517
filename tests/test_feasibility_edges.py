"""Numeric edges of the consistent-parameter methods: penalty weights that do not overflow,
convex problems whose feasibility does not depend on the magnitude of the bounds or of the
prior, default bounds that contain a link's centre of mass.

References: exact coefficients and exact static data of a known robot, which a consistent
answer reproduces (the true parameters are one).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.feasibility import METHODS, RetrievalOptions, SDPOptions, default_bounds
from dynid.feasibility.penalty.options import MAX_WEIGHT
from dynid.identification.data import StaticDataset
from dynid.io.model_json import save_model_json
from dynid.io.robot.toml import save_toml
from dynid.io.static_data import save_static_data

from conftest import exact_model, planar_2r


def test_a_long_penalty_schedule_is_capped_instead_of_overflowing(tmp_path):
    """Regression: ``retrieve --method penalty --stages 200`` ended in "unexpected
    OverflowError" (100**198); the default schedule stops growing at MAX_WEIGHT and the run
    ends feasible."""
    xi = RetrievalOptions(stages=200).schedule()
    assert len(xi) == 200 and all(math.isfinite(x) for x in xi)
    assert list(xi) == sorted(xi) and max(xi) == MAX_WEIGHT
    arm = planar_2r()
    path = save_model_json(tmp_path / "identification.json", exact_model(arm, arm))
    argv = ["retrieve", "--model", str(path), "--method", "penalty", "--stages", "200"]
    argv += ["--runs", "1", "--workers", "1", "--no-figures", "-q", "--out", str(tmp_path / "o")]
    assert main(argv) == 0
    assert json.loads((tmp_path / "o" / "report.json").read_text())["feasible"]


def test_a_penalty_weight_beyond_the_cap_is_refused_in_one_line(tmp_path, capsys):
    """A prior weight (or a stage's xi) above MAX_WEIGHT is an OptionError naming it, not a
    run whose costs overflow."""
    with pytest.raises(ValueError, match="xi must be in"):
        RetrievalOptions(stages=2, xi=(0.0, 1e300))
    arm = planar_2r()
    path = save_model_json(tmp_path / "identification.json", exact_model(arm, arm))
    argv = ["retrieve", "--model", str(path), "--method", "penalty", "--prior-weight", "1e300"]
    assert main([*argv, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err  # the penalty method takes no prior from the command line
    assert "--prior-weight applies to --method sdp only" in err, err
    assert len(err.strip().splitlines()) == 1


@pytest.fixture(scope="module")
def panda_model_file(tmp_path_factory):
    panda = dynid.panda()
    path = tmp_path_factory.mktemp("panda") / "identification.json"
    return save_model_json(path, exact_model(panda, panda))


def test_a_loose_total_mass_band_is_as_feasible_as_a_tight_one(panda_model_file, tmp_path):
    """Regression: ``retrieve --total-mass 0,7e6`` was infeasible where ``0,1e5`` was
    feasible (the generic prior was scaled to the band's middle, 3.5e6 kg, and the solver
    lost the exact fit to scaling; the band's end moved by 1e-6 of its width, 7 kg). Both
    bands now give the same consistent parameters, and no note blames the band."""
    masses = []
    for band in ("0,1e5", "0,7e6"):
        out = tmp_path / band
        argv = ["retrieve", "--model", str(panda_model_file), "--total-mass", band]
        assert main([*argv, "--no-figures", "-q", "--out", str(out)]) == 0, band
        rep = json.loads((out / "report.json").read_text())
        assert rep["feasible"] and rep["relative_residual"] < 1e-9
        assert not any("total mass" in n for n in rep["notes"] if "bound" in n), rep["notes"]
        links = json.loads((out / "feasible.json").read_text())["links"]
        masses.append(np.array([link["mass"] for link in links]))
    np.testing.assert_allclose(masses[0], masses[1], rtol=1e-4)


@pytest.mark.parametrize("factor", [1e-3, 1e4, 1e6])
def test_the_convex_fit_is_feasible_whatever_the_magnitude_of_the_prior(factor):
    """Regression: a prior 1e4 times heavier than the data (another unit, a wild guess) left
    the convex problem's variables at 1e-4 and the solver reported the exact fit infeasible;
    the problem is scaled by the data's magnitude over the prior's. (The masses are not
    narrowed to a factor of the prior's here: that would exclude the data by design.)"""
    panda = dynid.panda()
    prior = panda.with_params(panda.phi * factor)
    options = SDPOptions(mass_factor=None)
    res = METHODS["sdp"].from_coefficients(exact_model(panda, panda), prior=prior, options=options)
    assert res.feasible and res.status == "optimal" and res.relative_residual < 1e-9


def test_default_bounds_contain_a_centre_of_mass_beyond_the_joint_offsets(tmp_path):
    """Regression: a one-joint arm (a pendulum, no link length) whose centre of mass lies
    0.4 m out: the default bounds boxed the CoM within 5 cm of the joint, so ``identify
    --consistent`` on exact data exited 1; the bounds now contain the link's own CoM."""
    arm = dynid.Robot.from_mdh(
        [0.0],
        [0.0],
        [0.0],
        mass=[2.0],
        com=[[0.4, 0.0, 0.0]],
        inertia=[np.diag([0.01, 0.01, 0.01])],
        gravity=(0.0, -9.81, 0.0),
        name="pendulum",
    )
    b = default_bounds(arm)
    assert np.all(b.com_min[0] < arm.com[0]) and np.all(arm.com[0] < b.com_max[0])
    assert b.mass_min[0] < arm.mass[0] < b.mass_max[0]
    q = np.random.default_rng(3).uniform(-2.0, 2.0, (30, 1))
    data = StaticDataset(q, dynid.mass_matrix(arm, q), dynid.gravity_torques(arm, q))
    static = save_static_data(tmp_path / "static.csv", data)
    save_toml(tmp_path / "arm.toml", arm)
    argv = ["identify", "--robot", str(tmp_path / "arm.toml"), "--data", str(static)]
    assert main([*argv, "--consistent", "--no-figures", "-q", "--out", str(tmp_path / "o")]) == 0
    rep = json.loads((tmp_path / "o" / "report.json").read_text())
    assert rep["feasible"] and rep["relative_residual"] < 1e-9
