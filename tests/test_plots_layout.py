"""The figures' layout and saving draw less and change no pixel: dynid's tight layout gives
matplotlib's own ``Figure.tight_layout`` subplot parameters with each panel measured once,
and ``save_figure`` draws a tight-laid-out figure once into the PNG ``savefig`` writes,
each axis computing its ticks once per measure or draw.

Reference: matplotlib's ``Figure.tight_layout`` and ``Figure.savefig`` on the same figure.
"""

from __future__ import annotations

import io

import numpy as np
import pytest

pytest.importorskip("matplotlib")


def _panels(rng: np.random.Generator):
    """A 2 x 2 figure of random lines with titles, labels, a suptitle and a figure legend."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 4))
    axes = fig.subplots(2, 2, sharex=True)
    for k, ax in enumerate(axes.ravel()):
        ax.plot(np.arange(50), rng.normal(scale=10.0**k, size=50), label="line")
        ax.set_title(f"panel {k} with a longer title")
        ax.set_ylabel(f"torque {k}\n[N m]")
    fig.suptitle("a figure")
    fig.legend(*axes[0, 0].get_legend_handles_labels(), loc="upper center")
    return fig


def _params(fig) -> tuple[float, ...]:
    p = fig.subplotpars
    return (p.left, p.bottom, p.right, p.top, p.wspace, p.hspace)


@pytest.mark.parametrize("rect", [None, (0.0, 0.05, 1.0, 0.9)])
def test_tight_layout_equals_matplotlibs_with_each_panel_measured_once(rect, monkeypatch):
    """The subplot parameters equal matplotlib's tight_layout's to the bit, with and
    without a rect (which made matplotlib measure every panel twice); each panel's tight
    box is computed once, and the panels keep the class's measuring method afterwards."""
    from matplotlib.axes import Axes

    from dynid.plots.layout import tight_layout

    theirs = _panels(np.random.default_rng(4))
    theirs.tight_layout(rect=rect)
    ours = _panels(np.random.default_rng(4))
    measure = Axes.get_tightbbox
    calls: list[int] = []

    def counted(ax, *args, **kwargs):
        calls.append(ours.axes.index(ax))
        return measure(ax, *args, **kwargs)

    monkeypatch.setattr(Axes, "get_tightbbox", counted)
    tight_layout(ours, rect=rect)
    assert _params(ours) == _params(theirs)
    assert sorted(calls) == list(range(len(ours.axes)))  # each panel once
    assert all("get_tightbbox" not in vars(ax) for ax in ours.axes)


def test_save_figure_draws_a_tight_laid_out_figure_once_into_the_same_png(tmp_path):
    """A figure laid out by tight_layout is drawn once by save_figure (savefig drew it
    twice: once without output for the placeholder layout engine left behind) and its PNG
    has the pixels of matplotlib's own savefig; a constrained layout is kept."""
    from matplotlib.figure import Figure
    from PIL import Image

    from dynid.plots.save import save_figure

    draws: list[object] = []

    def made() -> Figure:
        fig = _panels(np.random.default_rng(5))
        fig.tight_layout()
        fig.canvas.mpl_connect("draw_event", draws.append)
        return fig

    path = save_figure(made, tmp_path / "a.png", dpi=80)
    assert len(draws) == 1
    reference = io.BytesIO()
    made().savefig(reference, format="png", dpi=80)
    ours = np.asarray(Image.open(path))
    assert np.array_equal(ours, np.asarray(Image.open(reference)))

    constrained = Figure(figsize=(4, 3), layout="constrained")
    constrained.subplots(2, 1)
    engine = constrained.get_layout_engine()
    save_figure(lambda: constrained, tmp_path / "c.png")
    assert constrained.get_layout_engine() is engine


@pytest.mark.parametrize("aligned", [False, True])
def test_ticks_are_computed_once_per_draw_with_the_same_pixels(aligned, monkeypatch):
    """Within ticks_once, each axis computes its ticks once per measure or draw (matplotlib
    computes them again to place the axis label): at most half as often, and the PNG has
    the pixels of matplotlib's own draw, labels aligned across panels too (the boxes of
    the other panels' axes), and the axes keep the class's methods afterwards."""
    from matplotlib.axis import Axis
    from PIL import Image

    from dynid.plots.layout import ticks_once

    def drawn(fig, count: bool) -> np.ndarray:
        if aligned:
            fig.align_ylabels()
        update = Axis._update_ticks
        calls: list[Axis] = []

        def counted(axis):
            calls.append(axis)
            return update(axis)

        png = io.BytesIO()
        with monkeypatch.context() as m:
            m.setattr(Axis, "_update_ticks", counted)
            if count:
                with ticks_once(fig):
                    fig.savefig(png, format="png", dpi=60)
            else:
                fig.savefig(png, format="png", dpi=60)
        counts.append(len(calls))
        return np.asarray(Image.open(png))

    counts: list[int] = []
    ours = _panels(np.random.default_rng(6))
    assert np.array_equal(drawn(ours, True), drawn(_panels(np.random.default_rng(6)), False))
    assert 2 * counts[0] <= counts[1]  # matplotlib 3.11: 14 against 42 here
    names = ("_update_ticks", "_get_ticklabel_bboxes", "get_tightbbox", "draw")
    assert all(n not in vars(a) for ax in ours.axes for a in (ax.xaxis, ax.yaxis) for n in names)
