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
    "plot_validity_laws",
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


# -- the model-validity map ----------------------------------------------------------------
VALIDITY_MODELS = ("continuum", "theory")
"""Models whose error against the discrete chain a sweep can record (columns
``<model>_error`` of :func:`hertzchain.compare.compare_point` and
:func:`hertzchain.reproduce.validity.validity_point`)."""
_SHADES = ((0.01, "#009E73"), (0.10, "#F0E442"))
"""Bands under the thresholds (within 1 %, within 10 %), drawn faintly."""
_NOT_COMPARED = "#8C8C8C"
_INTERFACE_MARKERS = "os^Dv<>ph*"
_NA_LABEL = "n/a"


def _thresholds() -> tuple[float, float]:
    from .compare import THRESHOLDS

    return THRESHOLDS


def _validity_codes(err: np.ndarray, applies: np.ndarray | None = None) -> np.ndarray:
    """0 within 1 %, 1 within 10 %, 2 beyond, 3 not compared, 4 does not apply."""
    lo, hi = _thresholds()
    codes = np.full(err.shape, 3)
    ok = np.isfinite(err)
    codes[ok & (err <= lo)] = 0
    codes[ok & (err > lo) & (err <= hi)] = 1
    codes[ok & (err > hi)] = 2
    if applies is not None:
        codes[~applies] = 4
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


def _rounded(x: np.ndarray) -> np.ndarray:
    """Values to two significant digits (inf, NaN and 0 kept): the map's group keys."""
    return np.array([float(f"{a:.2g}") if np.isfinite(a) else a for a in x])


def _law(results: SweepResults) -> tuple[np.ndarray, np.ndarray]:
    """Exponent n and drag level β·t_end per row (1.5 and 0 where the table has none)."""
    n = _column(results, "exponent")
    g = _column(results, "damping")
    size = len(results)
    return (np.full(size, 1.5) if n is None else n,
            np.zeros(size) if g is None else _rounded(np.nan_to_num(g)))


def _applies(results: SweepResults, model: str) -> np.ndarray:
    """Whether ``model`` applies at each row (column ``<model>_applies``; True if absent)."""
    if f"{model}_applies" not in results:
        return np.ones(len(results), dtype=bool)
    return np.asarray(results[f"{model}_applies"]).astype(bool)


def validity_summary(results: SweepResults) -> list[dict]:
    """Per model, law and amplitude: how many points are within 1 % and 10 % of the chain.

    Rows are grouped by the contact law's exponent (column ``exponent``, 1.5 if absent),
    the drag level (``damping`` = β·t_end, 0 if absent) and the incident strain / δ0
    (column ``incident_strain_over_delta0``; both rounded to two significant digits;
    inf = sonic vacuum).  Each entry has ``model``, ``exponent``, ``damping``,
    ``strain_over_delta0``, ``n`` (points), ``within_1``, ``within_10``, ``beyond_10``,
    ``not_compared`` (a measurement window did not hold, or the model did not complete),
    ``does_not_apply`` (column ``<model>_applies`` false), ``max_error`` and
    ``median_error`` (over the compared points), ``equation`` (the continuum equations
    that ran, column ``continuum_model``: e.g. "eq4"; "" for the theory), ``theories``
    (the theories that answered, column ``theory_model``; "" for the continuum),
    ``reasons`` (why points were not compared: the distinct first clauses of
    ``<model>_note``, or of ``continuum_stopped_by`` for a continuum that did not
    complete) and ``does_not_apply_reasons`` (the distinct reasons, numbers elided).
    """
    amp = _rounded(_amplitude(results))
    expo, damp = _law(results)
    out = []
    for model in VALIDITY_MODELS:
        err = _column(results, f"{model}_error")
        if err is None:
            continue
        codes = _validity_codes(err, _applies(results, model))
        laws = sorted({(float(a), float(b)) for a, b in zip(expo, damp, strict=True)})
        groups = sorted({float(k) for k in amp if not np.isnan(k)}) or [math.nan]
        for n, g in laws:
            for a in groups:
                sel = (expo == n) & (damp == g) & (amp == a if not np.isnan(a)
                                                   else np.isnan(amp))
                if not sel.any():
                    continue
                e = err[sel & (codes <= 2)]
                out.append({
                    "model": model, "exponent": n, "damping": g, "strain_over_delta0": a,
                    "n": int(sel.sum()), "within_1": int((codes[sel] == 0).sum()),
                    "within_10": int((codes[sel] <= 1).sum()),
                    "beyond_10": int((codes[sel] == 2).sum()),
                    "not_compared": int((codes[sel] == 3).sum()),
                    "does_not_apply": int((codes[sel] == 4).sum()),
                    "max_error": float(np.max(e)) if e.size else math.nan,
                    "median_error": float(np.median(e)) if e.size else math.nan,
                    "equation": "/".join(sorted(set(_text(results, "continuum_model",
                                                          sel & (codes <= 2))) - {""}))
                    if model == "continuum" else "",
                    "theories": "/".join(sorted(set(_text(results, "theory_model",
                                                          sel & (codes <= 2))) - {""}))
                    if model == "theory" else "",
                    "reasons": _reasons(results, model, sel & (codes == 3)),
                    "does_not_apply_reasons": _na_reasons(results, model, sel & (codes == 4))})
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


def _na_reasons(results: SweepResults, model: str, sel: np.ndarray) -> str:
    """Distinct reasons why ``model`` does not apply at the selected rows (numbers elided).

    The note's text after "does not apply: ", up to a trailing "; set ..." (how to
    switch the model off), with the values after "= " of the chain's keys replaced by
    "…" (one reason for every drag level or exponent).
    """
    import re

    out = set()
    for note in _text(results, f"{model}_note", sel):
        text = note.removeprefix("does not apply: ").split("; set ")[0]
        out.add(re.sub(r"(\[chain\] \w+) = [^,;)]+", r"\1 = …", text))
    return "; ".join(sorted(out - {""}))


def _positions(amp: np.ndarray) -> tuple[np.ndarray, list[float], list[str], float]:
    """Horizontal positions of amplitudes: log10(strain/δ0), the sonic vacuum on its tick.

    Returns the positions, the tick positions and labels, and the x of the axis break
    (NaN without a sonic vacuum).  The decades span the finite amplitudes (at least one
    decade: a coarse map is not stretched over empty decades); the sonic vacuum (inf)
    has no place on that axis and sits in a column of its own, 1.5 decades right of the
    last, past a break.
    """
    amp = _rounded(amp)  # a measured 9.99e-4 is the map's 1e-3
    finite = amp[np.isfinite(amp) & (amp > 0)]
    lo = math.floor(np.log10(finite.min())) if finite.size else -1
    hi = max(math.ceil(np.log10(finite.max())) if finite.size else 0, lo + 1)
    x_sv = hi + 1.5
    with np.errstate(divide="ignore", invalid="ignore"):
        xs = np.where(np.isinf(amp), x_sv, np.log10(np.where(amp > 0, amp, np.nan)))
    ticks = [float(t) for t in range(lo, hi + 1)]
    labels = [f"$10^{{{t}}}$" if t not in (0, 1) else f"{10 ** t:g}" for t in range(lo, hi + 1)]
    if np.isinf(amp).any():
        ticks.append(x_sv)
        labels.append("sonic\nvacuum")
        return xs, ticks, labels, hi + 0.75
    return xs, ticks, labels, math.nan


def _amplitude_axis(ax, amp: np.ndarray, *, ylabel: bool = True) -> tuple[np.ndarray, float]:
    """Set up ``ax`` for error (%) against strain/δ0; the rows' x positions and the break.

    The break is the x left of the sonic vacuum's column (the axis' right end without
    one).
    """
    xs, ticks, labels, brk = _positions(amp)
    lo, hi = _thresholds()
    ax.set_yscale("log")
    ax.set_xticks(ticks, labels)
    ax.set_xlim(ticks[0] - 0.5, ticks[-1] + 0.5)
    floor = 1e-4
    ax.set_ylim(floor, 100.0)
    ax.axhspan(floor, 100 * lo, color=_SHADES[0][1], alpha=0.10, lw=0)
    ax.axhspan(100 * lo, 100 * hi, color=_SHADES[1][1], alpha=0.16, lw=0)
    for level in (lo, hi):
        ax.axhline(100 * level, color="0.35", lw=0.7, ls=":")
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.yaxis.set_minor_formatter(NullFormatter())
    if math.isfinite(brk):  # the sonic vacuum is no point of the log axis: its own column
        ax.axvspan(brk, ticks[-1] + 0.5, color="0.5", alpha=0.08, lw=0)
        for y in (0.0, 1.0):
            for x in (brk - 0.05, brk + 0.05):
                ax.plot([x - 0.05, x + 0.05], [y - 0.02, y + 0.02], color="k", lw=0.9,
                        transform=ax.get_xaxis_transform(), clip_on=False)
    ax.set_xlabel(r"incident strain / $\delta_0$")
    if ylabel:
        ax.set_ylabel("error against the discrete chain (%)")
    return xs, (brk if math.isfinite(brk) else ticks[-1] + 0.5)


def _interfaces(results: SweepResults, sel: np.ndarray):
    """(α_ρ values, α_kn values) of the selected rows, sorted; None if there are none."""
    ar, ak = _column(results, "alpha_rho"), _column(results, "alpha_kn")
    if ar is None or ak is None or not sel.any():
        return None
    return np.unique(_rounded(ar[sel])), np.unique(_rounded(ak[sel]))


def _interface_style(results: SweepResults, sel: np.ndarray):
    """Colour (by α_ρ) and marker (by α_kn) of each selected row, and the legend handles."""
    ar, ak = _rounded(_column(results, "alpha_rho")), _rounded(_column(results, "alpha_kn"))
    ur, uk = _interfaces(results, sel)
    cmap = __import__("matplotlib").colormaps["plasma"]
    colours = {a: cmap(0.1 + 0.75 * i / max(ur.size - 1, 1)) for i, a in enumerate(ur)}
    markers = {a: _INTERFACE_MARKERS[i % len(_INTERFACE_MARKERS)] for i, a in enumerate(uk)}
    rows = np.flatnonzero(sel)
    style = {int(j): (colours[ar[j]], markers[ak[j]]) for j in rows}
    handles = ([Line2D([], [], ls="", marker="o", color=colours[a], ms=6,
                       label=rf"$\alpha_\rho$ = {a:g}") for a in ur]
               + [Line2D([], [], ls="", marker=markers[a], mfc="none", mec="0.2", ms=6,
                         label=rf"$\alpha_{{k_n}}$ = {a:g}") for a in uk])
    return style, handles


def _regimes(ax, model: str, xs: np.ndarray, names: list[str], right: float) -> None:
    """Name, over the panel, the equation or theory that ran on each side of its switch.

    The switches (dashed lines, drawn where they fall within the finite amplitudes'
    decades) are ``"auto"``'s strain/δ0 thresholds for the continuum (Eq. 4 → Eq. 7,
    :data:`hertzchain.scenario.AUTO_EQ4_MAX_STRAIN`; Eq. 7 → quasi-continuum,
    :data:`hertzchain.scenario.AUTO_QC_MIN_STRAIN`) and
    :data:`theory.strong_interface.STRONG_THRESHOLD` (lattice acoustics → quasi-particle)
    for the theory, and halfway between two neighbouring amplitudes where the recorded
    model changes with no such switch between them (a table whose points named their
    models otherwise).
    The names are those the points recorded (``xs``: their positions, log10 of
    strain/δ0, ``names``: what ran there; ``right``: the x where the finite amplitudes
    end, the sonic vacuum's column beyond it named over that column).
    """
    from theory.strong_interface import STRONG_THRESHOLD

    from .scenario import AUTO_EQ4_MAX_STRAIN, AUTO_QC_MIN_STRAIN

    lo, hi = ax.get_xlim()
    known = ((AUTO_EQ4_MAX_STRAIN, AUTO_QC_MIN_STRAIN) if model == "continuum"
             else (STRONG_THRESHOLD,))
    cuts = [c for c in map(math.log10, known) if lo < c < right - 0.2]  # (not on the break)
    # a change of model between two neighbouring amplitudes with no known switch between
    # them: a line halfway (in log10)
    levels = np.unique(xs[xs < right])
    ran = [{n for n, x in zip(names, xs, strict=True) if x == lev and n} for lev in levels]
    for (a, na), (b, nb) in zip(zip(levels[:-1], ran[:-1], strict=True),
                                zip(levels[1:], ran[1:], strict=True), strict=True):
        if na != nb and not any(a < c <= b for c in cuts):  # (a point on a cut: right of it)
            cuts.append(0.5 * (a + b))
    cuts.sort()
    for c in cuts:
        ax.axvline(c, color="0.45", lw=0.8, ls="--")
    edges = [lo, *cuts, right]
    finite = xs < right
    spans = []  # (label, from x, to x): one label over neighbouring spans of the same names
    for a, b, here in [*((a, b, finite & (xs >= a) & (xs < b) if a > lo else
                          finite & (xs < b)) for a, b in zip(edges[:-1], edges[1:],
                                                             strict=True)),
                       (right, hi, ~finite)]:
        found = " / ".join(sorted({n for n, h in zip(names, here, strict=True) if h and n}))
        if spans and found and spans[-1][0] == found and spans[-1][2] == a:
            spans[-1] = (found, spans[-1][1], b)
        elif found:
            spans.append((found, a, b))
    for text, a, b in spans:
        ax.text(0.5 * (a + b), 1.01, text, transform=ax.get_xaxis_transform(),
                ha="center", va="bottom", fontsize="x-small", color="0.25")


_MODEL_LABELS = {"continuum": "continuum", "theory": "theory"}
_REGIME_COLUMN = {"continuum": "continuum_model", "theory": "theory_model"}


def _regime_name(name: str) -> str:
    """The label of a recorded model name (:data:`continuum.MODELS`; KdV; theories as is)."""
    import continuum

    if name in continuum.MODELS:
        return continuum.MODELS[name].label
    return {"kdv": "KdV"}.get(name, name)


def _median_line(ax, x: np.ndarray, y: np.ndarray, sonic: bool, **style) -> None:
    """A line through (x, y); the sonic vacuum (the last x, if ``sonic``) a bar of its own."""
    last = x.size - 1 if sonic else x.size
    ax.plot(x[:last], y[:last], "-", **style)
    if sonic:
        ax.plot([x[-1] - 0.22, x[-1] + 0.22], [y[-1], y[-1]], "-", **style)


def plot_validity_amplitude(ax, results: SweepResults, *, model: str = "theory",
                            exponent: float = 1.5, damping: float = 0.0,
                            legend: bool = False) -> bool:
    """Error of ``model`` against the incident strain / δ0, one marker per interface.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    results : SweepResults
        A sweep (or reproduce's table) with ``<model>_error`` columns
        (:func:`hertzchain.reproduce.validity.validity_point`).
    model : {"continuum", "theory"}
        Whose error (the largest of |ΔE_T|, |ΔE_R| over the incident energy and the
        relative transmitted front speed), in % on a log axis.
    exponent, damping : float
        The law drawn: contact exponent n and drag level β·t_end (rows of other laws
        are left out).
    legend : bool
        Add the interface legend (colour α_ρ, marker α_kn) right of the axes.

    Notes
    -----
    x: log10 of the strain/δ0, the sonic vacuum on its own labelled tick past a break;
    black line: the median over the interfaces compared; grey ×: not compared (a window
    did not hold); "n/a": the model does not apply there; shaded: within 1 % and 10 %;
    over the panel: the equation or theory that ran (columns ``continuum_model``,
    ``theory_model``).

    Returns
    -------
    bool
        False (and a note on the axes) if the table has no such error or law.
    """
    err = _column(results, f"{model}_error")
    amp = _amplitude(results)
    expo, damp = _law(results)
    sel = (expo == exponent) & (damp == float(f"{damping:.2g}")) & ~np.isnan(amp)
    if err is None or not sel.any() or _interfaces(results, sel) is None:
        ax.text(0.5, 0.5, f"no {model} error for this law", ha="center",
                transform=ax.transAxes)
        return False
    xs_all, right = _amplitude_axis(ax, amp)  # one axis for every law of the table
    xs_all = np.where(sel, xs_all, np.nan)
    xs = xs_all[sel]
    codes = _validity_codes(err, _applies(results, model))
    style, handles = _interface_style(results, sel)
    ur, uk = _interfaces(results, sel)
    spread = 0.12 * (np.arange(ur.size * uk.size) / max(ur.size * uk.size - 1, 1) - 0.5) \
        if ur.size * uk.size > 1 else np.zeros(1)
    ar, ak = _rounded(_column(results, "alpha_rho")), _rounded(_column(results, "alpha_kn"))
    for j in np.flatnonzero(sel & (codes <= 2)):
        dx = spread[int(np.searchsorted(ur, ar[j])) * uk.size + int(np.searchsorted(uk, ak[j]))]
        colour, marker = style[int(j)]
        ax.plot(xs_all[j] + dx, 100 * err[j], marker, color=colour, ms=5.5, mec="k",
                mew=0.3, ls="")
    levels = np.unique(xs)
    med = np.array([np.median(err[sel & (codes <= 2) & (xs_all == x)]) if
                    (sel & (codes <= 2) & (xs_all == x)).any() else np.nan for x in levels])
    _median_line(ax, levels, 100 * med, np.isinf(amp[sel]).any(), color="k", lw=1.1,
                 zorder=1)
    bottom = ax.get_ylim()[0]
    for x in levels:
        here = sel & (xs_all == x)
        if (codes[here] == 3).any():
            ax.plot(x, bottom * 1.6, "x", color=_NOT_COMPARED, ms=6, mew=1.2)
        if (codes[here] == 4).all():
            ax.text(x, bottom * 1.6, _NA_LABEL, ha="center", va="bottom",
                    fontsize="small", color="0.35", style="italic")
    names = [_regime_name(n) for n in
             _text(results, _REGIME_COLUMN[model], sel & (codes <= 2))]
    _regimes(ax, model, xs_all[sel & (codes <= 2)], names, right)
    law = "" if (exponent, damping) == (1.5, 0.0) else \
        f", n = {exponent:g}" + (rf", $\beta t_{{end}}$ = {damping:g}" if damping else "")
    ax.set_title(f"{_MODEL_LABELS[model]}{law}", fontsize="medium", pad=14)
    if legend:
        extra = [Line2D([], [], color="k", lw=1.1, label="median"),
                 Line2D([], [], ls="", marker="x", color=_NOT_COMPARED, mew=1.2,
                        label="not compared")]
        ax.legend(handles=handles + extra, loc="upper left", bbox_to_anchor=(1.02, 1.0),
                  fontsize="x-small", frameon=False)
    return True


def plot_validity_laws(ax, results: SweepResults, *, model: str = "theory",
                       exponent: float = 1.5, legend: bool = True) -> bool:
    """Median and largest error of ``model`` over the interfaces, per drag level, for one n.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    results : SweepResults
        A sweep (or reproduce's table) with ``<model>_error``, ``exponent`` and
        ``damping`` columns.
    model : {"continuum", "theory"}
        Whose error, in % on a log axis against the strain/δ0 (axis as
        :func:`plot_validity_amplitude`).
    exponent : float
        The contact law's n drawn.
    legend : bool
        Add the legend of the drag levels in the axes (where it covers least data;
        :func:`validity_figure` draws it beside the panels instead).

    Notes
    -----
    One colour per drag level β·t_end (black: lossless): line and filled marker the
    median over the interfaces compared, open triangle the largest; "n/a" where the
    model does not apply to any point of that amplitude (and "(n/a)" after a drag level
    where it applies nowhere).

    Returns
    -------
    bool
        False (and a note on the axes) if the table has no such error or exponent.
    """
    err = _column(results, f"{model}_error")
    amp = _amplitude(results)
    expo, damp = _law(results)
    sel = (expo == exponent) & ~np.isnan(amp)
    if err is None or not sel.any():
        ax.text(0.5, 0.5, f"no {model} error for n = {exponent:g}", ha="center",
                transform=ax.transAxes)
        return False
    xs_all = np.where(sel, _amplitude_axis(ax, amp)[0], np.nan)  # every law's axis
    xs = xs_all[sel]
    codes = _validity_codes(err, _applies(results, model))
    levels = np.unique(xs)
    dampings = sorted(set(damp[sel]))
    cmap = __import__("matplotlib").colormaps["viridis"]
    bottom = ax.get_ylim()[0]
    for i, g in enumerate(dampings):
        colour = "k" if g == 0 else cmap(0.15 + 0.7 * (i - (0 in dampings)) /
                                         max(len(dampings) - 1 - (0 in dampings), 1))
        med, top = [], []
        for x in levels:
            e = err[sel & (damp == g) & (xs_all == x) & (codes <= 2)]
            med.append(np.median(e) if e.size else np.nan)
            top.append(np.max(e) if e.size else np.nan)
        label = "lossless" if g == 0 else rf"$\beta t_{{end}}$ = {g:g}"
        if (codes[sel & (damp == g)] == 4).all():
            label += f" ({_NA_LABEL})"
        _median_line(ax, levels, 100 * np.asarray(med), np.isinf(amp[sel]).any(),
                     color=colour, lw=1.1)
        ax.plot(levels, 100 * np.asarray(med), "o", color=colour, ms=4, label=label)
        ax.plot(levels, 100 * np.asarray(top), "^", color=colour, mfc="none", ms=5)
    for x in levels:
        here = sel & (xs_all == x)
        if (codes[here] == 4).all():
            ax.text(x, bottom * 1.6, _NA_LABEL, ha="center", va="bottom",
                    fontsize="small", color="0.35", style="italic")
        elif (codes[here] == 3).any():
            ax.plot(x, bottom * 1.6, "x", color=_NOT_COMPARED, ms=6, mew=1.2)
    ax.set_title(f"{_MODEL_LABELS[model]}, n = {exponent:g}", fontsize="medium")
    if legend:
        ax.legend(handles=ax.get_legend_handles_labels()[0] + _LAWS_EXTRA(),
                  fontsize="x-small", loc="best", frameon=False)
    return True


def _LAWS_EXTRA() -> list:  # noqa: N802 - a constant's factory (new artists each call)
    """Legend entries of :func:`plot_validity_laws` besides the drag levels."""
    return [Line2D([], [], ls="-", marker="o", color="0.3", ms=4,
                   label="median over the interfaces"),
            Line2D([], [], ls="", marker="^", mfc="none", color="0.3", label="largest")]


def _laws_legend(axes_by_model: dict) -> list:
    """One legend for a row of :func:`plot_validity_laws` panels (one per model).

    A drag level's entry once, with "(n/a: <model>)" for each model that does not apply
    at any of its points (the panels' labels end in "(n/a)" there).
    """
    entries: dict[str, tuple] = {}
    for model, ax in axes_by_model.items():
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            base = lab.removesuffix(f" ({_NA_LABEL})")
            handle, na = entries.get(base, (h, []))
            entries[base] = (handle, na + ([model] if base != lab else []))
    out = []
    for base, (h, na) in entries.items():
        out.append(Line2D([], [], ls="-", marker="o", ms=4, color=h.get_color(),
                          label=base + (f" ({_NA_LABEL}: {', '.join(na)})" if na else "")))
    return out + _LAWS_EXTRA()


def validity_figure(results: SweepResults) -> Figure:
    """The validity map: each model's error against strain/δ0, per interface and per law.

    Top row, one panel per model (continuum, theory): :func:`plot_validity_amplitude`
    for the lossless Hertz chain (the table's first law if it has none), the interface
    legend on the right.  If the table has other laws (exponents, drag levels), one
    more row per exponent: :func:`plot_validity_laws` for each model.
    """
    expo, damp = _law(results)
    laws = sorted({(float(a), float(b)) for a, b in zip(expo, damp, strict=True)})
    main = (1.5, 0.0) if (1.5, 0.0) in laws else (laws[0] if laws else (1.5, 0.0))
    exponents = sorted({n for n, _ in laws}) if len(laws) > 1 else []
    models = [m for m in VALIDITY_MODELS if f"{m}_error" in results] or list(VALIDITY_MODELS)
    rows = 1 + len(exponents)
    fig = Figure(figsize=(max(4.3 * len(models) + 1.9, 10.5), 3.7 * rows + 0.5),
                 layout="constrained")
    grid = fig.add_gridspec(rows, len(models) + 1, width_ratios=[1.0] * len(models) + [0.42])
    handles = []
    law_axes: dict[int, dict] = {row: {} for row in range(1, rows)}
    for col, model in enumerate(models):
        ax = fig.add_subplot(grid[0, col])
        plot_validity_amplitude(ax, results, model=model, exponent=main[0], damping=main[1])
        if col:
            ax.set_ylabel("")
        for row, n in enumerate(exponents, start=1):
            lax = fig.add_subplot(grid[row, col], sharey=ax)
            plot_validity_laws(lax, results, model=model, exponent=n, legend=False)
            law_axes[row][model] = lax
            if col:
                lax.set_ylabel("")
            if row < rows - 1:
                lax.set_xlabel("")
        if rows > 1:
            ax.set_xlabel("")
    for row, by_model in law_axes.items():  # each row's drag levels beside it
        side = fig.add_subplot(grid[row, len(models)])
        side.axis("off")
        side.legend(handles=_laws_legend(by_model), loc="upper left", fontsize="x-small",
                    frameon=False, title=r"drag level $\beta t_{end}$",
                    title_fontsize="x-small")
    expo_ok = (expo == main[0]) & (damp == main[1])
    if _interfaces(results, expo_ok) is not None:
        handles = _interface_style(results, expo_ok)[1]
    lax = fig.add_subplot(grid[0, len(models)])
    lax.axis("off")
    lo, hi = _thresholds()
    lax.legend(handles=handles + [
        Line2D([], [], color="k", lw=1.1, label="median"),
        Line2D([], [], ls="", marker="x", color=_NOT_COMPARED, mew=1.2, label="not compared"),
        Patch(facecolor=_SHADES[0][1], alpha=0.25, label=f"within {100 * lo:.0f} %"),
        Patch(facecolor=_SHADES[1][1], alpha=0.35, label=f"within {100 * hi:.0f} %")],
        loc="upper left", fontsize="x-small", frameon=False, title="interface",
        title_fontsize="x-small")
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
