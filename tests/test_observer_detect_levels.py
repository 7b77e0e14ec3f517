"""The thresholds of a detection built once per block and handed along, against truth.

* a simulated step of force at the flange (its true external torques and onset known):
  one event, starting within the observer's first-order lag of the onset (the crossing
  time of ``tau (1 - exp(-K t))`` through the threshold, closed form) and ending within
  the lag's decay after the release; no other event; the figure's thresholds are the
  fixed levels given;
* the detector fed the levels directly: the events of a residual built by hand, NaN
  levels where the residual is not observed never read;
* the samples kept over the threshold for a carried load's fit, joined once and selected
  per span: exactly the samples built over the threshold, both ends included.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.exceptions import ShapeError
from dynid.io.observer_files import save_thresholds
from dynid.observer.carried_load import LoadSamples, samples_within
from dynid.observer.events import EventDetector
from dynid.observer.residual import DEFAULT_GAIN, ObserverOptions
from dynid.observer.thresholds import Thresholds
from dynid.workflows.observe import ObserveOptions, observe_files

RATE = 1000.0
CONTACT, COLLISION = 0.5, 1.0  # [N m], every joint
ONSET, RELEASE = 1.5, 2.0  # [s]


def _fixed(n: int = 7) -> Thresholds:
    return Thresholds(
        contact=np.full(n, CONTACT),
        collision=np.full(n, COLLISION),
        margin=1.5,
        quantile=1.0,
        collision_factor=COLLISION / CONTACT,
        options=ObserverOptions(),
        samples=1,
    )


@pytest.fixture(scope="module")
def pushed(tmp_path_factory):
    d = tmp_path_factory.mktemp("levels")
    assert main(["simulate", "--trajectory", "fourier", "-q", "--duration", "3", "--seed",
                 "3", "--noise", "0.01", "--q-noise", "1e-6", "--dq-noise", "1e-5",
                 "--contact", f"flange:0,10,0:{ONSET},{RELEASE}",
                 "--out", str(d / "hit.csv")]) == 0  # fmt: skip
    names = [f"joint{j + 1}" for j in range(7)]
    save_thresholds(d / "thresholds.json", _fixed(), joints=names)
    opts = ObserveOptions(
        data=(d / "hit.csv",),
        params="panda",
        thresholds=d / "thresholds.json",
        frame="flange",
        keep_series=True,
        figure_points=500,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return observe_files(opts)


def test_a_pushed_flange_is_one_event_within_the_observer_lag_of_its_onset(pushed):
    """One event, its start and end within the closed-form lag of the true step."""
    (log,) = pushed.logs
    ext = log.tau_ext
    on = np.abs(ext).max(axis=1) > 0
    t0, t1 = log.t[on][0], log.t[on][-1]
    assert t0 == pytest.approx(ONSET, abs=1.5 / RATE)
    assert t1 == pytest.approx(RELEASE, abs=1.5 / RATE)
    first, last = np.abs(ext[on][0]), np.abs(ext[on][-1])  # the step's torques [N m]
    up, down = first > CONTACT, last > CONTACT
    rise = float(np.min(-np.log(1.0 - CONTACT / first[up]) / DEFAULT_GAIN))
    fall = float(np.max(np.log(last[down] / CONTACT) / DEFAULT_GAIN))
    (event,) = log.events  # no false alarm
    assert t0 - 1 / RATE <= event.start <= t0 + rise + 3 / RATE
    assert t1 <= event.end <= t1 + fall + 3 / RATE
    surely = {j + 1 for j in np.flatnonzero(first > 1.2 * CONTACT)}
    maybe = {j + 1 for j in np.flatnonzero(np.abs(ext).max(axis=0) > 0.9 * CONTACT)}
    assert surely <= set(event.joints) <= maybe


def test_the_figure_carries_the_fixed_levels_where_observed(pushed):
    """Every figure sample's thresholds are the levels given (NaN only where unobserved)."""
    fig = pushed.logs[0].figure
    seen = np.all(np.isfinite(fig.r), axis=1)
    assert seen.all()
    assert np.all(fig.contact == CONTACT) and np.all(fig.collision == COLLISION)


def test_the_detector_fed_levels_finds_the_run_built_over_them():
    """A run over a varying threshold: its first and last samples are the event's."""
    t = np.arange(200) / RATE
    r = np.zeros((200, 2))
    contact = np.full((200, 2), 1.0)
    contact[:, 1] = np.linspace(1.0, 3.0, 200)  # a threshold that grows
    r[50:90, 1] = 2.0  # over 1 + 2 k / 199 up to k = 99: the whole run
    r[150:170, 1] = 2.0  # under the threshold there (2.5 and more)
    r[:5] = np.nan  # not observed: levels there are NaN and never read
    contact[:5] = np.nan
    det = EventDetector(_fixed(2), merge_s=0.0, min_duration_s=0.0)
    events = det.feed(t, r, levels=(contact, 2.0 * contact)) + det.finish()
    (event,) = events
    assert event.start == t[50] and event.end == t[89]
    assert event.joints == (2,) and event.level == "contact"


def test_the_detector_refuses_levels_of_another_shape():
    """Levels not (m, n): ShapeError naming them."""
    det = EventDetector(_fixed(2))
    bad = np.ones((3, 3))
    with pytest.raises(ShapeError, match="contact must have shape"):
        det.feed(np.arange(3.0), np.zeros((3, 2)), levels=(bad, bad))


def test_load_samples_are_joined_once_and_selected_by_span():
    """The samples over the threshold of two blocks, a span's both ends included."""
    kept = LoadSamples(1.0 / 200.0)  # every sample at 200 Hz
    t = np.arange(20) * 0.005
    q = np.arange(40.0).reshape(20, 2)
    r = np.zeros((20, 2))
    r[[3, 4, 12, 17], 0] = 2.0
    c = np.ones((20, 2))
    kept.add(t[:10], q[:10], r[:10], c[:10])
    kept.add(t[10:], q[10:], r[10:], c[10:])
    joined = kept.joined()
    assert joined is not None
    assert np.array_equal(joined[0], t[[3, 4, 12, 17]])
    assert np.array_equal(joined[1], q[[3, 4, 12, 17]])
    got = samples_within(joined, t[4], t[12])
    assert got is not None and np.array_equal(got[0], t[[4, 12]])
    assert samples_within(joined, t[5], t[11]) is None
    assert LoadSamples(None).joined() is None
