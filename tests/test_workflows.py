"""Every check a command applies lives in the library entry point it calls: the Python API
(dynid.workflows, dynid.io) and every command refuse the same inputs with the same line,
honour the same options, and ``-q`` silences every command."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.cli.common import cli_text, option_message
from dynid.exceptions import DataError, DynidError, OptionError
from dynid.io.feasible_bundle import FEASIBLE_BUNDLE
from dynid.io.robot.toml import save_toml
from dynid.io.static_data import load_static_data
from dynid.workflows.data_files import column_map, read_torque_log
from dynid.workflows.friction import FrictionOptions, fit_friction_files
from dynid.workflows.identify import IdentifyOptions, identify_files
from dynid.workflows.prior import load_prior
from dynid.workflows.retrieve import RetrieveOptions, retrieve_files

from conftest import planar_2r


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> Path:
    """Static data and a torque log of the Panda, another robot's description (the Panda's
    kinematics named 'other') and a two-joint arm."""
    d = tmp_path_factory.mktemp("workflows")
    static = ["acquire-static", "--n", "60", "--noise", "1e-4", "--seed", "1"]
    assert main([*static, "--out", str(d / "s.csv"), "-q"]) == 0
    sim = ["simulate", "--duration", "4", "--rate", "200", "--seed", "2"]
    assert main([*sim, "--out", str(d / "log.csv"), "-q"]) == 0
    save_toml(d / "other.toml", dynid.panda().replace(name="other"))
    save_toml(d / "two.toml", planar_2r())
    assert main(["identify", "--data", str(d / "s.csv"), "--out", str(d / "id"), "-q"]) == 0
    return d


def _refusal(capsys, argv: list[str]) -> str:
    """The one error line of a refused command (exit 2)."""
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


OTHER = "s.csv: the data were recorded with robot 'panda'; the robot given is 'other'"


@pytest.mark.parametrize(
    "argv",
    [
        ["identify"],
        ["identify", "--consistent"],
        ["retrieve", "--method", "sdp"],
        ["retrieve", "--method", "penalty", "--runs", "1", "--stages", "1"],
    ],
    ids=["identify", "identify-consistent", "retrieve-sdp", "retrieve-penalty"],
)
def test_static_data_of_another_robot_is_refused_by_the_api_and_every_command(
    files, tmp_path, capsys, argv
):
    """The recorded robot is checked where the data are read (load_static_data): the API's
    entry points and identify, identify --consistent, retrieve --static (both methods)
    give the same line."""
    other = dynid.panda().replace(name="other")
    with pytest.raises(DataError) as api:
        load_static_data(files / "s.csv", other)
    assert str(api.value).startswith(OTHER)
    for call in (
        lambda: identify_files(other, files / "s.csv"),
        lambda: identify_files(other, files / "s.csv", IdentifyOptions(consistent=True)),
        lambda: retrieve_files(files / "s.csv", kind="static", robot=other),
        lambda: retrieve_files(
            files / "s.csv", RetrieveOptions(method="penalty"), kind="static", robot=other
        ),
    ):
        with pytest.raises(DataError, match="recorded with robot 'panda'") as exc:
            call()
        assert str(exc.value) == str(api.value)
    flag = "--static" if argv[0] == "retrieve" else "--data"
    line = _refusal(
        capsys,
        [
            *argv,
            flag,
            str(files / "s.csv"),
            "--robot",
            str(files / "other.toml"),
            "--out",
            str(tmp_path / "o"),
        ],
    )
    assert line == f"dynid {argv[0]}: error: {api.value}"
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    "argv",
    [
        ["identify", "--robot"],
        ["identify", "--consistent", "--robot"],
        ["friction", "--robot"],
        ["validate", "--robot"],
    ],
    ids=["identify", "identify-consistent", "friction", "validate"],
)
def test_a_log_of_another_joint_count_is_refused_alike(files, tmp_path, capsys, argv):
    """A 7-joint log given with a two-joint robot: read_torque_log (the API) and every
    command that reads a log name the joint counts."""
    with pytest.raises(DataError, match="the log has 7 joints; the robot has 2"):
        read_torque_log(files / "log.csv", 2)
    with pytest.raises(DataError, match="the log has 7 joints; robot 'planar2r' has 2"):
        identify_files(planar_2r(), files / "log.csv")
    line = _refusal(
        capsys,
        [*argv, str(files / "two.toml"), "--data", str(files / "log.csv"), "--out", str(tmp_path)],
    )
    assert "log.csv: the log has 7 joints;" in line and " has 2; hint:" in line


def test_log_cleaning_through_a_column_map_is_strict_alike(files, tmp_path, capsys):
    """A mapped log with a NaN row is an error unless --drop-invalid / drop_invalid, in the
    API and in identify; dropping it leaves one row fewer."""
    log = dynid.io.load_torque_log(files / "log.csv")
    n = log.n
    cols = ["time"] + [f"pos{i}" for i in range(n)] + [f"vel{i}" for i in range(n)]
    cols += [f"eff{i}" for i in range(n)]
    table = np.column_stack([log.t, log.q, log.dq, log.tau])
    table[5, 3] = np.nan
    path = tmp_path / "other_tool.csv"
    np.savetxt(path, table, delimiter=",", header=",".join(cols), comments="")
    spec = ("t=time,q=pos{i0},dq=vel{i0},tau=eff{i0}", None)
    cmap = column_map(*spec)
    with pytest.raises(DataError, match=r"1 row\(s\) of \d+ holding NaN, inf") as api:
        read_torque_log(path, n, columns=cmap)
    assert read_torque_log(path, n, columns=cmap, drop_invalid=True).n_samples == len(log.t) - 1
    line = _refusal(
        capsys,
        ["identify", "--data", str(path), "--columns", spec[0], "--out", str(tmp_path / "o")],
    )
    # the same message, the Python option of the library's hint named by its flag
    assert "(drop_invalid=True)" in str(api.value)
    assert line == f"dynid identify: error: {cli_text(str(api.value))}"
    assert "drop_invalid=True" not in line and "--drop-invalid to drop" in line


def test_a_prior_with_other_joints_is_refused_alike(files, tmp_path, capsys):
    """The prior's joint types are checked in the library (load_prior) and by
    identify --consistent and retrieve."""
    panda = dynid.panda()
    with pytest.raises(DynidError, match="joints RR; the robot's are RRRRRRR") as api:
        load_prior(files / "two.toml", panda)
    argv = ["identify", "--consistent", "--data", str(files / "s.csv")]
    line = _refusal(capsys, [*argv, "--prior", str(files / "two.toml"), "--out", str(tmp_path)])
    assert line == f"dynid identify: error: {option_message(api.value)}"
    assert line.startswith("dynid identify: error: --prior ")


def test_std_is_honoured_on_every_route_and_with_the_consistent_fit(files, tmp_path):
    """--std robust/classical is what the model records on static data and on a torque
    log (its structure given: the search is not what is tested), through the API and the
    command; regression: --consistent refused --std and reported the classical standard
    deviations whatever the default (2.7-3.6 x smaller than hac on a 7-joint arm), now it
    reports the plain route's for the same coefficients, its consistent parameters the same
    whichever is chosen (the data term is the residual itself)."""
    panda = dynid.panda()
    for data, terms in (("s.csv", None), ("log.csv", "viscous,coulomb")):
        for std in ("robust", "classical"):
            opts = IdentifyOptions(std=std, terms=terms)
            model = identify_files(panda, files / data, opts).model
            assert model.info.std == std
            out = tmp_path / f"{data}-{std}"
            argv = ["identify", "--data", str(files / data), "--std", std, "--out", str(out)]
            argv += [] if terms is None else ["--terms", terms]
            assert main([*argv, "--no-figures", "-q"]) == 0
            doc = json.loads((out / "identification.json").read_text())
            assert doc["std_estimator"] == std
            got = [c["std"] for c in doc["coefficients"]]
            np.testing.assert_allclose(got, model.fit.std[: len(got)], rtol=1e-9, atol=0)
    plain = identify_files(panda, files / "s.csv").model
    phis = {}
    for std in (None, "classical"):
        res = identify_files(panda, files / "s.csv", IdentifyOptions(consistent=True, std=std))
        assert res.consistent is not None
        assert res.model.info.std == (std or plain.info.std)
        if std is None:  # the default: the plain route's standard deviations
            np.testing.assert_allclose(res.model.fit.std, plain.fit.std, rtol=1e-12, atol=0)
        phis[std] = res.consistent.phi
    assert not np.allclose(
        identify_files(panda, files / "s.csv", IdentifyOptions(std="classical")).model.fit.std,
        plain.fit.std,
    )
    np.testing.assert_allclose(phis[None], phis["classical"], rtol=1e-9, atol=1e-12)
    out = tmp_path / "c"
    argv = ["identify", "--consistent", "--std", "classical", "--data", str(files / "s.csv")]
    assert main([*argv, "--no-figures", "-q", "--out", str(out)]) in (0, 1)
    doc = json.loads((out / "identification.json").read_text())
    assert doc["std_estimator"] == "classical"


def test_retrieve_from_a_model_file_starts_from_the_description_it_was_identified_with(
    files, tmp_path
):
    """identification.json keeps the description's link inertials: retrieve without a
    prior gives what --prior with that description gives, and a file without them (an
    older file) falls back to the generic prior, saying so."""
    path = files / "id" / "identification.json"
    doc = json.loads(path.read_text())
    np.testing.assert_array_equal(np.array(doc["robot"]["phi"]), dynid.panda().phi)
    own = retrieve_files(path).result
    named = retrieve_files(path, RetrieveOptions(prior="panda")).result
    np.testing.assert_allclose(own.phi, named.phi, rtol=1e-9, atol=1e-12)
    assert "description (panda)" in own.notes[0]
    del doc["robot"]["phi"]
    (tmp_path / "old.json").write_text(json.dumps(doc))
    old = retrieve_files(tmp_path / "old.json").result
    assert "has no link inertials" in old.notes[0]


def test_the_output_bundle_of_a_consistent_fit_is_the_same_for_identify_and_retrieve(
    files, tmp_path
):
    """identify --consistent and retrieve write the bundle of dynid.io.feasible_bundle;
    the feasible.json of retrieve --static equals the API's."""
    a, b = tmp_path / "identify", tmp_path / "retrieve"
    s = str(files / "s.csv")
    flags = ["--no-figures", "-q"]  # the figures are not part of the bundle
    assert main(["identify", "--consistent", "--data", s, "--out", str(a), *flags]) in (0, 1)
    assert main(["retrieve", "--static", s, "--out", str(b), *flags]) in (0, 1)
    for folder in (a, b):
        names = {p.name for p in folder.iterdir() if not p.name.startswith(".")}
        assert set(FEASIBLE_BUNDLE) <= names
    api = retrieve_files(files / "s.csv", kind="static", robot=dynid.panda()).result
    doc = json.loads((b / "feasible.json").read_text())
    got = np.array([link["mass"] for link in doc["links"]])
    np.testing.assert_allclose(got, api.mass, rtol=1e-6)


QUIET = [
    ["fk"],
    ["jacobian"],
    ["ik", "--goal-xyz", "0.4,0.1,0.4"],
    ["acquire-static", "--n", "20", "--out", "{t}/s.csv"],
    ["simulate", "--duration", "1", "--rate", "100", "--out", "{t}/log.csv"],
    ["identify", "--data", "{d}/s.csv", "--out", "{t}/id"],
    ["identify", "--data", "{d}/log.csv", "--out", "{t}/id"],
    ["identify", "--consistent", "--data", "{d}/s.csv", "--out", "{t}/id", "--no-figures"],
    ["friction", "--robot", "panda", "--data", "{d}/log.csv", "--out", "{t}/f", "--no-figures"],
    ["validate", "--robot", "panda", "--data", "{d}/log.csv", "--out", "{t}/v", "--no-figures"],
    ["retrieve", "--static", "{d}/s.csv", "--out", "{t}/r", "--no-figures"],
    ["payload", "--robot", "panda", "--data", "{d}/s.csv", "--out", "{t}/p"],
    ["export", "--params", "panda", "--out", "{t}/panda.urdf"],
    ["predict", "--model", "{d}/id/identification.json", "--q", "0,0,0,-1.5,0,1.5,0.7"],
    [
        "excite",
        "--duration",
        "3",
        "--harmonics",
        "2",
        "--max-iter",
        "2",
        "--no-figure",
        "--out",
        "{t}/e",
    ],
]


def _quiet_case(argv: list[str]):
    """One command of QUIET; identify on the log (its structure search, about 5 s) is
    marked slow, which hands this file out among the first (tests/conftest.py)."""
    slow = argv[:3] == ["identify", "--data", "{d}/log.csv"]
    return pytest.param(argv, id=" ".join(argv[:2]), marks=[pytest.mark.slow] if slow else [])


@pytest.mark.parametrize("argv", [_quiet_case(a) for a in QUIET])
def test_quiet_silences_every_command(files, tmp_path, capsys, argv):
    """-q prints nothing (no table, summary, progress, note or warning) for every command;
    without it the same command prints its summary (identify without its figures, which
    the quiet run drew: a second drawing of the log's cost about 1.5 s; on the log with
    its structure given, the quiet run having silenced the search's progress: a second
    search cost about 5 s; friction with its law given, the quiet run having silenced the
    laws' comparison)."""
    argv = [a.format(d=files, t=tmp_path) for a in argv]
    assert main([*argv, "-q"]) in (0, 1)
    out, err = capsys.readouterr()
    assert (out, err) == ("", "")
    if argv[0] == "identify" and "--no-figures" not in argv:
        argv.append("--no-figures")
    if argv[0] == "identify" and argv[2].endswith("log.csv"):
        argv += ["--terms", "viscous,coulomb"]
    if argv[0] == "friction":  # a law given: the quiet run silenced the laws' comparison
        argv += ["--friction-model", "classical"]
    assert main(argv) in (0, 1)
    assert capsys.readouterr().out.strip()


def test_quiet_keeps_a_json_result(capsys):
    """--json is the result asked for: printed also with -q."""
    assert main(["fk", "--json", "-q"]) == 0
    T = np.array(json.loads(capsys.readouterr().out)["T"])
    np.testing.assert_allclose(T, dynid.fk(dynid.panda(), dynid.PANDA_NEUTRAL_Q), atol=1e-14)


def test_the_friction_law_policy_is_the_library_s(files, tmp_path, capsys):
    """fit_friction_files applies dynid friction's policy: auto compares every law on
    held-out blocks (the model's own friction too) and keeps the simplest within one
    standard error of the lowest, a named law is fitted as asked, an unknown one is
    refused; the command writes what the API returns."""
    from dynid.friction.select import simplest_within

    panda = dynid.panda()
    auto = fit_friction_files(panda, files / "log.csv")
    assert auto.selection is not None and auto.fit is auto.selection.fit
    scores = {s.name: s for s in auto.selection.scores}
    chosen = scores[auto.selection.chosen]
    assert chosen.name == simplest_within(auto.selection.scores).name and "own" in scores
    low = min(s.scaled_error_percent for s in scores.values())
    assert chosen.scaled_error_percent <= 1.05 * low < scores["none"].scaled_error_percent
    named = fit_friction_files(panda, files / "log.csv", FrictionOptions(law="classical"))
    assert named.selection is None and named.fit.kind == "classical"
    with pytest.raises(OptionError, match="law must be one of auto, none") as api:
        FrictionOptions(law="coulomb")
    assert option_message(api.value).startswith("--friction-model must be one of auto, none")

    out = tmp_path / "fr"
    argv = ["friction", "--robot", "panda", "--data", str(files / "log.csv"), "--out", str(out)]
    assert main([*argv, "--no-figures", "-q"]) == 0
    doc = json.loads((out / "friction.json").read_text())
    assert doc["selection"] == auto.selection.as_dict()
    assert [j["rms_after"] for j in doc["joints"]] == list(auto.fit.rms_after)
