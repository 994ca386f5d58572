"""Figures of a sweep: the phase-diagram map (paper Fig. 7) and 1-D cuts.

The drawing functions take a matplotlib ``ax`` and never call ``show()``;
:func:`save_sweep_figures` builds the figures (without pyplot) and saves PNGs.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

import theory

from .sweep.analysis import fission_parameter
from .sweep.store import SweepResults, read_results

__all__ = [
    "CLASSES",
    "classification_codes",
    "plot_phase_map",
    "plot_cut",
    "phase_map_figure",
    "cuts_figure",
    "save_sweep_figures",
    "VALIDITY_MODELS",
    "validity_summary",
    "plot_validity_map",
    "plot_validity_amplitude",
    "validity_figure",
    "plot_ensemble",
]

CLASSES: tuple[tuple[str, str], ...] = (
    ("I: fracture + expansive", "#E69F00"),
    ("II: fracture + compressive", "#D55E00"),
    ("III: squeeze + compressive", "#0072B2"),
    ("IV: squeeze + expansive", "#56B4E9"),
    ("no fracture/squeeze or no reflection", "#F0E442"),
    ("failed", "#8C8C8C"),
    ("pending", "#FFFFFF"),
    ("not classified (waves not separated, or run incomplete)", "#CC79A7"),
)
"""Label and colour of each class code 0..7 (Okabe–Ito colours; regions as in Fig. 7)."""

_CODES = {("fracture", "expansive"): 0, ("fracture", "compressive"): 1,
          ("squeeze", "compressive"): 2, ("squeeze", "expansive"): 3}
_LABELS = {
    "alpha_rho": r"$\alpha_\rho = \rho^R/\rho^L$",
    "alpha_kn": r"$\alpha_{k_n} = k_n^R/k_n^L$",
    "gamma_c0": r"$\gamma_{c_0}$",
    "gamma_RG": r"$\gamma_{R_G}$",
    "delta0_over_d": r"$\delta_0^L/d$",
}


def classification_codes(results: SweepResults) -> np.ndarray:
    """Class code (index into :data:`CLASSES`) of every row."""
    status = results["status"]
    trans = results["transmitted"] if "transmitted" in results else np.full(len(status), "")
    refl = results["reflected"] if "reflected" in results else np.full(len(status), "")
    codes = np.array([_CODES.get((t, r), 4) for t, r in zip(trans, refl, strict=True)])
    # a label is "" where it is undefined: not the same as a measured "none"
    codes[(trans == "") | (refl == "")] = 7
    if "completed" in results:
        codes[np.asarray(results["completed"]) == 0] = 7
    codes[status == "failed"] = 5
    codes[status == "pending"] = 6
    return codes


def _is_log(values: np.ndarray, name: str) -> bool:
    v = values[np.isfinite(values)]
    if v.size == 0 or v.min() <= 0:
        return False
    return name in _LABELS or v.max() / v.min() >= 5


def _edges(centres: np.ndarray, log: bool) -> np.ndarray:
    c = np.log(centres) if log else centres
    if c.size == 1:
        e = np.array([c[0] - 0.5, c[0] + 0.5]) if not log else c[0] + np.array([-0.1, 0.1])
    else:
        mid = 0.5 * (c[1:] + c[:-1])
        e = np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])
    return np.exp(e) if log else e


def _log_ticks(axis) -> None:
    """Plain-number ticks (0.2, 0.5, 1, 2, 5) on a log axis instead of 2×10⁻¹ labels."""
    axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def _grid(x: np.ndarray, y: np.ndarray):
    """Unique values and row -> (j, i) indices if (x, y) fill a full grid, else None."""
    ux, ix = np.unique(x, return_inverse=True)
    uy, iy = np.unique(y, return_inverse=True)
    if ux.size * uy.size != x.size:
        return None
    if np.unique(iy * ux.size + ix).size != x.size:
        return None
    return ux, uy, ix, iy


def plot_phase_map(ax, results: SweepResults, *, x: str = "alpha_rho", y: str = "alpha_kn",
                   energy: str | None = "Ek_re", levels=(0.01, 0.03, 0.1, 0.2, 0.3),
                   theory_lines: bool = True, fission_line: bool = True,
                   paper_points: bool = True, legend: bool = True) -> None:
    """Draw the classification map with theory lines and reflected-energy contours.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    results : SweepResults
        The sweep table.
    x, y : str
        Columns on the axes (default the interface ratios α_ρ, α_kn; log axes when the
        values are positive and span a wide range).
    energy : str or None
        Measured reflected-energy column to contour (solid), next to the linear-acoustic
        ``theory.energy_reflection(γ_RG)`` (dotted); None for no contours.
    levels : sequence of float
        Contour levels (fractions of the incident energy).
    theory_lines : bool
        Draw γ_c0 = 1 (Eq. 9, α_kn = α_ρ^{3/2}) and γ_RG = 1 (Eq. 13, α_kn = α_ρ^{-3/2})
        when the axes are (α_ρ, α_kn).
    fission_line : bool
        Also draw the weakly nonlinear fracture boundary q = 1
        (:func:`hertzchain.sweep.analysis.fission_parameter`).
    paper_points : bool
        Mark the paper's points a–d, M, N, P, Q inside the map.
    legend : bool
        Add a legend right of the axes.
    """
    xs = np.asarray(results[x], dtype=float)
    ys = np.asarray(results[y], dtype=float)
    codes = classification_codes(results)
    cmap = ListedColormap([c for _, c in CLASSES])
    norm = BoundaryNorm(np.arange(len(CLASSES) + 1) - 0.5, len(CLASSES))
    logx, logy = _is_log(xs, x), _is_log(ys, y)
    grid = _grid(xs, ys)
    if grid is not None:
        ux, uy, ix, iy = grid
        c = np.full((uy.size, ux.size), 6)
        c[iy, ix] = codes
        ax.pcolormesh(_edges(ux, logx), _edges(uy, logy), c, cmap=cmap, norm=norm,
                      edgecolors="0.85", linewidth=0.2)
    else:
        ax.scatter(xs, ys, c=codes, cmap=cmap, norm=norm, marker="s", s=36,
                   edgecolors="0.4", linewidths=0.4)
    ax.set_xscale("log" if logx else "linear")
    ax.set_yscale("log" if logy else "linear")
    if logx:
        _log_ticks(ax.xaxis)
    if logy:
        _log_ticks(ax.yaxis)
    if grid is not None:
        ex, ey = _edges(grid[0], logx), _edges(grid[1], logy)
        ax.set_xlim(ex[0], ex[-1])
        ax.set_ylim(ey[0], ey[-1])
    ax.set_xlabel(_LABELS.get(x, x))
    ax.set_ylabel(_LABELS.get(y, y))
    handles = [Patch(facecolor=col, edgecolor="0.4", label=lab)
               for k, (lab, col) in enumerate(CLASSES) if k < 4 or np.any(codes == k)]
    alphas = (x, y) == ("alpha_rho", "alpha_kn")
    xlo, xhi = ax.get_xlim()
    ylo, yhi = ax.get_ylim()
    if alphas and theory_lines and logx and logy:
        a = np.geomspace(xlo, xhi, 200)
        ax.plot(a, a**1.5, "k-", lw=1.4)
        ax.plot(a, a**-1.5, "k--", lw=1.4)
        handles += [Line2D([], [], color="k", ls="-", label=r"$\gamma_{c_0}=1$ (Eq. 9)"),
                    Line2D([], [], color="k", ls="--", label=r"$\gamma_{R_G}=1$ (Eq. 13)")]
        if fission_line:
            gx, gy = np.meshgrid(np.geomspace(xlo, xhi, 200), np.geomspace(ylo, yhi, 200))
            ax.contour(gx, gy, fission_parameter(gx, gy), levels=[1.0], colors="0.15",
                       linestyles="-.", linewidths=1.1)
            handles.append(Line2D([], [], color="0.15", ls="-.", label=(
                r"fission $\gamma_{c_0}\sqrt{2\gamma_{R_G}/(1+\gamma_{R_G})}=1$")))
    if energy is not None and energy in results:
        z = np.where(results.ok, np.asarray(results[energy], dtype=float), np.nan)
        drawn = _contour(ax, xs, ys, z, grid, levels, colors="#5B2C83", linestyles="-")
        if drawn:
            handles.append(Line2D([], [], color="#5B2C83", ls="-",
                                  label=f"measured {energy}"))
        if alphas and logx and logy:
            gx, gy = np.meshgrid(np.geomspace(xlo, xhi, 120), np.geomspace(ylo, yhi, 120))
            zt = theory.energy_reflection(theory.gamma_rg(gx, gy))
            cs = ax.contour(gx, gy, zt, levels=list(levels), colors="#5B2C83",
                            linestyles=":", linewidths=1.0)
            ax.clabel(cs, fontsize=6, fmt="%g")
            label = r"linear acoustics $((\gamma_{R_G}-1)/(\gamma_{R_G}+1))^2$"
            handles.append(Line2D([], [], color="#5B2C83", ls=":", label=label))
    if alphas and paper_points:
        for name, (pr, pk) in theory.PAPER_POINTS.items():
            if xlo <= pr <= xhi and ylo <= pk <= yhi:
                ax.plot(pr, pk, "o", mfc="none", mec="k", ms=5, mew=0.9)
                ax.annotate(name, (pr, pk), xytext=(3, 3), textcoords="offset points",
                            fontsize=8, weight="bold")
    ax.set_xlim(xlo, xhi)
    ax.set_ylim(ylo, yhi)
    if legend:
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0),
                  fontsize="x-small", frameon=False)


def _contour(ax, xs, ys, z, grid, levels, **style) -> bool:
    ok = np.isfinite(z)
    if ok.sum() < 4 or np.nanmin(z) == np.nanmax(z):
        return False
    try:
        if grid is not None:
            ux, uy, ix, iy = grid
            zz = np.full((uy.size, ux.size), np.nan)
            zz[iy, ix] = z
            cs = ax.contour(ux, uy, np.ma.masked_invalid(zz), levels=list(levels),
                            linewidths=1.1, **style)
        else:
            cs = ax.tricontour(xs[ok], ys[ok], z[ok], levels=list(levels), linewidths=1.1,
                               **style)
    except (ValueError, RuntimeError):  # degenerate triangulation or levels out of range
        return False
    ax.clabel(cs, fontsize=6, fmt="%g")
    return True


def plot_cut(ax, results: SweepResults, *, along: str = "alpha_rho", at: float = 1.0,
             quantities: tuple[str, ...] = ("Ek_re", "Et_re")) -> bool:
    """Plot measured quantities along one axis of an (α_ρ, α_kn) map, with theory.

    The other ratio is fixed at the sampled value nearest (in log) to ``at``.  Energy
    columns (``E*_re``, ``E*_tr``) get the linear-acoustic reflection/transmission
    ``((γ_RG-1)/(γ_RG+1))²`` / ``4γ_RG/(1+γ_RG)²``; ``front_speed_tr_over_c0L`` gets
    γ_c0 (Eq. 9), the long-wave limit of the transmitted front speed.

    Returns
    -------
    bool
        False (and a note in the axes) if the table has no such cut.
    """
    other = "alpha_kn" if along == "alpha_rho" else "alpha_rho"
    xa = np.asarray(results[along], dtype=float)
    xo = np.asarray(results[other], dtype=float)
    sel = np.isfinite(xa) & np.isfinite(xo) & (xo > 0)
    if sel.any():
        uo = np.unique(xo[sel])
        fixed = uo[np.argmin(np.abs(np.log(uo / at)))]
        sel &= np.isclose(xo, fixed, rtol=1e-9)
    if np.unique(xa[sel]).size < 2:
        ax.text(0.5, 0.5, f"no cut along {along}", transform=ax.transAxes, ha="center")
        return False
    order = np.flatnonzero(sel)[np.argsort(xa[sel])]
    ok = results.ok[order]
    a = np.geomspace(xa[order].min(), xa[order].max(), 200)
    pair = (a, fixed) if along == "alpha_rho" else (fixed, a)
    g = theory.gamma_rg(*pair)
    references = {
        "_re": (theory.energy_reflection(g),
                r"linear acoustics $((\gamma_{R_G}-1)/(\gamma_{R_G}+1))^2$"),
        "_tr": (theory.energy_transmission(g),
                r"linear acoustics $4\gamma_{R_G}/(1+\gamma_{R_G})^2$"),
        "speed": (theory.gamma_c0(*pair), r"$\gamma_{c_0}$ (Eq. 9, long-wave limit)"),
    }
    drawn = set()
    for q, marker in zip(quantities, "osD^v", strict=False):
        if q not in results:
            continue
        ax.plot(xa[order][ok], np.asarray(results[q], dtype=float)[order][ok], marker,
                ms=4, mfc="none" if marker != "o" else None, label=f"{q} (simulation)")
        ref = ("speed" if q == "front_speed_tr_over_c0L" else
               q[-3:] if q.startswith("E") and q.endswith(("_re", "_tr")) else None)
        if ref is not None and ref not in drawn:
            drawn.add(ref)
            ax.plot(a, references[ref][0], "k-", lw=1, label=references[ref][1])
    bad = order[~ok]
    for k, xb in enumerate(xa[bad]):
        ax.axvline(xb, color=CLASSES[5][1], lw=0.8, ls=":",
                   label="failed point" if k == 0 else None)
    ax.set_xscale("log")
    _log_ticks(ax.xaxis)
    ax.set_xlabel(_LABELS[along])
    ax.set_title(f"{_LABELS[other]} = {fixed:.3g}", fontsize="small")
    ax.legend(fontsize="x-small")
    return True


def _title(results: SweepResults) -> str:
    name = str(results.attrs.get("name", "sweep"))
    d0 = results["delta0_over_d"] if "delta0_over_d" in results else np.array([])
    d0 = np.unique(d0[np.isfinite(d0)])
    extra = rf", $\delta_0^L/d$ = {d0[0]:g}" if d0.size == 1 else ""
    return f"{name}: {results.attrs.get('n_ok', '?')} ok, {results.attrs.get('n_failed', '?')} " \
           f"failed of {len(results)} points{extra}"


def phase_map_figure(results: SweepResults, **kwargs) -> Figure:
    """A figure with :func:`plot_phase_map` (keyword arguments are passed on)."""
    fig = Figure(figsize=(8.2, 5.6), layout="constrained")
    ax = fig.subplots()
    plot_phase_map(ax, results, **kwargs)
    ax.set_title(_title(results), fontsize="small")
    return fig


def cuts_figure(results: SweepResults, *, energy: tuple[str, ...] = ("Ek_re", "Et_re")
                ) -> Figure:
    """Four 1-D cuts through α = 1: reflected energies and transmitted front speed."""
    fig = Figure(figsize=(9.5, 7.0), layout="constrained")
    axes = fig.subplots(2, 2)
    for col, along in enumerate(("alpha_rho", "alpha_kn")):
        plot_cut(axes[0, col], results, along=along, quantities=energy)
        axes[0, col].set_ylabel("reflected / incident energy")
        plot_cut(axes[1, col], results, along=along, quantities=("front_speed_tr_over_c0L",))
        axes[1, col].set_ylabel(r"transmitted front speed / $c_0^L$")
    fig.suptitle(_title(results), fontsize="small")
    return fig


def save_sweep_figures(results: SweepResults | str | Path, out: str | Path | None = None,
                       *, x: str | None = None, y: str | None = None,
                       energy: str = "Ek_re", dpi: int = 130) -> list[Path]:
    """Save the map (``out``, default ``DIR/phase_map.png``) and the cuts (``*-cuts.png``).

    Parameters
    ----------
    results : SweepResults or path
        The table or its file/directory.
    out : path-like, optional
        PNG path of the map.
    x, y : str, optional
        Map axes; default (α_ρ, α_kn) when they vary, else the first two swept columns.
    energy : str
        Reflected-energy column for the contours.
    dpi : int
        Resolution.

    Returns
    -------
    list of pathlib.Path
        The PNG files written (the cuts only when α_ρ/α_kn vary; ``validity_map.png``
        when the points ran every model, :func:`validity_figure`; ``ensemble_decay.png``
        for an ensemble sweep, :func:`plot_ensemble`).
    """
    if not isinstance(results, SweepResults):
        results = read_results(results)
    base = results.path.parent if results.path is not None else Path.cwd()
    out = Path(out) if out is not None else base / "phase_map.png"
    varies = [c for c in ("alpha_rho", "alpha_kn")
              if c in results and np.unique(results[c][np.isfinite(results[c])]).size > 1]
    if x is None or y is None:
        numeric = [a for a in results.axes if results[a].dtype.kind in "if"]
        dx, dy = ("alpha_rho", "alpha_kn") if len(varies) == 2 else \
            ((numeric + ["index", "index"])[:2] if len(numeric) != 1 else (numeric[0], "index"))
        x, y = x or dx, y or dy
    out.parent.mkdir(parents=True, exist_ok=True)
    import matplotlib.pyplot as plt

    from .cache import atomic_path

    figures = [(out, phase_map_figure(results, x=x, y=y, energy=energy))]
    if any(f"{m}_error" in results for m in VALIDITY_MODELS):
        figures.append((out.with_name("validity_map.png"), validity_figure(results)))
    if results.ensemble:  # the amplitude decay of an ensemble sweep
        fig = Figure(figsize=(7, 4.5))
        if plot_ensemble(fig.add_subplot(), results):
            figures.append((out.with_name("ensemble_decay.png"), fig))
    if varies:
        figures.append((out.with_name(out.stem + "-cuts.png"),
                        cuts_figure(results, energy=tuple(dict.fromkeys((energy, "Et_re"))))))
    for path, fig in figures:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=dpi, format="png")
        plt.close(fig)
    return [path for path, _ in figures]


# -- the model-validity map (issue 12) ---------------------------------------------------
VALIDITY_MODELS = ("continuum", "theory")
"""Models whose error against the discrete chain a sweep can record (columns
``<model>_error`` of :func:`hertzchain.compare.compare_point`)."""
_VALIDITY_CLASSES = (("within 1 %", "#009E73"), ("within 10 %", "#F0E442"),
                     ("beyond 10 %", "#D55E00"),
                     ("not compared (did not run or complete, or a window did not hold)",
                      "#8C8C8C"))


def _thresholds() -> tuple[float, float]:
    from .compare import THRESHOLDS

    return THRESHOLDS


def _validity_codes(err: np.ndarray) -> np.ndarray:
    lo, hi = _thresholds()
    codes = np.full(err.shape, 3)
    ok = np.isfinite(err)
    codes[ok & (err <= lo)] = 0
    codes[ok & (err > lo) & (err <= hi)] = 1
    codes[ok & (err > hi)] = 2
    return codes


def _column(results: SweepResults, *names: str) -> np.ndarray | None:
    for name in names:
        if name in results:
            return np.asarray(results[name], dtype=float)
    return None


def _amplitude(results: SweepResults) -> np.ndarray:
    """Incident strain / δ0 per row (inf in the sonic vacuum, NaN if not measured)."""
    col = _column(results, "incident_strain_over_delta0")
    return col if col is not None else np.full(len(results), np.nan)


def validity_summary(results: SweepResults) -> list[dict]:
    """Per model and amplitude: how many points are within 1 % and 10 % of the chain.

    Rows are grouped by the incident strain / δ0 (column ``incident_strain_over_delta0``,
    rounded to two significant digits; inf = sonic vacuum).  Each entry has ``model``,
    ``strain_over_delta0``, ``n`` (points), ``within_1``, ``within_10``, ``beyond_10``,
    ``not_compared``, ``max_error`` (over the compared points), ``equation`` (the
    continuum equations that ran, column ``continuum_model``: e.g. "eq4"; "" for the
    theory) and ``reasons`` (why points were not compared: the distinct first clauses of
    ``<model>_note``, or of ``continuum_stopped_by`` for a continuum that did not
    complete).
    """
    amp = _amplitude(results)
    key = np.array([float(f"{a:.2g}") if np.isfinite(a) else a for a in amp])
    out = []
    for model in VALIDITY_MODELS:
        err = _column(results, f"{model}_error")
        if err is None:
            continue
        codes = _validity_codes(err)
        groups = sorted({float(k) for k in key if not np.isnan(k)}) or [math.nan]
        for g in groups:
            sel = key == g if not np.isnan(g) else np.isnan(key)
            e = err[sel]
            out.append({"model": model, "strain_over_delta0": g, "n": int(sel.sum()),
                        "within_1": int((codes[sel] == 0).sum()),
                        "within_10": int((codes[sel] <= 1).sum()),
                        "beyond_10": int((codes[sel] == 2).sum()),
                        "not_compared": int((codes[sel] == 3).sum()),
                        "max_error": float(np.nanmax(e)) if np.isfinite(e).any()
                        else math.nan,
                        "equation": "/".join(sorted(set(_text(results, "continuum_model",
                                                              sel)) - {""}))
                        if model == "continuum" else "",
                        "reasons": _reasons(results, model, sel & (codes == 3))})
    return out


def _text(results: SweepResults, name: str, sel: np.ndarray) -> list[str]:
    """The string column ``name`` at the selected rows ("" for a missing column)."""
    if name not in results:
        return [""] * int(sel.sum())
    return [str(x) for x in np.asarray(results[name])[sel]]


def _reasons(results: SweepResults, model: str, sel: np.ndarray) -> str:
    """Distinct first clauses of why the selected rows of ``model`` were not compared."""
    notes = _text(results, f"{model}_note", sel)
    if model == "continuum":
        stopped = _text(results, "continuum_stopped_by", sel)
        notes = [n or (f"did not complete ({s})" if s and s not in ("t_end", "until_front_at")
                       else "") for n, s in zip(notes, stopped, strict=True)]
    first = {n.split(" (")[0].split(": ")[0].split(";")[0] for n in notes}
    return "; ".join(sorted(first - {""}))


def plot_validity_map(ax, results: SweepResults, *, model: str = "continuum",
                      amplitude: float | None = None, legend: bool = True) -> bool:
    """Draw where ``model`` is within 1 % / 10 % of the discrete chain over (α_ρ, α_kn).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    results : SweepResults
        A sweep whose points ran :func:`hertzchain.compare.compare_point`.
    model : {"continuum", "theory"}
        Whose error (column ``<model>_error``: the largest of |ΔE_T|, |ΔE_R| over the
        incident energy and the relative transmitted front speed).
    amplitude : float, optional
        Incident strain / δ0 of the rows drawn (nearest; inf = sonic vacuum); default
        the smallest in the table.
    legend : bool
        Draw the class legend.

    Returns
    -------
    bool
        False (and a note on the axes) if the table has no such error or no α grid.
    """
    err = _column(results, f"{model}_error")
    xr, yk = _column(results, "alpha_rho"), _column(results, "alpha_kn")
    if err is None or xr is None or yk is None:
        ax.text(0.5, 0.5, f"no {model} error in this sweep", ha="center",
                transform=ax.transAxes)
        return False
    amp = _amplitude(results)
    levels = np.unique(amp[~np.isnan(amp)])
    sel = np.ones(len(results), dtype=bool)
    if levels.size:
        target = levels[0] if amplitude is None else amplitude
        near = levels[np.argmin(np.abs(np.log(levels) - np.log(target)))] \
            if np.isfinite(target) else levels[-1]
        sel = np.isclose(amp, near, rtol=0.05) | (np.isinf(amp) & np.isinf(near))
        ratio = "sonic vacuum" if np.isinf(near) else rf"$\xi_m/\delta_0$ = {near:.2g}"
    else:
        ratio = ""
    codes = _validity_codes(err[sel])
    cmap = ListedColormap([c for _, c in _VALIDITY_CLASSES])
    ax.scatter(xr[sel], yk[sel], c=codes, cmap=cmap, vmin=-0.5, vmax=3.5, s=140,
               marker="s", edgecolors="k", linewidths=0.4)
    for x, y, e in zip(xr[sel], yk[sel], err[sel], strict=True):
        if np.isfinite(e):
            ax.annotate(f"{100 * e:.2g}", (x, y), ha="center", va="center", fontsize=6)
    ax.set_xscale("log")
    ax.set_yscale("log")
    _log_ticks(ax.xaxis)
    _log_ticks(ax.yaxis)
    ax.margins(0.12)
    ax.set_xlabel(_LABELS["alpha_rho"])
    ax.set_ylabel(_LABELS["alpha_kn"])
    ax.set_title(f"{model} vs discrete, error in % ({ratio})", fontsize="small")
    if legend:
        ax.legend(handles=[Patch(facecolor=c, edgecolor="k", label=lbl)
                           for lbl, c in _VALIDITY_CLASSES],
                  fontsize="x-small", loc="upper left", bbox_to_anchor=(1.02, 1.0),
                  frameon=False)
    return True


def plot_validity_amplitude(ax, results: SweepResults) -> bool:
    """Largest and median error of each model over the α grid against strain / δ0.

    The sonic vacuum (δ0 = 0, strain/δ0 = ∞) is drawn at the right edge, one decade past
    the largest finite amplitude.  Dashed lines: the 1 % and 10 % thresholds.
    """
    amp = _amplitude(results)
    finite = amp[np.isfinite(amp)]
    if not np.isfinite(amp).any() and not np.isinf(amp).any():
        ax.text(0.5, 0.5, "no amplitude column", ha="center", transform=ax.transAxes)
        return False
    x_inf = 10 * finite.max() if finite.size else 1.0
    xs = np.where(np.isinf(amp), x_inf, amp)
    drawn = False
    for model, colour in zip(VALIDITY_MODELS, ("#0072B2", "#D55E00"), strict=True):
        err = _column(results, f"{model}_error")
        if err is None:
            continue
        levels = np.unique(xs[np.isfinite(xs)])
        worst = [np.nanmax(err[xs == v]) if np.isfinite(err[xs == v]).any() else np.nan
                 for v in levels]
        median = [np.nanmedian(err[xs == v]) if np.isfinite(err[xs == v]).any() else np.nan
                  for v in levels]
        ax.plot(levels, worst, "o-", color=colour, label=f"{model}: largest")
        ax.plot(levels, median, "s--", color=colour, mfc="none", label=f"{model}: median")
        drawn = True
    for level in _thresholds():
        ax.axhline(level, color="0.4", lw=0.8, ls=":")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"incident strain / $\delta_0$ (last point: sonic vacuum)")
    ax.set_ylabel("error vs discrete chain")
    if drawn:
        ax.legend(fontsize="x-small")
    return drawn


def validity_figure(results: SweepResults) -> Figure:
    """The validity map: each model over (α_ρ, α_kn) per amplitude; error vs amplitude.

    One row per model (continuum, theory) of :func:`plot_validity_map` panels, one
    column per incident strain / δ0 in the table (the sonic vacuum last), and
    :func:`plot_validity_amplitude` on the right.
    """
    amp = _amplitude(results)
    levels = [float(a) for a in np.unique(amp[~np.isnan(amp)])] or [math.nan]
    n = len(levels)
    fig = Figure(figsize=(2.3 * n + 5.0, 5.2), layout="constrained")
    grid = fig.add_gridspec(2, n + 1, width_ratios=[1.0] * n + [2.2])
    for row, model in enumerate(VALIDITY_MODELS):
        for col, level in enumerate(levels):
            ax = fig.add_subplot(grid[row, col])
            drawn = plot_validity_map(ax, results, model=model,
                                      amplitude=None if math.isnan(level) else level,
                                      legend=False)
            if not drawn:
                continue
            where = "sonic vacuum" if math.isinf(level) else rf"$\xi_m/\delta_0$ = {level:.2g}"
            ax.set_title(f"{model}, {where}", fontsize="x-small")
            ax.tick_params(labelsize="xx-small")
            ax.xaxis.label.set_size("x-small")
            ax.yaxis.label.set_size("x-small")
            if col:
                ax.set_ylabel("")
            if row == 0:
                ax.set_xlabel("")
    side = fig.add_subplot(grid[:, n])
    plot_validity_amplitude(side, results)
    side.legend(handles=side.get_legend_handles_labels()[0]
                + [Patch(facecolor=c, edgecolor="k", label=lbl)
                   for lbl, c in _VALIDITY_CLASSES], fontsize="xx-small")
    fig.suptitle(_title(results) + " — error against the discrete chain, in % (1 % and "
                 "10 % thresholds)", fontsize="small")
    return fig


def plot_ensemble(ax, results: SweepResults, *, log: bool = True) -> bool:
    r"""Transmitted amplitude against distance of an ensemble sweep, one curve per point.

    For every row of the ``/ensemble`` table (a point of the other axes): the mean over
    its realisations of :math:`\ln A_i` (A the running maximum of v, m/s) at the
    profile grains, with a band of ±1 standard error, and the fitted decay
    :math:`e^{-(i - i_0)/\xi}` of the localisation length ξ (legend: ξ ± its error,
    grains; docs/physics.md §18).  ``log``: a logarithmic amplitude axis.  Returns False
    (nothing drawn) if the sweep has no ensemble statistics.
    """
    ens = results.ensemble
    if not ens or "log_profile_mean" not in ens or not ens["profile_grains"].size:
        return False
    grains = np.asarray(ens["profile_grains"], float)
    axes = [a for a in results.axes if a != "seed" and a in ens]
    for g in range(len(ens["n_realisations"])):
        lm, ls = ens["log_profile_mean"][g], ens["log_profile_sem"][g]
        ok = np.isfinite(lm)
        if not ok.any():
            continue
        label = ", ".join(f"{a}={ens[a][g]:g}" if isinstance(ens[a][g], float | np.floating)
                          else f"{a}={ens[a][g]}" for a in axes) or "ensemble"
        xi, err = ens["localisation_length"][g], ens["localisation_length_err"][g]
        label += f" (N={int(ens['n_realisations'][g])}"
        label += f", ξ = {xi:.3g} ± {err:.2g} grains)" if math.isfinite(xi) else ")"
        (line,) = ax.plot(grains[ok], np.exp(lm[ok]), label=label)
        band = np.isfinite(ls) & ok
        ax.fill_between(grains[band], np.exp(lm[band] - ls[band]), np.exp(lm[band] + ls[band]),
                        color=line.get_color(), alpha=0.25, linewidth=0)
    ax.set_xlabel("grain i")
    ax.set_ylabel(r"typical amplitude $\exp\langle\ln \max_t v_i\rangle$ (m/s)")
    if log:
        ax.set_yscale("log")
    ax.legend(fontsize="small")
    return True
