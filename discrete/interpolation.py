r"""Between steps: the cubic Hermite interpolant of a sampled quantity and its maximum.

A quantity y known at two step ends with its time derivative — u with v, v with a —
is interpolated on [t_n, t_n + h] by the cubic Hermite polynomial

.. math::
    p(s) = h_{00}(s)\,y_0 + h_{10}(s)\,h\,\dot y_0 + h_{01}(s)\,y_1 + h_{11}(s)\,h\,\dot y_1,
    \qquad s = (t - t_n)/h \in [0, 1],

:math:`h_{00} = 2s^3 - 3s^2 + 1`, :math:`h_{10} = s^3 - 2s^2 + s`,
:math:`h_{01} = -2s^3 + 3s^2`, :math:`h_{11} = s^3 - s^2`, which is exact for cubics, so
its error is :math:`O(h^4)` for a smooth y (given exact end values and derivatives): a
recorded maximum or arrival time taken from it carries the integrator's error, not a
per-step sampling error (:math:`O(h^2)` for "the largest sample").  Its maximum solves
:math:`p'(s) = A s^2 + B s + C = 0` with

.. math::
    A = 6(y_0 - y_1) + 3h(\dot y_0 + \dot y_1),\quad
    B = 6(y_1 - y_0) - h(4\dot y_0 + 2\dot y_1),\quad C = h\dot y_0 .

This is the one interpolation of the package: :func:`hermite_max` is compiled (for the
kernels' running maxima), :func:`hermite_max_np` is its NumPy twin (for the analysis of
recorded series: :func:`discrete.diagnostics.arrival_times` with
``interpolation="hermite"``, :mod:`discrete.waves`).
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["hermite_value", "hermite_max", "hermite_max_from", "hermite_max_np", "peak_time"]


@numba.njit(inline="always", nogil=True, error_model="numpy")
def hermite_value(s, h, y0, y1, d0, d1):
    """p(s) of the cubic Hermite interpolant (module docstring); s in [0, 1], h the step."""
    s2 = s * s
    s3 = s2 * s
    return ((2.0 * s3 - 3.0 * s2 + 1.0) * y0 + (s3 - 2.0 * s2 + s) * h * d0
            + (3.0 * s2 - 2.0 * s3) * y1 + (s3 - s2) * h * d1)


@numba.njit(inline="always", nogil=True, error_model="numpy")
def hermite_max(h, y0, y1, d0, d1):
    """(s, p(s)): the maximum of the cubic Hermite interpolant on s ∈ [0, 1].

    Endpoints included; interior stationary points with p'' < 0 from the quadratic
    p'(s) = 0 (module docstring), solved without cancellation.
    """
    return hermite_max_from(h, y0, y1, d0, d1, 0.0)


@numba.njit(inline="always", nogil=True, error_model="numpy")
def hermite_max_from(h, y0, y1, d0, d1, s_lo):
    r"""(s, p(s)): the largest of y0, y1 and the local maxima of p on (s_lo, 1), s_lo <= 0.

    With ``s_lo = -1`` the interpolant of [t_n, t_n + h] is also searched one step
    back, on [t_n - h, t_n]: a maximum that lies in the step before the data's first
    end (the kernels' running maxima, when a grain's velocity first exceeds its old
    maximum after its peak: :mod:`discrete.kernels`).  There
    :math:`v - p = \tfrac{h^4}{24} v^{(4)}(\xi)\, s^2 (s-1)^2`, at most
    :math:`h^4 |v^{(4)}|/6` at s = -1 (64 times the largest error inside the interval,
    :math:`h^4 |v^{(4)}|/384` at s = 1/2): still the integrator's fourth order.  p(s_lo) itself
    is not a candidate (an extrapolated value, not a datum).
    """
    best_s = 0.0
    best = y0
    if y1 > best:
        best_s = 1.0
        best = y1
    a = 6.0 * (y0 - y1) + 3.0 * h * (d0 + d1)
    b = 6.0 * (y1 - y0) - h * (4.0 * d0 + 2.0 * d1)
    c = h * d0
    r1 = -2.0
    r2 = -2.0
    if a == 0.0:
        if b != 0.0:
            r1 = -c / b
    else:
        disc = b * b - 4.0 * a * c
        if disc >= 0.0:
            q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
            r1 = q / a
            if q != 0.0:
                r2 = c / q
    for r in (r1, r2):
        if s_lo < r < 1.0 and r != 0.0 and 2.0 * a * r + b < 0.0:
            val = hermite_value(r, h, y0, y1, d0, d1)
            if val > best:
                best_s = r
                best = val
    return best_s, best


@numba.njit(nogil=True, error_model="numpy", cache=True)
def _hermite_max_arrays(h, y0, y1, d0, d1, s_out, y_out):
    for i in range(y0.size):
        s, y = hermite_max(h[i], y0[i], y1[i], d0[i], d1[i])
        s_out[i] = s
        y_out[i] = y


def hermite_max_np(h, y0, y1, d0, d1) -> tuple[np.ndarray, np.ndarray]:
    """:func:`hermite_max` on arrays (broadcast): (s, maximum) arrays."""
    h, y0, y1, d0, d1 = (np.ascontiguousarray(x, dtype=float).ravel() for x in
                         np.broadcast_arrays(h, y0, y1, d0, d1))
    s = np.empty(y0.size)
    y = np.empty(y0.size)
    _hermite_max_arrays(h, y0, y1, d0, d1, s, y)
    return s, y


def peak_time(t, y, dy) -> tuple[float, float]:
    """Time and value of the maximum of a sampled y(t) with its derivative dy(t).

    The largest sample i, then the cubic Hermite maxima on [t_{i-1}, t_i] and
    [t_i, t_{i+1}] (module docstring): the larger one.  t increasing, s.
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    dy = np.asarray(dy, dtype=float)
    i = int(np.argmax(y))
    best = (float(t[i]), float(y[i]))
    for j in (i - 1, i):
        if 0 <= j and j + 1 < t.size:
            h = t[j + 1] - t[j]
            s, val = hermite_max(h, y[j], y[j + 1], dy[j], dy[j + 1])
            if val > best[1]:
                best = (float(t[j] + s * h), float(val))
    return best
