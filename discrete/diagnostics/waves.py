r"""Wave analysis on snapshots and time series: pulses, fronts, speeds, 1st/2nd parts.

A *signal* is any per-grain (or per-contact) quantity of a snapshot — grain velocity v
(m/s), strain (r - δ0)/d, energy per grain — or a per-time quantity of one grain.  A
*pulse* is a local maximum of |signal| above ``threshold × reference``, bounded by the
minima of |signal| (or sign changes) on each side (Fig. 3a, 5 of the paper show such
trains).  Positions are in grain (or contact) index units; the peak position is refined
below the grid spacing by a three-point parabola through the peak sample and its two
neighbours (``"parabola"``), or through their logarithms (``"gaussian"``, exact for a
Gaussian), or by the |signal|-weighted centroid of the pulse (``"centroid"``).

Sign conventions (paper Section 4; docs/physics.md §6).  For a right-going wave u = f(x - Vt)
the particle velocity is v = V ξ with the strain ξ = -u_x; for a left-going one v = -V ξ.
So a compressive (ξ > 0) reflected (left-going) wave has negative grain velocities, as
the paper says of Fig. 3b; an expansive one positive.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..interpolation import peak_time

__all__ = [
    "Pulse",
    "find_pulses",
    "leading_pulse",
    "section_range",
    "SpeedFit",
    "fit_speed",
    "arrival_times",
    "front_positions",
    "split_parts_at_gap",
    "assign_parts_by_collisions",
]

FloatArray = NDArray[np.float64]
Interp = Literal["parabola", "gaussian", "centroid", "none"]
_EDGE = 1e-3
"""Outer pulse boundaries stop where |signal| falls below this fraction of the peak."""


@dataclass(frozen=True)
class Pulse:
    """One pulse of a signal.

    Attributes
    ----------
    index : int
        Sample (grain/contact/time index) of the peak of |signal|.
    position : float
        Refined peak position, in index units.
    amplitude : float
        Signed peak value (refined with the same interpolation, except ``"centroid"``).
    start, stop : int
        Extent: samples ``start ... stop - 1`` belong to the pulse.
    """

    index: int
    position: float
    amplitude: float
    start: int
    stop: int

    @property
    def sign(self) -> int:
        """+1 or -1, the sign of the amplitude."""
        return 1 if self.amplitude >= 0 else -1


def _parabola(y0: float, y1: float, y2: float) -> tuple[float, float]:
    """Vertex offset (in samples, |·| ≤ ½) and value of the parabola through 3 points."""
    den = y0 - 2.0 * y1 + y2
    if den == 0.0:
        return 0.0, y1
    off = float(np.clip(0.5 * (y0 - y2) / den, -0.5, 0.5))
    return off, y1 - 0.25 * (y0 - y2) * off


def _refine(s: FloatArray, i: int, start: int, stop: int, method: str,
            x: FloatArray | None = None) -> tuple[float, float]:
    """Refined (position, amplitude) of the peak at sample i (positions on grid ``x``)."""
    xs = np.arange(s.size, dtype=float) if x is None else x
    if method == "none" or i == 0 or i == s.size - 1:
        return float(xs[i]), float(s[i])
    if method == "centroid":
        w = np.abs(s[start:stop])
        return float(np.sum(w * xs[start:stop]) / np.sum(w)), float(s[i])
    y = s[i - 1:i + 2]
    sg = 1.0 if s[i] >= 0 else -1.0
    if method == "gaussian":
        if np.all(sg * y > 0):
            off, ly = _parabola(*np.log(sg * y))
            amp = sg * float(np.exp(ly))
        else:
            off, amp = _parabola(*y)
    elif method == "parabola":
        off, amp = _parabola(*y)
    else:
        raise ValueError(f"unknown interpolation {method!r}")
    # non-uniform grid: map the offset linearly onto the neighbouring interval
    pos = xs[i] + off * (xs[i + 1] - xs[i] if off > 0 else xs[i] - xs[i - 1])
    return float(pos), float(amp)


def find_pulses(
    signal: ArrayLike,
    *,
    threshold: float = 0.05,
    reference: float | None = None,
    lo: int = 0,
    hi: int | None = None,
    valley: float = 0.5,
    interpolation: Interp = "parabola",
) -> list[Pulse]:
    """Segment a signal into pulses (local maxima of |signal| separated by minima).

    Rule: every local maximum of a = |signal| in ``[lo, hi)`` (a_i ≥ a_{i-1}, a_i > a_{i+1},
    a neighbour of opposite sign counting as 0) with a_i ≥ ``threshold × reference`` is a
    candidate.  Two neighbouring candidates of
    the same sign are separate pulses only if |signal| drops between them below
    ``valley`` × the smaller peak, otherwise they are merged (the larger peak is kept);
    candidates of opposite sign are always separate.  Pulse boundaries are the minimum of
    |signal| between neighbouring pulses (or the first sign change); the outer ones are
    found by walking outward while |signal| does not increase, the sign is unchanged and
    |signal| stays above 1e-3 × the peak.

    Parameters
    ----------
    signal : array_like, shape (n,)
        E.g. grain velocities (m/s) or strain of a snapshot.
    threshold : float
        Minimum peak |signal| relative to ``reference``.
    reference : float, optional
        Reference amplitude (e.g. the incident wave's peak); default max |signal| in range.
    lo, hi : int
        Sample range searched.
    valley : float
        Depth criterion for separating same-sign peaks (0 < valley ≤ 1).
    interpolation : {"parabola", "gaussian", "centroid", "none"}
        Sub-sample refinement of the peak position.

    Returns
    -------
    list of Pulse
        Sorted by index.
    """
    s = np.asarray(signal, dtype=float)
    if s.ndim != 1 or s.size < 1:
        raise ValueError("signal must be a non-empty 1-D array")
    if not np.all(np.isfinite(s)):
        raise ValueError("signal contains NaN or inf")
    hi = s.size if hi is None else hi
    if not 0 <= lo < hi <= s.size:
        raise ValueError(f"need 0 <= lo < hi <= {s.size} (got lo={lo}, hi={hi})")
    if not 0 < valley <= 1 or threshold < 0:
        raise ValueError("need 0 < valley <= 1 and threshold >= 0")
    a = np.abs(s[lo:hi])
    ref = float(a.max()) if reference is None else abs(float(reference))
    if ref == 0.0:
        return []
    n = a.size
    sg = np.sign(s[lo:hi])
    # neighbours of the opposite sign count as 0: a sign change bounds a pulse
    left = np.concatenate([[-np.inf], np.where(sg[:-1] == sg[1:], a[:-1], 0.0)])
    right = np.concatenate([np.where(sg[1:] == sg[:-1], a[1:], 0.0), [-np.inf]])
    cand = np.nonzero((a >= left) & (a > right) & (a >= threshold * ref) & (a > 0))[0]
    peaks: list[int] = []
    for c in cand:
        if peaks:
            p = peaks[-1]
            if sg[p] == sg[c] and np.all(sg[p:c + 1] == sg[p]) and \
                    a[p:c + 1].min() > valley * min(a[p], a[c]):
                if a[c] > a[p]:
                    peaks[-1] = c
                continue
        peaks.append(int(c))
    out = []
    for m, p in enumerate(peaks):
        # left boundary
        if m > 0:
            q = peaks[m - 1]
            flips = np.nonzero(sg[q:p + 1] != sg[p])[0]
            start = q + flips[-1] + 1 if flips.size else q + 1 + int(np.argmin(a[q + 1:p]))
        else:
            start = p
            while (start > 0 and sg[start - 1] == sg[p] and a[start - 1] <= a[start]
                   and a[start - 1] > _EDGE * a[p]):
                start -= 1
        if m + 1 < len(peaks):
            q = peaks[m + 1]
            flips = np.nonzero(sg[p:q + 1] != sg[p])[0]
            stop = p + flips[0] if flips.size else p + 1 + int(np.argmin(a[p + 1:q]))
        else:
            stop = p + 1
            while (stop < n and sg[stop] == sg[p] and a[stop] <= a[stop - 1]
                   and a[stop] > _EDGE * a[p]):
                stop += 1
        stop = max(stop, p + 1)
        start = min(start, p)
        pos, amp = _refine(s, p + lo, start + lo, stop + lo, interpolation)
        out.append(Pulse(index=int(p + lo), position=pos, amplitude=amp,
                         start=int(start + lo), stop=int(stop + lo)))
    return out


def leading_pulse(
    signal: ArrayLike,
    *,
    direction: int = 1,
    threshold: float = 0.1,
    reference: float | None = None,
    lo: int = 0,
    hi: int | None = None,
    sign: int | None = None,
    valley: float = 0.5,
    interpolation: Interp = "parabola",
) -> Pulse | None:
    """The front pulse of a wave travelling in ``direction`` (+1 right, -1 left).

    The right-most (``direction=+1``, transmitted wave) or left-most (``-1``, reflected
    wave) pulse of :func:`find_pulses` in ``[lo, hi)`` whose |peak| is at least
    ``threshold × reference`` (default reference: max |signal| in the range) and, if
    ``sign`` is given, of that sign.  ``None`` if there is none.
    """
    if direction not in (1, -1):
        raise ValueError("direction must be +1 or -1")
    pulses = find_pulses(signal, threshold=threshold, reference=reference, lo=lo, hi=hi,
                         valley=valley, interpolation=interpolation)
    if sign is not None:
        pulses = [p for p in pulses if p.sign == sign]
    if not pulses:
        return None
    return pulses[-1] if direction == 1 else pulses[0]


def section_range(section: ArrayLike, which: int) -> tuple[int, int]:
    """(lo, hi) grain range of section ``which`` (must be contiguous)."""
    sec = np.asarray(section)
    idx = np.nonzero(sec == which)[0]
    if idx.size == 0:
        raise ValueError(f"no grain in section {which}")
    if idx[-1] - idx[0] + 1 != idx.size:
        raise ValueError(f"section {which} is not contiguous")
    return int(idx[0]), int(idx[-1] + 1)


@dataclass(frozen=True)
class SpeedFit:
    """Least-squares straight line position = x0 + speed × t.

    Attributes
    ----------
    speed : float
        Slope, in position units (grains) per time unit (s).
    speed_error : float
        Standard error of the slope (NaN for two points).
    intercept : float
        Position at t = 0.
    residual_rms : float
        Root-mean-square residual of the positions, grains.
    n : int
        Points used.
    """

    speed: float
    speed_error: float
    intercept: float
    residual_rms: float
    n: int

    def in_m_per_s(self, diameter: float) -> float:
        """Speed in m/s for grains of ``diameter`` m (lattice spacing = diameter)."""
        return self.speed * float(diameter)

    def reduced(self, diameter: float, c0: float) -> float:
        """V/c0, the quantity of the paper's Fig. 6 (c0 = c0^L in m/s, :func:`theory.c0`)."""
        return self.speed * float(diameter) / float(c0)


def fit_speed(positions: ArrayLike, times: ArrayLike) -> SpeedFit:
    """Front speed from positions (grains) at times (s): least-squares slope.

    Use it with front positions of several snapshots (:func:`front_positions`) or with
    arrival times (:func:`arrival_times`: positions = grain indices, times = arrivals).
    NaN entries are dropped; at least two points are needed.
    """
    x = np.asarray(positions, dtype=float).ravel()
    t = np.asarray(times, dtype=float).ravel()
    if x.shape != t.shape:
        raise ValueError("positions and times must have the same length")
    ok = np.isfinite(x) & np.isfinite(t)
    x, t = x[ok], t[ok]
    if x.size < 2 or np.ptp(t) == 0:
        raise ValueError("need at least two points at distinct times")
    tm, xm = t.mean(), x.mean()
    stt = np.sum((t - tm) ** 2)
    slope = float(np.sum((t - tm) * (x - xm)) / stt)
    icpt = float(xm - slope * tm)
    res = x - (icpt + slope * t)
    rms = float(np.sqrt(np.mean(res**2)))
    err = float(np.sqrt(np.sum(res**2) / (x.size - 2) / stt)) if x.size > 2 else float("nan")
    return SpeedFit(speed=slope, speed_error=err, intercept=icpt, residual_rms=rms, n=int(x.size))


def arrival_times(
    t: ArrayLike,
    series: ArrayLike,
    *,
    threshold: float = 0.5,
    reference: float | ArrayLike | None = None,
    sign: int | None = None,
    interpolation: Interp | Literal["hermite"] = "parabola",
    derivative: ArrayLike | None = None,
) -> FloatArray:
    """Time at which the leading pulse's peak passes each recorded grain.

    For each column (grain) of ``series``, the first pulse in time (:func:`find_pulses`
    on the time series) with |peak| ≥ ``threshold × reference`` (default reference: the
    column's own max |signal|) and, if given, of sign ``sign``; its peak time refined by
    a three-point parabola in time.  Feed the result to :func:`fit_speed` with the grain
    indices to get the front speed (Fig. 6).

    Parameters
    ----------
    t : array_like, shape (n_t,)
        Sample times, s (increasing).
    series : array_like, shape (n_t, n_grains)
        Signal of the recorded grains (e.g. velocity, m/s).
    threshold : float
        Relative amplitude of the pulse to be timed.
    reference : float or array_like of shape (n_grains,), optional
        Reference amplitude(s).
    sign : int, optional
        Only pulses of this sign.
    interpolation : {"parabola", "gaussian", "none", "hermite"}
        Sub-sample refinement; ``"hermite"``: the maximum of the cubic Hermite
        interpolant from the samples and their time derivatives (``derivative``, e.g.
        the grains' accelerations for a velocity series; :mod:`discrete.interpolation`),
        accurate to O(Δt³) in time instead of the parabola's O(Δt²).
    derivative : array_like, shape (n_t, n_grains), optional
        Time derivative of ``series`` (needed by ``"hermite"``).

    Returns
    -------
    ndarray, shape (n_grains,)
        Arrival times, s (NaN where no such pulse).
    """
    tt = np.asarray(t, dtype=float)
    y = np.asarray(series, dtype=float)
    if y.ndim == 1:
        y = y[:, None]
    if y.shape[0] != tt.size or tt.ndim != 1 or np.any(np.diff(tt) <= 0):
        raise ValueError("t must be increasing with one entry per row of series")
    refs = (np.abs(y).max(axis=0) if reference is None
            else np.broadcast_to(np.abs(np.asarray(reference, dtype=float)), (y.shape[1],)))
    dy = None
    if interpolation == "hermite":
        if derivative is None:
            raise ValueError("interpolation='hermite' needs derivative (the time derivative "
                             "of series, same shape)")
        dy = np.asarray(derivative, dtype=float).reshape(y.shape)
    out = np.full(y.shape[1], np.nan)
    for g in range(y.shape[1]):
        if refs[g] == 0:
            continue
        pulses = find_pulses(y[:, g], threshold=threshold, reference=refs[g],
                             interpolation="none")
        if sign is not None:
            pulses = [p for p in pulses if p.sign == sign]
        if pulses:
            p = pulses[0]
            if interpolation == "hermite":
                sl = slice(max(p.start, p.index - 1), min(p.stop, p.index + 2))
                sgn = -1.0 if y[p.index, g] < 0 else 1.0  # a negative pulse: its minimum
                out[g] = peak_time(tt[sl], sgn * y[sl, g], sgn * dy[sl, g])[0]
            else:
                out[g] = _refine(y[:, g], p.index, p.start, p.stop, interpolation, tt)[0]
    return out


def front_positions(
    signals: ArrayLike,
    *,
    direction: int = 1,
    threshold: float = 0.1,
    reference: float | None = None,
    lo: int = 0,
    hi: int | None = None,
    sign: int | None = None,
    interpolation: Interp = "parabola",
) -> tuple[FloatArray, FloatArray]:
    """Position (grains) and amplitude of the leading pulse in each of several snapshots.

    Applies :func:`leading_pulse` to each row of ``signals`` (n_snapshots, N); NaN where
    no pulse is found.  With the snapshot times, :func:`fit_speed` gives the front speed.
    """
    sig = np.asarray(signals, dtype=float)
    if sig.ndim != 2:
        raise ValueError("signals must be (n_snapshots, N)")
    pos = np.full(sig.shape[0], np.nan)
    amp = np.full(sig.shape[0], np.nan)
    for i, row in enumerate(sig):
        p = leading_pulse(row, direction=direction, threshold=threshold, reference=reference,
                          lo=lo, hi=hi, sign=sign, interpolation=interpolation)
        if p is not None:
            pos[i], amp[i] = p.position, p.amplitude
    return pos, amp


def split_parts_at_gap(pulses: list[Pulse], direction: int = 1
                       ) -> tuple[list[Pulse], list[Pulse]]:
    """Split a pulse train into the paper's 1st and 2nd parts at its largest gap.

    Operational rule for the "1st" and "2nd" parts of Figs. 3a/4a (the paper defines them
    by the successive collisions at the interface, which emit successive groups of pulses
    that then drift apart): order the pulses from the front (``direction=+1``: right-most
    first; ``-1``: left-most first) and cut at the largest distance between consecutive
    peak positions.  Use :func:`assign_parts_by_collisions` for the collision-based
    definition when the interface contact's time series is available.

    Returns
    -------
    first, second : list of Pulse
        Front part and the rest (``second`` empty for fewer than two pulses).
    """
    if direction not in (1, -1):
        raise ValueError("direction must be +1 or -1")
    ordered = sorted(pulses, key=lambda p: -direction * p.position)
    if len(ordered) < 2:
        return ordered, []
    gaps = np.abs(np.diff([p.position for p in ordered]))
    cut = int(np.argmax(gaps)) + 1
    return ordered[:cut], ordered[cut:]


def assign_parts_by_collisions(pulse_times: ArrayLike, collision_times: ArrayLike,
                               *, delay: float = 0.0) -> NDArray[np.int64]:
    """Number the collision that produced each pulse (1 = "1st", 2 = "2nd", ...).

    The paper (Section 4, Fig. 3c, 4c) attributes the 1st and 2nd parts of the transmitted
    and reflected waves to the first and second collisions at the interface (the gap
    between grains 399/400, or 199/200, in its 1-based numbering — contact N_L - 1 here —
    closing again).  Given the times at which that contact closes (``closings`` of
    :func:`discrete.diagnostics.gap_events`, which include the first closure when the
    contact starts open, as at δ0 = 0) and the time each pulse passed a reference grain
    (e.g. peak times from :func:`find_pulses` on the grain's velocity series), a pulse
    belongs to the last collision that started before ``pulse_time - delay`` (``delay``:
    travel time from the contact to the reference grain, s).  0 means before any
    collision.

    This collision rule and the largest-gap rule of :func:`split_parts_at_gap` need not
    agree: in the heavy–light case of Fig. 3a (δ0 = 0, α_ρ = 0.2) the first collision
    emits the four largest pulses (peaks 1.19, 0.66, 0.38, 0.22 × v0 of the incident
    wave) and the second the weaker rest, while the largest gap of a later snapshot lies
    between the front pulse and the others — the paper's description of Fig. 3a ("a
    leading front wave with large amplitude and a train of isolated TWs").
    """
    pt = np.asarray(pulse_times, dtype=float)
    ct = np.sort(np.asarray(collision_times, dtype=float).ravel())
    return np.searchsorted(ct, pt - delay, side="right").astype(np.int64)
