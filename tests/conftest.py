"""Shared fixtures: the built-in Panda, a planar 2R arm with closed forms, seeded states,
simulated recordings of an arm with known terms."""

from __future__ import annotations

import dataclasses
import html
import os
import re
import subprocess
import sys
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import ArrayLike

import dynid
from dynid.exceptions import DynidWarning
from dynid.feasibility.compare import perturbed_robot  # noqa: F401 (shared with the tests)
from dynid.friction.model import Friction
from dynid.identification.least_squares import LeastSquaresFit
from dynid.identification.log import TorqueLog
from dynid.identification.model import IdentifiedModel
from dynid.model.drive import Drive
from dynid.regressors.base import base_parameters
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import Trajectory, random_fourier
from dynid.simulation.unmodelled import UnmodelledEffects


def pytest_configure(config: pytest.Config) -> None:
    """Ctrl-C as Python sets it, in this process and so in the workers and commands it
    starts: a shell starts a background job (``make test &``, a script run with ``&``) with
    SIGINT ignored, which Python keeps and every process it starts inherits, and the tests
    of Ctrl-C (``test_run_output.py``, ``test_cli_truthful_errors.py``) then saw no
    interrupt (8 failed in a fresh clone's ``make test`` started so)."""
    import signal

    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_sessionstart(session: pytest.Session) -> None:
    """With several test workers, compile the numba kernels first, in parallel groups
    (``tests/warm_kernels.py``), so that no two workers compile the same kernel at once on
    a clean checkout; a no-op in a worker, in a single-process run, or without numba."""
    config = session.config
    workers = getattr(config.option, "numprocesses", None)
    if hasattr(config, "workerinput") or not workers or os.environ.get("DYNID_NO_NUMBA"):
        return
    script = Path(__file__).with_name("warm_kernels.py")
    procs = [
        subprocess.Popen(
            [sys.executable, str(script), str(g)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        for g in range(2)
    ]
    for p in procs:
        p.wait()  # (a failure is not checked here: the tests meet the same fault)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The files holding a test marked ``slow`` first, then the others, each file's tests in
    their order: the workers of ``make test`` take whole files in collection order
    (``--dist loadscope --no-loadscope-reorder``), and a long file handed out last leaves
    the other worker idle while it runs."""
    slow = {item.path for item in items if item.get_closest_marker("slow") is not None}
    items.sort(key=lambda item: item.path not in slow)  # (a stable sort)


@pytest.fixture(autouse=True)
def _figures_closed():
    """Every figure a test drew closed after it (pyplot keeps them open: a worker that ran
    many figure tests in a row crossed matplotlib's 20 open figures, a warning and so an
    error)."""
    yield
    plt = sys.modules.get("matplotlib.pyplot")
    if plt is not None:
        plt.close("all")


@pytest.fixture(scope="session")
def panda() -> dynid.Robot:
    return dynid.panda()


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


def random_states(robot: dynid.Robot, n: int, seed: int):
    """``n`` seeded random (q, dq, ddq) with q inside the limits."""
    rng = np.random.default_rng(seed)
    lo = np.where(np.isfinite(robot.q_min), robot.q_min, -np.pi)
    hi = np.where(np.isfinite(robot.q_max), robot.q_max, np.pi)
    q = rng.uniform(lo, hi, (n, robot.n))
    dq = rng.uniform(-2.0, 2.0, (n, robot.n))
    ddq = rng.uniform(-5.0, 5.0, (n, robot.n))
    return q, dq, ddq


def planar_2r(
    l1: float = 0.7,
    l2: float = 0.5,
    m1: float = 2.0,
    m2: float = 1.5,
    I1: float = 0.05,
    I2: float = 0.03,
    g: float = 9.81,
) -> dynid.Robot:
    """Planar 2R arm moving in the vertical x-y plane (gravity along -y), CoM at mid-link.

    Joints rotate about z; link i has length l_i along its x axis (MDH a), point CoM
    inertia I_i about z at the CoM.
    """
    inertia = np.zeros((2, 3, 3))
    inertia[0] = np.diag([I1, I1, I1])
    inertia[1] = np.diag([I2, I2, I2])
    r = dynid.Robot.from_mdh(
        [0.0, l1],
        [0.0, 0.0],
        [0.0, 0.0],
        flange=(l2, 0.0, 0.0, 0.0),
        mass=[m1, m2],
        com=[[l1 / 2, 0, 0], [l2 / 2, 0, 0]],
        inertia=inertia,
        gravity=(0.0, -g, 0.0),
        name="planar2r",
    )
    return r


@pytest.fixture
def planar2r() -> dynid.Robot:
    return planar_2r()


def pinocchio_panda_urdf() -> str:
    """Path of example-robot-data's Panda URDF (skips the test when not installed)."""
    return robot_data_urdf("panda_description/urdf/panda.urdf")


def pinocchio_panda_model(arm=None, load=None):
    """Pinocchio's model of example-robot-data's Panda without its fingers (their joints
    locked), its seven links holding ``arm``'s inertials (a dynid robot; dynid's Panda by
    default) and ``load`` (a ``pinocchio.Inertia`` in link 7's frame) added to link 7;
    gravity 9.80665 m/s^2 along -z. Skips the test without Pinocchio."""
    import pytest

    pin = pytest.importorskip("pinocchio")
    import dynid

    arm = dynid.panda() if arm is None else arm
    full = pin.buildModelFromUrdf(pinocchio_panda_urdf())
    fingers = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(full, fingers, pin.neutral(full))
    for i in range(7):
        model.inertias[i + 1] = pin.Inertia(
            float(arm.mass[i]), np.array(arm.com[i]), np.array(arm.inertia[i])
        )
    if load is not None:
        model.inertias[7] += load
    model.gravity.linear[:] = [0.0, 0.0, -9.80665]
    return model


def pinocchio_panda_static(seed, N, margin=0.95, load=None):
    """Pinocchio's exact ``(q, M, g)`` of :func:`pinocchio_panda_model` (``load`` on link
    7) at ``N`` configurations drawn uniformly within ``margin`` times dynid's Panda's
    joint limits (seed ``seed``): what a controller's model gives at static
    configurations. Skips the test without Pinocchio."""
    import pytest

    pin = pytest.importorskip("pinocchio")
    import dynid

    model = pinocchio_panda_model(None, load)
    data = model.createData()
    robot = dynid.panda()
    rng = np.random.default_rng(seed)
    q = rng.uniform(np.asarray(robot.q_min) * margin, np.asarray(robot.q_max) * margin, (N, 7))
    M, g = np.empty((N, 7, 7)), np.empty((N, 7))
    for s in range(N):
        A = pin.crba(model, data, q[s]).copy()
        M[s] = np.triu(A) + np.triu(A, 1).T
        g[s] = pin.computeGeneralizedGravity(model, data, q[s])
    return q, M, g


def mujoco_inverse(model, q, dq, ddq):
    """MuJoCo's inverse dynamics ``qfrc_inverse`` (N, nv) of ``model`` (an ``MjModel``) at
    each state (N, nv)."""
    import mujoco

    data = mujoco.MjData(model)
    out = np.empty_like(q)
    for s in range(q.shape[0]):
        data.qpos[:], data.qvel[:], data.qacc[:] = q[s], dq[s], ddq[s]
        mujoco.mj_inverse(model, data)
        out[s] = data.qfrc_inverse
    return out


def robot_data_urdf(rel: str) -> str:
    import importlib.util
    from pathlib import Path

    spec = importlib.util.find_spec("example_robot_data")
    roots = []
    if spec is not None and spec.submodule_search_locations:
        roots += [Path(p) for p in spec.submodule_search_locations]
    import sys

    for p in sys.path:
        roots.append(Path(p) / "cmeel.prefix" / "share" / "example-robot-data" / "robots")
    for root in roots:
        for cand in (root / rel, root / "robots" / rel):
            if cand.exists():
                return str(cand)
    pytest.skip(f"example-robot-data file {rel} not found")


def given_fit(
    beta: ArrayLike, std: ArrayLike | None = None, kept: ArrayLike | None = None, **fields
) -> LeastSquaresFit:
    """A least-squares fit that holds the coefficients ``beta`` with standard deviations
    ``std`` (zeros by default), those ``kept`` (all by default; the others' rank not
    counted); ``fields``: any other of :class:`LeastSquaresFit`'s (``covariance``,
    ``sigma``, ``n_rows``, ...), the rest those of an exact fit."""
    beta = np.asarray(beta, dtype=float)
    std = np.zeros(beta.size) if std is None else np.asarray(std, dtype=float)
    keep = np.ones(beta.size, bool) if kept is None else np.asarray(kept, dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        percent = np.where(beta != 0, 100 * std / np.abs(beta), 0.0)
    given = dict(
        std_percent=percent, rank=int(keep.sum()), condition_number=1.0,
        relative_error_percent=0.0, residual_rms=0.0, sigma=0.0, n_rows=0, rtol=1e-10,
    )  # fmt: skip
    return LeastSquaresFit(beta=beta, std=std, kept=keep, **(given | fields))


def exact_model(
    robot: dynid.Robot, truth: dynid.Robot, kept: np.ndarray | None = None
) -> IdentifiedModel:
    """An identified model holding the exact static coefficients of ``truth`` (``kept``:
    the coefficients not pruned; the others are 0)."""
    base = base_parameters(robot, kind="static")
    r = base.rank
    keep = np.ones(r, bool) if kept is None else np.asarray(kept, dtype=bool)
    fit = given_fit(np.where(keep, base.beta_from_phi(truth.phi), 0.0), kept=keep)
    return IdentifiedModel(robot=robot, base=base, fit=fit)


def recordings(
    robot: dynid.Robot,
    seeds: Sequence[int],
    *,
    friction: Friction | None,
    duration: float,
    armature: ArrayLike | None = None,
    drive: Drive | None = None,
    added: Callable[[TorqueLog], np.ndarray] | None = None,
    noise: SensorNoise | None = None,
    fs: float = 500.0,
) -> list[TorqueLog]:
    """Recordings of ``robot`` whose torques hold known terms, one per seed.

    Each follows the random Fourier trajectory of its seed, ``duration`` s sampled at
    ``fs`` Hz; its torques are the rigid body's plus the ground-truth ``friction`` (None:
    none; a law per joint acts where ``drive`` puts it), the rotor inertias ``armature``
    (n,) [kg m^2] at the joints, and ``added(log)`` (N, n) [N m] on the log's states (a
    term the simulation does not hold: a spring, friction at a joint). Exact without
    ``noise`` (no sensor noise, the true accelerations kept); with ``noise``, drawn from
    ``default_rng(seed + 100)``, and no accelerations (they are derived).
    """
    effects = None
    if armature is not None:
        effects = UnmodelledEffects(rotor_inertia=armature, torque_offset=np.zeros(robot.n))
    t = sample_times(duration, fs)
    logs = []
    for seed in seeds:
        log = simulate_measurement(
            robot,
            random_fourier(robot, np.random.default_rng(seed))(t),
            rng=np.random.default_rng(seed + 100),
            noise=SensorNoise.none() if noise is None else noise,
            friction=friction,
            effects=effects,
            drive=drive,
            with_ddq=noise is None,
        )
        if added is not None:
            log = dataclasses.replace(log, tau=log.tau + added(log))
        logs.append(log)
    return logs


#: A geared Panda with a coupled wrist (motor 7 turns with joint 6: ``qm7 = 50 q7 + 20
#: q6``), logged as motor currents: gear ratios, rotor inertias [kg m^2] and torque
#: constants [N m/A] at the motors, the motors' friction (viscous, Coulomb, offset).
GEARED_GEARS = np.array([100.0, 100.0, 100.0, 100.0, 80.0, 80.0, 50.0])
GEARED_ROTORS = np.array([3e-4, 3e-4, 2.5e-4, 2.5e-4, 1e-4, 1e-4, 1e-4])
GEARED_NOISE = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)


def geared_drive() -> Drive:
    """The geared Panda's true drive (:data:`GEARED_GEARS`, its rotor inertias known)."""
    return Drive.from_gears(
        GEARED_GEARS,
        [(7, 6, 20.0)],
        side="motor",
        effort="current",
        torque_constant=np.full(7, 0.1),
        rotor_inertia=GEARED_ROTORS,
    )


def geared_recordings(
    robot: dynid.Robot, seeds: Sequence[int], *, duration: float = 3.0, offset: float = 0.0
) -> tuple[list[TorqueLog], Drive]:
    """Noisy motor-side current logs of ``robot`` through :func:`geared_drive`, with motor
    friction (viscous 2e-3, Coulomb 4e-3, ``offset`` [N m] at each motor) and rotor
    inertias the description lacks, one per seed; and the drive file's drive they are
    read through (its rotor inertias to identify)."""
    from dynid.friction.model import ClassicalFriction

    truth = geared_drive()
    fr = ClassicalFriction(np.full(7, 2e-3), np.full(7, 4e-3), np.full(7, offset))
    logs = recordings(robot, seeds, friction=fr, drive=truth, duration=duration, noise=GEARED_NOISE)
    return logs, dataclasses.replace(truth, rotor_inertia=None)


def point_to_point(robot: dynid.Robot, seed: int, fs: float = 500.0, moves: int = 8) -> Trajectory:
    """``moves`` moves between random configurations (quintic profiles of 1.2 s), each
    followed by a rest of 1 s: the joints stand still more than a third of the time. The
    first moves of a seed are the same whatever ``moves``."""
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(robot.q_min), np.asarray(robot.q_max)
    mid, span = (lo + hi) / 2, (hi - lo) / 2
    q0 = mid + 0.3 * span * rng.uniform(-1, 1, robot.n)
    s = np.arange(0.0, 1.2, 1 / fs) / 1.2
    h = np.column_stack(
        [
            10 * s**3 - 15 * s**4 + 6 * s**5,
            (30 * s**2 - 60 * s**3 + 30 * s**4) / 1.2,
            (60 * s - 180 * s**2 + 120 * s**3) / 1.2**2,
        ]
    )
    rest = int(fs)
    parts = []
    for _ in range(moves):
        q1 = mid + 0.5 * span * rng.uniform(-1, 1, robot.n)
        d = q1 - q0
        moving = [q0 + np.outer(h[:, 0], d), np.outer(h[:, 1], d), np.outer(h[:, 2], d)]
        still = [np.tile(q1, (rest, 1)), np.zeros((rest, robot.n)), np.zeros((rest, robot.n))]
        parts.append([np.vstack([m, r]) for m, r in zip(moving, still, strict=True)])
        q0 = q1
    q, dq, ddq = (np.vstack([p[k] for p in parts]) for k in range(3))
    return Trajectory(np.arange(q.shape[0]) / fs, q, dq, ddq)


#: A test asset: the SO-101's 5-joint arm (joints, limits and inertials; no meshes, no jaw).
SO101_URDF = Path(__file__).parent / "data" / "so101_arm.urdf"
#: A short exciting-trajectory design for tests: 6 s, 3 harmonics, a budget a test affords.
SHORT_EXCITATION = {
    "duration": 6.0,
    "harmonics": 3,
    "base_frequency": 1 / 6,
    "max_iter": 40,
    "n_starts": 8,
    "max_evaluations": 1500,
}


def said_warnings(fn: Callable[..., object], *args: object, **kw: object):
    """``fn(*args, **kw)``'s result and the messages of the DynidWarnings it gave."""
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        out = fn(*args, **kw)
    return out, [str(w.message) for w in got if issubclass(w.category, DynidWarning)]


#: A URDF whose tree has two leaves (an arm of two joints and a camera pan beside it): a
#: chain needs its tip named.
TWO_LEAVES = """<robot name="two_leaves">
  <link name="world"/>
  <link name="upper"><inertial><origin xyz="0 0 0.15"/><mass value="2.0"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.004"/></inertial></link>
  <link name="lower"><inertial><origin xyz="0.1 0 0"/><mass value="1.0"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="camera"><inertial><mass value="0.3"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="world"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="50" velocity="3"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="lower"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="30" velocity="3"/></joint>
  <joint name="pan" type="revolute"><parent link="world"/><child link="camera"/>
    <origin xyz="0.2 0 0.05"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="5" velocity="3"/></joint>
</robot>
"""


def report_of(command: str, files: dict[str, Path], notes: Sequence[str] = ()) -> str:
    """The report page of a ``command`` run that wrote ``files`` (name -> path) and said
    ``notes``, written beside the first file as ``report.html`` (to open in a browser)."""
    from dynid.report import RunSummary, render_html_report

    page = render_html_report(RunSummary(command=command, notes=tuple(notes)), files)
    next(iter(files.values())).with_name("report.html").write_text(page, encoding="utf-8")
    return page


def verdict_of(page: str) -> str:
    """The text of a report page's verdict box (tags stripped, white space collapsed)."""
    m = re.search(r'<section class="verdict \w+" id="verdict">(.*?)</section>', page, re.S)
    assert m is not None, "no verdict box"
    text = re.sub(r"<[^>]+>", "", re.sub(r"</(li|p|span)>", " ", m.group(1)))
    return " ".join(html.unescape(text).split())


def section_of(page: str, anchor: str) -> list[list[str]]:
    """The rows (cell texts) of the first table after the heading ``id=anchor``."""
    after = page.split(f'<h2 id="{anchor}">', 1)
    assert len(after) == 2, f"no section {anchor}"
    body = after[1].split("</table>", 1)[0]
    rows = re.findall(r"<tr[^>]*>(.*?)</tr>", body, re.S)
    cells = [re.findall(r"<t[hd][^>]*>(.*?)</t[hd]>", r, re.S) for r in rows]
    return [[html.unescape(re.sub(r"<[^>]+>", "", c)).strip() for c in r] for r in cells]
