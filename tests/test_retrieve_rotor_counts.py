"""``dynid retrieve`` of a model with rotor inertias in its base: the coefficients are
counted as link base parameters plus rotor inertias (they were one count), and the
retrieved parameters the data do not determine are marked as taken from the prior."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.cli.summaries import format_consistent
from dynid.exceptions import DynidWarning
from dynid.feasibility.determined import DATA, determined_by_data
from dynid.friction.model import ClassicalFriction
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.model_json import save_model_json
from dynid.io.report_json import report_to_dict
from dynid.model.drive import Drive
from dynid.regressors.torque import torque_regressor
from dynid.workflows.retrieve import RetrieveOptions, retrieve_files

from conftest import recordings

GEARS = np.array([50.0, 50.0, 40.0, 40.0, 30.0, 30.0, 30.0])
IA = np.array([5e-5, 6e-5, 4e-5, 3e-5, 2e-5, 2.5e-5, 1.5e-5])


@pytest.fixture(scope="module")
def retrieved(tmp_path_factory):
    """A geared Panda with known rotor inertias, identified (rotor inertias identified)
    from exact data, then retrieved with a prior 20 % heavier than the truth."""
    import dynid

    panda = dynid.panda()
    truth = Drive.from_gears(GEARS, rotor_inertia=IA)
    fr = ClassicalFriction(np.full(7, 1e-3), np.zeros(7), np.zeros(7)).at(truth)
    logs = recordings(panda, (7, 8), friction=fr, drive=truth, duration=4.0)
    given = Drive.from_gears(GEARS, rotor_inertia=None)
    model = identify_recordings(
        panda, logs, cutoff_hz=None, drive=given, structure=Structure(True, ("viscous",))
    )
    path = save_model_json(tmp_path_factory.mktemp("rotors") / "identification.json", model)
    prior = panda.with_params(1.2 * panda.phi)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        result = retrieve_files(path, RetrieveOptions(prior=prior)).result
    return panda, logs, model, result, path


def _independent_sources(panda, logs) -> tuple[int, int, np.ndarray]:
    """The link rank, the rotors' added rank and, per rotor, whether its column is in the
    span of the others (rank of the stacked regressor with unit columns, by SVD): the
    link regressor with the rotors' columns ``g_j^2 ddq_j`` at joint ``j`` beside it."""
    Y = np.concatenate(
        [torque_regressor(panda, g.q, g.dq, g.ddq).reshape(-1, 70) for g in logs[:1]]
    )
    ddq = np.concatenate([g.ddq for g in logs[:1]])
    R = np.zeros((Y.shape[0], 7))
    for j in range(7):
        R[j::7, j] = GEARS[j] ** 2 * ddq[:, j]

    def unit(A: np.ndarray) -> np.ndarray:  # columns that act (not round-off) at norm 1
        c = np.linalg.norm(A, axis=0)
        return A[:, c > 1e-9 * c.max()] / c[c > 1e-9 * c.max()]

    W, Wl = unit(np.hstack([Y, R])), unit(Y)

    def rank(A: np.ndarray) -> int:
        s = np.linalg.svd(A, compute_uv=False)
        return int(np.sum(s > 1e-8 * s[0]))

    full, links = rank(W), rank(Wl)
    in_span = np.array([rank(np.delete(W, W.shape[1] - 7 + j, axis=1)) == full for j in range(7)])
    return links, full - links, in_span


def test_counts_and_prior_rotors_match_an_independent_rank_test(retrieved):
    """The counts are the link regressor's rank and what the rotors' columns add, and
    the rotors marked as taken from the prior are exactly those whose column lies in the
    span of the others (SVD rank of the stacked regressor; the Panda's motors 1 and 2)."""
    panda, logs, model, result, _ = retrieved
    links, rotors, in_span = _independent_sources(panda, logs)
    det = result.determined
    assert det is not None
    assert (det.n_link, det.n_rotor) == (links, rotors) == (43, 5)
    assert det.n_link + det.n_rotor == model.base.rank
    np.testing.assert_array_equal(det.rotor_from_prior, in_span)
    text = format_consistent(result)
    assert "coefficients: 43 link base parameters + 5 rotor inertias (armatures)" in text
    line = next(x for x in text.splitlines() if x.startswith("rotor inertia at the motors"))
    marks = [v.endswith("*") for v in line.split(":")[1].split()]
    assert marks == list(in_span)
    assert "rotor(s) 1, 2: from the prior" in text
    rec = report_to_dict(result)["determined"]
    assert rec["link_base_parameters"] == 43 and rec["rotor_inertias"] == 5
    assert [s != DATA for s in rec["rotor_source"]] == list(in_span)


def test_determined_parameters_match_the_truth(retrieved):
    """The rotor inertias and link parameters the data determine are the truth's to
    1e-6 (relative) although the prior is 20 % off; the links' determined parameters
    include the standard parameters the base gives alone (``J7zz``)."""
    panda, logs, model, result, _ = retrieved
    det = determined_by_data(model)
    src = dict(zip(det.labels, det.source, strict=True))
    ia = np.asarray(result.rotor_inertia)
    for j in range(7):
        if src[f"Ia{j + 1}"] == DATA:
            assert ia[j] == pytest.approx(IA[j], rel=1e-6)
    phi, truth = result.phi.reshape(-1), panda.phi.reshape(-1)
    scale = np.abs(truth).max()
    got = [k for k, lab in enumerate(det.labels[:70]) if src[lab] == DATA]
    assert "J7zz" in [det.labels[k] for k in got]
    np.testing.assert_allclose(phi[got], truth[got], atol=1e-6 * scale)


def test_the_report_page_says_the_counts_and_the_rotors_from_the_prior(retrieved, tmp_path):
    """``dynid retrieve``'s report.html: the counts, a rotor table whose motors 1 and 2
    say "the prior", and a mass column (link 1's mass: not excited)."""
    *_, path = retrieved
    out = tmp_path / "ret"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert (
            main(["retrieve", "--model", str(path), "--out", str(out), "-q", "--no-figures"]) == 0
        )
    page = (out / "report.html").read_text()
    text = re.sub(r"<[^>]+>", "", page)
    assert "Coefficients: 43 link base parameters + 5 rotor inertias (armatures)" in text
    rotors = page[page.index("Rotor inertias (armatures)") :]
    rows = rotors.split("<tr>")[2:9]
    assert ["the prior" in r for r in rows] == [True, True] + [False] * 5
    assert "mass from" in page and "the data do not excite it" in page
