r"""Figs. 3 and 4: mass- and stiffness-mismatched chains without precompression.

Paper Section 4.  δ0 = 0; the incident wave is the settled δ0 = 0 impact wave
(v0 = 1 m/s, cut and placed 100 grains left of the interface, as the paper's
"translated" wave).  Fig. 3: α_ρ = 0.2 and 5, interface between grains 400 and 401,
snapshot when the centre of the transmitted front reaches grain 550, displacement–time
curves of grains 395–402.  Fig. 4: α_kn = 0.2 and 5, interface 200|201, grains 195–202;
the paper gives no snapshot grain for Fig. 4, we take 350 (150 grains past the
interface, as Fig. 3's 550 is past 400).

Panels a, b: grain velocity against grain number; c, d: u_i/ū_max against time, with
free-flight stretches (both contacts open, :func:`discrete.diagnostics.grain_modes`)
drawn thick and the gap openings of the contact between the paper's grains 399|400
(199|200), :func:`discrete.diagnostics.gap_events`.  ū_max is the mean maximum
displacement of left-section grains that the incident wave has fully passed before it
reaches the interface (the paper's ū_max, Section 2).  Grain numbers are the paper's
(1-based) throughout.

Each case is the paper scenario ``hertzchain/scenarios/paper/fig3.toml`` (``fig4.toml``)
with the case's α and the mode's sizes (:func:`scenario`), run through the one run path
(:func:`.common.run_models`).  Fig. 3's scenario also runs the continuum — the paper's
own model, the regularised Eq. 7, pinned as ``[models] continuum = "eq7"`` (``"auto"``
would pick the grain-averaged quasi-continuum at δ0 = 0,
:meth:`hertzchain.scenario.ModelsSpec.continuum_model`) — from the same grains, drawn
beside the discrete profile in panels a, b with its difference where it is large.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

import theory
from discrete import diagnostics as D

from ..plotting import plot_displacement_time, plot_grain_profile
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

__all__ = ["SETUPS", "QUICK", "FULL", "CaseResult", "scenario", "run", "plot_velocity",
           "plot_displacements", "figure", "figures", "report", "to_json"]

SETUPS = {
    "fig3": {"what": "alpha_rho", "alphas": (0.2, 5.0), "interface": 400, "snapshot": 550,
             "grains": tuple(range(395, 403))},
    "fig4": {"what": "alpha_kn", "alphas": (0.2, 5.0), "interface": 200, "snapshot": 350,
             "grains": tuple(range(195, 203))},
}
"""Paper set-ups (1-based grain numbers; Section 4)."""
QUICK = {"n_right_extra": 100, "lead": 100, "series_every": 10}
FULL = {"n_right_extra": 100, "lead": 100, "series_every": 2}
PULSE_MIN = 0.05
"""Pulses below this fraction of the incident peak velocity are not counted."""


@dataclass
class CaseResult:
    """One panel pair (a/c or b/d) of Fig. 3 or 4."""

    item: str
    alpha_rho: float
    alpha_kn: float
    interface: int
    snapshot_grain: int
    grains: tuple
    v: np.ndarray
    t_snapshot: float
    series_t: np.ndarray
    series: np.ndarray
    u_bar_max: float
    incident_peak: float
    modes: list
    gaps: D.GapEvents
    numbers: dict = field(default_factory=dict)
    path: object = None
    continuum: ContinuumProfile | None = None


def _params(item: str, alpha: float, s: dict) -> dict:
    setup = SETUPS[item]
    ar, ak = (alpha, 1.0) if setup["what"] == "alpha_rho" else (1.0, alpha)
    n_left = setup["interface"]
    return {"item": item, "alpha_rho": ar, "alpha_kn": ak, "n_left": n_left,
            "n_right": setup["snapshot"] - n_left + s["n_right_extra"],
            "centre": n_left - s["lead"], "snapshot_index": setup["snapshot"] - 1,
            "series_grains": [g - 1 for g in setup["grains"]],
            "series_every": s["series_every"]}


def scenario(item: str, alpha: float, s: dict | None = None):
    """One case of Fig. 3 or 4: ``paper/fig3.toml`` or ``fig4.toml`` with α and sizes.

    ``s``: the mode's sizes (default :data:`QUICK`).
    """
    p = _params(item, alpha, QUICK if s is None else s)
    return paper_scenario(item, {
        "chain.sections.0.n": p["n_left"], "chain.sections.1.n": p["n_right"],
        "chain.sections.1.alpha_rho": p["alpha_rho"],
        "chain.sections.1.alpha_kn": p["alpha_kn"],
        "initial.center": p["centre"], "run.until_front_at": p["snapshot_index"],
        "record.time_series_grains": p["series_grains"],
        "record.series_every": p["series_every"]})


def _case(ctx: Context, item: str, alpha: float, s: dict) -> CaseResult:
    p = _params(item, alpha, s)
    r = run_models(ctx, item, scenario(item, alpha, s))
    sim, path = r.simulation, r.discrete.path
    n_left = r.interface  # (hertzchain.measure.interfaces: the scenario's p["n_left"])
    arr = sim.record.arrays()
    t, ser = arr["series_t"], arr["series"]
    umax = np.asarray(sim.record.umax)
    # grains fully passed by the incident wave before the interface (module docstring)
    u_bar = float(np.mean(umax[p["centre"] + 45:n_left - 30]))
    inc = float(np.max(sim.record.vmax[p["centre"] + 45:n_left - 30]))
    modes = [D.grain_modes(t, ser[:, j, 0], ser[:, j, 2], ser[:, j, 3], v=ser[:, j, 1],
                           min_samples=3) for j in range(ser.shape[1])]
    # contact between the paper's grains N_L - 1 and N_L (1-based): the grain with paper
    # number N_L is index N_L - 1; its left contact is column 2
    j_iface = p["series_grains"].index(n_left - 1)
    gaps = D.gap_events(t, ser[:, j_iface, 2])
    v = np.asarray(sim.v)
    left, right = v[:n_left], v[n_left:]
    pulses_tr = D.find_pulses(v, threshold=PULSE_MIN, reference=inc, lo=n_left, hi=v.size)
    pulses_re = D.find_pulses(v, threshold=PULSE_MIN, reference=inc, lo=0, hi=n_left)
    ct = D.classify_transmitted(v, lo=n_left, hi=v.size - 1, direction=1)
    cr = D.classify_reflected(velocity=v, lo=0, hi=n_left, reference=inc)
    u_n = ser[:, :, 0] / u_bar
    pred = theory.predict(p["alpha_rho"], p["alpha_kn"])
    numbers = {
        "alpha_rho": p["alpha_rho"], "alpha_kn": p["alpha_kn"],
        "gamma_c0": pred.gamma_c0, "gamma_RG": pred.gamma_RG, "region": pred.region,
        "t_snapshot_ms": sim.t * 1e3, "u_bar_max_m": u_bar, "incident_peak_v": inc,
        "n_transmitted_pulses": len(pulses_tr),
        "leading_transmitted_peak_over_incident": (pulses_tr[-1].amplitude / inc
                                                   if pulses_tr else 0.0),
        "n_reflected_pulses": len(pulses_re),
        "max_abs_left_v_over_incident": float(np.max(np.abs(left)) / inc),
        "min_left_v_over_incident": float(left.min() / inc),
        "max_right_v_over_incident": float(right.max() / inc),
        "transmitted_class": ct.label, "transmitted_reason": ct.reason,
        "reflected_class": cr.label,
        "interface_gap_openings": int(gaps.openings.size),
        "max_u_over_ubar": {int(g): float(u_n[:, j].max())
                            for j, g in enumerate(SETUPS[item]["grains"])},
        "free_flight_segments": {int(g): sum(seg.mode == "free-flight" for seg in m.segments)
                                 for g, m in zip(SETUPS[item]["grains"], modes, strict=True)},
    }
    cont = continuum_profile(r, v, inc, n_left)  # the scenario's [models] continuum
    if cont is not None:
        numbers["continuum"] = cont.numbers
    return CaseResult(item, p["alpha_rho"], p["alpha_kn"], n_left, SETUPS[item]["snapshot"],
                      SETUPS[item]["grains"], v, sim.t, t, ser, u_bar, inc, modes, gaps,
                      numbers, path, cont)


def run(ctx: Context, item: str = "fig3", **overrides) -> list[CaseResult]:
    """Run both cases of Fig. 3 (``item="fig3"``) or Fig. 4 (``"fig4"``)."""
    if item not in SETUPS:
        raise ValueError(f"item must be one of {sorted(SETUPS)} (got {item!r})")
    s = ctx.pick(QUICK, FULL) | overrides
    out = []
    for alpha in SETUPS[item]["alphas"]:
        ctx.log(f"{item}: {SETUPS[item]['what']} = {alpha:g}, δ0 = 0")
        out.append(_case(ctx, item, alpha, s))
    return out


def _alpha_text(c: CaseResult) -> str:
    if c.alpha_kn == 1.0:
        return rf"$\alpha_\rho = {c.alpha_rho:g}$"
    return rf"$\alpha_{{k_n}} = {c.alpha_kn:g}$"


def plot_velocity(ax, case: CaseResult, *, label: str = "", legend: bool = True) -> None:
    """Panel a/b: grain velocity at the snapshot, transmitted pulses marked.

    The discrete chain solid black; with the continuum (:func:`.common.plot_continuum`)
    its profile thin dashed on top, the difference where it is large.  ``legend``: a
    legend of the models in the axes (False: the caller draws one for the figure).
    """
    n = case.v.size
    plot_grain_profile(ax, case.v / V0, interface=case.interface, ylabel=r"$v_i$ (m/s)",
                       color="k", lw=1.0, label="discrete", numbering="paper")
    plot_continuum(ax, case.continuum, case.v, case.incident_peak, scale=V0)
    if case.continuum is not None and legend:
        ax.legend(fontsize="x-small", loc="best")
    ax.axhline(0, color="0.7", lw=0.5, zorder=0)
    pulses = D.find_pulses(case.v, threshold=PULSE_MIN, reference=case.incident_peak,
                           lo=case.interface, hi=n)
    first, second = D.split_parts_at_gap(pulses, direction=1)
    for part, name in ((first, "1st"), (second, "2nd")):
        if part:
            p = max(part, key=lambda q: abs(q.amplitude))
            ax.annotate(name, (p.position + 1, p.amplitude), xytext=(0, 6),
                        textcoords="offset points", ha="center", fontsize="small")
    ax.set_xlim(0, n + 1)
    ymin, ymax = ax.get_ylim()
    ax.set_ylim(ymin, ymax + 0.1 * (ymax - ymin))  # the pulse names under the top spine
    ax.set_title(f"({label}) {_alpha_text(case)}, front at grain {case.snapshot_grain}, "
                 f"t = {case.t_snapshot * 1e3:.3g} ms", fontsize="medium")


OPENING_STYLES = (":", "-.")
"""Line styles of the first and second opening of the gap left of the interface grain."""


def _opening_handles(case: CaseResult) -> list:
    """Legend entries of the free-flight stretches and gap openings (:func:`plot_displacements`)."""
    from matplotlib.lines import Line2D

    g = case.grains[case.grains.index(case.interface) - 1]
    return ([Line2D([], [], color="0.5", lw=3, alpha=0.4, label="free flight")]
            + [Line2D([], [], color="0.35", lw=0.9, ls=ls,
                      label=f"gap {g}|{g + 1} opens ({'1st' if k == 0 else '2nd'})")
               for k, ls in enumerate(OPENING_STYLES)])


def plot_displacements(ax, case: CaseResult, *, label: str = "", legend: bool = True) -> None:
    """Panel c/d: u_i/ū_max against time, free flight thick, interface-gap openings.

    The first two openings of the gap left of the interface grain are vertical lines
    (dotted, dash-dotted: :data:`OPENING_STYLES`), named in the legend, not over the
    curves.  ``legend``: the grains' legend in the axes (False: the caller draws one;
    :func:`_opening_handles` are its extra entries).
    """
    t, ser = case.series_t, case.series
    free = np.stack([m.codes == D.FREE_FLIGHT for m in case.modes], axis=1)
    u = ser[:, :, 0]
    moving = np.nonzero(np.any(np.abs(ser[:, :, 1]) > 1e-3 * case.incident_peak, axis=1))[0]
    i0 = max(0, moving[0] - 20) if moving.size else 0
    plot_displacement_time(ax, t[i0:], u[i0:], [g - 1 for g in case.grains],
                           u_ref=case.u_bar_max, free_flight=free[i0:], numbering="paper",
                           legend=False)
    for a, ls in zip(case.gaps.openings[:2], OPENING_STYLES, strict=False):
        ax.axvline(a * 1e3, color="0.35", lw=0.9, ls=ls)
    ax.axhline(1.0, color="0.7", lw=0.5, ls="--")
    if legend:
        ax.legend(handles=ax.get_legend_handles_labels()[0][:len(case.grains)]
                  + _opening_handles(case), title="grain (paper's)", fontsize="x-small",
                  ncol=2, loc="best")
    ax.set_title(f"({label}) {_alpha_text(case)}: grains {case.grains[0]}–{case.grains[-1]}",
                 fontsize="medium")


def figure(cases: list[CaseResult]):
    """The Fig. 3 or Fig. 4 figure: 2 × 2 panels as the paper.

    The legends are the figure's, outside the panels: the models' (top row) above,
    the grains' (both lower panels show the same grains in the same colours) and the
    gap openings' on the right.
    """
    fig, axes = new_figure(2, 2, figsize=(12, 7.8))
    for col, (case, lab) in enumerate(zip(cases, "ab", strict=True)):
        plot_velocity(axes[0, col], case, label=lab, legend=False)
        plot_displacements(axes[1, col], case, label="cd"[col], legend=False)
    models = {}
    for ax in axes[0]:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            models.setdefault(lab, h)
    if len(models) > 1:
        fig.legend(list(models.values()), list(models), loc="outside upper center",
                   ncol=len(models), fontsize="small", frameon=False)
    grains = axes[1, 0].get_legend_handles_labels()[0][:len(cases[0].grains)]
    fig.legend(handles=grains + _opening_handles(cases[0]), loc="outside right lower",
               title="grain (paper's)", fontsize="small", title_fontsize="small",
               frameon=False)
    return fig


def figures(ctx: Context, cases: list[CaseResult]) -> list:
    """Save ``fig3.png`` or ``fig4.png`` (:func:`figure`)."""
    item = cases[0].item
    path = save_figure(ctx, figure(cases), item)
    return [(path, f"{item[:3].capitalize()}. {item[3]}: {_what(item)}-mismatched chain, "
             "δ0 = 0. (a, b) grain velocity when the transmitted front reaches the paper's "
             "grain (dotted: the interface); (c, d) displacement/ū_max of the grains around "
             "the interface; thick: free flight (both contacts open); vertical lines: the "
             "first and second openings of the gap left of the interface grain."
             + (" Dashed: the continuum from the same grains; red: its difference where "
                "large." if any(c.continuum is not None for c in cases) else ""))]


def _what(item: str) -> str:
    """"mass" (Fig. 3) or "elastic-coefficient" (Fig. 4)."""
    return "mass" if item == "fig3" else "elastic-coefficient"


def report(rep, cases: list[CaseResult], figs: list) -> None:
    """Add the Fig. 3 or Fig. 4 section."""
    item = cases[0].item
    num = item[3]
    rep.heading(f"Fig. {num} — {'mass' if num == '3' else 'stiffness'} mismatch at δ0 = 0")
    header = ["α_ρ", "α_kn", "γ_c0", "γ_RG", "t (ms)", "transmitted pulses",
              "lead TSW / ISW", "reflected pulses", "min v_left / ISW", "TSW class",
              "gap openings at interface"]
    rows = [[c.alpha_rho, c.alpha_kn, c.numbers["gamma_c0"], c.numbers["gamma_RG"],
             c.numbers["t_snapshot_ms"], c.numbers["n_transmitted_pulses"],
             c.numbers["leading_transmitted_peak_over_incident"],
             c.numbers["n_reflected_pulses"], c.numbers["min_left_v_over_incident"],
             c.numbers["transmitted_class"], c.numbers["interface_gap_openings"]]
            for c in cases]
    rep.table(header, rows, caption=f"Fig. {num}: pulses ≥ {PULSE_MIN:g} × the incident "
              "peak velocity at the snapshot; ISW = incident solitary wave")
    bullets = []
    for c in cases:
        mx = c.numbers["max_u_over_ubar"]
        ff = c.numbers["free_flight_segments"]
        bullets.append(
            f"{_plain(c)}: max u_i/ū_max over grains {c.grains[0]}–{c.grains[-1]}: "
            + ", ".join(f"{g}: {v:.3f}" for g, v in mx.items())
            + "; free-flight stretches: " + ", ".join(f"{g}: {n}" for g, n in ff.items()))
    rep.bullets(bullets)
    rep.paragraph(_claims(cases))
    cont = continuum_sentence([(_plain(c), c.continuum) for c in cases])
    if cont:
        rep.paragraph(cont)
    for path, caption in figs:
        rep.figure(path, caption)


def _plain(c: CaseResult) -> str:
    return f"α_ρ = {c.alpha_rho:g}" if c.alpha_kn == 1.0 else f"α_kn = {c.alpha_kn:g}"


def _claims(cases: list[CaseResult]) -> str:
    """The paper's statements about these panels, checked against the run."""
    lo, hi = cases
    out = []
    # grains next to the interface (paper: 399-402 / 199-202), which the scattered waves move
    near = lo.grains[-4:]
    mlo = max(lo.numbers["max_u_over_ubar"][g] for g in near)
    mhi = max(hi.numbers["max_u_over_ubar"][g] for g in near)
    if lo.item == "fig3":
        left = lo.numbers["max_abs_left_v_over_incident"]
        out.append(f"Paper: for α_ρ = 0.2 the left section stays static (no reflection): "
                   f"max |v| left of the interface = {left:.2e}"
                   f" × the incident peak.  Paper: for α_ρ = 5 the reflected waves have "
                   f"negative velocities (compressive): min v left = "
                   f"{hi.numbers['min_left_v_over_incident']:.3f} × incident.  Paper: "
                   f"u_i/ū_max < 1 for the light–heavy chain: max over grains "
                   f"{near[0]}–{near[-1]} = {mhi:.3f}.")
    else:
        out.append(f"Paper: for α_kn = 0.2 the overshoot gives u_i/ū_max > 1 for grains "
                   f"199–202: min of their maxima = "
                   f"{min(lo.numbers['max_u_over_ubar'][g] for g in near):.3f}, max = "
                   f"{mlo:.3f}.  Paper: for α_kn = 5 all displacements are below 1: max "
                   f"over grains 199–202 = {mhi:.3f}.")
    return " ".join(out)


def to_json(cases: list[CaseResult]) -> dict:
    """Numbers of both cases keyed by ``alpha_rho=..``/``alpha_kn=..``."""
    return {_plain(c).replace(" ", "").replace("α_ρ", "alpha_rho").replace("α_kn", "alpha_kn"):
            c.numbers for c in cases}
