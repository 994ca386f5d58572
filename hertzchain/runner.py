"""Run one :class:`~hertzchain.scenario.Scenario` with the discrete solver and summarise it.

:func:`run_scenario` builds the chain (:func:`build_chain`), the initial state
(:func:`build_initial`) and the recording, integrates, and returns a flat JSON-able
summary: the Table 2 energy ratios (transmitted/reflected over incident, docs/physics.md §6),
front speeds of the transmitted and reflected waves (Fig. 6), the classification of
Fig. 7, the energy drift and the cost.  The same summary is a row of a sweep.

Reliability: :func:`build_simulation` validates what needs the built chain
(dt against the stability bound, the wave fits the chain and the Hertz range, the stop
event can happen) and names the scenario key in a :class:`ScenarioError`;
:func:`run_scenario` can integrate in checkpointed segments with a bit-for-bit identical
result (:mod:`hertzchain.checkpoint`), and on an instability writes the partial results
beside the output before re-raising.

Every measured quantity of the summary and its window is :mod:`hertzchain.measure`'s
(:func:`hertzchain.measure.summarise`): the energy ratios after separation (with the
dissipated energy ``Ed`` and ``ratios_normalised_to``), the front speeds on the rows
before a wave reached a chain end, the labels on the final state only if the waves
separated and no wave reached a chain end, the incident strain measured on the
incident wave, the solitary waves of the final state (the train: their amplitudes,
speeds and energies, :func:`hertzchain.measure.wave_train`); a quantity outside its
window is NaN (a label None, the train's lists empty) and its ``*_note`` says why.

Summary invariants (``tests/test_reliability_property.py``): ``steps``, ``t``, ``dt``,
``energy_drift``, ``n_grains`` and ``wall_time`` are always finite; ``integrator``,
``dt_source`` (``"default"``, ``"explicit"`` or ``"rtol"``), ``rtol`` (None unless
given) and ``rtol_estimate`` (the estimated relative error of an rtol run, NaN
otherwise; :mod:`discrete.timestep`; for the total-energy ratios ``Et_*`` of a chain
with an interface an absolute error in units of the incident energy) say how the step
was chosen, and ``rtol_maxima`` which running maxima the estimate is about
(``"refined"``: between the steps, ``"sampled"``: at the step ends, a dissipative run;
None without rtol: :attr:`discrete.TimeStep.maxima`); ``split_estimate`` is the
estimated error of the phase-averaged kinetic/potential split ``Ek_*``, ``Ep_*`` (NaN
unless they are measured; :func:`discrete.diagnostics.phase_averaged_ratios`,
docs/physics.md §6) and
``split_meets_rtol`` whether it is within ``rtol``, ``front_speed_meets_rtol`` whether
the front speeds are converged to it in the grid's rows (None without rtol or unless
measured; False: not verified — ``hertzchain run`` then exits 4, docs/guide/exit_status.md).

How the run ended: ``stopped_by`` names what ended it (``t_end``,
``until_front_at`` or ``max_steps``) and ``completed`` says whether that is what the
scenario asked for (:func:`run_outcome`; ``incomplete_reason`` says why not).  A
``t_end`` or snapshot time that ``max_steps`` cannot reach, and a ``t_end`` shorter than
one step, are refused before the run (:func:`check_stop`).
"""

from __future__ import annotations

import json
import math
import os
import time
from pathlib import Path

import numpy as np

import discrete
import theory
from discrete import diagnostics as D

from . import measure as M
from .cache import canonical_json
from .measure import interfaces
from .scenario import ChainSpec, Scenario, ScenarioError, SectionSpec, schema_key

__all__ = ["build_chain", "chain_inputs", "choose_time_step", "build_law", "build_section",
           "build_initial", "build_initial_checked",
           "build_simulation", "check_run", "check_stop", "run_outcome", "run_scenario",
           "run_simulation", "summarise", "partial_path", "STOPPED_BY",
           "GRID_ROWS_PER_GRAIN", "GRID_ROWS_PER_GRAIN_RTOL", "GRID_ROWS_DISSIPATIVE",
           "split_row_spacing", "MAX_OVERLAP_OVER_D"]

GRID_ROWS_PER_GRAIN = 0.5
"""Energy space-time grid: one row per this many grain transits of the incident wave."""

GRID_ROWS_PER_GRAIN_RTOL = 1.0
"""The same in a run whose step is chosen for ``rtol`` on a chain of one section
without running maxima (with them, such a run records no grid: its front speed comes
from the refined peak times, :func:`hertzchain.measure.front_speed_from_maxima`).

There the summary reads only the transmitted front speed from the grid (arrival times
refined by a parabola through three rows, a straight-line fit over the grains), and
the rows, whose count does not shrink with the step, were most of the cost that did
not (about 40 % of a small run).  On impacts
(δ0 = 0, front to 0.75 N) the front speed's difference from a grid of 0.25 transits a
row stays below 6e-6 at one transit (2,000 and 600 grains, default and rtol = 1e-4
steps) and reaches 3e-5 at two on 600 grains: one transit keeps it ~20 times inside
rtol = 1e-4 and halves the rows, which then also need less coarsening (coarsening by 8
moved it 1.3e-4).  Chains with an
interface keep :data:`GRID_ROWS_PER_GRAIN` or finer (:func:`split_row_spacing`, for the
phase-averaged energy split): their reflected front speed is not
converged in the row spacing (266, 294 and 279 m/s at 0.25, 0.5 and 2 transits a row
behind a precompressed interface, δ0/d = 1e-3), so a coarser grid would change a
reported number by more than rtol (``tests/hertzchain/test_runner.py``); such a speed
is now NaN (:data:`hertzchain.measure.FRONT_ROWS_RTOL`), and finer rows let more of
them converge."""

GRID_ROWS_DISSIPATIVE = 0.125
"""Row spacing, in incident transits, of a run with a dissipative law or drag.

A decaying wave slows down along the chain (V ∝ ξ^{1/4}, Eq. 8), and the parabola
through three rows that refines each grain's arrival time is biased by the pulse's
changing shape; the bias no longer averages out over the grains as for a steady wave.
Measured (viscoelastic Hertz, damping time 2e-7 s, 150 grains, impact, dt 2e-9 s,
transit ~8 µs): the front speed 609.4847, 609.4845, 609.4735, 610.77 and 598.7 m/s
at rows every 125, 250, 500, 1,000 and 2,000 steps (1/64 … 1/4 transit; the grains
fitted fixed by the refined peaks, :func:`hertzchain.measure.front_speed`); the
lossless chain 657.1277 m/s to 2e-7 at all of them.  An eighth of a transit keeps it
~2e-5 off (inside :data:`hertzchain.measure.FRONT_ROWS_RTOL` and rtol = 1e-4; the
every-other-row check then passes)."""

def split_row_spacing(chain: discrete.Chain) -> float:
    """Grid row spacing, in incident transits d/V, that lets the split be phase-averaged.

    The kinetic/potential split of each wave oscillates at its lattice frequency
    f = V_s/d (docs/physics.md §6); :func:`discrete.diagnostics.phase_averaged_ratios`
    averages it away over a window of W = 16 incident transits only if the rows do not
    alias f to within 4/W = 0.25/T_in of zero (T_in = d/V_in).  Rows R per incident
    transit alias f·T_in = r to |r - mR|, so R ≥ r_max + 1 keeps every wave with
    r ≤ r_max at least 1/T_in away (four times the window's main lobe, so a 30 %
    error in r_max is still safe).  r_max over the sections s, relative to the first:
    a solitary wave's speed V ∝ d (k/m)^{1/2} ξ^{1/4} (Eq. 8) with the strain of a
    force-continuous transmitted wave ξ ∝ (F/k)^{2/3}/d, so V_s/V_0 ≈
    (k_s/k_0)^{1/3} (m_0/m_s)^{1/2} at δ0 = 0, and c0 ∝ (k_s^{2/3}/m_s)^{1/2} with
    precompression (δ0 ∝ k^{-2/3}); both are bounded by the larger of
    (k_s/k_0)^{1/2} and (k_s/k_0)^{1/3} times (m_0/m_s)^{1/2}, which is used.  Points a
    and d (α = 0.2, 5): r_max = 2.24, rows every 0.25 transit; at 0.5 transit the
    transmitted wave's oscillation (r = 2.1 at a) aliased to a slow 7e-3 swing of the
    windowed Ek_tr.  Returns at most :data:`GRID_ROWS_PER_GRAIN`.
    """
    kk = np.asarray(chain.k, dtype=float)
    mm = np.asarray(chain.mass, dtype=float)
    s0 = M.first_grain(chain)  # (a striker belongs to no section)
    k0, m0 = kk[min(s0 + 1, kk.size - 1)], mm[s0]
    r_max = 1.0
    for i in interfaces(chain):
        j = min(i + 1, kk.size - 1)  # a contact inside the section, not the interface's
        q = kk[j] / k0
        r_max = max(r_max, max(q ** 0.5, q ** (1 / 3)) * (m0 / mm[i]) ** 0.5)
    return min(GRID_ROWS_PER_GRAIN, 1.0 / (r_max + 1.0))


_MAX_GRID = 2e7  # entries of the (rows, columns) energy grid before coarsening


def _material(spec) -> theory.Material:
    if spec == "paper":
        return theory.PAPER_MATERIAL
    if spec == "table1":
        return theory.STEEL_TABLE1
    return theory.Material(**spec)


def build_section(spec: SectionSpec, base: theory.Material, diameter: float
                  ) -> discrete.Section:
    """The :class:`discrete.Section` of one ``[[chain.sections]]`` table.

    ``base`` is the first section's material, ``diameter`` the chain's (m).  The profile
    keys map to :class:`discrete.Tapered` (``mass_ratio``), :class:`discrete.Periodic`
    (``cell_*``: each cell grain's material is the section's scaled by its
    ``cell_alpha_rho``/``cell_alpha_kn``) and the disorder keys to
    :class:`discrete.Disorder`.
    """
    mat = _material(spec.material) if spec.material is not None \
        else base.scaled(spec.alpha_rho, spec.alpha_kn)
    profile = None
    if spec.profile == "tapered":
        profile = discrete.Tapered(spec.mass_ratio)
    elif spec.profile == "periodic":
        m = len(spec.cell_diameters)
        rho = spec.cell_alpha_rho or (1.0,) * m
        kn = spec.cell_alpha_kn or (1.0,) * m
        profile = discrete.Periodic(tuple(
            (f, None if (a, b) == (1.0, 1.0) else mat.scaled(a, b))
            for f, a, b in zip(spec.cell_diameters, rho, kn, strict=True)))
    disorder = None
    if spec.disorder_mass or spec.disorder_stiffness or spec.disorder_diameter:
        disorder = discrete.Disorder(mass=spec.disorder_mass,
                                     stiffness=spec.disorder_stiffness,
                                     diameter=spec.disorder_diameter, seed=spec.seed)
    d = diameter if spec.diameter is None else spec.diameter
    return discrete.Section(spec.n, d, mat, profile=profile, disorder=disorder)


def build_law(spec: ChainSpec) -> tuple[discrete.ContactLaw, float]:
    """The contact law (:mod:`theory.laws`) and on-site drag rate (1/s) of a chain spec.

    The law is the registered class of ``[chain] law`` built from its parameters
    (:meth:`hertzchain.scenario.ChainSpec.contact_law`).
    """
    return spec.contact_law(), spec.drag


def _wall(kind: str):
    """A scenario wall as a :data:`discrete.chain.WallKind`: a keyword, or a named material.

    ``"free"`` is None (no contact); ``"paper"``, ``"hertz"``, ``"flat"`` pass through; any
    other value is a material name (validated by the scenario): a flat wall of it.
    """
    if kind == "free":
        return None
    if kind in ("paper", "hertz", "flat"):
        return kind
    return theory.get_material(kind)


def chain_inputs(spec: ChainSpec) -> tuple[list[discrete.Section], dict]:
    """The sections and keywords of :meth:`discrete.Chain.from_sections` for a chain spec.

    Sections (:func:`build_section`: profiles, disorder, own diameters), walls, the
    exponent n of the law's static forces (:func:`build_law`) and the static overlaps:
    δ0 of section 0 (``delta0_over_d`` × its diameter) or, with ``gravity``, the weight
    of the grains above each contact plus ``top_force``.  :func:`build_chain` builds
    one chain from them; an ensemble many seeds at once
    (:meth:`discrete.Chain.from_sections_seeds`, bit for bit the same chains).
    """
    base = _material(spec.material)
    sections = [build_section(s, base, spec.diameter) for s in spec.sections]
    law, _ = build_law(spec)
    kwargs = ({"gravity": spec.gravity, "wall_force": spec.top_force} if spec.gravity > 0
              else {"delta0": spec.delta0_over_d * float(sections[0].diameter)})
    kwargs.update(left_wall=_wall(spec.left_wall), right_wall=_wall(spec.right_wall),
                  exponent=law.exponent)
    return sections, kwargs


def build_chain(spec: ChainSpec) -> discrete.Chain:
    """The :class:`discrete.Chain` of a chain spec: the one mapping of ``[chain]``.

    :meth:`discrete.Chain.from_sections` of :func:`chain_inputs` (sections, walls,
    static overlaps from force equilibrium for the law's exponent n).  The law and drag
    are :func:`build_law`'s; :func:`build_simulation` uses both.
    """
    sections, kwargs = chain_inputs(spec)
    chain = discrete.Chain.from_sections(sections, **kwargs)
    return chain.with_params(scenario_chain=json.loads(canonical_json(
        {"sections": [vars(s) for s in spec.sections], "diameter": spec.diameter,
         "delta0_over_d": spec.delta0_over_d, "material": spec.material}, )))


def build_initial(scenario: Scenario, chain: discrete.Chain, *, cache_dir=None):
    """The initial state (:class:`discrete.initial.Initial`) of a scenario.

    Built by its kind (:meth:`hertzchain.initial_kinds.InitialKind.build`).
    ``cache_dir``: where a costly state is cached (a ``cut_wave``'s settled wave, an
    ``.npz`` file, :func:`discrete.settled_wave`); None: in memory only.
    """
    ini = scenario.initial
    return ini.initial_kind.build(ini, scenario.chain, chain, cache_dir=cache_dir)


def _wave_speed_estimate(chain: discrete.Chain, v: np.ndarray) -> float:
    """A rough speed of the incident wave, m/s (Eq. 5/8 via Nesterenko's relation)."""
    j = int(np.argmax(np.abs(v)))
    jc = min(max(j, 1), chain.n - 1)
    d = float(chain.diameter[j])
    cm = float(theory.c_mat(chain.k[jc], chain.mass[j], d))
    vm = max(float(np.max(np.abs(v))), 1e-12)
    xi = (vm / cm) ** 0.8  # v ≈ V ξ and V ≈ c_mat ξ^{1/4} (Eq. 8)
    return float(theory.nesterenko_speed(cm, chain.delta0[jc] / d, xi))


RUN_LENGTH_MARGIN = 1.5
"""Safety factor on the time an ``until_front_at`` run is estimated to take.

The estimate is the distance from the initial velocity peak to the target grain over
:func:`_wave_speed_estimate`, which takes the initial peak velocity as the wave's: an
impact's solitary wave carries ~0.68 v0 (Eq. 8: speed ∝ v^{1/5}, 8 % slower than
estimated) and needs a few tens of grains to form.  Measured (benchmarks/rtol.py,
impact, until 0.75 N): the run lasts 1.07-1.10 times the bare estimate at 2,000 and
5,000 grains, so 1.5 over-estimates it, the safe side for both uses (grid
coarsening, the rtol probe's drift scaled to the run's length)."""


def _run_length_estimate(scenario: Scenario, chain: discrete.Chain, v: np.ndarray,
                         speed: float) -> float:
    """The run's expected length, s: ``t_end``, or the time to ``until_front_at``.

    ``until_front_at`` on a chain of one section: :data:`RUN_LENGTH_MARGIN` × (distance
    from the initial velocity peak to the target grain, m) / ``speed`` (m/s, the
    incident wave's, :func:`_wave_speed_estimate`), at most ``t_end``.  A chain with an
    interface keeps the bound 3 N d / speed (the wave's speed changes at the interface
    by a factor the estimate does not know); so does a run with neither.
    """
    run = scenario.run
    if run.until_front_at is None and run.t_end is not None:
        return run.t_end  # the run stops there, not earlier
    d = float(np.mean(chain.diameter))
    t = 3.0 * chain.n * d / speed
    if run.until_front_at is not None and not interfaces(chain):
        j = int(np.argmax(np.abs(v)))
        t = RUN_LENGTH_MARGIN * (abs(run.until_front_at - j) + 1) * d / speed
    return min(t, run.t_end) if run.t_end is not None else t


MAX_OVERLAP_OVER_D = 0.1
"""Largest expected contact overlap / d an initial state may reach (Hertz small strain;
the same bound as ``[chain] delta0_over_d``)."""


def _stable_and_auto_dt(init, spec: ChainSpec) -> tuple[float, float]:
    """(largest linearly stable dt, default dt) of an initial state, s (discrete.TimeStep)."""
    law, drag = build_law(spec)
    step = discrete.TimeStep.choose(init.chain, init.u, init.v, init.wall_left,
                                    init.wall_right, law=law, drag=drag, check=False)
    return step.stable, step.default


def _check_amplitude(chain: discrete.Chain, init, key: str, value: float,
                     law: discrete.ContactLaw | None = None) -> None:
    """ScenarioError if the initial state's largest expected overlap exceeds the Hertz range."""
    delta = discrete.expected_overlaps(chain, init.u, init.v, init.wall_left, init.wall_right,
                                       law=law)
    d = np.r_[chain.diameter[0], chain.diameter]  # contact j: grain j-1's diameter (wall: 0)
    worst = float(np.max(delta / d))
    if not worst < MAX_OVERLAP_OVER_D:
        unit = schema_key("initial", key).unit
        raise ScenarioError(
            f"[initial] {key} = {value!r}{' ' + unit if unit else ''} is "
            f"non-physical: the contacts would overlap by "
            f"{worst:.3g} grain diameters (allowed < {MAX_OVERLAP_OVER_D:g}, the Hertz "
            f"small-strain range); lower {key} (or stiffen the contacts: alpha_kn, "
            "material)")


def build_initial_checked(scenario: Scenario, chain: discrete.Chain, *, cache_dir=None):
    """:func:`build_initial` with every failure named by its scenario key (ScenarioError).

    Also rejects a non-physical amplitude (:data:`MAX_OVERLAP_OVER_D`), checked on the
    cheap impact state before a cut wave is settled.
    """
    ini = scenario.initial
    kind = ini.initial_kind
    law = build_law(scenario.chain)[0]
    key = kind.amplitude_key(ini)
    early = kind.amplitude_state(ini, chain)
    if early is not None:  # before a costly state (a cut wave's settling) is built
        _check_amplitude(chain, early, key, getattr(ini, key), law)
    overflow = (f"[initial] kind = {ini.kind!r}: the initial state's scales leave double "
                "precision for this chain (grain masses "
                f"{chain.mass.min():.3g}-{chain.mass.max():.3g} kg, contact constants up to "
                f"{chain.k.max():.3g} N/m^n): check [chain.sections] alpha_rho and alpha_kn")
    try:
        init = build_initial(scenario, chain, cache_dir=cache_dir)
    except ArithmeticError as exc:  # FloatingPointError (numpy set to raise), OverflowError
        raise ScenarioError(f"{overflow} ({exc})") from None
    except ValueError as exc:
        raise ScenarioError(kind.build_error(ini, exc)) from None
    if not (np.all(np.isfinite(init.u)) and np.all(np.isfinite(init.v))):
        raise ScenarioError(overflow)
    late = kind.amplitude_state(ini, init.chain, init)
    if late is not None:
        _check_amplitude(init.chain, late, key, getattr(ini, key), law)
    return init


BYTES_PER_GRAIN = 16 * 8
"""A lower bound of the memory a run needs per grain, bytes: 16 float64 arrays (the
chain's mass, k, δ0, diameter, section; the state u, v, a; the kernel's scratch and
running maxima), not counting the recording."""


def _memory_bytes() -> int | None:
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, OSError, ValueError):  # pragma: no cover - not POSIX
        return None


def _too_large(scenario: Scenario, what: str) -> ScenarioError:
    n = scenario.chain.n
    mem = _memory_bytes()
    limit = (f"; allowed total n <= {mem // BYTES_PER_GRAIN:,} on this machine "
             f"({mem / 1e9:.3g} GB of memory)" if mem else "")
    return ScenarioError(
        f"[chain.sections] n: the chain of {n:,} grains does not fit in memory ({what}; "
        f"at least {n * BYTES_PER_GRAIN / 1e9:.3g} GB, {BYTES_PER_GRAIN} bytes a "
        f"grain){limit}")


def check_size(scenario: Scenario) -> None:
    """ScenarioError naming ``[chain.sections] n`` if the chain cannot fit in memory.

    Checked before anything is allocated (``n = 1e12`` was a MemoryError traceback;
    a size just above the memory would have been killed by the OS instead): the
    lower bound :data:`BYTES_PER_GRAIN` per grain must fit in the physical memory.
    """
    mem = _memory_bytes()
    if mem and scenario.chain.n * BYTES_PER_GRAIN > mem:
        raise _too_large(scenario, "checked before allocating")


def check_run(scenario: Scenario, init) -> None:
    """ScenarioError for a ``[run]`` table that cannot work with this initial state.

    * ``dt`` above the largest linearly stable step (:func:`discrete.stable_dt` at the
      largest expected overlaps: the Gershgorin bound 2/ω_lat, exact for a uniform
      chain) — the run would blow up within a few steps;
    * ``until_front_at`` behind or at the start of a right-going cut or exact wave —
      the event could never happen and the run would go on to ``max_steps``.
    """
    run, ini = scenario.run, scenario.initial
    if run.dt_fraction is not None:  # its stability limit depends on the chain
        law, drag = build_law(scenario.chain)
        step = discrete.TimeStep.choose(init.chain, init.u, init.v, init.wall_left,
                                        init.wall_right, law=law, drag=drag, check=False,
                                        fraction=run.dt_fraction)
        stable, auto = step.stable, step.default
        limit = run.dt_fraction * stable / auto
        if auto > stable:
            raise ScenarioError(
                f"[run] dt_fraction = {run.dt_fraction!r} gives dt = {auto:.4g} s, above the "
                f"largest linearly stable time step {stable:.4g} s of this chain (Gershgorin "
                f"bound 2/ω_lat at the largest expected overlaps); allowed range (0, "
                f"{limit:.4g}] for this chain")
    if run.dt is not None:
        stable, auto = _stable_and_auto_dt(init, scenario.chain)
        if run.dt > stable:
            raise ScenarioError(
                f"[run] dt = {run.dt!r} s is above the largest linearly stable time step "
                f"{stable:.4g} s of this chain and initial state (Gershgorin bound 2/ω_lat "
                f"at the largest expected overlaps); allowed range (0, {stable:.4g}] s. "
                f"dt = 'auto' gives {auto:.4g} s")
        law, drag = build_law(scenario.chain)
        try:  # the damping bound of a dissipative law or drag (discrete.TimeStep.check)
            discrete.TimeStep.choose(init.chain, init.u, init.v, init.wall_left,
                                     init.wall_right, dt=run.dt, law=law, drag=drag)
        except ValueError as exc:
            raise ScenarioError(f"[run] {exc}") from None
    if run.until_front_at is not None and ini.initial_kind.placed \
            and run.until_front_at <= ini.center:
        raise ScenarioError(
            f"[run] until_front_at = {run.until_front_at} can never be reached: the "
            f"{ini.kind} starts with its peak at grain {ini.center} and travels to the "
            f"right; allowed range [{ini.center + 1}, {init.chain.n - 1}]")


def build_simulation(scenario: Scenario, *, energy_grid: bool = True,
                     threads: int | None = None, check: bool = True, cache_dir=None,
                     init=None):
    """Chain, initial state and a ready :class:`discrete.Simulation` for ``scenario``.

    The energy space-time grid (needed for the energy ratios and front speeds) gets a
    row every :data:`GRID_ROWS_PER_GRAIN` transit times of the incident wave
    (:data:`GRID_ROWS_PER_GRAIN_RTOL` in an rtol run of a one-section chain,
    :func:`split_row_spacing` on a chain with an interface) unless the
    scenario sets ``record.energy_every``; long chains are coarsened so that the grid
    stays below ~2e7 entries.

    Parameters
    ----------
    scenario : Scenario
        A validated scenario.
    energy_grid : bool
        Record the energy grid (automatic row interval) if the scenario does not set one.
    threads : int, optional
        Kernel threads (``Simulation(threads=...)``; results are bitwise identical for
        every value).  None: the Simulation's default.
    check : bool
        Run the checks that need the built chain (:func:`build_initial_checked`,
        :func:`check_run`): False only to provoke an instability on purpose.
    cache_dir : path, optional
        Cache of settled waves (:func:`build_initial`).
    init : discrete.initial.Initial, optional
        The initial state already built for this scenario's ``[chain]`` and ``[initial]``
        (:func:`build_initial_checked`, e.g. by :func:`hertzchain.models.run`), used
        instead of building it again (an exact solitary wave is a Petviashvili solve,
        ~0.1-0.3 s).  Its chain must be this scenario's (checked: grain count and
        masses); the Simulation copies its state.

    Raises
    ------
    ScenarioError
        If the chain, the initial wave or the time step cannot work (names the key).
    ValueError
        ``init`` is not a state of this scenario's chain.
    """
    check_size(scenario)
    try:
        return _build_simulation(scenario, energy_grid=energy_grid, threads=threads,
                                 check=check, cache_dir=cache_dir, init=init)
    except MemoryError:
        raise _too_large(scenario, "building the chain and its recording") from None


def choose_time_step(scenario: Scenario, init, horizon: float) -> discrete.TimeStep:
    """The time step of a scenario's run from its initial state (:meth:`~discrete.TimeStep.choose`).

    ``[run]`` dt, dt_fraction, integrator and rtol; the law and drag of ``[chain]``
    (:func:`build_law`); ``horizon`` the run's expected length, s (the rtol rule's
    drift budget; ``t_end`` for a run to ``t_end``).

    Raises
    ------
    ScenarioError
        If no step can be chosen (names the key), or the step is not a positive finite
        number (a contact's k/m overflows a double).
    """
    rec, run = scenario.record, scenario.run
    law, drag = build_law(scenario.chain)
    ifaces = interfaces(init.chain)
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            # k/m may overflow (alpha_rho = 1e-300): dt = 0, refused below by name
            step = discrete.TimeStep.choose(
                init.chain, init.u, init.v, init.wall_left, init.wall_right, dt=run.dt,
                integrator=None if run.integrator == "auto" else run.integrator, law=law,
                drag=drag, fraction=run.dt_fraction, check=False, rtol=run.rtol,
                horizon=horizon, recording=discrete.Recording(
                    maxima=True, strain_maxima=rec.strain_maxima),
                energy_ratios=bool(ifaces))  # (the summary's, Table 2)
    except ValueError as exc:  # e.g. v0 = 1e-300: the expected overlaps underflow to 0
        if run.rtol is not None and run.dt is None and str(exc).startswith("rtol"):
            raise ScenarioError(f"[run] {exc}") from None  # (below the round-off floor)
        amp = scenario.initial.initial_kind.amplitude_key(scenario.initial)
        raise ScenarioError(
            f"[run] dt = {'auto' if run.dt is None else run.dt!r}: the time step cannot be "
            f"chosen for this chain and initial state ({exc}); give [run] dt (s, > 0) or "
            f"a larger [initial] {amp}") from None
    dt = step.dt
    if not (math.isfinite(dt) and dt > 0):  # k/m overflows a double: ω_max = inf
        ratios = [(s.alpha_rho, s.alpha_kn) for s in scenario.chain.sections]
        raise ScenarioError(
            f"[chain.sections] alpha_rho, alpha_kn = {ratios}: the stiffest contact's "
            f"frequency sqrt(k/m) overflows a double, so the time step is {dt!r} s; "
            "allowed: ratios (and diameter, material) for which every contact's k/m is a "
            "finite double")
    return step


def _build_simulation(scenario: Scenario, *, energy_grid: bool, threads: int | None,
                      check: bool, cache_dir, init=None):
    try:
        chain = build_chain(scenario.chain)
    except ValueError as exc:
        raise ScenarioError(
            f"[chain] non-physical chain: {exc} (each section's static overlap is "
            "delta0_over_d·d·alpha_kn^(-2/3), from force equilibrium)") from None
    if init is not None:
        _check_given_initial(chain, init)
    elif check:
        init = build_initial_checked(scenario, chain, cache_dir=cache_dir)
    else:
        init = build_initial(scenario, chain, cache_dir=cache_dir)
    if check:
        check_run(scenario, init)
    rec = scenario.record
    ifaces = interfaces(init.chain)
    law, drag = build_law(scenario.chain)
    speed = _wave_speed_estimate(init.chain, init.v)
    horizon = _run_length_estimate(scenario, init.chain, init.v, speed)
    step = choose_time_step(scenario, init, horizon)
    dt = step.dt
    d = float(np.mean(init.chain.diameter))
    every = rec.energy_every or None
    coarsen = 1
    # an rtol run of one section with running maxima keeps them refined between the steps
    # (Simulation: rtol, forces of positions only): their peak times give the front
    # speed, the one number its summary read from the grid (_front_speed_from_maxima)
    rtol_one_section = step.source == "rtol" and not ifaces
    maxima_front = (rtol_one_section and rec.running_max
                    and not (law.dissipative or drag > 0))
    if energy_grid and rec.energy_grid and every is None and not maxima_front:
        # (two sections: rows dense enough that the energy ratios' split does not alias;
        # a decaying wave: dense enough for its front speed, GRID_ROWS_DISSIPATIVE)
        per = (split_row_spacing(init.chain) if ifaces else GRID_ROWS_PER_GRAIN_RTOL
               if rtol_one_section else GRID_ROWS_PER_GRAIN)
        if law.dissipative or drag > 0:
            per = min(per, GRID_ROWS_DISSIPATIVE)
        every = max(1, int(per * d / (speed * dt)))
    if every:
        # (never beyond max_steps: t_end = 1e300 with max_steps = 10 is refused by
        # check_stop, not by a coarsening factor overflowing int64)
        t_est = min(horizon, scenario.run.max_steps * dt)
        rows = t_est / (every * dt)
        while rows * init.chain.n / coarsen > _MAX_GRID and coarsen < init.chain.n:
            coarsen *= 2
    # a wave that forms on the way (an impact's): measured (incident strain, position,
    # peak velocity) when its velocity peak passes the middle of section 0
    measuring = ([discrete.WaveAt(M.incident_grain(init.chain))]
                 if not scenario.initial.initial_kind.placed else [])
    recording = discrete.Recording(
        snapshots=[discrete.AtTime(t) for t in rec.snapshot_times]
        + [discrete.WaveAt(g) for g in rec.snapshot_grains] + measuring,
        series_grains=list(rec.time_series_grains), series_every=rec.series_every,
        maxima=rec.running_max, energy_every=every, energy_coarsen=coarsen,
        # asked for, not left to Simulation's default: the front speed depends on them
        refined_maxima=True if maxima_front else None,
        sensors=list(rec.sensors), wall_forces=rec.wall_forces,
        strain_maxima=rec.strain_maxima)
    kwargs = {} if threads is None else {"threads": threads}
    sim = init.simulation(dt=step, record=recording, check_dt=check, law=law, drag=drag,
                          **kwargs)
    return init.chain, init, sim


def _check_given_initial(chain: discrete.Chain, init) -> None:
    """ValueError unless ``init`` (a built initial state) belongs to ``chain``.

    The state's chain is ``chain``, or ``chain`` with a striker grain prepended (an
    impact's ``striker_mass``, section −1): the grain count, the grains' masses and the
    contacts' constants and static overlaps (those behind a striker: all but its own
    contact) are compared exactly (both are built from the same scenario keys).
    """
    c = init.chain
    s0 = M.first_grain(c)  # a prepended striker grain
    c0 = s0 + 1 if s0 else 0  # first contact of ``c`` that is one of ``chain``'s
    q0 = 1 if s0 else 0
    if not (c.n == chain.n + s0 and np.array_equal(c.mass[s0:], chain.mass)
            and np.array_equal(c.k[c0:], chain.k[q0:])
            and np.array_equal(c.delta0[c0:], chain.delta0[q0:])):
        raise ValueError(f"init must be the initial state of this scenario's chain "
                         f"({chain.n} grains; got a state of {c.n} grains or of other "
                         "masses, contact constants or static overlaps)")


def summarise(chain: discrete.Chain, sim: discrete.Simulation,
              incident: float | None = None, *, rtol: float | None = None) -> dict:
    """The measured quantities of a finished run: :func:`hertzchain.measure.summarise`."""
    return M.summarise(chain, sim, incident, rtol=rtol)


def _incident_strain(scenario: Scenario, sim: discrete.Simulation, strain0: float) -> dict:
    """``incident_strain`` and ``incident_strain_note`` of a finished run.

    The peak dynamic strain of the incident wave (:func:`hertzchain.measure.incident_strain`):
    of the initial state (``strain0``) for a placed wave, of the snapshot taken when an
    impact's wave passed :func:`hertzchain.measure.incident_grain`.
    """
    if scenario.initial.initial_kind.placed:
        return {"incident_strain": strain0, "incident_strain_note": ""}
    g = M.incident_grain(sim.chain)
    snap = next((s for s in sim.record.snapshots
                 if s.label == discrete.WaveAt(g).label), None)
    if snap is None:
        return {"incident_strain": math.nan, "incident_strain_note":
                f"the incident wave had not reached grain {g} (the middle of section 0, "
                "where it is measured) by the end of the run"}
    law, drag = build_law(scenario.chain)
    return {"incident_strain": M.incident_strain(sim.chain, snap.v, snap.overlaps, law, drag,
                                                 at=g),
            "incident_strain_note": ""}


def partial_path(out: str | Path) -> Path:
    """Where a failed run's partial results go: ``run.h5`` -> ``run.partial.h5``."""
    out = Path(out)
    return out.with_name(f"{out.stem}.partial{out.suffix or '.h5'}")


def _write_partial(out: Path, sim: discrete.Simulation, scenario: Scenario, error: str) -> str:
    """Save the failed run as it is (record up to the failure); a note for the message."""
    path = partial_path(out)
    try:
        with np.errstate(all="ignore"):
            discrete.save(path, sim, attrs={"scenario": canonical_json(scenario.to_dict()),
                                            "error": error, "complete": False})
    except Exception as exc:  # never hide the instability behind a failed write
        return f"; the partial results could not be written to {path}: {exc}"
    return (f"; the results up to the failure are in {path} (hertzchain info; the state is "
            "not resumable)")


def _integrate(sim, scenario: Scenario, until, ckpt, key, interval, extra, progress,
               flag: list[int]) -> str:
    """One ``Simulation.run`` call, or checkpointed segments (bit for bit the same).

    Returns what stopped the run (``RunInfo.stopped_by``: an event label, ``"t_end"``
    or ``"max_steps"``).
    """
    from . import checkpoint as C

    if interval is None:
        return sim.run(scenario.run.t_end, until=until, max_steps=scenario.run.max_steps,
                       progress=progress).stopped_by
    return C.run_segmented(sim, t_end=scenario.run.t_end, until=until,
                           step_limit=scenario.run.max_steps, checkpoint=ckpt, key=key,
                           interval=float(interval), extra=extra, progress=progress,
                           signals=flag)


def check_stop(scenario: Scenario, dt: float) -> None:
    """ScenarioError if the requested stop can never be reached with time step ``dt``.

    A run ends at ``t_end`` (the first step with t >= t_end), at ``until_front_at``, or
    after ``max_steps`` steps, whichever comes first; ``max_steps`` is a safety bound.
    Refused up front: a ``t_end`` or a snapshot time that ``max_steps`` steps of ``dt``
    cannot reach (``dt = 1e-300``), and a ``t_end`` shorter than one step (the run would
    take no step).  Whether ``until_front_at`` is reached is known only at the end
    (:func:`run_outcome`).
    """
    run = scenario.run
    if not (math.isfinite(dt) and dt > 0):
        raise ScenarioError(f"[run] dt = {dt!r} s: allowed range (0, inf)")
    if run.t_end is not None:
        need = run.t_end / dt  # steps to t_end (may overflow to inf: compare as floats)
        if need <= 1e-9:  # Simulation.run rounds ceil(t/dt - 1e-9)
            raise ScenarioError(
                f"[run] t_end = {run.t_end!r} s is shorter than one time step dt = {dt:.4g} s:"
                f" the run would take no step; allowed t_end >= dt (or a smaller dt)")
        if need > run.max_steps:
            raise ScenarioError(
                f"[run] max_steps = {run.max_steps} ends the run at t = "
                f"{run.max_steps * dt:.4g} s, before t_end = {run.t_end!r} s, which needs "
                f"{math.ceil(need - 1e-9) if math.isfinite(need) else need:.6g} steps of "
                f"dt = {dt:.4g} s; allowed max_steps >= that number (or a larger dt, a "
                "smaller t_end)")
    late = [t for t in scenario.record.snapshot_times if t / dt > run.max_steps]
    if late:
        raise ScenarioError(
            f"[record] snapshot_times = {list(scenario.record.snapshot_times)}: "
            f"{late[0]!r} s comes after max_steps = {run.max_steps} steps of dt = {dt:.4g} s "
            f"(t = {run.max_steps * dt:.4g} s) and would never be taken; allowed range "
            f"[0, {run.max_steps * dt:.4g}] s (or raise [run] max_steps)")


STOPPED_BY = ("t_end", "until_front_at", "max_steps")
"""Values of the summary's ``stopped_by``: what ended the run."""


def run_outcome(scenario: Scenario, sim: discrete.Simulation, stopped_by: str) -> dict:
    """``stopped_by``, ``completed`` and ``incomplete_reason`` ("" if completed) of a run.

    ``stopped_by`` is the scenario key that ended the run (:data:`STOPPED_BY`; the
    ``Simulation`` reports the event label ``wave_at=N`` for ``until_front_at``).  The
    run is *completed* when it stopped where the scenario asked — at ``until_front_at``
    if given, otherwise at ``t_end`` — and every requested snapshot was taken.
    """
    run = scenario.run
    key = stopped_by if stopped_by in ("t_end", "max_steps") else "until_front_at"
    wanted = "until_front_at" if run.until_front_at is not None else "t_end"
    why = []
    if key != wanted:
        goal = (f"the wave front reached grain {run.until_front_at} (until_front_at)"
                if wanted == "until_front_at" else f"t_end = {run.t_end!r} s")
        bound = (f"max_steps = {run.max_steps}" if key == "max_steps"
                 else f"t_end = {run.t_end!r} s")
        why.append(f"the run stopped at {bound} (t = {sim.t:.6g} s, step {sim.steps}) "
                   f"before {goal}")
    from collections import Counter

    # the scenario's own snapshots (not the measurement's, hertzchain.measure)
    wanted = [discrete.AtTime(t).label for t in scenario.record.snapshot_times] \
        + [discrete.WaveAt(g).label for g in scenario.record.snapshot_grains]
    missing = Counter(wanted) - Counter(s.label for s in sim.record.snapshots)
    if missing:
        why.append(f"the snapshots {sorted(missing.elements())} were never taken")
    return {"stopped_by": key, "completed": not why, "incomplete_reason": "; ".join(why)}


def run_scenario(scenario: Scenario, **kwargs) -> dict:
    """Run ``scenario`` with the discrete solver; return its summary dict.

    :func:`run_simulation` without the Simulation (the keyword arguments are its own).
    """
    return run_simulation(scenario, **kwargs)[0]


def run_simulation(scenario: Scenario, *, out: str | Path | None = None,
                   progress: bool = False, checkpoint_interval: float | None = None,
                   resume: bool = True, threads: int | None = None, check: bool = True,
                   log=None, cache_dir=None, save: bool = True, init=None
                   ) -> tuple[dict, discrete.Simulation]:
    """Run ``scenario`` with the discrete solver; return its summary and the Simulation.

    Parameters
    ----------
    scenario : Scenario
        A validated scenario.
    out : path, optional
        Write the full run (chain, state, recording, scenario and summary as JSON
        attributes) to this HDF5 file, atomically.
    progress : bool
        Show a progress bar for long runs.
    checkpoint_interval : float, optional
        Wall time between checkpoints, s (>= 0).  None (default): one uninterrupted
        ``Simulation.run`` call, no checkpoints.  Otherwise the run is integrated in
        segments (:func:`hertzchain.checkpoint.run_segmented`, bit for bit the same
        result) and, with ``out``, checkpointed to ``out + ".ckpt"``, which is removed
        once ``out`` is written; SIGINT/SIGTERM then stop cleanly with a checkpoint
        (:class:`hertzchain.checkpoint.Interrupted`).
    resume : bool
        Continue from an existing checkpoint of the same scenario (default).  A
        checkpoint of another scenario raises :class:`~hertzchain.checkpoint.CheckpointError`;
        ``resume=False`` deletes it and starts over.
    threads : int, optional
        Kernel threads (bitwise identical results for every value); None: default.
    check : bool
        Validate dt, the wave and the stop event against the built chain
        (:func:`build_simulation`); False only to provoke an instability on purpose.
    log : callable, optional
        Receives one-line messages (resuming, checkpoint removed); default: silent.
    cache_dir : path, optional
        Cache of settled waves (:func:`build_initial`).
    save : bool
        Write the finished run to ``out`` (default).  False: ``out`` names only the
        checkpoint (removed at the end as usual) and the lock; the caller keeps what it
        needs of the returned Simulation (``hertzchain reproduce``'s reduced files).
    init : discrete.initial.Initial, optional
        The scenario's initial state, already built (:func:`build_simulation`'s
        ``init``: not built a second time; :func:`hertzchain.models.run` passes its
        own).  Unused when the run resumes from a checkpoint.

    Returns
    -------
    summary : dict
        Keys ``Ek_tr, Ek_re, Ep_tr, Ep_re, Et_tr, Et_re`` (NaN unless ``separated``),
        ``front_speed_tr, front_speed_re`` (m/s; NaN if fewer than 5 grains gave an
        arrival time, the wave never reached the interface, or the speed is not
        converged in the grid's rows, module docstring), ``front_speed_tr_over_c0L``
        (NaN also at δ0 = 0), ``transmitted`` (fracture/squeeze/none), ``reflected``
        (compressive/expansive/none), ``n_transmitted_pulses`` (these three None unless
        ``separated``), ``separated``, ``separation_fraction``, ``stopped_by``
        (:data:`STOPPED_BY`), ``completed`` (the run stopped where the scenario asked
        and took every snapshot), ``incomplete_reason`` ("" if completed),
        ``energy_drift``, ``steps``, ``t`` (s), ``dt`` (s), ``n_grains``, ``wall_time``
        (s; summed over resumed sessions), the wave train of the final state
        (``train_waves``, None outside its window with ``train_note`` saying why, and
        the per-wave lists of :data:`hertzchain.measure.TRAIN_KEYS`, front first;
        :func:`hertzchain.measure.wave_train`, written to ``out`` as the group
        ``train``, :func:`discrete.io.load_train`).  Every key but ``wall_time`` is bit for bit
        the same whether the run was checkpointed, interrupted and resumed, or not.
    sim : discrete.Simulation
        The finished simulation (state and record).

    Raises
    ------
    ScenarioError
        Invalid scenario for the built chain (:func:`build_simulation`), or a stop that
        cannot be reached (:func:`check_stop`).
    discrete.InstabilityError
        NaN or energy drift beyond the tolerance; the message names the cause and the
        largest stable dt, and with ``out`` the partial results are written to
        :func:`partial_path` (a checkpoint, if any, is kept).
    hertzchain.checkpoint.Interrupted
        SIGINT/SIGTERM during a checkpointed run (after writing the checkpoint).
    hertzchain.checkpoint.OutputBusy
        Another process is running into the same ``out`` (an advisory lock,
        :func:`hertzchain.checkpoint.output_lock`).
    """
    from . import checkpoint as C

    kwargs = {"out": out, "progress": progress, "checkpoint_interval": checkpoint_interval,
              "resume": resume, "threads": threads, "check": check, "log": log,
              "cache_dir": cache_dir, "save": save, "init": init}
    if out is None:
        return _run_simulation(scenario, **kwargs)
    with C.output_lock(out):  # one process per output file (and its checkpoint)
        return _run_simulation(scenario, **kwargs)


def _run_simulation(scenario: Scenario, *, out, progress, checkpoint_interval, resume,
                    threads, check, log, cache_dir, save, init=None
                    ) -> tuple[dict, discrete.Simulation]:
    from . import checkpoint as C

    start = time.perf_counter()
    say = log or (lambda message: None)
    if checkpoint_interval is not None and not (
            isinstance(checkpoint_interval, int | float) and math.isfinite(checkpoint_interval)
            and checkpoint_interval >= 0):
        raise ValueError(f"checkpoint_interval must be None or a finite number of seconds "
                         f">= 0 (got {checkpoint_interval!r})")
    out = None if out is None else Path(out)
    ckpt = C.checkpoint_path(out) if out is not None and checkpoint_interval is not None \
        else None
    key = C.run_key(scenario.to_dict())
    resumed = None
    if ckpt is not None:
        C.remove_stale_temporaries(out)
        if resume:
            resumed = C.read_checkpoint(ckpt, key, threads=threads)
        elif ckpt.exists():
            ckpt.unlink()
            say(f"removed the checkpoint {ckpt} (--force)")
    if resumed is not None:
        sim, extra = resumed
        chain, amp, elapsed = sim.chain, extra["incident_amplitude"], extra["wall_time"]
        strain0 = extra.get("incident_strain", math.nan)
        say(f"resuming from {ckpt}: t = {sim.t:.6g} s, step {sim.steps}")
    else:
        chain, init, sim = build_simulation(scenario, threads=threads, check=check,
                                            cache_dir=cache_dir, init=init)
        check_stop(scenario, sim.dt)
        amp = M.classification_amplitude(chain, init.u, init.v, init.wall_left,
                                         init.wall_right)
        strain0 = math.nan if not scenario.initial.initial_kind.placed else M.incident_strain(
            chain, init.v, D.overlaps_from_displacements(init.u, chain.delta0,
                                                          init.wall_left, init.wall_right),
            *build_law(scenario.chain))
        elapsed = 0.0
    until = None
    if scenario.run.until_front_at is not None:
        until = discrete.WaveAt(scenario.run.until_front_at)

    def extra_state() -> dict:
        return {"incident_amplitude": amp, "incident_strain": strain0,
                "wall_time": elapsed + time.perf_counter() - start,
                "scenario": scenario.to_dict()}

    # with checkpoints, SIGINT/SIGTERM stop the integration at a segment end (checkpoint,
    # Interrupted) and, once it is done, wait until the output is written
    with C.deferred_signals(checkpoint_interval is not None) as late_signal:
        try:
            stopped_by = _integrate(sim, scenario, until, ckpt, key, checkpoint_interval,
                                    extra_state, progress, late_signal)
        except discrete.InstabilityError as exc:
            # the message names the cause, the stable dt at the initial expected overlaps
            # and the default dt (kept across save/load, so also after a resume)
            text = str(exc)
            if out is not None:
                text += _write_partial(out, sim, scenario, text)
            if ckpt is not None and ckpt.exists():
                text += f"; the last checkpoint {ckpt} is kept"
            raise discrete.InstabilityError(text) from exc
        ts = sim.time_step  # how dt was chosen, and the accuracy estimate of an rtol run
        summary = {**run_outcome(scenario, sim, stopped_by),
                   **M.summarise(chain, sim, amp, rtol=ts.rtol),
                   **_incident_strain(scenario, sim, strain0)}
        train, train_note = M.wave_train(chain, sim, summary["t_end_reached"])
        summary.update(M.train_summary(train, train_note))
        summary.update(integrator=sim.integrator, dt_source=ts.source,
                       rtol=ts.rtol, rtol_estimate=ts.error_estimate,
                       rtol_maxima=ts.maxima)
        # the split's own estimate against rtol (NaN: not verified, so not met)
        summary["split_meets_rtol"] = (None if ts.rtol is None
                                       or not math.isfinite(summary["Ek_tr"])
                                       else bool(summary["split_estimate"] <= ts.rtol))
        summary["wall_time"] = elapsed + time.perf_counter() - start
        if out is not None and save:
            try:
                discrete.save(out, sim, attrs={"scenario": canonical_json(scenario.to_dict()),
                                               "summary": canonical_json(summary),
                                               "split_estimate": summary["split_estimate"]},
                              train=train)
            except OSError as exc:  # disk full, ...: the summary and checkpoint survive
                kept = ckpt if ckpt is not None and ckpt.exists() else None
                raise C.OutputWriteError(out, exc, summary, kept) from None
        if ckpt is not None:
            ckpt.unlink(missing_ok=True)
            C.remove_stale_temporaries(out)
    if late_signal:
        done = f"the run had finished: results written to {out}" if out is not None \
            and save else "the run had finished (no output file)"
        raise C.Interrupted(late_signal[0], None, sim.t, sim.steps, note=done)
    return summary, sim
