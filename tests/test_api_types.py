"""Wrong argument types at the public entry points: one WrongTypeError naming the argument,
what was given and what is expected, never an AttributeError from deep inside."""

import numpy as np
import pytest

import dynid
from dynid.exceptions import WrongTypeError
from dynid.workflows.identify import IdentifyOptions, identify_files, identify_logs
from dynid.workflows.validate import validate_files

Q7 = np.zeros(7)


@pytest.fixture(scope="module")
def log() -> dynid.TorqueLog:
    t = np.arange(5) * 0.002
    return dynid.TorqueLog(t=t, q=np.zeros((5, 7)), dq=np.zeros((5, 7)), tau=np.zeros((5, 7)))


@pytest.mark.parametrize(
    ("logs", "got"),
    [
        ({"t": np.arange(3.0)}, "got dict$"),
        ([{"t": np.arange(3.0)}], "got a list holding dict at index 0$"),
        ((np.arange(3.0), np.zeros((3, 7))), "got a tuple holding ndarray of float64 at index 0$"),
        ("rec1.csv", "got str$"),
    ],
)
def test_identify_logs_names_logs_of_the_wrong_type(panda, logs, got):
    """A dict, a tuple of arrays or a file name as ``logs``: the argument and what it takes
    (was: AttributeError "'dict' object has no attribute 'dq_derived'")."""
    with pytest.raises(WrongTypeError, match="^logs: expected a TorqueLog or a sequence of Torq"):
        identify_logs(panda, logs)
    with pytest.raises(WrongTypeError, match=got):
        identify_logs(panda, logs)


def test_identify_logs_names_options_robot_and_validate_on(panda, log):
    """A dict of options (once silently the defaults when empty), a robot's name and a
    separate log of the wrong type are each named."""
    for options in ({}, {"cutoff_hz": 3.0}):
        with pytest.raises(
            WrongTypeError, match="^options: expected an IdentifyOptions, got dict$"
        ):
            identify_logs(panda, [log], options)
    with pytest.raises(
        WrongTypeError, match=r"^robot: expected a Robot \(dynid.panda\(\), .*got str$"
    ):
        identify_logs("panda", [log], IdentifyOptions())
    with pytest.raises(WrongTypeError, match="^validate_on: expected a TorqueLog .*got dict$"):
        identify_logs(panda, [log], validate_on={"t": log.t})
    with pytest.raises(WrongTypeError, match="^robot: expected a Robot .*got None$"):
        identify_files(None, "x.csv")
    with pytest.raises(
        WrongTypeError, match="^model: expected an IdentifiedModel .* or a Robot, got str$"
    ):
        validate_files("identification.json", "x.csv")


@pytest.mark.parametrize(
    "call",
    [
        lambda r: dynid.rnea("panda", Q7, Q7, Q7),
        lambda r: dynid.mass_matrix(None, Q7),
        lambda r: dynid.gravity_torques({"n": 7}, Q7),
        lambda r: dynid.fk([r], Q7),
        lambda r: dynid.jacobian("panda", Q7),
        lambda r: dynid.torque_regressor("panda", Q7, Q7, Q7),
        lambda r: dynid.base_parameters("panda"),
        lambda r: dynid.random_fourier("panda", np.random.default_rng(0)),
    ],
)
def test_functions_of_a_robot_name_a_robot_of_the_wrong_type(panda, call):
    """A non-Robot first argument is named, not an AttributeError ('str' object has no
    attribute 'joint_names')."""
    with pytest.raises(WrongTypeError, match=r"^robot: expected a Robot \(dynid.panda\(\), "):
        call(panda)


def test_logs_and_static_data_of_the_wrong_type_are_named(panda, log):
    """validate_torques, fit_friction, identify_static and simulate_measurement name their
    data argument."""
    with pytest.raises(WrongTypeError, match="^log: expected a TorqueLog .*got dict$"):
        dynid.validate_torques(panda, {"t": log.t})
    with pytest.raises(WrongTypeError, match="^log: expected a TorqueLog .*got list$"):
        dynid.fit_friction(panda, [log])
    with pytest.raises(WrongTypeError, match="^data: expected a StaticDataset .*got dict$"):
        dynid.identify_static(panda, {"q": Q7})
    with pytest.raises(WrongTypeError, match="^traj: expected a Trajectory .*ndarray of float64$"):
        dynid.simulate_measurement(panda, np.zeros((3, 7)), rng=np.random.default_rng(0))


@pytest.mark.parametrize("fn", [dynid.mass_matrix, dynid.gravity_torques, dynid.static_regressor])
@pytest.mark.parametrize(
    ("q", "got"),
    [
        ("abc", "str"),
        (Q7 + 0j, "ndarray of complex128"),
        (np.zeros((3, 7), complex), "ndarray of complex128"),
        ([0j] * 7, "list"),
        (np.array(["0"] * 7), "ndarray of <U1"),
    ],
)
def test_text_and_complex_positions_are_refused_as_types(panda, fn, q, got):
    """Text was a ShapeError and a complex q was cast to real with a ComplexWarning (its
    imaginary part dropped): both are a WrongTypeError naming q."""
    with pytest.raises(WrongTypeError, match=f"^q: expected a real numeric array_like, got {got}$"):
        fn(panda, q)


def test_complex_states_are_refused_on_the_single_sample_path(panda):
    """One sample as the fast path takes it: complex velocities refused there too."""
    for _ in range(3):
        with pytest.raises(WrongTypeError, match="^dq: expected a real numeric array_like"):
            dynid.rnea(panda, Q7, Q7 + 1j, Q7)
    assert np.allclose(dynid.rnea(panda, Q7, Q7, Q7), dynid.gravity_torques(panda, Q7))


def test_text_positions_are_refused_on_the_compiled_paths(panda):
    """Once the compiled kernels serve the calls, text arrays were read as numbers
    (``np.array(["0"] * 7)`` gave the mass matrix at zero) and complex ones cast."""
    for _ in range(300):  # past the single-sample calls served by numpy first
        dynid.mass_matrix(panda, Q7)
    for q in (np.array([["0"] * 7] * 2), np.array(["0"] * 7), np.zeros((2, 7), complex)):
        with pytest.raises(WrongTypeError, match="^q: expected a real numeric array_like, got nd"):
            dynid.mass_matrix(panda, q)


def test_entry_points_of_files_name_a_log_given_for_a_path(panda, log):
    """A TorqueLog given where files are read said "'TorqueLog' object is not iterable";
    the message names data and the functions that take logs already read."""
    from dynid.workflows.retrieve import retrieve_files

    for data in (log, [log]):
        with pytest.raises(WrongTypeError, match=r"^data: expected a path \(str or Path\) or a"):
            identify_files(panda, data)
    with pytest.raises(WrongTypeError, match=r"\(logs already read: identify_logs, validate_t"):
        validate_files(panda, log)
    with pytest.raises(WrongTypeError, match=r"^source: expected a path \(str or Path\) of a file"):
        retrieve_files(panda)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda r: dynid.random_fourier(r, 0), "^rng: expected a numpy.random.Generator"),
        (lambda r: dynid.optimise_excitation(r, 7), "^rng: expected a numpy.random.Generator"),
        (lambda r: dynid.acquire_static(r), "^controller: expected a SimulatedController"),
        (lambda r: dynid.identifiability(r), r"^base: expected a BaseParameters \(dynid.base_p"),
        (
            lambda r: dynid.param_labels("7"),
            r"^n: expected an int \(the number of links\), got str$",
        ),
        (lambda r: dynid.scale_into_limits(r, np.zeros((3, 7))), "^traj: expected a Trajectory"),
        (
            lambda r: dynid.check_limits(r, dynid.random_fourier(r, np.random.default_rng(0))),
            r"random_fourier\(robot, rng\)\(t\)\), got FourierSeries$",
        ),
    ],
)
def test_generators_controllers_and_trajectories_of_the_wrong_type(panda, call, message):
    """A seed for a Generator ('int' object has no attribute 'standard_normal'), a robot
    for a controller, an unsampled Fourier series for a trajectory: each named."""
    with pytest.raises(WrongTypeError, match=message):
        call(panda)


def test_identify_from_log_names_a_list_of_logs(panda, log):
    """Regression (a Python API trial): ``identify_from_log(robot, [log1, log2])`` raised
    AttributeError "'list' object has no attribute 'dq_derived'"; it names the argument
    and the function that takes several."""
    with pytest.raises(WrongTypeError, match="^log: expected a TorqueLog, got a list of 2; sev"):
        dynid.identify_from_log(panda, [log, log])
    with pytest.raises(WrongTypeError, match="identify_logs, which keeps each apart"):
        dynid.identify_from_log(panda, (log,))
    with pytest.raises(WrongTypeError, match="^robot: "):
        dynid.identify_from_log("panda", log)


def test_fk_names_a_list_of_frames_as_a_type(panda):
    """Regression (a Python API trial): ``fk(robot, q, ["flange"])`` said "Unknown frame
    ['flange']" as if the name were wrong; a frame is one name a call."""
    with pytest.raises(WrongTypeError, match="^frame: expected a frame's name"):
        dynid.fk(panda, Q7, ["flange"])
    np.testing.assert_array_equal(dynid.fk(panda, Q7, "flange"), dynid.fk(panda, Q7))
