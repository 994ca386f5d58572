r"""The one run path: every model of a scenario, from the same initial grain state.

:func:`run` is what ``hertzchain run``, ``hertzchain compare``, ``hertzchain sweep`` (with
:func:`hertzchain.compare.compare_point` as the point function) and every simulation of
``hertzchain reproduce`` call (:func:`hertzchain.reproduce.common.run_models`: Figs. 2–6
from the paper scenarios in ``hertzchain/scenarios/paper/``, Fig. 7, Table 2 and Fig. 8
from scenario dicts — Table 2's continuum column a continuum-only run of the same
scenario —, the validity map from the shipped sweep's points).  For a
:class:`~hertzchain.scenario.Scenario` it

1. builds the chain and the initial grain state once (:func:`hertzchain.runner.build_chain`,
   :func:`~hertzchain.runner.build_initial_checked`);
2. runs the **discrete** chain (paper Eq. 2, the reference) with
   :func:`hertzchain.runner.run_simulation` — cached by its parameters and checkpointed;
3. runs the **continuum** (``[models] continuum``: corrected Eq. 4, Eq. 7, the
   grain-averaged quasi-continuum or KdV, :mod:`continuum`; ``"auto"`` is resolved by
   the one rule :meth:`hertzchain.scenario.ModelsSpec.continuum_model` from the chain
   and the incident strain amplitude / δ0 measured on the initial state: Eq. 4 for weak
   precompressed waves, the quasi-continuum at δ0 = 0 and for strong waves on lossless
   chains without periodic cells, taper or gravity, Eq. 7 otherwise) from the same grain
   state interpolated onto its grid (:func:`continuum.from_grains`: cubic splines for a
   placed wave, per grain for an impact, whose struck grain is a velocity jump a spline
   would ring on), to the discrete run's end time, with the splitting method and
   dt_safety of ``[models]`` or, not given, the model's own
   (:meth:`hertzchain.scenario.ModelsSpec.continuum_step`, resolved once the model is) —
   cached too, keyed by the resolved values;
4. evaluates the **theory** (:class:`TheoryModel`: Nesterenko's wave speeds for the law's
   exponent n — Eqs. 5 and 8 for Hertz —, the linear-acoustic interface of Eqs. 9–13
   and the strongly nonlinear one of docs/physics.md §16 where they apply, and the
   theory of a chain beyond the paper, :class:`ChainTheory`: gravity, tapers, periodic
   cells, dissipation, a striker, a linear chain; null with the reason elsewhere).

Which of the continuum and the theory run is decided by
:func:`hertzchain.scenario.model_applies` (``[models]`` not given: where they apply,
:meth:`hertzchain.scenario.Scenario.with_default_models`; :attr:`Run.skipped` says why
a model is off).

Common sample times
-------------------
The models are compared at the same times: ``[models] samples`` times evenly spaced from
0 to ``[run] t_end`` or, for a run that stops on ``until_front_at``, spaced by the
theory's estimate of that time / (samples − 1) (the samples after the stop are not
taken).  The discrete run stores a snapshot at each (taken at the first step at or
after it: within one discrete step, ~5e-8 s); the continuum is stepped with a time step
that divides the spacing, so its samples fall on the same times, and it is then stepped
on to the discrete run's exact end time (without the discrete chain, ``[models] discrete
= false``, a run with ``until_front_at`` ends at the theory's estimate of that event,
or at ``t_end`` if earlier).  Both are read grain by grain: the velocity
v_i (m/s) and the dynamic overlap δ_j − δ0_j (m) of every contact, from which every
energy is computed with the discrete formulas (docs/physics.md §6).

Ends of the continuum
---------------------
The continuum solvers have the same condition at both ends: a rigid wall at rest or a
constant-force ("free") end (:data:`continuum.medium.BOUNDARY_CONDITIONS`).  An initial
state at rest in displacement (an impact) uses walls; a placed wave, whose passed grains
and left wall are shifted (paper Section 2, :func:`discrete.place_wave`), uses free
ends, equivalent to the discrete walls until a wave reaches an end.  Past that time
(:attr:`ModelRun.valid_until`) the continuum is not compared.

Caching: with ``cache=DIR`` the discrete run is ``DIR/<stem>-<hash>.h5`` (its key is
:meth:`Scenario.discrete_dict` with the sample times), the continuum
``DIR/<stem>-continuum-<hash>.h5``; an existing complete file is reused, an interrupted
discrete run resumes from its checkpoint (``.ckpt``) bit for bit.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import discrete
import theory
import theory.dimers
import theory.dissipation
import theory.gravity
import theory.striker
import theory.tapers
from discrete import diagnostics as D
from theory import integrity

from . import checkpoint as C
from . import measure as M
from .cache import cache_path, canonical_json
from .measure import interfaces
from .runner import build_chain, build_initial_checked, build_law, check_size, run_simulation
from .scenario import ModelsSpec, Scenario, ScenarioError

__all__ = ["ModelRun", "IncidentWave", "TheoryModel", "ChainTheory", "Run", "run",
           "sample_grid", "incident_wave", "strain_from_velocity", "chain_theory",
           "interface_applies", "chain_exponent", "FORMED_GRAINS", "FORMAT"]

FORMAT = "hertzchain.continuum-samples/2"
"""``format`` attribute of a continuum result file."""

_ESTIMATE_MARGIN = 4
"""Sample times are requested up to this many times the estimated run time."""


# -- results ----------------------------------------------------------------------------
@dataclass
class ModelRun:
    """One model's samples, grain by grain, at the common times.

    Attributes
    ----------
    name : str
        ``"discrete"`` or ``"continuum"``.
    label : str
        For legends, e.g. ``"continuum (Eq. 4, 5 nodes/grain)"``.
    times : ndarray, shape (K,)
        Sample times, s.
    v : ndarray, shape (K, N)
        Grain velocities, m/s.
    strain : ndarray, shape (K, N+1)
        Dynamic overlap δ_j − δ0_j of every contact (0 and N: the walls), m.
    t_final : float
        End time of the run, s (the last sample is taken there).
    completed : bool
        The run reached what was asked (False: see ``stopped_by``).
    stopped_by : str
        ``"t_end"``, ``"until_front_at"`` or what stopped it early (an error).
    valid_until : float
        Samples after this time are not compared (a wave reached a chain end where the
        model's end condition differs from the discrete chain's), s.
    summary : dict
        The model's own numbers (the discrete runner's summary; the continuum's energy
        drift, time step, cost).
    params : dict
        Everything the result depends on.
    path : Path or None
        Its HDF5 file.
    cached : bool
        Read from ``path`` rather than computed.
    own_energy : ndarray, shape (K, 4), or None
        The continuum's own conserved energy (its functional, the PDE's
        ``energy_density``: kinetic with the Rosenau term, potential with F0 × the overlap
        change added, docs/physics.md §6) left and right of the first interface, J:
        columns kinetic left, kinetic right, potential left, potential right
        (:func:`_own_energy`).  None for the discrete chain and KdV.
    """

    name: str
    label: str
    times: np.ndarray
    v: np.ndarray
    strain: np.ndarray
    t_final: float
    completed: bool = True
    stopped_by: str = "t_end"
    valid_until: float = math.inf
    summary: dict = field(default_factory=dict)
    params: dict = field(default_factory=dict)
    path: Path | None = None
    cached: bool = False
    own_energy: np.ndarray | None = None

    @property
    def final_v(self) -> np.ndarray:
        """Grain velocities at ``t_final`` (the last sample), m/s."""
        return self.v[-1]


@dataclass(frozen=True)
class IncidentWave:
    """The incident wave as all models start it: where, how strong.

    ``x0`` is the grain position of its peak at t = 0 (grains; 0 for an impact),
    ``velocity`` its peak grain velocity (m/s), ``strain`` its peak dynamic overlap
    (r − δ0)/d as the theory takes it (the solitary wave's of that peak velocity,
    :func:`strain_from_velocity`) and ``measured_at`` the time it was measured (0: the
    initial state; an impact's wave is measured on the discrete run once formed).
    ``peak_strain`` is the wave's own peak dynamic strain where the initial state knows
    it (an exact wave: ~8 % below ``strain`` at δ0 = 0 and ~7 % at strain/δ0 = 9, 1e-4
    at the paper's amplitude), NaN otherwise; :attr:`amplitude` is the better of the two.
    """

    x0: float
    velocity: float
    strain: float
    measured_at: float = 0.0
    peak_strain: float = math.nan

    @property
    def amplitude(self) -> float:
        """The incident peak dynamic strain (r − δ0)/d: ``peak_strain``, else ``strain``."""
        return self.peak_strain if math.isfinite(self.peak_strain) else self.strain


# -- theory --------------------------------------------------------------------------
def chain_exponent(chain: discrete.Chain) -> float:
    """Exponent n of the chain's elastic contact law F = k δ^n (3/2: Hertz)."""
    return float(chain.params.get("exponent", 1.5))


def _side(chain: discrete.Chain, grain: int, contact: int) -> dict[str, float]:
    """A section's grain and contact constants and its wave speeds at one grain/contact.

    ``c_mat`` = √(k d^{n+1}/m) and ``c0`` = d √(n k δ0^{n-1}/m) for the chain's exponent
    n (:meth:`theory.laws.ContactLaw.long_wave`; paper Eqs. 4 and 7 for n = 3/2), m/s.
    """
    d = float(chain.diameter[grain])
    m, k, d0 = float(chain.mass[grain]), float(chain.k[contact]), float(chain.delta0[contact])
    n = chain_exponent(chain)
    return {"mass": m, "k": k, "delta0": d0, "d": d, "xi0": d0 / d, "exponent": n,
            "c_mat": float(theory.c_mat(k, m, d, exponent=n)),
            "c0": float(theory.c0(k, m, d, d0, exponent=n)) if d0 > 0 else 0.0}


def _speed(side: dict, xi: float) -> float:
    """Nesterenko's solitary-wave speed for F = k δ^n at dynamic strain ξ, m/s.

    :func:`theory.nesterenko_speed` (Nesterenko 2001, Eq. 1.4.28 for n = 3/2; any n,
    docs/physics.md §15): Eq. 5 to first order under precompression, the compacton's
    speed (Eq. 8 for Hertz) at δ0 = 0; the sound speed c0 for ξ = 0.
    """
    if not (xi > 0 and math.isfinite(xi)):
        return side["c0"] if side["c0"] > 0 else math.nan
    return float(theory.nesterenko_speed(side["c_mat"], side["xi0"], xi,
                                         exponent=side.get("exponent", 1.5)))


def _strain_of_force(side: dict, force_change: float) -> float:
    """Dynamic strain of a contact whose force changes by ``force_change`` (N), F = k δ^n."""
    n = side.get("exponent", 1.5)
    f0 = side["k"] * side["delta0"] ** n
    f = max(f0 + force_change, 0.0)
    return ((f / side["k"]) ** (1.0 / n) - side["delta0"]) / side["d"]


@dataclass
class TheoryModel:
    """Closed-form predictions for the first interface a right-going wave meets.

    From the chain (masses, contact constants and static overlaps either side; α_ρ and
    α_kn are read off the built chain, so swapped or explicit materials work) and the
    incident wave (:class:`IncidentWave`):

    * speeds: Nesterenko's general relation (Nesterenko 2001, Eq. 1.4.28;
      :func:`theory.nesterenko_speed`), which is Eq. 5 to first order under
      precompression and Eq. 8 at δ0 = 0, at the incident amplitude; the transmitted
      and reflected amplitudes follow from the force transmission 2/(1 + γ_RG⁻¹) and
      reflection (γ_RG − 1)/(γ_RG + 1) of Eq. 12 applied to the peak contact force
      (Hertz law, Eq. 1, either side).  An expansive reflected wave (force decrease) is
      no solitary wave: it travels at the sound speed c0 (Eq. 4) and not at all at δ0 = 0;
    * trajectories: the incident peak moves at its speed to the interface contact
      (x = i − ½) and the transmitted and reflected peaks leave it at theirs;
    * energy partition: :func:`theory.table2_prediction` (Eqs. 9–13 with the incident
      kinetic, linear and quadratic potential energy) applied at the crossing time;
    * classes: :func:`theory.predict` (Fig. 7 regions) and the fission parameter.

    Without an interface only the incident wave is predicted.  At δ0 = 0 the linear
    acoustics behind Eqs. 9–13 has no basis (no sound speed); the formulas are applied
    formally and the comparison shows how far they hold.
    """

    incident: IncidentWave
    left: dict
    interface: int | None = None
    right: dict | None = None
    energies_in: dict = field(default_factory=dict)
    alpha_rho: float = 1.0
    alpha_kn: float = 1.0
    interface_note: str = ""
    strong_note: str = ""
    chain_theory: ChainTheory | None = None
    chain_theory_note: str = ""

    # derived ------------------------------------------------------------------------
    @property
    def has_interface(self) -> bool:
        """Whether a second section follows the first."""
        return self.interface is not None and self.right is not None

    @property
    def interface_theory(self) -> bool:
        """Whether Eqs. 9–13 describe the first interface (:attr:`interface_note`: why not)."""
        return self.has_interface and not self.interface_note

    @property
    def strong(self):
        """The strongly nonlinear interface theory's prediction, or None (:attr:`strong_note`).

        :func:`theory.strong_interface.predict_strong` at the incident amplitude over δ0
        (inf at δ0 = 0): the quasi-particle theory from
        :data:`theory.strong_interface.STRONG_THRESHOLD` and in the sonic vacuum,
        lattice acoustics below (docs/physics.md §16); the answer names its theory and
        regime.
        """
        if self.interface is None or self.right is None or self.strong_note:
            return None
        from theory.strong_interface import predict_strong

        xi0 = self.left["xi0"]
        amp = self.incident.amplitude
        if not (math.isfinite(amp) and amp > 0):
            return None
        eps = amp / xi0 if xi0 > 0 else math.inf
        return predict_strong(self.alpha_rho, self.alpha_kn, eps,
                              exponent=self.left.get("exponent", 1.5))

    @property
    def gamma_c0(self) -> float:
        """c0^R/c0^L = α_ρ^{-1/2} α_kn^{1/3} (Eq. 9)."""
        return float(theory.gamma_c0(self.alpha_rho, self.alpha_kn))

    @property
    def gamma_rg(self) -> float:
        """Impedance ratio γ_RG = α_ρ^{1/2} α_kn^{1/3} (Eq. 13)."""
        return float(theory.gamma_rg(self.alpha_rho, self.alpha_kn))

    @property
    def x_interface(self) -> float:
        """Position of the interface contact, grains (contact i sits at i − ½)."""
        return math.nan if self.interface is None else self.interface - 0.5

    @property
    def force_in(self) -> float:
        """Peak dynamic contact force of the incident wave, N (F = k δ^n; Eq. 1 for Hertz)."""
        s = self.left
        n = s.get("exponent", 1.5)
        d = s["delta0"] + self.incident.strain * s["d"]
        return s["k"] * (d**n - s["delta0"] ** n)

    @property
    def strain_tr(self) -> float:
        """Predicted peak dynamic strain of the transmitted wave (Eq. 12, Eq. 1)."""
        if not self.has_interface:
            return math.nan
        g = self.gamma_rg
        return _strain_of_force(self.right, 2.0 * g / (1.0 + g) * self.force_in)

    @property
    def strain_re(self) -> float:
        """Predicted peak dynamic strain of the reflected wave (negative: expansive)."""
        if not self.has_interface:
            return math.nan
        g = self.gamma_rg
        return _strain_of_force(self.left, (g - 1.0) / (g + 1.0) * self.force_in)

    @property
    def speed_in(self) -> float:
        """Incident wave speed at its amplitude, m/s (Nesterenko; Eq. 5/8 limits)."""
        return _speed(self.left, self.incident.strain)

    @property
    def speed_tr(self) -> float:
        """Transmitted wave speed at the predicted amplitude, m/s."""
        return _speed(self.right, self.strain_tr) if self.has_interface else math.nan

    @property
    def reflects(self) -> bool:
        """Whether a reflected wave is predicted (γ_RG ≠ 1, Eq. 12)."""
        return self.has_interface and abs(self.gamma_rg - 1.0) > 1e-9

    @property
    def speed_re(self) -> float:
        """Reflected wave speed, m/s (sound speed c0 for an expansive wave; NaN if none)."""
        if not self.reflects:
            return math.nan
        xi = self.strain_re
        if xi > 0:
            return _speed(self.left, xi)
        return self.left["c0"] if self.left["c0"] > 0 else math.nan

    def speed(self, where: str, strain: float) -> float:
        """Nesterenko's speed in the ``"left"`` or ``"right"`` section at ``strain``, m/s."""
        side = self.left if where == "left" else self.right
        return math.nan if side is None else _speed(side, strain)

    @property
    def t_hit(self) -> float:
        """Time the incident peak reaches the interface contact, s."""
        if not self.has_interface:
            return math.inf
        return self.incident.measured_at + (self.x_interface - self.incident.x0) \
            * self.left["d"] / self.speed_in

    @property
    def ratios(self) -> dict[str, float]:
        """Table-2 energy ratios (Eqs. 9–13, :func:`theory.table2_prediction`)."""
        if not self.interface_theory or not self.energies_in:
            return {}
        e = self.energies_in
        if e["linear"] + e["quadratic"] <= 0:  # no potential energy (an impact at t = 0)
            te, re = (float(theory.energy_transmission(self.gamma_rg)),
                      float(theory.energy_reflection(self.gamma_rg)))
            return {"Ek_tr": te, "Ek_re": re, "Ep_tr": math.nan, "Ep_re": math.nan,
                    "Et_tr": te, "Et_re": re}
        return theory.table2_prediction(self.gamma_rg, e["kinetic"], e["linear"],
                                        e["quadratic"])

    def fronts(self, t) -> dict[str, np.ndarray]:
        """Peak positions (grains) of the incident, transmitted and reflected waves at ``t``.

        NaN where the wave does not exist (before or after the crossing).
        """
        t = np.asarray(t, dtype=float)
        d = self.left["d"]
        x_in = self.incident.x0 + self.speed_in * (t - self.incident.measured_at) / d
        out = {"incident": np.where(t <= self.t_hit, x_in, np.nan),
               "transmitted": np.full(t.shape, np.nan), "reflected": np.full(t.shape, np.nan)}
        if self.has_interface:
            after = t > self.t_hit
            dt = t - self.t_hit
            out["transmitted"] = np.where(after, self.x_interface + self.speed_tr * dt / d,
                                          np.nan)
            out["reflected"] = np.where(after & np.isfinite(self.speed_re),
                                        self.x_interface - np.nan_to_num(self.speed_re)
                                        * dt / d, np.nan)
        return out

    def partition(self, t) -> dict[str, np.ndarray]:
        """Total energy left and right of the interface / incident energy, at ``t``.

        A step at :attr:`t_hit` from (1, 0) to (Et_re, Et_tr) — linear acoustics has no
        duration of the crossing.  Keys ``left``, ``right``.
        """
        t = np.asarray(t, dtype=float)
        r = self.ratios
        if not r:
            return {"left": np.ones(t.shape), "right": np.zeros(t.shape)}
        after = t > self.t_hit
        return {"left": np.where(after, r["Et_re"], 1.0),
                "right": np.where(after, r["Et_tr"], 0.0)}

    def classes(self) -> dict[str, Any]:
        """Predicted classes (Fig. 7 region, fracture/squeeze, reflected wave)."""
        if not self.interface_theory:
            return {}
        pred = theory.predict(self.alpha_rho, self.alpha_kn)
        return {"region": pred.region,
                "transmitted": "fracture" if pred.gamma_c0 > 1 else "squeeze",
                "reflected": "compressive" if pred.gamma_RG > 1 else (
                    "expansive" if pred.gamma_RG < 1 else "none"),
                "fission_parameter": float(theory.fission_parameter(self.alpha_rho,
                                                                    self.alpha_kn))}

    def to_dict(self) -> dict[str, Any]:
        """Plain numbers (JSON-able)."""
        out = {"incident": dataclasses.asdict(self.incident), "interface": self.interface,
               "alpha_rho": self.alpha_rho, "alpha_kn": self.alpha_kn,
               "speed_in": self.speed_in, "left": self.left, "right": self.right,
               "energies_in": self.energies_in, "interface_note": self.interface_note,
               "strong_note": self.strong_note,
               "chain_theory": (self.chain_theory.to_dict() if self.chain_theory
                                else None),
               "chain_theory_note": self.chain_theory_note}
        strong = self.strong
        if strong is not None:
            d = strong.to_dict()
            d.pop("waves", None)
            out["strong"] = d
        if self.interface_theory:
            out.update(gamma_c0=self.gamma_c0, gamma_rg=self.gamma_rg,
                       strain_tr=self.strain_tr, strain_re=self.strain_re,
                       speed_tr=self.speed_tr, speed_re=self.speed_re, t_hit=self.t_hit,
                       ratios=self.ratios, classes=self.classes())
        return out


# -- the theory of chains beyond the paper ------------------------------------------------
FORMED_GRAINS = 20
"""Grains an impact's wave needs to form (an equal-mass impact's wave is the settled
solitary wave within ~20 grains, paper Fig. 2): the theory of a chain is compared from
there on."""

@dataclass
class ChainTheory:
    """The theory of the leading wave of a chain beyond the paper's (docs/physics.md §14).

    One published (or here derived and tested) closed form per kind of chain, each
    compared with the discrete chain by :mod:`hertzchain.compare` on one quantity:

    * ``"gravity"``: arrival times along a vertical chain, the adiabatic solitary wave
      at the local static load (:func:`theory.gravity.solitary_wave_descent`), or the
      weak pulse's WKB + Airy front (:func:`theory.gravity.weak_pulse_arrival_times`)
      when the wave is weak (A < δ0) at the first contact — ``travel_time``;
    * ``"taper"``: the adiabatic solitary wave of the local grains carrying the energy
      of the wave that enters the taper (:func:`theory.tapers.adiabatic_taper_wave`) —
      ``travel_time``;
    * ``"periodic"``: the homogenised cell's Nesterenko speed at the wave's peak contact
      force (:func:`theory.dimers.cell_solitary_speed`) — ``travel_time``;
    * ``"linear"`` (F = k δ, one uniform section struck at grain 0): Schrödinger's (1914)
      solution v_i = v0 J_{2i}(ωt), ω = 2√(k/m), whose velocity peak passes grain i when
      ωt is the first maximum of J_{2i}, 2i + 0.8086 (2i)^{1/3} + O(i^{-1/3})
      (Abramowitz & Stegun 9.5.16; the Airy head of docs/physics.md §14) —
      ``travel_time``;
    * ``"drag"``, ``"viscoelastic"``: the first-order decay of the leading solitary wave
      (:func:`theory.dissipation.drag_wave_decay`,
      :func:`theory.dissipation.kuwabara_kono_wave_decay`) — ``peak_velocity``;
    * ``"striker"``: the geometric train of a heavy striker (:func:`theory.striker.striker_train`)
      — ``leading_peak`` and ``wave_count``.

    Attributes
    ----------
    kind : str
        One of the kinds above.
    label : str
        The theory and its function, for reports.
    accuracy : float
        Its measured relative accuracy against the discrete chain (docs/physics.md §14),
        the scale of its comparison.
    first, last : int
        The grains [first, last) the theory describes (a section).
    front : str
        ``"incident"`` or ``"transmitted"``: the sampled front that carries the wave there
        (:func:`hertzchain.measure.sample_fronts`).
    quantity : str
        ``"travel_time"``, ``"peak_velocity"`` or ``"leading_peak"``.
    params : dict
        The numbers it is evaluated with (JSON-able).
    """

    kind: str
    label: str
    accuracy: float
    first: int
    last: int
    front: str
    quantity: str
    params: dict = field(default_factory=dict)
    chain: Any = field(default=None, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """Plain numbers (JSON-able)."""
        return {"kind": self.kind, "label": self.label, "accuracy": self.accuracy,
                "first": self.first, "last": self.last, "front": self.front,
                "quantity": self.quantity, "params": self.params}

    def travel_time(self, a: float, b: float, velocity_a: float = math.nan,
                    force_max: float = math.nan) -> float:
        """Time the wave's peak needs from grain position ``a`` to ``b`` (grains), s.

        ``velocity_a``: its peak grain velocity at ``a`` (m/s; the taper's energy),
        ``force_max``: its peak contact force (N; the periodic cell's speed).  Arrival
        times are interpolated linearly between grains.
        """
        ch, p = self.chain, self.params
        n = p["exponent"]
        if self.kind == "gravity":
            m, k, d = float(ch.mass[0]), float(ch.k[1]), float(ch.diameter[0])
            if p["weak"]:
                t = theory.gravity.weak_pulse_arrival_times(
                    ch.n, m, k, d, p["gravity"], exponent=n, top_force=p["top_force"])
            else:
                t = theory.gravity.solitary_wave_descent(
                    ch.n, m, k, d, p["gravity"], p["energy"], exponent=n,
                    top_force=p["top_force"]).arrival_time
            grains = np.arange(ch.n)
            return float(np.interp(b, grains, t) - np.interp(a, grains, t))
        if self.kind == "taper":
            start = int(math.floor(a))
            c_e = theory.tapers.sonic_vacuum_wave_constants(n).energy
            energy = c_e * float(ch.mass[start]) * velocity_a ** 2
            w = theory.tapers.adiabatic_taper_wave(ch.mass, ch.k[1:-1], ch.diameter, energy,
                                                   exponent=n, start=start)
            grains = np.arange(ch.n)
            return float(np.interp(b, grains, w.arrival_time)
                         - np.interp(a, grains, w.arrival_time))
        if self.kind == "linear":
            # the first maximum of J_ν(x) at x = ν + 0.8086165 ν^{1/3} + O(ν^{-1/3})
            # (Abramowitz & Stegun 9.5.16), ν = 2i (grain i)
            def peak(i: float) -> float:
                nu = 2.0 * i
                return (nu + 0.8086165 * nu ** (1.0 / 3.0)) / p["omega"]
            return peak(b) - peak(a)
        if self.kind == "periodic":
            cell = self._cell()
            f0 = p["static_force"]
            if not force_max > f0:
                return math.nan
            speed = float(theory.dimers.cell_solitary_speed(cell, force_max, f0))
            return (b - a) * cell.length / p["cell_grains"] / speed
        raise ValueError(f"{self.kind}: no travel time")  # pragma: no cover

    def _cell(self):
        ch, p = self.chain, self.params
        i, q = self.first, p["cell_grains"]
        return theory.dimers.homogenise_cell(ch.mass[i:i + q], ch.k[i + 1:i + q + 1],
                                             float(ch.diameter[i:i + q].sum()),
                                             exponent=p["exponent"])

    def peak_velocity(self, a: int, b: int, velocity_a: float) -> float:
        """Peak grain velocity (m/s) of the damped wave at grain ``b``, ``velocity_a`` at ``a``."""
        ch, p = self.chain, self.params
        m, k = float(ch.mass[a]), float(ch.k[a + 1])
        if self.kind == "drag":
            return float(theory.dissipation.drag_wave_decay(b - a, velocity_a, k, m,
                                                            p["drag"], exponent=p["exponent"]))
        if self.kind == "viscoelastic":
            return float(theory.dissipation.kuwabara_kono_wave_decay(
                b - a, velocity_a, k, m, p["damping_time"]))
        raise ValueError(f"{self.kind}: no decay")  # pragma: no cover

    @property
    def striker(self):
        """The striker's train (:class:`theory.striker.StrikerTrain`), or None."""
        if self.kind != "striker":
            return None
        return theory.striker.striker_train(self.params["mass_ratio"], self.params["v0"],
                                            exponent=self.params["exponent"])


def chain_theory(scenario: Scenario, chain: discrete.Chain, init) -> tuple[
        ChainTheory | None, str]:
    """The :class:`ChainTheory` of a scenario's chain, or (None, why) where none applies.

    (None, "") for the paper's chain and for uniform lossless power-law chains, whose
    leading wave is the steady solitary wave of :class:`TheoryModel` (its speed is
    compared as it stands).
    """
    spec, ini = scenario.chain, scenario.initial
    n = chain_exponent(chain)
    s0 = M.first_grain(chain)
    bounds = np.r_[s0, np.asarray(interfaces(chain), dtype=int), chain.n]
    uniform = [s.uniform for s in spec.sections]
    placed = ini.initial_kind.placed  # else: the wave forms on the way (an impact's)
    x0 = M.incident_peak(chain, np.asarray(init.v))[0] if placed else s0
    formed = (s0 + FORMED_GRAINS if not placed
              else int(math.ceil(x0 if math.isfinite(x0) else s0)) + 3)
    p: dict[str, Any] = {"exponent": n}
    sonic = spec.delta0_over_d == 0 and spec.gravity == 0
    if ini.striker_grains:
        if not (sonic and spec.law == "power" and not spec.drag and uniform[0]):
            return None, ("the striker's train is known for a lossless uniform power-law "
                          "chain at δ0 = 0 only (theory.striker)")
        p.update(mass_ratio=ini.striker_mass, v0=ini.v0)
        return ChainTheory("striker", "geometric train of exact solitary waves "
                           "(theory.striker.striker_train)", 0.03, s0 + 1, int(bounds[1]),
                           "incident", "leading_peak", p, chain), ""
    if spec.gravity > 0:
        if len(spec.sections) > 1 or not uniform[0] or spec.law != "power" or spec.drag:
            return None, ("the gravity theory (theory.gravity) is for one section of "
                          "identical grains with a lossless power law")
        v0 = float(np.max(np.abs(init.v)))
        m, k = float(chain.mass[0]), float(chain.k[1])
        energy = 0.5 * m * v0 ** 2
        d01 = float(chain.delta0[1])
        amp = float(theory.gravity.solitary_wave_amplitude(energy, k, d01, exponent=n))
        p.update(gravity=spec.gravity, top_force=spec.top_force, energy=energy,
                 weak=bool(amp < d01))
        label = ("weak pulse, WKB + Airy front (theory.gravity.weak_pulse_arrival_times)"
                 if p["weak"] else "adiabatic solitary wave at the local static load "
                 "(theory.gravity.solitary_wave_descent)")
        return ChainTheory("gravity", label, 0.02, formed, chain.n, "incident",
                           "travel_time", p, chain), ""
    if spec.drag > 0 or spec.law == "viscoelastic_hertz":
        kind = "drag" if spec.drag > 0 else "viscoelastic"
        if spec.drag > 0 and spec.law != "power":
            return None, "drag with a dissipative law: no closed form combines the two"
        if spec.delta0_over_d > 0 or not uniform[0]:
            return None, (f"the decay of a {kind}-damped solitary wave is known at δ0 = 0 "
                          "in a uniform section (theory.dissipation)")
        if kind == "drag":
            p["drag"] = spec.drag
            label = "first-order drag decay (theory.dissipation.drag_wave_decay)"
        else:
            p["damping_time"] = spec.law_values["damping_time"]
            label = ("first-order Kuwabara–Kono decay "
                     "(theory.dissipation.kuwabara_kono_wave_decay)")
        return ChainTheory(kind, label, 0.03, formed, int(bounds[1]), "incident",
                           "peak_velocity", p, chain), ""
    if n == 1.0 and len(spec.sections) == 1 and uniform[0] \
            and ini.initial_kind.single_struck_grain and not ini.striker_grains:
        k, m = float(chain.k[s0 + 1]), float(chain.mass[s0])
        p["omega"] = 2.0 * math.sqrt(k / m)
        return ChainTheory("linear", "Schrödinger's Bessel-function front of a linear "
                           "chain, J_2i(ωt)", 0.02, formed, chain.n, "incident",
                           "travel_time", p, chain), ""
    for i, sec in enumerate(spec.sections):
        if sec.profile == "uniform":
            continue
        if i > 1 or any(not u for u in uniform[:i]):
            return None, (f"[chain.sections[{i}]]: the theory follows the wave through one "
                          "profiled section after a uniform one")
        first, last = int(bounds[i]), int(bounds[i + 1])
        front = "incident" if i == 0 else "transmitted"
        start = max(first, formed) + (M.FIT_FROM if i > 0 else 0)
        if sec.profile == "tapered":
            # the exact wave of the local grains from a few grains on (docs/physics.md
            # §14: the adiabatic wave holds from grain 5 of an impact)
            start = first + M.FIT_FROM if i > 0 else s0 + 5
            if spec.delta0_over_d > 0:
                return None, ("the adiabatic taper wave (theory.tapers) is the exact wave "
                              "at δ0 = 0; no theory for a precompressed taper")
            return ChainTheory("taper", "adiabatic solitary wave of the local grains "
                               "(theory.tapers.adiabatic_taper_wave)", 0.015, start, last,
                               front, "travel_time", p, chain), ""
        cell = len(sec.cell_diameters)
        p.update(cell_grains=cell, static_force=float(chain.k[first + 1]
                                                      * chain.delta0[first + 1] ** n))
        return ChainTheory("periodic", "homogenised cell, Nesterenko's speed at the peak "
                           "contact force (theory.dimers.cell_solitary_speed)", 0.02,
                           start, last, front, "travel_time", p, chain), ""
    return None, ""


def interface_applies(scenario: Scenario) -> tuple[str, str]:
    """Why the linear (Eqs. 9–13) and the strong interface theory do not apply ("" if they do).

    Both are derived for two uniform sections of equal diameters joined by a lossless
    contact law without gravity: Eqs. 9–13 for Hertz (their exponents 1/2, 1/3 are
    Hertz's), the strongly nonlinear theory for Hertz at any precompression and for
    any exponent in the sonic vacuum (:func:`theory.strong_interface.predict_strong`).
    """
    spec = scenario.chain
    if len(spec.sections) < 2:
        return "one section: no interface", "one section: no interface"
    why = []
    for i in (0, 1):
        s = spec.sections[i]
        if not s.uniform:
            why.append(f"[chain.sections[{i}]] is not uniform (profile {s.profile!r}"
                       + (", disorder" if s.profile == "uniform" else "") + ")")
    d_left, d_right = (s.diameter or spec.diameter for s in spec.sections[:2])
    if d_left != d_right:
        why.append(f"the diameters differ ({d_left!r}, {d_right!r} m; the interface "
                   "theories are for equal diameters)")
    if spec.law != "power" or spec.drag:
        why.append("the contact law dissipates (no interface theory with losses)")
    if spec.gravity:
        why.append("gravity loads the chain non-uniformly")
    if scenario.initial.striker_grains:
        why.append("a striker's train, not one solitary wave, meets the interface")
    common = "; ".join(why)
    linear = common or ("" if spec.exponent == 1.5 else
                        f"Eqs. 9–13 are Hertz's (exponent 1.5; [chain] exponent = "
                        f"{spec.exponent!r})")
    strong = common or ("" if spec.exponent == 1.5 or spec.delta0_over_d == 0 else
                        "the precompressed solitary waves are known for Hertz only")
    return linear, strong


def strain_from_velocity(side: dict, velocity: float) -> float:
    """Peak strain ξ of the solitary wave with peak grain velocity ``velocity`` (m/s).

    Solves v = V(ξ) ξ (v = V ξ for any right-going travelling wave, with Nesterenko's
    speed V, :func:`theory.nesterenko_speed`).  The peak grain velocity is what a
    settled wave is known by (the paper's v̄max, Fig. 2); a peak strain read off the
    contacts of a wave a few grains wide depends on where the wave sits between them.

    Memoised on what it depends on, (c_mat, ξ0, c0, v) of ``side``: a sweep's points
    share their incident wave (Fig. 7's 408 points one cut wave), and the bisection
    costs ~60 speed evaluations.
    """
    return _strain_from_velocity(float(side["c_mat"]), float(side["xi0"]),
                                 float(side["c0"]), float(velocity),
                                 float(side.get("exponent", 1.5)))


@functools.lru_cache(maxsize=256)
def _strain_from_velocity(c_mat: float, xi0: float, c0: float, velocity: float,
                          exponent: float = 1.5) -> float:
    """:func:`strain_from_velocity` of the side's wave speeds (m/s; ξ0 = δ0/d; exponent n)."""
    side = {"c_mat": c_mat, "xi0": xi0, "c0": c0, "exponent": exponent}
    if not velocity > 0:
        return math.nan
    hi = 1e-12
    while _speed(side, hi) * hi < velocity:
        hi *= 4.0
        if hi > 1.0:
            return math.nan
    # bisection of the increasing V(ξ)ξ - v on [0, hi] to 1e-13 relative (not scipy's
    # brentq: importing scipy.optimize would add to every run's start-up)
    lo = hi / 4.0 if hi > 1e-12 else 0.0
    while hi - lo > 1e-13 * hi:
        mid = 0.5 * (lo + hi)
        if _speed(side, mid) * mid < velocity:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _left(chain: discrete.Chain, ifaces: list[int]) -> dict[str, float]:
    """Grain and contact parameters of the first section (past a striker)."""
    s0 = M.first_grain(chain)  # a striker grain
    n_first = ifaces[0] if ifaces else chain.n
    mid = s0 + (n_first - s0) // 2
    return _side(chain, mid, max(mid, 1))


def incident_wave(chain: discrete.Chain, init, kind: str, left: dict, law=None,
                  drag: float = 0.0) -> IncidentWave:
    """The incident wave of an initial state (an impact's: estimated, see :func:`run`).

    ``kind``: the ``[initial] kind``, whose registered
    :class:`hertzchain.initial_kinds.InitialKind` says whether the state is the wave
    (``placed``) and gives its peak velocity (``incident_velocity``).
    Position: the peak of the grain kinetic energy (parabola-refined,
    :func:`hertzchain.measure.incident_peak`).  Amplitude: the peak grain velocity (an
    exact wave's own; a cut, settled wave's as measured when it was cut) and the
    theory's strain for it, :func:`strain_from_velocity` (at δ0 = 0 the compacton's
    peak strain is ~8 % above the exact discrete wave's at the same peak velocity;
    under precompression they agree to ~1e-3); ``peak_strain``: the wave's own, measured
    on the state's contacts (:func:`hertzchain.measure.incident_strain`, any law).  An
    impact's wave forms on the way: 0.68 v0 (v̄max/v0 at δ0 = 0, paper Fig. 2) is only
    the estimate that places the samples; it is measured on the discrete run
    (:func:`incident_from_run`).  ``law``, ``drag``: the chain's contact law
    (:mod:`theory.laws`, default Hertz) and on-site drag rate, 1/s.
    """
    from .initial_kinds import initial_kind

    v = np.asarray(init.v)
    how = initial_kind(kind)
    vel = how.incident_velocity(init)
    if not how.placed:
        return IncidentWave(0.0, vel, strain_from_velocity(left, vel))
    x0, _ = M.incident_peak(chain, v)
    if not math.isfinite(x0):
        x0 = float(np.argmax(0.5 * chain.mass * v**2))
    r = D.overlaps_from_displacements(init.u, chain.delta0, init.wall_left, init.wall_right)
    law = discrete.PowerLaw(1.5) if law is None else law
    return IncidentWave(x0, vel, strain_from_velocity(left, vel),
                        peak_strain=M.incident_strain(chain, v, r, law, drag))


def incident_from_run(sim: discrete.Simulation, left: dict,
                      strain: float) -> IncidentWave | None:
    """An impact's incident wave, measured on the discrete run (None if it was not).

    On the snapshot taken when its velocity peak passed
    :func:`hertzchain.measure.incident_grain` (the middle of section 0): position and
    peak velocity (:func:`hertzchain.measure.incident_peak`), the theory's strain for
    that velocity, and ``strain``, the run summary's measured ``incident_strain``.  The
    same measurement whether or not the run was sampled for a continuum.
    """
    label = discrete.WaveAt(M.incident_grain(sim.chain)).label
    snap = next((s for s in sim.record.snapshots if s.label == label), None)
    if snap is None:
        return None
    x0, vel = M.incident_peak(sim.chain, snap.v)
    if not (math.isfinite(x0) and vel > 0):
        return None
    return IncidentWave(x0, vel, strain_from_velocity(left, vel), float(snap.t),
                        peak_strain=strain)


def _theory(chain: discrete.Chain, init, incident: IncidentWave, ifaces: list[int],
            left: dict, scenario: Scenario | None = None) -> TheoryModel:
    """The theory of the chain and its first interface, from the built chain and initial state.

    With ``scenario``: which interface theories apply (:func:`interface_applies`) and
    the theory of the chain beyond the paper (:func:`chain_theory`).
    """
    tm = _theory_paper(chain, init, incident, ifaces, left)
    if scenario is not None:
        tm.interface_note, tm.strong_note = interface_applies(scenario)
        if not ifaces:
            tm.interface_note = tm.strong_note = ""
        tm.chain_theory, tm.chain_theory_note = chain_theory(scenario, chain, init)
    return tm


def _theory_paper(chain: discrete.Chain, init, incident: IncidentWave, ifaces: list[int],
                  left: dict) -> TheoryModel:
    """The theory of the first interface (Eqs. 9–13), from the built chain and initial state."""
    en = D.chain_energies_of(chain, np.asarray(init.v), u=np.asarray(init.u),
                             wall_left=init.wall_left, wall_right=init.wall_right)
    if ifaces:  # the incident wave's energy: everything left of the interface
        en_left = D.section_sums(en, np.where(np.arange(chain.n) < ifaces[0], 0, 1))
        energies = {k: float(en_left[k][0]) for k in ("kinetic", "linear", "quadratic")}
    else:
        energies = {k: float(np.sum(getattr(en, k))) for k in ("kinetic", "linear")}
        energies["quadratic"] = float(np.sum(en.contact) - energies["linear"])
    if not ifaces:
        return TheoryModel(incident, left, energies_in=energies)
    i = ifaces[0]
    n_second = (ifaces[1] if len(ifaces) > 1 else chain.n) - i
    right = _side(chain, i + n_second // 2, i + max(n_second // 2, 1))
    return TheoryModel(incident, left, i, right, energies,
                       alpha_rho=right["mass"] / left["mass"],
                       alpha_kn=right["k"] / left["k"])


# -- sample times ---------------------------------------------------------------------
def sample_grid(scenario: Scenario, theory_model: TheoryModel, chain: discrete.Chain
                ) -> tuple[np.ndarray, float]:
    """Sample times (s) to request and their spacing (s).

    ``[run] t_end`` alone: ``samples`` times from 0 to t_end.  With ``until_front_at``:
    spaced by the theory's estimate of the stop time / (samples − 1), requested up to
    :data:`_ESTIMATE_MARGIN` × the estimate (later ones are not taken); ``samples = 2``:
    t = 0 only (the final state, at the stop event, is always the last sample).
    """
    k = scenario.models.samples
    run = scenario.run
    if run.until_front_at is None:
        return np.linspace(0.0, run.t_end, k), run.t_end / (k - 1)
    if k == 2:  # the initial state and the final one (the stop event)
        return np.zeros(1), math.inf
    est = estimate_arrival(theory_model, chain, run.until_front_at)
    if run.t_end is not None:
        est = min(est, run.t_end)
    step = est / (k - 1)
    n = k * _ESTIMATE_MARGIN
    times = step * np.arange(n)
    if run.t_end is not None:
        times = times[times <= run.t_end * (1 + 1e-12)]
    return times, step


def estimate_arrival(tm: TheoryModel, chain: discrete.Chain, grain: int) -> float:
    """Theory's estimate of when the leading wave's peak reaches ``grain``, s."""
    d = float(chain.diameter[0])
    v_in = tm.speed_in
    if not (v_in > 0 and math.isfinite(v_in)):
        raise ScenarioError("[run] until_front_at: the theory cannot estimate the wave "
                            "speed of this initial state; give t_end")
    if not tm.has_interface or grain <= tm.x_interface:
        return tm.incident.measured_at + max(grain - tm.incident.x0, 1.0) * d / v_in
    return tm.t_hit + (grain - tm.x_interface) * d / tm.speed_tr


# -- discrete -------------------------------------------------------------------------
def _discrete_label(scenario: Scenario) -> str:
    integ = scenario.run.integrator
    return "discrete" + ("" if integ == "verlet" else f" ({integ})")


def _effective(scenario: Scenario, times: np.ndarray, *, keep_name: bool = False
               ) -> Scenario:
    """The scenario the discrete solver runs: sample times added to its snapshots.

    ``[models]`` is reset (and ``name`` unless ``keep_name``): they do not change the
    discrete run, whose cached file and checkpoint are then shared.
    """
    rec = scenario.record
    snaps = tuple(sorted(set(rec.snapshot_times) | {float(t) for t in times}))
    return scenario.replace(record=dataclasses.replace(rec, snapshot_times=snaps),
                            models=ModelsSpec(), name=scenario.name if keep_name else "")


def _samples_from_sim(sim: discrete.Simulation, times: np.ndarray, init
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(times, v, strain) of the snapshots taken at the sample times, then the final state.

    Without sample times: the initial state and the final state.
    """
    by_label = {sn.label: sn for sn in sim.record.snapshots}
    chain = sim.chain
    ts, vs, ss = [], [], []
    last = -math.inf
    if not len(times):
        ts.append(0.0)
        vs.append(np.asarray(init.v))
        ss.append(D.overlaps_from_displacements(init.u, chain.delta0, init.wall_left,
                                                init.wall_right) - chain.delta0)
        last = 0.0
    for t in times:
        sn = by_label.get(discrete.AtTime(float(t)).label)
        if sn is None or sn.t > sim.t:
            continue
        ts.append(float(t))
        vs.append(np.asarray(sn.v))
        ss.append(np.asarray(sn.overlaps) - chain.delta0)
        last = sn.t
    if sim.t > last:  # the final state (a stop event between two sample times)
        ts.append(float(sim.t))
        vs.append(np.asarray(sim.v).copy())
        ss.append(np.asarray(sim.overlaps()) - chain.delta0)
    return np.array(ts), np.array(vs), np.array(ss)


def _outcome(scenario: Scenario, summary: dict, sim: discrete.Simulation) -> dict:
    """``stopped_by``, ``completed``, ``incomplete_reason`` of the discrete run.

    :func:`hertzchain.runner.run_outcome` for the scenario's own snapshots: the common
    sample times requested past a stop event (:func:`sample_grid`) are not required.
    """
    from .runner import run_outcome

    return run_outcome(scenario, sim, summary.get("stopped_by", "t_end"))


def _run_discrete(scenario: Scenario, times: np.ndarray, *, cache, stem, out, force,
                  checkpoint_interval, resume, progress, threads, log, check,
                  wave_cache, init, save) -> tuple[ModelRun, discrete.Simulation]:
    eff = _effective(scenario, times, keep_name=out is not None)
    key = eff.discrete_dict()
    path = Path(out) if out is not None else (
        cache_path(cache, stem, key) if cache is not None else None)
    time.perf_counter()
    sim = summary = None
    cached = False
    if path is not None and out is None and path.exists() and not force:
        try:
            sim = discrete.load(path)  # verified (theory.integrity)
            with integrity.open_hdf5(path, what="cached result") as f:
                summary = json.loads(f.attrs["summary"])
            cached = True
        except (OSError, ValueError, KeyError) as exc:  # unreadable or unfinished
            sim = summary = None
            message = f"recomputing the cached run {path}: {exc}"
            if log is not None:
                log(message)
            else:
                warnings.warn(message, RuntimeWarning, stacklevel=3)
    if sim is None:
        if path is not None and force:
            ckpt = C.checkpoint_path(path)
            if ckpt.exists():
                ckpt.unlink()
        summary, sim = run_simulation(
            eff, out=path, progress=progress,
            checkpoint_interval=checkpoint_interval,
            resume=resume and not force, threads=threads, check=check, log=log,
            cache_dir=wave_cache, save=save, init=init)
    ts, vs, ss = _samples_from_sim(sim, times, init)
    summary = {**summary, **_outcome(scenario, summary, sim)}
    completed, stopped = bool(summary["completed"]), str(summary["stopped_by"])
    params = {"scenario": key, "dt": float(sim.dt), "integrator": scenario.run.integrator}
    return ModelRun("discrete", _discrete_label(scenario), ts, vs, ss, float(sim.t),
                    completed=completed, stopped_by=stopped, summary=dict(summary),
                    params=params, path=path if cached or save else None,
                    cached=cached), sim


# -- continuum -------------------------------------------------------------------------
def _medium(chain: discrete.Chain, scenario: Scenario):
    """The chain's coefficients with the scenario's law and drag (:meth:`discrete.Chain.medium`).

    Sections, tapers, gravity and periodic cells all enter as per-grain and per-contact
    coefficients (the continuum homogenises periodic sections itself).
    """
    from .runner import build_law

    law, drag = build_law(scenario.chain)
    try:
        return chain.medium(law, drag)
    except ValueError as exc:
        raise ScenarioError(f"[models] continuum: {exc}") from exc


KDV_LABEL = "KdV"
"""Legend text of ``[models] continuum = "kdv"`` (:class:`continuum.KdVPDE`, run on its own
path: not a model of :data:`continuum.MODELS`)."""


def continuum_label(model: str, models: ModelsSpec) -> str:
    """Legend text of a continuum model (its :attr:`continuum.ChainPDEBase.label`)."""
    import continuum

    name = continuum.MODELS[model].label if model in continuum.MODELS else KDV_LABEL
    return f"continuum ({name}, {models.nodes_per_grain} nodes/grain)"


def _ends(scenario: Scenario, init) -> str:
    """The continuum's end condition for this initial state (module docstring)."""
    walls = "free" not in (scenario.chain.left_wall, scenario.chain.right_wall)
    at_rest = not np.any(init.u) and init.wall_left == 0 and init.wall_right == 0
    return "wall" if walls and at_rest else "free"


def _continuum_key(scenario: Scenario, model: str, times: np.ndarray, t_final: float,
                   discrete_key: dict) -> dict:
    m = scenario.models
    method, safety = m.continuum_step(model)  # resolved: the model's own where not given
    return {"discrete": discrete_key, "model": model, "nodes_per_grain": m.nodes_per_grain,
            "integrator": method, "dt_safety": safety,
            "nonlinearity": m.nonlinearity, "delta_floor": m.delta_floor,
            "dispersion_cap": m.dispersion_cap,
            "times": [float(t) for t in times], "t_final": float(t_final),
            **({"interpolation": interp} if (interp := _launch(scenario, model)) != "spline"
               else {})}


def _launch(scenario: Scenario, model: str) -> str:
    """How the grain state is put on the model's nodes (:func:`continuum.from_grains`).

    The kind's choice, ``"smooth"`` resolved to the model's own: part of the cache key,
    since a run launched another way is another run.
    """
    import continuum

    return continuum.launch_interpolation(continuum.MODELS.get(model),
                                          scenario.initial.initial_kind.interpolation)


def _read_continuum(path: Path) -> ModelRun:
    with integrity.open_hdf5(path, what="continuum result") as f:
        if f.attrs.get("format") != FORMAT:
            raise ValueError(f"{path}: not a continuum result ({FORMAT})")
        g = f["samples"]
        run_ = ModelRun("continuum", str(f.attrs["label"]), g["t"][()], g["v"][()],
                        g["strain"][()], float(f.attrs["t_final"]),
                        completed=bool(f.attrs["completed"]),
                        stopped_by=str(f.attrs["stopped_by"]),
                        summary={**json.loads(f.attrs["summary"]),
                                 "wall_time": float(f.attrs["wall_time"])},
                        params=json.loads(f.attrs["params"]), path=path, cached=True,
                        own_energy=g["own_energy"][()] if "own_energy" in g else None)
    return run_


def _write_continuum(path: Path, run_: ModelRun, scenario: Scenario) -> None:
    with integrity.sealed_hdf5(path) as f:
        f.attrs["format"] = FORMAT
        f.attrs["label"] = run_.label
        f.attrs["t_final"] = run_.t_final
        f.attrs["completed"] = run_.completed
        f.attrs["stopped_by"] = run_.stopped_by
        summary = dict(run_.summary)
        f.attrs["wall_time"] = float(summary.pop("wall_time", math.nan))
        f.attrs["summary"] = canonical_json(summary)
        f.attrs["params"] = canonical_json(run_.params)
        f.attrs["scenario"] = canonical_json(scenario.to_dict())
        f.attrs["units"] = canonical_json({"t": "s", "v": "m/s", "strain": "m",
                                           "own_energy": "J"})
        g = f.create_group("samples")
        arrays = [("t", run_.times), ("v", run_.v), ("strain", run_.strain)]
        if run_.own_energy is not None:
            arrays.append(("own_energy", run_.own_energy))
        for name, data in arrays:
            g.create_dataset(name, data=data, compression="gzip" if data.size > 64 else None,
                             fletcher32=data.size > 64)


def _pde(model: str, med, models: ModelsSpec, bc: str, incident: IncidentWave, d: float):
    """The continuum model ``model`` of :data:`continuum.MODELS` for the medium ``med``.

    Its ``for_chain`` reads the scenario's continuum settings and the incident wave's
    peak overlap (m, ``incident.strain`` × d: Eq. 7's floor is a fraction of it).
    """
    import continuum

    if model not in continuum.MODELS:
        raise ScenarioError(f"[models] continuum = {model!r} is not a registered continuum "
                            f"model: {sorted(continuum.MODELS)} or \"kdv\"")
    options = {"nonlinearity": models.nonlinearity, "delta_floor": models.delta_floor,
               "dispersion_cap": models.dispersion_cap,
               "incident_overlap": float(incident.strain) * d}
    try:
        return continuum.MODELS[model].for_chain(med, nodes_per_grain=models.nodes_per_grain,
                                                 bc=bc, options=options)
    except ValueError as exc:
        raise ScenarioError(f"[models] continuum = {model!r}: {exc}") from exc


def _kdv_run(med, models, init, chain, times, t_final, d):
    """KdV (one precompressed section, periodic): (times, v, strain, summary)."""
    from scipy.interpolate import CubicSpline

    import continuum

    pde = continuum.KdVPDE.for_medium(med, med.n_grains // 2)
    n = models.nodes_per_grain
    grid = continuum.KdVPDE.grid(med.n_grains, n)
    strain = D.overlaps_from_displacements(init.u, chain.delta0, init.wall_left,
                                           init.wall_right) - chain.delta0
    xc = np.arange(1, chain.n) - 0.5  # inner contacts
    x = grid.axes_coords[0]
    from pde import ScalarField

    s0 = ScalarField(grid, CubicSpline(xc, strain[1:-1])(np.clip(x, xc[0], xc[-1])))
    centres = (np.arange(chain.n) * n + (n - 1) // 2)

    def sample(s):
        data = np.asarray(s.data)
        v = pde.speed * data[centres]
        st = np.zeros(chain.n + 1)
        st[1:-1] = 0.5 * (data[centres[:-1]] + data[centres[1:]])
        return v, st

    ts, (vs, ss), info = _stepped(pde, s0, times, t_final, sample, pde.stable_dt(s0),
                                  rk=True)
    return ts, vs, ss, None, info


def _stepped(pde, state, times, t_final, sample, dt_max, *, method="position_yoshida4",
             rk=False):
    """Run to the sample times (exactly, dt dividing their spacing) and on to t_final.

    ``sample(state)`` returns a tuple of arrays; returns (times, [each stacked], info).
    ``method``: the splitting method (:mod:`theory.splitting`) of a chain PDE; ``rk``:
    py-pde's RK4 (KdV).
    """
    from pde.trackers import CallbackTracker

    import continuum

    ts, out = [], []
    inner = times[(times > 0) & (times <= t_final * (1 + 1e-12))]
    spacing = float(times[1] - times[0]) if times.size > 1 else t_final
    t_last = float(inner[-1]) if inner.size else 0.0
    m = max(1, math.ceil(spacing / dt_max))
    dt = spacing / m
    ts.append(0.0)
    out.append(sample(state))

    def track(s, t):
        if t > 0.5 * dt:
            ts.append(float(times[len(ts)]) if len(ts) < times.size else float(t))
            out.append(sample(s))

    info: dict[str, Any] = {"dt": dt, "steps": 0}
    drift = math.nan
    if t_last > 0:
        tracker = CallbackTracker(track, interrupts=spacing)
        if rk:
            state = pde.solve(state, t_range=t_last, dt=dt, solver="runge-kutta",
                              tracker=[tracker], backend="numba", ret_info=False)
        else:
            res = continuum.run(pde, state, t_last, dt=dt, method=method, interval=spacing,
                                trackers=[tracker])
            state, drift = res["state"], res.energy_drift
        info["steps"] += int(round(t_last / dt))
    rest = t_final - t_last
    if rest > 1e-9 * max(t_final, 1e-300):
        m2 = max(1, math.ceil(rest / dt_max))
        dt2 = rest / m2
        if rk:
            state = pde.solve(state, t_range=rest, dt=dt2, solver="runge-kutta",
                              backend="numba", ret_info=False)
        else:
            res = continuum.run(pde, state, rest, dt=dt2, method=method, interval=rest)
            state = res["state"]
            drift = max(drift, res.energy_drift) if math.isfinite(drift) else res.energy_drift
        info["steps"] += m2
        ts.append(float(t_final))
        out.append(sample(state))
    info["energy_drift"] = drift
    return np.array(ts), [np.array(c) for c in zip(*out, strict=True)], info


def _own_energy(pde, state, grains, iface: int | None) -> np.ndarray:
    """The continuum's functional energy left and right of the interface contact, J.

    [kinetic left, kinetic right, potential left, potential right]: the equation's own
    densities (:meth:`energy_density`: kinetic per node with the Rosenau term u_Xt²,
    dynamic potential per face), nodes and faces left of the interface contact (x =
    iface − ½, in grains) on the left, a face on it half to each side; the potential
    gets the linear part F0 × the overlap change back (Table 2's definition,
    docs/physics.md §6), summed from the grain samples ``grains``
    (:func:`continuum.sample_grains`: it telescopes to the displacements at the section
    ends, as the functional's does).  Once the waves have left the interface the two
    potentials agree to the grid's round-off; the kinetic energies differ from the
    grain-sampled ones by the long-wave error O(d²/L²) (0.7 % for Table 2's point P).
    """
    ek, ep = pde.energy_density(state)
    disc = pde.disc
    lin = grains.force0 * grains.strain
    if iface is None:
        return np.array([float(ek.sum()), 0.0, float(ep.sum() + lin.sum()), 0.0])
    x_i = iface - 0.5
    wn = (disc.x_nodes < x_i).astype(float)
    wf = np.where(np.isclose(disc.x_faces, x_i), 0.5, (disc.x_faces < x_i).astype(float))
    lin_left = float(lin[:iface].sum() + 0.5 * lin[iface])
    lin_right = float(lin[iface + 1:].sum() + 0.5 * lin[iface])
    return np.array([float(ek @ wn), float(ek @ (1 - wn)), float(ep @ wf) + lin_left,
                     float(ep @ (1 - wf)) + lin_right])


def _dt_max(pde, state, strain_ref: float, safety: float = 0.5) -> float:
    """Largest continuum time step: stable for ``state`` and for a strain ``strain_ref`` (m).

    The stability limit of the nonlinear equations depends on the strain; an impact
    starts with none (its limit would be infinite), a transmitted wave may be stronger
    than the incident one, so the limit is also taken at a uniform strain
    ``strain_ref`` (:func:`run`: 1.5 × the largest expected wave strain).  ``safety``:
    ``pde.stable_dt``'s fraction of velocity Verlet's limit (``[models] dt_safety`` or
    the model's own, :meth:`hertzchain.scenario.ModelsSpec.continuum_step`, which checks
    it against the method's own limit).
    """
    x = pde.disc.x_nodes
    ref = pde.get_initial_condition(-strain_ref * (x - x[0]))
    return float(min(pde.stable_dt(state, safety), pde.stable_dt(ref, safety)))


def _run_continuum(scenario: Scenario, chain, init, incident: IncidentWave, times, t_final,
                   *, cache, stem, out, force, discrete_key, progress, log,
                   strain_ref: float) -> ModelRun:
    import continuum

    models = scenario.models
    d0 = float(scenario.chain.delta0_over_d)
    # "auto": the one rule, from the chain and the incident strain amplitude / δ0
    amp = incident.amplitude / d0 if d0 > 0 and math.isfinite(incident.amplitude) else None
    model = models.continuum_model(scenario.chain, amp)
    label = continuum_label(model, models)
    times = np.asarray(times)
    times = times[times <= t_final * (1 + 1e-12)]
    key = _continuum_key(scenario, model, times, t_final, discrete_key)
    path = Path(out) if out is not None else (
        cache_path(cache, f"{stem}-continuum", key) if cache is not None else None)
    if path is not None and path.exists() and not force:
        try:
            found = _read_continuum(path)
            # every parameter of the key, not only the times: a file written with another
            # integrator, dt_safety, nodes per grain ... (``out`` names it, no hash) is
            # recomputed, not returned as this run
            want = json.loads(json.dumps(key))
            if all(found.params.get(k) == v for k, v in want.items()):
                return found
        except (OSError, ValueError, KeyError):
            pass
    start = time.perf_counter()
    d = float(chain.diameter[0])
    med = _medium(chain, scenario)
    ends = "free" if model == "kdv" else _ends(scenario, init)
    params = {**key, "ends": ends, "label": label}
    summary: dict[str, Any] = {"model": model, "ends": ends}
    if log:
        log(f"continuum: {label}, {chain.n} grains, to t = {t_final:.4g} s")
    try:
        with np.errstate(over="raise", invalid="raise", divide="ignore"):
            if model == "kdv":
                ts, vs, ss, own, info = _kdv_run(med, models, init, chain, times, t_final, d)
            else:
                pde = _pde(model, med, models, ends, incident, d)
                # a state that jumps (an impact's one struck grain): per grain, so the
                # continuum starts with the grains' momentum and energy (the kind says)
                state = continuum.from_grains(
                    pde, init.u, init.v,
                    interpolation=scenario.initial.initial_kind.interpolation)
                iface = interfaces(chain)

                def sample(s):
                    g = continuum.sample_grains(pde, s)
                    return g.v, g.strain, _own_energy(pde, s, g, iface[0] if iface else None)

                ts, (vs, ss, own), info = _stepped(pde, state, times, t_final, sample,
                                                   _dt_max(pde, state, strain_ref,
                                                           key["dt_safety"]),
                                                   method=key["integrator"])
        if not (np.all(np.isfinite(vs)) and np.all(np.isfinite(ss))):
            raise FloatingPointError("the continuum solution is not finite (unstable)")
        completed, stopped = True, "t_end"
        summary.update(dt=info["dt"], steps=info["steps"], energy_drift=info["energy_drift"])
    except (FloatingPointError, ValueError, ArithmeticError,
            continuum.InstabilityError) as exc:
        ts, vs, own = np.zeros(0), np.zeros((0, chain.n)), None
        ss = np.zeros((0, chain.n + 1))
        completed, stopped = False, f"error: {type(exc).__name__}: {exc}"
        summary.update(error=stopped)
    summary["wall_time"] = time.perf_counter() - start
    run_ = ModelRun("continuum", label, ts, vs, ss, float(t_final), completed=completed,
                    stopped_by=stopped, summary=summary, params=params, path=path,
                    own_energy=own)
    if path is not None and completed:
        _write_continuum(path, run_, scenario)
    return run_


# -- the run ----------------------------------------------------------------------------
@dataclass
class Run:
    """What :func:`run` returns: every model of a scenario, from one initial grain state.

    Attributes
    ----------
    scenario : Scenario
    chain : discrete.Chain
        The built chain (with a striker grain, if any).
    initial : discrete.Initial
        The shared initial grain state.
    interfaces : list of int
        First grain of every section after the first (:func:`hertzchain.measure.interfaces`).
    incident : IncidentWave
    discrete, continuum : ModelRun or None
    theory : TheoryModel or None
    simulation : discrete.Simulation or None
        The finished discrete simulation (record, final state).
    estimates : TheoryModel
        The theory's numbers even if ``[models] theory`` is off (arrival times, speeds:
        used to place samples and to tell incident from reflected waves).
    skipped : dict
        The models left off because they do not apply to this chain: {model: reason}
        (:meth:`hertzchain.scenario.Scenario.skipped_models`).
    """

    scenario: Scenario
    chain: discrete.Chain
    initial: Any
    interfaces: list[int]
    incident: IncidentWave
    discrete: ModelRun | None = None
    continuum: ModelRun | None = None
    theory: TheoryModel | None = None
    simulation: discrete.Simulation | None = None
    wall_time: float = 0.0
    estimates: TheoryModel | None = None
    skipped: dict[str, str] = field(default_factory=dict)

    @property
    def interface(self) -> int | None:
        """The first interface (grain index), or None."""
        return self.interfaces[0] if self.interfaces else None

    @property
    def models(self) -> list[ModelRun]:
        """The sampled models (discrete, continuum) that ran."""
        return [m for m in (self.discrete, self.continuum) if m is not None]

    @property
    def completed(self) -> bool:
        """Every model reached what was asked."""
        return all(m.completed for m in self.models)

    def _repr_html_(self) -> str:
        """Jupyter display (:func:`hertzchain.compare_output.run_html`)."""
        from .compare_output import run_html

        return run_html(self)

    def summary(self) -> dict[str, Any]:
        """Flat, JSON-able numbers: the discrete runner's summary, then per-model keys."""
        out: dict[str, Any] = {}
        if self.discrete is not None:
            out.update(self.discrete.summary)
            out.setdefault("completed", self.discrete.completed)
            out.setdefault("stopped_by", self.discrete.stopped_by)
        out["models"] = ",".join(self.scenario.models.names)
        for name, why in self.skipped.items():
            out[f"{name}_skipped"] = why
        # the incident wave's peak dynamic strain ξ_m/d, measured on its state
        # (hertzchain.measure.incident_strain; NaN, with the note, where it was not) and,
        # under precompression, ξ_m/δ0 (the amplitude axis of the model-validity map;
        # inf in the sonic vacuum)
        d0 = float(self.scenario.chain.delta0_over_d)
        strain = float(self.incident.peak_strain) if self.incident is not None else math.nan
        out["incident_strain"] = strain
        if not math.isfinite(strain):
            out["incident_strain_note"] = out.get("incident_strain_note") or (
                "no discrete run measured the impact's incident wave")
        out["incident_strain_over_delta0"] = strain / d0 if d0 > 0 else math.inf
        if self.continuum is not None:
            c = self.continuum
            out["continuum_model"] = c.summary.get("model", "")
            out["continuum_completed"] = c.completed
            out["continuum_stopped_by"] = c.stopped_by
            out["continuum_energy_drift"] = float(c.summary.get("energy_drift", math.nan))
            out["continuum_wall_time"] = float(c.summary.get("wall_time", math.nan))
        if self.theory is not None and self.theory.interface_theory:
            th = self.theory
            out["theory_gamma_c0"] = th.gamma_c0
            out["theory_gamma_rg"] = th.gamma_rg
            for k, v in th.ratios.items():
                out[f"theory_{k}"] = v
            out["theory_speed_tr"] = th.speed_tr
            out["theory_speed_re"] = th.speed_re
            out["theory_region"] = th.classes()["region"]
        if self.theory is not None:
            strong = self.theory.strong
            if strong is not None:
                out["theory_strong_theory"] = strong.theory
                out["theory_strong_regime"] = strong.regime
            if self.theory.chain_theory is not None:
                out["theory_chain"] = self.theory.chain_theory.label
        out["wall_time_all"] = self.wall_time
        return out


def run(scenario: Scenario, *, cache: str | Path | None = None, stem: str | None = None,
        out: str | Path | None = None, force: bool = False,
        checkpoint_interval: float | None = None, resume: bool = True,
        progress: bool = False, threads: int | None = None, check: bool = True,
        log=None, wave_cache: str | Path | None = None, samples: bool | None = None,
        save_discrete: bool = True, compare: bool = False) -> Run:
    """Run every model of ``scenario`` from one initial grain state (module docstring).

    Parameters
    ----------
    scenario : Scenario
        A validated scenario (its ``[models]`` table says which models run).
    cache : path, optional
        Directory of cached results (reused when complete; ``force`` recomputes).
    stem : str, optional
        File-name stem in ``cache`` (default: the scenario's name or ``"run"``).
    out : path, optional
        Write the discrete run to this HDF5 file (always run, resuming from its
        checkpoint); overrides ``cache`` for the discrete run.
    force : bool
        Recompute even if a cached file exists (and discard its checkpoint).
    checkpoint_interval : float, optional
        Wall time between checkpoints of the discrete run, s (written beside its file;
        without one the run is still integrated in segments, so that SIGINT/SIGTERM stop
        it cleanly with :class:`hertzchain.checkpoint.Interrupted`); None: one
        uninterrupted ``Simulation.run`` call.
    resume : bool
        Resume the discrete run from its checkpoint.
    progress : bool
        Progress bars.
    threads : int, optional
        Kernel threads of the discrete solver.
    check : bool
        Validate the scenario against the built chain (False only to provoke failures).
    log : callable, optional
        One-line messages.
    wave_cache : path, optional
        Cache of settled waves (``cut_wave``); default: ``cache`` if given.
    samples : bool, optional
        Sample the discrete run at the common times (:func:`sample_grid`); default: only
        if a continuum runs (otherwise the discrete run is the plain scenario's, with
        the initial and final states as its samples).
    save_discrete : bool
        Write the discrete run to its file in ``cache`` (or ``out``).  False: the file
        names only the run's checkpoint; a finished file already there is still reused,
        otherwise the discrete :class:`ModelRun` has no ``path`` and the caller keeps
        what it needs of :attr:`Run.simulation`.
    compare : bool
        Resolve the ``[models]`` not given as ``hertzchain compare`` does (the
        continuum on where it applies) rather than as ``run`` does
        (:meth:`hertzchain.scenario.Scenario.with_default_models`).

    Returns
    -------
    Run

    Raises
    ------
    ScenarioError
        The scenario cannot work with the built chain (names the key).
    discrete.InstabilityError, hertzchain.checkpoint.Interrupted,
    hertzchain.checkpoint.CheckpointError
        From the discrete run (:func:`hertzchain.runner.run_simulation`).
    """
    t0 = time.perf_counter()
    skipped = scenario.skipped_models(compare=compare)
    scenario = scenario.with_default_models(compare=compare)
    stem = stem or scenario.name or "run"
    cache = None if cache is None else Path(cache)
    wave_cache = wave_cache if wave_cache is not None else cache
    check_size(scenario)  # before anything is allocated ([chain.sections] n named)
    try:
        chain = build_chain(scenario.chain)
    except ValueError as exc:
        raise ScenarioError(f"[chain] non-physical chain: {exc}") from None
    init = build_initial_checked(scenario, chain, cache_dir=wave_cache)
    chain = init.chain
    ifaces = interfaces(chain)
    left = _left(chain, ifaces)
    # an impact's wave forms on the way: estimated here (only the sample spacing
    # depends on it), measured on the discrete run below
    incident = incident_wave(chain, init, scenario.initial.kind, left,
                             *build_law(scenario.chain))
    tm = _theory(chain, init, incident, ifaces, left, scenario)
    models = scenario.models
    sampled = bool(models.continuum) if samples is None else samples
    times = sample_grid(scenario, tm, chain)[0] if sampled or not models.discrete \
        else np.zeros(0)
    result = Run(scenario, chain, init, ifaces, tm.incident, skipped=skipped)
    d_run = None
    if models.discrete:
        d_run, sim = _run_discrete(
            scenario, times, cache=cache, stem=stem, out=out, force=force,
            checkpoint_interval=checkpoint_interval, resume=resume, progress=progress,
            threads=threads, log=log, check=check, wave_cache=wave_cache, init=init,
            save=save_discrete)
        result.discrete, result.simulation = d_run, sim
        t_final = float(d_run.times[-1])  # the last sample (t_end, or the stop event)
        if not scenario.initial.initial_kind.placed:  # formed on the way: measured
            measured = incident_from_run(sim, left, float(d_run.summary.get(
                "incident_strain", math.nan)))
            if measured is not None:
                tm.incident = measured
                result.incident = measured
    else:  # no discrete run to detect until_front_at: the theory's estimate of it
        t_final = math.inf if scenario.run.t_end is None else scenario.run.t_end
        if scenario.run.until_front_at is not None:
            t_final = min(t_final, estimate_arrival(tm, chain, scenario.run.until_front_at))
        if not math.isfinite(t_final):
            t_final = float(times[-1])
    result.estimates = tm
    if models.theory:
        result.theory = tm
    if models.continuum:
        key = _effective(scenario, times).discrete_dict()
        c_out = None if out is None else Path(out).with_suffix(".continuum.h5")
        expected = [result.incident.strain, tm.strain_tr, abs(tm.strain_re),
                    strain_from_velocity(left, float(np.max(np.abs(init.v))))]
        strain_ref = 1.5 * max(x for x in expected if math.isfinite(x)) * left["d"]
        c_run = _run_continuum(scenario, chain, init, result.incident, times, t_final,
                               cache=cache, stem=stem, out=c_out, force=force,
                               discrete_key=key, progress=progress, log=log,
                               strain_ref=strain_ref)
        if d_run is not None and c_run.completed:
            c_run.valid_until = M.valid_until(
                chain, d_run.times, d_run.v, d_run.strain, c_run.params.get("ends", "free"),
                (scenario.chain.left_wall, scenario.chain.right_wall))
        result.continuum = c_run
    result.wall_time = time.perf_counter() - t0
    return result
