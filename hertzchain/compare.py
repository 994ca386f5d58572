r"""Discrete, continuum and theory side by side: the comparison of one scenario.

:func:`compare` runs every model of a scenario through the one run path
(:func:`hertzchain.models.run`) and analyses them at their common sample times
(:class:`Comparison`); :meth:`Comparison.write` writes ``compare.h5`` (a group per
model plus the comparison, written atomically, carrying the scenario and every
parameter), the figures and a short report.  ``hertzchain compare SCENARIO.toml --out
DIR [--json]`` is the command line.

What is measured, on every sampled model, with the discrete chain's definitions
------------------------------------------------------------------------------------
* **Energy partition**: kinetic, potential (contact energy minus static energy,
  docs/physics.md §6) and total energy left and right of the first interface (its
  contact split half and half), over the incident energies (everything left of the
  interface at t = 0; the same for every model, which starts from the same grains) —
  the paper's Table 2 definition, at every sample time.
* **Fronts** (:func:`hertzchain.measure.sample_fronts`): the peak positions (grains,
  parabola-refined) of the leading pulses of the grain kinetic energy ½mv² above
  :data:`hertzchain.measure.FRONT_THRESHOLD` of the incident wave's peak: the incident
  wave (right-most pulse left of the interface, until the crossing), the transmitted
  wave (right-most pulse right of it) and the reflected wave (left-most pulse left of
  it, after the crossing).  The crossing time (:func:`hertzchain.measure.crossing_time`)
  is the theory's arrival time of the measured incident peak at the interface plus, at
  its speed, the larger of :data:`~hertzchain.measure.CROSSING_GRAINS` and the incident
  wave's extent behind its peak (:func:`hertzchain.measure.incident_extent`: the grains
  beyond which lies only :data:`~hertzchain.measure.SEPARATION` of its energy, measured
  on the common initial state — ~20 grains for the paper's wave, ~200 at strain/δ0 =
  1e-3): from then on at most that fraction of the incident energy has still to cross.
  Front speeds (:func:`hertzchain.measure.fit_sample_speed`) are straight-line fits of
  these positions over the samples whose front is ≥ :data:`~hertzchain.measure.FIT_FROM`
  grains from the interface (transmitted and reflected: from the crossing to the
  comparison time; incident: until the theory's arrival time of its peak at the
  interface — later the right-most pulse left of it is its tail and the forming
  reflected wave).
* **Differences** to the discrete chain (the reference): E_T and E_R (kinetic,
  potential, total) at the comparison time; front positions, speeds, leading-pulse
  peaks (parabola-refined between grains) and arrival times at
  :data:`ARRIVAL_DISTANCE` grains past the interface; L2
  (relative) and L∞ (over the incident peak velocity) of v at every display time.
* **Theory**: its fronts and energy partition (:class:`hertzchain.models.TheoryModel`),
  and the speeds of Nesterenko's relation (Eq. 5 / Eq. 8 limits) at each model's
  measured transmitted and reflected amplitudes; at an interface also the strongly
  nonlinear theory (``theory_strong``: quasi-particle or lattice acoustics, named with
  its regime, docs/physics.md §16).  On a chain beyond the paper
  (:func:`_theory_beyond`) the incident wave's speed for the law's exponent and the
  chain's own theory (:class:`hertzchain.models.ChainTheory`: travel times, a damped
  peak, a striker's train) in the discrete run's own window, and for an interface no
  theory describes, null and the reason.

The comparison time is the last common sample at which no wave has reached a chain end
where the continuum's end condition differs from the discrete chain's
(:attr:`hertzchain.models.ModelRun.valid_until`, :func:`hertzchain.measure.valid_until`).
Every difference is measured at that one time ``t_compare`` (one common sample: the
kinetic/potential split of a single sample carries the lattice phase, docs/physics.md
§6), the speeds over the samples from the crossing to it; the run summary's own
numbers (``Ek_tr`` …, ``front_speed_*``, in :meth:`Comparison.summary`) are the
discrete run's, in their windows (:mod:`hertzchain.measure`: phase-averaged after the
separation, arrival-time fits on the energy grid), and the report names both.

Measurement windows (never a number from an invalid one)
---------------------------------------------------------
A model's energy partition counts only if the comparison time is at or after the
crossing and the discrete run's waves had separated from the interface by then (the
run summary's rule, :func:`hertzchain.measure.separated_by`: before, the partition is
not the scattering result yet); its transmitted speed only if at least three samples of
the front lie between the crossing and the comparison time; its reflected speed only if
the discrete run's summary measured a reflected front (``front_speed_re`` finite: a
reflected wave that is classified and travels, :mod:`hertzchain.measure`); fronts and peaks
at the comparison time only after the crossing; and nothing counts if no sample
precedes a wave's arrival at a chain end.  Outside its window a quantity, its
difference and everything derived from it are NaN (JSON null);
:attr:`Comparison.notes` (summary keys ``<model>_note``) and
:attr:`Comparison.unmeasured` say why.

Validity (:data:`THRESHOLDS`)
-----------------------------
A model's error is the largest of |ΔE_T| and |ΔE_R| (total energy, in units of the
incident energy) and the relative error of the transmitted front speed (NaN, with a
note, unless every one of them was measured; without an interface: the incident front
speed).  Within
**1 %** it is quantitatively interchangeable with the discrete chain for these
observables (the paper's own numbers differ from the linear theory by ~1e-3–1e-2,
its Table 2 reports five digits); within **10 %** it gets the physics right (which
waves, how fast, where the energy goes) but not the numbers; beyond 10 % it does not
hold.  The verdict weighs the velocity profile too: its words are those of the
largest of the error and the profile's relative L2 difference at ``t_compare`` (a
continuum whose energies agree but whose waves are elsewhere does not hold).  A model
that did not complete is not compared (its row says so); a discrete run whose numbers
are not verified to the rtol asked for (``*_meets_rtol`` false) is said so in the
verdict, and ``hertzchain compare`` exits 4 (docs/guide/exit_status.md).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import measure as M
from .compare_output import FORMAT
from .measure import CROSSING_GRAINS, FIT_FROM, SEPARATION, grain_energies
from .models import FORMED_GRAINS, ModelRun, Run, run
from .scenario import Scenario, load_scenario

__all__ = ["Comparison", "ModelSeries", "compare", "analyse", "compare_point", "THRESHOLDS",
           "ARRIVAL_DISTANCE", "FORMAT", "validity_word"]

THRESHOLDS = (0.01, 0.10)
"""Error levels of the validity statements (module docstring): within 1 %, within 10 %."""
ARRIVAL_DISTANCE = 100
"""Grains past the interface at which arrival times and front positions are compared
(fewer if the run ends earlier: 80 % of the discrete front's final distance)."""
_TABLE2 = ("Ek_tr", "Ek_re", "Ep_tr", "Ep_re", "Et_tr", "Et_re")


def validity_word(error: float) -> str:
    """"within 1 %", "within 10 %", "off by X %" or "not compared" for an error."""
    if not math.isfinite(error):
        return "not compared"
    if error <= THRESHOLDS[0]:
        return "within 1 %"
    if error <= THRESHOLDS[1]:
        return "within 10 %"
    return f"off by {100 * error:.0f} %"


MAX_LAG = 5.0
"""Largest shift, grains, :func:`shifted_profile_error` tries (either way)."""


def shifted_profile_error(v_model: np.ndarray, v_ref: np.ndarray, *,
                          max_lag: float = MAX_LAG, step: float = 0.02) -> tuple[float, float]:
    """Shape error of a velocity profile: the least relative L2 difference over shifts.

    min over s in [-max_lag, max_lag] (grains, in ``step``s) of
    ‖v_model(i + s) - v_ref(i)‖₂ / ‖v_ref‖₂, v_model between grains a cubic spline
    (0 outside the chain).  Returns (that minimum, the s that gives it;
    s > 0: the model's wave is ahead of the reference's by s grains); (NaN, NaN) for a
    reference at rest.  At s = 0 it is the plain profile L2 difference, so the minimum
    never exceeds it.
    """
    v_model = np.asarray(v_model, dtype=float)
    v_ref = np.asarray(v_ref, dtype=float)
    norm = float(np.linalg.norm(v_ref))
    if not norm or v_ref.size < 2:
        return math.nan, math.nan
    i = np.arange(v_ref.size, dtype=float)
    keep = np.abs(v_ref) + np.abs(v_model) > 0
    lo, hi = max(0, int(np.argmax(keep)) - int(max_lag) - 1), \
        min(v_ref.size, v_ref.size - int(np.argmax(keep[::-1])) + int(max_lag) + 1)
    x, ref = i[lo:hi], v_ref[lo:hi]
    rest = norm**2 - float(ref @ ref)  # (zero: every moving grain is inside the window)
    from scipy.interpolate import CubicSpline

    pad = int(max_lag) + 2  # the model's profile with zeros beyond the chain's ends
    spline = CubicSpline(np.arange(-pad, v_ref.size + pad, dtype=float),
                         np.pad(v_model, pad))
    shifts = np.arange(-max_lag, max_lag + 0.5 * step, step)
    errs = np.array([np.linalg.norm(spline(x + s) - ref) for s in shifts])
    errs = np.sqrt(errs**2 + max(rest, 0.0)) / norm
    k = int(np.argmin(errs))
    if errs[k] >= errs[np.argmin(np.abs(shifts))]:
        return float(errs[np.argmin(np.abs(shifts))]), 0.0
    return float(errs[k]), float(shifts[k])


def _verdict_part(label: str, e: dict, interface: bool, note: str = "", *,
                  beyond: bool = False) -> str:
    """The verdict's clause for one model with errors ``e`` (NaN: not measured).

    ``note``: why the error is not measured (:attr:`Comparison.notes`); ``beyond``: the
    theory of a chain beyond the paper (its error is its largest relative difference,
    ``e["speed"]``).  A finite
    ``e["profile_l2"]`` (the velocity profile's relative L2 difference at the comparison
    time) is weighed with the error: the words are those of the larger.  Where the
    shape error ``e["profile_shape_l2"]`` is known (the same difference once the model's
    profile is shifted by its best ``e["profile_lag"]`` grains,
    :func:`shifted_profile_error`) it is weighed instead, and the shift is named: a
    narrow pulse one grain behind is a position error, which the front speed measures
    already, not a wrong wave.
    """
    measures = ((("energy", "energy", "{:.1e}"), ("transmitted speed", "speed", "{:.1%}"))
                if interface else (("largest relative difference", "speed", "{:.1%}"),)
                if beyond else (("front speed", "speed", "{:.1%}"),))
    profile = e.get("profile_shape_l2", math.nan)
    if not math.isfinite(profile):
        profile = e.get("profile_l2", math.nan)
    if math.isfinite(profile):
        measures += (("velocity profile L2", "profile_l2", "{:.2g}"),)
    got = [f"{what} {fmt.format(e[key])}" for what, key, fmt in measures
           if math.isfinite(e[key])]
    lag = e.get("profile_lag", math.nan)
    if math.isfinite(lag) and lag != 0 and math.isfinite(e.get("profile_shape_l2", math.nan)):
        got = [g + (f" ({e['profile_shape_l2']:.2g} once shifted by {-lag:+.2g} grains)"
                    if g.startswith("velocity profile") else "") for g in got]
    missing = [what for what, key, _ in measures if not math.isfinite(e[key])]
    if not math.isfinite(e["error"]):
        if note:
            return (f"{label} could not be compared with the discrete chain ({note}"
                    + (f"; measured: {', '.join(got)}" if got else "") + ")")
        return (f"{label} could not be compared with the discrete chain (no "
                f"{' and no '.join(missing)} difference: a wave front or an energy was "
                "not found in one of the models)")
    worst = max(e["error"], profile) if math.isfinite(profile) else e["error"]
    text = f"{label} is {validity_word(worst)} of the discrete chain ({', '.join(got)}"
    if missing:
        text += f"; {' and '.join(missing)} not measured"
    if beyond and note:
        text += f"; not compared: {note}"
    return text + ")"


# -- per-model series ------------------------------------------------------------------
@dataclass
class ModelSeries:
    """What is measured on one sampled model at the common times (module docstring).

    ``energy`` has keys ``"<kind>_<side>"`` (kind kinetic/potential/total, side
    left/right): energy over the incident energy of that kind.  ``fronts`` has keys
    incident/transmitted/reflected (grain positions, NaN where none), ``peaks`` the
    leading pulses' peak velocities (m/s) and ``strains`` their peak dynamic strain.
    ``own_energy``: the same partition of the continuum's own conserved energy
    (:attr:`hertzchain.models.ModelRun.own_energy`; empty for the discrete chain), over
    its own incident energies.
    """

    name: str
    label: str
    times: np.ndarray
    energy: dict[str, np.ndarray]
    fronts: dict[str, np.ndarray]
    peaks: dict[str, np.ndarray]
    strains: dict[str, np.ndarray]
    speeds: dict[str, float] = field(default_factory=dict)
    completed: bool = True
    stopped_by: str = ""
    own_energy: dict[str, np.ndarray] = field(default_factory=dict)

    def ratios_at(self, i: float, *, own: bool = False) -> dict[str, float]:
        """The paper's Table-2 ratios (``Ek_tr`` … ``Et_re``) at sample ``i``.

        ``i`` may be fractional: linear interpolation between samples ⌊i⌋ and ⌊i⌋ + 1.
        Transmitted: the right of the first interface; reflected: the left (``energy``,
        or with ``own`` the model's own conserved energy, ``own_energy``).
        """
        energy = self.own_energy if own else self.energy
        if not energy:
            raise ValueError(f"{self.name}: no own energy (only a continuum has one)")
        j = min(int(math.floor(i)), self.times.size - 1)
        w = float(i) - j
        out = {}
        for key in _TABLE2:
            kind = {"k": "kinetic", "p": "potential", "t": "total"}[key[1]]
            e = energy[f"{kind}_{'right' if key.endswith('tr') else 'left'}"]
            out[key] = float(e[j] if w == 0 else (1 - w) * e[j] + w * e[j + 1])
        return out


def _partition(chain, mrun: ModelRun, iface: int | None, incident: dict, law=None) -> dict:
    kin, pot = grain_energies(chain, mrun.v, mrun.strain, law)
    n = chain.n
    i = n if iface is None else iface
    gw = (np.arange(n) < i).astype(float)
    cw = (np.arange(n + 1) < i).astype(float)
    if iface is not None:
        cw[i] = 0.5
    else:  # one section: the whole chain, its end contacts too (as _incident_energies)
        cw[:] = 1.0
    out = {}
    for side, g, c in (("left", gw, cw), ("right", 1 - gw, 1 - cw)):
        k, p = kin @ g, pot @ c
        out[f"kinetic_{side}"] = k / incident["kinetic"]
        out[f"potential_{side}"] = p / incident["potential"] if incident["potential"] else \
            np.full(k.shape, np.nan)
        out[f"total_{side}"] = (k + p) / incident["total"]
    return out


def _own_partition(mrun: ModelRun) -> dict[str, np.ndarray]:
    """:func:`_partition` of a continuum's own energy (over its own incident energies)."""
    if mrun.own_energy is None or not len(mrun.own_energy):
        return {}
    e = np.asarray(mrun.own_energy)
    k_in, p_in = e[0, 0], e[0, 2]  # everything left of the interface at t = 0
    out = {}
    for side, k, p in (("left", e[:, 0], e[:, 2]), ("right", e[:, 1], e[:, 3])):
        out[f"kinetic_{side}"] = k / k_in
        out[f"potential_{side}"] = p / p_in if p_in else np.full(k.shape, np.nan)
        out[f"total_{side}"] = (k + p) / (k_in + p_in)
    return out


def _incident_energies(chain, first: ModelRun, iface: int | None, law=None
                       ) -> dict[str, float]:
    kin, pot = grain_energies(chain, first.v[:1], first.strain[:1], law)
    i = chain.n if iface is None else iface
    k = float(kin[0, :i].sum())
    p = float(pot[0, :i].sum() + (0.5 * pot[0, i] if iface is not None else pot[0, i]))
    return {"kinetic": k, "potential": p, "total": k + p}


def _crossing(times: np.ndarray, result: Run, extent: float) -> tuple[int, float]:
    """First sample after the incident wave has crossed the interface, and that time (s).

    :func:`hertzchain.measure.crossing_time` from the theory's arrival time of the
    incident peak, which starts from the measured incident wave (a placed wave's initial
    state, an impact's snapshot on the discrete run: the same with or without a
    continuum).
    """
    est = result.estimates
    if est is None or not est.has_interface:
        return times.size, math.inf
    t = M.crossing_time(est.t_hit, extent, est.left["d"], est.speed_in)
    after = np.flatnonzero(times > t)
    return (int(after[0]) if after.size else times.size), float(t)


# -- the comparison ---------------------------------------------------------------------
@dataclass
class Comparison:
    """All models of one scenario analysed at their common times (module docstring).

    Attributes
    ----------
    run : hertzchain.models.Run
        The models' results.
    series : dict
        :class:`ModelSeries` by model name ("discrete", "continuum").
    incident : dict
        Incident kinetic, potential and total energy, J.
    i_cross : int
        First sample after the crossing of the interface.
    i_compare : int
        Sample of the comparison time.
    display : list of int
        Samples of the profile panels (before, during and after the interface).
    differences : dict
        Per model (besides the discrete chain): quantity → (discrete, model, difference).
    errors : dict
        Per model: ``energy``, ``speed``, ``error`` (the larger; NaN unless both were
        measured), ``profile_l2``.
    notes : dict
        Per model whose error is NaN: why (a measurement window that does not hold).
    extent : float
        The incident wave's :func:`incident_extent`, grains (0 for an impact).
    t_cross : float
        The crossing time, s (inf without an interface).
    window : str
        Why no sample can be compared at all ("" if some can): a wave reached a chain
        end before the first common sample.
    t_separated : float
        When the discrete run's waves had separated from the interface, read up to the
        comparison time, s (:func:`hertzchain.measure.separated_by`; NaN: they had not).
    unmeasured : dict
        Per model: quantity of :attr:`differences` → why it is NaN (outside its window).
    """

    run: Run
    series: dict[str, ModelSeries]
    incident: dict[str, float]
    i_cross: int
    i_compare: int
    display: list[int]
    differences: dict[str, dict[str, tuple]] = field(default_factory=dict)
    errors: dict[str, dict[str, float]] = field(default_factory=dict)
    profile_errors: dict[str, list[dict]] = field(default_factory=dict)
    arrival_distance: float = math.nan
    notes: dict[str, str] = field(default_factory=dict)
    extent: float = 0.0
    t_cross: float = math.inf
    window: str = ""
    t_separated: float = math.nan
    unmeasured: dict[str, dict[str, str]] = field(default_factory=dict)
    theory_window: str = ""

    # ------------------------------------------------------------------ numbers
    @property
    def scenario(self) -> Scenario:
        """The scenario."""
        return self.run.scenario

    @property
    def times(self) -> np.ndarray:
        """The common sample times, s."""
        ref = self.series.get("discrete") or next(iter(self.series.values()))
        return ref.times

    @property
    def t_compare(self) -> float:
        """The comparison time, s."""
        return float(self.times[self.i_compare])

    @property
    def unverified(self) -> list[str]:
        """The discrete run's ``*_meets_rtol`` keys that are false (not verified to rtol)."""
        disc = self.run.discrete
        return M.unverified(disc.summary) if disc is not None else []

    @property
    def measured_at(self) -> dict[str, str]:
        """When and how each kind of number is measured, in words (module docstring)."""
        s = self.run.discrete.summary if self.run.discrete is not None else {}
        return {
            "differences": f"t_compare = {self.t_compare:.6g} s, one common sample of "
                           "every model",
            "speeds": f"straight-line fits of the sampled fronts from t_cross = "
                      f"{self.t_cross:.6g} s to t_compare",
            "run_ratios": s.get("ratios_normalised_to", "") or s.get("ratios_note", ""),
            "run_front_speeds": "arrival times of the energy peak on the discrete run's "
                                "energy grid (hertzchain.measure.front_speed), rows before "
                                "a wave reached a chain end",
            "run_labels": f"the discrete run's final state, t = {s.get('t', math.nan):.6g} s"}

    def windows(self) -> dict[str, str]:
        """Why each kind of difference is outside its measurement window ("" inside).

        Keys ``all``, ``energy``, ``after``, ``reflected`` (module docstring,
        "Measurement windows"): the rule every model's error is held to, for a
        prediction made outside this comparison (the validity map's theory).
        """
        return _windows(self)

    def verdict(self) -> str:
        """One sentence: where the continuum and the theory hold for this scenario."""
        parts = []
        for name in ("continuum", "theory", "theory_strong"):
            if name not in self.errors:
                if name == "continuum" and self.run.continuum is not None:
                    parts.append(f"the continuum did not complete "
                                 f"({self.run.continuum.stopped_by}) and is not compared")
                continue
            e = self.errors[name]
            label = self.series[name].label if name in self.series else \
                self.theory_label(name)
            interface = self.run.interface is not None and (
                name != "theory" or self.run.theory.interface_theory)
            parts.append(_verdict_part(label, e, interface, self.notes.get(name, ""),
                                       beyond=name == "theory" and not interface))
        skipped = "".join(f"  Not run: the {m} ({why})." for m, why in
                          self.run.skipped.items())
        flagged = ""
        if self.unverified:
            s = self.run.discrete.summary
            flagged = (f"  The discrete chain is not verified to rtol = {s.get('rtol')!r} "
                       f"({', '.join(self.unverified)} false; split_estimate = "
                       f"{s.get('split_estimate', math.nan):.2g}): its numbers are "
                       "reported but not to the accuracy asked for.")
        if not parts:
            return "Only the discrete chain ran: nothing to compare." + skipped + flagged
        when = f"up to t = {self.t_compare * 1e3:.4g} ms"
        if math.isfinite(self.run.continuum.valid_until if self.run.continuum else math.inf):
            when += " (later a wave reaches a chain end, where the continuum's end differs)"
        return (f"For this scenario, {when}, " + "; ".join(parts) + "." + skipped
                + flagged)

    def theory_label(self, name: str = "theory") -> str:
        """Which theory gave the numbers of ``name`` (``"theory"`` or ``"theory_strong"``)."""
        th = self.run.theory
        if name == "theory_strong":
            strong = th.strong if th is not None else None
            return (f"the interface theory: {strong.theory} ({strong.regime})"
                    if strong is not None else "the strongly nonlinear interface theory")
        if th is None:
            return "the theory"
        if th.interface_theory:
            return "the theory (Nesterenko speeds, Eqs. 9–13)"
        n = th.left.get("exponent", 1.5)
        law = "" if n == 1.5 else f" for exponent {n:g}"
        if th.chain_theory is not None:
            lead = "" if th.chain_theory.front == "incident" else \
                f"Nesterenko's speed{law} and "
            return f"the theory ({lead}{th.chain_theory.label})"
        return f"the theory (Nesterenko's speed{law})"

    def summary(self) -> dict[str, Any]:
        """Flat numbers (a sweep row): the run's summary, then differences and errors."""
        out = self.run.summary()
        for name, errs in self.errors.items():
            for key, val in errs.items():
                out[f"{name}_{key}"] = val
            out[f"{name}_note"] = self.notes.get(name, "")
        for name, diffs in self.differences.items():
            for key, (_, _, diff) in diffs.items():
                if isinstance(diff, float | int):
                    out[f"{name}_d_{key}"] = float(diff)
        for name, note in self.notes.items():
            out.setdefault(f"{name}_note", note)
        if self.theory_window:
            out["theory_window"] = self.theory_window
        out["t_compare"] = self.t_compare
        out["t_cross"] = self.t_cross
        out["t_separated_by_compare"] = self.t_separated
        out["incident_extent"] = self.extent
        out["verdict"] = self.verdict()
        return out

    def to_dict(self) -> dict[str, Any]:
        """Everything but the arrays (JSON-able)."""
        return {"scenario": self.scenario.to_dict(), "summary": self.summary(),
                "incident": self.incident, "t_compare": self.t_compare,
                "display_times": [float(self.times[i]) for i in self.display],
                "differences": {m: {k: list(v) for k, v in d.items()}
                                for m, d in self.differences.items()},
                "errors": self.errors, "notes": self.notes,
                "unmeasured": self.unmeasured, "measured_at": self.measured_at,
                "unverified": self.unverified, "t_separated": self.t_separated,
                "profile_errors": self.profile_errors,
                "speeds": {m: s.speeds for m, s in self.series.items()},
                "theory": self.run.theory.to_dict() if self.run.theory else None,
                "theory_labels": {name: self.theory_label(name) for name in
                                  ("theory", "theory_strong") if name in self.errors},
                "skipped": dict(self.run.skipped),
                "verdict": self.verdict()}

    def _repr_html_(self) -> str:
        """Jupyter display (:func:`hertzchain.compare_output.comparison_html`)."""
        from .compare_output import comparison_html

        return comparison_html(self)

    # ------------------------------------------------------------------ output
    def write(self, out: str | Path, *, figures: bool = True, report: bool = True
              ) -> dict[str, Any]:
        """Write ``compare.h5``, the figures (PNG) and ``report.md``/``.html`` into ``out``."""
        from .compare_output import write_all

        return write_all(self, Path(out), figures=figures, report=report)


def analyse(result: Run) -> Comparison:
    """Measure and compare the models of a finished :func:`hertzchain.models.run`."""
    chain, iface = result.chain, result.interface
    sampled = [m for m in result.models if m.completed and m.times.size]
    ref = result.discrete if result.discrete is not None and result.discrete.completed \
        else (sampled[0] if sampled else None)
    series: dict[str, ModelSeries] = {}
    if ref is None:
        raise ValueError("no model produced samples to analyse (the discrete chain did "
                         "not run or did not complete)")
    law = _elastic_law(result)
    incident = _incident_energies(chain, ref, iface, law)
    m_left = float(chain.mass[max(0, (iface or chain.n) // 2)])
    ref_ek = 0.5 * m_left * result.incident.velocity ** 2
    # a placed wave's extent, on the common initial state (an impact's forms later)
    extent = M.incident_extent(chain, ref.v[0], ref.strain[0], result.incident.x0) \
        if result.incident.measured_at == 0 and ref.times[0] == 0 else 0.0
    i_cross, t_cross = _crossing(ref.times, result, extent)
    d = float(chain.diameter[0])
    x_if = None if iface is None else iface - 0.5
    # comparison time: the last sample before a wave reaches an end where models differ
    until = min((m.valid_until for m in sampled), default=math.inf)
    ok = np.flatnonzero(ref.times < until * (1 - 1e-12))
    i_compare = int(ok[-1]) if ok.size else 0
    window = "" if ok.size else (
        f"a wave reached a chain end, where the continuum's end condition differs, at "
        f"t = {until * 1e3:.4g} ms, before any common sample")
    # the incident wave's fit stops when its peak reaches the interface: after that the
    # right-most pulse left of it is its tail and the forming reflected wave
    est = result.estimates
    hit = est.t_hit if est is not None and est.has_interface else math.inf
    i_hit = int(np.searchsorted(ref.times, hit, side="right"))
    x_formed = min(M.first_grain(chain) + FORMED_GRAINS, M.incident_grain(chain))
    # every front speed is fitted on the samples before a wave reached a chain end in
    # the discrete run (its summary's t_end_reached, the measure owner's end rule), for
    # every model alike: after it the leading pulse is a wall's echo or grains piling up
    # at a free end, whether or not the models' ends differ
    i_fit = min(i_compare + 1, _samples_before_end(result, ref.times))
    for m in sampled:
        part = _partition(chain, m, iface, incident, law)
        fr, pk, st = M.sample_fronts(chain, m.v, m.strain, iface, ref_ek, i_cross)
        before = slice(0, min(i_hit, i_fit))
        after = slice(min(i_cross, i_fit), i_fit)  # crossed, comparable, before an end
        # an impact's incident front is fitted once its wave has formed (from the grain
        # where it is measured, hertzchain.measure.incident_grain, or FORMED_GRAINS)
        x_in = fr["incident"][before]
        if not result.scenario.initial.initial_kind.placed:
            x_in = np.where(x_in >= x_formed, x_in, np.nan)
        speeds = {"incident": M.fit_sample_speed(m.times[before], x_in, x_if, d, 1),
                  "transmitted": M.fit_sample_speed(m.times[after],
                                                    fr["transmitted"][after], x_if, d, 1),
                  "reflected": M.fit_sample_speed(m.times[after], fr["reflected"][after],
                                                  x_if, d, -1)}
        series[m.name] = ModelSeries(m.name, m.label, m.times, part, fr, pk, st, speeds,
                                     m.completed, m.stopped_by, _own_partition(m))
    sim = result.simulation
    t_sep = (M.separated_by(sim, float(ref.times[i_compare]))
             if sim is not None and iface is not None and "discrete" in series
             else math.nan)
    cmp = Comparison(result, series, incident, i_cross, i_compare,
                     _display(result, ref.times, i_cross, i_compare), extent=extent,
                     t_cross=t_cross, window=window, t_separated=t_sep)
    _differences(cmp)
    return cmp


def _elastic_law(result: Run):
    """The chain's contact law for its potential energy; None: Hertz (n = 3/2).

    :func:`hertzchain.measure.grain_energies` evaluates Hertz's energy in closed form
    (:func:`theory.wave_contact_energy`) and another exponent with the law's own.
    """
    from .runner import build_law

    law = build_law(result.scenario.chain)[0]
    return None if law.exponent == 1.5 else law


def _display(result: Run, times: np.ndarray, i_cross: int, i_compare: int) -> list[int]:
    """Samples of the profile panels: before, during and after the interface."""
    asked = result.scenario.models.compare_times
    if asked:
        return sorted({int(np.argmin(np.abs(times - t))) for t in asked})
    if result.interface is None:
        return sorted({i_compare // 3, (2 * i_compare) // 3, i_compare})
    before = max(0, min(i_cross - 2, i_cross // 2))
    during = min(i_cross, i_compare)
    return sorted({before, during, i_compare})


def _at_distance(times, x, target) -> float:
    """First time a front trajectory passes ``target`` (linear interpolation), s."""
    ok = np.isfinite(x)
    t, x = times[ok], x[ok]
    above = np.flatnonzero(x >= target)
    if not above.size:
        return math.nan
    j = int(above[0])
    if j == 0:
        return float(t[0])
    return float(t[j - 1] + (target - x[j - 1]) * (t[j] - t[j - 1]) / (x[j] - x[j - 1]))


def _interp(times, x, t) -> float:
    ok = np.isfinite(x)
    if ok.sum() < 2 or not math.isfinite(t) or not times[ok][0] <= t <= times[ok][-1]:
        return math.nan
    return float(np.interp(t, times[ok], x[ok]))


def _windows(cmp: Comparison) -> dict[str, str]:
    """Why each kind of difference is outside its window ("" where it is inside).

    Keys: ``energy`` (the Table-2 rows: crossed and separated by the comparison time),
    ``after`` (fronts and peaks of the transmitted and reflected waves at the comparison
    time: crossed), ``reflected`` (the reflected front speed: the discrete run's own
    summary measured a reflected front, :func:`hertzchain.measure.summarise` — the one
    owner of whether there is one) and ``all`` (no common sample before a wave reached
    a chain end).
    """
    why = {"all": cmp.window, "energy": "", "after": "", "reflected": ""}
    if cmp.run.interface is None:
        return why
    if cmp.i_compare < cmp.i_cross:
        t_c = cmp.t_compare * 1e3
        why["after"] = (
            f"the incident wave had not crossed the interface by the comparison time "
            f"t = {t_c:.4g} ms (all but {SEPARATION:g} of its energy past it at "
            f"t = {cmp.t_cross * 1e3:.4g} ms, {max(CROSSING_GRAINS, cmp.extent):.0f} "
            "grains after its peak)")
        why["energy"] = why["after"] + ": the energy partition is not the scattering " \
            "result yet"
    elif not cmp.t_separated <= cmp.t_compare and cmp.run.discrete is not None:
        why["energy"] = (
            f"the discrete run's waves had not separated from the interface by the "
            f"comparison time t = {cmp.t_compare * 1e3:.4g} ms (the energy within 5 "
            f"grains of it stayed above {M.SEPARATION_FRACTIONS[-1]:g} of the chain's, "
            "hertzchain.measure.separated_by): the energy partition is not the "
            "scattering result yet")
    run_summary = cmp.run.discrete.summary if cmp.run.discrete is not None else {}
    if not math.isfinite(run_summary.get("front_speed_re", math.nan)):
        why["reflected"] = ("the discrete run measured no reflected front (front_speed_re: "
                            + (run_summary.get("front_speed_re_note") or "not measured")
                            + ")")
    return why


_GROUP = {"Ek_tr": "energy", "Ek_re": "energy", "Ep_tr": "energy", "Ep_re": "energy",
          "Et_tr": "energy", "Et_re": "energy", "peak_transmitted": "after",
          "peak_reflected": "after", "front_transmitted": "after",
          "front_reflected": "after", "speed_reflected": "reflected",
          "speed_reflected_at_measured_amplitude": "reflected"}
"""The window (:func:`_windows`) of each row of :attr:`Comparison.differences`."""


def _masked(cmp: Comparison, name: str, rows: dict[str, tuple]) -> dict[str, tuple]:
    """``rows`` with every row outside its window NaN (value, model, difference).

    The reasons go to ``cmp.unmeasured[name]``.
    """
    why = _windows(cmp)
    out, gone = {}, {}
    for key, row in rows.items():
        reason = why["all"] or why.get(_GROUP.get(key, ""), "")
        if reason:
            out[key] = (math.nan, math.nan, math.nan)
            gone[key] = reason
        else:
            out[key] = row
    if gone:
        cmp.unmeasured[name] = gone
    return out


def _differences(cmp: Comparison) -> None:
    """Fill ``differences``, ``errors`` and ``profile_errors`` against the discrete chain.

    A row outside its window (:func:`_windows`) is NaN, with the reason in
    ``unmeasured``; so is the error built from it (:func:`_error`).
    """
    result = cmp.run
    disc = cmp.series.get("discrete")
    if disc is None:
        return
    iface = result.interface
    i = cmp.i_compare
    v_in = result.incident.velocity
    dv = result.discrete.v
    # arrival distance: ARRIVAL_DISTANCE grains past the interface, or 80 % of the way
    x_tr = disc.fronts["transmitted"]
    if iface is not None and np.isfinite(x_tr[: i + 1]).any():
        reach = float(np.nanmax(x_tr[: i + 1]) - (iface - 0.5))
        dist = min(ARRIVAL_DISTANCE, 0.8 * reach)
        cmp.arrival_distance = dist
        t_arr = _at_distance(disc.times[: i + 1], x_tr[: i + 1], iface - 0.5 + dist)
    else:
        t_arr = math.nan
    for name, s in cmp.series.items():
        if name == "discrete":
            continue
        m = result.continuum
        rows: dict[str, tuple] = {}
        ours, theirs = disc.ratios_at(i), s.ratios_at(i)
        for key in _TABLE2:
            rows[key] = (ours[key], theirs[key], theirs[key] - ours[key])
        for w in ("transmitted", "reflected"):
            a, b = disc.speeds[w], s.speeds[w]
            rows[f"speed_{w}"] = (a, b, (b - a) / a if a else math.nan)
            a, b = disc.peaks[w][i], s.peaks[w][i]
            rows[f"peak_{w}"] = (float(a), float(b), float(b - a) / v_in)
            a, b = disc.fronts[w][i], s.fronts[w][i]
            rows[f"front_{w}"] = (float(a), float(b), float(b - a))
        if math.isfinite(t_arr):
            t_b = _at_distance(s.times[: i + 1], s.fronts["transmitted"][: i + 1],
                               iface - 0.5 + cmp.arrival_distance)
            rows["arrival_time"] = (t_arr, t_b, t_b - t_arr)
            rows["front_at_arrival"] = (iface - 0.5 + cmp.arrival_distance,
                                        _interp(s.times, s.fronts["transmitted"], t_arr),
                                        _interp(s.times, s.fronts["transmitted"], t_arr)
                                        - (iface - 0.5 + cmp.arrival_distance))
        rows = _masked(cmp, name, rows)
        cmp.differences[name] = rows
        prof = []
        for j in sorted({*cmp.display, i}):
            diff = m.v[j] - dv[j]
            norm = float(np.linalg.norm(dv[j]))
            shape, lag = shifted_profile_error(m.v[j], dv[j])
            prof.append({"t": float(cmp.times[j]),
                         "l2": float(np.linalg.norm(diff)) / norm if norm else math.nan,
                         "linf": float(np.max(np.abs(diff))) / v_in,
                         "shape_l2": shape, "lag": lag})
        cmp.profile_errors[name] = [p for p in prof if p["t"] in
                                    {float(cmp.times[j]) for j in cmp.display}]
        at_compare = next(p for p in prof if p["t"] == float(cmp.times[i]))
        energy = max(abs(rows["Et_tr"][2]), abs(rows["Et_re"][2])) if iface is not None \
            else math.nan
        speed_key = "speed_transmitted" if iface is not None else None
        speed = abs(rows[speed_key][2]) if speed_key else abs(
            (s.speeds["incident"] - disc.speeds["incident"]) / disc.speeds["incident"])
        cmp.errors[name] = {**_error(cmp, name, energy, speed),
                            "profile_l2": math.nan if cmp.window else at_compare["l2"],
                            "profile_shape_l2": math.nan if cmp.window else
                            at_compare["shape_l2"],
                            "profile_lag": math.nan if cmp.window else at_compare["lag"]}
    th = result.theory
    if th is not None:
        rows = {}
        i_t = cmp.i_compare
        if th.interface_theory:
            ours = disc.ratios_at(i_t)
            for key in _TABLE2:
                b = float(th.ratios[key])
                rows[key] = (ours[key], b, b - ours[key])
            for w, sp in (("transmitted", th.speed_tr), ("reflected", th.speed_re)):
                a = disc.speeds[w]
                rows[f"speed_{w}"] = (a, sp, (sp - a) / a if a else math.nan)
                # Nesterenko's relation at the measured amplitude of the discrete wave
                xi = disc.strains[w][i_t]
                at = th.speed("right" if w == "transmitted" else "left", xi)
                rows[f"speed_{w}_at_measured_amplitude"] = (a, at, (at - a) / a if a
                                                            else math.nan)
            a = disc.speeds["incident"]
            rows["speed_incident"] = (a, th.speed_in, (th.speed_in - a) / a if a
                                      else math.nan)
            if math.isfinite(t_arr):
                x_th = th.fronts(np.array([t_arr]))["transmitted"][0]
                rows["front_at_arrival"] = (iface - 0.5 + cmp.arrival_distance, float(x_th),
                                            float(x_th) - (iface - 0.5 + cmp.arrival_distance))
            rows = _masked(cmp, "theory", rows)
            energy = max(abs(rows["Et_tr"][2]), abs(rows["Et_re"][2]))
            speed = abs(rows["speed_transmitted"][2])
        else:
            _theory_beyond(cmp, th)
            return
        cmp.differences["theory"] = rows
        cmp.errors["theory"] = _error(cmp, "theory", energy, speed)
        _theory_strong(cmp, th)


def _theory_strong(cmp: Comparison, th) -> None:
    """The strongly nonlinear interface theory against the discrete chain (``theory_strong``).

    :attr:`hertzchain.models.TheoryModel.strong` (docs/physics.md §16): E_T and E_R at the
    comparison time, and the transmitted front speed as its speed ratio times the
    discrete chain's measured incident front speed (the ratio is over the exact discrete
    wave's speed, which the incident front is).  The same windows as the linear theory's.
    """
    strong = th.strong
    if strong is None:
        if th.has_interface and th.strong_note:
            cmp.notes["theory_strong"] = th.strong_note
        return
    disc = cmp.series["discrete"]
    ours = disc.ratios_at(cmp.i_compare)
    rows = {"Et_tr": (ours["Et_tr"], strong.energy_transmission,
                      strong.energy_transmission - ours["Et_tr"]),
            "Et_re": (ours["Et_re"], strong.energy_reflection,
                      strong.energy_reflection - ours["Et_re"])}
    a, v_in = disc.speeds["transmitted"], disc.speeds["incident"]
    sp = strong.speed_ratio * v_in
    rows["speed_transmitted"] = (a, sp, (sp - a) / a if a else math.nan)
    rows = _masked(cmp, "theory_strong", rows)
    cmp.differences["theory_strong"] = rows
    energy = max(abs(rows["Et_tr"][2]), abs(rows["Et_re"][2]))
    cmp.errors["theory_strong"] = _error(cmp, "theory_strong", energy,
                                         abs(rows["speed_transmitted"][2]))


def _relative(a: float, b: float) -> tuple[float, float, float]:
    """(discrete, theory, (theory − discrete)/discrete)."""
    a, b = float(a), float(b)
    return a, b, (b - a) / a if a and math.isfinite(a) and math.isfinite(b) else math.nan


def _theory_beyond(cmp: Comparison, th) -> None:
    """The theory where Eqs. 9–13 do not apply: the leading wave's theory, null + reason.

    * The steady solitary wave of the first section (Nesterenko's speed for the law's
      exponent n at the incident amplitude) against the incident front speed, where
      that section is uniform and lossless (no :class:`hertzchain.models.ChainTheory` in
      it);
    * the :class:`~hertzchain.models.ChainTheory` of the chain (gravity, taper, periodic
      cell, dissipation, striker) on its quantity (:func:`_chain_theory_rows`);
    * an interface the interface theories do not describe: its rows are absent and
      the note says why (:attr:`hertzchain.models.TheoryModel.interface_note`).

    The theory's error is the largest relative difference of these quantities; NaN,
    with the reasons, if none was measured.
    """
    ct = th.chain_theory
    rows: dict[str, tuple] = {}
    primary: list[str] = []
    why: list[str] = []
    if ct is None or ct.front != "incident":
        rows["speed_incident"] = _relative(_incident_speed(cmp), th.speed_in)
        primary.append("speed_incident")
        if not math.isfinite(rows["speed_incident"][2]):
            why.append("no incident front speed (fewer than 3 samples of the front "
                       "before it reached the interface or an end)")
    if ct is not None:
        ct_rows, ct_why, ct_primary = _chain_theory_rows(cmp, ct)
        rows.update(ct_rows)
        primary += ct_primary
        why += ct_why
    elif th.chain_theory_note:
        why.append(th.chain_theory_note)
    if th.has_interface and th.interface_note:
        why.append(f"the interface: {th.interface_note}")
    cmp.differences["theory"] = rows
    errs = [abs(rows[k][2]) for k in primary if math.isfinite(rows[k][2])]
    err = max(errs) if errs else math.nan
    if why:
        cmp.notes["theory"] = "; ".join(why)
    cmp.errors["theory"] = {"energy": math.nan, "speed": err, "error": float(err)}


def _t_end_reached(result: Run) -> float:
    """When a wave reached a chain end in the discrete run, s (inf: none, or no run).

    Its summary's ``t_end_reached`` (:func:`hertzchain.measure.windows`).
    """
    summary = result.discrete.summary if result.discrete is not None else {}
    return float(summary.get("t_end_reached", math.inf))


def _samples_before_end(result: Run, times: np.ndarray) -> int:
    """How many of the samples at ``times`` (s) precede :func:`_t_end_reached`."""
    return int(np.searchsorted(times, _t_end_reached(result), side="left"))


def _discrete_window(cmp: Comparison) -> np.ndarray:
    """The samples of the discrete run before a wave reached a chain end (bool mask).

    The theory is compared with the discrete chain in the discrete run's own window
    (its summary's ``t_end_reached``, :func:`hertzchain.measure.windows`), not in the
    continuum's (:attr:`hertzchain.models.ModelRun.valid_until`).
    """
    disc = cmp.series["discrete"]
    return disc.times < _t_end_reached(cmp.run)


def _incident_speed(cmp: Comparison) -> float:
    """The discrete chain's incident front speed in its own window, m/s.

    :func:`hertzchain.measure.fit_sample_speed` of the sampled incident front
    (:func:`hertzchain.measure.sample_fronts`) before its peak reaches the interface and
    before a wave reached a chain end; an impact's once its wave has formed.
    """
    result, disc = cmp.run, cmp.series["discrete"]
    chain, iface = result.chain, result.interface
    est = result.estimates
    x = np.where(_discrete_window(cmp), disc.fronts["incident"], np.nan)
    if est is not None and est.has_interface:
        x = np.where(disc.times <= est.t_hit, x, np.nan)
    if not result.scenario.initial.initial_kind.placed:  # formed on the way
        x_formed = min(M.first_grain(chain) + FORMED_GRAINS, M.incident_grain(chain))
        x = np.where(x >= x_formed, x, np.nan)
    return M.fit_sample_speed(disc.times, x, None if iface is None else iface - 0.5,
                              float(chain.diameter[0]), 1)


def _cell_peak_force(cmp: Comparison, ct, xa: float, xb: float, ia: int, ib: int,
                     final_ok: bool) -> float:
    """The periodic wave's peak contact force in the window, N.

    With the running maxima of the overlaps (``[record] strain_maxima``) and no wave at
    an end before the run's end: per contact of the cell, the mean over the cells
    between the window's grains of k_j r_max,j^n, and the largest of these (the
    measurement of docs/physics.md §14, "Dimers and trimers"); otherwise the largest
    contact force of the section in the window's samples.
    """
    result = cmp.run
    ch, n, q = result.chain, ct.params["exponent"], ct.params["cell_grains"]
    sim = result.simulation
    rmax = getattr(sim.record, "overlap_max", None) if sim is not None else None
    lo, hi = int(math.ceil(xa)), int(math.floor(xb))
    if rmax is not None and final_ok and hi - lo >= 2 * q:
        lo = ct.first + ((lo - ct.first) // q + 1) * q  # a cell boundary
        cells = (hi - lo) // q
        f = ch.k[lo:lo + cells * q] * np.maximum(rmax[lo:lo + cells * q], 0.0) ** n
        return float(f.reshape(cells, q).mean(axis=0).max())
    j = slice(ct.first + 1, ct.last)
    r = ch.delta0[j] + result.discrete.strain[ia:ib + 1, j]
    return float(np.max(ch.k[j] * np.maximum(r, 0.0) ** n))


def _chain_theory_rows(cmp: Comparison, ct) -> tuple[dict, list[str], list[str]]:
    """Rows of a :class:`hertzchain.models.ChainTheory` against the discrete chain.

    Window: the samples before a wave reached a chain end (the run summary's
    ``t_end_reached``, :func:`_discrete_window`) whose sampled
    front (:func:`hertzchain.measure.sample_fronts`) lies in the grains the theory
    describes, [first, last − 3].  From the first such sample (a) to the last (b):

    * ``travel_time``: t_b − t_a against the theory's time from x_a to x_b (a taper's
      energy from the peak velocity the discrete wave had at x_a, the running maximum
      of that grain; a periodic cell's speed at the largest contact force of the
      section in the window's samples);
    * ``peak_velocity``: the running maximum of grain ⌊x_b⌋ − 3 (its peak has passed)
      against the theory's decay from the running maximum at the first grain;
    * ``leading_peak``: the striker train's leading peak velocity against the same
      running maximum; not in the error, where the run measured its train
      (:func:`hertzchain.measure.wave_train`, the summary's ``train_*``): ``wave_count``,
      its waves above :data:`hertzchain.measure.TRAIN_FRACTION` of the leading one
      against the model's count at that fraction, and ``train_leading``, the peak
      velocity of the exact wave of the leading wave's energy against the model's v_1.
    """
    result, disc = cmp.run, cmp.series["discrete"]
    sim = result.simulation
    summary = result.discrete.summary if result.discrete is not None else {}
    t_end = float(summary.get("t_end_reached", math.inf))
    key = ct.quantity
    t, x = disc.times, disc.fronts[ct.front]
    ok = (np.isfinite(x) & _discrete_window(cmp) & (x >= ct.first) & (x <= ct.last - 3))
    if ok.sum() < 2:
        return ({key: (math.nan,) * 3},
                [f"{ct.kind}: fewer than 2 samples of the {ct.front} front in grains "
                 f"{ct.first}-{ct.last - 3} before a wave reached a chain end"], [key])
    ia, ib = int(np.flatnonzero(ok)[0]), int(np.flatnonzero(ok)[-1])
    xa, xb = float(x[ia]), float(x[ib])
    vmax = sim.record.vmax if sim is not None else None
    final_ok = float(sim.t) < t_end if sim is not None else False
    rows: dict[str, tuple] = {}
    why: list[str] = []
    cmp.theory_window = (f"{ct.kind}: samples t = {t[ia] * 1e3:.4g}-{t[ib] * 1e3:.4g} ms, "
                         f"{ct.front} front at grains {xa:.1f}-{xb:.1f}")
    if key == "travel_time":
        v_a = float(vmax[max(int(math.floor(xa)) - 1, 0)]) if vmax is not None \
            else float(disc.peaks[ct.front][ia])
        force = math.nan
        if ct.kind == "periodic":
            force = _cell_peak_force(cmp, ct, xa, xb, ia, ib, final_ok)
        rows[key] = _relative(t[ib] - t[ia], ct.travel_time(xa, xb, v_a, force))
    else:
        a = ct.first
        b = int(math.floor(xb)) - 3
        if vmax is not None and final_ok and b > a and vmax[a] > 0:
            # running maxima: phase-independent peaks, grain by grain
            v_a, v_b = float(vmax[a]), float(vmax[b])
            where = f"running maxima of grains {a} and {b}"
        else:  # the refined peaks of the sampled front (within the lattice phase)
            a, b = int(round(xa)), int(round(xb))
            v_a, v_b = float(disc.peaks[ct.front][ia]), float(disc.peaks[ct.front][ib])
            where = (f"sampled peaks at grains {xa:.1f} and {xb:.1f} (a wave reached a "
                     "chain end before the run's end: no running maxima)")
        if not (v_a > 0 and v_b > 0 and b > a):
            rows[key] = (math.nan,) * 3
            why.append(f"{ct.kind}: the front did not travel past grain {a}")
        elif key == "peak_velocity":
            rows[key] = _relative(v_b, ct.peak_velocity(a, b, v_a))
            cmp.theory_window += f"; peak velocities: {where}"
        else:
            train = ct.striker
            rows[key] = _relative(v_b, train.velocity_max)
            cmp.theory_window += f"; leading peak: {where}"
            waves = summary.get("train_waves")
            if waves:  # measured in its window (hertzchain.measure.wave_train)
                count = train.count_above(M.TRAIN_FRACTION)
                rows["wave_count"] = (float(waves), float(count), float(count - waves))
                lead = abs(float(summary["train_velocity_max"][0]))
                rows["train_leading"] = _relative(lead, train.velocity_max)
    return rows, why, [key]


def _error(cmp: Comparison, name: str, energy: float, speed: float) -> dict[str, float]:
    """``energy``, ``speed`` and ``error`` of one model, NaN where a window does not hold.

    The reason goes to ``cmp.notes[name]`` (module docstring, "Measurement windows").
    """
    result, disc = cmp.run, cmp.series["discrete"]
    win = _windows(cmp)
    why = []
    if win["all"]:
        why.append(win["all"])
        energy = speed = math.nan
    elif result.interface is not None:
        if win["energy"]:
            why.append(win["energy"])
            energy = math.nan
        if not math.isfinite(speed):
            fitted = [n for n, m in (("discrete chain", disc.speeds["transmitted"]),
                                     (name, cmp.series[name].speeds["transmitted"]
                                      if name in cmp.series else 0.0))
                      if not math.isfinite(m)]
            why.append("no transmitted front speed: "
                       + (f"fewer than 3 samples of the {' and the '.join(fitted)}'s front "
                          f">= {FIT_FROM} grains past the interface between the crossing "
                          "and the comparison time" if fitted else
                          "the theory predicts none for this amplitude"))
    elif not math.isfinite(speed):
        why.append("no incident front speed (fewer than 3 samples of the front)")
    if why:
        cmp.notes[name] = "; ".join(why)
    if why:
        error = math.nan
    else:
        error = max(energy, speed) if result.interface is not None else speed
    return {"energy": energy, "speed": speed, "error": float(error)}


def compare(scenario: Scenario | str | Path, *, cache: str | Path | None = None,
            out: str | Path | None = None, **kwargs) -> Comparison:
    """Run every model of ``scenario`` and compare them (:class:`Comparison`).

    Parameters
    ----------
    scenario : Scenario or path
        A scenario, or its TOML file (a bare name: a shipped scenario).
    cache : path, optional
        Directory of cached runs (default: ``out/runs`` if ``out`` is given).
    out : path, optional
        Also write the comparison there (:meth:`Comparison.write`).
    **kwargs
        Passed to :func:`hertzchain.models.run` (``force``, ``checkpoint_interval``,
        ``progress``, ``threads``, ``log``).

    Examples
    --------
    >>> from hertzchain.compare import compare
    >>> cmp = compare("table2_M")                        # doctest: +SKIP
    >>> cmp.errors["continuum"]["error"] < 0.01          # doctest: +SKIP
    True
    """
    sc = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    if cache is None and out is not None:
        cache = Path(out) / "runs"
    # the discrete run is sampled at the common times whatever else runs: the theory is
    # compared on the same samples with or without a continuum
    kwargs.setdefault("samples", True)
    cmp = analyse(run(sc, cache=cache, compare=True, **kwargs))
    if out is not None:
        cmp.write(out)
    return cmp


def compare_point(scenario: Scenario, *, out: str | Path | None = None,
                  progress: bool = False) -> dict[str, Any]:
    """Sweep point function: every model of the point, compared; a flat summary.

    The signature of :data:`hertzchain.sweep.engine.DEFAULT_POINT_FUNCTION`; ``out``
    (a file name) writes the discrete run there.
    """
    result = run(scenario, out=out, progress=progress, samples=True)
    if result.discrete is None or not result.discrete.completed:
        return result.summary()
    return analyse(result).summary()


def read_comparison(path: str | Path) -> dict[str, Any]:
    """The numbers of a ``compare.h5`` file (JSON attribute ``comparison``)."""
    from theory import integrity

    with integrity.open_hdf5(path, what="comparison") as f:
        if f.attrs.get("format") != FORMAT:
            raise ValueError(f"{path}: not a comparison file ({FORMAT})")
        return json.loads(f.attrs["comparison"])

