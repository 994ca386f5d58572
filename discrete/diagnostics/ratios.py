r"""Table 2 energy ratios, "incident"/"separated" times and the Fig. 8 normalisation.

The ratios of a run are read with :func:`phase_averaged_ratios`: the kinetic/potential
split of a lattice wave oscillates with its phase (period one transit d/V), so it is
averaged over a window of :data:`SPLIT_WINDOW_TRANSITS` transits (docs/physics.md §6).

Paper Section 4 (Fig. 8, Table 2) and docs/physics.md §6: E_Tr/E_In is the energy in the
right section once the waves have separated from the interface over the incident energy
measured in the left section before the wave reaches the interface; E_Re/E_In the
energy left in the left section over the same; for the kinetic, potential (contact
energy minus the static precompression energy, see :mod:`.energies`) and total energy.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .energies import (
    Attribution,
    ChainEnergies,
    FloatArray,
    _f,
    section_sums,
    section_weights,
    snapshot_energies,
)

__all__ = [
    "EnergyRatios",
    "energy_ratios",
    "table2_ratios",
    "energy_ratios_from_grid",
    "interface_activity",
    "incident_time_index",
    "separated_time_index",
    "normalise_to_incident_peak",
    "SPLIT_WINDOW_TRANSITS",
    "phase_window",
    "phase_averaged_ratios",
]

SPLIT_WINDOW_TRANSITS = 16.0
"""Length of the window over which the kinetic/potential split is averaged, in transit
times d/V of the incident wave (:func:`phase_averaged_ratios`)."""


@dataclass(frozen=True)
class EnergyRatios:
    r"""Transmitted and reflected energies relative to the incident wave (paper Table 2).

    E_Tr/E_In = (energy in the right section, late) / (energy in the left section, early),
    E_Re/E_In = (energy in the left section, late) / (same incident energy), for the
    kinetic (k), potential (p, relative to static, docs/physics.md §6) and total (t) energy.

    Attributes
    ----------
    Ek_tr, Ek_re, Ep_tr, Ep_re, Et_tr, Et_re : float
        The six ratios of Table 2.
    incident_kinetic, incident_potential : float
        K and P of the incident wave, J.
    incident_linear, incident_quadratic : float
        L = Σ F0 (r - δ0) and Q = P - L of the incident wave, J (NaN when computed from
        per-grain energies only).
    interface : str
        Attribution of the interface contact used.
    windows : tuple
        ((start, stop), (start, stop)) in s: the spans over which the incident and the
        final energies were averaged (:func:`phase_averaged_ratios`; one row's time
        twice when a single row was read); () when not known.
    """

    Ek_tr: float
    Ek_re: float
    Ep_tr: float
    Ep_re: float
    Et_tr: float
    Et_re: float
    incident_kinetic: float
    incident_potential: float
    incident_linear: float
    incident_quadratic: float
    interface: str
    windows: tuple = ()

    KEYS = ("Ek_tr", "Ek_re", "Ep_tr", "Ep_re", "Et_tr", "Et_re")

    def as_dict(self) -> dict[str, float]:
        """The six ratios with the keys of :func:`theory.table2_prediction`."""
        return {key: getattr(self, key) for key in self.KEYS}

    @property
    def balance(self) -> dict[str, float]:
        """Tr + Re for each kind; the total is 1 up to the energy drift of the run."""
        return {"kinetic": self.Ek_tr + self.Ek_re, "potential": self.Ep_tr + self.Ep_re,
                "total": self.Et_tr + self.Et_re}

    def theory(self, gamma_rg: float) -> dict[str, float]:
        """Linear-acoustic prediction :func:`theory.table2_prediction` for this incident wave."""
        from theory import table2_prediction

        if not np.isfinite(self.incident_linear):
            raise ValueError("the linear/quadratic split needs contact energies "
                             "(use energy_ratios with ChainEnergies)")
        return table2_prediction(gamma_rg, self.incident_kinetic, self.incident_linear,
                                 self.incident_quadratic)


def _ratios(inc: dict, fin: dict, left: int, right: int, interface: str) -> EnergyRatios:
    ids = list(inc["sections"])
    for s in (left, right):
        if s not in ids:
            raise ValueError(f"no grain in section {s} (sections: {ids})")

    def g(d: dict, key: str, s: int) -> float:
        # states stacked along leading axes are averaged (see energy_ratios)
        return float(np.mean(d[key][..., ids.index(s)])) if key in d else float("nan")

    out = {}
    for short, key in (("k", "kinetic"), ("p", "potential"), ("t", "total")):
        e_in = g(inc, key, left)
        if e_in == 0.0:
            raise ValueError(f"incident {key} energy is zero: is the wave in section {left}?")
        out[f"E{short}_tr"] = g(fin, key, right) / e_in
        out[f"E{short}_re"] = g(fin, key, left) / e_in
    return EnergyRatios(**out, incident_kinetic=g(inc, "kinetic", left),
                        incident_potential=g(inc, "potential", left),
                        incident_linear=g(inc, "linear", left),
                        incident_quadratic=g(inc, "quadratic", left), interface=interface)


def energy_ratios(
    incident: ChainEnergies,
    final: ChainEnergies,
    section: ArrayLike,
    *,
    left: int = 0,
    right: int = 1,
    interface: Attribution = "half",
) -> EnergyRatios:
    """Table 2 energy ratios from two chain states (paper Section 4, docs/physics.md §6).

    Parameters
    ----------
    incident : ChainEnergies
        A state with the incident wave entirely in section ``left``, before it reaches
        the interface (see :func:`incident_time_index`); or several such states stacked
        along a leading axis, whose section sums are averaged.
    final : ChainEnergies
        A state (or stacked states, averaged) with the transmitted and reflected waves
        separated from the interface (see :func:`separated_time_index`).
    section : array_like of int, shape (N,)
        Section index per grain.
    left, right : int
        Section of the incident (and reflected) wave and of the transmitted wave.
    interface : {"half", "left", "right"}
        Attribution of the interface contact; once the waves have separated it does not
        matter (docs/physics.md §6).

    Returns
    -------
    EnergyRatios

    Notes
    -----
    The kinetic/potential split of a lattice solitary wave oscillates as it moves by one
    grain (the sum over grains of a sampled profile depends on its phase): by ~1e-12
    relative at δ0/d = 1e-3 (smooth, ~20-grain wave) but by a few per cent at δ0 = 0
    (~5-grain wave).  Averaging stacked states over one grain passage removes it; the
    total energy is unaffected (:func:`phase_averaged_ratios` does it for a space-time
    grid, with a window of many passages).
    """
    return _ratios(section_sums(incident, section, interface),
                   section_sums(final, section, interface), left, right, interface)


def table2_ratios(chain: Any, incident: Any, final: Any, *, left: int = 0, right: int = 1,
                  interface: Attribution = "half") -> EnergyRatios:
    """:func:`energy_ratios` of two snapshots (``v``, ``overlaps``) of a ``Chain``-like object.

    ``chain`` supplies ``mass``, ``k``, ``delta0`` and ``section``.
    """
    return energy_ratios(snapshot_energies(chain, incident), snapshot_energies(chain, final),
                         chain.section, left=left, right=right, interface=interface)


def energy_ratios_from_grid(
    kinetic: ArrayLike,
    potential: ArrayLike,
    section: ArrayLike,
    i_incident: int | ArrayLike,
    i_final: int | ArrayLike,
    *,
    left: int = 0,
    right: int = 1,
    w_incident: ArrayLike | None = None,
    w_final: ArrayLike | None = None,
) -> EnergyRatios:
    """Table 2 ratios from per-grain energies on a (n_times, N) space-time grid.

    Per-grain potential energies already split each grain–grain contact half to each
    grain (the recorded grid of :class:`discrete.Simulation`, and
    :attr:`ChainEnergies.potential`), so the interface contact is attributed half to
    each side; L and Q are not available (NaN).  For a grid coarsened over blocks of
    grains, pass the section of each block.

    Parameters
    ----------
    kinetic, potential : array_like, shape (n_times, N)
        Per-grain kinetic and potential (relative to static) energies, J.
    section : array_like of int, shape (N,)
        Section index per grain.
    i_incident, i_final : int or array_like of int
        Time index (or indices, averaged — see :func:`energy_ratios`) of the incident and
        of the separated state.
    left, right : int
        Sections of the incident and transmitted waves.
    w_incident, w_final : array_like of float, optional
        Weights of the rows ``i_incident``, ``i_final`` (>= 0): their section sums are
        averaged with these weights instead of equally (:func:`phase_window`).
    """
    ek = _f(kinetic, "kinetic")
    ep = _f(potential, "potential")
    if ek.shape != ep.shape or ek.ndim != 2:
        raise ValueError("kinetic and potential must be (n_times, N) arrays of equal shape")
    gw, _, ids = section_weights(section)
    if gw.shape[0] != ek.shape[1]:
        raise ValueError("section must have one entry per grain (column) of the grid")

    def sums(i: int | ArrayLike, w: ArrayLike | None) -> dict:
        i = np.atleast_1d(i)
        k, p = ek[i] @ gw, ep[i] @ gw
        if w is not None:  # a weighted mean over the rows (one row left)
            w = np.asarray(w, dtype=float)
            if w.shape != i.shape or not np.all(w >= 0) or not w.sum() > 0:
                raise ValueError("weights must be >= 0, not all 0, one per row index")
            wn = w / w.sum()
            k, p = wn @ k, wn @ p
        return {"kinetic": k, "potential": p, "total": k + p, "sections": ids}

    return _ratios(sums(i_incident, w_incident), sums(i_final, w_final), left, right,
                   "half")


_BLACKMAN_HARRIS = (0.35875, 0.48829, 0.14128, 0.01168)


def phase_window(t: ArrayLike, start: float, stop: float) -> tuple[np.ndarray, FloatArray]:
    r"""Rows in [start, stop] and their Blackman–Harris weights.

    The weight of a row at time t is the 4-term Blackman–Harris window
    w(x) = a0 - a1 cos 2πx + a2 cos 4πx - a3 cos 6πx, x = (t - start)/(stop - start)
    (Harris 1978, Proc. IEEE 66, 51, Table 1: a = 0.35875, 0.48829, 0.14128, 0.01168;
    highest side lobe -92 dB).  The weighted mean Σ w y / Σ w of y = A cos(2πft + φ)
    sampled densely over a window of length W = stop - start is off by at most
    ~2.5e-5 A once f ≥ 4/W (outside the main lobe), and by less further out; a linear
    trend of y gives the value at the window's centre.

    Parameters
    ----------
    t : array_like, shape (n_times,)
        Row times, s, increasing.
    start, stop : float
        The window, s (stop > start).

    Returns
    -------
    rows : ndarray of int
        Rows with start <= t <= stop (may be empty).
    weights : ndarray of float, same shape
    """
    t = np.asarray(t, dtype=float)
    if not stop > start:
        raise ValueError(f"window [{start!r}, {stop!r}] s: stop must be > start")
    rows = np.flatnonzero((t >= start) & (t <= stop))
    x = (t[rows] - start) / (stop - start)
    a0, a1, a2, a3 = _BLACKMAN_HARRIS
    w = a0 - a1 * np.cos(2 * np.pi * x) + a2 * np.cos(4 * np.pi * x) - a3 * np.cos(6 * np.pi * x)
    return rows, np.maximum(w, 0.0)  # (w >= 6e-5 in [0, 1]; the max only clips round-off)


def _incident_transit(kinetic: np.ndarray, potential: np.ndarray, t: np.ndarray,
                      i_incident: int, n_left: int) -> float:
    """Transit time d/V of the incident wave, s, from its energy peak's grain vs time.

    A straight-line fit of the peak's grain index (argmax of the energy over the left
    section) against time over the second half of the rows up to ``i_incident``, at
    most the last 256 (the first half may hold an impact wave still forming).  NaN if
    fewer than 4 rows or the peak does not move to the right.
    """
    lo = max(i_incident // 2, i_incident - 256)  # (256 rows: ~100 transits or more)
    if i_incident - lo < 3:
        return float("nan")
    rows = slice(lo, i_incident + 1)
    energy = kinetic[rows, :n_left] + potential[rows, :n_left]
    peak = np.argmax(energy, axis=1).astype(float)
    slope = np.polyfit(t[lo:i_incident + 1], peak, 1)[0]  # grains per second
    return float(1.0 / slope) if slope > 0 else float("nan")


def phase_averaged_ratios(
    t: ArrayLike,
    kinetic: ArrayLike,
    potential: ArrayLike,
    section: ArrayLike,
    i_incident: int,
    i_final: int,
    *,
    transit: float | None = None,
    window: float = SPLIT_WINDOW_TRANSITS,
    coarsen: int = 1,
    left: int = 0,
    right: int = 1,
) -> tuple[EnergyRatios, float]:
    r"""Table 2 ratios with the kinetic/potential split averaged over the lattice phase.

    Physics (docs/physics.md §6).  A solitary wave moving through the lattice at speed V
    is the same profile one transit time T = d/V later, shifted by one grain; in between,
    the section sums K = Σ m v²/2 and P = Σ (contact energy - static) of its sampled
    profile oscillate with period T around their means, in antiphase (K + P is conserved).
    The oscillation's amplitude at point P, δ0 = 0 (impact, v0 = 1 m/s, ~5-grain wave) is
    ~1e-2 of the incident energy for the incident and the transmitted wave, ~1e-3 for the
    reflected one; at δ0/d = 1e-3 (~20-grain wave) ~1e-12.  The split read at one row
    therefore depends on the phase of that row, which moves with dt and the row spacing:
    an rtol run cannot bound it.  The phase-free quantity is the time mean of K and P over
    whole periods; here a Blackman–Harris weighted mean (:func:`phase_window`) over
    ``window`` incident transits, ending at row ``i_incident`` (incident energies) and
    starting at row ``i_final`` (separated waves).  Every wave faster than V/4 (period
    below ``window``/4 transits) is then averaged to ≤ 2.5e-5 of its oscillation
    amplitude, provided the rows sample it: a wave whose frequency lies within 4/W of a
    multiple of the row rate aliases to ~0 and is not removed (rows half an incident
    transit apart alias a wave twice as fast as the incident one).  The total energies
    Et_* are averaged in the same window (they are constant there to the run's drift).

    Parameters
    ----------
    t : array_like, shape (n_times,)
        Row times, s.
    kinetic, potential, section, left, right
        As in :func:`energy_ratios_from_grid`.
    i_incident, i_final : int
        Rows of :func:`incident_time_index` and :func:`separated_time_index`.
    transit : float, optional
        d/V of the incident wave, s; default: fitted from the incident energy peak's
        motion over the rows before ``i_incident``.
    window : float
        Window length in transits (> 0).
    coarsen : int
        Grains per column of the grid (the fitted transit is per column).

    Returns
    -------
    ratios : EnergyRatios
    estimate : float
        Estimated error of the phase average of the kinetic and potential ratios
        (Ek_*, Ep_*; absolute, the units of the ratios): the largest change when both
        windows are shortened to 3/4 of their length about the same centres.  A
        residual or aliased oscillation changes with the window; a linear drift of the
        means (physical reshaping) does not.  NaN when the transit time cannot be found
        or a window holds fewer than 3 rows (the single rows are then used).  A window
        the grid cuts short (the run ends less than ``window`` transits after
        separation, or the wave reaches the interface sooner after t = 0) averages
        less, and the estimate says so.
    """
    t = np.asarray(t, dtype=float)
    if not window > 0:
        raise ValueError(f"window = {window!r} transits: allowed range (0, inf)")
    # (no whole-grid copies or checks here: energy_ratios_from_grid checks the rows it
    # reads, and the summary of a 5,000-row grid should not pay for it three times)
    ek, ep = np.asarray(kinetic), np.asarray(potential)
    if ek.shape != ep.shape or ek.ndim != 2 or t.shape != ek.shape[:1]:
        raise ValueError("kinetic and potential must be (n_times, N) arrays of equal "
                         "shape, t one time per row")
    if transit is None:
        sec = np.asarray(section)
        n_left = int(np.flatnonzero(sec == left)[-1]) + 1 if np.any(sec == left) else 0
        transit = _incident_transit(ek, ep, t, i_incident, n_left) / coarsen
    rows_only = ((float(t[i_incident]),) * 2, (float(t[i_final]),) * 2)
    if not (transit is not None and np.isfinite(transit) and transit > 0):
        r = energy_ratios_from_grid(ek, ep, section, i_incident, i_final, left=left,
                                    right=right)
        return replace(r, windows=rows_only), float("nan")

    # windows: [t_in - W, t_in] and [t_out, t_out + W], cut to the grid; the estimate's
    # windows have 3/4 of their length and the same centres (a linear drift of the
    # means, physical reshaping, then does not count as an error)
    w = window * transit
    spans = ((max(t[0], t[i_incident] - w), t[i_incident]),
             (t[i_final], min(t[-1], t[i_final] + w)))

    def at(shrink: float) -> EnergyRatios | None:
        sel = []
        for lo, hi in spans:
            mid, half = 0.5 * (lo + hi), 0.5 * shrink * (hi - lo)
            if not hi > lo:
                return None
            rows, wts = phase_window(t, mid - half, mid + half)
            if rows.size < 3 or not wts.sum() > 0:
                return None
            sel.append((rows, wts))
        (ri, wi), (rf, wf) = sel
        rows = np.concatenate([ri, rf])  # only the windows' rows are read
        return energy_ratios_from_grid(ek[rows], ep[rows], section, np.arange(ri.size),
                                       ri.size + np.arange(rf.size), left=left,
                                       right=right, w_incident=wi, w_final=wf)

    full, short = at(1.0), at(0.75)
    if full is None or short is None:  # fewer than 3 rows in a window: the single rows
        r = energy_ratios_from_grid(ek, ep, section, i_incident, i_final, left=left,
                                    right=right)
        return replace(r, windows=rows_only), float("nan")
    est = max(abs(getattr(full, k) - getattr(short, k))
              for k in ("Ek_tr", "Ek_re", "Ep_tr", "Ep_re"))
    return replace(full, windows=tuple((float(a), float(b)) for a, b in spans)), float(est)


def interface_activity(energy: ArrayLike, interface: int, halfwidth: int = 5, *,
                       overwrite: bool = False) -> FloatArray:
    """Fraction of the wave energy within ``halfwidth`` grains of an interface, per time.

    Σ_{|i - interface + ½| < halfwidth} |e_i| / Σ_i |e_i|, with ``interface`` the index
    of the first grain right of the interface (so grains interface - halfwidth ...
    interface + halfwidth - 1 are counted).  Absolute values, because the potential
    energy relative to static may be negative (docs/physics.md §6).

    Parameters
    ----------
    energy : array_like, shape (n_times, N)
        Per-grain energy, J (e.g. total, or kinetic + |potential|).
    interface : int
        First grain of the right section (e.g. ``n_left``).
    halfwidth : int
        Grains on each side.
    overwrite : bool
        ``energy`` is a float64 array the caller no longer needs: |e| is taken in place
        (the same values, without a second array: a 256-row block of 1,900 grains is
        3.9 MB, which would otherwise be a fresh mapping and its page faults per call).
    """
    e = _f(energy, "energy")
    if e.ndim != 2:
        raise ValueError("energy must be a (n_times, N) array")
    n = e.shape[1]
    if not 0 < interface < n or halfwidth < 1:
        raise ValueError("need 0 < interface < N and halfwidth >= 1")
    e = np.abs(e, out=e) if overwrite and e is energy else np.abs(e)
    lo, hi = max(0, interface - halfwidth), min(n, interface + halfwidth)
    tot = e.sum(axis=1)
    loc = e[:, lo:hi].sum(axis=1)
    return np.divide(loc, tot, out=np.zeros_like(tot), where=tot > 0)


def _activity(energy, interface, halfwidth, activity) -> FloatArray:
    if activity is not None:  # computed once by the caller for several fractions
        return np.asarray(activity, dtype=float)
    return interface_activity(energy, interface, halfwidth)


def incident_time_index(energy: ArrayLike | None, interface: int, *, halfwidth: int = 5,
                        fraction: float = 1e-6, activity: ArrayLike | None = None) -> int:
    """Last time index before the wave's energy near the interface exceeds ``fraction``.

    Where to measure the incident energy (docs/physics.md §6: "on the left section before the
    wave arrives").  See :func:`interface_activity`; ``activity`` is its result for
    ``energy``, ``interface`` and ``halfwidth`` if already computed (``energy`` is then
    not read).  Raises ``ValueError`` if the wave is already at the interface in the
    first row.
    """
    act = _activity(energy, interface, halfwidth, activity)
    above = np.nonzero(act > fraction)[0]
    if above.size == 0:
        return act.size - 1
    if above[0] == 0:
        raise ValueError("energy near the interface exceeds the fraction already at index 0")
    return int(above[0] - 1)


def separated_time_index(energy: ArrayLike | None, interface: int, *, halfwidth: int = 5,
                         fraction: float = 1e-6,
                         activity: ArrayLike | None = None) -> int | None:
    """First time index from which the energy near the interface stays below ``fraction``.

    "The waves have separated from the interface": after the wave has reached the
    interface, Σ|e| within ``halfwidth`` grains of it is below ``fraction`` of the chain's
    Σ|e| at this and every later time.  ``None`` if that never happens on the grid (or
    the wave never reached the interface).  ``activity``: as in
    :func:`incident_time_index`.
    """
    act = _activity(energy, interface, halfwidth, activity)
    above = np.nonzero(act > fraction)[0]
    if above.size == 0 or above[-1] == act.size - 1:
        return None
    return int(above[-1] + 1)


def normalise_to_incident_peak(
    kinetic: ArrayLike,
    potential: ArrayLike,
    *,
    incident_rows: ArrayLike | int = 0,
    grains: slice | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray, tuple[float, float, float]]:
    """Fig. 8 normalisation: e_k/e_k0, e_p/e_p0, e_t/e_t0.

    e_k0, e_p0, e_t0 are "the single grain kinetic energy, potential energy, and total
    energy at the peak of the ISW" (paper Section 4; Fig. 8 caption: "to corresponding
    maximum ones in the ISW"): the maxima over grains (``grains``, default all) of the
    incident rows (default the first row) of each kind separately.

    Parameters
    ----------
    kinetic, potential : array_like, shape (n_times, N)
        Per-grain energies, J.
    incident_rows : int or array_like of int
        Row(s) in which the incident wave is free (before the interface).
    grains : slice, optional
        Grains searched for the peak (e.g. the left section).

    Returns
    -------
    ek_n, ep_n, et_n : ndarray, shape (n_times, N)
    (e_k0, e_p0, e_t0) : tuple of float, J
    """
    ek = _f(kinetic, "kinetic")
    ep = _f(potential, "potential")
    et = ek + ep
    rows = np.atleast_1d(np.asarray(incident_rows))
    sl = slice(None) if grains is None else grains
    refs = tuple(float(np.max(a[..., sl][rows] if a.ndim == 2 else a[sl])) for a in (ek, ep, et))
    if min(refs) <= 0:
        raise ValueError(f"incident peak energies must be > 0 (got {refs})")
    return ek / refs[0], ep / refs[1], et / refs[2], refs
