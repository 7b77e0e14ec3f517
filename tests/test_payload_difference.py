"""The load's doubt judged on what the load leaves beyond the arm (difference method).

References: the loaded and unloaded Panda following one trajectory, Pinocchio's RNEA
(example-robot-data's kinematics, the published inertials of Gaz et al. 2019, the load
added to link 7 at the flange) with white sensor noise and a spring on joint 2 that the
arm's model lacks; the load is the truth the estimates are compared with. The matching
along the unloaded trajectory is checked against a closed form (a residual linear along
a straight-line motion).
"""

from __future__ import annotations

import dataclasses
import json
import re
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.feasibility.payload import identify_payload
from dynid.feasibility.payload_difference import MATCH_DISTANCE, matched_residual
from dynid.identification.log import TorqueLog
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.model_json import save_model_json
from dynid.io.payload_json import payload_to_dict
from dynid.io.torque_log import save_torque_log
from dynid.model.drive import Drive
from dynid.simulation.measurement import simulate_measurement
from dynid.simulation.trajectories import random_fourier, uniform_times

from conftest import pinocchio_panda_model

MASS, COM = 1.5, np.array([0.03, -0.02, 0.08])
INERTIA = np.diag([0.004, 0.005, 0.003])
ARM = dynid.panda().with_friction(None)
FLANGE_Z = 0.107  # the flange on link 7 [m]
SPRING = 4.0  # the joint-2 spring the arm's model lacks [N m / rad]: 6.6 x the noise
LINKS = Structure.parse("links")


@pytest.fixture(scope="module")
def logs():
    """8 s at 500 Hz of one trajectory: the loaded Panda, the load moved 2 cm along x
    halfway, and the arm without it; Pinocchio's torques, 0.05 N m noise, and a spring
    on joint 2 in each."""
    pin = pytest.importorskip("pinocchio")
    model = pinocchio_panda_model(ARM)
    t = uniform_times(8.0, 500.0)
    traj = random_fourier(ARM, np.random.default_rng(4), q0=dynid.PANDA_NEUTRAL_Q)(t)
    arm7 = model.inertias[7].copy()

    def torques(com, seed):
        model.inertias[7] = arm7.copy()
        if com is not None:
            model.inertias[7] += pin.Inertia(MASS, com + [0.0, 0.0, FLANGE_Z], INERTIA)
        data = model.createData()
        states = zip(traj.q, traj.dq, traj.ddq, strict=True)
        tau = np.array([pin.rnea(model, data, q, dq, ddq) for q, dq, ddq in states])
        tau[:, 1] += SPRING * (traj.q[:, 1] - 0.2)
        return tau + np.random.default_rng(seed).normal(0.0, 0.05, tau.shape)

    def log(tau):
        return TorqueLog(t=t, q=traj.q, dq=traj.dq, tau=tau)

    loaded, moved = torques(COM, 2), torques(COM + [0.02, 0.0, 0.0], 2)
    half = t.size // 2
    moved = np.concatenate([loaded[:half], moved[half:]])
    return log(loaded), log(moved), log(torques(None, 3))


def _estimate(log, unloaded=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dynid.DynidWarning)
        return identify_payload(ARM, log, unloaded=unloaded, structure=LINKS)


def test_an_arm_misfit_common_to_both_recordings_does_not_withhold_the_load(logs):
    """Regression (--unloaded with a spring the arm's model lacks in both recordings: the
    fit left 6 x the torque noise and setLoad was withheld although the mass was right):
    the difference from the unloaded arm's residual at matched states is judged, at the
    noise; setLoad's mass and CoM are written, within one standard deviation of the truth.
    Without --unloaded the same log is doubted as before (the fit's residual judged)."""
    loaded, _, unloaded = logs
    est = _estimate(loaded, unloaded)
    assert est.residual_rms > 3 * est.noise_rms  # the arm's misfit is in the fit
    j = est.judged
    assert j is not None and j.kind == "difference" and j.matched > 0.99
    assert j.ratio is not None and j.ratio < 1.5
    assert not est.doubts, est.doubts
    assert abs(est.mass - MASS) < est.std_mass
    assert np.all(np.abs(est.com - COM) < est.std_com)
    d = payload_to_dict(est, ARM)
    assert d["load_mass"] == pytest.approx(est.mass) and d["F_x_Cload"] is not None
    assert d["judged_residual"]["kind"] == "difference"
    alone = _estimate(loaded)
    assert alone.judged is not None and alone.judged.kind == "fit"
    assert alone.judged.ratio == pytest.approx(alone.residual_rms / alone.noise_rms)
    assert alone.judged.ratio > 3 and not alone.plausible
    assert payload_to_dict(alone, ARM)["load_mass"] is None


def test_a_load_that_moved_between_the_recordings_is_still_withheld(logs):
    """The load moved 2 cm halfway through the loaded recording (the spring in both): the
    difference at matched states leaves more than 3 x the noise of both recordings, the
    doubt says what it judged and no setLoad values are written."""
    _, moved, unloaded = logs
    est = _estimate(moved, unloaded)
    j = est.judged
    assert j is not None and j.kind == "difference" and j.ratio is not None and j.ratio > 3
    (said,) = [d for d in est.doubts if "x the noise of both recordings" in d]
    assert f"{j.ratio:.3g} x" in said and "matched states" in said
    d = payload_to_dict(est, ARM)
    assert d["load_mass"] is None and d["F_x_Cload"] is None and not d["plausible"]


def test_cli_prints_the_residual_judged_and_its_ratio(logs, tmp_path, capsys):
    """dynid payload --model (the arm's links, identified on the unloaded log) --unloaded:
    the fit at over 3 x the torque noise, the printout names the difference judged and its
    ratio, payload.json records it with setLoad's mass within its std, and the report
    calls the load no misfit's (not 'not a load to trust')."""
    loaded, _, unloaded = logs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dynid.DynidWarning)
        model = identify_recordings(ARM, [unloaded], structure=LINKS)
    save_model_json(tmp_path / "arm.json", model)
    save_torque_log(tmp_path / "loaded.csv", loaded)
    save_torque_log(tmp_path / "unloaded.csv", unloaded)
    argv = ["payload", "--model", str(tmp_path / "arm.json"), "--data"]
    argv += [str(tmp_path / "loaded.csv"), "--unloaded", str(tmp_path / "unloaded.csv")]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dynid.DynidWarning)
        assert main([*argv, "--out", str(tmp_path / "p")]) == 0
    out = capsys.readouterr().out
    (line,) = [x for x in out.splitlines() if x.strip().startswith("judged")]
    doc = json.loads((tmp_path / "p" / "payload.json").read_text())
    ratio = doc["judged_residual"]["ratio"]
    assert doc["residual_rms"] > 3 * doc["noise_rms"]
    assert "difference from the unloaded arm's residual" in line and f"{ratio:.3g} x" in line
    assert ratio < 3 and doc["load_mass"] is not None
    assert abs(doc["load_mass"] - MASS) < doc["std"]["mass"]
    html = (tmp_path / "p" / "report.html").read_text(encoding="utf-8")
    box = re.search(r'<section class="verdict.*?</section>', html, re.S)
    assert box is not None
    text = " ".join(re.sub(r"<[^>]+>", " ", box.group(0)).split())
    assert "not a load to trust" not in text
    assert "judged on the difference from the unloaded arm" in text


def test_matching_interpolates_along_the_unloaded_trajectory():
    """A motion repeated 0.4 of a sample later: the unloaded residual, linear along a
    straight-line motion, is interpolated at the loaded states exactly (closed form), each
    at distance 0; a state far from the trajectory is beyond MATCH_DISTANCE. Samples of
    another piece are not joined across its end."""
    s0 = np.linspace(0.0, 1.0, 11)
    direction = np.array([1.0, -2.0, 0.5])
    x0 = s0[:, None] * direction
    r0 = np.stack([3.0 * s0 + 1.0, -s0], axis=1)
    labels = np.zeros(11, dtype=np.int64)
    s1 = np.clip(s0 + 0.04, 0.0, 1.0)
    x1 = np.vstack([s1[:, None] * direction, [[5.0, 5.0, 5.0]]])
    at, dist = matched_residual(x1, x0, labels, r0)
    np.testing.assert_allclose(at[:-1], np.stack([3.0 * s1 + 1.0, -s1], axis=1), atol=1e-12)
    np.testing.assert_allclose(dist[:-1], 0.0, atol=1e-12)
    assert dist[-1] > MATCH_DISTANCE
    labels[6:] = 1  # a gap between samples 5 and 6: no segment across it
    at, _ = matched_residual(np.array([0.55 * direction]), x0, labels, r0)
    assert at[0, 0] == pytest.approx(3.0 * 0.5 + 1.0) or at[0, 0] == pytest.approx(2.8)


def test_without_a_repeated_motion_the_fit_is_judged(logs):
    """An unloaded recording of another motion (the loaded states time-reversed) matches
    no loaded sample: the fit's residual is judged, with a note, as without --unloaded."""
    loaded, _, unloaded = logs
    other = dataclasses.replace(
        unloaded, q=unloaded.q[::-1].copy(), dq=-unloaded.dq[::-1], tau=unloaded.tau[::-1].copy()
    )
    est = _estimate(loaded, other)
    assert est.judged is not None and est.judged.kind == "fit" and est.judged.matched < 0.5
    assert any("motions do not match" in note for note in est.notes)


def test_an_armature_both_recordings_hold_does_not_withhold_the_load():
    """A per-joint armature (0.03-0.1 kg m^2) the arm's links-only model lacks, in a loaded
    and an unloaded recording of one motion (dynid's simulation, the load put on with
    Robot.with_tool): the fit leaves over 3 x the torque noise, the difference at matched
    states stays under 1.5 x, and the mass and CoM are within one standard deviation of
    the load, their setLoad values written."""
    ia = np.array([0.08, 0.08, 0.06, 0.09, 0.1, 0.03, 0.06])
    drive = dataclasses.replace(Drive.identity(7), rotor_inertia=ia)
    traj = random_fourier(ARM, np.random.default_rng(4), q0=dynid.PANDA_NEUTRAL_Q)(
        uniform_times(8.0, 200.0)
    )
    loaded = ARM.with_tool(np.eye(4), MASS, COM, INERTIA, name="load")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dynid.DynidWarning)
        logs = [
            simulate_measurement(r, traj, rng=np.random.default_rng(s), friction=None, drive=drive)
            for r, s in ((loaded, 1), (ARM, 2))
        ]
    est = _estimate(*logs)
    assert est.residual_rms > 3 * est.noise_rms
    assert est.judged is not None and est.judged.kind == "difference"
    assert est.judged.ratio is not None and est.judged.ratio < 1.5
    assert abs(est.mass - MASS) < est.std_mass
    assert np.all(np.abs(est.com - COM) < est.std_com)
    assert payload_to_dict(est, ARM)["F_x_Cload"] is not None
