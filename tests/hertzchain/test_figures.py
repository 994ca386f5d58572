"""The reproduce figures read as a referee would: no overlapping text, legends off the data,
Fig. 5 zoomed on its wave, Fig. 8 with shared colour bars that show the reflected waves, the
validity map's sonic vacuum in a column of its own.

Geometry is checked on the rendered figure (Agg renderer, display coordinates): two text
artists overlap when their window extents intersect by more than :data:`SLACK` pixels in
both directions.  Synthetic data (Figs. 5, 8 and the validity map) are numbers for drawing,
not physics; Figs. 3 and 4 are the real ``--quick`` runs (a few seconds each).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgb

from hertzchain.reproduce import fig5, fig8, fig34, validity
from hertzchain.reproduce.common import Context, ContinuumProfile
from hertzchain.sweep_plot import validity_figure

SLACK = 1.0
"""Pixels two text boxes may share (anti-aliasing) before they count as overlapping."""


# -- geometry on the rendered figure ---------------------------------------------------------
def _render(fig):
    FigureCanvasAgg(fig)
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def _all_axes(fig) -> list:
    out, todo = [], list(fig.axes)
    while todo:
        ax = todo.pop()
        out.append(ax)
        todo += list(ax.child_axes)
    return out


def _legends(fig) -> list:
    return [lg for lg in [ax.get_legend() for ax in _all_axes(fig)] + list(fig.legends) if lg]


def _texts(fig) -> list:
    """Every visible, non-empty text artist of the figure (titles, labels, tick labels,
    annotations, legend entries and titles, colour-bar labels, figure texts)."""
    out = [fig._suptitle] if fig._suptitle is not None else []
    out += list(fig.texts)
    for ax in _all_axes(fig):
        out += [ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label]
        out += list(ax.texts)
        for axis in (ax.xaxis, ax.yaxis):  # the tick labels drawn: ticks inside the view
            lo, hi = sorted(axis.get_view_interval())
            tol = 1e-9 * (hi - lo)
            out += [lab for tick in axis.get_major_ticks() if lo - tol <= tick.get_loc() <= hi + tol
                    for lab in (tick.label1, tick.label2)]
    for lg in _legends(fig):
        out += list(lg.get_texts()) + [lg.get_title()]
    out = list({id(t): t for t in out if t is not None}.values())  # (suptitle in fig.texts)
    return [t for t in out if t.get_visible() and t.get_text().strip()]


def _overlap(a, b) -> bool:
    return (min(a.x1, b.x1) - max(a.x0, b.x0) > SLACK
            and min(a.y1, b.y1) - max(a.y0, b.y0) > SLACK)


def overlapping_texts(fig) -> list[tuple[str, str]]:
    """Pairs of text artists whose rendered boxes overlap."""
    r = _render(fig)
    boxes = [(t.get_text(), t.get_window_extent(r)) for t in _texts(fig)]
    return [(ta, tb) for i, (ta, a) in enumerate(boxes) for tb, b in boxes[i + 1:]
            if _overlap(a, b)]


def texts_over_data(fig) -> list[str]:
    """Texts inside an axes (annotations, ``ax.text``) with a data vertex of its lines
    under them."""
    r = _render(fig)
    out = []
    for ax in _all_axes(fig):
        pts = [ln.get_transform().transform(np.column_stack([ln.get_xdata(), ln.get_ydata()]))
               for ln in ax.lines if ln.get_visible() and len(ln.get_xdata())]
        pts = np.concatenate(pts) if pts else np.empty((0, 2))
        for t in ax.texts:
            if not t.get_visible() or not t.get_text().strip():
                continue
            bb = t.get_window_extent(r)
            inside = ((pts[:, 0] > bb.x0) & (pts[:, 0] < bb.x1) & (pts[:, 1] > bb.y0)
                      & (pts[:, 1] < bb.y1))
            if inside.any():
                out.append(t.get_text())
    return out


def legends_over_data(fig) -> list[str]:
    """Legends with a data vertex of a line (any axes) under them; figure legends must also
    stay off every axes."""
    r = _render(fig)
    out = []
    for lg in _legends(fig):
        bb = lg.get_window_extent(r)
        for ax in _all_axes(fig):
            if lg in fig.legends and _overlap(bb, ax.get_window_extent(r)) \
                    and ax.get_visible() and ax.axison:
                out.append(f"figure legend over axes {ax.get_title()!r}")
            for ln in ax.lines:
                xy = np.column_stack([ln.get_xdata(), ln.get_ydata()]).astype(float)
                if not ln.get_visible() or not xy.size:
                    continue
                d = ln.get_transform().transform(xy)
                if ((d[:, 0] > bb.x0) & (d[:, 0] < bb.x1) & (d[:, 1] > bb.y0)
                        & (d[:, 1] < bb.y1)).any():
                    out.append(f"legend over {ln.get_label()!r} in {ax.get_title()!r}")
    return out


# -- Figs. 3 and 4: the real --quick runs -----------------------------------------------------
@pytest.fixture(scope="module")
def fig34_cases(tmp_path_factory):
    ctx = Context(tmp_path_factory.mktemp("fig34"), progress=False)
    return {item: fig34.run(ctx, item) for item in ("fig3", "fig4")}


@pytest.mark.parametrize("item", ["fig3", "fig4"])
def test_fig34_text_and_legends_clear(fig34_cases, item):
    fig = fig34.figure(fig34_cases[item])
    assert overlapping_texts(fig) == []
    assert texts_over_data(fig) == []
    assert legends_over_data(fig) == []
    # the gap openings are vertical lines named in the legend, not text over panels c, d
    c, d = fig.axes[2], fig.axes[3]
    assert len(c.texts) == len(d.texts) == 0
    names = [t.get_text() for lg in fig.legends for t in lg.get_texts()]
    assert any("opens (1st)" in n for n in names) and any("opens (2nd)" in n for n in names)


# -- Fig. 5: zoomed on the wave ----------------------------------------------------------------
def _sech2(x):
    return 1.0 / np.cosh(np.clip(x, -300.0, 300.0)) ** 2


def _fig5_case(case: str = "a", continuum: bool = True) -> fig5.CaseResult:
    """A 2,000-grain snapshot: sech² transmitted pulse (FWHM 7 grains) at grain index 1,900
    with an oscillatory tail, a reflected pulse at 800, interface 1,400|1,401."""
    n, interface, peak, half = 2000, 1400, 1900, 4.0
    i = np.arange(n, dtype=float)
    v = 0.08 * _sech2((i - peak) / half)
    tail = (i > interface) & (i < peak - 10)
    v[tail] += 0.004 * np.sin(0.5 * i[tail]) * np.exp((i[tail] - peak) / 200)
    v -= 0.02 * _sech2((i - 800) / 8.0)
    cont = None
    if continuum:
        vc = 0.08 * _sech2((i - peak - 1) / half)
        cont = ContinuumProfile("continuum (Eq. 4, 3 nodes/grain)", vc)
    numbers = {"incident_peak_v": 0.08, "transmitted": "squeeze", "reflected": "compressive"}
    return fig5.CaseResult(case, 5.0, 1.0, v, 0.01, interface, numbers, None, cont)


def test_fig5_zoom_window_is_a_few_widths_around_the_wave():
    res = _fig5_case()
    lo, hi, peak, w = fig5.zoom_window(res)
    # sech²((i-p)/4) ≥ 1/2 for |i-p| ≤ 4 arccosh(√2) = 3.53: 7 grains
    assert (peak, w) == (1900, 7)
    assert lo == peak - round(fig5.BEHIND * w) and hi >= peak + round(fig5.AHEAD * w)
    assert hi - lo <= (fig5.BEHIND + fig5.AHEAD) * w + 3


def test_fig5_panel_brackets_the_wave_and_shows_both_models():
    res = _fig5_case()
    fig, axes = fig5.new_figure()
    ax = axes[0, 0]
    fig5.plot_case(ax, res)
    lo, hi = ax.get_xlim()
    _, _, peak, w = fig5.zoom_window(res)
    k = fig5.BEHIND + fig5.AHEAD + 1
    assert lo < peak + 1 < hi and hi - lo <= k * w          # paper's grain = index + 1
    # no data of the main axes outside the window (the y range is the wave's)
    for ln in ax.lines:
        x = np.asarray(ln.get_xdata(), float)
        if x.size > 2:
            assert x.min() >= lo - 1 and x.max() <= hi + 1, ln.get_label()
    disc = next(ln for ln in ax.lines if ln.get_label() == "discrete")
    cont = next(ln for ln in ax.lines if ln.get_label().startswith("continuum ("))
    assert to_rgb(disc.get_color()) != to_rgb(cont.get_color())
    assert cont.get_linestyle() == "--" and cont.get_linewidth() < disc.get_linewidth()
    # the whole chain in the overview inset, the reflected wave included
    (ins,) = ax.child_axes
    assert ins.get_xlim()[1] >= res.v.size and ins.lines[0].get_ydata().min() < -0.019


def test_fig5_figure_text_and_legend_clear():
    fig = fig5.figure([_fig5_case(c, continuum=c in "ad") for c in "abcd"])
    assert overlapping_texts(fig) == []
    assert texts_over_data(fig) == []
    assert legends_over_data(fig) == []
    assert len(fig.legends) == 1 and all(ax.get_legend() is None for ax in fig.axes)


# -- Fig. 8: shared colour bars, the reflected waves visible ---------------------------------------
def _fig8_data() -> dict:
    """Four points; a transmitted wave of e/e0 up to 1.5 and a reflected one of 0.1 (kinetic)
    and -0.05 (potential) on the left; background 0."""
    t = np.linspace(0.0, 1.5e-3, 120)
    g = np.arange(fig8.GRAINS_SHOWN)
    out = {}
    for p in "MNPQ":
        front = 100 + 200 * t[:, None] / 0.75e-3
        refl = 200 - 150 * np.clip(t[:, None] - 0.75e-3, 0, None) / 0.75e-3
        wave = np.exp(-((g[None, :] - front) / 4.0) ** 2)
        back = np.exp(-((g[None, :] - refl) / 4.0) ** 2) * (t[:, None] > 0.75e-3)
        k = (1.5 * wave + 0.1 * back).astype(np.float32)
        pot = (1.2 * wave - 0.05 * back).astype(np.float32)
        out[p] = {"t": t, "k": k, "p": pot, "t_": k + pot, "interface": 200,
                  "limits": {"k": (0.0, 1.5), "p": (-0.05, 1.2), "t": (-0.0, 2.7)}}
    return out


def test_fig8_one_colour_bar_per_column():
    data = _fig8_data()
    fig = fig8.figure(data)
    panels = [ax for ax in fig.axes if ax.images]
    assert len(panels) == 12
    assert len(fig.axes) - len(panels) <= 3                    # colour bars: one per column
    # the panels of a column share one norm (one colour bar is true for all of them)
    for j in range(3):
        norms = {id(ax.images[0].norm) for ax in panels[j::3]}
        assert len(norms) == 1
    assert overlapping_texts(fig) == []


def test_fig8_colour_scale_shows_the_reflected_wave():
    data = _fig8_data()
    panels = [ax for ax in fig8.figure(data).axes if ax.images]
    for col, kind, value in ((0, "k", 0.1), (1, "p", -0.05)):
        image = panels[col].images[0]                      # row M, the column's scale
        norm, cmap = image.norm, image.get_cmap()
        assert norm.vmax == fig8.color_norm(data, kind).vmax
        background = np.array(cmap(norm(0.0))[:3])
        wave = np.array(cmap(norm(value))[:3])
        # a linear scale over [0, 1.5] would put 0.1 at 7 % of the colour range: near the
        # background; the symmetric-log one at ≥ 40 % of its half
        assert np.abs(wave - background).max() > 0.3, kind
    # white is zero in the signed columns (symmetric limits)
    norm = fig8.color_norm(data, "p")
    assert norm(0.0) == pytest.approx(0.5) and norm.vmin == -norm.vmax


# -- the validity map --------------------------------------------------------------------------
def _quick_table():
    """The --quick map's shape: one interface, strain/δ0 = 0.01, 0.09 and the sonic vacuum."""
    rows = [{"alpha_rho": 2.0, "alpha_kn": 0.5, "exponent": 1.5, "damping": 0.0,
             "incident_strain_over_delta0": amp, "continuum_error": err,
             "theory_error": 2 * err, "continuum_applies": True, "theory_applies": True,
             "continuum_model": m, "theory_model": tm, "continuum_note": "",
             "theory_note": "", "continuum_stopped_by": "t_end"}
            for amp, err, m, tm in ((0.01, 2e-5, "eq4", "lattice acoustics"),
                                    (0.09, 4e-4, "eq4", "lattice acoustics"),
                                    (math.inf, 0.035, "eq7", "quasi-particle"))]
    t = validity._Table({k: np.array([r[k] for r in rows]) for k in rows[0]})
    t.attrs = {"name": "model validity (--quick)", "n_ok": 3, "n_failed": 0}
    return t


def test_validity_sonic_vacuum_in_its_own_column():
    fig = validity_figure(_quick_table())
    panels = [ax for ax in fig.axes if ax.axison]
    assert len(panels) == 2
    for ax in panels:
        labels = [t.get_text() for t in ax.get_xticklabels()]
        ticks = list(ax.get_xticks())
        # no log axis on which the sonic vacuum would need a number: log10 positions on a
        # linear axis, the sonic vacuum a named tick past the finite decades
        assert ax.get_xscale() == "linear"
        assert labels[-1] == "sonic\nvacuum"
        assert ticks[-1] - ticks[-2] >= 1.5
        # the coarse map is not stretched over empty decades: 1e-2 and 1e-1 only
        assert ticks[:-1] == [-2.0, -1.0]
        # the sonic vacuum's marker sits on its tick
        xs = [x for ln in ax.lines if ln.get_marker() == "o" for x in ln.get_xdata()]
        assert any(abs(x - ticks[-1]) < 0.2 for x in xs)
        # no numbers printed over the markers: the texts in the panel are the model names
        assert {t.get_text() for t in ax.texts} <= {"Eq. 4", "Eq. 7", "lattice acoustics",
                                                    "quasi-particle"}
    # the sonic vacuum's model named over its own column
    cont = panels[0]
    names = {t.get_text(): t.get_position()[0] for t in cont.texts}
    assert names["Eq. 7"] > cont.get_xticks()[-2] + 0.5 and names["Eq. 4"] < -0.5
    assert overlapping_texts(fig) == []


def test_validity_switch_to_the_quasi_continuum_is_drawn_at_its_threshold():
    """Rows at strain/δ0 = 1 (Eq. 7), 9 and 100 (qc): the continuum panel's only line between
    the rows is the Eq. 7 → qc switch at log10(AUTO_QC_MIN_STRAIN) (a point on the threshold
    is right of it), not a second one halfway between rows 1 and 9."""
    from hertzchain.scenario import AUTO_QC_MIN_STRAIN

    rows = [{"alpha_rho": 2.0, "alpha_kn": 0.5, "exponent": 1.5, "damping": 0.0,
             "incident_strain_over_delta0": amp, "continuum_error": 0.01,
             "theory_error": 0.02, "continuum_applies": True, "theory_applies": True,
             "continuum_model": m, "theory_model": "quasi-particle", "continuum_note": "",
             "theory_note": "", "continuum_stopped_by": "t_end"}
            for amp, m in ((1.0, "eq7"), (9.0, "qc"), (100.0, "qc"))]
    t = validity._Table({k: np.array([r[k] for r in rows]) for k in rows[0]})
    t.attrs = {"name": "model validity", "n_ok": 3, "n_failed": 0}
    fig = validity_figure(t)
    cont = [ax for ax in fig.axes if ax.axison][0]
    dashed = [ln.get_xdata()[0] for ln in cont.lines if ln.get_linestyle() == "--"]
    between = [x for x in dashed if 0.0 < x < math.log10(100.0)]  # rows 1 and 100
    assert between == [pytest.approx(math.log10(AUTO_QC_MIN_STRAIN))]
