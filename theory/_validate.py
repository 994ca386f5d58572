"""Input validation shared by the public functions of :mod:`theory`.

Every check raises :class:`ValueError` naming the parameter, the offending value
and the allowed range, so that a user sees at once what to change.
"""

from __future__ import annotations

import numpy as np

__all__ = ["check_finite", "check_positive", "check_range", "check_nonnegative", "check_exponent",
           "check_array"]


def _describe(value) -> str:
    arr = np.asarray(value)
    if arr.ndim == 0:
        return repr(arr.item())
    return f"array with min {np.nanmin(arr)!r}, max {np.nanmax(arr)!r}"


def check_finite(name: str, value) -> np.ndarray:
    """Return ``value`` as an array, raising if any element is NaN or infinite."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a real number (got {value!r})") from exc
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (got {_describe(arr)}); allowed: finite reals")
    return arr


def check_positive(name: str, value) -> np.ndarray:
    """Return ``value`` as an array, raising unless every element is finite and > 0."""
    arr = check_finite(name, value)
    if np.any(arr <= 0):
        raise ValueError(f"{name} must be > 0 (got {_describe(arr)}); allowed range: (0, inf)")
    return arr


def check_nonnegative(name: str, value) -> np.ndarray:
    """Return ``value`` as an array, raising unless every element is finite and >= 0."""
    arr = check_finite(name, value)
    if np.any(arr < 0):
        raise ValueError(f"{name} must be >= 0 (got {_describe(arr)}); allowed range: [0, inf)")
    return arr


def check_range(
    name: str, value, low: float, high: float, *, closed: tuple[bool, bool] = (False, False)
) -> np.ndarray:
    """Return ``value`` as an array, raising unless ``low < value < high``.

    ``closed`` makes either end inclusive.
    """
    arr = check_finite(name, value)
    lo_ok = arr >= low if closed[0] else arr > low
    hi_ok = arr <= high if closed[1] else arr < high
    if not np.all(lo_ok & hi_ok):
        br = ("[" if closed[0] else "(") + f"{low}, {high}" + ("]" if closed[1] else ")")
        raise ValueError(f"{name} must lie in {br} (got {_describe(arr)})")
    return arr


def check_exponent(value, *, low: float = 1.0, closed_low: bool = True) -> float:
    """The exponent n of a power-law contact F = k δ^n as a float; ValueError unless in [1, 10].

    ``low``/``closed_low`` narrow the lower end (e.g. n > 1 where a solitary wave needs
    a nonlinear force).
    """
    return float(check_range("exponent", value, low, 10.0, closed=(closed_low, True)))


def check_array(name: str, value, size: int, *, positive: bool = False,
                nonneg: bool = False) -> np.ndarray:
    """``value`` as a read-only float array of shape (size,) (a scalar is broadcast).

    ValueError naming ``name`` if it is not real, of another shape, not finite, or
    (``positive``/``nonneg``) outside (0, inf) / [0, inf).  The per-grain and
    per-contact coefficients of a chain (:class:`theory.medium.Medium`,
    :class:`discrete.Chain`) are checked with it.
    """
    try:
        a = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be an array of reals (got {value!r})") from exc
    if a.ndim == 0:
        a = np.full(size, float(a))
    if a.shape != (size,):
        raise ValueError(f"{name} must have shape ({size},) (got {a.shape})")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite (got NaN or inf)")
    if positive and np.any(a <= 0):
        raise ValueError(f"{name} must be > 0 (min {a.min()!r}); allowed range (0, inf)")
    if nonneg and np.any(a < 0):
        raise ValueError(f"{name} must be >= 0 (min {a.min()!r}); allowed range [0, inf)")
    a.setflags(write=False)
    return a
