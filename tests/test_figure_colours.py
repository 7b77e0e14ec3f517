"""The figures of a report draw each quantity in one colour (dynid.plots.style.COLOURS)
and keep their legends off the data."""

from __future__ import annotations

import numpy as np
from matplotlib.colors import to_rgba

from dynid.friction.validation import Validation
from dynid.identification.log import TorqueLog
from dynid.identification.metrics import torque_errors


def _validation(rng: np.random.Generator, N: int = 400, n: int = 3) -> Validation:
    """Measured torques, a rigid-body prediction and a friction term (random signals)."""
    t = 0.01 * np.arange(N)
    q, dq, ddq = (rng.normal(size=(N, n)) for _ in range(3))
    tau = rng.normal(size=(N, n))
    model, friction = tau + rng.normal(0, 0.3, (N, n)), rng.normal(0, 0.2, (N, n))
    log = TorqueLog(t, q, dq, tau, ddq)
    return Validation(
        log, model, friction, torque_errors(tau, model), torque_errors(tau, model + friction), None
    )


def test_without_and_with_friction_keep_their_colours_from_traces_to_rms_bars():
    """The model without friction and the model with it are drawn in the same colours in
    the torque traces, the error panels and the RMS bars of one report (the bars drew
    "without friction" blue beside traces where blue was "with friction")."""
    from dynid.plots.style import COLOURS
    from dynid.plots.torques import plot_torque_validation, plot_validation_rms

    v = _validation(np.random.default_rng(1))
    traces = plot_torque_validation(v)
    lines = {ln.get_label(): to_rgba(ln.get_color()) for ln in traces.axes[0].lines}
    bars = plot_validation_rms(v)
    patches = {
        c.get_label(): to_rgba(c.patches[0].get_facecolor()) for c in bars.axes[0].containers
    }
    no, yes = to_rgba(COLOURS["no_friction"]), to_rgba(COLOURS["model"])
    assert lines["model, no friction"] == patches["without friction"] == no
    assert lines["model + friction"] == patches["with friction"] == yes
    errors = [to_rgba(ln.get_color()) for ln in traces.axes[1].lines[:2]]
    assert errors == [no, yes]  # the error panels: the same two colours


def _overlaps(fig, legend) -> list[int]:
    """Indices of the axes of ``fig`` whose drawing area ``legend`` overlaps [pixels]."""
    fig.canvas.draw()
    box = legend.get_window_extent()
    return [k for k, ax in enumerate(fig.axes) if ax.get_window_extent().overlaps(box)]


def test_torque_and_observer_legends_cover_no_data():
    """The legends of the torque traces and of the observer's residuals stand outside
    every axes (they sat in the first panels, over the error traces and the thresholds)."""
    from dynid.plots.observer import plot_residuals
    from dynid.plots.torques import plot_torque_validation

    rng = np.random.default_rng(2)
    fig = plot_torque_validation(_validation(rng))
    t = np.linspace(0.0, 4.0, 400)
    r = rng.normal(size=(400, 2))
    obs = plot_residuals(t, r, np.full_like(r, 2.0), np.full_like(r, 4.0), events=())
    for f in (fig, obs):
        assert all(ax.get_legend() is None for ax in f.axes)
        (legend,) = f.legends
        assert _overlaps(f, legend) == []


def test_residual_histograms_show_the_distribution_not_the_few_reversal_samples():
    """Residuals of 0.05 N m noise with a few samples of 2.5 N m (a velocity reversal the
    model rounds): the axis spans the noise's distribution (within 0.45 N m either side),
    not the outliers' (it stretched to -1..2.5 N m, the noise in one bin), and the title
    counts the samples left beyond it."""
    from dynid.friction.heldout_torques import HeldOutTorques
    from dynid.plots.identification import plot_residual_histograms

    rng = np.random.default_rng(3)
    v = _validation(rng, N=4000, n=2)
    tau = np.array(v.log.tau)
    hat = tau - rng.normal(0.0, 0.05, tau.shape)
    hat[[10, 700, 2100], 0] = tau[[10, 700, 2100], 0] - 2.5
    v = Validation(v.log, hat, np.zeros_like(hat), torque_errors(tau, hat), None, None)
    h = HeldOutTorques(v, np.full(2, 0.05), "block 5", ("a", "b"))
    fig = plot_residual_histograms(h)
    lo, hi = fig.axes[0].get_xlim()
    assert -0.45 < lo < -0.2 and 0.2 < hi < 0.45
    assert "3 sample(s) beyond the axis" in fig.axes[0].get_title()
    assert "beyond" not in fig.axes[1].get_title()


def test_rms_bars_of_very_different_sizes_are_drawn_on_a_log_scale():
    """Errors without friction of 7 N m beside 0.05 N m with it: the axis is logarithmic
    (on a linear one the bars with friction could not be seen) and long joint names are
    slanted; bars of like sizes keep a linear axis."""
    from dynid.plots.torques import plot_rms_comparison

    names = [f"shoulder_pan_joint_{j}" for j in range(6)]
    fig = plot_rms_comparison(
        {"without friction": np.full(6, 7.0), "with friction": np.full(6, 0.05)}, joint_names=names
    )
    ax = fig.axes[0]
    assert ax.get_yscale() == "log"
    assert all(abs(t.get_rotation()) > 0 for t in ax.get_xticklabels())
    like = plot_rms_comparison({"a": np.full(3, 1.0), "b": np.full(3, 2.0)})
    assert like.axes[0].get_yscale() == "linear"
