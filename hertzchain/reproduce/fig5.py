r"""Fig. 5: precompressed composite chains (δ0^L/d = 1e-3), the four cases a–d.

Paper Section 4: (a) α_ρ = 0.2 (heavy–light), (b) α_ρ = 5 (light–heavy), (c) α_kn = 0.2
(hard–soft), (d) α_kn = 5 (soft–hard); 50,000 grains, interface between grains 35,000
and 35,001, grain velocity when the transmitted front reaches grain 49,900.  ``--full``
uses exactly that; ``--quick`` the same geometry at 1/5 scale (10,000 grains, interface
7,000|7,001, snapshot at 9,900), which shows the same structures (fracture into a
train for a and d, one leading wave with an oscillatory tail for b and c, expansive
reflected waves for a and c, compressive for b and d) less separated.

The incident wave is the paper's settled impact wave (cut and placed ``lead`` grains
left of the interface; where the paper placed it is not stated, and in a uniform chain
the settled wave travels unchanged, so only the cost depends on it).  The cost is
estimated and printed before each run (:func:`estimate_cost`).

Each case is the paper scenario ``hertzchain/scenarios/paper/fig5.toml`` with the case's
α and the mode's sizes (:func:`scenario`), run through the one run path
(:func:`.common.run_models`); it also runs the continuum (corrected Eq. 4, 3 nodes per
grain) from the same grains, drawn beside the discrete profile with its difference where
it is large.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

import theory
from discrete import diagnostics as D
from discrete.integrators import get_integrator

from ..plotting import plot_grain_profile
from .common import (
    V0,
    Context,
    ContinuumProfile,
    continuum_profile,
    continuum_sentence,
    new_figure,
    paper_scenario,
    plot_continuum,
    run_models,
    save_figure,
)

__all__ = ["QUICK", "FULL", "CASES", "CaseResult", "scenario", "estimate_cost", "run",
           "parts", "run_part", "combine", "zoom_window", "plot_case", "figure", "figures",
           "report", "to_json"]

QUICK = {"n_grains": 10_000, "interface": 7_000, "snapshot": 9_900, "lead": 300}
FULL = {"n_grains": 50_000, "interface": 35_000, "snapshot": 49_900, "lead": 300,
        "integrator": "blanes_moan4", "dt_fraction": 0.096,
        "continuum_integrator": "blanes_moan4", "continuum_dt_safety": 1.45}
"""--full integrates with Blanes–Moan's 4th-order method at 0.096·2π/ω_max (48× velocity
Verlet's default dt, 1/8 of its force evaluations): within 1e-7 of a dt = 1e-9 s
reference in section energies and front speed (``benchmarks/fig5_full.py``).  Its
continuum too: Blanes–Moan-4 at ``[models] dt_safety`` 1.45 (ω_max Δt = 2.9, 92 % of the
method's limit 3.163, with ω_max at 1.5 × the largest wave strain: 2.07 force
evaluations per 1/ω_max against 3.0 for --quick's Yoshida-4 at 0.5): relative L2 of
the final grain velocities against a converged reference (Blanes–Moan-4 at 0.2), quick
geometry, cases a–d: 3.1e-5, 5.6e-4, 4.6e-4, 1.4e-4, where Yoshida-4 at 0.5 is 1.9e-3,
2.2e-2, 2.2e-2, 7.7e-3 (39–60× closer at 0.69–0.73× the CPU;
``benchmarks/fig5_full.py --continuum``)."""
CASES = ("a", "b", "c", "d")
DELTA0_OVER_D = 1e-3
UPDATES_PER_SECOND = 1e9
"""Assumed kernel throughput (grain updates per second) for the printed cost estimate."""


@dataclass
class CaseResult:
    """One panel of Fig. 5."""

    case: str
    alpha_rho: float
    alpha_kn: float
    v: np.ndarray
    t: float
    interface: int
    numbers: dict = field(default_factory=dict)
    path: object = None
    continuum: ContinuumProfile | None = None


def scenario(case: str, s: dict | None = None):
    """Case ``a``–``d`` of Fig. 5: ``paper/fig5.toml`` with the case's α and the sizes.

    ``s``: the mode's sizes and integrators (default :data:`QUICK`; ``integrator``,
    ``dt_fraction``: the discrete run's; ``continuum_integrator``,
    ``continuum_dt_safety``: the continuum's ``[models] integrator`` and ``dt_safety``).
    """
    s = QUICK if s is None else s
    ar, ak = theory.PAPER_POINTS[case]
    values = {"chain.delta0_over_d": DELTA0_OVER_D,
              "chain.sections.0.n": s["interface"],
              "chain.sections.1.n": s["n_grains"] - s["interface"],
              "chain.sections.1.alpha_rho": ar, "chain.sections.1.alpha_kn": ak,
              "initial.center": s["interface"] - s["lead"],
              "run.until_front_at": s["snapshot"] - 1}
    if s.get("integrator"):
        values["run.integrator"] = s["integrator"]
    if s.get("dt_fraction"):
        values["run.dt_fraction"] = s["dt_fraction"]
    if s.get("continuum_integrator"):
        values["models.integrator"] = s["continuum_integrator"]
    if s.get("continuum_dt_safety"):
        values["models.dt_safety"] = s["continuum_dt_safety"]
    return paper_scenario("fig5", values)


def estimate_cost(ctx: Context, case: str, s: dict) -> dict:
    """Steps, grain updates and seconds a case will take (before running it).

    The incident wave crosses ``lead`` grains at its speed with a ~100-grain active
    window; then the window spreads with the transmitted front (speed ≈ γ_c0 c0^L) and
    the reflected waves (≈ c0^L), so the grain updates are ≈ steps × (mean window).
    """
    from ..runner import build_simulation

    p = {"case": case, **s}
    chain, _, sim = build_simulation(scenario(case, s), energy_grid=False,
                                     cache_dir=ctx.cache)
    stages = get_integrator(sim.integrator).stages
    d = float(chain.diameter[0])
    c0l = float(theory.c0(chain.k[1], chain.mass[0], d, chain.delta0[1]))
    gc = float(theory.gamma_c0(*theory.PAPER_POINTS[case]))
    v_in = 1.01 * c0l
    t1 = p["lead"] * d / v_in
    t2 = (p["snapshot"] - p["interface"]) * d / (gc * c0l)
    steps1, steps2 = t1 / sim.dt, t2 / sim.dt
    window_end = min(p["n_grains"], (p["snapshot"] - p["interface"]) * (1 + 1.05 / gc))
    updates = stages * (steps1 * 100 + steps2 * 0.5 * window_end)
    return {"dt": sim.dt, "steps": int(steps1 + steps2), "grain_updates": float(updates),
            "seconds": updates / UPDATES_PER_SECOND}


def _case(ctx: Context, case: str, s: dict) -> CaseResult:
    ar, ak = theory.PAPER_POINTS[case]
    p = {"case": case, **s}
    if ctx.progress:
        cost = estimate_cost(ctx, case, s)
        ctx.log(f"fig5 ({case}): {p['n_grains']} grains, ~{cost['steps']:.3g} steps, "
                f"~{cost['grain_updates']:.2g} grain updates, estimated "
                f"~{cost['seconds']:.0f} s at {UPDATES_PER_SECOND:.0e} updates/s "
                "(if not cached)")
    r = run_models(ctx, "fig5", scenario(case, s))
    sim, path = r.simulation, r.discrete.path
    n_left = r.interface  # (hertzchain.measure.interfaces: the scenario's p["interface"])
    chain = sim.chain
    v = np.asarray(sim.v)
    # incident peak velocity: the running maximum on left grains passed before the interface
    # (grains the peak passed freely: from just right of the start to 25 before the interface)
    inc = float(np.median(sim.record.vmax[n_left - p["lead"] + 5:n_left - 25]))
    ct = D.classify_transmitted(v, lo=n_left, hi=chain.n - 1, direction=1)
    cr = D.classify_reflected(overlaps=sim.overlaps(), delta0=chain.delta0, lo=1, hi=n_left - 1,
                              reference=None)
    pred = theory.predict(ar, ak)
    theory_tr = "fracture" if pred.gamma_c0 > 1 else "squeeze"
    theory_re = "compressive" if pred.gamma_RG > 1 else "expansive"
    lead_pulse = ct.pulses[0] if ct.pulses else None
    strain_ref = float(np.max(np.abs(sim.overlaps()[1:n_left] - chain.delta0[1:n_left])))
    numbers = {
        "alpha_rho": ar, "alpha_kn": ak, "gamma_c0": pred.gamma_c0, "gamma_RG": pred.gamma_RG,
        "region": pred.region, "t_ms": sim.t * 1e3, "incident_peak_v": inc,
        "leading_transmitted_v_over_incident": (lead_pulse.amplitude / inc
                                                if lead_pulse else float("nan")),
        "transmitted": ct.label, "transmitted_reason": ct.reason,
        "n_transmitted_pulses": ct.n_pulses, "trailing_excess": ct.trailing_excess,
        "reflected": cr.label, "reflected_dominant_strain": cr.dominant_amplitude,
        "reflected_max_abs_dynamic_overlap_m": strain_ref,
        "theory_transmitted": theory_tr, "theory_reflected": theory_re,
        "agrees": ct.label == theory_tr and cr.label == theory_re,
    }
    cont = continuum_profile(r, v, inc, n_left)  # the scenario's [models] continuum
    if cont is not None:
        numbers["continuum"] = cont.numbers
    return CaseResult(case, ar, ak, v, sim.t, n_left, numbers, path, cont)


def _sizes(ctx: Context, overrides: dict) -> dict:
    s = ctx.pick(QUICK, FULL) | overrides
    if not s["interface"] < s["snapshot"] < s["n_grains"]:
        raise ValueError("need interface < snapshot < n_grains")
    return s


def run(ctx: Context, cases=CASES, **overrides) -> list[CaseResult]:
    """Run the cases a–d of Fig. 5 (mode defaults, overridable: ``n_grains`` ...)."""
    s = _sizes(ctx, overrides)
    return [_case(ctx, c, s) for c in cases]


def parts(ctx: Context) -> tuple[str, ...]:
    """The cases, which ``reproduce`` runs as separate tasks.

    Fig. 5 is the largest item of ``--full``; as four tasks it spreads over the workers.
    """
    return CASES


def run_part(ctx: Context, case: str) -> CaseResult:
    """One case at the mode's sizes (:func:`run` of that case)."""
    if case not in CASES:
        raise ValueError(f"case must be one of {CASES} (got {case!r})")
    return _case(ctx, case, _sizes(ctx, {}))


def combine(ctx: Context, results: list[CaseResult]) -> list[CaseResult]:
    """The item's result from its cases' (:func:`run_part`, in :func:`parts` order)."""
    return list(results)


BEHIND, AHEAD = 20.0, 5.0
"""The zoomed window of a panel (:func:`zoom_window`): this many widths of the leading
transmitted pulse behind its peak (the train of a fracture, the oscillatory tail of a
squeeze) and ahead of it (at least to the front)."""


def zoom_window(res: CaseResult, *, behind: float = BEHIND, ahead: float = AHEAD
                ) -> tuple[int, int, int, int]:
    """The grains drawn in a panel: around the leading transmitted pulse.

    The leading pulse is the largest grain velocity right of the interface (its peak
    grain ``peak``, 0-based); its width ``w`` the number of grains around the peak at or
    above half its velocity (full width at half maximum, in grains; ≥ 1); the front the
    last grain moving faster than 1 % of the largest |v|.  The window [lo, hi) runs from
    ``behind`` widths behind the peak (not left of the interface) to ``ahead`` widths
    past it, and at least to the front.

    Returns
    -------
    (lo, hi, peak, w) : tuple of int
        Grain indices (0-based; hi exclusive) and the width in grains.
    """
    v = np.asarray(res.v)
    peak = res.interface + int(np.argmax(v[res.interface:]))
    half = v >= 0.5 * v[peak]
    a = peak
    while a > 0 and half[a - 1]:
        a -= 1
    b = peak
    while b < v.size - 1 and half[b + 1]:
        b += 1
    w = b - a + 1
    moving = np.flatnonzero(np.abs(v) > 0.01 * np.abs(v).max())
    front = int(moving[-1]) if moving.size else peak
    lo = max(res.interface, peak - int(round(behind * w)))
    hi = min(v.size, max(peak + int(round(ahead * w)), front + 2) + 1)
    return lo, hi, peak, w


def plot_case(ax, res: CaseResult, *, label: str | None = None, behind: float = BEHIND,
              ahead: float = AHEAD, overview: bool = True, legend: bool = True) -> None:
    """One panel: grain velocity / v0 around the leading transmitted wave at the snapshot.

    The axes show :func:`zoom_window` (a few hundred of the chain's grains), the discrete
    chain solid black, the continuum (:func:`.common.plot_continuum`) thin dashed orange
    on top of it and their difference (red) where it is large.  ``overview``: an inset,
    top left, with the whole chain (interface dotted, the reflected waves, the zoomed
    window shaded).  ``legend``: a legend in the axes (False: the caller draws one, e.g.
    for the whole figure).
    """
    lo, hi, _, _ = zoom_window(res, behind=behind, ahead=ahead)
    g = np.arange(lo, hi)
    plot_grain_profile(ax, res.v[g] / V0, start=lo, ylabel=r"$v_i/v_0$", color="k",
                       lw=1.3, label="discrete", numbering="paper")
    inc = res.numbers["incident_peak_v"]
    plot_continuum(ax, res.continuum, res.v, inc, scale=V0, start=lo, stop=hi)
    ax.axhline(0, color="0.7", lw=0.4, zorder=0)
    ax.set_xlim(lo + 1, hi)
    ymin, ymax = ax.get_ylim()
    ax.set_ylim(ymin, ymax + 0.8 * (ymax - ymin))  # the top ~45 %: the overview's room
    txt = (rf"$\alpha_\rho = {res.alpha_rho:g}$" if res.alpha_kn == 1 else
           rf"$\alpha_{{k_n}} = {res.alpha_kn:g}$")
    n = res.numbers
    ax.set_title(f"({label or res.case}) {txt}: transmitted {n['transmitted']}, "
                 f"reflected {n['reflected']}", fontsize="medium")
    if legend:
        ax.legend(fontsize="x-small", loc="upper right")
    if overview:
        ins = ax.inset_axes([0.16, 0.6, 0.46, 0.3])
        grains = np.arange(res.v.size) + 1
        ins.plot(grains, res.v / V0, color="k", lw=0.5)
        ins.axvspan(lo + 1, hi, color="C1", alpha=0.3, lw=0)
        ins.axvline(res.interface + 0.5, color="0.4", ls=":", lw=0.8)
        ins.set_xlim(0, res.v.size + 1)
        ins.tick_params(labelsize="x-small")
        ins.text(0.02, 0.95, f"whole chain; shaded: the panel's {hi - lo} grains",
                 transform=ins.transAxes, ha="left", va="top", fontsize="x-small")
        y0, y1 = ins.get_ylim()
        ins.set_ylim(y0, y1 + 0.5 * (y1 - y0))  # room for the text


def figure(results: list[CaseResult]):
    """The Fig. 5 figure: 2 × 2 panels a–d (:func:`plot_case`) as the paper, one legend."""
    fig, axes = new_figure(2, 2, figsize=(11, 7.6))
    for ax, res in zip(axes.ravel(), results, strict=False):
        plot_case(ax, res, legend=False)
    handles, labels = {}, {}
    for ax in axes.ravel():
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(lab, h)
    labels = list(handles)
    fig.legend([handles[k] for k in labels], labels, loc="outside lower center",
               ncol=len(labels), fontsize="small", frameon=False)
    return fig


def figures(ctx: Context, results: list[CaseResult]) -> list:
    """Save ``fig5.png`` (:func:`figure`)."""
    r0 = results[0]
    path = save_figure(ctx, figure(results), "fig5")
    return [(path, f"Fig. 5: δ0^L/d = 1e-3, {r0.v.size} grains, interface "
             f"{r0.interface}|{r0.interface + 1}; grain velocity when the transmitted "
             "front reaches the paper's grain (scaled in --quick), around the leading "
             f"transmitted pulse ({BEHIND:g} of its widths behind its peak, {AHEAD:g} "
             "ahead); inset: the whole chain (interface dotted, the zoomed window shaded)."
             + (" Dashed: the continuum from the same grains; red: its difference where "
                "large." if any(r.continuum is not None for r in results) else ""))]


def report(rep, results: list[CaseResult], figs: list) -> None:
    """Add the Fig. 5 section."""
    rep.heading("Fig. 5 — precompressed composite chains, cases a–d")
    rows = [[r.case, r.alpha_rho, r.alpha_kn, r.numbers["gamma_c0"], r.numbers["gamma_RG"],
             r.numbers["region"], r.numbers["transmitted"], r.numbers["theory_transmitted"],
             r.numbers["n_transmitted_pulses"], r.numbers["leading_transmitted_v_over_incident"],
             r.numbers["reflected"], r.numbers["theory_reflected"],
             "yes" if r.numbers["agrees"] else "NO"] for r in results]
    rep.table(["case", "α_ρ", "α_kn", "γ_c0", "γ_RG", "region", "TSW measured", "TSW theory",
               "pulses", "lead TSW v / ISW v", "RSW measured", "RSW theory", "agree"], rows,
              caption="Classification at the snapshot (discrete.diagnostics.classify_*); "
              "theory: fracture for γ_c0 > 1, expansive reflection for γ_RG < 1")
    a = {r.case: r for r in results}
    if "a" in a:
        rep.paragraph(
            "Paper (Fig. 5a): the overshoot makes the leading transmitted wave larger than "
            f"the incident one — measured lead TSW/ISW velocity ratio "
            f"{a['a'].numbers['leading_transmitted_v_over_incident']:.3f}.  The fractured "
            "trains (a, d) separate only slowly under precompression, which is why the paper "
            "uses 50,000 grains; --quick shows them at 1/5 of that distance.")
    cont = continuum_sentence([(f"({r.case})", r.continuum) for r in results])
    if cont:
        rep.paragraph(cont)
    for path, caption in figs:
        rep.figure(path, caption)


def to_json(results: list[CaseResult]) -> dict:
    """Numbers per case."""
    return {r.case: r.numbers for r in results}
