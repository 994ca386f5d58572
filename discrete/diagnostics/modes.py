r"""Grain motion modes and contact gaps from time series (paper Fig. 3c/d, 4c/d).

The paper (Section 4) reads the displacement–time curves of grains near the interface:

* **contact-move** — the grain is in contact with a neighbour (some contact overlap
  r > 0 carries force) and moves;
* **free-flight** — both contacts are open (r ≤ 0, no force), so the grain moves at a
  constant velocity: a straight inclined line in u(t);
* **static** — the grain is at rest (horizontal line).

A contact is *open* when its overlap r ≤ ``open_tol`` (m; 0 by default): for δ0 = 0 this
is the overlap crossing 0, under precompression the overlap dropping to 0 from δ0 (a gap
opening against the static load).  Forward/backward motion is the sign of the velocity.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "STATIC",
    "CONTACT_MOVE",
    "FREE_FLIGHT",
    "MODE_NAMES",
    "ModeSegment",
    "GrainModes",
    "grain_modes",
    "GapEvents",
    "gap_events",
]

FloatArray = NDArray[np.float64]
STATIC, CONTACT_MOVE, FREE_FLIGHT = 0, 1, 2
MODE_NAMES = {STATIC: "static", CONTACT_MOVE: "contact-move", FREE_FLIGHT: "free-flight"}


@dataclass(frozen=True)
class ModeSegment:
    """A maximal run of samples in one mode.

    Attributes
    ----------
    mode : str
        ``"static"``, ``"contact-move"`` or ``"free-flight"``.
    start, stop : float
        Time of the first and last sample of the run, s.
    i_start, i_stop : int
        Sample range ``i_start ... i_stop - 1``.
    mean_velocity : float
        Mean velocity over the run, m/s (sign: forward > 0, backward < 0).
    """

    mode: str
    start: float
    stop: float
    i_start: int
    i_stop: int
    mean_velocity: float

    @property
    def direction(self) -> str:
        """``"forward"``, ``"backward"`` or ``"none"`` (static)."""
        if self.mode == "static":
            return "none"
        return "forward" if self.mean_velocity > 0 else "backward"


@dataclass(frozen=True, eq=False)
class GrainModes:
    """Mode of one grain at every sample, and the runs of equal mode.

    Attributes
    ----------
    codes : ndarray of int, shape (n_t,)
        :data:`STATIC` (0), :data:`CONTACT_MOVE` (1) or :data:`FREE_FLIGHT` (2).
    segments : list of ModeSegment
        Runs of equal mode, in time order.
    v_tol, a_tol : float
        Velocity (m/s) and acceleration (m/s²) tolerances used for "static".
    """

    codes: NDArray[np.int64]
    segments: list[ModeSegment]
    v_tol: float
    a_tol: float

    def sequence(self) -> list[str]:
        """The mode names of the segments, e.g. ``["static", "contact-move", "static"]``."""
        return [s.mode for s in self.segments]


def _segments(codes: NDArray[np.int64], t: FloatArray, v: FloatArray) -> list[ModeSegment]:
    cuts = np.nonzero(np.diff(codes))[0] + 1
    bounds = np.concatenate([[0], cuts, [codes.size]])
    return [ModeSegment(MODE_NAMES[int(codes[a])], float(t[a]), float(t[b - 1]), int(a), int(b),
                        float(v[a:b].mean())) for a, b in zip(bounds[:-1], bounds[1:], strict=True)]


def grain_modes(
    t: ArrayLike,
    u: ArrayLike,
    overlap_left: ArrayLike,
    overlap_right: ArrayLike,
    *,
    v: ArrayLike | None = None,
    v_tol: float | None = None,
    a_tol: float | None = None,
    open_tol: float = 0.0,
    min_samples: int = 1,
) -> GrainModes:
    """Classify each sample of a grain's motion as static, contact-move or free-flight.

    Rule per sample: **static** if |v| ≤ ``v_tol`` and |a| ≤ ``a_tol`` (the acceleration
    test keeps the turning point of a contact-move, where v = 0 but a ≠ 0, out of
    "static"); else **free-flight** if both contacts are open (r ≤ ``open_tol``); else
    **contact-move**.  Runs shorter than ``min_samples`` samples are absorbed into the
    preceding run.

    Parameters
    ----------
    t : array_like, shape (n_t,)
        Times, s (increasing).
    u : array_like, shape (n_t,)
        Displacement of the grain, m.
    overlap_left, overlap_right : array_like, shape (n_t,)
        Overlaps of the grain's two contacts, m (walls included; for a free end pass an
        array of zeros, i.e. an always-open contact).
    v : array_like, shape (n_t,), optional
        Velocity, m/s; default ``np.gradient(u, t)``.
    v_tol : float, optional
        Velocity below which the grain may be static, m/s; default 1e-3 × max |v|.
    a_tol : float, optional
        Acceleration below which the grain may be static, m/s²; default 1e-3 × max |a|,
        with a = ``np.gradient(v, t)``.
    open_tol : float
        A contact is open when its overlap is ≤ this, m.
    min_samples : int
        Minimum run length (>= 1).

    Returns
    -------
    GrainModes
    """
    tt = np.asarray(t, dtype=float)
    uu = np.asarray(u, dtype=float)
    rl = np.asarray(overlap_left, dtype=float)
    rr = np.asarray(overlap_right, dtype=float)
    if tt.ndim != 1 or tt.size < 3 or np.any(np.diff(tt) <= 0):
        raise ValueError("t must be increasing with at least 3 samples")
    if not (uu.shape == rl.shape == rr.shape == tt.shape):
        raise ValueError("t, u, overlap_left, overlap_right must have the same shape")
    vv = np.gradient(uu, tt) if v is None else np.asarray(v, dtype=float)
    if vv.shape != tt.shape:
        raise ValueError("v must have the shape of t")
    aa = np.gradient(vv, tt)
    vmax, amax = float(np.abs(vv).max()), float(np.abs(aa).max())
    v_tol = 1e-3 * vmax if v_tol is None else float(v_tol)
    a_tol = 1e-3 * amax if a_tol is None else float(a_tol)
    static = (np.abs(vv) <= v_tol) & (np.abs(aa) <= a_tol)
    free = (rl <= open_tol) & (rr <= open_tol)
    codes = np.where(static, STATIC, np.where(free, FREE_FLIGHT, CONTACT_MOVE)).astype(np.int64)
    if min_samples > 1:
        changed = True
        while changed:
            changed = False
            for seg in _segments(codes, tt, vv)[1:]:
                if seg.i_stop - seg.i_start < min_samples:
                    codes[seg.i_start:seg.i_stop] = codes[seg.i_start - 1]
                    changed = True
                    break
    return GrainModes(codes=codes, segments=_segments(codes, tt, vv), v_tol=v_tol, a_tol=a_tol)


@dataclass(frozen=True, eq=False)
class GapEvents:
    """Openings and closings of one contact.

    Attributes
    ----------
    openings, closings : ndarray
        Times at which the contact opens (r drops to ≤ threshold) and closes again, s,
        linearly interpolated between samples.
    initially_open : bool
        Whether the contact is open at the first sample.
    intervals : list of (float, float)
        Open intervals (t_open, t_close); t_open = t[0] if initially open, t_close = inf if
        still open at the end.
    """

    openings: FloatArray
    closings: FloatArray
    initially_open: bool
    intervals: list[tuple[float, float]]

    @property
    def n_gaps(self) -> int:
        """Number of open intervals."""
        return len(self.intervals)


def _crossings(t: FloatArray, y: FloatArray, idx: NDArray[np.int64]) -> FloatArray:
    """Zero crossing times of y between samples idx and idx + 1 (linear interpolation)."""
    y0, y1 = y[idx], y[idx + 1]
    frac = np.where(y1 != y0, y0 / np.where(y1 != y0, y0 - y1, 1.0), 0.0)
    return t[idx] + frac * (t[idx + 1] - t[idx])


def gap_events(t: ArrayLike, overlap: ArrayLike, *, threshold: float = 0.0) -> GapEvents:
    """Gap opening and closing times of a contact (paper Fig. 3c/d: "separation gap").

    A contact is open while its overlap r ≤ ``threshold`` (m; 0: no force), for δ0 = 0
    and under precompression alike.

    Parameters
    ----------
    t : array_like, shape (n_t,)
        Times, s (increasing).
    overlap : array_like, shape (n_t,)
        Overlap r(t) of the contact, m.
    threshold : float
        Overlap at or below which the contact is open, m.
    """
    tt = np.asarray(t, dtype=float)
    r = np.asarray(overlap, dtype=float)
    if tt.ndim != 1 or r.shape != tt.shape or tt.size < 2 or np.any(np.diff(tt) <= 0):
        raise ValueError("t must be increasing and overlap must have the shape of t")
    y = r - float(threshold)
    op = y <= 0
    ch = np.nonzero(op[1:] != op[:-1])[0]
    opening_idx = ch[op[ch + 1]]
    closing_idx = ch[~op[ch + 1]]
    openings = _crossings(tt, y, opening_idx)
    closings = _crossings(tt, y, closing_idx)
    starts = list(openings)
    if op[0]:
        starts = [float(tt[0])] + starts
    ends = list(closings) + ([float("inf")] if op[-1] else [])
    return GapEvents(openings=openings, closings=closings, initially_open=bool(op[0]),
                     intervals=[(float(a), float(b)) for a, b in zip(starts, ends, strict=True)])
