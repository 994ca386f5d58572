r"""Fig. 8: space–time maps of the kinetic, potential and total energy per grain, M N P Q.

Paper Section 4, Fig. 8: δ0^L/d = 1e-3, interface between grains 200 and 201; rows
a–d are the points M, N, P, Q, columns 1–3 the kinetic, potential and total energy per
grain (potential: half of each adjacent contact's energy minus its static energy,
docs/physics.md §6) divided by "the single grain kinetic energy, potential energy, and total
energy at the peak of the ISW" (:func:`discrete.diagnostics.normalise_to_incident_peak`,
the maxima over the left section before the wave reaches the interface).  The runs are
those of :mod:`.table2` (one HDF5 file each).
"""

from __future__ import annotations

import numpy as np

from discrete import diagnostics as D

from ..plotting import plot_spacetime
from .common import Context, new_figure, save_figure
from .table2 import POINTS, run_point

__all__ = ["QUICK", "FULL", "GRAINS_SHOWN", "run", "plot_map", "figures", "report", "to_json"]

QUICK: dict = {}
FULL: dict = {}
GRAINS_SHOWN = 600
"""Grains drawn (the paper's maps show the neighbourhood of the interface at 200)."""
KINDS = (("k", "kinetic", r"$e_k/e_{k0}$"), ("p", "potential", r"$e_p/e_{p0}$"),
         ("t", "total", r"$e_t/e_{t0}$"))


def run(ctx: Context, points=POINTS) -> dict:
    """Normalised energy grids of the points (from the Table 2 runs)."""
    out = {}
    for p in points:
        ctx.log(f"fig8: point {p}")
        r = run_point(ctx, p, grid=True)
        g = r.grid
        iface = g["interface"]
        rows = np.arange(0, g["i_incident"] + 1)
        ek, ep, et, refs = D.normalise_to_incident_peak(
            g["ek"], g["ep"], incident_rows=rows, grains=slice(0, iface))
        # stop the maps when the reflected wave reaches the left wall (its echo is not
        # part of the paper's figure)
        act = np.abs(g["ek"][:, :3] + g["ep"][:, :3]).sum(axis=1)
        tot = np.abs(g["ek"] + g["ep"]).sum(axis=1)
        hit = np.flatnonzero(act > 1e-3 * tot)
        stop = int(hit[0]) if hit.size else tot.size
        ek, ep, et = ek[:stop], ep[:stop], et[:stop]
        out[p] = {"t": g["t"][:stop], "k": ek, "p": ep, "t_": et, "refs": refs,
                  "interface": iface,
                  "gamma": (r.alpha_rho, r.alpha_kn),
                  "max_right": {k: float(a[:, iface:].max()) for k, a in
                                (("k", ek), ("p", ep), ("t", et))},
                  "min_left": {k: float(a[-1, :iface].min()) for k, a in
                               (("k", ek), ("p", ep), ("t", et))}}
    return out


def _limits(data: dict, kind: str) -> tuple[float, float]:
    key = "t_" if kind == "t" else kind
    lo = min(float(np.percentile(d[key], 0.05)) for d in data.values())
    hi = max(float(np.percentile(d[key], 99.95)) for d in data.values())
    return min(lo, 0.0), hi


def plot_map(ax, d: dict, kind: str, *, vmin=None, vmax=None, colorbar: bool = True,
             grains: int = GRAINS_SHOWN):
    """One panel: e/e0 of one kind (``"k"``, ``"p"``, ``"t"``) against grain and time."""
    key = "t_" if kind == "t" else kind
    vals = d[key][:, :grains]
    label = dict((k, lab) for k, _, lab in KINDS)[kind] if colorbar else ""
    return plot_spacetime(ax, d["t"], vals, interface=d["interface"], cmap="inferno",
                          vmin=vmin, vmax=vmax, label=label)


def figures(ctx: Context, data: dict) -> list:
    """Save ``fig8.png``: 4 × 3 panels (rows M, N, P, Q; columns kinetic, potential, total)."""
    pts = list(data)
    fig, axes = new_figure(len(pts), 3, figsize=(13, 3.0 * len(pts)))
    lims = {k: _limits(data, k) for k, _, _ in KINDS}
    for i, p in enumerate(pts):
        for j, (k, name, _) in enumerate(KINDS):
            ax = axes[i, j]
            plot_map(ax, data[p], k, vmin=lims[k][0], vmax=lims[k][1])
            ax.set_title(f"({'abcd'[i]}{j + 1}) {p}: {name}", fontsize="medium")
            if i < len(pts) - 1:
                ax.set_xlabel("")
    path = save_figure(ctx, fig, "fig8", dpi=90)
    return [(path, "Fig. 8: energy per grain over its value at the incident peak, δ0^L/d = "
             "1e-3, interface 200|201 (dotted); rows M, N, P, Q; colour scale shared per "
             "column (negative potential energy: expansive waves).")]


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
