"""Small numerical kernels shared by the closed forms of :mod:`theory`."""

from __future__ import annotations

import numpy as np

__all__ = ["power_remainder"]


def power_remainder(w, p: float):
    """(1 + w)_+^p - 1 - p w, without the cancellation of the direct difference.

    The second-order remainder of the binomial expansion, which the precompressed
    solitary waves are made of: the nonlinear part of the force (p = n) and of the
    elastic energy (p = n + 1) about the static overlap.  For |w| <= 1/4 the binomial
    series Σ_{j>=2} C(p, j) w^j (each term at most a quarter of the one before, summed
    to 1e-17 of the sum; exact polynomials for integer p), beyond it
    expm1(p log1p(w)) - p w (relative error ≲ 1e-15/(p - 1) there); for w < -1 (the
    base clipped at 0) -1 - p w.

    Parameters
    ----------
    w : array_like
        Relative change of the base.
    p : float
        Exponent, > 1.
    """
    w = np.asarray(w, dtype=float)
    small = np.abs(w) <= 0.25
    ws = np.where(small, w, 0.0)
    term = 0.5 * p * (p - 1.0) * ws * ws
    series, j = term.copy(), 2
    while np.any(np.abs(term) > 1e-17 * np.abs(series)) and j < 200:
        term = term * ws * ((p - j) / (j + 1.0))
        series += term
        j += 1
    wc = np.maximum(w, -1.0)
    with np.errstate(divide="ignore"):
        direct = np.expm1(p * np.log1p(wc)) - p * wc  # wc = -1: exactly p - 1
    return np.where(small, series, np.where(w >= -1.0, direct, -1.0 - p * w))
