"""The registry of consistent-parameter methods: every method answers "from coefficients" and
"from data" with one signature, and an option that does not apply to a method is refused.

References: the coefficients of the true parameters (``P phi_true``) and the static data of
the true robot, which every consistent answer must reproduce.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import build_parser, main
from dynid.exceptions import OptionError, WrongTypeError
from dynid.feasibility import METHODS, FeasibleResult, RetrievalOptions, SDPOptions, method
from dynid.identification.data import StaticDataset
from dynid.identification.log import TorqueLog
from dynid.io.model_json import save_model_json

from conftest import exact_model, planar_2r, random_states

#: the options of each method that keep the tests short
SHORT = {"sdp": SDPOptions(), "penalty": RetrievalOptions(runs=2, stages=3)}


@pytest.fixture(scope="module")
def arm() -> dynid.Robot:
    return planar_2r()


@pytest.mark.parametrize("name", list(METHODS))
def test_every_method_answers_from_coefficients_and_from_data(arm, name):
    """Each registered method, called through the registry with the same arguments, returns a
    consistent FeasibleResult that reproduces exact coefficients and exact static data."""
    m = METHODS[name]
    assert m.name == name and isinstance(SHORT[name], m.options_type)
    workers = 1 if m.parallel else None
    res = m.from_coefficients(exact_model(arm, arm), options=SHORT[name], workers=workers)
    assert isinstance(res, FeasibleResult) and res.method == name and res.kind == "coefficients"
    assert res.feasible and res.relative_residual < 1e-4
    q = random_states(arm, 30, 5)[0]
    data = StaticDataset(q, dynid.mass_matrix(arm, q), dynid.gravity_torques(arm, q))
    one = m.from_data(arm, data, options=SHORT[name], workers=workers)
    assert one.method == name and one.kind == "static" and one.feasible
    np.testing.assert_allclose(
        dynid.gravity_torques(one.robot, q), data.g, atol=1e-4 * np.abs(data.g).max()
    )


def test_the_retrieve_command_offers_exactly_the_registered_methods():
    """--method's choices are the registry's names, the first its default."""
    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    action = next(a for a in sub.choices["retrieve"]._actions if a.dest == "method")
    assert tuple(action.choices) == tuple(METHODS) and action.default == next(iter(METHODS))


def test_an_unknown_method_or_another_methods_options_are_refused(arm):
    """method('x') names the choices; each method refuses the other's options."""
    with pytest.raises(OptionError, match="choose from sdp, penalty"):
        method("lmi")
    model = exact_model(arm, arm)
    with pytest.raises(WrongTypeError, match="takes SDPOptions; got RetrievalOptions"):
        METHODS["sdp"].from_coefficients(model, options=RetrievalOptions())
    with pytest.raises(WrongTypeError, match="takes RetrievalOptions; got SDPOptions"):
        METHODS["penalty"].from_coefficients(model, options=SDPOptions())


def test_the_penalty_method_refuses_a_torque_log_it_cannot_fit(arm):
    """The penalty method fits static data in one step; a torque log is a one-line refusal,
    not an attribute error deep inside."""
    q, dq, ddq = random_states(arm, 50, 6)
    log = TorqueLog(np.arange(50) * 1e-3, q, dq, dynid.rnea(arm, q, dq, ddq), ddq)
    with pytest.raises(WrongTypeError, match="not a torque log"):
        METHODS["penalty"].from_data(arm, log)


def test_workers_are_refused_by_the_convex_method(arm, tmp_path, capsys):
    """Regression: ``retrieve --workers 2`` with the convex method ran and ignored --workers;
    it is refused in one line (exit 2), and so are --runs and --stages; the library's convex
    method refuses ``workers`` too."""
    with pytest.raises(OptionError, match="workers apply to the penalty method"):
        METHODS["sdp"].from_coefficients(exact_model(arm, arm), workers=2)
    path = save_model_json(tmp_path / "identification.json", exact_model(arm, arm))
    for flag in ("--workers", "--runs", "--stages"):
        rc = main(["retrieve", "--model", str(path), flag, "2", "--out", str(tmp_path / "o")])
        err = capsys.readouterr().err
        assert rc == 2 and f"{flag} applies to --method penalty only" in err, err
        assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()
