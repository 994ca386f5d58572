r"""Fig. 7: the phase diagram in (α_ρ, α_kn), simulated points classified from the data.

Paper Section 4, Fig. 7 (δ0^L/d = 1e-3): the lines γ_c0 = 1 (α_kn = α_ρ^{3/2}, Eq. 9)
and γ_RG = 1 (α_kn = α_ρ^{-3/2}, Eq. 13) divide the plane into regions I (fracture,
expansive reflection), II (fracture, compressive), III (squeeze, compressive) and IV
(squeeze, expansive).  Every point is one run of the scenario runner; its summary
classifies the transmitted wave (fracture/squeeze, :func:`discrete.diagnostics.
classify_transmitted`) and the reflected wave (compressive/expansive/none) at the end of
the run, and :func:`hertzchain.sweep.classification_agreement` compares the labels
with the theory.

Points: a log-spaced ``grid`` × ``grid`` over ``lim`` (an even count keeps every grid
point off both lines) plus the paper's named points a–d, M, N, P, Q.  They are computed
by :func:`compute_points`, with a plain loop (``backend="loop"``, one small HDF5
file of scenario and summary per point; both modes) or on Dask through
:func:`hertzchain.sweep.run_sweep` (``backend="sweep"``, resumable results table; the
same labels, ``tests/hertzchain/test_reproduce.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

import theory

from .common import Context, log_ticks, new_figure, run_scenario_cached, save_figure, tqdm_iter

__all__ = ["QUICK", "FULL", "BASE", "Fig7Result", "points", "scenario", "compute_points",
           "run", "plot_phase_diagram", "reflected_counts", "paper_statements", "figures",
           "report", "to_json"]

QUICK = {"grid": 10, "lim": (0.2, 5.0), "backend": "loop"}
"""Both modes run the points in this process (``backend="loop"``); :func:`run` takes
``backend="sweep"`` and its ``workers`` (Dask processes, default 2) as overrides."""
FULL = {"grid": 20, "lim": (0.2, 5.0), "backend": "loop",
        "run": {"integrator": "blanes_moan4", "dt_fraction": 0.048},
        "record": {"energy_every": 16}}
"""--full: the 408 points in this process (``backend="loop"``) with Blanes–Moan 4 at
0.048·2π/ω_max (``run``: keys of every point's ``[run]``; 24× velocity Verlet's default
dt, 1/4 of its force evaluations; the chains are precompressed, no gaps, the method keeps
its order).  The 408 labels are those of velocity Verlet at the default dt, every one
(also at 0.096; ``benchmarks/full_dt.py --fig7``), at half its cost.  The points run in
this process because a local Dask cluster (``backend="sweep"``) adds worker start-up,
imports, kernel loading and scheduling, and in a two-lane ``--full`` its workers compete
with Fig. 5's lane for the cores: in-process the item costs about half
(``benchmarks/full_items.py fig7``; numbers in docs/benchmarks.md).

``record``: keys of every point's ``[record]``: an energy-grid row every 16 steps (a few
incident transits d/V) instead of the runner's automatic spacing (rows every 1/(r_max+1)
transit, :func:`hertzchain.runner.split_row_spacing`, here every 1-2 steps).  Fig. 7
reads only the labels, classified on the final state; the grid decides only whether the
waves have separated (the summary's rule; the phase-averaged split its dense rows are
for is Table 2's, not printed here, and is aliased on these rows).  Recording the dense
grid is most of a point's integration (a point at α = (0.5, 2) costs twice as much with
it as with a row every 8 steps, three times as much as without a grid).  The 408 labels
are those of the automatic grid, every one, at 8, 16 and 32 steps per row (item timings
in docs/benchmarks.md)."""
BASE = {
    "chain": {"delta0_over_d": 1e-3, "material": "paper",
              "sections": [{"n": 500}, {"n": 1400, "alpha_rho": 1.0, "alpha_kn": 1.0}]},
    "initial": {"kind": "cut_wave", "v0": 1.0, "center": 400},
    "run": {"t_end": 2.0e-3},
}
"""The base scenario of every point (as ``hertzchain/sweeps/fig7_map.toml``): the wave
starts 100 grains before the interface; at 2 ms the reflected wave is clear of it and
nothing has reached a wall."""
CLASS_COLOURS = {("fracture", "expansive"): ("I", "#E69F00"),
                 ("fracture", "compressive"): ("II", "#D55E00"),
                 ("squeeze", "compressive"): ("III", "#0072B2"),
                 ("squeeze", "expansive"): ("IV", "#56B4E9")}
OTHER_COLOUR = "#F0E442"


def points(grid: int, lim=(0.2, 5.0)) -> list[tuple[str, float, float]]:
    """(label, α_ρ, α_kn) of the grid and the paper's named points."""
    a = np.geomspace(lim[0], lim[1], grid)
    out = [("", float(x), float(y)) for x in a for y in a]
    out += [(name, *map(float, theory.PAPER_POINTS[name])) for name in "abcdMNPQ"]
    return out


def scenario(alpha_rho: float, alpha_kn: float, run: dict | None = None,
             record: dict | None = None) -> dict:
    """The scenario dict of one point (``run``/``record``: keys added, e.g. FULL's)."""
    sc = {k: (dict(v) if isinstance(v, dict) else v) for k, v in BASE.items()}
    sc["run"] = {**BASE["run"], **(run or {})}
    if record:
        sc["record"] = dict(record)
    sc["chain"] = dict(BASE["chain"])
    sc["chain"]["sections"] = [dict(BASE["chain"]["sections"][0]),
                               {"n": BASE["chain"]["sections"][1]["n"],
                                "alpha_rho": alpha_rho, "alpha_kn": alpha_kn}]
    sc["name"] = f"fig7-{alpha_rho:.6g}-{alpha_kn:.6g}"
    return sc


def compute_points(ctx: Context, pts, *, backend: str = "loop", workers: int = 2,
                   run: dict | None = None, record: dict | None = None) -> list[dict]:
    """Runner summaries of the points (same order); ``run``, ``record``: :func:`scenario`'s.

    ``backend="loop"`` runs them one after the other in this process (cached per point);
    ``"sweep"`` hands them to :func:`hertzchain.sweep.run_sweep` (a ``zip`` sweep on a
    local Dask cluster of ``workers`` processes, results in ``out/fig7-sweep``).
    """
    if backend == "loop":
        out = []
        for _, ar, ak in tqdm_iter(ctx, pts, desc="fig7 points", total=len(pts)):
            summary, _ = run_scenario_cached(ctx, "fig7", scenario(ar, ak, run, record),
                                             full=False)
            out.append(summary)
        return out
    if backend != "sweep":
        raise ValueError(f"backend must be 'loop' or 'sweep' (got {backend!r})")
    from ..sweep import read_results, run_sweep

    spec = {"name": f"fig7-{ctx.mode}", "base": scenario(1.0, 1.0, run, record),
            "sweep": {"mode": "zip", "axes": [
                {"path": "chain.sections.1.alpha_rho", "name": "alpha_rho_R",
                 "values": [p[1] for p in pts]},
                {"path": "chain.sections.1.alpha_kn", "name": "alpha_kn_R",
                 "values": [p[2] for p in pts]}]}}
    spec["base"]["name"] = "fig7-point"
    outcome = run_sweep(spec, out=ctx.out / f"fig7-sweep-{ctx.mode}", workers=workers,
                        progress=ctx.progress, retry_failed=ctx.force)
    ctx.notes["fig7"] = (f"Fig. 7 sweep ({outcome.directory}): {outcome.n_run} points run on "
                         f"Dask, {outcome.n_skipped} reused, {outcome.n_failed} failed")
    res = read_results(outcome.table)
    cols = res.columns
    return [{k: (cols[k][i] if k in cols else None) for k in
             ("transmitted", "reflected", "n_transmitted_pulses", "Ek_tr", "Ek_re", "status")}
            for i in range(len(res))]


@dataclass
class Fig7Result:
    """Classified points and their agreement with the theory."""

    labels: list[str]
    alpha_rho: np.ndarray
    alpha_kn: np.ndarray
    transmitted: list[str]
    reflected: list[str]
    agreement: object
    lim: tuple
    extra: dict = field(default_factory=dict)

    @property
    def gamma_c0(self) -> np.ndarray:
        """γ_c0 of every point (Eq. 9)."""
        return np.asarray(theory.gamma_c0(self.alpha_rho, self.alpha_kn))

    @property
    def gamma_rg(self) -> np.ndarray:
        """γ_RG of every point (Eq. 13)."""
        return np.asarray(theory.gamma_rg(self.alpha_rho, self.alpha_kn))


def run(ctx: Context, **overrides) -> Fig7Result:
    """Classify the grid and the named points; compare with the theory.

    ``overrides``: keys of :data:`QUICK` / :data:`FULL`, and ``workers`` (the Dask
    processes of ``backend="sweep"``, :func:`compute_points`).
    """
    from ..sweep.analysis import classification_agreement
    from ..sweep.store import SweepResults

    s = ctx.pick(QUICK, FULL) | overrides
    pts = points(s["grid"], s["lim"])
    ctx.log(f"fig7: {len(pts)} points ({s['grid']}×{s['grid']} grid + a–d, M, N, P, Q), "
            f"backend {s['backend']}")
    summ = compute_points(ctx, pts, backend=s["backend"],
                          **{k: s[k] for k in ("workers", "run", "record") if k in s})
    ar = np.array([p[1] for p in pts])
    ak = np.array([p[2] for p in pts])
    tr = [str(x["transmitted"]) for x in summ]
    re = [str(x["reflected"]) for x in summ]
    status = np.array(["ok" if x.get("status", "ok") in ("ok", None) else str(x["status"])
                       for x in summ], dtype=object)
    table = SweepResults(columns={"id": np.array([f"p{i}" for i in range(len(pts))], dtype=object),
                                  "status": status, "alpha_rho": ar, "alpha_kn": ak,
                                  "transmitted": np.array(tr, dtype=object),
                                  "reflected": np.array(re, dtype=object)})
    agree = classification_agreement(table)
    return Fig7Result([p[0] for p in pts], ar, ak, tr, re, agree, tuple(s["lim"]),
                      {"n_grid": s["grid"], "backend": s["backend"]})


def _colour(tr: str, re: str) -> str:
    return CLASS_COLOURS.get((tr, re), ("", OTHER_COLOUR))[1]


def plot_phase_diagram(ax, res: Fig7Result) -> None:
    """Fig. 7: theory lines and regions, points coloured by their measured class.

    A red ring marks a point whose measured class differs from the theory's (points on
    a line are compared for the other label only); letters mark the paper's points.
    """
    from ..plotting import plot_theory_lines

    plot_theory_lines(ax, lim=res.lim)
    bad = {(d["alpha_rho"], d["alpha_kn"]) for d in res.agreement.disagreeing}
    for lab, x, y, tr, re in zip(res.labels, res.alpha_rho, res.alpha_kn, res.transmitted,
                                 res.reflected, strict=True):
        named = bool(lab)
        ax.plot(x, y, "D" if named else "o", ms=8 if named else 7, color=_colour(tr, re),
                mec="k", mew=0.5, zorder=3)
        if (x, y) in bad:
            ax.plot(x, y, "o", ms=13, mfc="none", mec="r", mew=1.5, zorder=4)
        if named:
            # off the line through the point: γ_c0 = 1 rises to the right (its points are
            # named below right), γ_RG = 1 falls (above right)
            rising = math.isclose(float(theory.gamma_c0(x, y)), 1.0, rel_tol=1e-6)
            ax.annotate(lab, (x, y), xytext=(7, -5) if rising else (5, 4),
                        textcoords="offset points", va="top" if rising else "baseline",
                        fontsize="medium", weight="bold", zorder=5)
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], ls="", marker="o", color=c, mec="k", mew=0.5,
                      label=f"{name}: {t} + {r}") for (t, r), (name, c) in CLASS_COLOURS.items()]
    handles.append(Line2D([], [], ls="", marker="o", color=OTHER_COLOUR, mec="k", mew=0.5,
                          label="no reflection detected"))
    handles.append(Line2D([], [], ls="", marker="o", mfc="none", mec="r", mew=1.5, ms=10,
                          label="differs from theory"))
    handles += ax.get_legend_handles_labels()[0][:2]
    ax.legend(handles=handles, fontsize="small", loc="upper left", bbox_to_anchor=(1.02, 1.0),
              borderaxespad=0.0)
    pad = 1.15
    ax.set_xlim(res.lim[0] / pad, res.lim[1] * pad)
    ax.set_ylim(res.lim[0] / pad, res.lim[1] * pad)
    ticks = [t for t in (0.2, 0.5, 1, 2, 5) if res.lim[0] <= t <= res.lim[1]]
    log_ticks(ax, "x", ticks)
    log_ticks(ax, "y", ticks)
    ax.set_title(r"measured classes, $\delta_0^L/d = 10^{-3}$", fontsize="medium")


def figures(ctx: Context, res: Fig7Result) -> list:
    """Save ``fig7.png``."""
    fig, axes = new_figure(1, 1, figsize=(9.0, 6.0))
    plot_phase_diagram(axes[0, 0], res)
    path = save_figure(ctx, fig, "fig7")
    return [(path, "Fig. 7: phase diagram; solid line γ_c0 = 1, dashed γ_RG = 1 (theory); "
             "points coloured by the class measured in the simulation (diamonds: the "
             "paper's a–d, M, N, P, Q).")]


def reflected_counts(res: Fig7Result, side: int = 1) -> dict[str, int]:
    """Reflected labels of the points off the lines with γ_RG > 1 (``side=1``) or < 1."""
    gc, gr = res.gamma_c0, res.gamma_rg
    off = (np.abs(np.log(gc)) > 1e-9) & (np.abs(np.log(gr)) > 1e-9)
    m = off & ((gr > 1) if side > 0 else (gr < 1))
    re = np.array(res.reflected)[m]
    return {"points": int(m.sum()), **{k: int(np.sum(re == k))
                                       for k in ("compressive", "expansive", "none")}}


def paper_statements(res: Fig7Result) -> list[str]:
    """The paper's statements about Fig. 7, checked on the classified points."""
    gc = res.gamma_c0
    tr = np.array(res.transmitted)
    off = (np.abs(np.log(gc)) > 1e-9) & (np.abs(np.log(res.gamma_rg)) > 1e-9)
    out = []
    c = reflected_counts(res, 1)
    out.append(f"Section 4: \"when γ_RG > 1, i.e. (II) and (III) regions … the RSWs are "
               f"expansive waves\": of {c['points']} points with γ_RG > 1, "
               f"{c['compressive']} reflect a compressive wave, {c['expansive']} an expansive "
               f"one ({c['none']} below the detection threshold) — the text contradicts the "
               f"data (and the paper's own Section 3.2 and Fig. 5b, d).")
    c = reflected_counts(res, -1)
    out.append(f"γ_RG < 1 (regions I, IV): {c['expansive']} of {c['points']} points reflect "
               f"an expansive wave, {c['compressive']} a compressive one (paper: expansive, "
               f"overshoot).")
    m = (gc > 1) & off
    nf = int(np.sum(tr[m] == "fracture"))
    both = m & ~((res.alpha_rho < 1) & (res.alpha_kn > 1))
    out.append(f"γ_c0 > 1 (regions I, II): {nf} of {m.sum()} points fracture.  The "
               f"conclusions' \"γ_c0 > 1, i.e. α_ρ < 1 and α_kn > 1\" is not an "
               f"equivalence: {both.sum()} of these points have α_ρ ≥ 1 or α_kn ≤ 1 "
               f"({np.sum(tr[both] == 'fracture')} of them fracture).")
    m = (gc < 1) & off
    out.append(f"γ_c0 < 1 (regions III, IV): {np.sum(tr[m] == 'squeeze')} of {m.sum()} "
               f"points are squeezed.")
    return out


def _sides(d: dict) -> str:
    return "; ".join(f"{k}: {v:.3g}" if isinstance(v, float) else f"{k}: {v}"
                     for k, v in d.items())


def report(rep, res: Fig7Result, figs: list) -> None:
    """Add the Fig. 7 section."""
    rep.heading("Fig. 7 — phase diagram")
    a = res.agreement
    rep.paragraph(
        f"{len(res.labels)} points ({res.extra['n_grid']}×{res.extra['n_grid']} grid over "
        f"[{res.lim[0]:g}, {res.lim[1]:g}]² plus the named points), backend "
        f"{res.extra['backend']}.  Agreement with the theory (points off the lines): "
        f"{a.fraction_agree:.1%} of the points have both labels right (transmitted "
        f"{a.fraction_agree_transmitted:.1%}, reflected {a.fraction_agree_reflected:.1%}); "
        f"disagreement band around γ_c0 = 1: |ln γ_c0| ≤ {a.band_gamma_c0:.3g}, around "
        f"γ_RG = 1: |ln γ_RG| ≤ {a.band_gamma_rg:.3g} (the band around γ_c0 = 1 on each "
        f"side of γ_RG = 1: {_sides(a.band_gamma_c0_by_side)}).  Measured labels of the "
        f"points on the lines: {_sides(a.on_line_labels)}."
        + (f"  The transmitted labels agree better ({a.fraction_agree_fission:.1%}) with "
           f"the fission criterion q = γ_c0 √(2γ_RG/(1 + γ_RG)) > 1 "
           f"(theory.fission_parameter; the transmitted amplitude also matters, not γ_c0 "
           f"alone): the disagreements cluster on the γ_RG < 1 side of γ_c0 = 1."
           if getattr(a, "fraction_agree_fission", None) is not None else ""))
    rows = []
    for lab, x, y, tr, re, gc, gr in zip(res.labels, res.alpha_rho, res.alpha_kn,
                                         res.transmitted, res.reflected, res.gamma_c0,
                                         res.gamma_rg, strict=True):
        if lab:
            pred = theory.predict(x, y)
            rows.append([lab, x, y, gc, gr, pred.region, tr, re])
    rep.table(["point", "α_ρ", "α_kn", "γ_c0", "γ_RG", "theory region", "TSW measured",
               "RSW measured"], rows, caption="The paper's named points")
    if a.disagreeing:
        rep.table(["α_ρ", "α_kn", "measured", "theory"],
                  [[d["alpha_rho"], d["alpha_kn"],
                    f"{d.get('transmitted')} / {d.get('reflected')}",
                    f"{d.get('predicted_transmitted')} / {d.get('predicted_reflected')}"]
                   for d in a.disagreeing], caption="Grid points that differ from the theory")
    rep.bullets(paper_statements(res))
    for path, caption in figs:
        rep.figure(path, caption)


def to_json(res: Fig7Result) -> dict:
    """Points with labels and the agreement numbers."""
    a = res.agreement
    return {"points": [{"label": lab, "alpha_rho": float(x), "alpha_kn": float(y),
                        "transmitted": t, "reflected": r}
                       for lab, x, y, t, r in zip(res.labels, res.alpha_rho, res.alpha_kn,
                                                  res.transmitted, res.reflected, strict=True)],
            "fraction_agree": a.fraction_agree,
            "fraction_agree_transmitted": a.fraction_agree_transmitted,
            "fraction_agree_reflected": a.fraction_agree_reflected,
            "band_gamma_c0": a.band_gamma_c0, "band_gamma_rg": a.band_gamma_rg}
