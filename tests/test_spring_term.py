"""The joint spring as a model term of ``--terms``: identified, saved, evaluated.

References: simulated Panda recordings with sensor noise, classical friction and a spring
``k (q2 - q0)`` on joint 2 (the truth's stiffness, rest position and noise are known).
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from test_systematic_residual import Q0, K, _fitted, _logs

from dynid.identification.structure import Structure
from dynid.io.model_json import load_model_json, save_model_json
from dynid.io.torque_log import save_torque_log
from dynid.observer.model import from_identified
from dynid.workflows.validate import ValidateOptions, validate_files


@pytest.fixture(scope="module")
def spring_logs(panda):
    """The recordings with the spring."""
    return _logs(panda, spring=True)


def test_the_spring_term_recovers_the_stiffness_and_reaches_the_floor(panda, spring_logs, tmp_path):
    """``--terms ...,spring`` on the spring's recordings: joint 2's stiffness within 3 of
    its standard deviations of the truth's (to 2 %), the other joints' zero within 4, the
    held-out recording predicted at its noise on every joint; the spring survives the JSON
    round trip and the observer subtracts it."""
    *train, test = spring_logs
    model = _fitted(panda, train, "viscous,coulomb,offset,spring")
    spring = model.terms["spring"]
    assert spring.term.labels == tuple(f"k{j}" for j in range(1, 8))
    k, s = np.asarray(spring.values), np.asarray(spring.std)
    assert abs(k[1] - K) < 3 * s[1] and s[1] < 0.02 * K, (k, s)
    others = np.delete(np.abs(k) / s, 1)  # zero in the truth
    assert np.all(others < 4.0), (k, s)
    save_model_json(tmp_path / "model.json", model)
    back = load_model_json(tmp_path / "model.json")
    np.testing.assert_array_equal(back.terms["spring"].values, spring.values)
    save_torque_log(tmp_path / "held.csv", test)
    res = validate_files(back, tmp_path / "held.csv", ValidateOptions())
    ratio = res.validation.errors.rms / res.noise_rms
    assert np.all(ratio < 1.15), ratio
    assert res.verdict.level == "good", res.verdict
    q = test.q[:50]
    held = from_identified(back).position_torques(q)
    assert held is not None
    q0 = np.asarray(spring.term.q0)  # type: ignore[attr-defined]
    np.testing.assert_allclose(held, (q - q0) * k, rtol=1e-12, atol=1e-12)


def test_the_structure_names_spring_as_a_term():
    """``spring`` parses as a term beside the friction's, prints back, and an unknown name
    lists it among the terms."""
    s = Structure.parse("armature,spring,viscous,offset")
    assert s.spring and s.armature and s.friction == ("viscous", "offset")
    assert s.name == "links + armature + spring + viscous + offset"
    assert Structure.parse(",".join(s.terms)) == s
    with pytest.raises(ValueError, match="terms are armature, spring, viscous"):
        Structure.parse("springs")


def test_the_summary_gives_the_springs_rest_position_with_its_offset(panda, spring_logs):
    """The spring term is ``k (q - q0)`` about the joint's mid-range, the offset ``fo``
    beside it: the summary gives where the two leave no torque, ``q0 - fo/k``, for the
    determined spring alone: the truth's rest position 0.3 rad on joint 2, within 0.01 rad
    (the offset's and stiffness's standard deviations put 3 std of the ratio at 0.0064)."""
    from dynid.cli.summaries import term_lines

    *train, _ = spring_logs
    model = _fitted(panda, train, "viscous,coulomb,offset,spring")
    line = next(x for x in term_lines(model) if x.startswith("  rest position"))
    said = dict(
        (int(j), float(r)) for j, r in re.findall(r"joint (\d+) at ([+-][\d.e+-]+) rad", line)
    )
    assert list(said) == [2], line
    fr = model.terms["friction"]
    i = fr.labels.index("fo2")
    k, sk = model.spring.k[1], model.terms["spring"].std[1]
    spread = 3 * np.hypot(fr.std[i] / k, fr.values[i] * sk / k**2)
    assert abs(said[2] - Q0) < 0.01 and spread < 0.01, (line, spread)
