"""Plotting functions for the paper's figures; each draws on a given matplotlib ``ax``.

Grains on the axes are grain indices, counted from 0 as everywhere in hertzchain
(docs/guide/cli.md); ``numbering="paper"`` labels them with the paper's 1-based grain
numbers (index + 1) instead, for the figures of ``hertzchain reproduce`` that reproduce
the paper's.  None of these functions calls ``show()``; callers save the figure.
"""

from __future__ import annotations

import numpy as np

import theory

__all__ = [
    "plot_grain_profile",
    "plot_vmax",
    "plot_displacement_time",
    "plot_spacetime",
    "plot_theory_lines",
    "plot_forces",
    "plot_strain_maxima",
    "mark_interface",
    "plot_profiles",
    "plot_profile_difference",
    "plot_fronts",
    "plot_energy_partition",
]


NUMBERINGS = {"index": (0, "grain index $i$"), "paper": (1, "grain number $i$ (paper's)")}
"""Grain labels on the axes: (first label, axis title) of ``numbering="index"`` (0-based,
hertzchain's) and ``"paper"`` (the paper's 1-based numbers)."""


def _numbering(numbering: str) -> tuple[int, str]:
    if numbering not in NUMBERINGS:
        raise ValueError(f"numbering must be one of {sorted(NUMBERINGS)} (got {numbering!r})")
    return NUMBERINGS[numbering]


def mark_interface(ax, interface: int | None, *, numbering: str = "index",
                   **kwargs) -> None:
    """A vertical line between the last grain left of the interface and the first right.

    ``interface`` is the number of grains left of it (the index of the first grain of
    the second section).
    """
    if interface is None:
        return
    first, _ = _numbering(numbering)
    style = {"color": "0.4", "ls": ":", "lw": 1.0} | kwargs
    ax.axvline(interface + first - 0.5, **style)


def plot_grain_profile(ax, values, *, interface: int | None = None, label: str | None = None,
                       ylabel: str = r"$v_i/v_0$", start: int = 0, numbering: str = "index",
                       **kwargs):
    """Plot a per-grain quantity against the grain index (paper Figs. 3a, 4a, 5).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    values : array
        One value per grain (e.g. velocity / v0).
    interface : int, optional
        Number of grains left of the interface (paper: 400, 200, 35000).
    label, ylabel : str
        Legend label and y-axis label.
    start : int
        Array index of ``values[0]`` (to plot a window of a long chain).
    numbering : {"index", "paper"}
        Grain indices (0-based) or the paper's grain numbers (1-based) on the axis.
    """
    first, title = _numbering(numbering)
    values = np.asarray(values)
    grains = np.arange(start, start + values.size) + first
    line = ax.plot(grains, values, label=label, **({"lw": 0.8} | kwargs))
    mark_interface(ax, interface, numbering=numbering)
    ax.set_xlabel(title)
    ax.set_ylabel(ylabel)
    return line


def plot_vmax(ax, vmax_over_v0, *, mean: float | None = None, grain_range=None,
              label: str | None = None, numbering: str = "index"):
    """Per-grain maximum velocity / v0 with its mean (paper Fig. 2, squares and dashed line).

    ``grain_range``: the index range [lo, hi) of the mean.
    """
    first, title = _numbering(numbering)
    vmax_over_v0 = np.asarray(vmax_over_v0)
    grains = np.arange(vmax_over_v0.size) + first
    ax.plot(grains, vmax_over_v0, "s", ms=2, mfc="none", label=label)
    if mean is not None:
        lo, hi = grain_range if grain_range is not None else (0, vmax_over_v0.size)
        ax.hlines(mean, lo + first, hi - 1 + first, colors="k", linestyles="--",
                  label=rf"mean $\bar v_{{max}}/v_0$ = {mean:.4f}")
    ax.set_xlabel(title)
    ax.set_ylabel(r"$v_{max}/v_0$")


def plot_displacement_time(ax, t, u, grains, *, u_ref: float = 1.0, free_flight=None,
                           time_unit: float = 1e-3, numbering: str = "index",
                           legend: bool = True):
    """Displacement of chosen grains against time (paper Figs. 3c/d, 4c/d).

    Parameters
    ----------
    t : array (n_t,)
        Times, s.
    u : array (n_t, n_grains)
        Displacements, m.
    grains : sequence of int
        Array indices of the grains (labelled by ``numbering``: the index, or the paper's
        1-based number).
    u_ref : float
        Normalisation (paper: ū_max).
    free_flight : array (n_t, n_grains) of bool, optional
        Where a grain is in free flight (both contacts open); drawn as thick segments.
    time_unit : float
        Seconds per unit on the time axis (default ms).
    legend : bool
        A legend of the grains in the axes (False: the caller draws one, e.g. beside
        several panels showing the same grains).
    """
    first, _ = _numbering(numbering)
    t = np.asarray(t) / time_unit
    u = np.asarray(u) / u_ref
    for j, g in enumerate(grains):
        (line,) = ax.plot(t, u[:, j], lw=0.9, label=f"{g + first}")
        if free_flight is not None:
            mask = np.asarray(free_flight)[:, j]
            ax.plot(np.where(mask, t, np.nan), np.where(mask, u[:, j], np.nan), lw=3,
                    color=line.get_color(), alpha=0.4)
    ax.set_xlabel("time (ms)" if time_unit == 1e-3 else f"time (×{time_unit:g} s)")
    ax.set_ylabel(r"$u_i/\bar u_{max}$" if u_ref != 1.0 else r"$u_i$ (m)")
    if legend:
        ax.legend(title="grain" if first == 0 else "grain (paper's)", fontsize="x-small",
                  ncol=2)


def plot_spacetime(ax, t, values, *, interface: int | None = None, cmap: str = "inferno",
                   vmin=None, vmax=None, norm=None, label: str = "", time_unit: float = 1e-3,
                   start: int = 0, numbering: str = "index", interface_color: str = "w"):
    """Space-time map of a per-grain quantity (paper Fig. 8); returns the image.

    ``values`` has shape (n_times, n_grains); x is the grain (``numbering``), y the time.
    ``norm``: a :class:`matplotlib.colors.Normalize` (e.g. a symmetric-log one, so that
    weak waves next to strong ones stay visible) instead of ``vmin``/``vmax``; ``label``:
    a colour bar of its own with that label ("" for none: a caller sharing one colour bar
    between panels draws it).
    """
    first, title = _numbering(numbering)
    values = np.asarray(values)
    t = np.asarray(t) / time_unit
    extent = (start + first - 0.5, start + values.shape[1] + first - 0.5, t[0], t[-1])
    limits = {} if norm is not None else {"vmin": vmin, "vmax": vmax}
    im = ax.imshow(values, origin="lower", aspect="auto", extent=extent, cmap=cmap,
                   norm=norm, interpolation="nearest", **limits)
    mark_interface(ax, interface, numbering=numbering, color=interface_color)
    ax.set_xlabel(title)
    ax.set_ylabel("time (ms)" if time_unit == 1e-3 else "time")
    if label:
        ax.figure.colorbar(im, ax=ax, label=label)
    return im


def plot_theory_lines(ax, *, lim=(0.2, 5.0), regions: bool = True):
    """Draw γ_c0 = 1 (α_kn = α_ρ^{3/2}, Eq. 9) and γ_RG = 1 (α_kn = α_ρ^{-3/2}, Eq. 13).

    Log-log axes in (α_ρ, α_kn) as the paper's Fig. 7, with the region numerals.
    """
    a = np.geomspace(lim[0], lim[1], 200)
    ax.plot(a, a**1.5, "k-", lw=1.2, label=r"$\gamma_{c_0}=1$ (Eq. 9)")
    ax.plot(a, a**-1.5, "k--", lw=1.2, label=r"$\gamma_{R_G}=1$ (Eq. 13)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(*lim)
    ax.set_ylim(*lim)
    ax.set_xlabel(r"$\alpha_\rho = \rho^R/\rho^L$")
    ax.set_ylabel(r"$\alpha_{k_n} = k_n^R/k_n^L$")
    if regions:
        # a representative point inside each region, classified by theory itself
        lo, hi = np.log(lim[0]), np.log(lim[1])
        for x, y in ((0.3, 0.5), (0.5, 0.85), (0.7, 0.5), (0.5, 0.15)):
            ar, ak = np.exp(lo + x * (hi - lo)), np.exp(lo + y * (hi - lo))
            name = theory.region(theory.gamma_c0(ar, ak), theory.gamma_rg(ar, ak))
            ax.text(ar, ak, name, ha="center", va="center", fontsize=12, weight="bold",
                    color="0.3")


def plot_forces(ax, t, forces, labels, *, time_unit: float = 1e-3):
    """Measured forces vs time: wall forces and embedded sensors (N; t in s).

    ``forces`` (R, S) with one label per column.
    """
    forces = np.asarray(forces, dtype=float)
    for q, label in enumerate(labels):
        ax.plot(np.asarray(t) / time_unit, forces[:, q], lw=1.0, label=label)
    ax.set_xlabel("time (ms)" if time_unit == 1e-3 else "time")
    ax.set_ylabel("force (N)")
    if labels:
        ax.legend(fontsize=8)


def plot_strain_maxima(ax, strain_max, *, interface: int | None = None) -> None:
    """Per-contact strain maxima (max δ_j − δ0_j)/d vs contact index j (0: left wall).

    ``interface``: the first grain of the second section (0-based; its left contact is
    marked).  ``strain_max`` (N+1,): the running overlap maxima of a run
    (:class:`discrete.Recording` ``strain_maxima``) minus the static overlaps, over the
    grain diameter (dimensionless).
    """
    strain_max = np.asarray(strain_max, dtype=float)
    ax.plot(np.arange(strain_max.size), strain_max, lw=1.0, color="C3")
    if interface is not None:  # the interface contact j = interface (0-based grains)
        ax.axvline(interface, color="0.4", ls=":", lw=1.0)
    ax.set_xlabel("contact $j$")
    ax.set_ylabel(r"strain maximum $(\max\delta_j - \delta_{0,j})/d$")


# -- models side by side (hertzchain.compare) -------------------------------------------
_MODEL_STYLE = ({"color": "k", "lw": 1.2}, {"color": "C1", "lw": 1.0, "ls": "--"},
                {"color": "C2", "lw": 1.0, "ls": "-."})


def plot_profiles(ax, profiles: dict, *, interface: int | None = None, v_ref: float = 1.0,
                  title: str = "", ylabel: str = r"$v_i / v_{in}$") -> None:
    """Per-grain profiles of several models overlaid (e.g. grain velocity / v_ref).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    profiles : dict
        Label → one value per grain (the first is drawn solid black: the reference).
    interface : int, optional
        Grains left of the interface.
    v_ref : float
        Divisor of the values (e.g. the incident peak velocity, m/s).
    """
    for (label, values), style in zip(profiles.items(), _MODEL_STYLE, strict=False):
        plot_grain_profile(ax, np.asarray(values) / v_ref, interface=interface, label=label,
                           ylabel=ylabel, **style)
    ax.axhline(0, color="0.8", lw=0.4)
    if title:
        ax.set_title(title, fontsize="medium")
    ax.legend(fontsize="x-small", loc="upper left")


def plot_profile_difference(ax, differences: dict, *, interface: int | None = None,
                            v_ref: float = 1.0) -> None:
    """Model − reference of a per-grain profile, over ``v_ref`` (one line per model)."""
    for (label, values), style in zip(differences.items(), _MODEL_STYLE[1:], strict=False):
        plot_grain_profile(ax, np.asarray(values) / v_ref, interface=interface,
                           label=f"{label} − discrete", ylabel=r"$\Delta v_i / v_{in}$",
                           **style)
    ax.axhline(0, color="0.8", lw=0.4)
    if differences:
        ax.legend(fontsize="x-small", loc="upper left")


_WAVE_MARK = {"incident": "o", "transmitted": "^", "reflected": "v"}


def plot_fronts(ax, fronts: dict, *, theory=None, theory_speeds: dict | None = None,
                interface: int | None = None) -> None:
    """Front trajectories x(t) of the incident, transmitted and reflected waves.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    fronts : dict
        Label → (times (s), {wave: grain positions}) per model (markers).
    theory : (times, {wave: positions}), optional
        The theory's trajectories (lines).
    theory_speeds : dict, optional
        Wave → speed (m/s) for the legend.
    interface : int, optional
        Grains left of the interface (dotted line).
    """
    for (label, (t, fr)), style in zip(fronts.items(), _MODEL_STYLE, strict=False):
        for wave, x in fr.items():
            x = np.asarray(x)
            if np.isfinite(x).any():
                ax.plot(np.asarray(t) * 1e3, x, _WAVE_MARK[wave], ms=4, mfc="none",
                        color=style["color"], label=f"{label}: {wave}")
    if theory is not None:
        t, fr = theory
        for wave, x in fr.items():
            x = np.asarray(x)
            if np.isfinite(x).any():
                sp = (theory_speeds or {}).get(wave)
                ax.plot(np.asarray(t) * 1e3, x, "-", color="C3", lw=0.9,
                        label=f"theory: {wave}" + (f" ({sp:.1f} m/s)" if sp else ""))
    if interface is not None:
        ax.axhline(interface - 0.5, color="0.4", ls=":", lw=1.0)
    ax.set_xlabel("t (ms)")
    ax.set_ylabel("front position (grain index)")
    ax.legend(fontsize="xx-small", ncol=2)


def plot_energy_partition(ax, series: dict, *, theory=None, t_compare: float | None = None
                          ) -> None:
    """Energy left and right of the interface over the incident energy, against time.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    series : dict
        Label → (times (s), left fraction, right fraction) per model.
    theory : (times, left, right), optional
        The linear-acoustic prediction (dashed).
    t_compare : float, optional
        The comparison time, s (vertical line).
    """
    for (label, (t, left, right)), style in zip(series.items(), _MODEL_STYLE, strict=False):
        t = np.asarray(t) * 1e3
        ax.plot(t, right, label=f"{label}: right (transmitted)", **style)
        ax.plot(t, left, label=f"{label}: left (incident/reflected)",
                **(style | {"alpha": 0.6}))
    if theory is not None:
        t, left, right = theory
        ax.plot(np.asarray(t) * 1e3, right, color="C3", ls=":", lw=1.2,
                label="theory (Eqs. 9–13): right")
        ax.plot(np.asarray(t) * 1e3, left, color="C3", ls=":", lw=1.2, alpha=0.6,
                label="theory: left")
    if t_compare is not None:
        ax.axvline(t_compare * 1e3, color="0.6", lw=0.6)
    ax.set_xlabel("t (ms)")
    ax.set_ylabel(r"$E / E_{in}$")
    ax.legend(fontsize="x-small")
