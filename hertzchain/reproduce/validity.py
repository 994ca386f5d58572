r"""Beyond the paper: the model-validity map (issue 12).

Where the continuum (``"auto"``: corrected Eq. 4 under precompression up to an incident
strain/δ0 of :data:`hertzchain.scenario.AUTO_EQ4_MAX_STRAIN`, Eq. 7 above and at δ0 = 0) and the
theory (Nesterenko's wave speeds, the linear-acoustic interface, Eqs. 9–13) are within
1 % and within 10 % of the discrete chain (paper Eq. 2), over the interface ratios
(α_ρ, α_kn) and the amplitude: incident strain / δ0 from 1e-3 to 100 and the sonic
vacuum (:data:`AMPLITUDES`; each row's chain, wave and run length from
:func:`amplitude_row`).  Each point is the shipped sweep's scenario
(``hertzchain/sweeps/model_validity.toml``) run through the one run path
(:func:`.common.run_point_cached`: in memory, its row of errors cached in ``runs/`` and
counted) and compared by :func:`hertzchain.compare.analyse`.  ``--quick``: one
interface at three amplitudes (:data:`QUICK`); ``--full``: the four corner interfaces
at four amplitudes (:data:`FULL`); the shipped 5 × 5 × 7 map is ``hertzchain sweep
model_validity`` (about an hour on two cores), not part of ``reproduce``.  The error of
a model: the largest of |ΔE_T|, |ΔE_R| (over the incident energy) and the relative
transmitted front speed (:mod:`hertzchain.compare`); NaN, with the reason, where a
measurement window does not hold.
"""

from __future__ import annotations

import math
from importlib.resources import files

import numpy as np

from ..compare import THRESHOLDS, analyse
from ..scenario import AUTO_EQ4_MAX_STRAIN
from ..sweep.spec import load_sweep_spec
from .common import Context, run_point_cached, save_figure

__all__ = ["QUICK", "FULL", "run", "figures", "report", "to_json"]

QUICK: dict = {"alpha_rho": (2.0,), "alpha_kn": (0.5,), "amplitudes": (1e-2, 0.09, math.inf)}
"""The coarse map of ``--quick``: one interface (γ_c0 = 0.56, γ_RG = 1.12) at three of
the shipped sweep's amplitudes (incident strain / δ0; inf: the sonic vacuum)."""
FULL: dict = {"alpha_rho": (0.25, 4.0), "alpha_kn": (0.25, 4.0),
              "amplitudes": (1e-2, 0.09, 1.0, math.inf)}
"""The map of ``--full``: the four corner interfaces of the shipped sweep (the strongest
contrasts, where both models are worst) at four of its amplitudes.  The shipped 5 × 5 × 7
map is a sweep of its own (``hertzchain sweep model_validity``, ~1 h on two cores), not
part of ``reproduce``, which stays a few minutes."""


AMPLITUDES = ((1e-3, 1e-3), (1e-2, 1e-3), (0.09, 1e-3), (1.0, 1e-3), (9.0, 1e-4),
              (100.0, 1e-5), (math.inf, 0.0))
"""The map's amplitudes: (incident strain / δ0, δ0/d); ``inf``: the sonic vacuum, δ0 = 0.

Everything in the Hertz chain scales with the strain amplitude over δ0 alone (the force
k δ0^{3/2}(1 + ξ/δ0)^{3/2}; time in units of the contact period), so the models' errors,
the wave's width in grains and the steps per grain travelled depend on ξ_m/δ0 only, not
on how it is reached.  The amplitude is set by the exact discrete solitary wave's peak
strain (``[initial] kind = "exact_wave"``, ``strain_max``) and δ0 is chosen so that the
wave's overlap stays ≤ 1e-3 d (Hertz's small-strain range; grain velocities ≤ 1 m/s, the
paper's scale): the paper's δ0/d = 1e-3 up to ξ_m/δ0 = 1, smaller δ0 above.  The other
way, ξ_m/δ0 = 1e-3 at the paper's v0 = 1 m/s would need δ0/d ≈ 0.04, outside Hertz's
range, and an impact wave that settles over far more than 10,000 grains."""
SONIC_STRAIN = 1e-3
"""Peak strain ξ_m/d of the sonic-vacuum wave (any value gives the same errors: at δ0 = 0
the chain has no scale; 1e-3 is the paper's v0 = 1 m/s wave, 0.95e-3)."""
FIT_GRAINS = 100
"""Grains (at the incident speed) the run goes on past the crossing: the transmitted
front speed is fitted over them (≥ 3 samples, hertzchain.measure.FIT_FROM past the interface)."""
SPEED_RATIO = 4.0
"""Largest transmitted over incident wave speed on the map's (α_ρ, α_kn) ∈ [1/4, 4]²
(γ_c0 ≤ 2·4^{1/3} = 3.17 under precompression; c_mat ratio (α_kn/α_ρ)^{1/2} ≤ 4 times
the amplitude factor ≤ 1 in the sonic vacuum): the right section holds the transmitted
wave for that long."""
SAMPLES = 60
"""Common sample times per point: ≥ 3 of them after the crossing at every amplitude."""


def amplitude_row(strain_over_delta0: float, delta0_over_d: float) -> dict:
    r"""Chain, wave and run length for one amplitude of the map (the shipped TOML's rows).

    From the exact discrete solitary wave of the paper's grains (:data:`theory.PAPER_MATERIAL`,
    :data:`theory.PAPER_DIAMETER`, :func:`theory.discrete_solitary_wave`) at that
    amplitude, with speed V, and — under precompression — the decay rate q (per grain) of
    its strain tail e^{-q|z|}, from the lattice's linear dispersion at the wave speed,
    sinh(q/2)/(q/2) = V/c0 (q ≈ √(2 ξ_m/δ0) for small amplitudes: the KdV width 2/q):

    * the wave is placed with its whole periodic domain (``n_dom`` grains, where the
      solver resolved it) in the left section, n_dom/2 + 5 grains before the interface
      (the exact wave's placement refuses tails above 1e-12 of the peak outside its
      section);
    * it has crossed the interface (:data:`hertzchain.measure.SEPARATION` of its energy
      left, :func:`hertzchain.measure.incident_extent`) L = ln(1/SEPARATION)/q grains
      after its peak (the linear potential energy F0 ξ ∝ the strain dominates the tail;
      at least :data:`~hertzchain.measure.CROSSING_GRAINS`);
    * the run ends :data:`FIT_GRAINS` (or L, if more) grains later, at
      t_end = (n_dom/2 + 5 + L + max(FIT_GRAINS, L)) d / V;
    * the chain ends stay quiet: nothing that leaves the wave to the left at t = 0
      (the continuum, started from the discrete wave, sheds a small tail while it
      adapts; at a free continuum end its motion would do the work F0 Δu on the
      left section's potential energy) reaches the left end by t_end — ``center`` =
      n_dom/2 + 5 + L + max(FIT_GRAINS, L) + 20 —, nor does the reflected wave; the
      right section holds :data:`SPEED_RATIO` × (L + max(FIT_GRAINS, L) + T) + 20
      grains, T = ln(1/END_FRACTION)/q (≥ 10) grains of the transmitted wave's tail
      (energy of the last ten grains below :data:`hertzchain.measure.END_FRACTION` of
      the total).

    In the sonic vacuum the tail is doubly exponential (no q): L = CROSSING_GRAINS, T = 10.

    Returns
    -------
    dict
        ``delta0_over_d``, ``strain_max`` (ξ_m/d), ``n_left``, ``n_right``, ``center``,
        ``t_end`` (s, rounded up to 3 digits), and ``speed`` (m/s), ``tail_rate`` (q, 1/grain;
        inf at δ0 = 0), ``crossing`` (L, grains) for the record.
    """
    from scipy.optimize import brentq

    import theory

    from ..measure import CROSSING_GRAINS, END_FRACTION, SEPARATION

    mat, d = theory.PAPER_MATERIAL, theory.PAPER_DIAMETER
    k, m = theory.hertz_constant(d, mat), theory.grain_mass(d, mat.density)
    d0 = float(delta0_over_d) * d
    strain = SONIC_STRAIN if d0 == 0 else float(
        f"{float(strain_over_delta0) * float(delta0_over_d):.12g}")
    wave = theory.discrete_solitary_wave(k, m, d, d0, amplitude=strain * d)
    if d0 > 0:
        ratio = wave.speed / float(theory.c0(k, m, d, d0))
        q = 2.0 * brentq(lambda x: math.sinh(x) / x - ratio, 1e-12, 60.0, xtol=1e-14)
        cross = max(CROSSING_GRAINS, math.log(1.0 / SEPARATION) / q)
        tail = max(10.0, math.log(1.0 / END_FRACTION) / q)
    else:
        q, cross, tail = math.inf, CROSSING_GRAINS, 10.0
    half = wave.z.size // wave.points_per_grain // 2 + 5
    after = cross + max(FIT_GRAINS, cross)
    center = math.ceil(half + after) + 20
    t_end = (half + after) * d / wave.speed
    digits = 10 ** (math.floor(math.log10(t_end)) - 2)
    return {"delta0_over_d": float(delta0_over_d), "strain_max": strain,
            "n_left": center + half, "n_right": math.ceil(SPEED_RATIO * (after + tail)) + 20,
            "center": center,
            "t_end": float(f"{math.ceil(t_end / digits) * digits:.3g}"),
            "speed": wave.speed, "tail_rate": q, "crossing": cross}


class _Table(dict):
    """Columns by name, the interface :mod:`hertzchain.sweep_plot` reads (``len`` = rows)."""

    attrs: dict

    def __len__(self) -> int:
        return len(next(iter(self.values()))) if dict.__len__(self) else 0


def _points(ctx: Context) -> list:
    """The :data:`QUICK` (``--quick``) or :data:`FULL` (``--full``) subset of the sweep's points."""
    import dataclasses

    spec = load_sweep_spec(files("hertzchain") / "sweeps" / "model_validity.toml")
    q = dict(FULL if ctx.mode == "full" else QUICK)
    rows = [j for j, (amp, _) in enumerate(AMPLITUDES) if amp in q["amplitudes"]]
    new = {"alpha_rho_R": q["alpha_rho"], "alpha_kn_R": q["alpha_kn"]}
    axes = tuple(dataclasses.replace(a, values=new[a.name]) if a.name in new else
                 dataclasses.replace(a, values=tuple(a.values[j] for j in rows))
                 for a in spec.axes)
    return dataclasses.replace(spec, axes=axes, _points=[]).points()


_COLUMNS = ("incident_strain_over_delta0", "continuum_error", "theory_error",
            "continuum_energy", "continuum_speed", "theory_energy", "theory_speed")
_TEXT = ("continuum_model", "continuum_stopped_by", "continuum_note", "theory_note")
_KEYS = ("alpha_rho", "alpha_kn", "delta0_over_d", *_COLUMNS, *_TEXT)
ROW_KEPT = "validity-row/1"
"""Names what :func:`_row` keeps (:func:`.common.run_point_cached`): bump the version
whenever :func:`_row`, the columns or :func:`hertzchain.compare.analyse`'s measurements
change, so that no row of the old kind is reused."""
"""The table's columns, in order (a reused row comes back with its keys sorted)."""


def _row(result) -> dict:
    """One point's row of the table: the interface, δ0 and the models' errors."""
    s = analyse(result).summary()
    sc = result.scenario
    return {"alpha_rho": float(sc.chain.sections[1].alpha_rho),
            "alpha_kn": float(sc.chain.sections[1].alpha_kn),
            "delta0_over_d": float(sc.chain.delta0_over_d),
            **{k: float(s.get(k, math.nan)) for k in _COLUMNS},
            **{k: str(s.get(k, "")) for k in _TEXT}}


def run(ctx: Context) -> _Table:
    """Compare every model at each point; a table of the errors and amplitudes.

    Each point's row is kept in ``runs/validity-point-<hash>.h5``
    (:func:`.common.run_point_cached`: the scenario and the row; a rerun reuses it): the
    runs themselves are compared in memory and not written (measured, issue 13,
    ``--full``'s 16 points: writing them took 5.2 s of the item's 25-29 s).
    """
    from .common import tqdm_iter

    rows = []
    points = _points(ctx)
    for p in tqdm_iter(ctx, points, desc="validity", total=len(points)):
        ctx.log(f"validity: {p.label()}")
        rows.append(run_point_cached(ctx, "validity-point", p.scenario, _row,
                                     kept=ROW_KEPT)[0])
    table = _Table({k: np.array([r[k] for r in rows]) for k in _KEYS})
    table.attrs = {"name": f"model validity (--{ctx.mode})", "n_ok": len(rows),
                   "n_failed": 0}
    return table


def figures(ctx: Context, table: _Table) -> list:
    """Save ``validity.png`` (:func:`hertzchain.sweep_plot.validity_figure`)."""
    from ..sweep_plot import validity_figure

    path = save_figure(ctx, validity_figure(table), "validity", dpi=90)
    return [(path, "Model validity: error of the continuum (top) and of the theory "
             "(bottom) against the discrete chain, in %, over (α_ρ, α_kn) at each "
             "incident strain / δ0 (columns; the sonic vacuum last), and the largest / "
             "median over the ratios against the amplitude (right; dotted: 1 % and "
             "10 %).")]


def report(rep, table: _Table, figs: list) -> None:
    """Add the model-validity section."""
    from ..sweep_plot import validity_summary

    rep.heading("Beyond the paper — where the continuum and the theory hold")
    summary = validity_summary(table)
    full = "full" in table.attrs.get("name", "")
    q = FULL if full else QUICK
    rep.paragraph(
        f"The map of --{'full' if full else 'quick'}: α_ρ = "
        + ", ".join(f"{a:g}" for a in q["alpha_rho"]) + " and α_kn = "
        + ", ".join(f"{a:g}" for a in q["alpha_kn"]) + " at incident strain / δ0 = "
        + ", ".join("the sonic vacuum" if math.isinf(a) else f"{a:g}"
                    for a in q["amplitudes"])
        + ".  The shipped map, 5 × 5 interfaces × 7 amplitudes from 1e-3 to the sonic "
        "vacuum (175 points, about an hour on two cores), is a sweep of its own: "
        "hertzchain sweep model_validity, then hertzchain plot-sweep.")
    rows = [[r["model"] + (f" ({r['equation'].replace('eq', 'Eq. ')})"
                           if r["equation"] else ""),
             "sonic vacuum" if math.isinf(r["strain_over_delta0"])
             else f"{r['strain_over_delta0']:.2g}", r["n"], r["within_1"], r["within_10"],
             r["not_compared"], f"{100 * r['max_error']:.2g} %"
             if math.isfinite(r["max_error"]) else "—"]
            for r in summary]
    rep.table(["model", "incident strain / δ0", "points", "within 1 %", "within 10 %",
               "not compared", "largest error"], rows,
              caption="Error: the largest of |ΔE_T|, |ΔE_R| over the incident energy and the "
              "relative transmitted front speed, against the discrete chain")
    why = sorted({f"{r['model']} at strain/δ0 = {r['strain_over_delta0']:.2g}: "
                  f"{r['reasons']}" for r in summary if r["reasons"]})
    rep.paragraph(
        f"Thresholds {100 * THRESHOLDS[0]:.0f} % and {100 * THRESHOLDS[1]:.0f} %: the paper "
        "prints Table 2 to two digits and its speeds to about 1 %, so a model within 1 % "
        "reproduces the paper's numbers; within 10 % it gives the right wave pattern with "
        "numbers to one digit (a qualitative model).  Each amplitude has its own chain, "
        "exact incident wave and run length (hertzchain.reproduce.validity.amplitude_row: "
        "the wave's width grows as (strain/δ0)^(-1/2), up to 2,872 | 2,492 grains at 1e-3); "
        "a point is compared only once the incident wave has crossed the interface (all "
        "but 1e-4 of its energy) and before any wave reaches a chain end — otherwise it is "
        "not compared, with the reason" + (f" ({'; '.join(why)})" if why else "")
        + ".  \"auto\" runs Eq. 4 only up to an incident strain/δ0 of "
        f"{AUTO_EQ4_MAX_STRAIN:g} (its quadratic Hertz force is 0.8 % off there, and its "
        "flux is ill-posed once the strain passes −2δ0) and Eq. 7 above it.")
    for path, caption in figs:
        rep.figure(path, caption)


def to_json(table: _Table) -> dict:
    """The errors per point and the per-amplitude counts."""
    from ..sweep_plot import validity_summary

    def num(x):
        x = float(x)
        return x if math.isfinite(x) else None

    return {"points": [{k: (str(v[i]) if k in _TEXT else num(v[i])) for k, v in table.items()}
                       for i in range(len(table))],
            "summary": [{k: (num(v) if isinstance(v, float) else v) for k, v in r.items()}
                        for r in validity_summary(table)]}
