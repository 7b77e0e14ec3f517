"""Both consistent-parameter methods through one result base and one report converter.

References: each link's pseudo-inertia built here from the written mass, CoM and inertia
(Wensing, Kim, Slotine 2018: ``J = [[Sigma, h], [h^T, m]]``, ``Sigma = tr(I_o)/2 1 - I_o``)
and its eigenvalues from numpy; the masses of the result's robot.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from dynid.feasibility.constraints import feasibility_report
from dynid.feasibility.convex import ConsistentResult, retrieve_sdp
from dynid.feasibility.penalty import RetrievalOptions, RetrievalResult, retrieve
from dynid.feasibility.result import FeasibleResult
from dynid.io.feasible import feasible_to_dict
from dynid.io.report_json import report_to_dict, save_report_json

from conftest import exact_model, planar_2r

#: report.json keys every method writes, with the same meaning.
SHARED = {
    "schema",
    "dynid_version",
    "method",
    "kind",
    "robot",
    "link_names",
    "relative_residual",
    "feasible",
    "min_margin",
    "constraints",
    "pseudo_inertia_margin",
    "friction",
    "heldout",
    "run_time_s",
    "seed",
    "notes",
    "total_mass",
    "bounds",
    "units",
}
PHYSICAL = ("mass_positive", "inertia_positive_definite", "triangle_inequality")


@pytest.fixture(scope="module")
def results() -> list[FeasibleResult]:
    """The convex and the penalty method on the exact static coefficients of a planar 2R."""
    robot = planar_2r()
    model = exact_model(robot, robot)
    sdp = retrieve_sdp(model, prior=robot)
    pen = retrieve(model, options=RetrievalOptions(runs=2, stages=3), workers=1, seed=0)
    return [sdp, pen]


def _pseudo_inertia_eigenvalues(links: list[dict]) -> np.ndarray:
    """Eigenvalues (n, 4) of each link's pseudo-inertia about the link origin, from a
    feasible.json's ``mass``, ``com`` and ``inertia`` (about the CoM, xx xy xz yy yz zz)."""
    out = []
    for link in links:
        m, c = link["mass"], np.array(link["com"])
        xx, xy, xz, yy, yz, zz = link["inertia"]
        I_c = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        I_o = I_c + m * (c @ c * np.eye(3) - np.outer(c, c))  # parallel axis
        J = np.zeros((4, 4))
        J[:3, :3] = 0.5 * np.trace(I_o) * np.eye(3) - I_o
        J[:3, 3] = J[3, :3] = m * c
        J[3, 3] = m
        out.append(np.linalg.eigvalsh(J))
    return np.array(out)


def _physical_ok(report: dict, n: int) -> list[bool]:
    """Per link: every physical constraint of report.json satisfied."""
    ok = [True] * n
    for c in report["constraints"]:
        if c["name"] in PHYSICAL:
            ok[c["link"] - 1] &= c["satisfied"]
    return ok


def test_both_methods_are_feasible_results_with_their_own_method_name(results):
    """ConsistentResult and RetrievalResult derive from the base and name their method."""
    sdp, pen = results
    assert isinstance(sdp, ConsistentResult) and isinstance(sdp, FeasibleResult)
    assert isinstance(pen, RetrievalResult) and isinstance(pen, FeasibleResult)
    assert (sdp.method, pen.method) == ("sdp", "penalty")
    assert sdp.feasible and pen.feasible


def test_one_report_function_writes_the_shared_keys_for_both_methods(results, tmp_path):
    """Each report holds every shared key, a method's own fields never repeat one, and the
    written file is the converter's dictionary."""
    for res in results:
        d = report_to_dict(res)
        assert SHARED <= set(d), sorted(SHARED - set(d))
        assert not set(res.report_fields()) & SHARED, res.method
        assert d["method"] == res.method and d["robot"] == "planar2r"
        assert d["link_names"] == list(res.robot.link_names[1:])
        assert d["relative_residual"] == res.relative_residual
        assert len(d["constraints"]) == len(res.report.constraints)
        path = save_report_json(tmp_path / f"{res.method}.json", res, source="test")
        assert json.loads(path.read_text()) == json.loads(json.dumps(d | {"source": "test"}))
    sdp, pen = (report_to_dict(r) for r in results)
    assert sdp["fit"] == "equality" and sdp["prior"]["source"]
    assert len(pen["runs"]) == 2 and len(pen["stage_costs"]) == 3
    assert "runs" not in sdp and "prior" not in pen


def test_written_masses_and_consistency_agree_with_an_independent_pseudo_inertia(results):
    """feasible.json's masses are the result's; report.json's pseudo-inertia margins and
    physical checks agree with eigenvalues of J built from the written parameters, for a
    consistent robot and for one whose link 2 breaks the triangle inequality."""
    for res in results:
        bad_robot = res.robot.with_inertials(
            res.mass, res.com, np.array([res.inertia[0], np.diag([0.01, 0.01, 0.05])])
        )
        bad = dataclasses.replace(res, robot=bad_robot, report=feasibility_report(bad_robot))
        for r, expected in ((res, [True, True]), (bad, [True, False])):
            f, d = feasible_to_dict(r), report_to_dict(r)
            assert f["method"] == d["method"] == r.method
            np.testing.assert_array_equal([link["mass"] for link in f["links"]], r.mass)
            lam = _pseudo_inertia_eigenvalues(f["links"])
            consistent = list(lam[:, 0] > 0)
            assert consistent == expected, (r.method, lam)
            assert _physical_ok(d, 2) == consistent
            np.testing.assert_allclose(
                d["pseudo_inertia_margin"], lam[:, 0] / lam.sum(axis=1), rtol=1e-9, atol=1e-15
            )
