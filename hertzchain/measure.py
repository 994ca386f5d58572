r"""The one owner of every measured quantity of a run and of its measurement window.

Everything ``hertzchain run``, ``hertzchain compare``, a sweep and ``hertzchain
reproduce`` report about the waves of a run is measured here, with the low-level tools
of :mod:`discrete.diagnostics`, and only inside the window in which it is what its name
says.  Outside its window a number is NaN and a label None (JSON null), and a
``*_note`` says why; everything derived from it (a difference, an error, a verdict)
inherits the window (docs/physics.md §17).

Geometry
    :func:`first_grain` (the first grain of section 0, past a striker grain prepended
    by :func:`discrete.initial.impact`), :func:`interfaces` (the first grain of every
    later section).  Every interface position in the package comes from here.

Windows of a discrete run (:class:`Windows`, :func:`windows`, read off its energy grid)
    * the **incident** time ``t_incident``: the last row before the incident wave's
      energy within 5 grains of the first interface exceeds 1e-6 of the chain's
      (:func:`discrete.diagnostics.incident_time_index`);
    * the **separation** ``t_separated``: the first row from which that energy stays
      below the strictest of :data:`SEPARATION_FRACTIONS` that is met
      (:func:`separated_row`);
    * **a wave reached a chain end** ``t_end_reached``: the first row at which the
      energy of the :data:`END_GRAINS` grains at an end rises by more than
      :data:`END_FRACTION` of the chain's (its largest total so far), and more than
      doubles, above the least it held since the start (:func:`end_arrival_row`): a
      wall's echo or grains piling up at a free end.

Quantities and their windows (:func:`summarise`)
    * energy ratios (Table 2, docs/physics.md §6): after separation, phase-averaged
      (:func:`discrete.diagnostics.phase_averaged_ratios`); normalised to the incident
      energy of section 0 in the window before ``t_incident`` (``ratios_normalised_to``
      says so); a dissipative run also gets the energy dissipated between the two
      windows, ``Ed``, so that E_T + E_R + E_d = 1 (docs/physics.md §17), and
      ``dissipated`` (J);
    * front speeds: arrival-time fits (:func:`front_speed`) on the rows before a wave
      reached a chain end, reported only if converged in the grid's row spacing;
    * labels (fracture/squeeze, compressive/expansive, pulse count) on the final state,
      only if the waves separated and no wave reached a chain end before it;
    * the incident strain: the peak dynamic strain (r − δ0)/d of the incident wave,
      read off the contacts of the measured state (the initial state of a placed wave;
      an impact's wave when its velocity peak passes :func:`incident_grain`), for
      whatever contact law (:func:`incident_strain`).

The wave train (:func:`wave_train`, :func:`train_summary`)
    the solitary waves of the final state (:func:`discrete.waves.split_train`: each
    pulse above :data:`TRAIN_FRACTION` of the largest |v|, its amplitude, speed and
    energy those of the exact lattice wave of its energy), only on a chain of one
    section, once a striker has handed over its energy, and if no wave reached a chain
    end before the final state; otherwise ``train_waves`` is None and ``train_note``
    says why.

Samples of several models (``hertzchain compare``)
    :func:`sample_fronts`, :func:`fit_sample_speed`, :func:`incident_extent`,
    :func:`crossing_time`, :func:`valid_until` and :func:`separated_by`: the same
    windows for the samples at the common times.

Exit status (:data:`EXIT_OK` … :data:`EXIT_NOT_VERIFIED`, :func:`unverified`): the one
contract of ``run``, ``compare`` and ``sweep`` (docs/guide/exit_status.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

import theory
from discrete import diagnostics as D

__all__ = [
    "ACTIVITY_ROWS", "CROSSING_GRAINS", "END_FRACTION", "END_GRAINS", "EXIT_ERROR",
    "EXIT_INCOMPLETE", "EXIT_NOT_VERIFIED", "EXIT_OK", "EXIT_PENDING", "FIT_FROM",
    "FRONT_ROWS_RTOL", "FRONT_THRESHOLD", "HANDOVER_FRACTION", "SEPARATION", "SEPARATION_FRACTIONS",
    "TRANSMITTED_FLOOR", "Windows", "classification_amplitude", "crossing_time",
    "end_arrival_row", "first_grain", "fit_sample_speed", "front_speed",
    "front_speed_from_maxima", "grain_energies", "handover_row", "incident_extent",
    "incident_grain", "incident_peak", "incident_strain", "interfaces", "sample_fronts",
    "separated_by", "separated_row", "summarise", "total_energy_rows", "unverified", "valid_until",
    "windows", "TRAIN_FRACTION", "TRAIN_KEYS", "TRAIN_MAX_WAVES", "SUMMARY_UNITS",
    "wave_train", "train_summary",
]

# -- exit status --------------------------------------------------------------------
EXIT_OK = 0
"""Everything asked for ran to its stop and every quantity asked to rtol met it."""
EXIT_PENDING = 1
"""(sweep) Points are still pending: interrupted, or ``--max-points``."""
EXIT_ERROR = 2
"""An error: invalid input, an instability, I/O; a sweep whose every point failed."""
EXIT_INCOMPLETE = 3
"""A run (a model, a sweep point) ended before the stop it asked for, or failed."""
EXIT_NOT_VERIFIED = 4
"""Everything completed, but a quantity is not verified to the ``rtol`` asked for (a
``*_meets_rtol`` key of the summary is false): its number is reported and flagged."""


def unverified(summary: dict) -> list[str]:
    """The ``*_meets_rtol`` keys of a summary that are False (not verified to rtol).

    A key that is None (no rtol asked, or the quantity not measured) is no failure.
    """
    return sorted(k for k, v in summary.items()
                  if k.endswith("_meets_rtol") and v is False)


# -- geometry -------------------------------------------------------------------------
def first_grain(chain: Any) -> int:
    """Index of the first grain of section 0: the number of striker grains before it.

    :func:`discrete.initial.impact` prepends a striker of another mass as section -1;
    it belongs to no section of the scenario.
    """
    return int(np.count_nonzero(np.asarray(chain.section) < 0))


def interfaces(chain: Any) -> list[int]:
    """First grain of every section after the first: the interfaces of ``chain``.

    The one place the interface position comes from (grain ``i`` right of contact ``i``);
    a striker grain (section -1, :func:`first_grain`) is not a section.  Empty for a
    chain of one section.
    """
    sec = np.asarray(chain.section)
    starts = [0, *(np.flatnonzero(sec[1:] != sec[:-1]) + 1).tolist()]
    return [s for s in starts if sec[s] >= 0][1:]


def _first_section_end(chain: Any) -> int:
    """One past the last grain of section 0."""
    ifaces = interfaces(chain)
    return ifaces[0] if ifaces else int(chain.n)


# -- row blocks of the energy grid -------------------------------------------------------
ACTIVITY_ROWS = 256
"""Grid rows per block in :func:`total_energy_rows` (256 × 1,000 grains: 2 MiB)."""


def total_energy_rows(ek: np.ndarray, ep: np.ndarray, fn):
    """``fn`` of the total energy grid e = ek + ep (J, (T, Nc)), row block by row block.

    ``fn(e_block)`` returns one array, or a tuple of arrays, with one value per row of
    the block (it may overwrite the block, and must not return a view of it: one block
    buffer serves every block); the blocks' results are joined.  The same values, bit
    for bit, as ``fn`` of the whole e for any row-wise ``fn`` (each row's reductions do
    not depend on the other rows; a block is C-contiguous like a fresh array), with
    neither e nor |e| held whole.
    """
    rows = ek.shape[0]
    buf = np.empty((min(ACTIVITY_ROWS, rows), *ek.shape[1:]),
                   dtype=np.result_type(ek, ep))
    parts = []
    for i in range(0, max(rows, 1), ACTIVITY_ROWS):
        block = buf[:min(ACTIVITY_ROWS, rows - i)]
        np.add(ek[i:i + ACTIVITY_ROWS], ep[i:i + ACTIVITY_ROWS], out=block)
        parts.append(fn(block))
    if isinstance(parts[0], tuple):
        return tuple(np.concatenate(col) for col in zip(*parts, strict=True))
    return np.concatenate(parts)


# -- separation -------------------------------------------------------------------------
SEPARATION_FRACTIONS = (1e-6, 1e-5, 1e-4, 1e-3)
"""Energy fractions near the interface tried, strictest first, to call the waves separated."""


def separated_row(activity: np.ndarray, iface: int) -> tuple[int | None, float]:
    """The grid row where the waves count as separated, and the fraction that was met.

    The first of :data:`SEPARATION_FRACTIONS` (strictest first) for which
    :func:`discrete.diagnostics.separated_time_index` finds a row, given the interface
    activity per row (:func:`discrete.diagnostics.interface_activity`); (None, NaN) if
    none is met.  A cut impact wave drags a weak dispersive tail (~1e-5 of the energy)
    across the interface for a long time, so the strictest fraction that is met is
    used and reported (docs/physics.md §6: the attribution of the interface contact
    then changes the ratios by less than that fraction).  The one rule of the run
    summary, Table 2 and ``compare``.
    """
    for fraction in SEPARATION_FRACTIONS:
        i_out = D.separated_time_index(None, iface, fraction=fraction, activity=activity)
        if i_out is not None:
            return i_out, fraction
    return None, math.nan


# -- chain ends ---------------------------------------------------------------------------
END_FRACTION = 1e-4
"""A wave has reached a chain end when the energy of the :data:`END_GRAINS` grains there
exceeds this fraction of the chain's (above what they held before it came)."""
END_GRAINS = 10


def end_arrival_row(fraction_at_end: np.ndarray, *, fraction: float = END_FRACTION,
                    active_start: str = "rise") -> int | None:
    """First row at which a wave arrives at a chain end; None if none does.

    ``fraction_at_end``: per row, the energy of the grains at that end over the chain's.
    ``active_start`` says what an end that already holds energy at the first row means:

    * ``"rise"`` (the discrete chain's own windows): a wave arrives when the end's
      share rises above the least it held since the first row by more than
      ``fraction`` and by more than that least share itself (it more than doubles).
      An impact starts at the left end, where the share wobbles at ~1 while the wave
      forms, and leaves drifting grains there (0.1–1 % of the energy at δ0 = 0): they
      are no arrival, a returning wave is.  For an end quiet at the start this is
      "exceeds ``fraction``" to within the share it held;
    * ``"arrived"`` (a wall's echo, :mod:`hertzchain.reproduce.table2`): an end not
      quiet (share ≥ ``fraction``) at the first row counts as reached then; otherwise
      the first row at which the share reaches ``fraction``.
    """
    f = np.asarray(fraction_at_end, dtype=float)
    if f.size == 0:
        return None
    if active_start == "arrived":
        quiet = f < fraction
        if not quiet[0]:
            return 0
        hit = np.flatnonzero(~quiet)
    elif active_start == "rise":
        low = np.minimum.accumulate(f)
        hit = np.flatnonzero(f - low > np.maximum(fraction, low))
    else:
        raise ValueError(f"active_start must be 'rise' or 'arrived' (got {active_start!r})")
    return int(hit[0]) if hit.size else None


# -- windows of a discrete run -----------------------------------------------------------
@dataclass(frozen=True)
class Windows:
    """The measurement windows of one discrete run, read off its energy grid.

    Attributes
    ----------
    interface : int or None
        First grain of the second section (:func:`interfaces`); None for one section.
    i_incident, i_separated : int or None
        Grid rows of the incident time and of the separation (None: the wave started at
        the interface or never reached it / the waves did not separate).
    separation_fraction : float
        The fraction of :data:`SEPARATION_FRACTIONS` that was met (NaN if none).
    i_end : int
        Rows ``[0, i_end)`` are before any wave reached a chain end (the grid's row
        count if none did).
    end_reached : str
        ``"left"``, ``"right"`` or ``""`` (no wave reached a chain end on the grid).
    t : ndarray
        The grid's row times, s.
    """

    interface: int | None
    i_incident: int | None
    i_separated: int | None
    separation_fraction: float
    i_end: int
    end_reached: str
    t: np.ndarray

    def time(self, row: int | None) -> float:
        """The time of a row, s (NaN for None)."""
        return math.nan if row is None else float(self.t[row])

    @property
    def t_incident(self) -> float:
        """The incident time, s (NaN if none)."""
        return self.time(self.i_incident)

    @property
    def t_separated(self) -> float:
        """The separation time, s (NaN unless separated)."""
        return self.time(self.i_separated)

    @property
    def t_end_reached(self) -> float:
        """When a wave first reached a chain end, s (inf: on no row of the grid)."""
        return float(self.t[self.i_end]) if self.end_reached else math.inf


def windows(chain: Any, t: np.ndarray, ek: np.ndarray, ep: np.ndarray, coarsen: int = 1
            ) -> Windows:
    """The :class:`Windows` of a run from its energy grid (rows at ``t`` s, J).

    One pass over the grid by row blocks (:func:`total_energy_rows`): the interface
    activity (bit for bit :func:`discrete.diagnostics.interface_activity` of the whole
    grid) and the energy at both ends.  ``coarsen``: grains per grid column; the ends
    count ⌈:data:`END_GRAINS` / coarsen⌉ columns.
    """
    ifaces = interfaces(chain)
    iface = ifaces[0] // coarsen if ifaces else None
    g = max(1, math.ceil(END_GRAINS / coarsen))
    n_cols = ek.shape[1]

    def per_row(e):
        act = (D.interface_activity(e, iface, overwrite=True) if iface is not None
               and 0 < iface < n_cols else np.zeros(e.shape[0]))
        a = e if iface is not None and 0 < iface < n_cols else np.abs(e, out=e)
        return act, a.sum(axis=1), a[:, :g].sum(axis=1), a[:, -g:].sum(axis=1)

    rows = ek.shape[0]
    if rows == 0:
        return Windows(iface, None, None, math.nan, 0, "", np.asarray(t, dtype=float))
    act, tot, left, right = total_energy_rows(ek, ep, per_row)
    # (over the largest total so far: a dissipative chain's total decays, and the
    # share of grains left drifting at an end would rise without a wave arriving)
    ref = np.maximum.accumulate(tot)
    safe = np.where(ref > 0, ref, 1.0)
    ends = {side: end_arrival_row(x / safe) for side, x in (("left", left),
                                                             ("right", right))}
    hit = {k: v for k, v in ends.items() if v is not None}
    side = min(hit, key=hit.get) if hit else ""
    i_end = hit[side] if hit else rows
    i_in = i_out = None
    frac = math.nan
    if iface is not None and 0 < iface < n_cols:
        try:
            i_in = D.incident_time_index(None, iface, activity=act)
        except ValueError:  # the wave is at the interface already at t = 0
            i_in = None
        i_out, frac = separated_row(act, iface)
    return Windows(iface, i_in, i_out, frac, i_end, side, np.asarray(t, dtype=float))


def separated_by(sim: Any, until: float) -> float:
    """When the waves of a discrete run had separated from its first interface, s.

    :func:`separated_row` on the rows of its energy grid up to ``until`` (s, a sample's
    nominal time: the rows up to the step that took it): NaN if they
    had not (or the chain has no interface, or no grid was recorded).  ``compare``'s
    window for an energy partition: the run summary's rule, read up to the comparison
    time.
    """
    rec = sim.record
    if not len(rec.energy):
        return math.nan
    t, ek, ep = rec.energy_grids()
    ifaces = interfaces(sim.chain)
    if not ifaces:
        return math.nan
    # (a sample at a nominal time is the state at the first step at or after it: the
    # rows up to that step)
    rows = int(np.searchsorted(t, until + float(sim.dt) * (1 - 1e-9), side="right"))
    iface = ifaces[0] // rec.energy_coarsen
    if rows < 2 or not 0 < iface < ek.shape[1]:
        return math.nan
    act = total_energy_rows(ek[:rows], ep[:rows],
                            lambda e: D.interface_activity(e, iface, overwrite=True))
    i_out, _ = separated_row(act, iface)
    return math.nan if i_out is None else float(t[i_out])


# -- front speeds -----------------------------------------------------------------------
FRONT_ROWS_RTOL = 1e-3
"""Largest relative change of a front speed when every other grid row is dropped for it
to be reported (else NaN, :func:`front_speed`).

A front speed is a straight-line fit of the grains' arrival times, each the peak of
the grain's energy refined by a parabola through three rows; a number that moves with
the rows is no front speed.  The reflected wave is often no travelling pulse at all: at
δ0 = 0 an expansive "reflection" is grains drifting apart, and behind many interfaces
the reflected energy is a dispersive tail (measured on 300 | 300-grain chains, rows
every 25 … 400 steps: point b at δ0/d = 1e-3 885.59 m/s at 25–100 steps, 869 at 200,
672 at 400).  Where the wave is a pulse the speed is converged: point N 898.19–898.45
m/s (25–200 steps), a change ≤ 3e-4 per halving of the rows."""


def _column_argmax(e: np.ndarray, block: int = 64) -> np.ndarray:
    """``e.argmax(axis=0)`` (first maximum of each column), by blocks of rows.

    NumPy's argmax along the first axis of a C-ordered grid transposes the whole grid;
    blocks of 64 rows stay in cache.
    """
    best = e[0].copy()
    idx = np.zeros(e.shape[1], dtype=np.int64)
    for s in range(1, e.shape[0], block):
        blk = e[s:s + block]
        m = blk.max(axis=0)
        better = m > best
        if better.any():
            cols = np.flatnonzero(better)
            idx[cols] = s + blk[:, cols].argmax(axis=0)
            best[cols] = m[cols]
    return idx


def _arrival_fit(e: np.ndarray, tt: np.ndarray, x: np.ndarray, skip: int,
                 floor_after_skip: bool) -> float:
    """Grains per second from the energy peaks of the columns of ``e`` (rows at ``tt``).

    Each column's peak row i (interior: 0 < i < last) is refined by the parabola
    through rows i−1, i, i+1, which gives the arrival time and the peak's value.  A
    column counts if its refined peak is above 0.2 of the largest refined peak (of
    every column, or with ``floor_after_skip`` of the columns from ``skip`` on) — the
    range of grains fitted then does not move with the rows (a decaying wave's speed
    changes along the chain) — and lies at or past ``skip``.  NaN if fewer than 5
    columns count.
    """
    if e.shape[0] < 3:
        return math.nan
    i = _column_argmax(e)
    inner = np.flatnonzero((i > 0) & (i < e.shape[0] - 1))
    if inner.size < 5:
        return math.nan
    y0, y1, y2 = e[i[inner] - 1, inner], e[i[inner], inner], e[i[inner] + 1, inner]
    den = y0 - 2 * y1 + y2
    frac = np.clip(np.where(den != 0, 0.5 * (y0 - y2) / np.where(den != 0, den, 1), 0.0),
                   -0.5, 0.5)
    peak = y1 - 0.25 * (y0 - y2) * frac
    top = (peak[inner >= skip].max(initial=0.0) if floor_after_skip
           else peak.max(initial=0.0))
    ok = (peak > 0.2 * top) & (inner >= skip)
    if np.count_nonzero(ok) < 5:
        return math.nan
    arrival = tt[i[inner[ok]]] + frac[ok] * (tt[1] - tt[0])
    return float(np.polyfit(arrival, x[inner[ok]], 1)[0])


def front_speed(t, energy, grains: range, i_start: int, d: float, *, skip: int = 10,
                floor_after_skip: bool = False, stop: int | None = None,
                tol: float = FRONT_ROWS_RTOL) -> tuple[float, float, str]:
    """Front speed (m/s) from arrival times of the energy peak at ``grains`` (in order).

    Rows ``[i_start, stop)`` of the grid ``energy`` (rows at ``t``, s; ``stop``: before
    a wave reached a chain end).  Per grain the row of its largest energy is refined
    (:func:`_arrival_fit`); a straight-line fit of grain position against arrival time
    over the grains from ``skip`` past the start gives the speed (Fig. 6), times the
    column width ``d`` (m).  The speed is measured again on the even and on the odd rows
    (two grids of twice the spacing, at two phases: the arrival-time bias depends on the
    phase of the rows, and one coarse grid can agree by chance): the larger relative
    change is the returned estimate, an upper bound of the error on the rows (the error
    at twice the spacing), and the speed is NaN unless it is within ``tol``
    (:data:`FRONT_ROWS_RTOL`; against an rtol run's own ``rtol`` the caller reports
    ``front_speed_meets_rtol``).  Measured on a decaying wave (viscoelastic Hertz, see
    :data:`hertzchain.runner.GRID_ROWS_DISSIPATIVE`): estimates 2.6e-5, 3.9e-3, 2.0e-2,
    2.1e-3 at 1/8, 1/4, 1/2, 1 transit a row, errors 1e-6, 1.8e-5, 2.1e-3, 1.8e-2 (the
    drop of the even rows alone gave 1.3e-3 at one transit: nearly passed).  ``grains``
    is a range of columns (step ±1): the grid is read through a view, never copied.

    Returns
    -------
    speed : float
        m/s, NaN if no front was measured.
    estimate : float
        |speed on every other row / speed − 1| (NaN if not measured).
    note : str
        Why the speed is NaN ("" if it is not).
    """
    stop_col = None if grains.stop < 0 else grains.stop
    end = energy.shape[0] if stop is None else stop
    e = np.asarray(energy)[i_start:end, slice(grains.start, stop_col, grains.step)]
    tt = np.asarray(t)[i_start:end]
    if len(grains) < skip + 5:
        return math.nan, math.nan, f"fewer than {skip + 5} grains to fit"
    x = np.asarray(grains)
    slope = _arrival_fit(e, tt, x, skip, floor_after_skip)
    if not (math.isfinite(slope) and slope != 0):
        return math.nan, math.nan, ("fewer than 5 grains gave an arrival time "
                                    "(on the rows before a wave reached a chain end)")
    halves = [_arrival_fit(e[k::2], tt[k::2], x, skip, floor_after_skip) for k in (0, 1)]
    est = max((abs(h / slope - 1) if math.isfinite(h) else math.inf) for h in halves)
    if not est <= tol:
        return math.nan, est, (f"not converged in the grid's rows (changes by {est:.2g} "
                               f"on every other row; allowed {tol:g}): no travelling "
                               "pulse, or rows too far apart")
    return abs(slope) * d, est, ""


def front_speed_from_maxima(vmax, vmax_time, v, d: float, *, skip: int = 10) -> float:
    """Front speed (m/s) from the times of every grain's refined velocity peak.

    The estimator of :func:`front_speed` on the kinetic-energy grid (a grain's kinetic
    energy peaks when its speed does), with the peak times the kernel found between the
    steps (``record.vmax_time``: cubic Hermite, O(h⁴)): a straight-line fit
    (:func:`discrete.diagnostics.fit_speed`) of grain index against peak time over the
    grains from ``skip`` on whose peak has passed (v below half of it) and is above 0.2
    of the largest, times the grain diameter ``d`` (m).  NaN if fewer than 5 grains
    qualify.
    """
    vmax, tpk, v = (np.asarray(a, dtype=float) for a in (vmax, vmax_time, v))
    done = (v < 0.5 * vmax) & np.isfinite(tpk) & (vmax > 0)
    if not done.any():
        return math.nan
    ok = done & (vmax > 0.2 * vmax[done].max())
    ok[:skip] = False
    cols = np.flatnonzero(ok)
    if cols.size < 5:
        return math.nan
    return abs(D.fit_speed(cols, tpk[cols]).speed) * d


# -- incident wave -----------------------------------------------------------------------
def incident_grain(chain: Any) -> int:
    """Grain at which an impact's incident wave is measured: the middle of section 0.

    A snapshot is taken when the leading wave's velocity peak passes it
    (:class:`discrete.WaveAt`, :func:`hertzchain.runner.build_simulation`): the wave
    has formed on the way there (an equal-mass impact's within ~20 grains, paper Fig.
    2) and has not yet met the interface or the far end.
    """
    s0 = first_grain(chain)
    return s0 + (_first_section_end(chain) - s0) // 2


def incident_peak(chain: Any, v: np.ndarray) -> tuple[float, float]:
    """Position (grains) and peak grain velocity (m/s) of the incident wave in a state.

    The leading pulse (:func:`discrete.diagnostics.leading_pulse`, above half of the
    largest) of the grain kinetic energy ½mv² in section 0: its parabola-refined
    position, and the refined peak |v| of the velocity pulse there.  (NaN, NaN) if
    there is none.
    """
    v = np.asarray(v, dtype=float)
    s0, n1 = first_grain(chain), _first_section_end(chain)
    kin = 0.5 * np.asarray(chain.mass) * v ** 2
    p = D.leading_pulse(kin, lo=s0, hi=n1, threshold=0.5)
    if p is None:
        return math.nan, math.nan
    q = [x for x in D.find_pulses(v, threshold=0.0, lo=max(s0, p.start - 1),
                                  hi=min(n1, p.stop + 1))]
    vel = max((abs(x.amplitude) for x in q), default=abs(float(v[p.index])))
    return float(p.position), float(vel)


PEAK_STEPS_PER_PERIOD = 100
"""Steps per smallest contact period 2π/ω of :func:`_contact_peaks`' local integration
(velocity Verlet's error in the peak overlap ~ (π/100)²/24 ≈ 4e-5 of the wave's strain
at most, far less for the smooth peak)."""


def _contact_peaks(chain: Any, v: np.ndarray, overlaps: np.ndarray, law: Any,
                   drag: float, grains: tuple[int, int], contacts: np.ndarray,
                   max_steps: int = 20_000) -> np.ndarray:
    """The largest overlap each of ``contacts`` reaches from a state on, m.

    The equation of motion (paper Eq. 2 with the contact law's force, Eq. 1 for Hertz,
    :mod:`theory.laws`; static forces, which balance gravity, subtracted; on-site drag
    −γ v) in overlaps r_j and velocities v_i, ṙ_j = v_{j-1} − v_j, integrated by
    velocity Verlet from the state (``v`` m/s, ``overlaps`` m) on the grains
    ``grains = (a, b)`` only (the grains just outside keep their velocity: a window
    wider than the wave, whose outside is at rest for the few periods integrated), at
    :data:`PEAK_STEPS_PER_PERIOD` steps per period of the stiffest contact, until every
    one of ``contacts`` (indices of the chain's contacts, inside the window) is past its
    maximum (its overlap fell below it) or ``max_steps``.  The maxima are the sampled
    ones at the steps.  A plain NumPy reference, independent of the solver's kernels.
    """
    a, b = grains
    m = np.asarray(chain.mass, dtype=float)[a:b]
    k = np.asarray(chain.k, dtype=float)[a:b + 1]
    d0 = np.asarray(chain.delta0, dtype=float)[a:b + 1]
    r = np.asarray(overlaps, dtype=float)[a:b + 1].copy()
    vv = np.asarray(v, dtype=float)
    left = float(vv[a - 1]) if a > 0 else 0.0
    right = float(vv[b]) if b < vv.size else 0.0
    vw = vv[a:b].copy()

    def force(x, xd):
        return law.force(x, xd, k) if law.dissipative else law.elastic(x, k)

    f0 = force(d0, np.zeros_like(d0))

    def rates(vel):
        return np.concatenate([[left], vel]) - np.concatenate([vel, [right]])

    def acc(x, vel):
        f = force(x, rates(vel)) - f0
        return (f[:-1] - f[1:]) / m - drag * vel

    stiff = float(np.max(law.stiffness(np.maximum(r, d0) * 1.5, k) / np.r_[m, m[-1]]))
    dt = 2 * math.pi / math.sqrt(max(4.0 * stiff, 1e-300)) / PEAK_STEPS_PER_PERIOD
    j = np.asarray(contacts) - a
    best = r[j].copy()
    done = np.zeros(j.size, dtype=bool)
    a_n = acc(r, vw)
    for _ in range(max_steps):
        vh = vw + 0.5 * dt * a_n
        r += dt * rates(vh)
        a_n = acc(r, vh)  # (the dissipative force at the half-step velocity)
        vw = vh + 0.5 * dt * a_n
        done |= r[j] < best
        np.maximum(best, r[j], out=best)
        if done.all():
            break
    return best


PEAK_NOW = 1e-6
"""A contact is at its maximum now when its vertex time |τ*| = |ṙ/r̈| is below this
fraction of its own period (:func:`_at_its_peak`): a placed wave centred on a contact
(ṙ = 0 there by symmetry, to round-off)."""


def _at_its_peak(chain: Any, v: np.ndarray, overlaps: np.ndarray, law: Any, drag: float,
                 c: int) -> float | None:
    """Contact ``c``'s overlap (m) if the state is at its maximum in time, else None.

    ṙ_c = v_{c-1} − v_c and r̈_c = a_{c-1} − a_c from the equation of motion (as in
    :func:`_contact_peaks`); at its maximum when r̈_c < 0 and the vertex time
    τ* = −ṙ_c/r̈_c is within :data:`PEAK_NOW` of the contact's period 2π (m/K)^{1/2};
    the value is then the vertex r_c − ṙ_c²/(2 r̈_c).
    """
    n = int(chain.n)
    if not 1 <= c <= n - 1:
        return None
    a0 = max(c - 2, 0)
    b0 = min(c + 2, n)
    sub = slice(a0, b0 + 1)  # contacts a0 .. b0 around grains a0 .. b0-1
    vv = np.asarray(v, dtype=float)
    r = np.asarray(overlaps, dtype=float)[sub]
    k, d0 = np.asarray(chain.k, dtype=float)[sub], np.asarray(chain.delta0, dtype=float)[sub]
    m = np.asarray(chain.mass, dtype=float)[a0:b0]
    vg = vv[a0:b0]
    ext = np.concatenate([[vv[a0 - 1] if a0 > 0 else 0.0], vg, [vv[b0] if b0 < n else 0.0]])
    rd = ext[:-1] - ext[1:]

    def force(x, xd):
        return law.force(x, xd, k) if law.dissipative else law.elastic(x, k)

    f = force(r, rd) - force(d0, np.zeros_like(d0))
    acc = (f[:-1] - f[1:]) / m - drag * vg
    j = c - a0  # contact c between grains c-1 and c: accelerations j-1 and j
    rdd = float(acc[j - 1] - acc[j])
    rdot = float(rd[j])
    stiff = float(law.stiffness(max(r[j], d0[j]), k[j]))
    if not (rdd < 0 and stiff > 0):
        return None
    period = 2 * math.pi * math.sqrt(float(min(m[j - 1], m[j])) / stiff)
    if abs(rdot / rdd) > PEAK_NOW * period:
        return None
    return float(r[j] - 0.5 * rdot * rdot / rdd)


def incident_strain(chain: Any, v: np.ndarray, overlaps: np.ndarray, law: Any,
                    drag: float = 0.0, at: float | None = None) -> float:
    """Peak dynamic strain (r − δ0)/d of the incident wave in a state of ``chain``, 1.

    From the state (``v`` m/s, ``overlaps`` r m, N + 1) and the contact ``law`` (with the
    on-site ``drag``, 1/s): the strain pulse of the incident wave among the contacts
    between grains of section 0 — the pulse of r − δ0 nearest to grain ``at`` (its
    velocity peak, an impact's measurement grain) or, without ``at``, under the peak of
    the grain kinetic energy (:func:`incident_peak`) — and the largest overlap its
    contacts from the peak on reach as the wave goes by (:func:`_contact_peaks`, a few
    periods integrated from the state): every contact sees the whole wave pass, so its
    maximum in time is the wave's peak, whereas the largest overlap of a single state
    misses it by the wave's phase between contacts (~12 % for the ~5 grains of a wave
    at δ0 = 0).  Measured with the chain's own law, so it holds for any contact law and
    any striker (no solitary-wave relation assumed).  NaN if there is no compressive
    pulse.
    """
    s0 = first_grain(chain)
    n1 = _first_section_end(chain)
    lo, hi = s0 + 1, n1  # contacts between two grains of section 0
    if hi - lo < 1:
        return math.nan
    d = np.asarray(chain.diameter, dtype=float)
    dia = np.r_[d[0], d]  # contact j: grain j-1's diameter (wall: grain 0's)
    d0 = np.asarray(chain.delta0, dtype=float)
    r = np.asarray(overlaps, dtype=float)
    if at is None:
        at = incident_peak(chain, v)[0]
        if not math.isfinite(at):
            return math.nan
    pulses = [p for p in D.find_pulses((r - d0) / dia, threshold=0.0, lo=lo, hi=hi)
              if p.sign > 0]
    if not pulses:
        return math.nan
    # contact j sits at j - 1/2 in grain units: a wave whose velocity peaks at grain
    # ``at`` has its strain peak between contacts at and at + 1
    c = at + 0.5

    def distance(p) -> tuple[float, float]:
        return max(0.0, p.start - c, c - (p.stop - 1)), abs(p.position - c)

    pulse = min(pulses, key=distance)
    c = pulse.index
    at_peak = _at_its_peak(chain, v, r, law, drag, c)
    if at_peak is not None:  # (a placed wave centred on a contact: read it off)
        return float((at_peak - d0[c]) / dia[c])
    # the peak lies between the pulse's largest contact and the next: it and the three
    # contacts ahead of it reach their maxima within a few transits; the window holds
    # the pulse and ten grains more either side
    ahead = np.arange(max(pulse.index, lo), min(pulse.index + 4, hi))
    a, b = max(s0, pulse.start - 10), min(n1, pulse.stop + 10)
    peak = _contact_peaks(chain, v, r, law, drag, (a, b), ahead)
    return float(np.max((peak - d0[ahead]) / dia[ahead]))


# -- energies of samples -----------------------------------------------------------------
def grain_energies(chain: Any, v: np.ndarray, strain: np.ndarray, law: Any = None
                   ) -> tuple[np.ndarray, np.ndarray]:
    r"""Kinetic energy per grain and potential energy per contact, J (docs/physics.md §6).

    ``v`` (…, N) m/s and ``strain`` (…, N+1) m (δ − δ0); the potential energy is the
    contact energy minus the static energy of the same contact: for Hertz (``law``
    None) (2/5) k ([δ]_+^{5/2} − δ0^{5/2}) (:func:`theory.wave_contact_energy`), for
    another law (:class:`theory.laws.ContactLaw`) its :meth:`~theory.laws.ContactLaw.energy`,
    k/(n+1) ([δ]_+^{n+1} − δ0^{n+1}) for F = k δ^n.
    The linear term F0 (δ − δ0) is kept (Table 2).

    Under gravity (a body force m_i g on every grain, ``chain.gravity``) the energy the
    equations of motion conserve also holds the body force's potential −g Σ_i m_i u_i
    (:meth:`discrete.Simulation.energy`, which books it per grain from the displacements).
    From strains alone it is written per contact: with δ_j − δ0_j = u_{j-1} − u_j and
    the walls at rest (the bottom wall carries the weight), Σ_i m_i g u_i =
    Σ_j W_j (δ_j − δ0_j), W_j = g Σ_{i<j} m_i the weight above contact j (summation by
    parts; W_0 = 0).  So contact j's potential energy is
    U(δ_j) − U(δ0_j) − W_j (δ_j − δ0_j): summed over the chain it is the conserved
    energy of the discrete run, for the discrete chain's samples and a continuum's
    alike (without it the linear term g Σ m u, first order in the strain and weighted
    by the depth's static force, made the whole chain's energy of a 100-grain vertical
    chain swing from 0.93 to 3.5 of E_in as the wave went down).  Without gravity
    W = 0: the definition above, unchanged.
    """
    strain = np.asarray(strain)
    kin = 0.5 * chain.mass * np.asarray(v) ** 2
    r = chain.delta0 + np.asarray(strain)
    pot = theory.wave_contact_energy(r, chain.k, chain.delta0) if law is None \
        else law.energy(r, chain.k, chain.delta0)
    g = float(getattr(chain, "gravity", 0.0))
    if g:
        weight_above = g * np.r_[0.0, np.cumsum(chain.mass)]
        pot = pot - weight_above * np.asarray(strain)
    return kin, pot


def valid_until(chain: Any, times: np.ndarray, v: np.ndarray, strain: np.ndarray,
                ends: str, walls: tuple[str, str]) -> float:
    """First sample time at which a wave arrives at an end where two models differ, s.

    The continuum's ends (``ends``: ``"wall"`` or ``"free"``) against the discrete
    chain's ``walls``; inf when they are the same.  Per sample (``times`` s, ``v`` and
    ``strain`` of the discrete chain) the energy of the :data:`END_GRAINS` grains at
    each end over the chain's (:func:`grain_energies`).  An end condition acts on the
    chain only through the force of its end contact, so

    * an end whose end contact carries at least :data:`END_FRACTION` of the chain's
      energy at the first sample (a wave placed against it) gives that sample's time:
      the models differ there from the start;
    * any other end counts from the first sample at which a wave *arrives* there,
      :func:`end_arrival_row` with ``active_start="rise"`` (the discrete run's own rule,
      :func:`windows`): an impact's struck grain moves away from its end, whose share
      falls from ~1 to the grains left drifting there (no force on the end), and only
      a wave coming back (or, at a quiet end, any wave reaching it) closes the window.
    """
    if ends == "wall" and "free" not in walls:
        return math.inf
    kin, pot = grain_energies(chain, v, strain)
    e = np.abs(kin) + 0.5 * np.abs(pot[:, :-1] + pot[:, 1:])
    total = e.sum(axis=1)
    safe = np.where(total > 0, total, 1.0)
    out = math.inf
    for sl, contact in ((slice(0, END_GRAINS), 0), (slice(-END_GRAINS, None), -1)):
        if abs(pot[0, contact]) >= END_FRACTION * safe[0]:
            return float(times[0])
        row = end_arrival_row(e[:, sl].sum(axis=1) / safe, active_start="rise")
        if row is not None:
            out = min(out, float(times[row]))
    return out


# -- fronts of samples (compare) ---------------------------------------------------------
FRONT_THRESHOLD = 0.05
"""A pulse of grain kinetic energy counts as a wave front if its peak exceeds this
fraction of the incident wave's peak grain kinetic energy (≈ 22 % in velocity)."""
FIT_FROM = 10
"""Fronts closer than this to the interface (grains) are left out of the speed fits."""
CROSSING_GRAINS = 5.0
"""The incident wave has crossed the interface at least this many grains (at its speed)
after its peak reached it (the half-width of the paper's precompressed wave; the
compacton at δ0 = 0 is narrower); wider waves take their :func:`incident_extent`."""
SEPARATION = 1e-4
"""Energy fraction of the incident wave that may still be on its way across the
interface at the crossing time (:func:`incident_extent`): 100 times below the 1 %
validity threshold, so that a partition measured after the crossing is the scattering
result to better than 1e-4 of the incident energy."""


def sample_fronts(chain: Any, v: np.ndarray, strain: np.ndarray, iface: int | None,
                  ref_ek: float, i_cross: int) -> tuple[dict, dict, dict]:
    """Fronts, leading-pulse peak velocities and strains of samples (``compare``).

    Per sample (rows of ``v`` m/s and ``strain`` m), the peak positions (grains,
    parabola-refined) of the leading pulses of the grain kinetic energy ½mv² above
    :data:`FRONT_THRESHOLD` of ``ref_ek`` (J): the incident wave (right-most pulse left
    of the interface, before sample ``i_cross``), the transmitted wave (right-most
    pulse right of it) and the reflected wave (left-most pulse left of it, from
    ``i_cross`` on); NaN where there is none.  ``peaks``: the refined peak velocity of
    each (m/s); ``strains``: its peak |dynamic strain| / d.
    """
    kin, _ = grain_energies(chain, v, strain)
    k = v.shape[0]
    n = chain.n
    fronts = {w: np.full(k, np.nan) for w in ("incident", "transmitted", "reflected")}
    peaks = {w: np.full(k, np.nan) for w in fronts}
    strains = {w: np.full(k, np.nan) for w in fronts}
    i = n if iface is None else iface
    d = float(chain.diameter[0])

    def peak(signal, lo, hi) -> float:
        """Parabola-refined extreme of ``signal`` in [lo, hi) (its value between samples)."""
        found = D.find_pulses(signal, threshold=0.0, lo=lo, hi=hi)
        return max((q.amplitude for q in found), key=abs) if found else math.nan

    def put(which, s, p):
        fronts[which][s] = p.position
        lo, hi = max(p.start - 1, 0), min(p.stop + 1, n)
        peaks[which][s] = peak(v[s], lo, hi)
        strains[which][s] = abs(peak(strain[s], lo, min(hi + 1, n + 1))) / d

    for s in range(k):
        ek = kin[s]
        if s < i_cross:
            p = D.leading_pulse(ek, lo=0, hi=i, threshold=FRONT_THRESHOLD, reference=ref_ek)
            if p is not None:
                put("incident", s, p)
        elif i > 1:
            p = D.leading_pulse(ek, direction=-1, lo=0, hi=i, threshold=FRONT_THRESHOLD,
                                reference=ref_ek)
            if p is not None:
                put("reflected", s, p)
        if iface is not None and i < n - 1:
            p = D.leading_pulse(ek, lo=i, hi=n, threshold=FRONT_THRESHOLD, reference=ref_ek)
            if p is not None:
                put("transmitted", s, p)
    return fronts, peaks, strains


def fit_sample_speed(t, x, iface: float | None, d: float, sign: int) -> float:
    """Speed (m/s) of a sampled front: a straight-line fit of its positions ``x`` (grains).

    Over the samples ≥ :data:`FIT_FROM` grains from the interface (``iface``, the
    interface contact's position), at times ``t`` (s), times the grain diameter ``d``
    (m) and ``sign`` (−1: a left-going wave).  NaN from fewer than 3 samples.
    """
    x = np.asarray(x, dtype=float)
    ok = np.isfinite(x)
    if iface is not None:
        ok &= np.abs(x - iface) >= FIT_FROM
    if ok.sum() < 3:
        return math.nan
    slope = np.polyfit(np.asarray(t)[ok], x[ok], 1)[0]
    return float(sign * slope * d)


def incident_extent(chain: Any, v: np.ndarray, strain: np.ndarray, x0: float,
                    fraction: float = SEPARATION) -> float:
    """Grains behind a right-going wave's peak ``x0`` holding all but ``fraction`` of its energy.

    ``v`` (m/s, one per grain) and ``strain`` (m, δ − δ0 per contact) describe one state
    of ``chain`` holding only that wave; the energy per grain is its kinetic energy plus
    half the |potential energy| of each of its contacts (docs/physics.md §6).  The result
    L is the smallest distance such that the grains more than L behind ``x0`` carry at
    most ``fraction`` of the total: once the peak is L past the interface, at most that
    fraction of the wave has still to cross.  For the KdV wave (strain ∝
    sech²(x/W), W = √(2δ0/ξ_m) grains, whose linear potential energy F0 ξ dominates)
    L ≈ (W/2) ln(1/fraction): ~21 grains at the paper's ξ_m/δ0 = 0.09, ~200 at 1e-3.
    """
    kin, pot = grain_energies(chain, v, strain)
    e = np.abs(kin) + 0.5 * (np.abs(pot[:-1]) + np.abs(pot[1:]))
    total = float(e.sum())
    if not total > 0 or not math.isfinite(total):
        return 0.0
    first = int(np.flatnonzero(np.cumsum(e) > fraction * total)[0])
    return max(0.0, float(x0) - first)


def crossing_time(t_hit: float, extent: float, d: float, speed: float) -> float:
    """When the incident wave has crossed the interface, s.

    The arrival time ``t_hit`` (s) of its peak at the interface plus, at its ``speed``
    (m/s), the larger of :data:`CROSSING_GRAINS` and its :func:`incident_extent`
    (grains of diameter ``d``, m): from then on at most :data:`SEPARATION` of the
    incident energy has still to cross.
    """
    return t_hit + max(CROSSING_GRAINS, extent) * d / speed


# -- the discrete run's summary ---------------------------------------------------------
TRANSMITTED_FLOOR = 1e-3
"""The transmitted wave is classified only if the right section's largest |v| exceeds
this fraction of the chain's (otherwise "none": the wave has not arrived, and
classifying round-off dust of 1e-50 m/s can fail)."""

_RATIOS = ("Ek_tr", "Ek_re", "Ep_tr", "Ep_re", "Et_tr", "Et_re")


def _dissipated_between(sim: Any, t: np.ndarray, ek: np.ndarray, ep: np.ndarray,
                        spans) -> float:
    """Energy dissipated between the two ratio windows, J.

    From the energy balance E(t) + D(t) = E(0) (docs/physics.md §11), which the run's
    monitor verifies to its ``energy_drift``: the decrease of the whole chain's energy
    (every column of the grid) between the windows, each averaged with the window's
    Blackman–Harris weights (:func:`discrete.diagnostics.phase_window`, the average the
    ratios' energies are taken with; the row itself for a one-row window).  The kernel
    books D(t) only at the monitor samples (every 10,000 steps: interpolating them was
    1e-3 of the incident energy off); the rows hold E(t) at every row.  0 for a
    conservative run.
    """
    if not sim.dissipated() > 0:
        return 0.0
    total = total_energy_rows(ek, ep, lambda e: e.sum(axis=1))

    def mean(lo: float, hi: float) -> float:
        if hi > lo:
            rows, w = D.phase_window(t, lo, hi)
            if rows.size and w.sum() > 0:
                return float(np.sum(w * total[rows]) / w.sum())
        return float(np.interp(0.5 * (lo + hi), t, total))

    (a0, a1), (b0, b1) = spans
    return mean(a0, a1) - mean(b0, b1)


HANDOVER_FRACTION = 1e-3
"""The incident window holds only once the striker keeps at most this fraction of the
chain's energy (:func:`handover_row`)."""


def handover_row(ek: np.ndarray, ep: np.ndarray, columns: int, i_incident: int,
                 fraction: float = HANDOVER_FRACTION) -> int | None:
    """First grid row from which a striker has handed its energy to the chain.

    ``ek``, ``ep``: the energy grid (J, (T, Nc)); ``columns``: the first columns, which
    hold the striker (section -1 of :func:`discrete.initial.impact`).  Their Σ|e| over
    the chain's Σ|e| per row: the first row from which it stays at or below
    ``fraction`` through row ``i_incident``; None if it is above at ``i_incident``.

    A striker heavier than the grains gives its energy not to one wave but to a train
    of decreasing waves, unloading nearly exponentially, and ends almost at rest (Job,
    Melo, Sokolow & Sen, Granular Matter 10 (2007) 13; Sen et al., Phys. Rep. 462
    (2008) 21; docs/physics.md, "A heavy striker").  Until it has, the energy of section
    0 is not the incident energy: what is still in the striker enters the chain later
    and crosses the interface after the incident window (E_T + E_R of a lossless chain
    was 1.03 for a 3-mass striker on 20 grains).  From the returned row on, at most
    ``fraction`` of the energy is still to be handed over.
    """

    def share(e):
        a = np.abs(e, out=e)
        tot = a.sum(axis=1)
        return np.divide(a[:, :columns].sum(axis=1), tot, out=np.zeros_like(tot),
                         where=tot > 0)

    f = total_energy_rows(ek[:i_incident + 1], ep[:i_incident + 1], share)
    above = np.flatnonzero(f > fraction)
    if above.size and above[-1] == i_incident:
        return None
    return int(above[-1] + 1) if above.size else 0


def _normalisation(sim: Any, e_in: float, spans, striker: bool = False) -> str:
    """What the energy ratios are normalised to, in words (the summary's key)."""
    (a0, a1), (b0, b1) = spans
    where = ("section 0 and the striker" if striker else "section 0")
    text = (f"E_in = {e_in:.6g} J, the energy of {where} averaged over t = "
            f"{a0 * 1e3:.4g}-{a1 * 1e3:.4g} ms (before the incident wave reached the "
            "interface")
    if striker:
        text += (f", after the striker had handed over all but {HANDOVER_FRACTION:g} of "
                 "the chain's energy; E_R counts the striker with section 0")
    text += f"); E_T, E_R averaged over t = {b0 * 1e3:.4g}-{b1 * 1e3:.4g} ms"
    rec = sim.record
    if sim.dissipated() > 0 and len(rec.monitor_t):
        before = float(np.interp(a1, rec.monitor_t, rec.monitor_dissipated))
        e0 = float(rec.monitor_energy[0])
        text += (f"; the run had dissipated {before:.4g} J ({before / e0:.3g} of E(0) = "
                 f"{e0:.6g} J) by the end of the incident window, and Ed is the energy "
                 "dissipated between the two windows over E_in: Et_tr + Et_re + Ed = 1")
    return text


def classification_amplitude(chain: Any, u, v, wall_left: float = 0.0,
                             wall_right: float = 0.0) -> float:
    """The incident amplitude :func:`summarise` classifies against (of the initial state).

    Max dynamic strain (r − δ0)/δ0 under precompression, max |v| (m/s) at δ0 = 0 (the
    reference of :func:`discrete.diagnostics.classify_reflected`'s "none").
    """
    if np.any(chain.delta0 > 0):
        r = D.overlaps_from_displacements(u, chain.delta0, wall_left, wall_right)
        ok = chain.delta0 > 0
        return float(np.max(np.abs(r[ok] - chain.delta0[ok]) / chain.delta0[ok]))
    return float(np.max(np.abs(v)))


def summarise(chain: Any, sim: Any, incident: float | None = None, *,
              rtol: float | None = None) -> dict:
    """Flat summary of a finished run: every quantity in its window (module docstring).

    ``incident`` is the classification's incident amplitude (max (r − δ0)/δ0 of the
    initial state, or max |v| at δ0 = 0): reflected waves below 5 % of it are "none", and
    so is a transmitted wave whose peak velocity is below :data:`TRANSMITTED_FLOOR` of
    the chain's.  ``rtol``: the run's requested accuracy (front speeds are then checked
    to it too, ``front_speed_meets_rtol``).

    For a chain with one section only the drift, cost, windows and front speed are
    filled; the energy ratios and classifications need an interface.
    """
    out: dict = {"steps": int(sim.steps), "t": float(sim.t), "dt": float(sim.dt),
                 "energy_drift": float(sim.energy_drift), "n_grains": int(chain.n)}
    out.update(dict.fromkeys(_RATIOS, math.nan))
    out.update(front_speed_tr=math.nan, front_speed_re=math.nan,
               front_speed_tr_over_c0L=math.nan, transmitted=None, reflected=None,
               n_transmitted_pulses=None, separated=False, separation_fraction=math.nan,
               split_estimate=math.nan, front_speed_meets_rtol=None,
               t_incident=math.nan, t_separated=math.nan, t_end_reached=math.inf,
               end_reached="", Ed=math.nan, dissipated=float(sim.dissipated()),
               ratios_normalised_to="", ratios_note="", labels_note="",
               front_speed_tr_note="", front_speed_re_note="")
    rec = sim.record
    s0 = first_grain(chain)
    d = float(chain.diameter[s0])
    ifaces = interfaces(chain)
    if not ifaces:
        out.update(ratios_note="one section: no interface", labels_note="one section: "
                   "no interface", front_speed_re_note="one section: no reflected wave")
    if not len(rec.energy):
        if not ifaces and rec.vmax_time is not None:  # an rtol run's maxima
            out["front_speed_tr"] = front_speed_from_maxima(rec.vmax_refined, rec.vmax_time,
                                                            sim.v, d)
            if not math.isfinite(out["front_speed_tr"]):
                out["front_speed_tr_note"] = ("fewer than 5 grains' velocity peaks had "
                                              "passed")
        else:
            out["front_speed_tr_note"] = "no energy grid was recorded"
        return out
    t, ek, ep = rec.energy_grids()  # (views of the record's grid, no copy)
    coarsen = rec.energy_coarsen
    win = windows(chain, t, ek, ep, coarsen)
    end_note = (f"a wave reached the {win.end_reached} end of the chain at t = "
                f"{win.t_end_reached * 1e3:.4g} ms" if win.end_reached else "")
    out.update(t_incident=win.t_incident, t_end_reached=win.t_end_reached,
               end_reached=win.end_reached)

    def speed(grains, i_start, **kw) -> tuple[float, float, str]:
        return front_speed(t, ek, grains, i_start, d * coarsen, stop=win.i_end, **kw)

    def meets(est: float, value: float) -> None:
        if rtol is not None and math.isfinite(value):
            ok = est <= rtol and out["front_speed_meets_rtol"] is not False
            out["front_speed_meets_rtol"] = bool(ok)

    if not ifaces:
        v, est, note = speed(range(ek.shape[1]), 0)
        out["front_speed_tr"], out["front_speed_tr_note"] = v, note
        meets(est, v)
        return out
    iface = win.interface
    # (a striker, section -1, is on the incident side: it counts with section 0)
    block_section = np.maximum(chain.section[::coarsen][: ek.shape[1]], 0)
    i_in, i_out = win.i_incident, win.i_separated
    i_lo = 0
    if s0 > 0 and i_in is not None:
        i_lo = handover_row(ek, ep, math.ceil(s0 / coarsen), i_in)
    if i_in is None:
        out["ratios_note"] = ("the incident wave was at the interface already at t = 0: "
                              "no incident energy to normalise to")
    elif i_lo is None:
        out["ratios_note"] = (
            f"the striker still held more than {HANDOVER_FRACTION:g} of the chain's "
            f"energy when the incident wave reached the interface (t = "
            f"{win.t_incident * 1e3:.4g} ms): the wave train had not left it, and the "
            "energy of section 0 was not yet the incident energy")
    elif i_out is None:
        out["ratios_note"] = ("the waves did not separate from the interface on the "
                              "recorded grid (the energy within 5 grains of it stayed "
                              f"above {SEPARATION_FRACTIONS[-1]:g} of the chain's)")
    else:
        # the kinetic/potential split averaged over the lattice phase in windows of
        # SPLIT_WINDOW_TRANSITS incident transits before i_in and after i_out (a single
        # row's split depends on its phase, which moves with dt: docs/physics.md §6)
        # (the incident window starts no earlier than the striker's handover, i_lo)
        r, split_est = D.phase_averaged_ratios(t[i_lo:], ek[i_lo:], ep[i_lo:],
                                               block_section, i_in - i_lo, i_out - i_lo,
                                               coarsen=coarsen)
        ratios = {k: float(v) for k, v in r.as_dict().items() if k in _RATIOS}
        if all(math.isfinite(v) for v in ratios.values()):
            e_in = r.incident_kinetic + r.incident_potential
            ed = _dissipated_between(sim, t, ek, ep, r.windows) / e_in
            out.update(ratios, separated=True, separation_fraction=win.separation_fraction,
                       split_estimate=split_est, t_separated=win.t_separated, Ed=ed)
            (a0, a1), (b0, b1) = r.windows
            out["ratios_normalised_to"] = _normalisation(sim, e_in, r.windows, s0 > 0)
            if win.end_reached and win.i_end <= int(np.searchsorted(t, b1)):
                # (said, and weighed: the window's edges carry little weight, and the
                # split's estimate compares it with a window 3/4 as long about the same
                # centre, which a wave at an end near the window's end would move)
                out["ratios_note"] = (
                    f"{end_note}, inside the averaging window of the kinetic/potential "
                    f"split (t = {b0 * 1e3:.4g}-{b1 * 1e3:.4g} ms): its effect on Ek_*, "
                    f"Ep_* is within split_estimate = {split_est:.2g}; Et_* hold")
        else:
            out["ratios_note"] = "a window of the ratios holds no energy"
    # the wave reached the interface: its energy there passed 1e-6 of the total on the
    # grid (incident_time_index is the last row before), or it started there
    if i_in is not None and i_in >= ek.shape[0] - 1:
        why = "the incident wave had not reached the interface by the end of the run"
        out.update(front_speed_tr_note=why, front_speed_re_note=why,
                   labels_note=why, ratios_note=out["ratios_note"] or why)
        return out
    # arrival times after the incident peak has reached the interface, on the rows
    # before a wave reached a chain end
    i_hit = int(np.argmax(ek[:, max(iface - 1, 0)]))
    vtr, est_tr, note_tr = speed(range(iface, ek.shape[1]), i_hit)
    vre, est_re, note_re = speed(range(iface - 1, -1, -1), i_hit + 1,
                                 floor_after_skip=True)
    out.update(front_speed_tr=vtr, front_speed_re=vre, front_speed_tr_note=note_tr,
               front_speed_re_note=note_re)
    meets(est_tr, vtr)
    meets(est_re, vre)
    precompressed = chain.delta0[s0 + 1] > 0
    if precompressed:
        c0l = float(theory.c0(chain.k[s0 + 1], chain.mass[s0], d, chain.delta0[s0 + 1]))
        out["front_speed_tr_over_c0L"] = vtr / c0l
    # classification on the final state (Fig. 7), only once the waves have separated
    # and before any wave reached a chain end: before separation the left section still
    # holds (part of) the incident wave and the right one a transmitted wave still
    # forming; after an end, a wall's echo or grains piled up at a free end
    if not out["separated"]:
        out["labels_note"] = ("the waves did not separate from the interface: the final "
                              "state holds no scattered waves yet")
        return out
    if win.end_reached:
        out["labels_note"] = (f"{end_note}, before the final state at t = "
                              f"{sim.t * 1e3:.4g} ms: its waves are no longer the "
                              "scattered ones")
        return out
    n_left = ifaces[0]
    # (ranges of fewer than 3 grains are left "none")
    out.update(transmitted="none", reflected="none", n_transmitted_pulses=0)
    v_tr = float(np.max(np.abs(sim.v[n_left:])))
    if chain.n - 1 - n_left >= 2 and v_tr > TRANSMITTED_FLOOR * float(np.max(np.abs(sim.v))):
        ctr = D.classify_transmitted(sim.v, lo=n_left, hi=chain.n - 1, direction=1)
        out["transmitted"], out["n_transmitted_pulses"] = ctr.label, int(ctr.n_pulses)
    lo = s0 + 1 if precompressed else s0
    if n_left - 1 - lo >= 2:
        if precompressed:
            cre = D.classify_reflected(overlaps=sim.overlaps(), delta0=chain.delta0,
                                       lo=lo, hi=n_left - 1, reference=incident)
        else:
            cre = D.classify_reflected(velocity=sim.v, lo=lo, hi=n_left - 1,
                                       reference=incident)
        out["reflected"] = cre.label
    if out["reflected"] == "none":  # measured: no reflected wave, so no front to time
        out["front_speed_re"] = math.nan
        out["front_speed_re_note"] = "no reflected wave (reflected = none)"
    return out


# -- the wave train -------------------------------------------------------------------
TRAIN_FRACTION = 0.05
"""A train counts the pulses whose peak |v| exceeds this fraction of the largest
(:func:`discrete.waves.split_train`'s threshold; docs/physics.md §14, "A heavy
striker": the count of :func:`theory.striker.StrikerTrain.count_above` at the same
fraction)."""

TRAIN_KEYS = {"train_position": "1", "train_velocity_max": "m/s", "train_amplitude": "m",
              "train_speed": "m/s", "train_energy": "J"}
"""The per-wave lists of the summary (front first) and their units: grain index, the
exact lattice wave's peak grain velocity and peak dynamic overlap, its speed, and the
wave's energy (:class:`discrete.waves.TrainWave`)."""


TRAIN_MAX_WAVES = 100
"""More pulses than this above :data:`TRAIN_FRACTION` are no train of solitary waves
(a disordered or thermalised state), and are not split into exact waves (one root
search each)."""


def wave_train(chain: Any, sim: Any, t_end_reached: float) -> tuple[Any, str]:
    """The solitary waves of a finished run's final state, or None and why not.

    :func:`discrete.waves.split_train` of the final state over the grains of section 0
    (past a striker, :func:`first_grain`) with :data:`TRAIN_FRACTION`, in its window:

    * a chain of one section (at an interface the final state holds the scattered
      waves, counted by ``n_transmitted_pulses``);
    * the energy grid was recorded and no wave reached a chain end before the final
      state (``t_end_reached``, s, :func:`windows`): an echo or grains piled up at an
      end are no waves of the train;
    * a striker (section -1) keeps at most :data:`HANDOVER_FRACTION` of the chain's
      energy (:func:`handover_row`'s rule on the final state: until then the train is
      still leaving it);
    * at most :data:`TRAIN_MAX_WAVES` pulses.

    Returns
    -------
    train : discrete.waves.Train or None
        With at least one wave; None outside the window.
    note : str
        Why there is none ("" if there is).
    """
    if interfaces(chain):
        return None, "an interface: the final state holds the scattered waves"
    if not len(sim.record.energy):
        return None, "no energy grid was recorded: whether a wave reached a chain end is unknown"
    if t_end_reached <= sim.t:
        return None, (f"a wave reached a chain end at t = {t_end_reached * 1e3:.4g} ms, "
                      f"before the final state (t = {sim.t * 1e3:.4g} ms)")
    s0 = first_grain(chain)
    ek, ep = sim.grain_energy()
    e = np.abs(ek + ep)
    if s0 and e.sum() > 0 and e[:s0].sum() > HANDOVER_FRACTION * e.sum():
        return None, (f"the striker still held {e[:s0].sum() / e.sum():.3g} of the chain's "
                      f"energy (> {HANDOVER_FRACTION:g}): the train had not left it")
    if not np.any(sim.v[s0:]):
        return None, "every grain is at rest: no wave"
    lo, hi = s0, int(chain.n)
    pulses = len(D.find_pulses(sim.v, threshold=TRAIN_FRACTION, lo=lo, hi=hi))
    if pulses > TRAIN_MAX_WAVES:
        return None, (f"{pulses} pulses above {TRAIN_FRACTION:g} of the largest |v| "
                      f"(more than {TRAIN_MAX_WAVES}): no train of solitary waves")
    from discrete.waves import Train, split_train  # (only where there is a train to split)

    waves = split_train(sim, threshold=TRAIN_FRACTION, lo=lo, hi=hi)
    if not waves:  # pragma: no cover - a nonzero velocity always makes a pulse
        return None, "no pulse above the threshold"
    return Train(tuple(waves), float(sim.t), TRAIN_FRACTION, 0.5, lo, hi), ""


def train_summary(train: Any, note: str = "") -> dict:
    """The summary keys of a train: ``train_waves``, ``train_note`` and :data:`TRAIN_KEYS`.

    ``train_waves``: the number of waves (None: not measured, ``train_note`` says
    why); the lists run from the front of the train (wave 1 leads: the right-most for
    waves moving right, v > 0), empty when not measured.
    """
    out: dict = {"train_waves": None, "train_note": note}
    out.update({key: [] for key in TRAIN_KEYS})
    if train is None or not len(train):
        return out
    waves = list(train.waves)
    lead = max(waves, key=lambda w: w.energy)
    if lead.velocity_max > 0:  # right-going: the front is the right-most
        waves = waves[::-1]
    out["train_waves"] = len(waves)
    out["train_note"] = ""
    for key in TRAIN_KEYS:
        out[key] = [float(getattr(w, key.removeprefix("train_"))) for w in waves]
    return out


SUMMARY_UNITS = {
    "t": "s", "dt": "s", "energy_drift": "1", "steps": "1", "n_grains": "1",
    "Ek_tr": "1", "Ek_re": "1", "Ep_tr": "1", "Ep_re": "1", "Et_tr": "1", "Et_re": "1",
    "Ed": "1", "dissipated": "J", "front_speed_tr": "m/s", "front_speed_re": "m/s",
    "front_speed_tr_over_c0L": "1", "separation_fraction": "1", "split_estimate": "1",
    "t_incident": "s", "t_separated": "s", "t_end_reached": "s", "incident_strain": "1",
    "incident_strain_over_delta0": "1", "rtol": "1", "rtol_estimate": "1",
    "wall_time": "s", "wall_time_all": "s", "train_waves": "1", **TRAIN_KEYS,
    "t_compare": "s", "t_cross": "s", "t_separated_by_compare": "s",
    "incident_extent": "1",
}
"""The unit of every number of a run's and a comparison's summary ("1": dimensionless
— energy ratios are over the incident energy, strains over d or δ0 —; grain positions
are indices, "1").  A key not listed is a label or a note."""
