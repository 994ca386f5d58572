r"""Beyond the paper: the model-validity map — where the continuum and the theory hold.

The continuum (``"auto"``, hertzchain's one rule
:meth:`hertzchain.scenario.ModelsSpec.continuum_model`: corrected Eq. 4 under
precompression up to an incident strain/δ0 of
:data:`hertzchain.scenario.AUTO_EQ4_MAX_STRAIN`, Eq. 7 above it, and on lossless chains
from :data:`hertzchain.scenario.AUTO_QC_MIN_STRAIN` and at δ0 = 0 the grain-averaged
quasi-continuum ``"qc"``) and the theory are measured against the
discrete chain (paper Eq. 2) over the interface ratios (α_ρ, α_kn), the amplitude
(incident strain / δ0 from 1e-3 to 100 and the sonic vacuum, :data:`AMPLITUDES`), the
contact law's exponent n (:data:`EXPONENTS`) and an on-site drag (:data:`DAMPINGS`). The
error of a model: the largest of |ΔE_T|, |ΔE_R| (total energy over the incident energy)
and the relative transmitted front speed (:mod:`hertzchain.compare`); NaN, with the
reason, where a measurement window does not hold ("not compared") or where the model
does not apply to the point ("does not apply", with the reason; the point is kept, not
dropped).

**The theory** is regime-aware (docs/physics.md §16):
:func:`theory.strong_interface.predict_strong` with ``theory="auto"`` — lattice acoustics
below an incident strain/δ0 of :data:`theory.strong_interface.STRONG_THRESHOLD`, the
quasi-particle theory above it and in the sonic vacuum — read through one adapter,
:func:`theory_prediction`; every point records which theory answered
(``theory_model``).  Its transmitted speed is ``speed_ratio`` × the exact incident
wave's speed, its energies are taken at face value.  It is lossless: on the damping
axis the map measures how far a lossless prediction holds.

**The continuum** runs wherever hertzchain admits it: the point's scenario with
``[models] continuum`` as "auto" resolves it (:func:`with_models`) is validated by
:func:`hertzchain.scenario.parse_scenario`, which refuses a model that does not apply to
the chain with the reason of hertzchain's one applicability rule; that refusal is the
point's "does not apply" reason.

Each point is the shipped sweep's scenario (``hertzchain/sweeps/model_validity.toml``,
its linked rows :func:`law_rows`) run through the one run path
(:func:`.common.run_point_cached` here, :func:`validity_point` in the sweep: sampled
discrete chain and continuum in memory) and compared by
:func:`hertzchain.compare.analyse`.  ``--quick``: one interface at three amplitudes of
the lossless Hertz chain (:data:`QUICK`); ``--full``: the four corner interfaces at four
amplitudes, and one interface at n = 2, 5/2 and at three drag levels (:data:`FULL`); the
shipped map (5 × 5 interfaces × 7 amplitudes × 3 exponents × 4 drag levels) is
``hertzchain sweep model_validity --point-function
hertzchain.reproduce.validity:validity_point``, not part of ``reproduce``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from importlib.resources import files

import numpy as np

from ..compare import THRESHOLDS, analyse
from ..scenario import AUTO_EQ4_MAX_STRAIN, AUTO_QC_MIN_STRAIN, ModelsSpec, ScenarioError
from ..sweep.spec import load_sweep_spec
from .common import Context, run_point_cached, save_figure

__all__ = ["QUICK", "FULL", "Block", "AMPLITUDES", "EXPONENTS", "DAMPINGS", "amplitude_row",
           "law_rows", "linked_axes_toml", "DoesNotApply", "TheoryPrediction",
           "theory_prediction", "theory_errors", "with_models",
           "longer_run",
           "validity_point", "run",
           "figures", "report", "to_json", "error_table"]


@dataclass(frozen=True)
class Block:
    """A product of the shipped sweep's values: interfaces × amplitudes × exponents × drags.

    ``amplitudes``: incident strain / δ0 (inf: the sonic vacuum), values of
    :data:`AMPLITUDES`; ``exponents`` of :data:`EXPONENTS`; ``dampings`` of
    :data:`DAMPINGS` (β·t_end).
    """

    alpha_rho: tuple[float, ...]
    alpha_kn: tuple[float, ...]
    amplitudes: tuple[float, ...]
    exponents: tuple[float, ...] = (1.5,)
    dampings: tuple[float, ...] = (0.0,)


QUICK: tuple[Block, ...] = (Block((2.0,), (0.5,), (1e-2, 0.09, math.inf)),)
"""The coarse map of ``--quick``: one interface (γ_c0 = 0.56, γ_RG = 1.12) of the lossless
Hertz chain at three of the shipped sweep's amplitudes (incident strain / δ0; inf: the
sonic vacuum)."""
FULL: tuple[Block, ...] = (
    Block((0.25, 4.0), (0.25, 4.0), (1e-2, 0.09, 1.0, math.inf)),
    Block((2.0,), (0.5,), (0.09, 9.0, math.inf), exponents=(2.0, 2.5)),
    Block((2.0,), (0.5,), (0.09, math.inf), dampings=(0.01, 0.1, 1.0)))
"""The map of ``--full``: the four corner interfaces of the shipped sweep (the strongest
contrasts, where both models are worst) at four amplitudes of the lossless Hertz chain;
the ``--quick`` interface for the laws n = 2 and 5/2 (weakly, strongly nonlinear, sonic
vacuum) and for the three drag levels (paper's amplitude, sonic vacuum).  The shipped
map is a sweep of its own, not part of ``reproduce``, which stays a few minutes."""


AMPLITUDES = ((1e-3, 1e-3), (1e-2, 1e-3), (0.09, 1e-3), (1.0, 1e-3), (9.0, 1e-4),
              (100.0, 1e-5), (math.inf, 0.0))
"""The map's amplitudes: (incident strain / δ0, δ0/d); ``inf``: the sonic vacuum, δ0 = 0.

Everything in a power-law chain scales with the strain amplitude over δ0 alone (the force
k δ0^n (1 + ξ/δ0)^n; time in units of the contact period), so the models' errors, the
wave's width in grains and the steps per grain travelled depend on ξ_m/δ0 only, not on
how it is reached.  The amplitude is set by the exact discrete solitary wave's peak
strain (``[initial] kind = "exact_wave"``, ``strain_max``) and δ0 is chosen so that the
wave's overlap stays ≤ 1e-3 d (Hertz's small-strain range; grain velocities ≤ 1 m/s, the
paper's scale): the paper's δ0/d = 1e-3 up to ξ_m/δ0 = 1, smaller δ0 above.  The other
way, ξ_m/δ0 = 1e-3 at the paper's v0 = 1 m/s would need δ0/d ≈ 0.04, outside Hertz's
range, and an impact wave that settles over far more than 10,000 grains."""
EXPONENTS = (1.5, 2.0, 2.5)
"""Exponents n of the contact law F = k δ^n (``[chain] exponent``; 3/2: Hertz's spheres, 2:
cones, 5/2 between; Nesterenko 2001, §1.1).  The chain's k is the paper's Hertz constant
in N/m^n; only ξ_m/δ0 and n enter the errors."""
DAMPINGS = (0.0, 0.01, 0.1, 1.0)
"""Drag levels β·t_end: the on-site drag −m β v (``[chain] drag`` = β, 1/s) times the
point's run length, i.e. the velocity e-foldings a free grain would lose over the run
(lossless; weak, 1 %; moderate, 10 %; strong, one e-folding).  A wave of energy E loses
it at 2β E_kin (E_kin ≈ E/2 for a weakly nonlinear wave, (n+1)/(n+3) E in the sonic
vacuum, :func:`theory.dissipation.drag_wave_decay`), so β·t_end is about the fraction of
its energy the incident wave has lost by the end of the run at the weak levels; the
run length is in units of the wave's own crossing (:func:`amplitude_row`), so one level
means the same damping at every amplitude."""
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


@functools.lru_cache(maxsize=64)
def _amplitude_row(strain_over_delta0: float, delta0_over_d: float, exponent: float) -> tuple:
    from scipy.optimize import brentq

    import theory

    from ..measure import CROSSING_GRAINS, END_FRACTION, SEPARATION

    mat, d = theory.PAPER_MATERIAL, theory.PAPER_DIAMETER
    k, m = theory.hertz_constant(d, mat), theory.grain_mass(d, mat.density)
    d0 = delta0_over_d * d
    strain = SONIC_STRAIN if d0 == 0 else float(f"{strain_over_delta0 * delta0_over_d:.12g}")
    wave = theory.discrete_solitary_wave(k, m, d, d0, amplitude=strain * d, exponent=exponent)
    if d0 > 0:
        ratio = wave.speed / float(theory.c0(k, m, d, d0, exponent=exponent))
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
    return (("delta0_over_d", float(delta0_over_d)), ("strain_max", strain),
            ("n_left", center + half),
            ("n_right", math.ceil(SPEED_RATIO * (after + tail)) + 20), ("center", center),
            ("t_end", float(f"{math.ceil(t_end / digits) * digits:.3g}")),
            ("speed", float(wave.speed)), ("tail_rate", q), ("crossing", cross))


def amplitude_row(strain_over_delta0: float, delta0_over_d: float, exponent: float = 1.5
                  ) -> dict:
    r"""Chain, wave and run length for one amplitude and law of the map (the TOML's rows).

    From the exact discrete solitary wave of the paper's grains (:data:`theory.PAPER_MATERIAL`,
    :data:`theory.PAPER_DIAMETER`, :func:`theory.discrete_solitary_wave` for F = k δ^n) at
    that amplitude, with speed V, and — under precompression — the decay rate q (per grain)
    of its strain tail e^{-q|z|}, from the lattice's linear dispersion at the wave speed,
    sinh(q/2)/(q/2) = V/c0, c0 = d (n k δ0^{n-1}/m)^{1/2} (:func:`theory.c0`; q ≈
    √(2 ξ_m/δ0) for small Hertz amplitudes: the KdV width 2/q):

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

    Parameters
    ----------
    strain_over_delta0 : float
        Incident ξ_m/δ0 (ignored at δ0 = 0: the wave's strain is :data:`SONIC_STRAIN`).
    delta0_over_d : float
        δ0/d of the left section (0: the sonic vacuum).
    exponent : float
        n of the contact law, in (1, 10].

    Returns
    -------
    dict
        ``delta0_over_d``, ``strain_max`` (ξ_m/d), ``n_left``, ``n_right``, ``center``,
        ``t_end`` (s, rounded up to 3 digits), and ``speed`` (m/s), ``tail_rate`` (q, 1/grain;
        inf at δ0 = 0), ``crossing`` (L, grains) for the record.
    """
    return dict(_amplitude_row(float(strain_over_delta0), float(delta0_over_d),
                               float(exponent)))


def law_rows() -> list[dict]:
    """The shipped sweep's cases in its order: every exponent × amplitude × drag level.

    Each row: :func:`amplitude_row` for (:data:`AMPLITUDES`, n) plus ``exponent``,
    ``strain_over_delta0``, ``damping`` (β·t_end, :data:`DAMPINGS`) and ``drag`` = β =
    damping / t_end (1/s, three digits); the TOML's linked axes are these columns (a test
    checks them).  Order: exponent, then amplitude, then drag level.
    """
    rows = []
    for n in EXPONENTS:
        for amp, d0 in AMPLITUDES:
            row = amplitude_row(amp, d0, n)
            for damping in DAMPINGS:
                drag = float(f"{damping / row['t_end']:.3g}") if damping else 0.0
                rows.append({**row, "exponent": n, "strain_over_delta0": amp,
                             "damping": damping, "drag": drag})
    return rows


_LINKED = (("delta0", "chain.delta0_over_d", "delta0_over_d"),
           ("exponent", "chain.exponent", "exponent"), ("drag", "chain.drag", "drag"),
           ("strain_max", "initial.strain_max", "strain_max"),
           ("n_left", "chain.sections.0.n", "n_left"), ("n_right", "chain.sections.1.n", "n_right"),
           ("center", "initial.center", "center"), ("t_end", "run.t_end", "t_end"))
"""The sweep's case axes: (name, path, column of :func:`law_rows`); the first leads."""


def linked_axes_toml() -> str:
    """The ``[[sweep.axes]]`` tables of the shipped sweep's cases (:func:`law_rows`), as TOML.

    What ``hertzchain/sweeps/model_validity.toml`` holds after its two interface axes;
    regenerate it with this when the sizing rule (:func:`amplitude_row`) changes.
    """
    import textwrap

    def fmt(v) -> str:
        s = f"{v:g}" if isinstance(v, float) else str(v)
        return s + ".0" if isinstance(v, float) and not any(c in s for c in ".e") else s

    rows = law_rows()
    out = []
    for i, (name, path, col) in enumerate(_LINKED):
        text = textwrap.fill(", ".join(fmt(r[col]) for r in rows), 86,
                             initial_indent="  ", subsequent_indent="  ")
        out.append("[[sweep.axes]]\n" f'path = "{path}"\nname = "{name}"\n'
                   + ("" if i == 0 else 'with = "delta0"\n') + f"values = [\n{text}]\n")
    return "\n".join(out)


# -- the models of a point ----------------------------------------------------------------
class DoesNotApply(ValueError):  # noqa: N818 - a reason, not a failure
    """A model does not apply to a point; the message is the reason."""


@dataclass(frozen=True)
class TheoryPrediction:
    """The theory's numbers for one point (:func:`theory_prediction`).

    Attributes
    ----------
    energy_transmission, energy_reflection : float
        Total energy right and left of the interface over the incident energy.
    speed_transmitted : float
        Speed of the transmitted front, m/s.
    model : str
        The theory that answered (``"quasi-particle"``, ``"lattice acoustics"``).
    """

    energy_transmission: float
    energy_reflection: float
    speed_transmitted: float
    model: str


def theory_prediction(result) -> TheoryPrediction:
    """The map's theory for a run (the one adapter: compare's TheoryModel may replace it).

    :func:`theory.strong_interface.predict_strong` (``theory="auto"``) at the first
    interface of ``result`` (a :class:`hertzchain.models.Run`): α_ρ = m_R/m_L and
    α_kn = k_R/k_L read off the built chain (contacts inside each section), the incident
    amplitude ξ_m/δ0 of the exact wave placed in the left section (its peak dynamic overlap
    over that section's δ0; inf at δ0 = 0), the law's exponent n.  The transmitted speed
    is ``speed_ratio`` × the exact incident wave's speed (m/s), the energies are its
    E_T, E_R (docs/physics.md §16).  The prediction is lossless whatever the chain's drag.

    Raises
    ------
    DoesNotApply
        No interface; an incident wave that is not the exact solitary wave; sections of
        different diameters; or outside predict_strong's domain (its message: n ≠ 3/2
        under precompression).
    """
    from theory.strong_interface import predict_strong

    from ..runner import build_law

    i = result.interface
    if i is None:
        raise DoesNotApply("the chain has no interface")
    params = result.initial.params or {}
    if params.get("kind") != "exact_wave":
        raise DoesNotApply("the theory takes the exact incident solitary wave "
                           "([initial] kind = 'exact_wave')")
    chain = result.chain
    if chain.diameter[i - 1] != chain.diameter[i]:
        raise DoesNotApply("the sections' grain diameters differ (the theory is for "
                           "equal diameters)")
    d0 = float(chain.delta0[i - 1])
    eps = math.inf if d0 == 0 else float(params["amplitude"]) / d0
    n = build_law(result.scenario.chain)[0].exponent
    try:
        p = predict_strong(float(chain.mass[i]) / float(chain.mass[i - 1]),
                           float(chain.k[i + 1]) / float(chain.k[i - 1]), eps, exponent=n)
    except ValueError as exc:
        raise DoesNotApply(str(exc)) from None
    return TheoryPrediction(p.energy_transmission, p.energy_reflection,
                            p.speed_ratio * float(params["speed"]), p.theory)


def theory_errors(cmp) -> dict:
    """The theory's error against the discrete chain of a comparison, in compare's windows.

    The error of :mod:`hertzchain.compare` (the continuum's): the largest of |ΔE_T| and
    |ΔE_R| (total energy over the incident energy, the discrete chain's at the comparison
    time) and the relative transmitted front speed (the discrete chain's fitted from the
    crossing to the comparison time), each only inside its measurement window
    (:meth:`hertzchain.compare.Comparison.windows`).  Returns ``energy``, ``speed``,
    ``error`` (NaN unless both were measured), ``note`` (why NaN: outside a window, or
    "does not apply: ..."), ``model`` (the theory that answered, :func:`theory_prediction`)
    and ``applies``.
    """
    from ..measure import FIT_FROM

    nan = math.nan
    try:
        pred = theory_prediction(cmp.run)
    except DoesNotApply as exc:
        return {"energy": nan, "speed": nan, "error": nan, "note": f"does not apply: {exc}",
                "model": "", "applies": False}
    win = cmp.windows()
    disc = cmp.series["discrete"]
    why, energy, speed = [], nan, nan
    if win["all"] or win["energy"]:
        why.append(win["all"] or win["energy"])
    else:
        got = disc.ratios_at(cmp.i_compare)
        energy = max(abs(pred.energy_transmission - got["Et_tr"]),
                     abs(pred.energy_reflection - got["Et_re"]))
    v = disc.speeds["transmitted"]
    if win["all"]:
        pass
    elif not math.isfinite(pred.speed_transmitted):
        why.append("no transmitted front speed: the theory predicts none")
    elif math.isfinite(v) and v != 0:
        speed = abs(pred.speed_transmitted / v - 1.0)
    else:
        why.append(f"no transmitted front speed: fewer than 3 samples of the discrete "
                   f"chain's front >= {FIT_FROM} grains past the interface between the "
                   "crossing and the comparison time")
    return {"energy": energy, "speed": speed, "error": nan if why else max(energy, speed),
            "note": "; ".join(why), "model": pred.model, "applies": True}


def with_models(scenario):
    """The point's scenario with every model that applies, and why the continuum does not.

    The continuum is ``"auto"``, resolved here by hertzchain's one rule
    (:meth:`hertzchain.scenario.ModelsSpec.continuum_model`) at the exact incident
    wave's strain/δ0 (``[initial] strain_max``; the run resolves it again at the
    measured one, the same to round-off): where it picks the quasi-continuum the point
    names ``"qc"``.  Every model steps with its own method and dt_safety
    (:meth:`hertzchain.scenario.ModelsSpec.continuum_step`; the quasi-continuum's
    position Verlet at 0.8, docs/physics.md §24).  It is switched on if hertzchain's
    rule admits it (:func:`hertzchain.scenario.parse_scenario`, via
    :meth:`hertzchain.scenario.Scenario.with_values`); its refusal is returned as the
    reason ("" when it runs).  The closed-form TheoryModel is off: the map's theory is
    :func:`theory_prediction`.

    Returns
    -------
    (Scenario, str)
    """
    d0 = float(scenario.chain.delta0_over_d)
    strain = scenario.initial.strain_max
    resolved = ModelsSpec(continuum="auto").continuum_model(
        scenario.chain, strain / d0 if strain is not None and d0 > 0 else None)
    model = "qc" if resolved == "qc" else "auto"
    try:
        return scenario.with_values({"models.continuum": model, "models.theory": False}), ""
    except ScenarioError as exc:
        return (scenario.with_values({"models.continuum": False, "models.theory": False}),
                str(exc))


_COLUMNS = ("exponent", "damping", "incident_strain_over_delta0", "continuum_error",
            "theory_error", "continuum_energy", "continuum_speed", "theory_energy",
            "theory_speed")
_TEXT = ("continuum_model", "continuum_stopped_by", "continuum_note", "theory_note",
         "theory_model")
_FLAGS = ("continuum_applies", "theory_applies")
_KEYS = ("alpha_rho", "alpha_kn", "delta0_over_d", *_COLUMNS, *_TEXT, *_FLAGS)
"""The table's columns, in order (a reused row comes back with its keys sorted)."""
ROW_KEPT = "validity-row/3"
"""Names what :func:`_row` keeps (:func:`.common.run_point_cached`): bump the version
whenever :func:`_row`, the columns or :func:`hertzchain.compare.analyse`'s measurements
change, so that no row of the old kind is reused."""


def _models_row(cmp, continuum_reason: str) -> dict:
    """The point's model columns: errors, notes, which models apply and which theory ran."""
    s = cmp.summary()
    sc = cmp.run.scenario
    out = {k: float(s.get(k, math.nan)) for k in
           ("continuum_error", "continuum_energy", "continuum_speed")}
    out.update({k: str(s.get(k, "")) for k in
                ("continuum_model", "continuum_stopped_by", "continuum_note")})
    if continuum_reason:
        out["continuum_note"] = f"does not apply: {continuum_reason}"
    th = theory_errors(cmp)
    out.update(theory_error=th["error"], theory_energy=th["energy"], theory_speed=th["speed"],
               theory_note=th["note"], theory_model=th["model"],
               continuum_applies=not continuum_reason, theory_applies=th["applies"],
               damping=float(sc.chain.drag) * float(sc.run.t_end or 0.0))
    return out


def longer_run(result, cmp) -> dict | None:
    r"""A longer run for a point whose waves had not left the interface, or None.

    The map's run length is set per amplitude row (:func:`amplitude_row`, at the incident
    speed V); light → heavy onto a soft side the transmitted wave is much slower, and the
    discrete run's waves may not have separated from the interface
    (:func:`hertzchain.measure.separated_by`) by its end, so the energies are not
    compared.  Only for such a point: the run is stretched by the slowest transmitted
    speed, t_end → t_end V / V_T (V_T from :func:`theory_prediction`), so that the
    transmitted wave covers the grains past the interface the row's run gives a wave at
    V, and the left section (with the wave's placement) grows by V (t'_end − t_end) + 5
    grains so that the reflected wave, at most as fast as V, still does not reach the
    left end.  Every other point keeps its run; so do chains with drag (their damping
    level β·t_end is the run's).

    Returns
    -------
    dict or None
        ``Scenario.with_values`` keys (``run.t_end``, ``chain.sections.0.n``,
        ``initial.center``), or None: compared, or no prediction (the theory does not
        apply) or no slower transmitted wave.
    """
    sc = result.scenario
    if (result.interface is None or result.discrete is None or sc.chain.drag
            or cmp.i_compare < cmp.i_cross or cmp.t_separated <= cmp.t_compare):
        return None
    try:
        pred = theory_prediction(result)
    except DoesNotApply:
        return None
    v_in = float((result.initial.params or {})["speed"])
    if not 0 < pred.speed_transmitted < v_in:
        return None
    t_end = float(sc.run.t_end)
    t_new = t_end * v_in / pred.speed_transmitted
    digits = 10 ** (math.floor(math.log10(t_new)) - 2)
    t_new = float(f"{math.ceil(t_new / digits) * digits:.3g}")
    grains = math.ceil(v_in * (t_new - t_end) / float(result.chain.diameter[0])) + 5
    return {"run.t_end": t_new, "chain.sections.0.n": int(sc.chain.sections[0].n) + grains,
            "initial.center": int(sc.initial.center) + grains}


def _row(result, continuum_reason: str = "") -> dict:
    """One point's row of the table: the interface, the law, δ0 and the models' errors.

    Plus ``"longer"``: :func:`longer_run`'s keys (None: the run stands).
    """
    cmp = analyse(result)
    sc = result.scenario
    row = {"alpha_rho": float(sc.chain.sections[1].alpha_rho),
           "alpha_kn": float(sc.chain.sections[1].alpha_kn),
           "delta0_over_d": float(sc.chain.delta0_over_d),
           "exponent": float(sc.chain.exponent),
           "incident_strain_over_delta0": float(cmp.summary().get(
               "incident_strain_over_delta0", math.nan)),
           **_models_row(cmp, continuum_reason)}
    return {**{k: row[k] for k in _KEYS}, "longer": longer_run(result, cmp)}


def validity_point(scenario, *, out=None, progress: bool = False) -> dict:
    """Sweep point function of the map: every model that applies, compared; a flat summary.

    The signature of :data:`hertzchain.sweep.engine.DEFAULT_POINT_FUNCTION`
    (``hertzchain sweep model_validity --point-function
    hertzchain.reproduce.validity:validity_point``): the scenario with the models of
    :func:`with_models`, run by :func:`hertzchain.models.run` (sampled), compared by
    :func:`hertzchain.compare.analyse`; the summary is the comparison's, with the map's
    columns (:func:`theory_errors`, ``damping``, ``continuum_applies``, ``theory_applies``,
    ``theory_model``; the continuum's note says why it does not apply).  A point whose
    waves had not left the interface by the row's run length is run again, longer
    (:func:`longer_run`).
    """
    from ..models import run as run_models

    sc, reason = with_models(scenario)
    result = run_models(sc, out=out, progress=progress, samples=True)
    if result.discrete is None or not result.discrete.completed:
        return result.summary()
    cmp = analyse(result)
    longer = longer_run(result, cmp)
    if longer:  # the waves had not left the interface: a longer run
        result = run_models(sc.with_values(longer), out=out, progress=progress,
                            samples=True)
        if result.discrete is None or not result.discrete.completed:
            return result.summary()
        cmp = analyse(result)
    return {**cmp.summary(), **_models_row(cmp, reason)}


# -- reproduce's item -----------------------------------------------------------------------
class _Table(dict):
    """Columns by name, the interface :mod:`hertzchain.sweep_plot` reads (``len`` = rows)."""

    attrs: dict

    def __len__(self) -> int:
        return len(next(iter(self.values()))) if dict.__len__(self) else 0


def _cases() -> list[tuple[float, float, float]]:
    """(exponent, strain/δ0, damping) of each value of the sweep's case axes, in order."""
    return [(r["exponent"], r["strain_over_delta0"], r["damping"]) for r in law_rows()]


def _blocks(ctx: Context) -> tuple[Block, ...]:
    return FULL if ctx.mode == "full" else QUICK


def _points(ctx: Context) -> list:
    """The :data:`QUICK` (``--quick``) or :data:`FULL` (``--full``) points of the sweep."""
    import dataclasses

    spec = load_sweep_spec(files("hertzchain") / "sweeps" / "model_validity.toml",
                           validate_points=False)
    cases = _cases()
    points = []
    for b in _blocks(ctx):
        keep = [j for j, (n, amp, damp) in enumerate(cases)
                if n in b.exponents and amp in b.amplitudes and damp in b.dampings]
        new = {"alpha_rho_R": b.alpha_rho, "alpha_kn_R": b.alpha_kn}
        axes = tuple(dataclasses.replace(a, values=new[a.name]) if a.name in new else
                     dataclasses.replace(a, values=tuple(a.values[j] for j in keep))
                     for a in spec.axes)
        points += dataclasses.replace(spec, axes=axes, _points=[]).points()
    return points


def run(ctx: Context) -> _Table:
    """Compare every model that applies at each point; a table of the errors and amplitudes.

    Each point's row is kept in ``runs/validity-point-<hash>.h5``
    (:func:`.common.run_point_cached`: the scenario and the row; a rerun reuses it): the
    runs themselves are compared in memory and not written.
    """
    from .common import tqdm_iter

    rows = []
    points = _points(ctx)
    for p in tqdm_iter(ctx, points, desc="validity", total=len(points)):
        ctx.log(f"validity: {p.label()}")
        sc, reason = with_models(p.scenario)
        reduce = functools.partial(_row, continuum_reason=reason)
        row = run_point_cached(ctx, "validity-point", sc, reduce, kept=ROW_KEPT,
                               samples=True)[0]
        if row.get("longer"):  # the waves had not left the interface: a longer run
            row = run_point_cached(ctx, "validity-point", sc.with_values(row["longer"]),
                                   reduce, kept=ROW_KEPT, samples=True)[0]
        rows.append(row)
    table = _Table({k: np.array([r[k] for r in rows]) for k in _KEYS})
    table.attrs = {"name": f"model validity (--{ctx.mode})", "n_ok": len(rows),
                   "n_failed": 0}
    return table


def figures(ctx: Context, table: _Table) -> list:
    """Save ``validity.png`` (:func:`hertzchain.sweep_plot.validity_figure`)."""
    from ..sweep_plot import validity_figure

    path = save_figure(ctx, validity_figure(table), "validity", dpi=110)
    laws = len({(float(n), float(f"{g:.2g}")) for n, g in
                zip(table["exponent"], table["damping"], strict=True)}) > 1
    return [(path, "Model validity: error against the discrete chain of the continuum "
             "(left) and of the theory (right; the theory that answered is named over "
             "the panel) against the incident strain / δ0 of the lossless Hertz chain, "
             "the sonic vacuum on its own tick; markers by interface (colour α_ρ, shape "
             "α_kn), line: median over the interfaces; shaded: within 1 % and 10 %."
             + (" Rows below: each law (exponent n; colour: drag level β·t_end), median "
                "over the interfaces (line) and largest (marker); 'n/a': the model does "
                "not apply there." if laws else ""))]


def error_table(table) -> list[list[str]]:
    """Per model, law and amplitude: points, ≤1 %, ≤10 %, largest, median (text rows).

    :func:`hertzchain.sweep_plot.validity_summary` as the rows of the report's table:
    model (with the equation or theory that ran), n, β·t_end, incident strain / δ0, points,
    within 1 %, within 10 %, largest, median, not compared, does not apply.
    """
    from ..sweep_plot import validity_summary

    def pct(x):
        return f"{100 * x:.2g} %" if math.isfinite(x) else "—"

    rows = []
    for r in validity_summary(table):
        what = r["equation"].replace("eq", "Eq. ") if r["model"] == "continuum" \
            else r["theories"]
        rows.append([r["model"] + (f" ({what})" if what else ""), f"{r['exponent']:g}",
                     f"{r['damping']:g}",
                     "sonic vacuum" if math.isinf(r["strain_over_delta0"])
                     else f"{r['strain_over_delta0']:.2g}", r["n"], r["within_1"],
                     r["within_10"], pct(r["max_error"]), pct(r["median_error"]),
                     r["not_compared"], r["does_not_apply"]])
    return rows


ERROR_HEADER = ["model", "n", "β·t_end", "incident strain / δ0", "points", "within 1 %",
                "within 10 %", "largest", "median", "not compared", "does not apply"]
"""Columns of :func:`error_table`."""


def report(rep, table: _Table, figs: list) -> None:
    """Add the model-validity section."""
    from theory.strong_interface import STRONG_THRESHOLD

    from ..sweep_plot import validity_summary

    rep.heading("Beyond the paper — where the continuum and the theory hold")
    full = "full" in table.attrs.get("name", "")

    def amps(values):
        return ", ".join("the sonic vacuum" if math.isinf(a) else f"{a:g}" for a in values)

    parts = []
    for b in FULL if full else QUICK:
        law = ("the lossless Hertz chain" if b.exponents == (1.5,) and b.dampings == (0.0,)
               else "n = " + ", ".join(f"{n:g}" for n in b.exponents) if b.dampings == (0.0,)
               else "the Hertz chain with drag β·t_end = " + ", ".join(f"{g:g}" for g in
                                                                        b.dampings))
        parts.append(f"α_ρ = {', '.join(f'{a:g}' for a in b.alpha_rho)} and α_kn = "
                     f"{', '.join(f'{a:g}' for a in b.alpha_kn)}, {law}, at incident "
                     f"strain / δ0 = {amps(b.amplitudes)}")
    rep.paragraph(
        f"The map of --{'full' if full else 'quick'}: " + "; ".join(parts) + ".  The "
        "shipped map — 5 × 5 interfaces × 7 amplitudes from 1e-3 to the sonic vacuum × "
        "the exponents n = 1.5, 2, 2.5 × the drag levels β·t_end = 0, 0.01, 0.1, 1 "
        "(2,100 points) — is a sweep of its own: hertzchain sweep model_validity "
        "--point-function hertzchain.reproduce.validity:validity_point, then hertzchain "
        "plot-sweep.")
    rep.table(ERROR_HEADER, error_table(table),
              caption="Error: the largest of |ΔE_T|, |ΔE_R| over the incident energy and the "
              "relative transmitted front speed, against the discrete chain; n: the contact "
              "law's exponent; β·t_end: the drag over the run")
    summary = validity_summary(table)
    why = sorted({f"{r['model']} at n = {r['exponent']:g}, β·t_end = {r['damping']:g}, "
                  f"strain/δ0 = {r['strain_over_delta0']:.2g}: {r['reasons']}"
                  for r in summary if r["reasons"]})
    na = sorted({f"{r['model']}: {r['does_not_apply_reasons']}" for r in summary
                 if r["does_not_apply_reasons"]})
    rep.paragraph(
        f"Thresholds {100 * THRESHOLDS[0]:.0f} % and {100 * THRESHOLDS[1]:.0f} %: the paper "
        "prints Table 2 to two digits and its speeds to about 1 %, so a model within 1 % "
        "reproduces the paper's numbers; within 10 % it gives the right wave pattern with "
        "numbers to one digit (a qualitative model).  The theory is regime-aware "
        "(theory.strong_interface.predict_strong, docs/physics.md §16): lattice acoustics "
        f"below an incident strain/δ0 of {STRONG_THRESHOLD:g}, the quasi-particle "
        "collision of the two sections' exact solitary waves above it and in the sonic "
        "vacuum; it is lossless, so on the drag levels its error measures how far "
        "damping can be neglected.  Each amplitude and law has its own chain, exact "
        "incident wave and run length (hertzchain.reproduce.validity.amplitude_row: the "
        "wave's width grows as (strain/δ0)^(-1/2), up to 2,872 | 2,492 grains at 1e-3); "
        "a point is compared only once the incident wave has crossed the interface (all "
        "but 1e-4 of its energy) and before any wave reaches a chain end — otherwise it is "
        "not compared, with the reason" + (f" ({'; '.join(why)})" if why else "")
        + ".  \"auto\" runs Eq. 4 only up to an incident strain/δ0 of "
        f"{AUTO_EQ4_MAX_STRAIN:g} (its quadratic Hertz force is 0.8 % off there, and its "
        "flux is ill-posed once the strain passes −2δ0) and Eq. 7 above it; from "
        f"{AUTO_QC_MIN_STRAIN:g} and at δ0 = 0 it runs the grain-averaged quasi-continuum "
        "on chains without drag (Eq. 7 with drag)."
        + (f"  Where a model does not apply the point is kept and says why: "
           f"{'; '.join(na)}." if na else ""))
    for path, caption in figs:
        rep.figure(path, caption)


def to_json(table: _Table) -> dict:
    """The errors per point and the per-law, per-amplitude counts."""
    from ..sweep_plot import validity_summary

    def num(x):
        x = float(x)
        return x if math.isfinite(x) else None

    def value(k, v):
        if k in _TEXT:
            return str(v)
        if k in _FLAGS:
            return bool(v)
        return num(v)

    return {"points": [{k: value(k, v[i]) for k, v in table.items()} for i in range(len(table))],
            "summary": [{k: (num(v) if isinstance(v, float) else v) for k, v in r.items()}
                        for r in validity_summary(table)]}
