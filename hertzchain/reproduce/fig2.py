r"""Fig. 2: the impact pulse in a monodisperse chain and its settled amplitude v̄max/v0.

Paper Section 2: the left-most grain gets v0 = 1 m/s, the others are at rest; a
leading solitary wave forms, followed by a tail of solitary waves (δ0 = 0) or of
decaying oscillations (δ0/d = 1e-3).  The per-grain maximum velocity v_max settles to
v̄max/v0 = 0.6816 (δ0 = 0) and 0.0822 (δ0/d = 1e-3).  At δ0/d = 1e-3 the wave settles
only after ~6,000–9,000 grains (docs/physics.md §1), so the chain is 10,000 grains long in
``--quick`` and 20,000 in ``--full``; the averaging range is chosen by
:func:`discrete.diagnostics.vmax_plateau` (every v_max from there on within
``RTOL`` of the settled value, ``MARGIN`` grains kept clear of the wave's position at
the end of the run).

The k_n convention (docs/physics.md §1): the paper's printed k_n = 2E√d/(3(1-ν²)) with
Table 1's ν = 0.25 gives v̄max/v0 ≈ 0.041 at δ0/d = 1e-3, not 0.0822; the Hertz
constant of two spheres with ν = 0.25 gives ≈ 0.0846 and with ν = 0.30 the paper's
0.0822 (only k_n/m matters).  Both alternatives are run as variants.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

import theory
from discrete import diagnostics as D

from ..paper import VMAX_OVER_V0
from ..plotting import plot_grain_profile
from .common import V0, Context, new_figure, paper_scenario, run_models, save_figure

__all__ = ["QUICK", "FULL", "VARIANTS", "Fig2Result", "scenario", "run", "plot_panel",
           "figures", "report", "to_json"]

QUICK = {"n_grains": {0.0: 400, 1e-3: 10_000},
         "variants": ("printed_nu025", "hertz_nu025")}
FULL = {"n_grains": {0.0: 2_000, 1e-3: 20_000},
        "variants": ("printed_nu025", "hertz_nu025"), "rtol": 1e-5}
"""``rtol``: the precompressed runs (δ0/d = 1e-3: no gaps, so the 4th-order methods keep
their order) are run at that stated accuracy (``[run] rtol``, ``integrator = "auto"``,
:mod:`discrete.timestep`) and read the refined maxima (``record.vmax_refined``, between
the steps) instead of velocity Verlet's samples at the default dt.  The step chosen is
Blanes–Moan 4 at dt ≈ 6e-7 s, 13.6× the default's 4.4e-8 s, which about halves the
runs' cost, and v̄max/v0 is within 1.6e-7 (relative) of a converged reference
(rtol = 1e-7, refined maxima), where the default dt's sampled maxima are 1.1e-4 high
for the paper's k_n and 1.5e-4 for the printed one (Verlet's O(dt²) error,
:mod:`discrete.timestep`; ``benchmarks/full_dt.py --fig2``, timings in
docs/benchmarks.md).  δ0 = 0 (gaps: the 4th-order methods lose their order) keeps the
default dt (2,000 grains, ~1 s)."""
RTOL = 1e-4
"""Plateau criterion: every v_max from the start of the range on within this (relative)
of the settled value."""
MARGIN = 60
"""Grains left out at the wave's end position (still being overtaken)."""
STOP_BEFORE_END = 50
"""The run stops when the leading wave's peak passes grain N - this."""

_T1 = theory.STEEL_TABLE1
VARIANTS = {
    "hertz_nu030": ("Hertz k_n, ν = 0.30 (theory.PAPER_MATERIAL; reproduces the paper)",
                    "paper"),
    "printed_nu025": ("printed k_n = 2E√d/(3(1-ν²)), ν = 0.25 (paper Sec. 2, Table 1)",
                      {"density": _T1.density, "youngs_modulus": 2.0 * _T1.youngs_modulus,
                       "poisson_ratio": _T1.poisson_ratio}),
    "hertz_nu025": ("Hertz k_n, ν = 0.25 (Table 1)", "table1"),
}
"""k_n conventions run at δ0/d = 1e-3 (the paper's own is ``hertz_nu030``), as the
scenario's ``[chain] material``: the printed k_n is the Hertz constant of a material with
twice Table 1's Young's modulus (the same density: only k_n/m matters)."""


@dataclass
class Fig2Result:
    """Fig. 2 numbers and the arrays behind the panels.

    ``plateaus`` and ``profiles`` are keyed by δ0/d (the paper's k_n), ``variants`` by
    the :data:`VARIANTS` name (δ0/d = 1e-3).
    """

    plateaus: dict[float, D.PlateauStats]
    profiles: dict[float, dict[str, np.ndarray]]
    variants: dict[str, D.PlateauStats] = field(default_factory=dict)
    files: list = field(default_factory=list)

    @property
    def vmax_over_v0(self) -> dict[float, float]:
        """v̄max/v0 per δ0/d."""
        return {k: p.mean for k, p in self.plateaus.items()}


def scenario(delta0_over_d: float, n: int, variant: str = "hertz_nu030",
             rtol: float | None = None):
    """The impact of Fig. 2: ``paper/fig2a.toml`` (δ0 = 0) or ``fig2b.toml``, sized.

    ``n`` grains, stopped when the leading wave's peak passes grain n −
    :data:`STOP_BEFORE_END`; ``variant`` (:data:`VARIANTS`) sets ``[chain] material``;
    ``rtol`` (precompressed chains only, see :data:`FULL`) sets ``[run] rtol`` with
    ``integrator = "auto"`` (default None: the default dt).
    """
    values = {"chain.delta0_over_d": float(delta0_over_d), "chain.sections.0.n": int(n),
              "run.until_front_at": int(n) - STOP_BEFORE_END}
    if variant != "hertz_nu030":
        values["chain.material"] = VARIANTS[variant][1]
    if rtol is not None and delta0_over_d > 0:
        values |= {"run.rtol": float(rtol), "run.integrator": "auto"}
    return paper_scenario("fig2a" if delta0_over_d == 0 else "fig2b", values)


def _impact_run(ctx: Context, delta0_over_d: float, n: int, variant: str,
                rtol: float | None):
    """The run and its file; the per-grain maxima v_max (m/s) it reads.

    v_max: the refined maxima (``record.vmax_refined``, interpolated between the steps at
    the method's order) where the run records them (an ``rtol`` run), else the largest
    sample (``record.vmax``, O(dt²)).
    """
    sc = scenario(delta0_over_d, n, variant, rtol)
    r = run_models(ctx, "fig2", sc)
    rec = r.simulation.record
    if sc.run.rtol is not None and rec.vmax_refined is None:
        # (a file of an older version: its sampled maxima are O(dt²) at the rtol step,
        # ~1e-4 low at 13× velocity Verlet's dt — never read them instead)
        raise ValueError(f"{r.discrete.path}: the rtol = {sc.run.rtol:g} run has no refined maxima "
                         "(record/vmax_refined); rerun with --force")
    vmax = rec.vmax_refined if rec.vmax_refined is not None else rec.vmax
    return r.simulation, r.discrete.path, np.asarray(vmax)


def _plateau(vmax: np.ndarray) -> D.PlateauStats:
    return D.vmax_plateau(vmax, V0, rtol=RTOL, margin=MARGIN)


def run(ctx: Context, n_grains: dict | None = None, variants=None) -> Fig2Result:
    """Run the impacts of Fig. 2 (and the k_n variants) and measure v̄max/v0.

    Parameters
    ----------
    ctx : Context
    n_grains : dict, optional
        Chain length per δ0/d (default: the mode's).
    variants : sequence of str, optional
        Names of :data:`VARIANTS` to run at δ0/d = 1e-3 besides the paper's k_n.
    """
    s = ctx.pick(QUICK, FULL)
    n_grains = s["n_grains"] if n_grains is None else n_grains
    variants = s["variants"] if variants is None else variants
    plateaus, profiles, files = {}, {}, []
    for d0, n in n_grains.items():
        ctx.log(f"fig2: impact on {n} grains, δ0/d = {d0:g}")
        sim, path, vmax = _impact_run(ctx, float(d0), int(n), "hertz_nu030", s.get("rtol"))
        plateaus[float(d0)] = _plateau(vmax)
        profiles[float(d0)] = {"v": sim.v / V0, "vmax": vmax / V0, "t": sim.t}
        files.append(path)
    out = {}
    n_pre = int(n_grains.get(1e-3, max(n_grains.values())))
    for name in variants:
        ctx.log(f"fig2: k_n variant {name} ({n_pre} grains, δ0/d = 1e-3)")
        sim, path, vmax = _impact_run(ctx, 1e-3, n_pre, name, s.get("rtol"))
        out[name] = _plateau(vmax)
        files.append(path)
    return Fig2Result(plateaus, profiles, out, files)


def plot_panel(ax, result: Fig2Result, delta0_over_d: float, *, every: int | None = None,
               zoom: int = 200):
    """One panel of Fig. 2: v_i/v0 at the end of the run, v_max/v0 and its mean.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    result : Fig2Result
    delta0_over_d : float
        Which chain (0 or 1e-3).
    every : int, optional
        Plot every ``every``-th v_max square (default: ~300 squares).
    zoom : int
        Grains behind the leading wave repeated in an inset for long chains (0: none).
    """
    prof = result.profiles[delta0_over_d]
    p = result.plateaus[delta0_over_d]
    n = prof["v"].size
    every = max(1, n // 300) if every is None else every
    plot_grain_profile(ax, prof["v"], ylabel=r"$v_i/v_0$", color="C0", numbering="paper",
                       label=rf"$v_i/v_0$ at $t$ = {prof['t'] * 1e3:.3g} ms")
    g = np.arange(0, n, every)
    ax.plot(g + 1, prof["vmax"][g], "s", ms=2.5, mfc="none", color="C3",
            label=r"$v_{max}/v_0$ per grain")
    ax.hlines(p.mean, p.start + 1, p.stop, colors="k", linestyles="--", zorder=3,
              label=rf"$\bar v_{{max}}/v_0$ = {p.mean:.4f} (grains {p.start + 1}–{p.stop})")
    paper = VMAX_OVER_V0.get(delta0_over_d)
    top = 1.6 * paper if paper else 1.0
    ax.set_ylim(min(-0.1 * top, float(prof["v"].min()) * 1.1), top)
    ax.set_xlim(0, n + 1)
    title = r"$\delta_0 = 0$" if delta0_over_d == 0 else rf"$\delta_0/d = {delta0_over_d:g}$"
    ax.set_title(f"({'a' if delta0_over_d == 0 else 'b'}) {title}")
    ax.legend(fontsize="x-small", loc="upper right")
    if zoom and n > 4 * zoom:
        # inset: the leading wave and the start of its tail at the end of the run
        front = int(np.argmax(prof["v"]))
        g = np.arange(max(0, front - zoom), min(n, front + 15))
        # (between the velocities and the v_max plateau: neither is covered)
        lo_v, hi_v = ax.get_ylim()
        y0 = (max(float(prof["v"].max(initial=0.0, where=np.arange(n) < g[0])), 0.0)
              - lo_v) / (hi_v - lo_v) + 0.04
        y1 = (p.mean - lo_v) / (hi_v - lo_v) - 0.08
        ins = ax.inset_axes([0.3, y0, 0.45, max(y1 - y0, 0.15)])
        ins.plot(g + 1, prof["v"][g], lw=0.8, color="C0")
        ins.axhline(0, color="0.7", lw=0.4)
        ins.set_xlim(g[0] + 1, g[-1] + 1)
        ins.tick_params(labelsize="x-small")
        ins.text(0.02, 0.95, f"grains {g[0] + 1}–{g[-1] + 1}", transform=ins.transAxes,
                 ha="left", va="top", fontsize="x-small")
        ymin, ymax = ins.get_ylim()
        ins.set_ylim(ymin, ymax + 0.25 * (ymax - ymin))  # room for the text


def figures(ctx: Context, result: Fig2Result) -> list:
    """Save ``fig2.png`` (panels a, b as the paper) and return [(path, caption)]."""
    keys = sorted(result.profiles)
    fig, axes = new_figure(1, len(keys), figsize=(5.2 * len(keys), 3.8))
    for ax, k in zip(axes[0], keys, strict=True):
        plot_panel(ax, result, k)
    path = save_figure(ctx, fig, "fig2")
    return [(path, "Fig. 2: impact v0 = 1 m/s on a monodisperse chain; grain velocity at the "
             "end of the run, per-grain maximum velocity (squares) and its mean over the "
             "settled range (dashed).")]


def report(rep, result: Fig2Result, figs: list) -> None:
    """Add the Fig. 2 section to a :class:`hertzchain.report.Report`."""
    rep.heading("Fig. 2 — settled solitary-wave amplitude v̄max/v0")
    rows = []
    for d0, p in result.plateaus.items():
        paper = VMAX_OVER_V0.get(d0)
        rows.append([f"{d0:g}", "Hertz, ν = 0.30", f"{p.start + 1}–{p.stop}", f"{p.mean:.6f}",
                     f"{p.std:.1e}", f"{p.slope_per_1000:.1e}", paper,
                     f"{p.mean - paper:+.1e}" if paper else "—"])
    for name, p in result.variants.items():
        rows.append(["0.001", VARIANTS[name][0], f"{p.start + 1}–{p.stop}", f"{p.mean:.6f}",
                     f"{p.std:.1e}", f"{p.slope_per_1000:.1e}", 0.0822,
                     f"{p.mean - 0.0822:+.1e}"])
    rep.table(["δ0/d", "k_n", "grains averaged", "v̄max/v0", "std", "slope /1000 grains",
               "paper", "difference"], rows,
              caption="Mean of the per-grain maximum velocity over the settled range")
    rep.paragraph(
        f"The averaging range is chosen by `discrete.diagnostics.vmax_plateau`: from the "
        f"first grain after which every v_max lies within {RTOL:g} (relative) of the "
        f"settled value, to {MARGIN} grains before the last grain the wave has reached "
        f"(grain numbers 1-based).  At δ0/d = 1e-3 the leading wave keeps shedding its "
        f"tail for thousands of grains (docs/physics.md §1), hence the long chain.  Only the "
        f"Hertz constant with ν = 0.30 reproduces the paper's 0.0822; the printed k_n "
        f"(2× the Hertz value) with Table 1's ν = 0.25 gives about half of it.")
    for path, caption in figs:
        rep.figure(path, caption)


def to_json(result: Fig2Result) -> dict:
    """``{"vmax_over_v0": {"0": ..., "0.001": ...}}`` (the issue's format)."""
    return {"vmax_over_v0": {f"{k:g}": float(v) for k, v in result.vmax_over_v0.items()}}
