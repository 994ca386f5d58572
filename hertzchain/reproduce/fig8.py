r"""Fig. 8: space–time maps of the kinetic, potential and total energy per grain, M N P Q.

Paper Section 4, Fig. 8: δ0^L/d = 1e-3, interface between grains 200 and 201; rows
a–d are the points M, N, P, Q, columns 1–3 the kinetic, potential and total energy per
grain (potential: half of each adjacent contact's energy minus its static energy,
docs/physics.md §6) divided by "the single grain kinetic energy, potential energy, and total
energy at the peak of the ISW" (:func:`discrete.diagnostics.normalise_to_incident_peak`,
the maxima over the left section before the wave reaches the interface).  The runs are
those of :mod:`.table2`: :func:`.table2.maps_from_grid` reduces each run's full energy grids
once (the normalisation, the extremes and the colour limits in float64 from every row
and grain; the maps themselves, for drawing only, to at most :data:`.table2.MAP_ROWS` rows
of the first :data:`.table2.GRAINS_SHOWN` grains), and :mod:`.table2` keeps that in its per-point
file.
"""

from __future__ import annotations

import numpy as np

from ..plotting import plot_spacetime
from .common import Context, new_figure, save_figure
from .table2 import (
    GRAINS_SHOWN,
    POINTS,
    in_run_order,
    run_point,
)

__all__ = ["QUICK", "FULL", "GRAINS_SHOWN", "LINTHRESH", "run", "color_norm", "plot_map",
           "figure", "figures", "report", "to_json"]

QUICK: dict = {}
FULL: dict = {}
KINDS = (("k", "kinetic", r"$e_k/e_{k0}$"), ("p", "potential", r"$e_p/e_{p0}$"),
         ("t", "total", r"$e_t/e_{t0}$"))


def run(ctx: Context, points=POINTS) -> dict:
    """Normalised energy maps of the points (from the Table 2 runs)."""
    out = {}
    for p in in_run_order(points):  # (the largest run first: the peak memory)
        ctx.log(f"fig8: point {p}")
        r = run_point(ctx, p)
        out[p] = dict(r.maps) | {"gamma": (r.alpha_rho, r.alpha_kn)}
    return {p: out[p] for p in points}


def _limits(data: dict, kind: str) -> tuple[float, float]:
    lo = min(d["limits"][kind][0] for d in data.values())
    hi = max(d["limits"][kind][1] for d in data.values())
    return min(lo, 0.0), hi


LINTHRESH = 3e-3
"""Linear range ±e/e0 of the colour scale (:func:`color_norm`): logarithmic beyond it, so
that the reflected waves (largest e/e0 ~0.1–0.3 for M, N, down to ~4e-3 for Q) show next
to transmitted waves of e/e0 ≈ 1, while the transmitted waves' brightness still differs
(e_k/e_k0 ≈ 2 for P, 0.6 for Q)."""
SIGNED_CMAP = "RdBu_r"
"""Colour map of every column: white at e = 0, red for positive energy, blue for negative
(potential energy below its static value: an expansive wave); the kinetic column uses its
upper (red) half."""


def color_norm(data: dict, kind: str):
    """The colour scale of one column (``kind``: ``"k"``, ``"p"``, ``"t"``), shared by the points.

    A symmetric-log scale (:class:`matplotlib.colors.SymLogNorm`, linear within
    ±:data:`LINTHRESH`) between the column's colour limits (:data:`.table2.PERCENTILES` over the
    points): from 0 to the largest value for the kinetic energy (never negative), and
    symmetric about 0 (± the largest magnitude) for the potential and total energies, so
    that white is e = 0 in every panel.
    """
    from matplotlib.colors import SymLogNorm

    lo, hi = _limits(data, kind)
    if kind == "k":
        return SymLogNorm(LINTHRESH, linscale=1.0, vmin=0.0, vmax=hi, base=10)
    top = max(abs(lo), abs(hi))
    return SymLogNorm(LINTHRESH, linscale=1.0, vmin=-top, vmax=top, base=10)


def _cmap(kind: str):
    import matplotlib
    from matplotlib.colors import ListedColormap

    base = matplotlib.colormaps[SIGNED_CMAP]
    if kind != "k":
        return base
    return ListedColormap(base(np.linspace(0.5, 1.0, 128)), name=f"{SIGNED_CMAP}_upper")


def plot_map(ax, d: dict, kind: str, *, vmin=None, vmax=None, norm=None,
             colorbar: bool = True, grains: int = GRAINS_SHOWN):
    """One panel: e/e0 of one kind (``"k"``, ``"p"``, ``"t"``) against grain and time.

    ``norm`` (e.g. :func:`color_norm`) or ``vmin``/``vmax``: the colour scale;
    ``colorbar``: a colour bar of the panel's own (False: the caller shares one).
    """
    key = "t_" if kind == "t" else kind
    vals = d[key][:, :grains]
    label = dict((k, lab) for k, _, lab in KINDS)[kind] if colorbar else ""
    return plot_spacetime(ax, d["t"], vals, interface=d["interface"], cmap=_cmap(kind),
                          vmin=vmin, vmax=vmax, norm=norm, label=label, numbering="paper",
                          interface_color="0.35")


def figure(data: dict):
    """The Fig. 8 figure: 4 × 3 panels (rows M, N, P, Q; columns kinetic, potential, total).

    One colour bar per column (each column is one quantity on one scale,
    :func:`color_norm`), under it.
    """
    from matplotlib.ticker import FixedLocator, FuncFormatter

    pts = list(data)
    fig, axes = new_figure(len(pts), 3, figsize=(12, 2.7 * len(pts) + 1.2),
                           sharex=True, sharey="row")
    norms = {k: color_norm(data, k) for k, _, _ in KINDS}
    for j, (k, name, label) in enumerate(KINDS):
        for i, p in enumerate(pts):
            ax = axes[i, j]
            im = plot_map(ax, data[p], k, norm=norms[k], colorbar=False)
            ax.set_title(f"({'abcd'[i]}{j + 1}) {p}: {name}", fontsize="medium")
            if i < len(pts) - 1:
                ax.set_xlabel("")
            if j:
                ax.set_ylabel("")
        cb = fig.colorbar(im, ax=axes[:, j], location="bottom", shrink=0.9, aspect=30,
                          pad=0.01, label=f"{label} (symmetric log scale)")
        top = norms[k].vmax
        ticks = [t for t in (-1.0, -0.1, -0.01, 0.0, 0.01, 0.1, 1.0)
                 if norms[k].vmin <= t <= top]
        cb.ax.xaxis.set_major_locator(FixedLocator(ticks))
        cb.ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))
        cb.ax.tick_params(labelsize="small")
    return fig


def figures(ctx: Context, data: dict) -> list:
    """Save ``fig8.png`` (:func:`figure`)."""
    path = save_figure(ctx, figure(data), "fig8", dpi=90)
    return [(path, "Fig. 8: energy per grain over its value at the incident peak, δ0^L/d = "
             "1e-3, interface 200|201 (dotted); rows M, N, P, Q; one colour scale per "
             f"column (colour bar under it), symmetric-logarithmic: linear within "
             f"±{LINTHRESH:g}, logarithmic beyond, so that the weak reflected waves show; "
             "white: zero, red: positive, blue: negative potential energy (expansive "
             "waves).")]


def report(rep, data: dict, figs: list) -> None:
    """Add the Fig. 8 section."""
    rep.heading("Fig. 8 — space–time energy maps of M, N, P, Q")
    rows = []
    for p, d in data.items():
        rows.append([p, d["max_right"]["k"], d["max_right"]["p"], d["max_right"]["t"],
                     d["min_left"]["p"], d["min_left"]["t"]])
    rep.table(["point", "max e_k/e_k0 right", "max e_p/e_p0 right", "max e_t/e_t0 right",
               "min e_p/e_p0 left (end)", "min e_t/e_t0 left (end)"], rows,
              caption="Extremes of the normalised maps (right: transmitted side; left at the "
              "last time: the reflected wave)")
    rep.paragraph(
        "Paper's reading, checked: M (γ_RG = 0.5) — transmitted waves brighter than the "
        "incident one in potential and total energy (max e_p/e_p0 on the right > 1), "
        "reflected wave a dark (negative potential energy, expansive) line; N (γ_RG = 2) — "
        "transmitted and reflected waves compressive (bright); P (γ_c0 = 0.5) — the "
        "transmitted wave slower and more compact, brighter; Q (γ_c0 = 2) — faster, "
        "extended, darker; P and Q reflect almost nothing.")
    for path, caption in figs:
        rep.figure(path, caption)


def to_json(data: dict) -> dict:
    """Incident-peak energies (J) and the extremes of the maps per point."""
    return {p: {"e_k0": d["refs"][0], "e_p0": d["refs"][1], "e_t0": d["refs"][2],
                "max_right": d["max_right"], "min_left_end": d["min_left"]}
            for p, d in data.items()}
