r"""Fig. 2: the settled solitary-wave amplitude from per-grain running maxima of velocity.

The paper (Section 2, Fig. 2) gives a velocity v0 to the first grain and records, for
every grain, the maximum velocity reached "when solitary wave passes by"; its average
over the grains where the wave has formed is v̄max, with v̄max/v0 = 0.6816 at δ0 = 0 and
0.0822 at δ0/d = 1e-3 (the latter needs ~6,000–9,000 grains to settle, docs/physics.md §1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["PlateauStats", "choose_plateau_range", "vmax_plateau"]


@dataclass(frozen=True)
class PlateauStats:
    """Mean v_max/v0 over a grain range and how flat it is there.

    Attributes
    ----------
    mean : float
        Mean of v_max/v0 over grains ``start ... stop - 1`` (the paper's v̄max/v0).
    std : float
        Standard deviation of v_max/v0 over the range.
    slope_per_1000 : float
        Least-squares slope of v_max/v0 per 1000 grains (trend; → 0 when converged).
    first_half, second_half : float
        Means over the two halves of the range (their difference shows the trend).
    start, stop : int
        Grain range used.
    settled : bool
        Whether the automatic range criterion (see :func:`choose_plateau_range`) was met
        over at least ``min_length`` grains (True when the range was given).
    """

    mean: float
    std: float
    slope_per_1000: float
    first_half: float
    second_half: float
    start: int
    stop: int
    settled: bool

    @property
    def n(self) -> int:
        """Number of grains averaged."""
        return self.stop - self.start


def choose_plateau_range(vmax: ArrayLike, *, rtol: float = 2e-3, margin: int = 10,
                         min_length: int = 20, reached: float = 1e-3) -> tuple[int, int, bool]:
    """Grain range over which the leading wave's v_max has settled.

    * ``stop``: the last grain the wave has reached (v_max > ``reached`` × max v_max)
      minus ``margin`` grains (the last grains are still being overtaken, or feel the
      wall);
    * the settled value f is the median of v_max over the last ``min_length`` grains
      before ``stop``;
    * ``start``: the first grain from which every v_max up to ``stop`` lies within
      ``rtol`` (relative) of f — skips the formation region after the impact.

    Returns
    -------
    start, stop : int
    settled : bool
        False if fewer than ``min_length`` grains satisfy the criterion (the range is then
        the last ``min_length`` grains before ``stop``).
    """
    a = np.asarray(vmax, dtype=float)
    if a.ndim != 1 or a.size < 3 or not np.all(np.isfinite(a)):
        raise ValueError("vmax must be a finite 1-D array with at least 3 grains")
    if rtol <= 0 or margin < 0 or min_length < 2:
        raise ValueError("need rtol > 0, margin >= 0, min_length >= 2")
    peak = np.abs(a).max()
    if peak == 0:
        raise ValueError("vmax is zero everywhere")
    hit = np.nonzero(np.abs(a) > reached * peak)[0]
    stop = int(hit[-1]) + 1 - margin
    if stop < min_length:
        raise ValueError(f"the wave has reached only {hit[-1] + 1} grains; need more than "
                         f"margin + min_length = {margin + min_length}")
    f = float(np.median(a[stop - min_length:stop]))
    bad = np.nonzero(np.abs(a[:stop] - f) > rtol * abs(f))[0]
    start = int(bad[-1]) + 1 if bad.size else 0
    if stop - start < min_length:
        return stop - min_length, stop, False
    return start, stop, True


def vmax_plateau(vmax: ArrayLike, v0: float = 1.0, *, start: int | None = None,
                 stop: int | None = None, rtol: float = 2e-3, margin: int = 10,
                 min_length: int = 20) -> PlateauStats:
    """The paper's v̄max/v0 (Fig. 2) with its spread and trend.

    Parameters
    ----------
    vmax : array_like, shape (N,)
        Per-grain running maximum of the velocity, m/s.
    v0 : float
        Impact velocity, m/s.
    start, stop : int, optional
        Grain range; chosen by :func:`choose_plateau_range` if either is None.
    rtol, margin, min_length
        Parameters of :func:`choose_plateau_range`.

    Returns
    -------
    PlateauStats
    """
    a = np.asarray(vmax, dtype=float) / float(v0)
    settled = True
    if start is None or stop is None:
        s0, s1, settled = choose_plateau_range(a, rtol=rtol, margin=margin,
                                               min_length=min_length)
        start = s0 if start is None else start
        stop = s1 if stop is None else stop
    if not 0 <= start < stop <= a.size or stop - start < 2:
        raise ValueError(f"bad grain range [{start}, {stop}) for {a.size} grains")
    seg = a[start:stop]
    x = np.arange(start, stop, dtype=float)
    slope = float(np.polyfit(x, seg, 1)[0]) if seg.size > 2 else float("nan")
    h = seg.size // 2
    return PlateauStats(mean=float(seg.mean()), std=float(seg.std()),
                        slope_per_1000=1000.0 * slope, first_half=float(seg[:h].mean()),
                        second_half=float(seg[h:].mean()), start=int(start), stop=int(stop),
                        settled=settled)
