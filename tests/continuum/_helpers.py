"""Shared helpers for the continuum tests (peak tracking, shape comparison)."""

import numpy as np
from scipy.optimize import minimize_scalar


def peak_position(x, f):
    """Position of the maximum of samples f(x), by a parabola through three points."""
    i = int(np.argmax(f))
    a, b, c = f[i - 1], f[i], f[i + 1]
    return x[i] + 0.5 * (x[1] - x[0]) * (a - c) / (a - 2 * b + c)


def shape_change(x, f, profile, guess, window=None):
    """min over shifts X of ||f - profile(x - X)|| / ||profile(x - X)|| (optionally windowed).

    ``profile`` is a callable of the distance from the wave centre; ``window`` limits the
    norm to |x - X| <= window.
    """
    def err(xc):
        ref = profile(x - xc)
        m = np.ones_like(x, bool) if window is None else np.abs(x - xc) <= window
        return np.linalg.norm((f - ref)[m]) / np.linalg.norm(ref[m])

    res = minimize_scalar(err, bounds=(guess - 1.0, guess + 1.0), method="bounded",
                          options={"xatol": 1e-6})
    return float(res.fun), float(res.x)
