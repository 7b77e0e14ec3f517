"""Detection a block of samples at a time: the events of :class:`EventDetector` fed any
blocks equal those of a per-sample reference written from the definition (runs over the
threshold, joined within merge_s, never across a restart; peaks at the first largest
magnitude; the largest residual over its sample's threshold); ``dynid observe
--thresholds`` in blocks that cut a contact gives the events and the residual table of one
block, and finds a simulated contact at its time."""

from __future__ import annotations

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.observer.detection import Thresholds, detect
from dynid.observer.events import EventDetector
from dynid.observer.residual import ObserverOptions


def _reference(t, r, contact, collision, merge_s, restarts, min_duration_s=0.0, dropped=None):
    """Events sample by sample: (start, end, joints, peak, level). Runs of samples over
    the threshold one after the other in one piece; a run shorter than
    ``min_duration_s`` at the contact level with no other run within ``merge_s / 2``
    before or after it in its piece left out; the other runs joined when closer than
    ``merge_s`` in one piece; events shorter than ``min_duration_s`` at the contact
    level left out; joints, peaks and level over every sample of an event. The runs and
    events left out are appended to ``dropped`` as (start, end, joints, peak, rule,
    ratio), ``ratio`` the largest ``|r| / contact`` per joint over their samples."""
    r = np.where(np.isfinite(r), r, 0.0)

    def named(a, last, rule):
        b = last + 1
        over = (np.abs(r[a:b]) > contact[a:b]).any(0)
        k = np.argmax(np.abs(r[a:b]), axis=0)  # the first of the largest magnitudes
        peak = tuple(float(r[a + k[j], j]) for j in range(r.shape[1]))
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.nan_to_num(np.abs(r[a:b]) / contact[a:b], nan=0.0).max(0)
        joints = tuple(int(j) + 1 for j in np.flatnonzero(over))
        return (float(t[a]), float(t[last]), joints, peak, rule, tuple(ratio))

    def piece(k):
        return sum(s <= k for s in restarts)

    def collides(a, b):
        return bool(np.any(np.abs(r[a : b + 1]) > collision[a : b + 1]))

    runs = []
    for k in range(t.shape[0]):
        if not (np.abs(r[k]) > contact[k]).any():
            continue
        if runs and runs[-1][1] == k - 1 and piece(k) == piece(k - 1):
            runs[-1][1] = k
        else:
            runs.append([k, k])
    kept = []
    for i, (a, b) in enumerate(runs):
        others = [x for x in runs[:i] + runs[i + 1 :] if piece(x[0]) == piece(a)]
        near = any(0.0 < t[x[0]] - t[b] <= merge_s / 2 or 0.0 < t[a] - t[x[1]] <= merge_s / 2
                   for x in others)  # fmt: skip
        if t[b] - t[a] >= min_duration_s or collides(a, b) or near:
            kept.append((a, b))
        elif dropped is not None:
            dropped.append(named(a, b, "isolated"))
    events = []
    for a, b in kept:
        if events and piece(a) == piece(events[-1][1]) and t[a] - t[events[-1][1]] <= merge_s:
            events[-1][1] = b
        else:
            events.append([a, b])
    out = []
    for a, last in events:
        if t[last] - t[a] < min_duration_s and not collides(a, last):
            if dropped is not None:
                dropped.append(named(a, last, "short"))
            continue
        b = last + 1
        joints = tuple(int(j) + 1 for j in np.flatnonzero((np.abs(r[a:b]) > contact[a:b]).any(0)))
        peak = []
        for j in range(r.shape[1]):
            best = 0
            for k in range(a, b):  # the first of the largest magnitudes
                if abs(r[k, j]) > abs(r[best + a, j]):
                    best = k - a
            peak.append(float(r[a + best, j]))
        out.append((float(t[a]), float(t[b - 1]), joints, tuple(peak),
                    "collision" if collides(a, last) else "contact"))  # fmt: skip
    return out


def _as_tuples(events):
    return [(e.start, e.end, e.joints, e.peak, e.level) for e in events]


def _same_dropped(got, want):
    """Dropped crossings equal: times, joints, peaks and rule exactly, ratios to 1e-12."""
    assert [(d.start, d.end, d.joints, d.peak, d.rule) for d in got] == [w[:5] for w in want]
    for d, w in zip(got, want, strict=True):
        np.testing.assert_allclose(d.ratio, w[5], rtol=1e-12)


@pytest.mark.parametrize("merge", [0.05, 0.0])
def test_events_fed_in_blocks_are_those_of_the_definition(merge):
    """A noisy residual with bursts (some closer than merge_s, one across a restart, NaN
    samples, the uncertainty's std and a standstill margin, a one-sample crossing 40 ms
    before a burst, a contact-level burst that the noise dips below the threshold, two
    one-sample crossings 3 ms apart):
    blocks of every size from 1 sample to the whole log give the reference's events, as
    the whole log in one block (detect) does. The lone crossing does not start the
    burst's event (joined first, it began the event 40 ms early); the dipping burst is
    one contact event (its crossings are close together). With ``merge_s = 0`` a run of
    samples over the threshold one after the other is one event (each sample was one).
    The crossings the minimum duration drops are the reference's, isolated or short, in
    any blocks."""
    rng = np.random.default_rng(4)
    N, n = 1000, 3
    t = np.cumsum(rng.uniform(0.8e-3, 1.2e-3, N))
    r = 0.05 * rng.standard_normal((N, n))
    for a, size, j in ((100, 30, 0), (160, 5, 1), (400, 80, 2), (590, 30, 0), (700, 3, 1)):
        r[a : a + size, j] += rng.choice([-1, 1]) * rng.uniform(0.3, 1.2, size)
    r[850:870, 2] += 0.35  # a contact-level burst
    r[450:470] = np.nan  # the observer did not run
    r[360, 2] = 0.4  # one sample over the contact level only (std 0 there, no margin)
    r[[990, 993], 1] = 0.4  # two crossings 3 samples apart: together still short
    std = np.abs(0.02 * rng.standard_normal((N, n)))
    std[450:470] = np.nan
    std[[360, 990, 993]] = 0.0
    margin = np.where(np.arange(N)[:, None] % 200 < 20, 0.1, 0.0) * np.ones(n)
    th = Thresholds(
        contact=np.full(n, 0.2), collision=np.full(n, 0.6), margin=1.5, quantile=1.0,
        collision_factor=3.0, options=ObserverOptions(), samples=1, k_sigma=3.0,
        noise=np.full(n, 0.15), standstill=True,
    )  # fmt: skip
    restarts = [0, 610]
    c = 3.0 * np.nan_to_num(std) + 0.15 + margin
    k = 3.0 * (3.0 * np.nan_to_num(std) + 0.15) + margin
    gone: list = []
    want = _reference(t, r, c, k, merge, restarts, 0.01, gone)
    assert {d[4] for d in gone} == ({"isolated", "short"} if merge else {"isolated"})
    assert all(d[1] - d[0] < 0.01 and max(d[5]) > 1.0 for d in gone)
    levels = {e[4] for e in want}
    assert len(want) >= 5 and levels == ({"contact", "collision"} if merge else {"collision"})
    assert all(e[1] - e[0] >= 0.01 or e[4] == "collision" for e in want)
    raw = _reference(t, r, c, k, merge, restarts)
    assert any(e[1] - e[0] < 0.01 for e in raw)  # some dropped
    assert t[360] in {e[0] for e in _reference(t, r, c, k, 0.0, restarts)}  # a crossing
    burst = [e for e in want if e[0] <= t[420] <= e[1]]
    assert len(burst) == 1 and burst[0][0] >= t[400]
    if merge:
        assert t[400] - t[360] <= merge  # joined first, it began the event
        dipping = [e for e in want if e[0] <= t[860] <= e[1]]
        assert len(dipping) == 1 and dipping[0][4] == "contact"
        runs = [e for e in _reference(t, r, c, k, 0.0, restarts) if t[845] <= e[0] <= t[875]]
        assert len(runs) > 1 and all(e[1] - e[0] < 0.01 for e in runs)  # each one short
    whole = detect(
        t, r, th, std=std, standstill=margin, merge_s=merge, min_duration_s=0.01,
        restarts=restarts,
    )  # fmt: skip
    assert _as_tuples(whole) == want
    # the largest |r| over the threshold at its sample, what the console prints beside the
    # largest |r| (that one over the base threshold made 'max |r| > contact, 0 events')
    ratio = np.nanmax(np.abs(r) / c, axis=0)
    for block in range(1, N + 1):
        det = EventDetector(th, merge_s=merge, min_duration_s=0.01, restarts=restarts)
        got = []
        for a in range(0, N, block):
            k = slice(a, a + block)
            got += det.feed(t[k], r[k], std=std[k], standstill=margin[k])
        assert _as_tuples(got + det.finish()) == want, block
        np.testing.assert_allclose(det.largest_ratio, ratio, rtol=1e-12)
        _same_dropped(det.dropped, gone)
        assert det.dropped_count == len(gone)


def test_one_push_near_a_flickering_threshold_is_one_event_starting_at_its_first_crossing():
    """A 1 s step push of 1.2 N m on a joint at rest, through the observer's lag
    K_O / (s + K_O) (closed form), with a threshold that jumps between 0.8 and 1.4 N m as
    the standstill margin follows the velocity noise: raw (merge 0, no minimum) it is many
    events; by default one, from the first crossing, which is the raw first event's start
    (neither rule delays it) and the closed form's crossing of the threshold. One-sample noise
    crossings are dropped, a one-sample crossing of the collision level kept."""
    rng = np.random.default_rng(7)
    fs, K, A, t0 = 500.0, 50.0, 1.2, 2.0
    t = np.arange(0.0, 5.0, 1 / fs)
    r = np.zeros((t.size, 2))
    on = t >= t0
    r[on, 0] = A * -np.expm1(-K * (t[on] - t0)) * (t[on] < t0 + 1.0)
    off = t >= t0 + 1.0
    r[off, 0] = r[off, 0] + A * -np.expm1(-K * 1.0) * np.exp(-K * (t[off] - t0 - 1.0))
    r += 0.02 * rng.standard_normal(r.shape)
    r[[200, 1900], 1] = 0.9  # one-sample noise crossings of joint 2 (contact level)
    r[2300, 1] = 3.0  # one sample over its collision level
    held = np.repeat(rng.random(t.size // 10) < 0.5, 10)[: t.size]  # 20 ms segments
    margin = np.where(held, 0.6, 0.0)[:, None] * np.array([1.0, 0.0])
    th = Thresholds(
        contact=np.full(2, 0.8), collision=np.full(2, 2.0), margin=1.5, quantile=1.0,
        collision_factor=2.5, options=ObserverOptions(), samples=1, standstill=True,
    )  # fmt: skip
    margin = np.broadcast_to(margin, r.shape)
    raw = detect(t, r, th, standstill=margin, merge_s=0.0, min_duration_s=0.0)
    default = detect(t, r, th, standstill=margin)
    in_push = [e for e in default if t0 <= e.start <= t0 + 1.1]
    assert len([e for e in raw if t0 <= e.start <= t0 + 1.1]) > 3
    assert len(in_push) == 1 and in_push[0].start == min(e.start for e in raw if e.start >= t0)
    lag = A * -np.expm1(-K * np.clip(t - t0, 0.0, None))  # the closed form, noise-free
    crossing = t[np.argmax(lag > 0.8 + margin[:, 0])]  # of the threshold at each sample
    assert abs(in_push[0].start - crossing) < 3 / fs
    assert in_push[0].end > t0 + 0.9
    others = [(e.start, e.level) for e in default if e not in in_push]
    assert others == [(t[2300], "collision")]
    assert {t[200], t[1900]} <= {e.start for e in raw}


def test_a_lone_crossing_before_a_contact_does_not_start_its_event():
    """A 0.5 s step contact of 1.0 N m through the observer's lag K_O / (s + K_O) (closed
    form) with a one-sample noise crossing 0.13 s before it, as on the TALOS arm: by
    default the event starts at the closed form's crossing of the threshold (it started
    at the lone crossing, 130 ms early, joined to it within merge_s); in blocks of any
    size as in one. Two one-sample crossings 20 ms apart (closer than merge_s / 2) are
    not isolated: one contact-level event of 20 ms; a lone crossing far from anything is
    dropped."""
    rng = np.random.default_rng(2)
    fs, K, A, t0 = 500.0, 50.0, 1.0, 2.0
    t = np.arange(0.0, 4.0, 1 / fs)
    r = np.zeros((t.size, 1))
    on = (t >= t0) & (t < t0 + 0.5)
    r[on, 0] = A * -np.expm1(-K * (t[on] - t0))
    off = t >= t0 + 0.5
    r[off, 0] = A * -np.expm1(-K * 0.5) * np.exp(-K * (t[off] - t0 - 0.5))
    r += 0.01 * rng.standard_normal(r.shape)
    blip = int(round((t0 - 0.13) * fs))
    r[blip, 0] = 0.6
    pair = [int(round(3.0 * fs)), int(round(3.02 * fs))]
    r[pair, 0] = 0.6
    r[int(round(1.0 * fs)), 0] = 0.6  # alone
    th = Thresholds(
        contact=np.full(1, 0.5), collision=np.full(1, 5.0), margin=1.5, quantile=1.0,
        collision_factor=10.0, options=ObserverOptions(), samples=1, k_sigma=0.0,
        noise=np.zeros(1), standstill=False,
    )  # fmt: skip
    crossing = t[np.argmax(np.where(on, A * -np.expm1(-K * (t - t0)), 0.0) > 0.5)]
    got = detect(t, r, th)
    assert t[pair[1]] - t[blip] > 0.2 and t0 - t[blip] < 0.2  # the blip within merge_s
    starts = [e.start for e in got]
    assert len(got) == 2 and abs(starts[0] - crossing) < 3 / fs, starts
    assert starts[1] == t[pair[0]] and got[1].end == t[pair[1]]
    for block in (1, 7, 64, 65, 650):
        det = EventDetector(th)
        ev = [
            e for a in range(0, t.size, block) for e in det.feed(t[a : a + block], r[a : a + block])
        ]
        assert _as_tuples(ev + det.finish()) == _as_tuples(got)


@pytest.fixture(scope="module")
def contact_log(tmp_path_factory):
    """A Panda log with a contact from 1.0 to 1.4 s (tau_ext written beside it), its
    thresholds from a free log, and the same contact log with 50 ms of rows removed at
    2 s (a gap: two pieces)."""
    d = tmp_path_factory.mktemp("events")
    sim = ["simulate", "--robot", "panda", "--trajectory", "fourier", "-q", "--duration", "3"]
    assert main([*sim, "--seed", "2", "--out", str(d / "free.csv")]) == 0
    hit = ["--contact", "link6:0,0,-15:1,1.4", "--contact", "flange:0,0,0,0,0,2:2.3,2.6"]
    assert main([*sim, "--seed", "3", *hit, "--out", str(d / "hit.csv")]) == 0
    p = ["observe", "--params", "panda", "--no-figures"]
    assert main([*p, "--data", str(d / "free.csv"), "--calibrate", "--out", str(d / "cal")]) == 0
    lines = (d / "hit.csv").read_text().splitlines(keepends=True)
    head, rows = lines[:3], lines[3:]
    kept = [x for x in rows if not 2.0 <= float(x.split(",", 1)[0]) < 2.05]
    head[1] = f"# rows: {len(kept)}\n"
    (d / "gap.csv").write_text("".join(head + kept))
    return d


@pytest.mark.parametrize("name", ["hit.csv", "gap.csv"])
def test_observe_in_blocks_that_cut_the_events_equals_one_block(contact_log, monkeypatch, name):
    """Blocks of 97 samples (both contacts span several; the gap cuts the log in two)
    against one block of the whole log: the same events, the same residual table bytes;
    the contacts start within 15 ms of the true torques' first sample (K_O = 50/s); the
    summaries kept without the series (largest |r|, r - tau_ext) agree with those of the
    series."""
    from dynid.io.observer_files import ResidualTables
    from dynid.workflows.observe import ObserveOptions, observe_files

    d = contact_log
    opts = ObserveOptions(
        data=(d / name,), params="panda", thresholds=d / "cal" / "thresholds.json"
    )
    monkeypatch.setattr("dynid.workflows.observe_logs.OBSERVE_BLOCK", 1 << 20)
    whole_tables = ResidualTables(d / f"whole_{name}")
    whole = observe_files(opts, whole_tables).logs[0]
    monkeypatch.setattr("dynid.workflows.observe_logs.OBSERVE_BLOCK", 97)
    tables = ResidualTables(d / f"blocks_{name}")
    lean = observe_files(
        ObserveOptions(data=opts.data, params="panda", thresholds=opts.thresholds,
                       keep_series=False), tables,
    ).logs[0]  # fmt: skip
    assert lean.r is None and len(whole.restarts) == (2 if name == "gap.csv" else 1)
    assert _as_tuples(lean.events) == _as_tuples(whole.events)
    assert tables.written[0].read_bytes() == whole_tables.written[0].read_bytes()
    ext = whole.tau_ext
    assert ext is not None
    on = np.flatnonzero(np.any(ext != 0, axis=1))
    onsets = [whole.t[on[0]], whole.t[on[np.argmax(np.diff(on) > 1) + 1]]]
    assert len(whole.events) == 2
    for e, t0 in zip(whole.events, onsets, strict=True):
        assert t0 <= e.start <= t0 + 0.015  # the lag: 20 ms time constant
    np.testing.assert_allclose(lean.largest(), np.nanmax(np.abs(whole.series), axis=0))
    e = whole.series - ext
    ran = np.all(np.isfinite(e), axis=1)
    np.testing.assert_allclose(lean.truth_error(), np.sqrt(np.mean(e[ran] ** 2, axis=0)))


def test_observe_command_writes_the_table_a_block_at_a_time(contact_log, monkeypatch):
    """``dynid observe --thresholds --no-figures`` in blocks of 97 samples: residuals.csv
    holds the residual of the observer run over the whole log at once (rows, header,
    values to the last digit)."""
    d = contact_log
    monkeypatch.setattr("dynid.workflows.observe_logs.OBSERVE_BLOCK", 97)
    p = ["observe", "--params", "panda", "--no-figures"]
    th = ["--thresholds", str(d / "cal" / "thresholds.json")]
    assert main([*p, *th, "--data", str(d / "hit.csv"), "--out", str(d / "cmd")]) == 0
    lines = (d / "cmd" / "residuals.csv").read_text().splitlines()
    assert lines[1] == "# rows: 3001" and lines[2] == "t,r1,r2,r3,r4,r5,r6,r7"
    table = np.loadtxt(d / "cmd" / "residuals.csv", delimiter=",", comments="#", skiprows=3)
    from dynid.io.torque_log import load_torque_log
    from dynid.observer import observe
    from dynid.workflows.observe import load_observer_model

    log = load_torque_log(d / "hit.csv")
    model, _ = load_observer_model(None, "panda")
    r = observe(model, log.t, log.q, log.dq, log.tau, ObserverOptions()).r  # the whole log
    np.testing.assert_array_equal(table[:, 0], log.t)
    np.testing.assert_array_equal(table[:, 1:], r)


def test_a_detection_figure_keeps_every_kth_sample_of_the_series(contact_log, monkeypatch):
    """figure_points 50 over blocks of 97 samples: the figure's series are every
    ceil(N / 50)-th sample of the whole series, with the thresholds at those samples;
    the command draws residuals.png from them."""
    from dynid.observer.detection import threshold_series
    from dynid.workflows.observe import ObserveOptions, observe_files

    d = contact_log
    monkeypatch.setattr("dynid.workflows.observe_logs.OBSERVE_BLOCK", 97)
    opts = ObserveOptions(
        data=(d / "gap.csv",), params="panda", thresholds=d / "cal" / "thresholds.json",
        figure_points=50,
    )  # fmt: skip
    result = observe_files(opts)
    x = result.logs[0]
    f = x.figure
    assert f is not None and x.tau_ext is not None
    step = int(np.ceil(x.t.shape[0] / 50))
    assert f.step == step and f.t.shape[0] <= 50
    c, k = threshold_series(result.thresholds, x.t.shape[0], x.std, x.standstill)
    for got, whole in ((f.t, x.t), (f.r, x.r), (f.contact, c), (f.collision, k)):
        np.testing.assert_array_equal(got, whole[::step])
    np.testing.assert_array_equal(f.tau_ext, x.tau_ext[::step])
    p = ["observe", "--params", "panda", "--thresholds", str(d / "cal" / "thresholds.json")]
    assert main([*p, "--data", str(d / "hit.csv"), "--out", str(d / "fig")]) == 0
    assert (d / "fig" / "residuals.png").stat().st_size > 0


def test_without_merging_a_run_over_the_threshold_is_one_event():
    """``merge_s = 0``: a push of 50 samples over the threshold is one event (it was 50,
    one per sample), in any blocks; two runs one sample apart are two."""
    N, n = 200, 2
    t = np.arange(N) * 1e-3
    r = np.zeros((N, n))
    r[50:100, 0] = 1.0
    r[101:110, 0] = 1.0
    th = Thresholds(
        contact=np.full(n, 0.5), collision=np.full(n, 5.0), margin=1.0, quantile=1.0,
        collision_factor=10.0, options=ObserverOptions(), samples=1, k_sigma=0.0,
        noise=np.zeros(n), standstill=False,
    )  # fmt: skip
    whole = detect(t, r, th, merge_s=0.0, min_duration_s=0.0)
    assert [(e.start, e.end) for e in whole] == [(t[50], t[99]), (t[101], t[109])]
    det = EventDetector(th, merge_s=0.0, min_duration_s=0.0)
    got = [e for a in range(0, N, 7) for e in det.feed(t[a : a + 7], r[a : a + 7])]
    assert _as_tuples(got + det.finish()) == _as_tuples(whole)


def _impact_log(t0, fs=100.0, seconds=2.0, at=1.0, samples=2, rng=None):
    """A 100 Hz log stamped from ``t0`` (``t0 + k / fs``, as a logger writes them) whose
    residual is noise under 0.5 N m but for a contact of ``samples`` samples at 1.2 N m
    from ``at`` s after its start: (t, r, first and last sample of the contact)."""
    rng = rng or np.random.default_rng(5)
    k = np.arange(int(seconds * fs))
    t = t0 + k / fs
    r = 0.1 * rng.standard_normal((k.size, 1))
    a = int(round(at * fs))
    r[a : a + samples, 0] = 1.2
    return t, r, a, a + samples - 1


def _one_joint(contact=0.5, collision=5.0):
    return Thresholds(
        contact=np.full(1, contact), collision=np.full(1, collision), margin=1.5,
        quantile=1.0, collision_factor=10.0, options=ObserverOptions(), samples=1,
    )  # fmt: skip


def test_a_short_contact_is_kept_or_dropped_whatever_the_clock_it_is_stamped_on():
    """A 2-sample contact at 100 Hz spans one period, 10 ms, the --min-duration: it is a
    contact at every clock offset, although the stamps' difference falls on either side
    of 0.01 s by their rounding (at 48.03 s it was 0.00999999999999801 s and the contact
    was dropped; 0.02 s later it was kept). A 1-sample crossing is dropped at every
    offset, and a 3-sample one kept; two one-sample crossings exactly merge_s / 2 apart
    are not isolated at any offset. Fed a sample at a time as in one block."""
    offsets = [0.0, 0.02, 47.03 - 1.0, 48.03 - 1.0, 1234.567, 1.7e9 + 0.13]
    signs = set()
    for t0 in offsets:
        for samples, kept in ((1, False), (2, True), (3, True)):
            t, r, a, b = _impact_log(t0, samples=samples)
            if samples == 2:
                signs.add(np.sign(round((t[b] - t[a] - 0.01) / 1e-18)))
            for got in (detect(t, r, _one_joint()), _fed_one_at_a_time(t, r, _one_joint())):
                assert [(e.start, e.end) for e in got] == ([(t[a], t[b])] if kept else []), (
                    t0,
                    samples,
                )
        t, r, a, _ = _impact_log(t0, samples=1)
        c = a + 10  # 0.1 s later: merge_s / 2 of 0.2 s
        r[c, 0] = 1.2
        got = detect(t, r, _one_joint(), merge_s=0.2)
        assert [(e.start, e.end) for e in got] == [(t[a], t[c])], t0
    assert signs >= {-1.0, 1.0}  # the stamps' rounding went both ways


def _fed_one_at_a_time(t, r, th):
    det = EventDetector(th)
    return [e for k in range(t.size) for e in det.feed(t[k : k + 1], r[k : k + 1])] + det.finish()
