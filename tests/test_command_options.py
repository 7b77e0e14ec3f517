"""Each command's policy lives in its library entry point, which takes typed options: the
Python API and the command refuse the same input (an ``OptionError`` carrying the field,
which the command names by its flag) and give the same result."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import build_parser, main
from dynid.cli.common import flag, option_message
from dynid.exceptions import DynidWarning, ModelError, OptionError
from dynid.io.model_json import save_model_json
from dynid.io.robot.toml import save_toml
from dynid.io.robot_file import load_robot
from dynid.io.static_data import load_static_data
from dynid.io.torque_log import save_torque_log_pieces
from dynid.simulation.excitation import ExcitationOptions
from dynid.workflows.acquire_static import AcquireStaticOptions, acquire_static_data
from dynid.workflows.excite import design_excitation
from dynid.workflows.export import ExportRobotOptions, export_robot
from dynid.workflows.friction import FrictionOptions
from dynid.workflows.identify import IdentifyOptions, identify_files
from dynid.workflows.kinematics import goal_pose
from dynid.workflows.retrieve import RetrieveOptions, retrieve_files
from dynid.workflows.simulate import SimulateOptions, simulate_log

from conftest import exact_model, pinocchio_panda_urdf, planar_2r


@pytest.fixture(scope="module")
def static(tmp_path_factory) -> Path:
    """Static data of the Panda (40 configurations, noise-free)."""
    path = tmp_path_factory.mktemp("options") / "s.csv"
    assert main(["acquire-static", "--n", "40", "--seed", "3", "--out", str(path), "-q"]) == 0
    return path


def _refusal(capsys, argv: list[str]) -> str:
    """The one error line of a refused command (exit 2), without its prefix."""
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    prefix = f"dynid {argv[0]}: error: "
    assert err[0].startswith(prefix), err
    return err[0][len(prefix) :]


def test_an_option_error_names_its_field_in_the_api_and_its_flag_on_the_command_line():
    exc = OptionError("applies with {unmodelled} only", field="arm_seed", others=("unmodelled",))
    assert str(exc) == "arm_seed applies with unmodelled only"
    assert option_message(exc) == "--arm-seed applies with --unmodelled only"
    assert exc.field == "arm_seed" and isinstance(exc, ValueError)
    assert option_message(OptionError("no field: as it is")) == "no field: as it is"
    assert flag("cutoff_hz") == "--cutoff" and flag("max_gap_s") == "--max-gap"


@pytest.mark.parametrize(
    ("options", "argv", "field"),
    [
        ({"prior": "panda"}, ["--prior", "panda"], "prior"),
        ({"total_mass": (16.0, 20.0)}, ["--total-mass", "16,20"], "total_mass"),
        (
            {"consistent": True, "max_std_percent": 30.0},
            ["--consistent", "--max-std-percent", "30"],
            "max_std_percent",
        ),
        ({"terms": "armature,viscous"}, ["--terms", "armature,viscous"], "terms"),
        ({"terms": "viscous,smooth,coulomb"}, ["--terms", "viscous,smooth,coulomb"], "terms"),
        ({"folds": 3}, ["--folds", "3"], "folds"),
        ({"consistent": True, "max_gap_s": 0.1}, ["--consistent", "--max-gap", "0.1"], "max_gap_s"),
    ],
    ids=["prior", "mass-band", "prune-consistent", "terms-static", "terms-smooth", "folds", "gap"],
)
def test_identify_refuses_alike(static, tmp_path, capsys, options, argv, field):
    """identify's policies (consistent-only options, options of torque logs given static
    data, terms that do not go together) through identify_files and dynid identify."""
    panda = dynid.panda()
    with pytest.raises(OptionError) as api:
        identify_files(panda, static, IdentifyOptions(**options))
    assert api.value.field == field
    line = _refusal(
        capsys, ["identify", "--data", str(static), *argv, "--out", str(tmp_path / "o")]
    )
    assert line == option_message(api.value) and line.startswith(flag(field))
    assert not (tmp_path / "o").exists()


def test_identify_gives_the_same_model_through_both(static, tmp_path):
    """The coefficients of dynid identify are those of identify_files (with an option
    that changes them: pruning)."""
    import json

    model = identify_files(dynid.panda(), static, IdentifyOptions(max_std_percent=30.0)).model
    out = tmp_path / "id"
    argv = ["identify", "--data", str(static), "--max-std-percent", "30", "--out", str(out)]
    assert main([*argv, "-q"]) == 0
    doc = json.loads((out / "identification.json").read_text())
    got = [(c["value"], c["kept"]) for c in doc["coefficients"]]
    want = [(float(b), bool(k)) for b, k in zip(model.fit.beta, model.fit.kept, strict=False)]
    assert got == want[: len(got)] and len(got) == model.base.rank


# ---------------------------------------------------------------------- simulate
@pytest.mark.parametrize(
    ("options", "argv", "field"),
    [
        ({"arm_seed": 3}, ["--arm-seed", "3"], "arm_seed"),
        ({"q0": (0.0, 0.1)}, ["--q0", "0,0.1"], "q0"),
        (
            {"amplitudes": (0.1,) * 7, "periods": (5.0,) * 6},
            ["--amplitudes", ",".join(["0.1"] * 7), "--periods", ",".join(["5"] * 6)],
            "periods",
        ),
    ],
    ids=["arm-seed-alone", "q0-count", "periods-count"],
)
def test_simulate_refuses_alike(tmp_path, capsys, options, argv, field):
    with pytest.raises(OptionError) as api:
        simulate_log(dynid.panda(), SimulateOptions(duration_s=1.0, **options))
    assert api.value.field == field
    out = tmp_path / "x.csv"
    line = _refusal(capsys, ["simulate", "--duration", "1", *argv, "--out", str(out)])
    assert line == option_message(api.value) and line.startswith(flag(field))
    assert not out.exists()


def test_simulate_needs_sinusoids_for_a_robot_without_seven_joints(tmp_path, capsys):
    """Table I's sinusoids are for 7 joints: another robot needs its own, in both."""
    save_toml(tmp_path / "two.toml", planar_2r())
    with pytest.raises(OptionError, match="default sinusoids are for 7 joints") as api:
        simulate_log(planar_2r(), SimulateOptions(duration_s=1.0))
    argv = ["simulate", "--robot", str(tmp_path / "two.toml"), "--duration", "1"]
    line = _refusal(capsys, [*argv, "--out", str(tmp_path / "x.csv")])
    assert line.startswith("--amplitudes and --periods are needed: the default sinusoids")
    assert line == option_message(api.value)
    # one of the two given: the other is named as missing (it said "--amplitudes are
    # needed" with --amplitudes given)
    for given, missing in (("amplitudes", "periods"), ("periods", "amplitudes")):
        with pytest.raises(OptionError) as api:
            simulate_log(planar_2r(), SimulateOptions(duration_s=1.0, **{given: (1.0, 1.0)}))
        assert api.value.field == missing
        line = _refusal(capsys, [*argv, f"--{given}", "1,1", "--out", str(tmp_path / "x.csv")])
        assert line.startswith(f"--{missing} is needed beside --{given}: the default")
        assert line == option_message(api.value)


def test_simulate_writes_the_log_of_the_api(tmp_path):
    """dynid simulate writes, byte for byte, the log simulate_log gives (with options that
    change it: fourier, unmodelled effects of another arm seed, jitter, dropped samples)."""
    options = SimulateOptions(
        trajectory="fourier",
        duration_s=1.0,
        rate_hz=200.0,
        jitter_s=1e-4,
        drop_fraction=0.1,
        unmodelled=True,
        arm_seed=4,
        seed=9,
        with_ddq=True,
    )
    res = simulate_log(dynid.panda(), options)
    api = save_torque_log_pieces(
        tmp_path / "api.csv", res.log, n=7, n_rows=res.log.n_samples, with_ddq=True
    )
    argv = ["simulate", "--trajectory", "fourier", "--duration", "1", "--rate", "200"]
    argv += ["--jitter", "1e-4", "--drop", "0.1", "--unmodelled", "--arm-seed", "4"]
    argv += ["--seed", "9", "--with-ddq", "--out", str(tmp_path / "cli.csv"), "-q"]
    assert main(argv) == 0
    assert (tmp_path / "cli.csv").read_bytes() == api.read_bytes()
    assert res.log.n_samples < 200  # samples were dropped


def test_simulate_says_where_the_simulated_friction_acts_in_the_drive_line():
    """A geared drive's line in simulate says where the simulated friction acts: none with
    friction "none"; the Panda's own at the joints when the drive file leaves friction_at
    out (a description's friction stays at the joints); at the motors when it says so."""
    from dynid.model.drive import Drive

    def drive_line(friction, **kw):
        drive = Drive.from_gears(50.0, n=7, side="motor", **kw)
        options = SimulateOptions(duration_s=0.2, rate_hz=100.0, drive=drive, friction=friction)
        notes = simulate_log(dynid.panda(), options).notes
        return next(n for n in notes if n.startswith("drive:"))

    none = drive_line("none", friction_at="motor")
    assert "no friction simulated" in none and "friction at the motors" not in none
    default = drive_line("robot")
    assert "own friction at the joints" in default and "at the motors" not in default
    assert "friction at the motors" in drive_line("robot", friction_at="motor")


# ---------------------------------------------------------------------- export
def test_export_chooses_the_chain_of_a_urdf_with_several_leaves(tmp_path, capsys):
    """A URDF with a hand and two fingers has several leaves: export --params refuses it
    without --tip (naming the leaves; the API's message names the Python argument,
    tip_link=...), and --tip panda_hand exports the arm's seven
    revolute joints as the file names them, through the API and the command alike."""
    urdf = Path(pinocchio_panda_urdf())
    text = urdf.read_text()
    revolute = re.findall(r'<joint\s+name="([^"]+)"\s+type="revolute"', text)
    assert len(revolute) == 7
    out = tmp_path / "arm.toml"
    with pytest.raises(ModelError, match="several leaf links") as api:
        export_robot(urdf, out)
    line = _refusal(capsys, ["export", "--params", str(urdf), "--out", str(out)])
    assert "pass tip_link=... to choose" in str(api.value) and "--tip" not in str(api.value)
    assert line == str(api.value).replace("tip_link=...", "--tip") and not out.exists()
    res = export_robot(urdf, out, ExportRobotOptions(tip="panda_hand"))
    assert res.robot.joint_names == tuple(revolute) and res.format == "toml"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert (
            main(["export", "--params", str(urdf), "--tip", "panda_hand", "--out", str(out), "-q"])
            == 0
        )
    saved = load_robot(out)
    assert saved.joint_names == tuple(revolute)
    np.testing.assert_allclose(saved.phi, res.robot.phi, rtol=1e-12, atol=1e-15)


def test_export_refuses_a_chain_without_a_urdf(tmp_path, capsys):
    """--base/--tip choose the chain of a URDF --params or template: with panda they would
    do nothing; a template for MJCF is refused; both alike through the API."""
    for options, argv, field, out in (
        ({"tip": "link7"}, ["--tip", "link7"], "tip", "x.toml"),
        ({"urdf_template": "t.urdf"}, ["--urdf-template", "t.urdf"], "urdf_template", "x.xml"),
    ):
        with pytest.raises(OptionError) as api:
            export_robot("panda", tmp_path / out, ExportRobotOptions(**options))
        assert api.value.field == field
        line = _refusal(
            capsys, ["export", "--params", "panda", *argv, "--out", str(tmp_path / out)]
        )
        assert line == option_message(api.value) and line.startswith(flag(field))


# ---------------------------------------------------------------------- acquire-static
def test_acquire_static_refuses_obstacles_without_a_pool_alike(tmp_path, capsys):
    with pytest.raises(OptionError, match="obstacles needs pool") as api:
        AcquireStaticOptions(n=5, obstacles="floor.json")
    assert api.value.field == "obstacles"
    argv = ["acquire-static", "--n", "5", "--obstacles", "floor.json"]
    line = _refusal(capsys, [*argv, "--out", str(tmp_path / "s.csv")])
    assert line == option_message(api.value) and line.startswith("--obstacles needs --pool")


def test_acquire_static_writes_the_data_of_the_api(tmp_path):
    """dynid acquire-static writes the configurations and readings acquire_static_data
    gives (noisy, with the effects outside the model, which both record); the noise-free
    readings equal M(q) and g(q) of the robot (the controller's reference)."""
    options = AcquireStaticOptions(n=12, noise=1e-3, seed=5, unmodelled=True)
    res = acquire_static_data(dynid.panda(), options)
    argv = ["acquire-static", "--n", "12", "--noise", "1e-3", "--seed", "5", "--unmodelled"]
    assert main([*argv, "--out", str(tmp_path / "s.npz"), "-q"]) == 0
    got, _ = load_static_data(tmp_path / "s.npz", dynid.panda())
    np.testing.assert_array_equal(got.q, res.data.q)
    np.testing.assert_array_equal(got.g, res.data.g)
    assert got.metadata["unmodelled"] == res.data.metadata["unmodelled"]
    clean = acquire_static_data(dynid.panda(), AcquireStaticOptions(n=4, seed=5)).data
    np.testing.assert_allclose(clean.g, dynid.gravity_torques(dynid.panda(), clean.q), atol=1e-12)


# ---------------------------------------------------------------------- retrieve
@pytest.mark.parametrize(
    ("options", "argv", "field"),
    [
        ({"workers": 2}, ["--workers", "2"], "workers"),
        ({"runs": 3}, ["--runs", "3"], "runs"),
        (
            {"method": "penalty", "margin": 0.01},
            ["--method", "penalty", "--margin", "0.01"],
            "margin",
        ),
        (
            {"method": "penalty", "prior_weight": 1e300},
            ["--method", "penalty", "--prior-weight", "1e300"],
            "prior_weight",
        ),
    ],
    ids=["workers-convex", "runs-convex", "margin-penalty", "weight-penalty"],
)
def test_retrieve_refuses_an_option_of_the_other_method_alike(
    tmp_path, capsys, options, argv, field
):
    """Options of one consistent method given to the other are refused by RetrieveOptions,
    through the API and the command, in one line naming the flag."""
    arm = planar_2r()
    path = save_model_json(tmp_path / "identification.json", exact_model(arm, arm))
    with pytest.raises(OptionError) as api:
        retrieve_files(path, RetrieveOptions(**options))
    assert api.value.field == field
    line = _refusal(capsys, ["retrieve", "--model", str(path), *argv, "--out", str(tmp_path / "o")])
    assert line == option_message(api.value) and line.startswith(flag(field))
    assert not (tmp_path / "o").exists()


# ---------------------------------------------------------------------- excite
def test_excite_refuses_aliased_harmonics_alike(tmp_path, capsys):
    """A highest harmonic above half the rate the regressor is optimised at is refused by
    ExcitationOptions, which design_excitation and dynid excite take alike."""
    with pytest.raises(OptionError, match="highest harmonic") as api:
        design_excitation(dynid.panda(), ExcitationOptions(harmonics=20, base_frequency=1.0))
    argv = ["excite", "--harmonics", "20", "--base-frequency", "1", "--out", str(tmp_path / "e")]
    assert _refusal(capsys, argv) == option_message(api.value)
    assert not (tmp_path / "e").exists()


@pytest.mark.parametrize(
    ("command", "cls", "given"),
    [
        ("identify", IdentifyOptions, {"columns", "drive", "total_mass"}),
        (
            "simulate",
            SimulateOptions,
            {"friction", "amplitudes", "periods", "q0", "contacts", "drive"},
        ),
        ("export", ExportRobotOptions, {"friction"}),
        ("acquire-static", AcquireStaticOptions, set()),
        ("friction", FrictionOptions, {"columns", "drive"}),
        ("retrieve", RetrieveOptions, {"total_mass_band", "total_mass"}),
    ],
)
def test_every_option_field_has_its_flag(command, cls, given):
    """Each field of a command's options class is given by the command (parsed first) or
    read from the flag cli.common.flag names, which the command's parser has: the table of
    flags and the parsers agree, so that every refusal names a flag the user can type."""
    import dataclasses

    parser = build_parser((command.replace("-", "_"),))
    sub = next(a for a in parser._actions if a.dest == "command").choices[command]
    flags = {s for a in sub._actions for s in a.option_strings}
    for f in dataclasses.fields(cls):
        assert f.name in given or flag(f.name) in flags, (command, f.name, flag(f.name))


# ---------------------------------------------------------------------- ik
def test_an_ik_goal_by_position_keeps_the_start_orientation_through_both(capsys):
    """goal_pose without rpy keeps the frame's orientation at q0 (fk at q0, the reference);
    dynid ik --goal-xyz solves for that goal: the same configuration as ik on goal_pose."""
    import json

    robot, q0 = dynid.panda(), dynid.PANDA_NEUTRAL_Q
    T = goal_pose(robot, q0, (0.35, 0.1, 0.45))
    np.testing.assert_array_equal(T[:3, :3], dynid.fk(robot, q0)[:3, :3])
    np.testing.assert_array_equal(T[:3, 3], [0.35, 0.1, 0.45])
    ref = dynid.ik(robot, T, q0, rng=np.random.default_rng(0))
    assert main(["ik", "--goal-xyz", "0.35,0.1,0.45", "--json"]) == 0
    np.testing.assert_array_equal(json.loads(capsys.readouterr().out)["q"], ref.q)
    with pytest.raises(OptionError) as api:
        goal_pose(robot, q0, (0.3, 0.1))
    assert api.value.field == "goal_xyz"
